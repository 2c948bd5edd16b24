//! The memory this process may still use: what the problem layer checks a model's estimate
//! against before building it, and what the linear solver checks a sparse LU against before
//! factorising (`linalg::ldlt_gmres`).

/// Address space a run takes beyond its data: the program, the threads' stacks and the
/// allocator's per-thread heaps, which are reserved whether used or not. Measured (VmPeak against
/// VmHWM, `stamp run`, 2026-11-25, 2 threads): 210 MiB for a 14 MiB run, 300 and 370 MiB for the
/// sphere-displacement plate at n = 100 and 200; below that `ulimit -v` aborts even small runs.
pub const ADDRESS_SPACE_OVERHEAD: f64 = 512.0 * 1024.0 * 1024.0;

/// What bounds the memory this process may use.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum MemoryLimit {
    /// The system's memory: MemAvailable of /proc/meminfo (else MemTotal).
    Available,
    /// The address-space limit (`ulimit -v`, RLIMIT_AS) of `limit` bytes, less
    /// [`ADDRESS_SPACE_OVERHEAD`].
    AddressSpace { limit: f64 },
}

/// The memory this process may use, in bytes, and what bounds it: the smaller of the system's
/// memory and the address-space limit less [`ADDRESS_SPACE_OVERHEAD`]; None when neither is
/// known.
pub fn memory_limit() -> Option<(f64, MemoryLimit)> {
    let memory = meminfo().map(|b| (b, MemoryLimit::Available));
    let address = address_space_limit().map(|limit| ((limit - ADDRESS_SPACE_OVERHEAD).max(0.0), MemoryLimit::AddressSpace { limit }));
    match (memory, address) {
        (Some(m), Some(a)) => Some(if a.0 < m.0 { a } else { m }),
        (m, a) => m.or(a),
    }
}

/// [`memory_limit`]'s bytes.
pub fn available_bytes() -> Option<f64> {
    memory_limit().map(|(bytes, _)| bytes)
}

/// MemAvailable of /proc/meminfo, else MemTotal.
fn meminfo() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let field = |name: &str| -> Option<f64> {
        let line = text.lines().find(|l| l.starts_with(name))?;
        let kib: f64 = line[name.len()..].trim().trim_end_matches("kB").trim().parse().ok()?;
        Some(kib * 1024.0)
    };
    field("MemAvailable:").or_else(|| field("MemTotal:"))
}

/// The soft address-space limit of this process (RLIMIT_AS) in bytes; None when unlimited.
fn address_space_limit() -> Option<f64> {
    let mut r = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: getrlimit writes the struct it is given
    let rc = unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut r) };
    (rc == 0 && r.rlim_cur != libc::RLIM_INFINITY).then_some(r.rlim_cur as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// On Linux the system's memory is read, and a limit with it.
    #[test]
    fn the_memory_of_this_machine_is_read() {
        if cfg!(target_os = "linux") {
            assert!(meminfo().expect("/proc/meminfo") > 1024.0 * 1024.0);
            let (bytes, _) = memory_limit().expect("a limit");
            assert!(bytes >= 0.0 && available_bytes().is_some(), "{bytes}");
        }
    }
}

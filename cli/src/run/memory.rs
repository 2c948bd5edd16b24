//! How much memory a model will need, checked before it is built: a problem that cannot fit is
//! refused with the estimate instead of dying of an allocation failure (or swapping for minutes).
//!
//! The estimate covers the mesh, the sparse tangent and its pattern, the preconditioner and the
//! LDL^T factor, whose fill grows like N log2 N for a nested-dissection ordering of a 2D mesh
//! (N unknowns: 6 per node in the paper's plate, 3 per surface in the others). Calibrated on
//! `stamp bench` (quarter plate, n x n cells): peak RSS 1.36 GiB at n = 200 (241 200 unknowns) and 5.85 GiB at n = 400 (961 600 unknowns); the formula
//! gives 1.44 and 6.14 GiB, a little on the safe side. Measured again with /usr/bin/time -v
//! (`stamp bench --one n`, 2026-11-24): n = 50 peaks at 0.077 GiB (estimate 0.13), n = 100 at
//! 0.32 GiB (estimate 0.37).

/// Unknowns per node of a plate of `surfaces` surfaces (the problem file's `[plate] surfaces`):
/// three per surface.
pub fn dofs_per_node(surfaces: impl Into<usize>) -> u64 {
    3 * surfaces.into() as u64
}

/// Bytes per unknown and per factor of log2(unknowns) (see the calibration above).
const BYTES_PER_UNKNOWN_LOG: f64 = 340.0;
/// What any run needs besides (program, buffers).
const BASE_BYTES: f64 = 64.0 * 1024.0 * 1024.0;

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// Estimated peak memory in bytes of a model with `nodes` nodes of `dofs_per_node` unknowns each
/// (f64: no overflow).
pub fn estimate_bytes(nodes: u64, dofs_per_node: u64) -> f64 {
    let unknowns = (nodes as f64) * dofs_per_node as f64;
    BASE_BYTES + BYTES_PER_UNKNOWN_LOG * unknowns * unknowns.max(2.0).log2()
}

/// The memory this process may use, in bytes: MemAvailable of /proc/meminfo, else MemTotal, else
/// None (unknown: no check).
pub fn available_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let field = |name: &str| -> Option<f64> {
        let line = text.lines().find(|l| l.starts_with(name))?;
        let kib: f64 = line[name.len()..].trim().trim_end_matches("kB").trim().parse().ok()?;
        Some(kib * 1024.0)
    };
    field("MemAvailable:").or_else(|| field("MemTotal:"))
}

/// Ok if a model of `nodes` nodes with `dofs_per_node` unknowns each fits in the available
/// memory; else what it needs and what to do, as a message (the caller names the file and key).
pub fn check_model_fits(nodes: u64, dofs_per_node: u64) -> Result<(), String> {
    check_against(nodes, dofs_per_node, available_bytes())
}

/// [`check_model_fits`] against a given amount of memory (None: unknown, accepted).
pub fn check_against(nodes: u64, dofs_per_node: u64, available: Option<f64>) -> Result<(), String> {
    let need = estimate_bytes(nodes, dofs_per_node);
    match available {
        Some(avail) if need > avail => Err(format!(
            "the model has {nodes} nodes ({} unknowns) and needs about {:.1} GiB of memory (mesh, sparse matrix, LDL^T factor), \
             but only {:.1} GiB is available: use a coarser mesh, or a machine with more memory",
            nodes.saturating_mul(dofs_per_node),
            need / GIB,
            avail / GIB
        )),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's plate: three displacements on each of its two faces.
    const DOFS_PER_NODE: u64 = 6;

    #[test]
    fn the_estimate_matches_the_bench_calibration() {
        // quarter plate n x n: (n + 1)^2 nodes; measured 1.36 GiB (n = 200) and 5.85 GiB (n = 400)
        for (n, measured) in [(200u64, 1.36), (400, 5.85)] {
            let est = estimate_bytes((n + 1) * (n + 1), DOFS_PER_NODE) / GIB;
            assert!(est >= measured && est < 1.15 * measured, "n = {n}: {est} GiB against {measured}");
        }
    }

    #[test]
    fn three_unknowns_per_surface() {
        assert_eq!(dofs_per_node(2usize), DOFS_PER_NODE);
        assert_eq!(dofs_per_node(5usize), 15);
    }

    #[test]
    fn a_model_too_large_is_refused_with_the_estimate() {
        let e = check_against(25_010_001, DOFS_PER_NODE, Some(8.0 * GIB)).unwrap_err();
        assert!(e.contains("25010001 nodes") && e.contains("GiB") && e.contains("8.0 GiB is available") && e.contains("coarser mesh"), "{e}");
        assert!(check_against(441, DOFS_PER_NODE, Some(8.0 * GIB)).is_ok());
        assert!(check_against(u64::MAX, DOFS_PER_NODE, None).is_ok());
        assert!(check_against(u64::MAX, DOFS_PER_NODE, Some(1e12)).is_err());
    }
}

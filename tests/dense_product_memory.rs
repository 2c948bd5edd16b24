//! The address space of the dense products follows the matrices, not the CPU's cache: a run of a
//! small plate under `ulimit -v` must not die of a kernel that reserves twice the L3 cache per
//! thread (faer's "std" feature sends products to private-gemm-x86, which does: 0.96 GB a thread
//! on a CPU that reports 480 MiB of L3; see the workspace's Cargo.toml).
//!
//! One test in its own binary: VmPeak is the process's, and no other test runs beside it.

mod common;
use common::sphere::*;
use stamp::linalg::ldlt_gmres::LdltGmres;
use stamp::linalg::linear_solver::LinearSolver;
use stamp::nonlinear::NonlinearProblem;

/// The process's peak address space (VmPeak of /proc/self/status) in bytes.
fn vm_peak() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let line = status.lines().find(|l| l.starts_with("VmPeak:")).unwrap();
    let kib: f64 = line.split_whitespace().nth(1).unwrap().parse().unwrap();
    kib * 1024.0
}

#[test]
#[cfg(target_os = "linux")]
fn element_kernels_and_the_factorisation_reserve_memory_by_the_model_not_by_the_cache() {
    // the threads and the model first (their stacks and heaps are not what is measured)
    let p = SphereProblem::new(40.0, 1.0, 24, Support::Clamped);
    let (_, mut model) = p.build();
    let u = vec![0.0; model.num_dofs()];
    rayon::broadcast(|_| ());
    let before = vm_peak();
    // element kernels (dense products of 24 x 24 blocks on every thread) and the supernodal LDL^T
    // of 3 750 unknowns (dense updates of its supernodes)
    for _ in 0..3 {
        model.evaluate(&u, 0.5, true).unwrap();
    }
    let mut solver = LdltGmres::new();
    solver.factorize(model.matrix()).unwrap();
    let mut x = model.residual().to_vec();
    solver.solve_in_place(&mut x).unwrap();
    // a dense product of 300^3 on every thread, as the factorisation of a larger plate does
    rayon::broadcast(|_| {
        let a = faer::Mat::<f64>::from_fn(300, 300, |i, j| (i + 2 * j) as f64);
        let b = &a * &a;
        assert!(b[(0, 0)].is_finite());
    });
    let grown = vm_peak() - before;
    let mib = 1024.0 * 1024.0;
    println!("VmPeak grew by {:.1} MiB on {} threads", grown / mib, rayon::current_num_threads());
    // the model's own matrices are a few MiB; a kernel sized by an L3 cache of 16 MiB or more
    // reserves at least 32 MiB a thread
    assert!(grown < 32.0 * mib * rayon::current_num_threads() as f64 / 2.0 + 16.0 * mib, "the address space grew by {:.0} MiB: a dense kernel reserves by the cache", grown / mib);
}

//! The solver as a whole: direct, preconditioned, reused, parallel, handed to the LU.

use super::factorisation::pivots;
use super::matrix::multiply;
use super::parallelism::FactorParallelism;
use super::*;
use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
use faer::sparse::{SparseColMat, Triplet};

pub(super) fn matrix(n: usize, entries: &[(usize, usize, f64)]) -> SparseColMat<usize, f64> {
    let t: Vec<Triplet<usize, usize, f64>> = entries.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
    SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
}

/// 1D Laplacian-like matrix of size n with a skew part `skew` on the off-diagonals and a
/// diagonal shift.
pub(super) fn tridiagonal(n: usize, skew: f64, shift: f64) -> SparseColMat<usize, f64> {
    let mut e = Vec::new();
    for i in 0..n {
        e.push((i, i, 2.0 + shift));
        if i + 1 < n {
            e.push((i, i + 1, -1.0 + skew));
            e.push((i + 1, i, -1.0 - skew));
        }
    }
    matrix(n, &e)
}

fn check_solution(a: &SparseColMat<usize, f64>, solver: &mut LdltGmres) {
    let n = a.nrows();
    let exact: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos() + 0.1 * i as f64).collect();
    let mut b = vec![0.0; n];
    multiply(a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val(), &exact, &mut b);
    solver.factorize(a.as_ref()).unwrap();
    solver.solve_in_place(&mut b).unwrap();
    let scale = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let err = b.iter().zip(&exact).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale;
    assert!(err < 1e-9, "error {err:e}, {:?}", solver.stats());
}

/// The pivots read from faer's factor are those of A: their log sum is log det A, for a
/// simplicial and a supernodal factor of the 2D Laplacian with three coupled unknowns per
/// grid point (L (x) B, eigenvalues the products of L's and B's).
#[test]
fn pivots_multiply_to_the_determinant() {
    let b = [[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]];
    let b_eigen = [2.0 - 2f64.sqrt(), 2.0, 2.0 + 2f64.sqrt()];
    let mut kinds = Vec::new();
    for m in [6, 60] {
        let id = |i: usize, j: usize| i * m + j;
        let mut e = Vec::new();
        let mut couple = |p: usize, q: usize, v: f64| {
            for r in 0..3 {
                for c in 0..3 {
                    if b[r][c] != 0.0 {
                        e.push((3 * p + r, 3 * q + c, v * b[r][c]));
                    }
                }
            }
        };
        for i in 0..m {
            for j in 0..m {
                couple(id(i, j), id(i, j), 4.0);
                if i + 1 < m {
                    couple(id(i, j), id(i + 1, j), -1.0);
                    couple(id(i + 1, j), id(i, j), -1.0);
                }
                if j + 1 < m {
                    couple(id(i, j), id(i, j + 1), -1.0);
                    couple(id(i, j + 1), id(i, j), -1.0);
                }
            }
        }
        let a = matrix(3 * m * m, &e);
        let mut s = LdltGmres::new();
        s.factorize(a.as_ref()).unwrap();
        let sym = s.symbolic.as_ref().unwrap();
        kinds.push(matches!(sym.raw(), SymbolicCholeskyRaw::Supernodal(_)));
        let log_det: f64 = pivots(sym, &s.factor).map(f64::ln).sum();
        let angle = |k: usize| 2.0 - 2.0 * (k as f64 * std::f64::consts::PI / (m + 1) as f64).cos();
        let expected: f64 = (1..=m).flat_map(|j| (1..=m).flat_map(move |k| b_eigen.map(|mu| ((angle(j) + angle(k)) * mu).ln()))).sum();
        assert!((log_det - expected).abs() <= 1e-10 * expected.abs(), "m = {m}: {log_det} against {expected}");
        assert_eq!(pivots(sym, &s.factor).count(), 3 * m * m);
    }
    assert_eq!(kinds, [false, true], "the factor kinds this test means to cover (supernodal?)");
}

#[test]
fn symmetric_matrix_is_solved_directly() {
    let mut s = LdltGmres::new();
    check_solution(&tridiagonal(300, 0.0, 0.01), &mut s);
    assert_eq!((s.stats().direct, s.stats().preconditioned, s.stats().lu_fallbacks, s.stats().gmres_iterations), (1, 0, 0, 0));
}

#[test]
fn symmetric_indefinite_matrix_is_solved_directly() {
    // a saddle point: [[2, 1], [1, -1]] blocks, quasi-definite
    let mut e = Vec::new();
    for k in 0..50 {
        let (i, j) = (2 * k, 2 * k + 1);
        e.extend([(i, i, 2.0), (i, j, 1.0), (j, i, 1.0), (j, j, -1.0)]);
    }
    let mut s = LdltGmres::new();
    check_solution(&matrix(100, &e), &mut s);
    assert_eq!(s.stats().direct, 1);
}

#[test]
fn nonsymmetric_matrix_is_solved_by_preconditioned_gmres() {
    let mut s = LdltGmres::new().reuse(false);
    check_solution(&tridiagonal(300, 0.2, 0.01), &mut s);
    let st = s.stats();
    assert_eq!((st.preconditioned, st.lu_fallbacks), (1, 0), "{st:?}");
    assert!(st.gmres_iterations > 0);
    // the same pattern again: the symbolic phase is reused
    let before = s.timings().symbolic;
    check_solution(&tridiagonal(300, 0.1, 0.02), &mut s);
    assert_eq!(s.timings().symbolic, before);
    assert_eq!(s.stats().preconditioned, 2);
}

#[test]
fn a_factor_is_reused_for_a_nearby_matrix_and_renewed_for_a_distant_one() {
    let mut s = LdltGmres::new().reuse(true);
    check_solution(&tridiagonal(400, 0.2, 0.01), &mut s);
    let first = s.stats().gmres_iterations;
    // nearby: solved with the first matrix's factor, to the same accuracy
    check_solution(&tridiagonal(400, 0.21, 0.011), &mut s);
    let st = s.stats();
    assert_eq!((st.preconditioned, st.reused, s.timings().factorizations), (1, 1, 1), "{st:?}");
    assert!(st.gmres_iterations > first, "{st:?}");
    // far off: after a nearly singular symmetric matrix (solved directly) a well-conditioned
    // one, whose GMRES on the old factor would need thousands of iterations: the stale solve
    // gives up (within 200 iterations whatever the clock says), the matrix is factorised and
    // solved again, accurately
    let mut s = LdltGmres::new().reuse(true);
    check_solution(&tridiagonal(400, 0.0, 1e-6), &mut s);
    check_solution(&tridiagonal(400, 0.4, 3.0), &mut s);
    let st = s.stats();
    assert_eq!((st.direct, st.reused, st.preconditioned, st.lu_fallbacks), (1, 1, 1, 0), "{st:?}");
    assert_eq!(s.timings().factorizations, 2, "{st:?}");
    // without reuse (the default) every matrix is factorised
    let mut s = LdltGmres::new();
    check_solution(&tridiagonal(400, 0.2, 0.01), &mut s);
    check_solution(&tridiagonal(400, 0.21, 0.011), &mut s);
    assert_eq!((s.stats().reused, s.timings().factorizations), (0, 2));
}

/// A k x k grid Laplacian with a skew part on the x couplings.
fn grid(k: usize, skew: f64) -> SparseColMat<usize, f64> {
    let mut e = Vec::new();
    for (x, y) in (0..k).flat_map(|x| (0..k).map(move |y| (x, y))) {
        let i = x * k + y;
        e.push((i, i, 4.01));
        if x + 1 < k {
            e.extend([(i, i + k, -1.0 + skew), (i + k, i, -1.0 - skew)]);
        }
        if y + 1 < k {
            e.extend([(i, i + 1, -1.0), (i + 1, i, -1.0)]);
        }
    }
    matrix(k * k, &e)
}

#[test]
fn both_orderings_solve_the_same_systems() {
    for skew in [0.0, 0.3] {
        let a = grid(40, skew);
        let mut amd = LdltGmres::new().ordering(Ordering::Amd);
        let mut nd = LdltGmres::new().ordering(Ordering::NestedDissection);
        // Auto: AMD below ND_MIN_UNKNOWNS
        let mut auto = LdltGmres::new();
        for s in [&mut amd, &mut nd, &mut auto] {
            check_solution(&a, s);
            assert_eq!(s.stats().lu_fallbacks, 0);
        }
        assert_eq!(amd.ordering_used(), Some(Ordering::Amd));
        assert_eq!(nd.ordering_used(), Some(Ordering::NestedDissection));
        assert_eq!(auto.ordering_used(), Some(Ordering::Amd));
        assert!(nd.factor_len() > 0 && nd.factor_len() != amd.factor_len());
        assert_eq!(auto.factor_len(), amd.factor_len());
    }
    // a structurally non-symmetric pattern: no LDL^T, no ordering
    let mut s = LdltGmres::new().ordering(Ordering::NestedDissection);
    check_solution(&matrix(3, &[(0, 0, 2.0), (0, 1, 1.0), (1, 1, 3.0), (2, 2, 1.0), (2, 0, 0.5)]), &mut s);
    assert_eq!((s.ordering_used(), s.factor_len()), (None, 0));
}

/// From `PARALLEL_MIN_ROWS` unknowns on, with a supernodal factor, the solves are the
/// tree-parallel ones; they give the answers (and the GMRES iterations) of the same solve
/// on one thread, which a sequential solver uses (both against faer's own solve: the unit
/// tests of `crate::linalg::supernodal_solve`).
#[test]
fn large_matrices_use_the_parallel_supernodal_solve() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    for skew in [0.0, 0.3] {
        let a = grid(150, skew);
        assert!(a.nrows() >= crate::linalg::linear_solver::PARALLEL_MIN_ROWS);
        let mut parallel = LdltGmres::with_parallelism(Par::rayon(2));
        let mut sequential = LdltGmres::with_parallelism(Par::Seq);
        pool.install(|| check_solution(&a, &mut parallel));
        check_solution(&a, &mut sequential);
        assert!(parallel.supernodal.is_some() && sequential.supernodal.is_some());
        let (p, s) = (parallel.stats(), sequential.stats());
        assert_eq!((p.direct, p.preconditioned, p.lu_fallbacks), (s.direct, s.preconditioned, 0));
        assert_eq!(p.gmres_iterations, s.gmres_iterations, "{p:?} {s:?}");
        assert_eq!(p.direct, usize::from(skew == 0.0));
    }
}

/// The estimates for the linearised contact re-solve: many columns at once give what one
/// solve each gives (the factor of A when symmetric, of S otherwise: there within GMRES's
/// distance of A^-1 b); the forward halves of sparse vectors give b^T A^-1 c of a whole solve
/// with a supernodal factor, and none with a simplicial one.
#[test]
fn many_columns_and_forward_halves_agree_with_single_solves() {
    for (k, skew) in [(150, 0.0), (150, 0.05), (12, 0.0)] {
        let a = grid(k, skew);
        let n = a.nrows();
        let mut solver = LdltGmres::new();
        solver.factorize(a.as_ref()).unwrap();
        let columns: Vec<Vec<f64>> = (0..3).map(|c| (0..n).map(|i| ((i * (c + 2)) as f64 * 0.37).sin()).collect()).collect();
        let mut many: Vec<f64> = columns.concat();
        solver.solve_many_approx(&mut many, 3).unwrap();
        for (c, col) in columns.iter().enumerate() {
            let mut one = col.clone();
            solver.solve_in_place(&mut one).unwrap();
            let scale = one.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let err = many[c * n..(c + 1) * n].iter().zip(&one).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale;
            let allowed = if skew == 0.0 { 1e-10 } else { 0.2 };
            assert!(err < allowed, "k = {k}, skew {skew}, column {c}: {err:e}");
        }
        let sparse: Vec<Vec<(usize, f64)>> = vec![vec![(n / 2, 1.0), (n / 2 + 1, -0.5)], vec![(7, 2.0)], vec![(n - 3, 1.0), (n / 3, 0.25)]];
        match solver.forward_columns(&sparse).unwrap() {
            Some(fc) => {
                assert_eq!(k, 150, "forward halves from a simplicial factor");
                for (i, bi) in sparse.iter().enumerate() {
                    let mut x = vec![0.0; n];
                    bi.iter().for_each(|&(e, v)| x[e] += v);
                    // the same factor (of A or S) applied whole
                    solver.solve_many_approx(&mut x, 1).unwrap();
                    for (j, bj) in sparse.iter().enumerate() {
                        let expected: f64 = bj.iter().map(|&(e, c)| c * x[e]).sum();
                        let got = fc[j].dot(&fc[i]);
                        assert!((got - expected).abs() <= 1e-12 * expected.abs().max(1e-3), "k = {k}, skew {skew}: {got} against {expected}");
                    }
                }
            }
            None => assert!(k == 12, "no forward halves from the supernodal factor of {n} unknowns"),
        }
    }
}

/// With a parallel setting the first factorisation of a pattern runs on the threads, the
/// second on one, the later ones the faster way; a sequential solver never tries the threads;
/// a new pattern measures again.
#[test]
fn the_factorisation_parallelism_is_measured_then_chosen() {
    let mut f = FactorParallelism::default();
    assert_eq!(f.choose(Par::rayon(2)), Par::rayon(2));
    f.record(2.0);
    assert_eq!((f.choose(Par::rayon(2)), f.threads_won()), (Par::Seq, None));
    f.record(1.0);
    assert_eq!((f.choose(Par::rayon(2)), f.threads_won()), (Par::Seq, Some(false)));
    f.record(5.0);
    assert_eq!(f.choose(Par::rayon(2)), Par::Seq, "later timings do not undo the choice");
    let mut g = FactorParallelism::default();
    g.choose(Par::rayon(2));
    g.record(1.0);
    g.choose(Par::rayon(2));
    g.record(3.0);
    assert_eq!((g.choose(Par::rayon(2)), g.threads_won()), (Par::rayon(2), Some(true)));
    let mut h = FactorParallelism::default();
    assert_eq!(h.choose(Par::Seq), Par::Seq);
    h.record(1.0);
    assert_eq!((h.choose(Par::Seq), h.threads_won()), (Par::Seq, None));
    // in the solver: two factorisations of a large pattern settle it, a new pattern resets
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    let mut s = LdltGmres::with_parallelism(Par::rayon(2));
    pool.install(|| {
        check_solution(&grid(150, 0.0), &mut s);
        assert_eq!(s.factorizes_in_parallel(), None);
        check_solution(&grid(150, 0.0), &mut s);
        assert!(s.factorizes_in_parallel().is_some());
        check_solution(&grid(151, 0.0), &mut s);
        assert_eq!(s.factorizes_in_parallel(), None);
    });
}

/// A given P factorised on one thread while another takes A apart (the second factorisation
/// of a pattern always runs on one thread) solves as the plain path does; a symmetric A with
/// a P is factorised itself (direct), whichever path it takes.
#[test]
fn a_preconditioner_factorised_beside_the_pass_over_a_solves_the_same() {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
    for skew in [0.3, 0.0] {
        let a = grid(150, skew);
        assert!(a.nrows() >= crate::linalg::linear_solver::PARALLEL_MIN_ROWS);
        let p = grid(150, 0.0);
        let n = a.nrows();
        let exact: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos() + 0.1 * i as f64).collect();
        let mut s = LdltGmres::with_parallelism(Par::rayon(2));
        for round in 0..3 {
            // another A each round (a stale pass over A would show)
            let mut a = a.clone();
            a.val_mut().iter_mut().for_each(|v| *v *= 1.0 + 0.5 * round as f64);
            let mut x = vec![0.0; n];
            multiply(a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val(), &exact, &mut x);
            pool.install(|| {
                s.factorize_preconditioned(a.as_ref(), Some(p.as_ref())).unwrap();
                s.solve_in_place(&mut x).unwrap();
            });
            let scale = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let err = x.iter().zip(&exact).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale;
            assert!(err < 1e-9, "skew {skew}, round {round}: error {err:e}, {:?}", s.stats());
        }
        let st = s.stats();
        let expected = if skew == 0.0 { (3, 0) } else { (0, 3) };
        assert_eq!((st.direct, st.preconditioned, st.lu_fallbacks), (expected.0, expected.1, 0), "skew {skew}");
        assert!(s.factorizes_in_parallel().is_some());
    }
}

#[test]
fn a_useless_symmetric_part_hands_over_to_the_lu() {
    // symmetric part singular (zero): [[0, 1], [-1, 0]] blocks
    let mut e = Vec::new();
    for k in 0..20 {
        let (i, j) = (2 * k, 2 * k + 1);
        e.extend([(i, i, 0.0), (i, j, 1.0), (j, i, -1.0), (j, j, 0.0)]);
    }
    let mut s = LdltGmres::new();
    check_solution(&matrix(40, &e), &mut s);
    assert_eq!(s.stats().lu_fallbacks, 1, "{:?}", s.stats());
}

#[test]
fn a_structurally_nonsymmetric_matrix_goes_to_the_lu() {
    let a = matrix(3, &[(0, 0, 2.0), (0, 1, 1.0), (1, 1, 3.0), (2, 2, 1.0), (2, 0, 0.5)]);
    let mut s = LdltGmres::new();
    check_solution(&a, &mut s);
    assert_eq!(s.stats().lu_fallbacks, 1);
}

#[test]
fn singular_matrix_is_an_error() {
    let a = matrix(3, &[(0, 0, 1.0), (1, 1, 0.0), (2, 2, 1.0), (0, 1, 0.0), (1, 0, 0.0)]);
    let mut s = LdltGmres::new();
    let mut b = vec![1.0, 1.0, 1.0];
    let r = s.factorize(a.as_ref()).and_then(|_| s.solve_in_place(&mut b));
    assert!(r.is_err(), "{b:?}");
}

//! The fast linear solver (LDL^T of the symmetric part, GMRES on the plate's
//! non-symmetric tangent) against the sparse LU, on the real matrices of the sphere problem.

mod common;
use common::sphere::*;
use stamp::linalg::ldlt_gmres::{LdltGmres, Ordering};
use stamp::linalg::linear_solver::{LinearSolver, SparseLu};
use stamp::nonlinear::{NewtonRaphson, NonlinearProblem, NonlinearSolver};

fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let norm = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / norm
}

/// The clamped sphere problem on an n x n mesh evaluated at a random displacement (seed `seed`):
/// the model holding the tangent, the residual as right-hand side and the LU's solution.
fn deformed_tangent(n: usize, seed: u64) -> (stamp::model::Model<stamp_elements::PlateElements>, Vec<f64>, Vec<f64>) {
    let p = SphereProblem::new(40.0, 1.0, n, Support::Clamped);
    let (_, mut model) = p.build();
    let mut rng = common::Lcg(seed);
    let u: Vec<f64> = (0..model.num_dofs()).map(|_| 0.05 * (rng.next() - 0.5)).collect();
    model.evaluate(&u, 0.5, true).unwrap();
    let (b, x_lu) = residual_and_lu_solution(&model);
    (model, b, x_lu)
}

/// The residual of the model's last evaluation and the LU's solution of its tangent system.
fn residual_and_lu_solution(model: &stamp::model::Model<stamp_elements::PlateElements>) -> (Vec<f64>, Vec<f64>) {
    let b = model.residual().to_vec();
    let mut lu = SparseLu::new();
    lu.factorize(model.matrix()).unwrap();
    let mut x_lu = b.clone();
    lu.solve_in_place(&mut x_lu).unwrap();
    (b, x_lu)
}

/// The tangent of a deformed, contacting plate: not symmetric (b_ab33 = 0), so the solver takes the
/// preconditioned path, and its solution is the LU's.
#[test]
fn plate_tangent_is_solved_like_the_lu() {
    let (model, b, x_lu) = deformed_tangent(12, 7);
    let mut fast = LdltGmres::new();
    fast.factorize(model.matrix()).unwrap();
    let mut x = b.clone();
    fast.solve_in_place(&mut x).unwrap();
    let st = fast.stats();
    assert_eq!((st.direct, st.preconditioned, st.lu_fallbacks), (0, 1, 0), "{st:?}");
    assert!(st.gmres_iterations >= 2 && st.gmres_iterations <= 40, "{st:?}");
    let d = relative_difference(&x_lu, &x);
    println!("GMRES iterations {}, relative difference from the LU {d:.2e}", st.gmres_iterations);
    assert!(d < 1e-8, "{d:e}");
}

/// The plate's tangent under either fill-reducing ordering: the same solution (the LU's), nested
/// dissection with the smaller factor on this 24 x 24 mesh.
#[test]
fn plate_tangent_is_solved_alike_under_amd_and_nested_dissection() {
    let (model, b, x_lu) = deformed_tangent(24, 11);
    let mut len = Vec::new();
    for ordering in [Ordering::Amd, Ordering::NestedDissection] {
        let mut fast = LdltGmres::new().ordering(ordering);
        fast.factorize(model.matrix()).unwrap();
        let mut x = b.clone();
        fast.solve_in_place(&mut x).unwrap();
        let st = fast.stats();
        assert_eq!(fast.ordering_used(), Some(ordering));
        assert_eq!((st.preconditioned, st.lu_fallbacks), (1, 0), "{st:?}");
        let d = relative_difference(&x_lu, &x);
        println!("{ordering:?}: factor entries {}, GMRES iterations {}, relative difference from the LU {d:.2e}", fast.factor_len(), st.gmres_iterations);
        assert!(d < 1e-8, "{ordering:?}: {d:e}");
        len.push(fast.factor_len());
    }
    assert!(len[1] < len[0], "{len:?}");
}

/// The whole load path with either solver (and the LDL^T under either ordering): the same steps,
/// the same answer.
#[test]
fn sphere_problem_is_solved_like_the_lu() {
    let mut p = SphereProblem::new(40.0, 1.0, 10, Support::SimplySoft);
    p.depth = 1.5; // bending and membrane action, a contact zone of several nodes
    let run = |fast: Option<Ordering>| {
        let (mesh, mut model) = p.build();
        let mut u = vec![0.0; model.num_dofs()];
        let (summary, stats) = if let Some(ordering) = fast {
            let mut newton = NewtonRaphson::new(LdltGmres::new().ordering(ordering), p.settings());
            let s = newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
            (s, Some(newton.linear.stats()))
        } else {
            let mut newton = NewtonRaphson::new(SparseLu::new(), p.settings());
            (newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap(), None)
        };
        (summary.steps, p.measure(&mesh, &model, &u), u, stats)
    };
    let (steps_lu, r_lu, u_lu, _) = run(None);
    for ordering in [Ordering::Auto, Ordering::NestedDissection] {
        let (steps, r, u, stats) = run(Some(ordering));
        let st = stats.unwrap();
        println!("LU: {r_lu:?}\nLDL^T ({ordering:?}) + GMRES: {r:?}, {st:?}");
        assert_eq!(steps, steps_lu);
        assert_eq!(st.lu_fallbacks, 0, "{st:?}");
        assert!(st.preconditioned > 0);
        assert_eq!(r.active, r_lu.active);
        assert!(r.active >= 3, "{r:?}");
        assert!((r.reaction / r_lu.reaction - 1.0).abs() < 1e-8, "{} vs {}", r.reaction, r_lu.reaction);
        assert!(relative_difference(&u_lu, &u) < 1e-8);
    }
}

/// The plate's preconditioner P (the tangent without the one-way thickness coupling, see
/// `Element::has_preconditioner`) in place of the tangent's symmetric part: the same solution (the
/// LU's) in fewer GMRES iterations, on the tangent of a pressed plate. Through the bordered solver
/// too (its leading block).
#[test]
fn plate_preconditioner_saves_gmres_iterations() {
    use stamp::linalg::bordered::BorderedSolver;
    use stamp::linalg::linear_solver::SparseLu;
    let mut p = SphereProblem::new(100.0, 1.0, 16, Support::SimplySoft);
    p.radius = 50.0;
    p.depth = 2.0;
    let (_, mut model) = p.build();
    let mut u = vec![0.0; model.num_dofs()];
    NewtonRaphson::new(SparseLu::new(), p.settings()).solve_path(&mut model, &mut u, 0.0, &[0.5, 1.0], &mut |_, _, _| {}).unwrap();
    // the LU's Newton did not ask for P: the model built none
    assert!(model.preconditioner().is_none());
    model.want_preconditioner(true);
    model.evaluate(&u, 1.0, true).unwrap();
    let (b, x_lu) = residual_and_lu_solution(&model);
    let pre = model.preconditioner().expect("the plate gives a preconditioner");
    let mut its = Vec::new();
    for with_p in [false, true] {
        let mut fast = LdltGmres::new().with_preconditioner(with_p);
        fast.factorize_preconditioned(model.matrix(), Some(pre)).unwrap();
        let mut x = b.clone();
        fast.solve_in_place(&mut x).unwrap();
        let st = fast.stats();
        assert_eq!((st.preconditioned, st.lu_fallbacks), (1, 0), "{st:?}");
        let d = relative_difference(&x_lu, &x);
        assert!(d < 1e-8, "with P {with_p}: {d:e}");
        its.push(st.gmres_iterations);
    }
    println!("GMRES iterations to full accuracy: symmetric part {}, P {}", its[0], its[1]);
    assert!(3 * its[1] <= 2 * its[0], "{its:?}");
    // the bordered solver without a border hands P on
    let mut bordered = BorderedSolver::with_inner(0, LdltGmres::new().with_preconditioner(true));
    bordered.factorize_preconditioned(model.matrix(), Some(pre)).unwrap();
    let mut x = b.clone();
    bordered.solve_in_place(&mut x).unwrap();
    assert!(relative_difference(&x_lu, &x) < 1e-8);
}

/// A preconditioner matrix whose pattern is not the matrix's is refused with an error, by the
/// LDL^T solver and by the bordered one; the same pattern in other arrays is accepted.
#[test]
fn preconditioner_of_another_pattern_is_refused() {
    use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
    use stamp::linalg::bordered::BorderedSolver;
    let (mut model, _, _) = deformed_tangent(4, 3);
    model.want_preconditioner(true);
    let u = vec![0.0; model.num_dofs()];
    model.evaluate(&u, 0.5, true).unwrap();
    let (a, p) = (model.matrix(), model.preconditioner().unwrap());
    let n = a.nrows();
    // the same pattern in copied arrays: accepted
    let (cp, ri) = (p.symbolic().col_ptr().to_vec(), p.symbolic().row_idx().to_vec());
    let copy = SparseColMatRef::new(SymbolicSparseColMatRef::new_checked(n, n, &cp, None, &ri), p.val());
    LdltGmres::new().with_preconditioner(true).factorize_preconditioned(a, Some(copy)).unwrap();
    // the diagonal only: refused
    let diag_cp: Vec<usize> = (0..=n).collect();
    let diag_ri: Vec<usize> = (0..n).collect();
    let ones = vec![1.0; n];
    let diagonal = SparseColMatRef::new(SymbolicSparseColMatRef::new_checked(n, n, &diag_cp, None, &diag_ri), &ones);
    let e = LdltGmres::new().with_preconditioner(true).factorize_preconditioned(a, Some(diagonal)).unwrap_err();
    assert!(e.to_string().contains("preconditioner's pattern"), "{e}");
    // and so does the bordered solver
    let e = BorderedSolver::with_inner(1, LdltGmres::new().with_preconditioner(true)).factorize_preconditioned(a, Some(diagonal)).unwrap_err();
    assert!(e.to_string().contains("preconditioner's pattern"), "{e}");
}

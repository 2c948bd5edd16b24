//! The Newton iteration's economies change the work, not the answer.
//!
//! - Chord steps (NewtonSettings::chord_tol): near the solution the factorisation of the last
//!   iterate corrects instead of a new tangent; fewer factorisations, the same converged state.
//! - Inexact Newton (NewtonSettings::forcing): an iterative linear solver stops at a relative
//!   residual min(forcing, |R| / force scale); fewer GMRES iterations, the same converged state.

mod common;
use common::sphere::*;
use stamp::linalg::ldlt_gmres::LdltGmres;
use stamp::linalg::linear_solver::{LinearSolver, SparseLu};
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearProblem, NonlinearSolver};

fn problem() -> SphereProblem {
    let mut p = SphereProblem::new(40.0, 1.0, 10, Support::SimplySoft);
    p.depth = 1.5; // bending and membrane action, a contact zone of several nodes
    p
}

struct Outcome {
    u: Vec<f64>,
    result: SphereResult,
    newton_iterations: usize,
    factorizations: usize,
    gmres_iterations: usize,
    /// |R| / force scale of the final state.
    residual: f64,
}

fn solve<L: LinearSolver>(p: &SphereProblem, linear: L, settings: NewtonSettings, gmres: impl Fn(&L) -> usize) -> Outcome {
    let (mesh, mut model) = p.build();
    // the active-set path whose last iterations take chord steps: every penetrating point enters
    // at the first evaluation, no harder damping at a step's first iteration
    model.contacts[0].first_touch_fraction = None;
    model.contacts[0].step_start_entry_fraction = None;
    let mut u = vec![0.0; model.num_dofs()];
    let mut newton = NewtonRaphson::new(linear, settings);
    let summary = newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
    let ev = model.evaluate(&u, 1.0, false).unwrap();
    Outcome {
        result: p.measure(&mesh, &model, &u),
        newton_iterations: summary.newton_iterations,
        factorizations: newton.linear.timings().factorizations,
        gmres_iterations: gmres(&newton.linear),
        residual: ev.residual_norm / ev.force_scale,
        u,
    }
}

fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
}

#[test]
fn chord_steps_save_factorisations_and_reach_the_same_state() {
    let p = problem();
    // with the energy criterion this problem converges at the iterate where the chord steps
    // would start (NewtonSettings::floor_tol: quadratic convergence settled); without it
    // Newton goes down to the round-off floor, where the chord steps act
    // (and without the contact re-solve, whose path reaches the tolerance before the chord zone)
    let settings = NewtonSettings { energy_tol: 0.0, resolve_contact: false, ..p.settings() };
    let with = solve(&p, SparseLu::new(), settings.clone(), |_| 0);
    let without = solve(&p, SparseLu::new(), NewtonSettings { chord_tol: 0.0, ..settings }, |_| 0);
    let du = relative_difference(&without.u, &with.u);
    println!(
        "chord steps: {} Newton iterations, {} factorisations, |R| {:.1e}; without: {} iterations, {} factorisations, |R| {:.1e}; max |du| / max |u| {du:.1e}",
        with.newton_iterations, with.factorizations, with.residual, without.newton_iterations, without.factorizations, without.residual
    );
    assert_eq!(without.factorizations, without.newton_iterations, "without chord steps every iteration factorises");
    assert!(with.factorizations < with.newton_iterations, "no chord step was taken");
    assert!(with.factorizations < without.factorizations, "{} vs {} factorisations", with.factorizations, without.factorizations);
    assert!(with.residual <= 1e-8, "the chord path stopped short: |R| / scale {:e}", with.residual);
    assert!(du < 1e-9, "a different state: {du:e}");
    assert_eq!(with.result.active, without.result.active);
    assert!((with.result.reaction / without.result.reaction - 1.0).abs() < 1e-9, "{} vs {}", with.result.reaction, without.result.reaction);
}

#[test]
fn inexact_newton_saves_gmres_iterations_and_reaches_the_same_state() {
    let p = problem();
    let stats = |l: &LdltGmres| l.stats().gmres_iterations;
    let inexact = solve(&p, LdltGmres::new(), NewtonSettings { forcing: 1e-3, ..p.settings() }, stats);
    let exact = solve(&p, LdltGmres::new(), NewtonSettings { forcing: 0.0, ..p.settings() }, stats);
    let du = relative_difference(&exact.u, &inexact.u);
    println!(
        "forcing 1e-3: {} Newton iterations, {} GMRES iterations, |R| {:.1e}; exact solves: {} iterations, {} GMRES iterations, |R| {:.1e}; max |du| / max |u| {du:.1e}",
        inexact.newton_iterations, inexact.gmres_iterations, inexact.residual, exact.newton_iterations, exact.gmres_iterations, exact.residual
    );
    assert!(inexact.gmres_iterations < exact.gmres_iterations, "{} vs {} GMRES iterations", inexact.gmres_iterations, exact.gmres_iterations);
    assert!(inexact.residual <= 1e-8 && exact.residual <= 1e-8, "{:e} {:e}", inexact.residual, exact.residual);
    assert!(du < 1e-9, "a different state: {du:e}");
    assert_eq!(inexact.result.active, exact.result.active);
}

//! Verification of the plate under a sphere: unloading. The sphere presses the plate (twice its thickness), then goes
//! back up to where it started (solve_path with targets [0.25, 0.5, 1.0, 0.5, 0.0]). The plate is
//! elastic and the contact frictionless, so the path does not matter: at 0.5 going down the state
//! is the one at 0.5 going up, and at 0 the plate is back in its initial state (displacements ~ 0)
//! with no point in contact. The sphere starts a small gap (0.05 h) above the plate, so "no contact"
//! is unambiguous at the end (touching points with Psi = 0 belong to the active set).

mod common;
use common::sphere::*;
use stamp::linalg::linear_solver::SparseLu;
use stamp::nonlinear::{NewtonRaphson, NonlinearSolver};

#[test]
fn unloading_returns_the_plate_to_its_initial_state() {
    for support in [Support::SimplySoft, Support::Clamped] {
        let mut p = SphereProblem::new(40.0, 1.0, 12, support);
        p.radius = 40.0;
        p.gap = 0.05;
        p.depth = 2.05;
        let (mesh, mut model) = p.build();
        let mut newton = NewtonRaphson::new(SparseLu::new(), p.settings());
        let mut u = vec![0.0; model.dofs.num_dofs()];
        let targets = [0.25, 0.5, 1.0, 0.5, 0.0];
        let mut at_targets: Vec<(Vec<f64>, SphereResult, usize)> = Vec::new();
        let mut t_prev = 0.0;
        let mut went_down = false;
        newton
            .solve_path(&mut model, &mut u, 0.0, &targets, &mut |r, u, m| {
                went_down |= r.load_factor < t_prev;
                t_prev = r.load_factor;
                if r.is_target {
                    let active = m.contacts[0].state.iter().filter(|s| s.active).count();
                    at_targets.push((u.to_vec(), p.measure(&mesh, m, u), active));
                }
            })
            .unwrap();
        assert!(went_down, "the solver never stepped down");
        assert_eq!(at_targets.len(), 5);
        let umax = at_targets[2].0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let (up, down) = (&at_targets[1], &at_targets[3]);
        let path = up.0.iter().zip(&down.0).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / umax;
        let end = at_targets[4].0.iter().fold(0.0f64, |m, x| m.max(x.abs())) / umax;
        let end_active = at_targets[4].2;
        let end_lambda = model.contacts[0].state.iter().fold(0.0f64, |m, s| m.max(s.lambda.abs()));
        println!(
            "{support:?}: peak {:?}\n  t = 0.5 up {:?}\n  t = 0.5 down {:?}\n  max |u(0.5 up) - u(0.5 down)| / max |u(1)| = {path:.2e}; at t = 0: max |u| / max |u(1)| = {end:.2e}, active points {end_active}, max |lambda| {end_lambda:e}",
            at_targets[2].1, up.1, down.1
        );
        assert!(at_targets[2].1.active > 3, "the peak load should press several nodes");
        assert!(path < 1e-6, "{support:?}: the state at t = 0.5 depends on the path: {path:e}");
        assert!(end < 1e-9, "{support:?}: the plate does not return to its initial state: {end:e}");
        assert_eq!(end_active, 0, "{support:?}: the active set does not empty");
        assert_eq!(end_lambda, 0.0);
    }
}

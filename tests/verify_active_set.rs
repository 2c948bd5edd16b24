//! Verification of the plate under a sphere: robustness of the active set.
//!
//! (a) No cycling. A flat sphere (R = 200 on a 40 x 40 clamped plate, h = 1) pressed 0.5 in one
//! load increment without line search makes the semi-smooth Newton iteration swing many points in
//! and out of contact: points change state ContactPair::max_flips (10) times inside the step and are
//! frozen (they keep the active-side tangent, their force stays exact). The test checks that this
//! happens (the guard is exercised, not just present), that the step still converges, and that the
//! state it converges to is the exact solution: the same as a gentle path (four steps with line
//! search) on which no point is frozen, with lambda = min(0, eps Psi) at every point.
//!
//! (b) Monotone growth of the loaded zone: under monotone loading of the sphere problem the set of
//! nodes with |lambda| above a small threshold at step k is contained in the set at step k + 1.

mod common;
use common::sphere::*;
use stamp::linalg::linear_solver::SparseLu;
use stamp::nonlinear::{NewtonRaphson, NonlinearProblem, NonlinearSolver};

struct Run {
    u: Vec<f64>,
    cutbacks: usize,
    result: SphereResult,
    max_frozen: usize,
    max_flips: u32,
    lambda: Vec<f64>,
}

fn run(p: &SphereProblem, max_increment: f64, line_search: usize, flip_limit: u32, cycling_after: usize) -> Run {
    let (mesh, mut model) = p.build();
    model.contacts[0].max_flips = flip_limit;
    // (a set emptied by a wholesale release and entering again would count against
    // lone_max_flips, 3: the guard under test is max_flips)
    model.contacts[0].lone_max_flips = flip_limit;
    // the active-set path this test was built to provoke cycling on: every penetrating point
    // enters at the first evaluation, no harder damping at a step's first iteration
    model.contacts[0].first_touch_fraction = None;
    model.contacts[0].step_start_entry_fraction = None;
    // and every point released at once (the hold after entry damps the swings this test needs)
    model.contacts[0].hold_after_entry = false;
    // and a set may be emptied (the guard keeps a point that would end the swings)
    model.contacts[0].guard_empty = false;
    let mut s = p.settings();
    s.max_increment = max_increment;
    s.line_search_steps = line_search;
    s.cycling_after = cycling_after;
    // the rules alone: the re-solve of the linearised contact problem settles this set before
    // it can cycle (the rules remain where the re-solve does not apply: integrated contact,
    // several processes)
    s.resolve_contact = false;
    let mut newton = NewtonRaphson::new(SparseLu::new(), s);
    let mut u = vec![0.0; model.dofs.num_dofs()];
    let (mut max_frozen, mut max_flips) = (0, 0);
    let summary = newton
        .solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |r, _, m| {
            let c = &m.contacts[0];
            let frozen = c.frozen.iter().filter(|f| **f).count();
            let flips = *c.flips.iter().max().unwrap();
            println!("  t = {:.4}: {} iterations, most changes of one point {flips}, frozen points {frozen}", r.load_factor, r.iterations);
            max_frozen = max_frozen.max(frozen);
            max_flips = max_flips.max(flips);
        })
        .unwrap();
    // the converged state: residual at round-off, multipliers exactly min(0, eps Psi)
    let ev = model.evaluate(&u, 1.0, false).unwrap();
    assert!(ev.residual_norm <= 1e-8 * ev.force_scale, "residual {:e} of {:e}", ev.residual_norm, ev.force_scale);
    let pair = &model.contacts[0];
    for s in &pair.state {
        assert_eq!(s.lambda, (pair.eps_reg * s.psi).min(0.0));
    }
    let lambda = pair.state.iter().map(|s| s.lambda).collect();
    Run { result: p.measure(&mesh, &model, &u), u, cutbacks: summary.cutbacks, max_frozen, max_flips, lambda }
}

/// The guard's threshold on the hard path (the default of ContactPair::max_flips, set explicitly so
/// that the test keeps provoking the guard if the default changes).
const HARD_FLIP_LIMIT: u32 = 10;

#[test]
fn cycling_points_are_frozen_and_the_step_converges_to_the_exact_solution() {
    let mut p = SphereProblem::new(40.0, 1.0, 8, Support::Clamped);
    p.radius = 200.0;
    p.depth = 0.5;
    // the cycling cut-back off: the guard under test must settle the step on its own
    println!("one increment, no line search:");
    let hard = run(&p, 1.0, 0, HARD_FLIP_LIMIT, 0);
    println!("four increments with line search:");
    let gentle = run(&p, 0.25, 4, 10, 0);
    let umax = gentle.u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let du = hard.u.iter().zip(&gentle.u).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / umax;
    let lmax = gentle.lambda.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let dl = hard.lambda.iter().zip(&gentle.lambda).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / lmax;
    println!("hard path: {:?}\ngentle path: {:?}\nmax |du| / max |u| = {du:.2e}, max |dlambda| / max |lambda| = {dl:.2e}", hard.result, gentle.result);
    assert!(hard.max_frozen > 0 && hard.max_flips >= HARD_FLIP_LIMIT, "the test no longer provokes cycling (frozen {}, flips {})", hard.max_frozen, hard.max_flips);
    assert_eq!(gentle.max_frozen, 0, "the reference path should not need the guard");
    assert!(du < 1e-7 && dl < 1e-6, "the frozen step converged to a different state: du {du:e}, dlambda {dl:e}");
}

/// The other remedy (NewtonSettings::cycling_after, off by default): the step whose active set
/// changes at every iteration without progress is given up and cut back, before the guard
/// freezes anything, and the smaller increments reach the same solution.
#[test]
fn a_cycling_step_is_cut_back_and_converges_to_the_same_solution() {
    let mut p = SphereProblem::new(40.0, 1.0, 8, Support::Clamped);
    p.radius = 200.0;
    p.depth = 0.5;
    println!("one increment, no line search, cut-back on cycling from the 8th iteration:");
    let cut = run(&p, 1.0, 0, HARD_FLIP_LIMIT, 8);
    let gentle = run(&p, 0.25, 4, 10, 0);
    let umax = gentle.u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let du = cut.u.iter().zip(&gentle.u).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / umax;
    println!("cut-backs {}, most flips of a point {}, max |du| / max |u| = {du:.2e}", cut.cutbacks, cut.max_flips);
    assert!(cut.cutbacks > 0, "the cycling step was not cut back");
    assert_eq!(cut.max_frozen, 0, "the cut-back should come before the guard freezes points");
    assert!(du < 1e-7, "the cut-back path converged to a different state: du {du:e}");
}

/// The sets of loaded nodes (|lambda| > 1e-6 max |lambda|) and the outer contact radii (outermost
/// loaded node, and the interpolated edge on the x1 axis) at ten equal load steps.
fn zones(p: &SphereProblem) -> Vec<(f64, Vec<usize>, f64, f64)> {
    let (mesh, mut model) = p.build();
    let mut newton = NewtonRaphson::new(SparseLu::new(), p.settings());
    let mut u = vec![0.0; model.dofs.num_dofs()];
    let targets: Vec<f64> = (1..=10).map(|k| k as f64 / 10.0).collect();
    let mut out = Vec::new();
    newton
        .solve_path(&mut model, &mut u, 0.0, &targets, &mut |r, u, m| {
            let c = &m.contacts[0];
            let lmax = c.state.iter().fold(0.0f64, |a, s| a.max(s.lambda.abs()));
            let set: Vec<usize> = (0..c.points.len()).filter(|&k| c.state[k].lambda.abs() > 1e-6 * lmax).collect();
            let res = p.measure(&mesh, m, u);
            out.push((r.load_factor, set, res.radius, res.edge));
        })
        .unwrap();
    assert!(out.len() >= 10 && out.last().unwrap().1.len() >= 3, "too small a contact zone: {:?}", out.last());
    out
}

/// A moderately thick plate (a/h = 10), where the pressure under the sphere is Hertz-like: every
/// node that carries load keeps carrying it as the sphere goes down.
#[test]
fn loaded_zone_grows_monotonically_under_monotone_loading() {
    for support in [Support::Clamped, Support::SimplySoft] {
        let mut p = SphereProblem::new(40.0, 4.0, 12, support);
        p.radius = 40.0;
        p.depth = 1.0;
        let z = zones(&p);
        println!("{support:?}, a/h = 10: loaded nodes per step {:?}", z.iter().map(|s| s.1.len()).collect::<Vec<_>>());
        for w in z.windows(2) {
            let lost: Vec<usize> = w[0].1.iter().filter(|k| !w[1].1.contains(k)).copied().collect();
            assert!(lost.is_empty(), "{support:?}: nodes {lost:?} carry load at t = {} but not at t = {}", w[0].0, w[1].0);
        }
    }
}

/// A thin plate (a/h = 40) under the same sphere pressed twice its thickness: the contact zone's
/// outer edge moves out monotonically, but the set of loaded nodes does NOT grow monotonically: the
/// clamped plate's centre node carries no load at t = 0.7 and carries load again at t = 0.8. Inside
/// the contact zone of a thin plate the pressure is nearly zero (Kirchhoff theory puts the whole
/// force on the contact edge, del^4 w = 0 under a paraboloid; the paper's strip even lifts off the
/// cylinder at its centre, b_int > 0, the paper's section 5), so interior nodes sit at the kink
/// lambda = min(0, eps Psi) ~ 0 and their membership is not a property of the solution. This is not
/// an active-set failure; here only the outer radius is required to grow.
#[test]
fn contact_edge_moves_out_monotonically_on_a_thin_plate() {
    for support in [Support::Clamped, Support::SimplySoft] {
        let mut p = SphereProblem::new(40.0, 1.0, 12, support);
        p.radius = 40.0;
        p.depth = 2.0;
        let z = zones(&p);
        println!(
            "{support:?}, a/h = 40: loaded nodes per step {:?}; outermost loaded node {:?}; edge on the axis {:?}; centre loaded {:?}",
            z.iter().map(|s| s.1.len()).collect::<Vec<_>>(),
            z.iter().map(|s| (s.2 * 1e3).round() / 1e3).collect::<Vec<_>>(),
            z.iter().map(|s| (s.3 * 1e3).round() / 1e3).collect::<Vec<_>>(),
            z.iter().map(|s| s.1.contains(&0)).collect::<Vec<_>>()
        );
        for w in z.windows(2) {
            assert!(w[1].2 >= w[0].2 && w[1].3 >= w[0].3, "{support:?}: the contact edge moves in between t = {} and t = {}", w[0].0, w[1].0);
        }
    }
}

//! Verification of the plate under a sphere: global equilibrium at every converged load step. The punch's force on
//! the plate, the support reactions (Model::nodal_forces at the prescribed dofs) and the applied
//! loads add up to zero, in every direction, at every step the solver reports.
//!
//! Sign conventions: nodal_forces = f_int + w lambda grad Psi = f_int - (contact force on the plate),
//! and f_int = f_ext + (contact force) + (support force) at every node: at a prescribed dof
//! nodal_forces - f_ext is the support's force on the plate (test 1 below found the doc comment of
//! Model::nodal_forces saying the opposite; fixed). ContactPair::reaction() is the punch's force on
//! the plate.

mod common;
use common::sphere::*;
use stamp::linalg::linear_solver::SparseLu;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NonlinearSolver};
use stamp_contact::Sphere;
use stamp_elements::{Face, PlateElements};
use std::sync::Arc;

/// (contact force on the plate, support force on the plate, applied force), summed per direction.
fn balance(model: &Model<PlateElements>, t: f64) -> [[f64; 3]; 3] {
    let f = model.nodal_forces();
    let mut ext = vec![0.0; f.len()];
    for &(d, v) in &model.loads {
        ext[d] += t * v;
    }
    let mut support = [0.0; 3];
    let mut applied = [0.0; 3];
    for d in 0..f.len() {
        let c = (d % 6) % 3;
        applied[c] += ext[d];
        if model.dofs.equation(d).is_none() {
            support[c] += f[d] - ext[d];
        }
    }
    let mut contact = [0.0; 3];
    for pair in &model.contacts {
        let r = pair.reaction();
        for c in 0..3 {
            contact[c] += r[c];
        }
    }
    [contact, support, applied]
}

/// Solve along `targets` and check the balance after every step; returns the worst imbalance
/// relative to the largest of the three forces.
fn check(p: &SphereProblem, model: Model<PlateElements>, targets: &[f64], what: &str) -> f64 {
    let mut model = model;
    let mut newton = NewtonRaphson::new(SparseLu::new(), p.settings());
    let mut u = vec![0.0; model.dofs.num_dofs()];
    let mut worst = 0.0f64;
    let mut steps = 0;
    newton
        .solve_path(&mut model, &mut u, 0.0, targets, &mut |r, _, m| {
            let [contact, support, applied] = balance(m, r.load_factor);
            let scale = (0..3).map(|c| contact[c].abs().max(support[c].abs()).max(applied[c].abs())).fold(0.0, f64::max);
            let err = (0..3).map(|c| (contact[c] + support[c] + applied[c]).abs()).fold(0.0, f64::max) / scale;
            println!("{what} t = {:.4}: contact {:+.6e}, supports {:+.6e}, applied {:+.6e} (x3); imbalance {err:.2e}", r.load_factor, contact[2], support[2], applied[2]);
            assert!(contact[2].abs() > 1e-3 * scale, "the punch should carry load at t = {}", r.load_factor);
            worst = worst.max(err);
            steps += 1;
        })
        .unwrap();
    assert!(steps >= 5, "{what}: too few steps to call it a path ({steps})");
    worst
}

/// The quarter plate, simply supported, pressed by a sphere driven down twice the thickness: the
/// support reactions balance the punch.
#[test]
fn supports_balance_the_displacement_driven_sphere_at_every_step() {
    let mut p = SphereProblem::new(40.0, 1.0, 8, Support::SimplySoft);
    p.radius = 40.0;
    p.depth = 2.0;
    let (_, model) = p.build();
    let targets: Vec<f64> = (1..=8).map(|k| k as f64 / 8.0).collect();
    let worst = check(&p, model, &targets, "sphere pressed down");
    println!("worst imbalance {worst:.2e}");
    assert!(worst < 1e-8, "equilibrium violated by {worst:e}");
}

/// The clamped quarter plate under a uniform pressure q on its top face, pushed down onto a fixed
/// sphere under its centre (the sphere touches the bottom face): punch + supports = applied load.
#[test]
fn punch_and_supports_balance_the_applied_pressure_at_every_step() {
    let mut p = SphereProblem::new(40.0, 1.0, 8, Support::Clamped);
    p.radius = 40.0;
    let (mesh, mut model) = p.build();
    model.contacts.clear();
    let q = 2.0;
    for (n, a) in mesh.nodal_areas().into_iter().enumerate() {
        model.add_load(Face::Top.dof(n, 2), -q * a).unwrap();
    }
    let sphere = Sphere::new(nalgebra::Vector3::new(0.0, 0.0, -0.5 * p.h - 0.02 - p.radius), p.radius).unwrap();
    let areas = mesh.nodal_areas();
    let points = (0..mesh.num_nodes())
        .map(|n| stamp::contact::ContactPoint { node: n, x_ref: [mesh.coords[n][0], mesh.coords[n][1], -0.5 * p.h], dofs: [0, 1, 2].map(|c| Face::Bottom.dof(n, c)), weight: areas[n] })
        .collect();
    model.contacts.push(stamp::contact::ContactPair::new("sphere below", Arc::new(sphere), points, p.eps(), stamp::contact::ContactKinematics::Exact));
    let targets: Vec<f64> = (1..=8).map(|k| k as f64 / 8.0).collect();
    // from the first step on the plate rests on the sphere (gap 0.02 closes at a small fraction of q)
    let worst = check(&p, model, &targets, "pressure onto a fixed sphere");
    println!("worst imbalance {worst:.2e}");
    assert!(worst < 1e-8, "equilibrium violated by {worst:e}");
}

//! Verification of the plate under a sphere: the quarter model with symmetry conditions and the full model of the
//! sphere problem agree (centre deflection, contact radius, reaction, every displacement) to 1e-6
//! relative.
//!
//! Square plate a = 40, h = 1, simply supported (v3- = v3+ = 0, the CLI's `simply_supported`),
//! pressed by a sphere R = 40 moved 2 (twice the thickness: membrane action, large rotations near
//! the contact) with the automatic eps_reg. The quarter [0, 20]^2 has 12 x 12 elements with
//! v1 = 0 on x1 = 0 and v2 = 0 on x2 = 0; the full plate has 24 x 24 on the same node positions. The
//! soft support leaves the full plate's in-plane rigid motions free; they are held at the four edge
//! midpoints in the direction the symmetric solution does not move them (see common/sphere.rs).
//! The clamped plate is compared too.

mod common;
use common::sphere::*;
use stamp::linalg::linear_solver::SparseLu;
use stamp::nonlinear::{NewtonRaphson, NonlinearSolver};

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / a.abs().max(b.abs())
}

fn compare(support: Support) {
    let mut q = SphereProblem::new(40.0, 1.0, 12, support);
    q.radius = 40.0;
    q.depth = 2.0;
    let mut f = q.clone();
    f.quarter = false;
    let solve = |p: &SphereProblem| {
        let (mesh, mut model) = p.build();
        let mut newton = NewtonRaphson::new(SparseLu::new(), p.settings());
        let mut u = vec![0.0; model.dofs.num_dofs()];
        newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
        let r = p.measure(&mesh, &model, &u);
        (mesh, u, r)
    };
    let (qm, qu, qr) = solve(&q);
    let (fm, fu, fr) = solve(&f);
    println!("{support:?} quarter: {qr:?}\n{support:?} full:    {fr:?}");
    let checks = [("centre deflection", qr.w, fr.w), ("reaction", qr.reaction, fr.reaction), ("contact radius (axis)", qr.edge, fr.edge), ("outermost loaded node", qr.radius, fr.radius), ("force-weighted radius", qr.force_radius, fr.force_radius)];
    for (what, a, b) in checks {
        println!("  {what}: quarter {a:.12e}, full {b:.12e}, relative difference {:.2e}", rel(a, b));
        assert!(a > 0.0 && rel(a, b) < 1e-6, "{support:?}: {what} differs: quarter {a}, full {b}");
    }
    assert!(qr.active > 3, "the contact zone should span several nodes: {qr:?}");
    // every displacement of the quarter against the full model's node at the same place
    let umax = fu.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let mut worst = 0.0f64;
    for (k, x) in qm.coords.iter().enumerate() {
        let j = fm.coords.iter().position(|y| y == x).expect("the quarter's nodes are nodes of the full mesh");
        for c in 0..6 {
            worst = worst.max((qu[6 * k + c] - fu[6 * j + c]).abs() / umax);
        }
    }
    println!("  displacements: largest difference / max |u| = {worst:.2e}");
    assert!(worst < 1e-6, "{support:?}: displacements differ by {worst:e} of max |u|");
}

#[test]
fn quarter_and_full_model_agree_simply_supported() {
    compare(Support::SimplySoft);
}

#[test]
fn quarter_and_full_model_agree_clamped() {
    compare(Support::Clamped);
}

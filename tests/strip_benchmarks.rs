//! Beam-like checks of the plate in cylindrical bending: no shear locking for a very thin strip,
//! the large-deflection elastica, agreement of the linear and nonlinear variants at small loads, and
//! quadratic convergence of Newton's method.

mod common;
use common::*;
use stamp_elements::Kinematics;

#[test]
fn no_shear_locking_for_a_very_thin_strip() {
    // h / l = 1e-3 on 8 elements: tip deflection within 1 % of Kirchhoff's F l^3 / (3 D)
    let (l, h) = (1.0, 1e-3);
    let f = 1e-9;
    let (w, _, _) = cantilever_strip(l, h, 8, f, Kinematics::Linear, &[1.0]);
    let kirchhoff = f * l.powi(3) / (3.0 * bending_stiffness(h));
    let err = (w - kirchhoff) / kirchhoff;
    assert!(err.abs() < 0.01, "tip deflection {w:e} vs Kirchhoff {kirchhoff:e} ({:+.3}%)", 100.0 * err);
}

#[test]
fn large_deflection_cantilever_matches_the_elastica() {
    // P L^2 / EI = 1: tip deflection / L = 0.30172, horizontal tip displacement / L = 0.05643
    let (l, h) = (1.0, 0.005);
    let f = bending_stiffness(h) / (l * l);
    let (w, u2, _) = cantilever_strip(l, h, 48, f, Kinematics::Nonlinear, &[1.0]);
    let (ew, eu) = ((w / l - 0.30172) / 0.30172, (-u2 / l - 0.05643) / 0.05643);
    assert!(ew.abs() < 0.005, "tip deflection / L = {} ({:+.3}%)", w / l, 100.0 * ew);
    assert!(eu.abs() < 0.005, "horizontal tip displacement / L = {} ({:+.3}%)", -u2 / l, 100.0 * eu);
}

#[test]
fn linear_and_nonlinear_agree_at_small_loads() {
    let (l, h) = (1.0, 0.01);
    let f = 1e-6 * bending_stiffness(h) / (l * l);
    let (wl, _, _) = cantilever_strip(l, h, 10, f, Kinematics::Linear, &[1.0]);
    let (wn, _, _) = cantilever_strip(l, h, 10, f, Kinematics::Nonlinear, &[1.0]);
    assert!(((wn - wl) / wl).abs() < 1e-5, "linear {wl:e}, nonlinear {wn:e}");
    // and differ at large loads (the test can fail)
    let f = bending_stiffness(h) / (l * l);
    let (wl, _, _) = cantilever_strip(l, h, 10, f, Kinematics::Linear, &[1.0]);
    let (wn, _, _) = cantilever_strip(l, h, 10, f, Kinematics::Nonlinear, &[1.0]);
    assert!(((wn - wl) / wl).abs() > 0.02);
}

#[test]
fn newton_converges_quadratically() {
    let (l, h) = (1.0, 0.01);
    let f = 0.5 * bending_stiffness(h) / (l * l);
    let (_, _, reports) = cantilever_strip(l, h, 16, f, Kinematics::Nonlinear, &[1.0]);
    let last = reports.last().unwrap();
    let r0 = last.residual_history[0];
    let e: Vec<f64> = last.residual_history.iter().map(|r| r / r0).collect();
    println!("normalised residual history: {e:?}");
    // some iteration from e_k < 1e-2 must give e_{k+1} <= 10 e_k^2, and the last one is tiny
    let quadratic = e.windows(2).any(|w| w[0] < 1e-2 && w[0] > 1e-13 && w[1] <= 10.0 * w[0] * w[0]);
    assert!(quadratic, "no quadratic step in {e:?}");
    let peak = e.iter().cloned().fold(0.0, f64::max);
    assert!(*e.last().unwrap() < 1e-12 * peak);
}

//! `Element::evaluate_about`, the tangent of the mixed-integration-point Newton iteration, for
//! every plate element: its residual is `evaluate`'s; about the state itself it is `evaluate`
//! exactly; about another state its tangent differs from the exact one by the geometric stiffness
//! of the strains' quadratic remainder, which depends on the increment v - reference alone (the
//! Green-Lagrange strains are quadratic, their Hessians constant, the laws linear), and is not
//! zero. (The paper's plate is checked against a plain computation of the linearised resultants
//! in its unit tests.)

mod common;
use common::*;
use stamp::element::{Element, LocalSystem};
use stamp_elements::{FiveSurfaceLaminate, FourSurfacePlate, Isotropic, Kinematics, Laminate, Orthotropic, Ply, PlyMaterial, Section, ThreeSurfacePlate};

fn evaluate_with<E: Element>(e: &E, v: &[f64], reference: Option<&[f64]>) -> LocalSystem {
    let n = v.len();
    let mut ws = e.new_workspace();
    let mut out = LocalSystem::new(n);
    match reference {
        Some(r) => e.evaluate_about(0, v, r, &mut ws, &mut out, true),
        None => e.evaluate(0, v, &mut ws, &mut out, true),
    }
    out
}

fn largest_difference(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
}

fn check<E: Element>(what: &str, e: &E, kinematics: Kinematics) {
    let n = e.dofs_per_node() * 4;
    let mut rng = Lcg(7);
    // a large-displacement state (deflections of the order of the cell, small face separation)
    let v: Vec<f64> = (0..n).map(|k| if k % 3 == 2 { rng.range(-0.3, 0.3) } else { rng.range(-0.05, 0.05) }).collect();
    let dv: Vec<f64> = (0..n).map(|_| rng.range(-0.05, 0.05)).collect();
    let shift: Vec<f64> = (0..n).map(|_| rng.range(-0.1, 0.1)).collect();
    let exact = evaluate_with(e, &v, None);
    let scale = max_abs(&exact.tangent);
    // about itself: the same numbers
    let itself = evaluate_with(e, &v, Some(&v));
    assert!(largest_difference(&itself.tangent, &exact.tangent) <= 1e-13 * scale, "{what}: about itself");
    assert!(largest_difference(&itself.residual, &exact.residual) == 0.0, "{what}: residual about itself");
    // about v - dv: the same residual, another tangent
    let reference: Vec<f64> = v.iter().zip(&dv).map(|(a, b)| a - b).collect();
    let mixed = evaluate_with(e, &v, Some(&reference));
    assert!(largest_difference(&mixed.residual, &exact.residual) == 0.0, "{what}: the residual is evaluate's");
    let change: Vec<f64> = mixed.tangent.iter().zip(&exact.tangent).map(|(a, b)| a - b).collect();
    // the change depends on the increment only: the same at another state with the same increment
    let w: Vec<f64> = v.iter().zip(&shift).map(|(a, b)| a + b).collect();
    let w_reference: Vec<f64> = w.iter().zip(&dv).map(|(a, b)| a - b).collect();
    let other: Vec<f64> = evaluate_with(e, &w, Some(&w_reference)).tangent.iter().zip(&evaluate_with(e, &w, None).tangent).map(|(a, b)| a - b).collect();
    assert!(largest_difference(&change, &other) <= 1e-9 * scale, "{what}: {:e}", largest_difference(&change, &other));
    let size = max_abs(&change);
    match kinematics {
        // quadratic in the increment: twice the increment, four times the change
        Kinematics::Nonlinear => {
            assert!(size > 1e-8 * scale, "{what}: the linearisation changes nothing ({size:e})");
            let twice: Vec<f64> = v.iter().zip(&dv).map(|(a, b)| a - 2.0 * b).collect();
            let four: Vec<f64> = evaluate_with(e, &v, Some(&twice)).tangent.iter().zip(&exact.tangent).map(|(a, b)| a - b).collect();
            let ratio: Vec<f64> = change.iter().map(|c| 4.0 * c).collect();
            assert!(largest_difference(&four, &ratio) <= 1e-8 * scale, "{what}: not quadratic in the increment");
        }
        // no geometric stiffness: nothing to linearise
        Kinematics::Linear => assert!(size <= 1e-13 * scale, "{what}: {size:e}"),
    }
}

#[test]
fn the_paper_plate_linearises_its_geometric_stiffness_about_the_reference() {
    let mesh = distorted_element();
    for kin in [Kinematics::Nonlinear, Kinematics::Linear] {
        check("two-surface plate", &plate(&mesh, 0.15, kin), kin);
    }
}

#[test]
fn the_multi_surface_plates_and_the_laminate_linearise_theirs() {
    let mesh = distorted_element();
    let section = || Section::homogeneous(0.15, Isotropic::new(2.0e5, 0.3).unwrap()).unwrap();
    for kin in [Kinematics::Nonlinear, Kinematics::Linear] {
        check("three-surface plate", &ThreeSurfacePlate::new(&mesh, section(), kin).unwrap(), kin);
        check("four-surface plate", &FourSurfacePlate::new(&mesh, section(), kin).unwrap(), kin);
        let ply = |t: f64, angle: f64| Ply { thickness: t, material: PlyMaterial::Orthotropic(Orthotropic::new([25.0e4, 1.0e4, 1.0e4], [0.5e4, 0.5e4, 0.2e4], [0.25; 3]).unwrap()), angle };
        let stack = Laminate::new(vec![ply(0.05, 0.0), ply(0.06, 45.0), ply(0.04, -30.0)]).unwrap();
        check("five-surface laminate", &FiveSurfaceLaminate::new(&mesh, stack, kin).unwrap(), kin);
    }
}

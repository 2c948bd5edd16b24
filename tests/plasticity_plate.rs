//! The elastic-plastic plate of three to five surfaces (elements/src/plasticity): its tangent
//! against finite differences of its internal force at yielding states, the history committed by
//! the model after converged steps only, and the strip bent by end moments against the closed form
//! of the elastic-perfectly-plastic section, M = Mp (1 - (ke / k)^2 / 3).

mod common;
use common::*;
use stamp::element::{Element, LocalSystem};
use stamp_elements::plasticity::{Hardening, Plasticity};
use stamp_elements::{FourSurfacePlate, Isotropic, Kinematics, Section, ThreeSurfacePlate};

fn evaluate<E: Element>(e: &E, v: &[f64], tangent: bool) -> LocalSystem {
    let mut ws = e.new_workspace();
    let mut out = LocalSystem::new(v.len());
    e.evaluate(0, v, &mut ws, &mut out, tangent);
    assert!(out.inadmissible.is_none(), "{:?}", out.inadmissible);
    out
}

/// The largest difference between the tangent and central differences of the internal force,
/// relative to the largest tangent entry.
fn fd_error<E: Element>(e: &E, v: &[f64]) -> f64 {
    let n = v.len();
    let k = evaluate(e, v, true).tangent;
    let scale = max_abs(&k);
    let mut worst: f64 = 0.0;
    for j in 0..n {
        let step = 1e-7;
        let (mut vp, mut vm) = (v.to_vec(), v.to_vec());
        vp[j] += step;
        vm[j] -= step;
        let (rp, rm) = (evaluate(e, &vp, false).residual, evaluate(e, &vm, false).residual);
        for i in 0..n {
            worst = worst.max(((rp[i] - rm[i]) / (2.0 * step) - k[i * n + j]).abs() / scale);
        }
    }
    worst
}

fn steel() -> Isotropic {
    Isotropic::new(2.0e5, 0.3).unwrap()
}

#[test]
fn plastic_tangent_matches_finite_differences() {
    let mesh = distorted_element();
    let hill = Plasticity { hardening: Hardening::Swift { k: 530.0, e0: 0.005, n: 0.25 }, r_values: Some([1.8, 1.4, 2.2]) };
    let mises = Plasticity { hardening: Hardening::Linear { yield_stress: 150.0, modulus: 1000.0 }, r_values: None };
    for (what, p) in [("Hill, Swift", hill), ("von Mises, linear", mises)] {
        for kin in [Kinematics::Nonlinear, Kinematics::Linear] {
            let mut plate = ThreeSurfacePlate::new(&mesh, Section::homogeneous(0.15, steel()).unwrap(), kin).unwrap().with_plasticity(&[Some(p.clone())]).unwrap();
            let n = 36;
            let mut rng = Lcg(11);
            // a state that yields (strains of a few per cent), then a further one from its history
            let v: Vec<f64> = (0..n).map(|k| if k % 3 == 2 { rng.range(-0.05, 0.05) } else { rng.range(-0.03, 0.03) }).collect();
            let mut ws = plate.new_workspace();
            plate.commit(0, &v, &mut ws);
            let ep = plate.plastic_points().unwrap().of_element(0).iter().fold(0.0f64, |m, s| m.max(s.ep));
            assert!(ep > 1e-3, "{what}: the state yields (largest ep {ep:e})");
            let w: Vec<f64> = v.iter().map(|x| 1.3 * x + 0.002).collect();
            let err = fd_error(&plate, &w);
            assert!(err < 1e-6, "{what}, {kin:?}: tangent against finite differences {err:e}");
            let elastic = ThreeSurfacePlate::new(&mesh, Section::homogeneous(0.15, steel()).unwrap(), kin).unwrap();
            let (rp, re) = (evaluate(&plate, &w, false).residual, evaluate(&elastic, &w, false).residual);
            assert!(max_abs(&rp.iter().zip(&re).map(|(a, b)| a - b).collect::<Vec<_>>()) > 1e-2 * max_abs(&re), "{what}: plasticity changes the forces");
        }
    }
}

/// Below yield the elastic-plastic plate is the elastic one (Hencky's law against Saint
/// Venant-Kirchhoff's: equal to first order in the strains).
#[test]
fn below_yield_the_plate_is_elastic() {
    let mesh = distorted_element();
    let p = Plasticity { hardening: Hardening::Linear { yield_stress: 1e9, modulus: 0.0 }, r_values: None };
    let plastic = FourSurfacePlate::new(&mesh, Section::homogeneous(0.15, steel()).unwrap(), Kinematics::Linear).unwrap().with_plasticity(&[Some(p)]).unwrap();
    let elastic = FourSurfacePlate::new(&mesh, Section::homogeneous(0.15, steel()).unwrap(), Kinematics::Linear).unwrap();
    let mut rng = Lcg(3);
    let v: Vec<f64> = (0..48).map(|_| rng.range(-0.01, 0.01)).collect();
    let (a, b) = (evaluate(&plastic, &v, true), evaluate(&elastic, &v, true));
    let d = a.residual.iter().zip(&b.residual).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(d < 1e-10 * max_abs(&b.residual), "linear kinematics: {d:e}");
    let d = a.tangent.iter().zip(&b.tangent).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    assert!(d < 1e-10 * max_abs(&b.tangent), "linear kinematics tangent: {d:e}");
}

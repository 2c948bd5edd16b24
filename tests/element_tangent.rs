//! The element tangent is the exact derivative of the element's internal force: compared with
//! central finite differences at random large-displacement states.

mod common;
use common::*;
use stamp_elements::Kinematics;

fn check_tangent(kin: Kinematics, seed: u64) {
    let mesh = distorted_element();
    let plate = plate(&mesh, 0.15, kin);
    let mut rng = Lcg(seed);
    let v: Vec<f64> = (0..24).map(|_| rng.range(-0.6, 0.6)).collect();
    let k = eval(&plate, &v, true).tangent;
    let scale = max_abs(&k);
    let step = 1e-6;
    let mut worst: f64 = 0.0;
    for j in 0..24 {
        let mut vp = v.clone();
        let mut vm = v.clone();
        vp[j] += step;
        vm[j] -= step;
        let rp = eval(&plate, &vp, false).residual;
        let rm = eval(&plate, &vm, false).residual;
        for i in 0..24 {
            let fd = (rp[i] - rm[i]) / (2.0 * step);
            worst = worst.max((fd - k[i * 24 + j]).abs() / scale);
        }
    }
    assert!(worst < 1e-6, "{kin:?}: tangent differs from finite differences by {worst:e} (relative to max |K|)");
}

#[test]
fn nonlinear_tangent_matches_finite_differences() {
    for seed in [1, 2, 3] {
        check_tangent(Kinematics::Nonlinear, seed);
    }
}

#[test]
fn linear_tangent_matches_finite_differences() {
    check_tangent(Kinematics::Linear, 4);
}

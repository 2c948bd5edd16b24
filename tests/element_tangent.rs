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
    let worst = tangent_fd_error(&plate, &v);
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

/// The preconditioner matrix P of the element (the tangent without the one-way coupling of T33 to
/// the in-plane strains): symmetric, and differing from the tangent only in that coupling, a sum of
/// one outer product per Gauss point (rank <= 4); a plate with nu = 0 has no coupling and no P.
#[test]
fn preconditioner_is_the_symmetric_tangent_without_the_thickness_coupling() {
    use stamp::element::Element;
    let mesh = distorted_element();
    for kin in [Kinematics::Nonlinear, Kinematics::Linear] {
        let plate = plate(&mesh, 0.15, kin);
        assert!(plate.has_preconditioner());
        let mut rng = Lcg(9);
        let v: Vec<f64> = (0..24).map(|_| rng.range(-0.6, 0.6)).collect();
        let out = eval(&plate, &v, true);
        let (k, p) = (&out.tangent, &out.preconditioner);
        let scale = max_abs(k);
        // the tangent alone (no P asked for) is the same matrix
        let mut alone = stamp::element::LocalSystem::new(24);
        plate.evaluate(0, &v, &mut plate.new_workspace(), &mut alone, true);
        assert!(alone.preconditioner.is_empty());
        let same = k.iter().zip(&alone.tangent).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(same < 1e-13 * scale, "{kin:?}: {same:e}");
        let asym = (0..24).flat_map(|i| (0..24).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max((p[i * 24 + j] - p[j * 24 + i]).abs()));
        assert!(asym < 1e-12 * scale, "{kin:?}: P not symmetric: {asym:e}");
        // K - P: a non-zero matrix of rank at most 4 (singular values beyond the 4th vanish)
        let diff = nalgebra::DMatrix::from_fn(24, 24, |i, j| k[i * 24 + j] - p[i * 24 + j]);
        let sv = diff.singular_values();
        let mut sv: Vec<f64> = sv.iter().copied().collect();
        sv.sort_by(|a, b| b.total_cmp(a));
        assert!(sv[0] > 1e-3 * scale, "{kin:?}: K - P vanishes: {sv:?}");
        assert!(sv[4] < 1e-10 * scale, "{kin:?}: K - P has rank > 4: {sv:?}");
        // and K - P is what makes K non-symmetric: K^T - K = P^T + (K - P)^T - P - (K - P)
        let kt_asym = (0..24).flat_map(|i| (0..24).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max((k[i * 24 + j] - k[j * 24 + i]).abs()));
        assert!(kt_asym > 1e-3 * scale, "{kin:?}: the tangent should not be symmetric");
    }
    let section = stamp_elements::Section::homogeneous(0.15, stamp_elements::Isotropic::new(2.0e5, 0.0).unwrap()).unwrap();
    let plate = stamp_elements::PlateElements::new(&mesh, section, Kinematics::Nonlinear).unwrap();
    assert!(!plate.has_preconditioner());
}

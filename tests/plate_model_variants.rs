//! The plate's model choices beside the paper's (SPEC section 2): the transverse shear factor k
//! (`Section::shear_factor`) and the transverse normal stress in the in-plane law
//! (`Section::normal_stress`): the stiffness against closed forms, the tangent against central
//! finite differences, bad values refused.

mod common;
use common::*;
use stamp_elements::material::{idx, NSTRAIN};
use stamp_elements::{Isotropic, Kinematics, NormalStress, PlateElements, Section};

const E: f64 = 2.0e5;
const NU: f64 = 0.3;
const H: f64 = 0.15;

fn section(normal: NormalStress) -> Section {
    let mut s = Section::homogeneous(H, Isotropic::new(E, NU).unwrap()).unwrap();
    s.normal_stress = normal;
    s
}

fn resultants(s: &Section, strain: &[f64; NSTRAIN]) -> [f64; NSTRAIN] {
    let d = s.stiffness();
    let mut t = [0.0; NSTRAIN];
    for r in 0..NSTRAIN {
        t[r] = (0..NSTRAIN).map(|c| d[r][c] * strain[c]).sum();
    }
    t
}

/// A strain (E11, E22, E33) constant through the thickness: E11- = E11+ = a, E22- = E22+ = b.
fn homogeneous_strain(a: f64, b: f64, c: f64) -> [f64; NSTRAIN] {
    let mut e = [0.0; NSTRAIN];
    for p in 0..2 {
        e[idx::E11[p]] = a;
        e[idx::E22[p]] = b;
    }
    e[idx::E33] = c;
    e
}

#[test]
fn mean_normal_stress_gives_the_3d_law_for_a_strain_constant_through_the_thickness() {
    let (a, b, c) = (1.3e-3, -0.4e-3, -0.9e-3);
    let lam = E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU));
    let g = E / (2.0 * (1.0 + NU));
    // 3D Hooke: S11 = (lam + 2G) a + lam b + lam c, S33 = lam (a + b) + (lam + 2G) c
    let s11 = (lam + 2.0 * g) * a + lam * b + lam * c;
    let s22 = lam * a + (lam + 2.0 * g) * b + lam * c;
    let s33 = lam * (a + b) + (lam + 2.0 * g) * c;
    let t = resultants(&section(NormalStress::Mean), &homogeneous_strain(a, b, c));
    // T- + T+ = int S dx3 = h S for a constant S
    for (got, want, name) in [
        (t[idx::E11[0]] + t[idx::E11[1]], H * s11, "T11"),
        (t[idx::E22[0]] + t[idx::E22[1]], H * s22, "T22"),
        (t[idx::E33], H * s33, "T33"),
    ] {
        assert!((got - want).abs() <= 1e-12 * want.abs(), "mean: {name} = {got}, 3D law {want}");
    }
    // the paper's law: the plane-stress constants alone, whatever S33
    let q11 = E / (1.0 - NU * NU);
    let t = resultants(&section(NormalStress::Dropped), &homogeneous_strain(a, b, c));
    let want = H * (q11 * a + NU * q11 * b);
    let got = t[idx::E11[0]] + t[idx::E11[1]];
    assert!((got - want).abs() <= 1e-12 * want.abs(), "dropped: T11 = {got}, plane stress {want}");
}

#[test]
fn mean_normal_stress_changes_nothing_without_a_mean_transverse_normal_stress() {
    let (dropped, mean) = (section(NormalStress::Dropped), section(NormalStress::Mean));
    // pure bending: E11 = -+k on the faces, E33 = 0: T33 = 0, no Poisson locking
    let mut bend = [0.0; NSTRAIN];
    bend[idx::E11[0]] = -2e-3;
    bend[idx::E11[1]] = 2e-3;
    bend[idx::E22[0]] = -0.5e-3;
    bend[idx::E22[1]] = 0.5e-3;
    // a membrane state with S33 = 0: E33 = -lam / (lam + 2G) (E11 + E22)
    let lam = E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU));
    let g = E / (2.0 * (1.0 + NU));
    let membrane = homogeneous_strain(1e-3, 0.2e-3, -lam / (lam + 2.0 * g) * 1.2e-3);
    for (name, e) in [("bending", bend), ("membrane", membrane)] {
        let (td, tm) = (resultants(&dropped, &e), resultants(&mean, &e));
        assert!(tm[idx::E33].abs() < 1e-9 * tm[idx::E11[1]].abs(), "{name}: T33 = {}", tm[idx::E33]);
        for r in 0..NSTRAIN {
            assert!((td[r] - tm[r]).abs() <= 1e-9 * td[r].abs().max(1.0), "{name}: component {r}: {} vs {}", td[r], tm[r]);
        }
    }
}

#[test]
fn shear_factor_scales_the_transverse_shear_stiffness_only() {
    let d1 = section(NormalStress::Dropped).stiffness();
    let d56 = section(NormalStress::Dropped).with_shear_factor(5.0 / 6.0).unwrap().stiffness();
    let shear: Vec<usize> = idx::E13.iter().chain(&idx::E23).copied().collect();
    for r in 0..NSTRAIN {
        for c in 0..NSTRAIN {
            let want = if shear.contains(&r) && shear.contains(&c) { d1[r][c] * 5.0 / 6.0 } else { d1[r][c] };
            assert!((d56[r][c] - want).abs() <= 1e-12 * want.abs(), "D[{r}][{c}] = {}, want {want}", d56[r][c]);
        }
    }
    // G h for a constant shear strain: T13- + T13+ = k G h 2E13
    let g = E / (2.0 * (1.0 + NU));
    let t = d56[idx::E13[0]][idx::E13[0]] + d56[idx::E13[0]][idx::E13[1]] + d56[idx::E13[1]][idx::E13[0]] + d56[idx::E13[1]][idx::E13[1]];
    assert!((t - 5.0 / 6.0 * g * H).abs() < 1e-9 * g * H, "k G h = {t}");
    for bad in [0.0, -0.5, 1.5, f64::NAN] {
        let err = section(NormalStress::Dropped).with_shear_factor(bad).unwrap_err().to_string();
        assert!(err.contains("shear factor") && err.contains("(0, 1]"), "k = {bad}: {err}");
    }
}

/// The element's tangent with S_33 in the in-plane law (a D that is not symmetric in its in-plane
/// rows either) is still the exact derivative; the element then leaves the preconditioner to the
/// solver.
#[test]
fn mean_normal_stress_tangent_matches_finite_differences() {
    use stamp::element::Element;
    let mesh = distorted_element();
    for (kin, seed) in [(Kinematics::Nonlinear, 11), (Kinematics::Nonlinear, 12), (Kinematics::Linear, 13)] {
        let s = section(NormalStress::Mean).with_shear_factor(5.0 / 6.0).unwrap();
        let plate = PlateElements::new(&mesh, s, kin).unwrap();
        assert!(!plate.has_preconditioner());
        let mut rng = Lcg(seed);
        let v: Vec<f64> = (0..24).map(|_| rng.range(-0.6, 0.6)).collect();
        let worst = tangent_fd_error(&plate, &v);
        assert!(worst < 1e-6, "{kin:?}: tangent differs from finite differences by {worst:e}");
    }
}

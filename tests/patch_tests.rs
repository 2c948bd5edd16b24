//! Patch tests on a distorted five-element mesh: the boundary nodes get the nodal values of an exact
//! solution, the interior nodes are solved for and must reproduce it exactly.
//! - Constant membrane strain: any homogeneous deformation v(X) = G X, X = (x1, x2, delta), with the
//!   geometrically nonlinear and the linear element (Green-Lagrange strain is constant for it too).
//! - Constant curvature: w = -(k11 x1^2 + 2 k12 x1 x2 + k22 x2^2)/2, v_a = -delta w_,a (linear
//!   element): zero transverse shear, constant moments.

mod common;
use common::*;
use stamp::mesh::QuadMesh;
use stamp_elements::Kinematics;

fn five_element_patch() -> QuadMesh {
    let coords = vec![
        [0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], // outer corners 0..3
        [0.18, 0.22], [0.72, 0.12], [0.83, 0.74], [0.29, 0.66], // interior 4..7
    ];
    let cells = vec![[4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
    QuadMesh::new(coords, cells).unwrap()
}

/// Solve the patch with the four outer nodes prescribed to `exact(node, face) -> [v1, v2, v3]`;
/// return the largest error at the interior nodes relative to the largest exact value.
fn patch(kin: Kinematics, h: f64, exact: &dyn Fn([f64; 2], f64) -> [f64; 3]) -> f64 {
    patch_error(&five_element_patch(), &[0, 1, 2, 3], kin, h, exact)
}

fn homogeneous(g: [[f64; 3]; 3]) -> impl Fn([f64; 2], f64) -> [f64; 3] {
    move |x, z| {
        let r = [x[0], x[1], z];
        [0, 1, 2].map(|i| (0..3).map(|j| g[i][j] * r[j]).sum())
    }
}

/// The homogeneous in-plane deformation with gradient `a` (2 x 2) plus the through-thickness stretch
/// that makes the transverse normal force T33 vanish (a constant state needs no face tractions):
/// T33 = lambda h (E11 + E22) + (lambda + 2G) h E33 = 0 with E33 = g + g^2/2 (Green-Lagrange) or g.
fn membrane_state(a: [[f64; 2]; 2], nonlinear: bool) -> [[f64; 3]; 3] {
    let m = stamp_elements::Isotropic::new(2.0e5, 0.3).unwrap();
    let (lam, mu) = (m.lame_lambda(), m.shear_modulus());
    let e = |i: usize| {
        let lin = a[i][i];
        if nonlinear { lin + 0.5 * (a[0][i] * a[0][i] + a[1][i] * a[1][i]) } else { lin }
    };
    let e33 = -lam * (e(0) + e(1)) / (lam + 2.0 * mu);
    let g = if nonlinear { -1.0 + (1.0 + 2.0 * e33).sqrt() } else { e33 };
    [[a[0][0], a[0][1], 0.0], [a[1][0], a[1][1], 0.0], [0.0, 0.0, g]]
}

#[test]
fn constant_membrane_strain_is_reproduced_exactly() {
    let small = [[0.02, -0.013], [0.007, -0.011]];
    for (kin, nl) in [(Kinematics::Linear, false), (Kinematics::Nonlinear, true)] {
        let e = patch(kin, 0.05, &homogeneous(membrane_state(small, nl)));
        assert!(e < 1e-10, "{kin:?}: membrane patch error {e:e}");
    }
    // a large homogeneous deformation (stretch and shear of 20 %) with the nonlinear element
    let big = [[0.2, 0.1], [-0.05, 0.15]];
    let e = patch(Kinematics::Nonlinear, 0.05, &homogeneous(membrane_state(big, true)));
    assert!(e < 1e-10, "large membrane patch error {e:e}");
    // the state without the compatible thickness stretch is not an equilibrium: the test can fail
    let mut wrong = membrane_state(small, false);
    wrong[2][2] = 0.0;
    assert!(patch(Kinematics::Linear, 0.05, &homogeneous(wrong)) > 1e-4);
}

#[test]
fn constant_curvature_is_reproduced_exactly() {
    let (k11, k12, k22) = (0.3, -0.12, 0.2);
    let exact = move |x: [f64; 2], z: f64| {
        let w = -(k11 * x[0] * x[0] + 2.0 * k12 * x[0] * x[1] + k22 * x[1] * x[1]) / 2.0;
        let w1 = -(k11 * x[0] + k12 * x[1]);
        let w2 = -(k12 * x[0] + k22 * x[1]);
        [-z * w1, -z * w2, w]
    };
    for h in [0.1, 0.001] {
        let e = patch(Kinematics::Linear, h, &exact);
        assert!(e < 1e-8, "h = {h}: bending patch error {e:e}");
    }
}

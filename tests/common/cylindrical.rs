//! The exact 3D elasticity solution of a laminate in cylindrical bending (N. J. Pagano, "Exact
//! solutions for composite laminates in cylindrical bending", J. Compos. Mater. 3 (1969) 398-411;
//! plies at any angle: N. J. Pagano, "Influence of shear coupling in cylindrical bending of
//! anisotropic laminates", J. Compos. Mater. 4 (1970) 330-343): a plate infinite in x2, simply
//! supported at x1 = 0 and a (w = 0, s11 = s12 = 0), under s33 = q0 sin(p x1), p = pi/a, on its top
//! face. Every field depends on x1 and x3 only; with each ply's full stiffness in the plate's axes
//! (monoclinic about x3: C16, C26, C36, C45 may be non-zero)
//!
//!   u1 = U(z) cos px,  u2 = V(z) cos px,  u3 = W(z) sin px,
//!   s13 = X(z) cos px,  s23 = Y(z) cos px,  s33 = Z(z) sin px,
//!
//! the strains are e11 = -pU, e22 = 0, e33 = W', g23 = V', g13 = U' + pW, g12 = -pV (times sin, sin,
//! sin, cos, cos, sin), and the law and equilibrium give the constant-coefficient system S' = A S
//! for S = [U, V, W, X, Y, Z] in each ply:
//!
//!   W' = (Z + C13 p U + C36 p V) / C33,
//!   [V', U' + pW] = [[C44, C45], [C45, C55]]^-1 [Y, X],
//!   X' = -p s11,  Y' = -p s12,  Z' = p X,
//!
//! with s11 = -C11 p U - C16 p V + C13 W', s12 = -C16 p U - C66 p V + C36 W' (the amplitudes of
//! sin px). S is continuous at the interfaces; the free bottom face (X = Y = Z = 0) and the loaded
//! top face (X = Y = 0, Z = q0) fix U, V, W at the bottom (the transfer matrix of the square plate,
//! tests/common/pagano.rs). For a ply at 0 or 90 degrees V = Y = 0 (Pagano 1969); at other angles
//! u2 and s23 couple in (Pagano 1970).

use super::pagano::{Layer, Stiffness, ThroughThickness};
use nalgebra::Matrix6;

/// The exact solution for the load s33 = q0 sin(pi x1 / a) on the top face (upwards for q0 > 0),
/// layers from the bottom up, the mid-plane at z = 0.
pub struct Cylindrical {
    pub layers: Vec<Layer>,
    pub a: f64,
    pub q0: f64,
    /// The state through the layers.
    pub stack: ThroughThickness,
}

/// The rows over S of W' and of the in-plane stresses [s11, s22, s12] (amplitudes of sin px).
fn rows(c: &Stiffness, p: f64) -> ([f64; 6], [[f64; 6]; 3]) {
    let wp = [c[0][2] * p / c[2][2], c[2][5] * p / c[2][2], 0.0, 0.0, 0.0, 1.0 / c[2][2]];
    // strains e11 = -p U, e22 = 0, e33 = W', g12 = -p V
    let s = |i: usize| -> [f64; 6] {
        let mut r = [-c[i][0] * p, -c[i][5] * p, 0.0, 0.0, 0.0, 0.0];
        for j in 0..6 {
            r[j] += c[i][2] * wp[j];
        }
        r
    };
    (wp, [s(0), s(1), s(5)])
}

fn system(c: &Stiffness, p: f64) -> Matrix6<f64> {
    let (wp, [s11, _, s12]) = rows(c, p);
    let (c44, c45, c55) = (c[3][3], c[3][4], c[4][4]);
    let det = c44 * c55 - c45 * c45;
    let mut m = Matrix6::zeros();
    // U' = (C44 X - C45 Y) / det - p W,  V' = (C55 Y - C45 X) / det
    m[(0, 3)] = c44 / det;
    m[(0, 4)] = -c45 / det;
    m[(0, 2)] = -p;
    m[(1, 4)] = c55 / det;
    m[(1, 3)] = -c45 / det;
    for j in 0..6 {
        m[(2, j)] = wp[j];
        m[(3, j)] = -p * s11[j];
        m[(4, j)] = -p * s12[j];
    }
    m[(5, 3)] = p;
    m
}

impl Cylindrical {
    pub fn new(layers: Vec<Layer>, a: f64, q0: f64) -> Cylindrical {
        let p = std::f64::consts::PI / a;
        let stack = ThroughThickness::new(&layers, layers.iter().map(|l| system(&l.c, p)).collect(), q0, a);
        Cylindrical { layers, a, q0, stack }
    }

    /// The displacement [u1, u2, u3] at (x, z).
    pub fn displacement(&self, x: f64, z: f64) -> [f64; 3] {
        let s = self.stack.state(self.stack.layer_at(z), z);
        let px = std::f64::consts::PI * x / self.a;
        [s[0] * px.cos(), s[1] * px.cos(), s[2] * px.sin()]
    }

    /// The stresses [s11, s22, s33, s23, s13, s12] at (x, z) in layer k.
    pub fn stress(&self, k: usize, x: f64, z: f64) -> [f64; 6] {
        let p = std::f64::consts::PI / self.a;
        let s = self.stack.state(k, z);
        let (_, r) = rows(&self.layers[k].c, p);
        let amp = |row: &[f64; 6]| (0..6).map(|j| row[j] * s[j]).sum::<f64>();
        let (sn, cs) = ((p * x).sin(), (p * x).cos());
        [amp(&r[0]) * sn, amp(&r[1]) * sn, s[5] * sn, s[4] * cs, s[3] * cs, amp(&r[2]) * sn]
    }
}

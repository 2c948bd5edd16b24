//! Displacement-based Green-Lagrange strains as exact quadratic forms of the element's nodal
//! displacements (paper eqs. 1.4-1.5, 1.9).
//!
//! Every strain of the plate is a dot product of two vectors that are affine in the nodal face
//! displacements: the face tangents g_a = t_a + v_,a, the transverse fibre g_3 = e3 + beta with
//! beta = (v+ - v-)/h, and the covariant tangents g_xi = X_,xi + v_,xi. So 2 E_ij = g_i . g_j -
//! G_i . G_j (eq. 1.5 in vector form), which vanishes for any rigid motion because a rotation keeps
//! dot products (eqs. 1.6-1.8). A [`Sample`] stores the value, gradient and (constant) Hessian of
//! one such strain; the Hessian is a scalar P x P matrix over the (node, surface) pairs times the
//! 3 x 3 identity. P = 8 (4 nodes x 2 faces) for the paper's plate; the plate of N surfaces
//! ([`crate::multi_surface`]) uses the same types with P = 4 N.

/// Element dofs: 4 nodes x 2 faces x 3 components; local dof 3k + i is component i of the
/// displacement of (node, face) pair k = 2 node + face (face 0 = S-, 1 = S+).
pub const NDOF: usize = 24;
/// (node, face) pairs.
pub const NPAIR: usize = 8;

/// A vector affine in the nodal surface displacements: g = g0 + sum_k c_k v_k, k over the P
/// (node, surface) pairs.
#[derive(Debug, Clone, Copy)]
pub struct Affine<const P: usize = NPAIR> {
    pub g0: [f64; 3],
    pub g: [f64; 3],
    pub c: [f64; P],
}

impl<const P: usize> Affine<P> {
    /// Build from the reference vector and the coefficients, evaluating g at `v`.
    #[inline(always)]
    pub fn new(g0: [f64; 3], c: [f64; P], v: &[f64]) -> Self {
        let mut g = g0;
        for k in 0..P {
            if c[k] != 0.0 {
                for i in 0..3 {
                    g[i] += c[k] * v[3 * k + i];
                }
            }
        }
        Affine { g0, g, c }
    }
}

/// One strain: value, gradient with respect to the D = 3 P element dofs, and its (constant)
/// Hessian in factored form: s (a b^T + b a^T) over the (node, surface) pairs, times the 3 x 3
/// identity.
#[derive(Debug, Clone, Copy)]
pub struct Sample<const P: usize = NPAIR, const D: usize = NDOF> {
    pub val: f64,
    pub grad: [f64; D],
    /// Scale s of the Hessian (0 for a linear strain).
    pub scale: f64,
    pub a: [f64; P],
    pub b: [f64; P],
}

impl<const P: usize, const D: usize> Default for Sample<P, D> {
    fn default() -> Self {
        assert!(D == 3 * P, "a strain sample has three dofs per (node, surface) pair");
        Sample { val: 0.0, grad: [0.0; D], scale: 0.0, a: [0.0; P], b: [0.0; P] }
    }
}

#[inline(always)]
fn dot(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl<const P: usize, const D: usize> Sample<P, D> {
    /// The full (Green-Lagrange) strain s (gA . gB - g0A . g0B).
    #[inline(always)]
    pub fn quadratic(&mut self, s: f64, a: &Affine<P>, b: &Affine<P>) {
        self.val = s * (dot(&a.g, &b.g) - dot(&a.g0, &b.g0));
        for k in 0..P {
            for i in 0..3 {
                self.grad[3 * k + i] = s * (a.c[k] * b.g[i] + b.c[k] * a.g[i]);
            }
        }
        self.scale = s;
        self.a = a.c;
        self.b = b.c;
    }

    /// The strain s (gA . gB - g0A . g0B): [`quadratic`](Self::quadratic) if `full` (geometrically
    /// nonlinear), else [`linear`](Self::linear).
    #[inline(always)]
    pub fn set(&mut self, full: bool, s: f64, a: &Affine<P>, b: &Affine<P>) {
        if full {
            self.quadratic(s, a, b)
        } else {
            self.linear(s, a, b)
        }
    }

    /// The part of the strain's change under the increment `dv` of the element dofs that is
    /// quadratic in it: s (C_a dv) . (C_b dv), with C_a dv = sum_k a_k dv_k over the (node,
    /// surface) pairs. A Green-Lagrange strain is exactly quadratic, so its value at v less this
    /// remainder of dv = v - v0 is its linearisation about v0, E(v0) + dE/dv(v0) dv (zero for a
    /// linear strain, whose scale is 0).
    #[inline(always)]
    pub fn remainder(&self, dv: &[f64]) -> f64 {
        if self.scale == 0.0 {
            return 0.0;
        }
        let (mut da, mut db) = ([0.0; 3], [0.0; 3]);
        for k in 0..P {
            for i in 0..3 {
                da[i] += self.a[k] * dv[3 * k + i];
                db[i] += self.b[k] * dv[3 * k + i];
            }
        }
        self.scale * dot(&da, &db)
    }

    /// Hessian coefficient (k, l) over the (node, surface) pairs.
    pub fn hessian(&self, k: usize, l: usize) -> f64 {
        self.scale * (self.a[k] * self.b[l] + self.b[k] * self.a[l])
    }

    /// The part linear in the displacements, s (g0A . dB + g0B . dA) with d = g - g0: the strain of
    /// the geometrically linear theory (eta = 0). Its Hessian is zero.
    #[inline(always)]
    pub fn linear(&mut self, s: f64, a: &Affine<P>, b: &Affine<P>) {
        let da = [a.g[0] - a.g0[0], a.g[1] - a.g0[1], a.g[2] - a.g0[2]];
        let db = [b.g[0] - b.g0[0], b.g[1] - b.g0[1], b.g[2] - b.g0[2]];
        self.val = s * (dot(&a.g0, &db) + dot(&b.g0, &da));
        for k in 0..P {
            for i in 0..3 {
                self.grad[3 * k + i] = s * (a.c[k] * b.g0[i] + b.c[k] * a.g0[i]);
            }
        }
        self.scale = 0.0;
    }
}

/// a . (b x c)
#[inline(always)]
pub fn triple(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// y += a x over the element dofs (fixed size and distinct borrows: vectorised, no bounds checks).
#[inline(always)]
pub fn axpy<const D: usize>(y: &mut [f64; D], a: f64, x: &[f64; D]) {
    for (yi, &xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

/// m += (X + X^T) (x) I3: the geometric stiffness sum_s mu_s scale_s (a_s b_s^T + b_s a_s^T) (x) I3
/// of the samples, gathered in X = sum_s mu_s scale_s a_s b_s^T over the P (node, surface) pairs,
/// added into a row-major 3P x 3P matrix.
#[inline(always)]
pub fn add_geometric_stiffness<const P: usize>(x: &[[f64; P]; P], m: &mut [f64]) {
    let d = 3 * P;
    for k in 0..P {
        for l in 0..P {
            let val = x[k][l] + x[l][k];
            for i in 0..3 {
                m[(3 * k + i) * d + 3 * l + i] += val;
            }
        }
    }
}

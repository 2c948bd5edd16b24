//! The logarithmic (Hencky) strain of a Green-Lagrange strain and its first two derivatives, the
//! geometric pre- and post-processing of Miehe, Apel & Lambrecht (2002) that turns a small-strain
//! plasticity model into a finite-strain one:
//!
//!   H = 1/2 ln C,  C = I + 2 E;   S = P^T T,   dS/dE = P^T (dT/dH) P + T : d2H/dE2,
//!
//! with P = dH/dE. In the eigenbasis C = Q diag(c) Q^T the derivatives are divided differences of
//! ln (Daleckii-Krein): `dH[dE]^ = F1 o dE^` with `F1_ij = ln[c_i, c_j]`, and
//! T : d2H[A, B] = 2 sum_ijk T^_ij ln[c_i, c_k, c_j] (A^_ik B^_kj + B^_ik A^_kj), ^ the components in
//! the eigenbasis. H equals E to first order, so at small strains the law is the small-strain one.

use nalgebra::{Matrix3, SymmetricEigen};

/// Voigt index pairs [11, 22, 33, 23, 13, 12].
const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)];

/// ln[a, b] = (ln a - ln b) / (a - b), 1 / a when a = b.
fn ln1(a: f64, b: f64) -> f64 {
    if a == b {
        1.0 / a
    } else {
        let x = (a - b) / b;
        if x.abs() < 1e-300 {
            1.0 / b
        } else {
            x.ln_1p() / (a - b)
        }
    }
}

/// ln[a, b, c], the second divided difference (symmetric in its arguments): near coincidence its
/// Taylor expansion about the mean, -1/(2 m^2) + (a - m)^2 + ... terms.
fn ln2(a: f64, b: f64, c: f64) -> f64 {
    let mut v = [a, b, c];
    v.sort_by(|x, y| y.partial_cmp(x).unwrap());
    let [hi, mid, lo] = v;
    if hi - lo > 1e-4 * hi {
        (ln1(hi, mid) - ln1(mid, lo)) / (hi - lo)
    } else {
        // f[x0, x1, x2] of f = ln about m: f''/2 + f'''/6 s1 + f''''/24 s2 + f'''''/120 s3, with
        // s_k the complete homogeneous symmetric polynomials of the deviations d_i = x_i - m
        // (s1 = 0 at the mean)
        let m = (a + b + c) / 3.0;
        let d = [a - m, b - m, c - m];
        let s2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] + d[0] * d[1] + d[1] * d[2] + d[0] * d[2];
        let s3: f64 = {
            // h3 of three variables
            let mut s = 0.0;
            for i in 0..3 {
                for j in i..3 {
                    for k in j..3 {
                        s += d[i] * d[j] * d[k];
                    }
                }
            }
            s
        };
        // f'' = -1/m^2, f'''' = -6/m^4, f''''' = 24/m^5
        -0.5 / (m * m) - 0.25 * s2 / m.powi(4) + 0.2 * s3 / m.powi(5)
    }
}

/// The Hencky strain of a Green-Lagrange strain and its derivatives.
#[derive(Debug, Clone, Copy)]
pub struct Hencky {
    /// H (Voigt, engineering shears).
    pub strain: [f64; 6],
    /// P = dH/dE, both Voigt with engineering shears.
    pub p: [[f64; 6]; 6],
    q: Matrix3<f64>,
    c: [f64; 3],
    /// The unit strain directions of the Voigt components in the eigenbasis.
    units: [Matrix3<f64>; 6],
}

fn tensor(e: &[f64; 6]) -> Matrix3<f64> {
    Matrix3::new(e[0], 0.5 * e[5], 0.5 * e[4], 0.5 * e[5], e[1], 0.5 * e[3], 0.5 * e[4], 0.5 * e[3], e[2])
}

fn voigt_strain(m: &Matrix3<f64>) -> [f64; 6] {
    std::array::from_fn(|a| {
        let (i, j) = PAIRS[a];
        if i == j {
            m[(i, j)]
        } else {
            m[(i, j)] + m[(j, i)]
        }
    })
}

fn stress_tensor(s: &[f64; 6]) -> Matrix3<f64> {
    Matrix3::new(s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2])
}

impl Hencky {
    /// H and P of the Green-Lagrange strain `e` (Voigt, engineering shears). None when
    /// C = I + 2E is not positive definite (a state turned inside out).
    pub fn new(e: &[f64; 6]) -> Option<Hencky> {
        let cm = Matrix3::identity() + tensor(e) * 2.0;
        let eig = SymmetricEigen::new(cm);
        let c: [f64; 3] = std::array::from_fn(|i| eig.eigenvalues[i]);
        if c.iter().any(|&x| !(x > 0.0)) {
            return None;
        }
        let q = eig.eigenvectors;
        let hd = Matrix3::from_diagonal(&nalgebra::Vector3::from_fn(|i, _| 0.5 * c[i].ln()));
        let strain = voigt_strain(&(q * hd * q.transpose()));
        let units: [Matrix3<f64>; 6] = std::array::from_fn(|b| {
            let mut u = [0.0; 6];
            u[b] = 1.0;
            q.transpose() * tensor(&u) * q
        });
        let f1 = Matrix3::from_fn(|i, j| ln1(c[i], c[j]));
        let mut p = [[0.0; 6]; 6];
        for b in 0..6 {
            let dh = q * units[b].component_mul(&f1) * q.transpose();
            let col = voigt_strain(&dh);
            for a in 0..6 {
                p[a][b] = col[a];
            }
        }
        Some(Hencky { strain, p, q, c, units })
    }

    /// S = P^T T for the stress `t` conjugate to H.
    pub fn stress(&self, t: &[f64; 6]) -> [f64; 6] {
        std::array::from_fn(|a| (0..6).map(|b| self.p[b][a] * t[b]).sum())
    }

    /// dS/dE = P^T `dt_dh` P + T : d2H/dE2 for the stress `t` and its tangent `dt_dh`.
    pub fn tangent(&self, t: &[f64; 6], dt_dh: &[[f64; 6]; 6]) -> [[f64; 6]; 6] {
        let p = &self.p;
        let mut cp = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                cp[i][j] = (0..6).map(|k| dt_dh[i][k] * p[k][j]).sum();
            }
        }
        let th = self.q.transpose() * stress_tensor(t) * self.q;
        let mut f2 = [[[0.0; 3]; 3]; 3];
        for (i, fi) in f2.iter_mut().enumerate() {
            for (k, fik) in fi.iter_mut().enumerate() {
                for (j, x) in fik.iter_mut().enumerate() {
                    *x = ln2(self.c[i], self.c[k], self.c[j]);
                }
            }
        }
        // W_ik,kj: 2 sum_ij T^_ij f2[i][k][j] per (i, k, j)
        let mut k6 = [[0.0; 6]; 6];
        for a in 0..6 {
            for b in a..6 {
                let (ua, ub) = (&self.units[a], &self.units[b]);
                let mut g = 0.0;
                for i in 0..3 {
                    for j in 0..3 {
                        let tij = th[(i, j)];
                        if tij == 0.0 {
                            continue;
                        }
                        for k in 0..3 {
                            g += tij * f2[i][k][j] * (ua[(i, k)] * ub[(k, j)] + ub[(i, k)] * ua[(k, j)]);
                        }
                    }
                }
                k6[a][b] = 2.0 * g;
                k6[b][a] = 2.0 * g;
            }
        }
        std::array::from_fn(|a| std::array::from_fn(|b| (0..6).map(|k| p[k][a] * cp[k][b]).sum::<f64>() + k6[a][b]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// H of a stretch along x1 is ln(stretch); H turned with the strain; P and the second
    /// derivative against central differences of H and of S = P^T T for a fixed T.
    #[test]
    fn hencky_strain_and_its_derivatives() {
        let l: f64 = 1.3;
        let h = Hencky::new(&[0.5 * (l * l - 1.0), 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        assert!((h.strain[0] - l.ln()).abs() < 1e-14 && h.strain[1].abs() < 1e-14);
        let t = [120.0, -40.0, 15.0, 30.0, -22.0, 55.0];
        for e in [[0.2, -0.05, 0.08, 0.03, -0.1, 0.12], [0.1, 0.1, 0.1, 0.0, 0.0, 0.0], [0.0; 6], [0.1, 0.1, -0.05, 0.0, 0.0, 1e-7]] {
            let h = Hencky::new(&e).unwrap();
            let k = h.tangent(&t, &[[0.0; 6]; 6]);
            for b in 0..6 {
                let d = 1e-6;
                let (mut ep, mut em) = (e, e);
                ep[b] += d;
                em[b] -= d;
                let (hp, hm) = (Hencky::new(&ep).unwrap(), Hencky::new(&em).unwrap());
                for a in 0..6 {
                    let fd = (hp.strain[a] - hm.strain[a]) / (2.0 * d);
                    assert!((fd - h.p[a][b]).abs() < 1e-8, "e = {e:?}: P[{a}][{b}] = {} against {fd}", h.p[a][b]);
                    let fd = (hp.stress(&t)[a] - hm.stress(&t)[a]) / (2.0 * d);
                    assert!((fd - k[a][b]).abs() < 1e-6 * 120.0, "e = {e:?}: G[{a}][{b}] = {} against {fd}", k[a][b]);
                }
            }
        }
    }
}

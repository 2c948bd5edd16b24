//! The 3D linear elastic law of a ply, C in S = C E (Voigt order [11, 22, 33, 23, 13, 12], shear
//! strains engineering 2E_ij), isotropic or orthotropic in the ply's axes (1 along the fibres, 3 the
//! plate normal), and its rotation about the normal by the ply angle. With Green-Lagrange strains E
//! and second Piola-Kirchhoff stresses S it is the anisotropic Saint Venant-Kirchhoff law; the
//! material axes are those of the reference configuration.
//!
//! Orthotropic compliance in the ply's axes (e.g. R. M. Jones, Mechanics of Composite Materials,
//! eq. 2.17): E_11 = S_11/E1 - nu21 S_22/E2 - nu31 S_33/E3, ..., with nu_ji / E_j = nu_ij / E_i,
//! 2E_23 = S_23/G23, 2E_13 = S_13/G13, 2E_12 = S_12/G12; C is its inverse.

use crate::material::Isotropic;
use stamp::{Result, StampError};

/// A 6 x 6 elastic stiffness, Voigt order [11, 22, 33, 23, 13, 12], engineering shear strains.
pub type Stiffness = [[f64; 6]; 6];

/// An orthotropic material given by its engineering constants in the ply's axes.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Orthotropic {
    /// E1, E2, E3.
    pub young: [f64; 3],
    /// G12, G13, G23.
    pub shear: [f64; 3],
    /// nu12, nu13, nu23 (nu_ij: contraction along j under a stress along i, over the strain along i).
    pub poisson: [f64; 3],
}

impl Orthotropic {
    /// A validated material.
    pub fn new(young: [f64; 3], shear: [f64; 3], poisson: [f64; 3]) -> Result<Self> {
        let m = Orthotropic { young, shear, poisson };
        m.validate()?;
        Ok(m)
    }

    /// The compliance of the normal strains, S_ij with E_ii = sum_j S_ij S_jj (symmetric).
    fn normal_compliance(&self) -> [[f64; 3]; 3] {
        let [e1, e2, e3] = self.young;
        let [n12, n13, n23] = self.poisson;
        [[1.0 / e1, -n12 / e1, -n13 / e1], [-n12 / e1, 1.0 / e2, -n23 / e2], [-n13 / e1, -n23 / e2, 1.0 / e3]]
    }

    /// Moduli positive and finite, the compliance positive definite (a stable material: the
    /// leading minors 1 - nu12 nu21 > 0 and det > 0).
    pub fn validate(&self) -> Result<()> {
        for (name, v) in [("E", self.young), ("G", self.shear)] {
            if let Some(x) = v.iter().find(|x| !(x.is_finite() && **x > 0.0)) {
                return Err(StampError::Material(format!("every modulus {name} must be positive and finite, got {x}")));
            }
        }
        if let Some(x) = self.poisson.iter().find(|x| !x.is_finite()) {
            return Err(StampError::Material(format!("the Poisson ratios must be finite, got {x}")));
        }
        // scaled so that the minors are dimensionless: S'_ij = S_ij sqrt(E_i E_j)
        let s = self.normal_compliance();
        let e = self.young;
        let t: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| s[i][j] * (e[i] * e[j]).sqrt()));
        let m2 = t[0][0] * t[1][1] - t[0][1] * t[1][0];
        let m3 = det3(&t);
        if !(m2 > 0.0 && m3 > 0.0) {
            return Err(StampError::Material(format!(
                "the Poisson ratios nu12, nu13, nu23 = {:?} with E = {:?} give a compliance that is not positive definite (1 - nu12 nu21 = {m2:.4e}, 1 - nu12 nu21 - nu23 nu32 - nu13 nu31 - 2 nu21 nu32 nu13 = {m3:.4e}): no stable material",
                self.poisson, self.young
            )));
        }
        Ok(())
    }

    /// C in the ply's axes.
    pub fn stiffness(&self) -> Stiffness {
        let s = self.normal_compliance();
        let d = det3(&s);
        let mut c = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                // the inverse of the symmetric 3 x 3 block by cofactors
                let (i1, i2) = ((i + 1) % 3, (i + 2) % 3);
                let (j1, j2) = ((j + 1) % 3, (j + 2) % 3);
                c[j][i] = (s[i1][j1] * s[i2][j2] - s[i1][j2] * s[i2][j1]) / d;
            }
        }
        let [g12, g13, g23] = self.shear;
        c[3][3] = g23;
        c[4][4] = g13;
        c[5][5] = g12;
        c
    }
}

fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// The material of a ply.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum PlyMaterial {
    Isotropic(Isotropic),
    Orthotropic(Orthotropic),
}

impl PlyMaterial {
    pub fn validate(&self) -> Result<()> {
        match self {
            PlyMaterial::Isotropic(m) => m.validate(),
            PlyMaterial::Orthotropic(m) => m.validate(),
        }
    }
    /// C in the ply's axes.
    pub fn stiffness(&self) -> Stiffness {
        match self {
            PlyMaterial::Isotropic(m) => {
                let (l, g) = (m.lame_lambda(), m.shear_modulus());
                let mut c = [[0.0; 6]; 6];
                for i in 0..3 {
                    for j in 0..3 {
                        c[i][j] = l + if i == j { 2.0 * g } else { 0.0 };
                    }
                    c[i + 3][i + 3] = g;
                }
                c
            }
            PlyMaterial::Orthotropic(m) => m.stiffness(),
        }
    }
    /// Isotropic: the same in every rotated frame.
    pub fn is_isotropic(&self) -> bool {
        matches!(self, PlyMaterial::Isotropic(_))
    }
}

/// T(theta) with E' = T E: the strains (Voigt, engineering shear) in axes turned by theta about x3
/// (axis 1' = (cos, sin, 0)) from those in the original axes.
pub fn strain_rotation(theta: f64) -> Stiffness {
    let (s, c) = theta.sin_cos();
    [
        [c * c, s * s, 0.0, 0.0, 0.0, c * s],
        [s * s, c * c, 0.0, 0.0, 0.0, -c * s],
        [0.0, 0.0, 1.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, c, -s, 0.0],
        [0.0, 0.0, 0.0, s, c, 0.0],
        [-2.0 * c * s, 2.0 * c * s, 0.0, 0.0, 0.0, c * c - s * s],
    ]
}

/// The stiffness `c` of a material whose axes lie at `theta` (radians, from axis 1 towards axis 2)
/// of the frame it is wanted in: C = T^T C' T with T = [`strain_rotation`]\(theta\), from the energy
/// E'.C'E' / 2 = E.(T^T C' T)E / 2.
pub fn rotate(c: &Stiffness, theta: f64) -> Stiffness {
    let t = strain_rotation(theta);
    let mut ct = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..6 {
            ct[i][j] = (0..6).map(|k| c[i][k] * t[k][j]).sum();
        }
    }
    std::array::from_fn(|i| std::array::from_fn(|j| (0..6).map(|k| t[k][i] * ct[k][j]).sum()))
}

/// The stresses in axes turned by theta about x3 from those in the original axes: S' = T^-T S,
/// i.e. [11, 22, 33, 23, 13, 12] of R S R^T.
pub fn rotate_stress(s: &[f64; 6], theta: f64) -> [f64; 6] {
    let (sn, c) = theta.sin_cos();
    [
        c * c * s[0] + sn * sn * s[1] + 2.0 * c * sn * s[5],
        sn * sn * s[0] + c * c * s[1] - 2.0 * c * sn * s[5],
        s[2],
        c * s[3] - sn * s[4],
        sn * s[3] + c * s[4],
        -c * sn * s[0] + c * sn * s[1] + (c * c - sn * sn) * s[5],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// C inverts the compliance: a uniaxial stress along 1 gives the strains 1/E1, -nu12/E1,
    /// -nu13/E1; C is symmetric.
    #[test]
    fn stiffness_inverts_the_engineering_constants() {
        let m = Orthotropic::new([25.0, 1.0, 1.3], [0.5, 0.4, 0.2], [0.25, 0.3, 0.35]).unwrap();
        let c = m.stiffness();
        for i in 0..6 {
            for j in 0..6 {
                assert!((c[i][j] - c[j][i]).abs() < 1e-12 * c[0][0]);
            }
        }
        // solve C e = (1, 0, 0, 0, 0, 0) by the compliance: e = S (1, 0, 0)
        let e = [1.0 / 25.0, -0.25 / 25.0, -0.3 / 25.0, 0.0, 0.0, 0.0];
        let s: Vec<f64> = (0..6).map(|i| (0..6).map(|j| c[i][j] * e[j]).sum()).collect();
        for (i, want) in [1.0, 0.0, 0.0, 0.0, 0.0, 0.0].into_iter().enumerate() {
            assert!((s[i] - want).abs() < 1e-12, "stress {i}: {} against {want}", s[i]);
        }
        // isotropic constants give Lame's
        let iso = Orthotropic::new([2.0; 3], [2.0 / 2.6; 3], [0.3; 3]).unwrap().stiffness();
        let want = PlyMaterial::Isotropic(Isotropic::new(2.0, 0.3).unwrap()).stiffness();
        for i in 0..6 {
            for j in 0..6 {
                assert!((iso[i][j] - want[i][j]).abs() < 1e-12, "({i}, {j})");
            }
        }
        assert!(Orthotropic::new([25.0, 1.0, 1.0], [0.5; 3], [0.25, 0.25, 1.2]).is_err());
        assert!(Orthotropic::new([25.0, 1.0, 1.0], [0.5, 0.0, 0.5], [0.25; 3]).is_err());
    }

    /// The rotated stiffness is the tensor rotation: stresses from rotated strains rotate back, by
    /// an independent tensor computation; an isotropic C is unchanged; theta = 90 degrees swaps
    /// the axes.
    #[test]
    fn rotation_is_the_tensor_rotation() {
        let c = Orthotropic::new([25.0, 1.0, 1.3], [0.5, 0.4, 0.2], [0.25, 0.3, 0.35]).unwrap().stiffness();
        let theta = 0.7;
        let cg = rotate(&c, theta);
        let e = [0.3, -0.2, 0.1, 0.05, -0.07, 0.11]; // global axes, engineering shear
        let sg: Vec<f64> = (0..6).map(|i| (0..6).map(|j| cg[i][j] * e[j]).sum()).collect();
        // the same by tensors: E' = R E R^T in ply axes (rows of R the ply axes), S' = C' E', S = R^T S' R
        let (sn, cs) = theta.sin_cos();
        let r = [[cs, sn, 0.0], [-sn, cs, 0.0], [0.0, 0.0, 1.0]];
        let voigt = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)];
        let mut et = [[0.0; 3]; 3];
        for (k, &(i, j)) in voigt.iter().enumerate() {
            let v = if k < 3 { e[k] } else { 0.5 * e[k] };
            et[i][j] = v;
            et[j][i] = v;
        }
        let turn = |m: &[[f64; 3]; 3], fwd: bool| -> [[f64; 3]; 3] {
            std::array::from_fn(|i| {
                std::array::from_fn(|j| {
                    (0..3).flat_map(|k| (0..3).map(move |l| (k, l))).map(|(k, l)| if fwd { r[i][k] * m[k][l] * r[j][l] } else { r[k][i] * m[k][l] * r[l][j] }).sum()
                })
            })
        };
        let ep = turn(&et, true);
        let epv: Vec<f64> = voigt.iter().enumerate().map(|(k, &(i, j))| if k < 3 { ep[i][j] } else { 2.0 * ep[i][j] }).collect();
        let sp: Vec<f64> = (0..6).map(|i| (0..6).map(|j| c[i][j] * epv[j]).sum()).collect();
        let mut spt = [[0.0; 3]; 3];
        for (k, &(i, j)) in voigt.iter().enumerate() {
            spt[i][j] = sp[k];
            spt[j][i] = sp[k];
        }
        let st = turn(&spt, false);
        for (k, &(i, j)) in voigt.iter().enumerate() {
            assert!((sg[k] - st[i][j]).abs() < 1e-12, "stress {k}: {} against {}", sg[k], st[i][j]);
        }
        // rotate_stress takes the global stresses back to the ply axes
        let back = rotate_stress(&[sg[0], sg[1], sg[2], sg[3], sg[4], sg[5]], theta);
        for k in 0..6 {
            assert!((back[k] - sp[k]).abs() < 1e-12, "ply stress {k}");
        }
        let iso = PlyMaterial::Isotropic(Isotropic::new(3.0, 0.2).unwrap()).stiffness();
        let ri = rotate(&iso, 1.1);
        for i in 0..6 {
            for j in 0..6 {
                assert!((ri[i][j] - iso[i][j]).abs() < 1e-12);
            }
        }
        let c90 = rotate(&c, std::f64::consts::FRAC_PI_2);
        assert!((c90[0][0] - c[1][1]).abs() < 1e-12 && (c90[1][1] - c[0][0]).abs() < 1e-12 && (c90[3][3] - c[4][4]).abs() < 1e-12);
    }
}

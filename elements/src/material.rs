//! Plate stiffness (paper eqs. 2.6-2.7): the 11 x 11 matrix D that maps the strain vector
//! E = [E11-, E11+, E22-, E22+, 2E12-, 2E12+, 2E13-, 2E13+, 2E23-, 2E23+, E33] (eq. 4.1, with the
//! misprint of a 12-entry list fixed: eta_33 and T_33 are single) to the stress resultants
//! T = [T11-, T11+, T22-, T22+, T12-, T12+, T13-, T13+, T23-, T23+, T33], T^pm = int S N^pm dx3,
//! T33 = int S33 dx3.
//!
//! The through-thickness integrals are summed over layers, so laminated plates follow by giving
//! more layers. With b_ab33 = 0 in the in-plane equations (the paper's remedy for Poisson locking,
//! section 2) the in-plane law uses the reduced plane-stress constants and D is not symmetric:
//! T33 depends on the in-plane strains, the in-plane resultants do not depend on E33.

use stamp::{Result, StampError};

/// Number of strain (and stress-resultant) components of the plate.
pub const NSTRAIN: usize = 11;

/// Indices of the components in the strain vector.
pub mod idx {
    pub const E11: [usize; 2] = [0, 1];
    pub const E22: [usize; 2] = [2, 3];
    pub const E12: [usize; 2] = [4, 5];
    pub const E13: [usize; 2] = [6, 7];
    pub const E23: [usize; 2] = [8, 9];
    pub const E33: usize = 10;
}

/// An isotropic linear elastic material.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Isotropic {
    /// Young's modulus.
    pub young: f64,
    /// Poisson's ratio, in (-1, 0.5).
    pub poisson: f64,
}

impl Isotropic {
    /// A validated material.
    pub fn new(young: f64, poisson: f64) -> Result<Self> {
        let m = Isotropic { young, poisson };
        m.validate()?;
        Ok(m)
    }

    /// Check E > 0 and -1 < nu < 0.5.
    pub fn validate(&self) -> Result<()> {
        if !(self.young.is_finite() && self.young > 0.0) {
            return Err(StampError::Material(format!("Young's modulus must be positive and finite, got {}", crate::plasticity::short(self.young))));
        }
        if !(self.poisson > -1.0 && self.poisson < 0.5) {
            return Err(StampError::Material(format!("Poisson's ratio must lie in (-1, 0.5), got {}", crate::plasticity::short(self.poisson))));
        }
        Ok(())
    }

    /// Shear modulus G = E / (2 (1 + nu)).
    pub fn shear_modulus(&self) -> f64 {
        self.young / (2.0 * (1.0 + self.poisson))
    }

    /// Lame's lambda = E nu / ((1 + nu)(1 - 2 nu)).
    pub fn lame_lambda(&self) -> f64 {
        self.young * self.poisson / ((1.0 + self.poisson) * (1.0 - 2.0 * self.poisson))
    }
}

/// One layer of the plate between x3 = bottom and x3 = top.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Layer {
    pub bottom: f64,
    pub top: f64,
    pub material: Isotropic,
}

/// The plate's section: the face planes x3 = delta- and x3 = delta+ (thickness h = delta+ - delta-)
/// and the layers that fill it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Section {
    pub delta_minus: f64,
    pub delta_plus: f64,
    pub layers: Vec<Layer>,
    /// Transverse shear factor k in S_a3 = k G 2E_a3 (the paper's eq. 2.6, docs/design.md "The model": k = 1, no correction, the
    /// default and the paper's; 5/6 is Reissner's value for a parabolic shear stress).
    #[serde(default = "unit_shear_factor")]
    pub shear_factor: f64,
    /// How the transverse normal stress S_33 enters the in-plane law (default: not at all, the
    /// paper's b_ab33 = 0).
    #[serde(default)]
    pub normal_stress: NormalStress,
}

/// How the transverse normal stress S_33 enters the in-plane stresses S_ab.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NormalStress {
    /// S_ab by the plane-stress constants alone (b_ab33 = 0: the paper's eq. 2.6, docs/design.md "The model"): the paper's.
    #[default]
    Dropped,
    /// S_ab = plane-stress law + nu / (1 - nu) S33m delta_ab, S33m = T33 / h the mean transverse
    /// normal stress of the section: the 3D law with S_33 eliminated, for the part of S_33 that is
    /// constant through the thickness. Zero in pure bending and in a membrane state without face
    /// loads (T33 = 0 there), so it brings back no Poisson locking; it acts under face loads
    /// (contact pressure).
    Mean,
}
fn unit_shear_factor() -> f64 {
    1.0
}

impl Section {
    /// A homogeneous plate of thickness h centred on the reference plane (delta-+ = -+h/2).
    pub fn homogeneous(thickness: f64, material: Isotropic) -> Result<Self> {
        Self::homogeneous_offset(-0.5 * thickness, 0.5 * thickness, material)
    }

    /// A homogeneous plate between the face planes x3 = delta_minus and x3 = delta_plus.
    pub fn homogeneous_offset(delta_minus: f64, delta_plus: f64, material: Isotropic) -> Result<Self> {
        let s = Section {
            delta_minus,
            delta_plus,
            layers: vec![Layer { bottom: delta_minus, top: delta_plus, material }],
            shear_factor: 1.0,
            normal_stress: NormalStress::Dropped,
        };
        s.validate()?;
        Ok(s)
    }

    /// The same section with the transverse shear factor k (S_a3 = k G 2E_a3); k must lie in (0, 1].
    pub fn with_shear_factor(mut self, k: f64) -> Result<Self> {
        self.shear_factor = k;
        self.validate()?;
        Ok(self)
    }

    /// Thickness h = delta+ - delta-.
    pub fn thickness(&self) -> f64 {
        self.delta_plus - self.delta_minus
    }

    /// Check the thickness, the layers (contiguous, filling the section) and their materials.
    pub fn validate(&self) -> Result<()> {
        let h = self.thickness();
        if !(self.delta_minus.is_finite() && self.delta_plus.is_finite()) || !(h > 0.0) {
            return Err(StampError::Material(format!(
                "the thickness must be positive: delta- = {}, delta+ = {} give h = {h}",
                self.delta_minus, self.delta_plus
            )));
        }
        if !(self.shear_factor > 0.0 && self.shear_factor <= 1.0) {
            return Err(StampError::Material(format!(
                "the transverse shear factor must lie in (0, 1], got {}",
                self.shear_factor
            )));
        }
        if self.layers.is_empty() {
            return Err(StampError::Material("the section has no layer".into()));
        }
        let mut z = self.delta_minus;
        for (i, l) in self.layers.iter().enumerate() {
            l.material.validate().map_err(|e| StampError::Material(format!("layer {i}: {e}")))?;
            if (l.bottom - z).abs() > 1e-12 * h || !(l.top > l.bottom) {
                return Err(StampError::Material(format!(
                    "layer {i} spans [{}, {}], but must start at {z} and have positive thickness",
                    l.bottom, l.top
                )));
            }
            z = l.top;
        }
        if (z - self.delta_plus).abs() > 1e-12 * h {
            return Err(StampError::Material(format!("the layers end at {z}, not at delta+ = {}", self.delta_plus)));
        }
        Ok(())
    }

    /// The plate stiffness D (row-major 11 x 11), eq. 2.6 with b_ab33 = 0, the transverse shear
    /// scaled by `shear_factor`.
    pub fn stiffness(&self) -> [[f64; NSTRAIN]; NSTRAIN] {
        let h = self.thickness();
        let (dm, dp) = (self.delta_minus, self.delta_plus);
        let mut d = [[0.0; NSTRAIN]; NSTRAIN];
        for l in &self.layers {
            // exact integrals of N-N-, N-N+, N+N+, N-, N+ over the layer (N linear in x3)
            let nm = |z: f64| (dp - z) / h;
            let np = |z: f64| (z - dm) / h;
            let (a, b) = (l.bottom, l.top);
            let simpson = |f: &dyn Fn(f64) -> f64| (b - a) / 6.0 * (f(a) + 4.0 * f(0.5 * (a + b)) + f(b));
            let i_mm = simpson(&|z| nm(z) * nm(z));
            let i_mp = simpson(&|z| nm(z) * np(z));
            let i_pp = simpson(&|z| np(z) * np(z));
            let i_m = simpson(&|z| nm(z));
            let i_p = simpson(&|z| np(z));
            let m = l.material;
            let e = m.young;
            let nu = m.poisson;
            let g = m.shear_modulus();
            let lam = m.lame_lambda();
            let q11 = e / (1.0 - nu * nu);
            let q12 = nu * q11;
            let faces = [[i_mm, i_mp], [i_mp, i_pp]];
            for p in 0..2 {
                for q in 0..2 {
                    let w = faces[p][q];
                    // in-plane (reduced plane-stress constants)
                    d[idx::E11[p]][idx::E11[q]] += q11 * w;
                    d[idx::E11[p]][idx::E22[q]] += q12 * w;
                    d[idx::E22[p]][idx::E11[q]] += q12 * w;
                    d[idx::E22[p]][idx::E22[q]] += q11 * w;
                    d[idx::E12[p]][idx::E12[q]] += g * w;
                    // transverse shear, S_a3 = k G 2E_a3 (k = 1 unless chosen)
                    d[idx::E13[p]][idx::E13[q]] += self.shear_factor * g * w;
                    d[idx::E23[p]][idx::E23[q]] += self.shear_factor * g * w;
                }
            }
            // transverse normal: T33 = lambda int(eps11 + eps22) + (lambda + 2G) h E33 (b_33ab != 0)
            let int_n = [i_m, i_p];
            for p in 0..2 {
                d[idx::E33][idx::E11[p]] += lam * int_n[p];
                d[idx::E33][idx::E22[p]] += lam * int_n[p];
            }
            d[idx::E33][idx::E33] += (lam + 2.0 * g) * (b - a);
        }
        if self.normal_stress == NormalStress::Mean {
            // T+-_ab += int_layer nu/(1-nu) N+- dx3 * (T33 / h) delta_ab, T33 the full row
            let t33 = d[idx::E33];
            for l in &self.layers {
                let c = l.material.poisson / (1.0 - l.material.poisson);
                let (a, b) = (l.bottom, l.top);
                // exact integrals of N- and N+ over the layer
                let i_m = (b - a) * (dp - 0.5 * (a + b)) / h;
                let i_p = (b - a) * (0.5 * (a + b) - dm) / h;
                for (p, w) in [i_m, i_p].into_iter().enumerate() {
                    for col in 0..NSTRAIN {
                        d[idx::E11[p]][col] += c * w / h * t33[col];
                        d[idx::E22[p]][col] += c * w / h * t33[col];
                    }
                }
            }
        }
        d
    }
}

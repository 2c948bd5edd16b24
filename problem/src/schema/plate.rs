//! `[plate]`: the thickness (or the face planes), the material of a homogeneous plate or its
//! `layers`, the kinematics and the surfaces through the thickness.

use super::Problem;
use super::materials::LayerSpec;
use super::values::{Finite, Poisson, Positive};
use serde::Deserialize;
use serde::de::{Deserializer, Error as _};
use stamp::Result;
use toml::Spanned;

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum KinematicsSpec {
    #[default]
    Nonlinear,
    Linear,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlateSpec {
    /// Thickness h of a plate centred on the reference plane (delta-+ = -+h/2) ...
    #[serde(default)]
    pub thickness: Option<Positive>,
    /// ... or the face planes x3 = delta_minus and x3 = delta_plus.
    #[serde(default)]
    pub delta_minus: Option<Finite>,
    #[serde(default)]
    pub delta_plus: Option<Finite>,
    /// Young's modulus and Poisson's ratio of a homogeneous plate (not with `layers`).
    #[serde(rename = "E", default)]
    pub young: Option<Positive>,
    #[serde(default)]
    pub nu: Option<Poisson>,
    /// ... or the name of a `[[material]]` (isotropic, possibly with `plasticity`) for the whole
    /// plate (model/plasticity_spec.rs).
    #[serde(default)]
    pub material: Option<String>,
    /// The layers from the bottom face up (model/laminate_spec.rs); excludes `E`, `nu` and the thickness keys.
    #[serde(default)]
    pub layers: Option<Spanned<Vec<Spanned<LayerSpec>>>>,
    #[serde(default)]
    pub kinematics: KinematicsSpec,
    /// v1- = v1+ = 0 at every node.
    #[serde(default)]
    pub plane_strain: bool,
    /// Transverse shear factor k in (0, 1] (S_a3 = k G 2E_a3); default 1, the paper's.
    #[serde(default)]
    pub shear_factor: Option<Positive>,
    /// How S_33 enters the in-plane law: "dropped" (default, b_ab33 = 0) or "mean".
    #[serde(default)]
    pub normal_stress: stamp_elements::NormalStress,
    /// Surfaces through the thickness whose displacements are the unknowns: 2 (default, the
    /// paper's plate) to 5; with `layers`, the surfaces in each layer (3 to 5).
    #[serde(default)]
    pub surfaces: Option<Surfaces>,
}

impl PlateSpec {
    /// Surfaces through the thickness of a plate without layers (default 2).
    pub fn surfaces(&self) -> usize {
        self.surfaces.unwrap_or_default().0
    }
    /// Unknowns per node: 3 per surface; with L layers of N surfaces, 3 (L (N - 1) + 1).
    pub fn dofs_per_node(&self) -> u64 {
        match &self.layers {
            Some(l) => 3 * (l.get_ref().len() as u64 * (self.surfaces().max(2) as u64 - 1) + 1),
            None => 3 * self.surfaces() as u64,
        }
    }
}

/// `[plate] surfaces`: an integer from 2 to 5.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Surfaces(pub usize);
impl From<Surfaces> for usize {
    fn from(s: Surfaces) -> usize {
        s.0
    }
}
impl Default for Surfaces {
    fn default() -> Self {
        Surfaces(2)
    }
}
impl<'de> Deserialize<'de> for Surfaces {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = i64::deserialize(d)?;
        if (2..=5).contains(&v) {
            Ok(Surfaces(v as usize))
        } else {
            Err(D::Error::custom(format!(
                "{v}: expected 2 (the paper's plate: the two faces, displacement linear through the thickness) to 5 (faces and inner surfaces, displacement of degree surfaces - 1 through the thickness, the 3D law)"
            )))
        }
    }
}

impl Problem {
    /// The checks of `[plate]`: E and nu of a homogeneous plate, the thickness or both face planes.
    pub(super) fn check_plate(&self) -> Result<()> {
        let s = &self.spec;
        let plate = s.plate.get_ref();
        if plate.material.is_some() {
            if let Some(k) = [("E", plate.young.is_some()), ("nu", plate.nu.is_some()), ("layers", plate.layers.is_some())].iter().find(|(_, g)| *g).map(|(k, _)| k) {
                return Err(self.error_at(s.plate.span(), &format!("plate.{k}"), format!("`material` and `{k}` exclude each other: the [[material]] named by `material` gives the plate's material")));
            }
        } else if plate.layers.is_none() {
            for (k, given) in [("E", plate.young.is_some()), ("nu", plate.nu.is_some())] {
                if !given {
                    return Err(self.error_at(s.plate.span(), &format!("plate.{k}"), format!("missing field `{k}`: give E and nu of a homogeneous plate, `material` = the name of a [[material]], or `layers` with [[material]] tables")));
                }
            }
        }
        match (plate.thickness, plate.delta_minus, plate.delta_plus) {
            _ if plate.layers.is_some() => {}
            (Some(_), None, None) => {}
            (None, Some(a), Some(b)) => {
                if !(b.0 > a.0) {
                    return Err(self.error_at(s.plate.span(), "plate.delta_plus", format!("must exceed delta_minus (thickness delta_plus - delta_minus = {} must be positive)", b.0 - a.0)));
                }
            }
            _ => {
                return Err(self.error_at(s.plate.span(), "plate.thickness", "give either `thickness` or both `delta_minus` and `delta_plus`"));
            }
        }
        Ok(())
    }
}

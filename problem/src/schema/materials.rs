//! `[[material]]`: the materials of a laminate's layers and the entries of `[plate] layers`
//! (turned into a laminate by crate::model::laminate_spec).

use serde::Deserialize;
use serde::de::{Deserializer, Error as _};

/// A number or three numbers, as written.
#[derive(Debug, Clone, PartialEq)]
pub enum OneOrThree {
    One(f64),
    Three([f64; 3]),
}

impl<'de> Deserialize<'de> for OneOrThree {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            One(f64),
            Many(Vec<f64>),
        }
        const FORMS: &str = "expected a number (isotropic) or three numbers [1, 2, 3] in the ply's axes (orthotropic)";
        match Raw::deserialize(d).map_err(|_| D::Error::custom(FORMS))? {
            Raw::One(v) if v.is_finite() => Ok(OneOrThree::One(v)),
            Raw::Many(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => Ok(OneOrThree::Three([v[0], v[1], v[2]])),
            Raw::Many(v) if v.len() == 3 => Err(D::Error::custom("expected three finite numbers")),
            Raw::Many(v) => Err(D::Error::custom(format!("{FORMS}, got {} numbers", v.len()))),
            Raw::One(_) => Err(D::Error::custom("expected a finite number")),
        }
    }
}

/// One `[[material]]` table (turned into a laminate by model/laminate_spec.rs).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub name: String,
    #[serde(rename = "E")]
    pub young: OneOrThree,
    #[serde(rename = "G", default)]
    pub shear: Option<OneOrThree>,
    pub nu: OneOrThree,
    /// `plasticity = { ... }` of an isotropic material (model/plasticity_spec.rs).
    #[serde(default)]
    pub plasticity: Option<PlasticitySpec>,
}

/// `plasticity = { hardening = "swift", K = 530.0, e0 = 0.005, n = 0.25, r = [1.8, 1.4, 2.2] }`,
/// `{ yield = 150.0, hardening = "linear", H = 1000.0 }` or `{ table = [[0.0, 150.0], ...] }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlasticitySpec {
    /// "linear" (default without `table`), "swift" or "table".
    #[serde(default)]
    pub hardening: Option<String>,
    /// The initial yield stress of linear hardening.
    #[serde(rename = "yield", default)]
    pub yield_stress: Option<f64>,
    /// The hardening modulus of linear hardening (default 0: perfectly plastic).
    #[serde(rename = "H", default)]
    pub modulus: Option<f64>,
    /// Swift's sigma_y = K (e0 + ep)^n.
    #[serde(rename = "K", default)]
    pub k: Option<f64>,
    #[serde(default)]
    pub e0: Option<f64>,
    #[serde(default)]
    pub n: Option<f64>,
    /// Rows [plastic strain, yield stress].
    #[serde(default)]
    pub table: Option<Vec<[f64; 2]>>,
    /// Hill's r-values [r0, r45, r90] relative to x1 (the rolling direction); absent: von Mises.
    #[serde(default)]
    pub r: Option<[f64; 3]>,
}

/// One entry of `[plate] layers`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerSpec {
    pub thickness: f64,
    pub material: String,
    #[serde(default)]
    pub angle: f64,
}

//! `[[boundary]]`: the components a group holds at zero (`fix`) or prescribes (`prescribe`), named
//! by the constraint words.

use super::Problem;
use super::values::{Finite, PathSpec};
use serde::Deserialize;
use serde::de::{Deserializer, Error as _};
use stamp::Result;
use stamp::quote;
use std::collections::BTreeMap;
use toml::Spanned;

/// Component indices (0..6: v1-, v2-, v3-, v1+, v2+, v3+) named by one constraint word.
#[derive(Debug, Clone, PartialEq)]
pub struct DofSet {
    pub word: String,
    pub components: Vec<usize>,
}

/// The constraint words: the six face displacements, v1/v2/v3 (both faces) and the shorthands.
pub const DOF_WORDS: &str = "v1-, v2-, v3-, v1+, v2+, v3+, v1, v2, v3 (both faces), clamped (all six), \
simply_supported (v3- and v3+), symmetry_x1 (v1- and v1+), symmetry_x2 (v2- and v2+)";

pub fn dof_components(word: &str) -> Option<Vec<usize>> {
    Some(match word {
        "v1-" => vec![0],
        "v2-" => vec![1],
        "v3-" => vec![2],
        "v1+" => vec![3],
        "v2+" => vec![4],
        "v3+" => vec![5],
        "v1" | "symmetry_x1" => vec![0, 3],
        "v2" | "symmetry_x2" => vec![1, 4],
        "v3" | "simply_supported" => vec![2, 5],
        "clamped" => vec![0, 1, 2, 3, 4, 5],
        _ => return None,
    })
}

impl<'de> Deserialize<'de> for DofSet {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let word = String::deserialize(d)?;
        match dof_components(&word) {
            Some(components) => Ok(DofSet { word, components }),
            None => Err(D::Error::custom(format!(
                "unknown displacement or constraint '{}'; expected one of v1-, v2-, v3-, v1+, v2+, v3+, v1, v2, v3, clamped, simply_supported, symmetry_x1, symmetry_x2",
                quote(&word)
            ))),
        }
    }
}

/// A dof word usable as a key of `prescribe` (anything but the shorthands with several meanings is
/// fine: "v3" prescribes both faces).
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct DofKey(pub String);
impl<'de> Deserialize<'de> for DofKey {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let word = String::deserialize(d)?;
        match word.as_str() {
            "v1-" | "v2-" | "v3-" | "v1+" | "v2+" | "v3+" | "v1" | "v2" | "v3" => Ok(DofKey(word)),
            _ => Err(D::Error::custom(format!("'{}' cannot be prescribed; expected one of v1-, v2-, v3-, v1+, v2+, v3+, v1, v2, v3", quote(&word)))),
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    pub group: Spanned<String>,
    /// Components held at zero.
    #[serde(default)]
    pub fix: Vec<DofSet>,
    /// Components prescribed to value * load factor.
    #[serde(default)]
    pub prescribe: BTreeMap<DofKey, Finite>,
    /// Rows [t, factor]: the prescribed values are value times this factor at load factor t
    /// (default: t).
    #[serde(default)]
    pub path: Option<Spanned<PathSpec>>,
}

impl Problem {
    /// The checks of `[[boundary]]`: each holds or prescribes something.
    pub(super) fn check_boundary(&self) -> Result<()> {
        let s = &self.spec;
        for (i, b) in s.boundary.iter().enumerate() {
            let bs = b.get_ref();
            if bs.fix.is_empty() && bs.prescribe.is_empty() {
                return Err(self.error_at(b.span(), &format!("boundary[{i}]"), "needs `fix` or `prescribe`"));
            }
            if let Some(path) = &bs.path {
                if bs.prescribe.is_empty() {
                    return Err(self.error_at(path.span(), &format!("boundary[{i}].path"), "a path scales the values of `prescribe`, and this boundary prescribes none (`fix` holds at zero all along)"));
                }
            }
        }
        Ok(())
    }
}

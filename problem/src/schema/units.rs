//! Units for labels: the optional `[units]` table of a problem file.
//!
//! ```toml
//! [units]
//! length = "mm"
//! force = "N"
//! pressure = "MPa"   # default: force/length^2, e.g. "N/mm^2"
//! ```
//!
//! stamp computes in whatever consistent units the problem file uses; these names only label the
//! table, the CSV headers stay plain, and every plot axis says its unit. Without the table the labels
//! say "length", "force" and "force/length^2".

use serde::Deserialize;
use serde::de::{Deserializer, Error as _};

/// A unit name: 1 to 20 printable characters (no control characters), e.g. "mm", "kN", "N/mm^2".
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnitName(pub String);

impl<'de> Deserialize<'de> for UnitName {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let s = String::deserialize(d)?;
        if s.trim().is_empty() || s.chars().count() > 20 || s.chars().any(|c| c.is_control()) {
            return Err(D::Error::custom(format!("expected a unit name of 1 to 20 printable characters (e.g. \"mm\"), got {}", stamp::quote(&s))));
        }
        Ok(UnitName(s.trim().to_string()))
    }
}

/// The `[units]` table.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnitsSpec {
    #[serde(default)]
    pub length: Option<UnitName>,
    #[serde(default)]
    pub force: Option<UnitName>,
    /// Default: force/length^2.
    #[serde(default)]
    pub pressure: Option<UnitName>,
}

/// The unit labels of one run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Units {
    pub length: String,
    pub force: String,
    pub pressure: String,
    pub area: String,
    /// Whether the problem file named the length unit (values in labels then carry it).
    pub length_given: bool,
    /// Whether the problem file named the force unit.
    pub force_given: bool,
}

impl Units {
    /// Labels from the optional `[units]` table.
    pub fn new(spec: Option<&UnitsSpec>) -> Units {
        let spec = spec.cloned().unwrap_or_default();
        let (length_given, force_given) = (spec.length.is_some(), spec.force.is_some());
        let length = spec.length.map(|u| u.0).unwrap_or_else(|| "length".into());
        let force = spec.force.map(|u| u.0).unwrap_or_else(|| "force".into());
        let area = format!("{length}^2");
        let pressure = spec.pressure.map(|u| u.0).unwrap_or_else(|| format!("{force}/{length}^2"));
        Units { length, force, pressure, area, length_given, force_given }
    }

    /// "1.5 mm", or "1.5" when the file gives no length unit.
    pub fn length_value(&self, x: &str) -> String {
        if self.length_given { format!("{x} {}", self.length) } else { x.to_string() }
    }

    /// "1200 N", or "1200" when the file gives no force unit.
    pub fn force_value(&self, x: &str) -> String {
        if self.force_given { format!("{x} {}", self.force) } else { x.to_string() }
    }

    /// "name (unit)", the label of an axis or a column ("force", not "force (force)", without units).
    pub fn label(name: &str, unit: &str) -> String {
        if name == unit { name.to_string() } else { format!("{name} ({unit})") }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_say_the_quantity_and_pressure_is_derived() {
        let u = Units::new(None);
        assert_eq!((u.length.as_str(), u.force.as_str(), u.pressure.as_str(), u.area.as_str()), ("length", "force", "force/length^2", "length^2"));
        let spec: UnitsSpec = toml::from_str("length = \"mm\"\nforce = \"N\"").unwrap();
        let u = Units::new(Some(&spec));
        assert_eq!((u.pressure.as_str(), u.area.as_str()), ("N/mm^2", "mm^2"));
        let spec: UnitsSpec = toml::from_str("length = \"mm\"\nforce = \"N\"\npressure = \"MPa\"").unwrap();
        assert_eq!(Units::new(Some(&spec)).pressure, "MPa");
    }

    #[test]
    fn bad_unit_names_are_refused() {
        for bad in ["length = \"\"", "force = \"a very long unit name indeed\"", "length = \"m\\u0007\"", "mass = \"kg\""] {
            assert!(toml::from_str::<UnitsSpec>(bad).is_err(), "{bad} was accepted");
        }
    }
}

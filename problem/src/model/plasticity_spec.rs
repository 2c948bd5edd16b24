//! The material of a plate without layers: `E` and `nu` in `[plate]`, or `[plate] material` naming
//! a `[[material]]`, which may carry `plasticity = { ... }` (elements/src/plasticity):
//!
//! ```toml
//! [[material]]
//! name = "DC04"
//! E = 210000.0
//! nu = 0.3
//! plasticity = { hardening = "swift", K = 530.0, e0 = 0.005, n = 0.25, r = [1.8, 1.4, 2.2] }
//!
//! [plate]
//! material = "DC04"
//! thickness = 0.85
//! surfaces = 5
//! ```

use crate::schema::{num, PlasticitySpec, Problem};
use stamp::Result;
use stamp_elements::plasticity::{Hardening, Plasticity};
use stamp_elements::PlyMaterial;

/// The plate's elastic constants and its plasticity, if any.
#[derive(Debug, Clone)]
pub struct PlateMaterial {
    pub young: f64,
    pub poisson: f64,
    pub plasticity: Option<Plasticity>,
    /// The `[[material]]` it came from.
    pub name: Option<String>,
}

/// The material of a plate without layers (None with layers).
pub fn plate_material(p: &Problem) -> Result<Option<PlateMaterial>> {
    let s = &p.spec;
    let ps = s.plate.get_ref();
    if ps.layers.is_some() {
        return Ok(None);
    }
    let Some(name) = &ps.material else {
        return Ok(Some(PlateMaterial { young: ps.young.expect("checked").0, poisson: ps.nu.expect("checked").0, plasticity: None, name: None }));
    };
    let materials = crate::model::laminate_spec::materials(p)?;
    let Some(i) = materials.iter().position(|(n, _)| n == name) else {
        let known: Vec<String> = materials.iter().map(|(n, _)| format!("'{}'", stamp::quote(n))).collect();
        return Err(p.error_at(
            s.plate.span(),
            "plate.material",
            format!("no [[material]] is named '{}'; the materials are: {}", stamp::quote(name), if known.is_empty() { "none".into() } else { known.join(", ") }),
        ));
    };
    let PlyMaterial::Isotropic(m) = materials[i].1 else {
        return Err(p.error_at(s.plate.span(), "plate.material", format!("'{}' is orthotropic: a plate of one material takes an isotropic one (one number E and nu); give an orthotropic material in `layers`", stamp::quote(name))));
    };
    let plasticity = match &s.material[i].get_ref().plasticity {
        Some(spec) => Some(plasticity(p, i, spec)?),
        None => None,
    };
    if plasticity.is_some() && ps.surfaces() == 2 {
        return Err(p.error_at(
            s.plate.span(),
            "plate.surfaces",
            format!("'{}' is plastic, and the paper's two-surface plate stays elastic (its law is a plane-stress reduction of resultants, not the 3D law at points through the thickness that a return map needs): give surfaces = 3 to 5 (5 for bending within 1 %, docs/verification/plasticity.md)", stamp::quote(name)),
        ));
    }
    Ok(Some(PlateMaterial { young: m.young, poisson: m.poisson, plasticity, name: Some(name.clone()) }))
}

/// `material[i].plasticity` checked and turned into the elements' [`Plasticity`].
pub fn plasticity(p: &Problem, i: usize, spec: &PlasticitySpec) -> Result<Plasticity> {
    let m = &p.spec.material[i];
    let key = |k: &str| format!("material[{i}].plasticity{k}");
    let err = |k: &str, msg: String| p.error_at(m.span(), &key(k), msg);
    let given = |pairs: &[(&str, bool)]| pairs.iter().filter(|(_, g)| *g).map(|(k, _)| k.to_string()).collect::<Vec<_>>();
    let law = match (spec.hardening.as_deref(), &spec.table) {
        (Some(h), _) => h.to_string(),
        (None, Some(_)) => "table".into(),
        (None, None) => "linear".into(),
    };
    let foreign = |own: &[&str]| -> Result<()> {
        let all = [("yield", spec.yield_stress.is_some()), ("H", spec.modulus.is_some()), ("K", spec.k.is_some()), ("e0", spec.e0.is_some()), ("n", spec.n.is_some()), ("table", spec.table.is_some())];
        if let Some(k) = given(&all).into_iter().find(|k| !own.contains(&k.as_str())) {
            return Err(err(&format!(".{k}"), format!("does not belong to hardening = \"{law}\", which takes {}", own.join(", "))));
        }
        Ok(())
    };
    let finite = |k: &str, v: Option<f64>| -> Result<f64> {
        match v {
            Some(x) if x.is_finite() => Ok(x),
            Some(x) => Err(err(&format!(".{k}"), format!("expected a finite number, got {}", num(x)))),
            None => Err(err("", format!("missing `{k}` of hardening = \"{law}\""))),
        }
    };
    let hardening = match law.as_str() {
        "linear" => {
            foreign(&["yield", "H"])?;
            Hardening::Linear { yield_stress: finite("yield", spec.yield_stress)?, modulus: spec.modulus.map_or(Ok(0.0), |h| finite("H", Some(h)))? }
        }
        "swift" => {
            foreign(&["K", "e0", "n"])?;
            Hardening::Swift { k: finite("K", spec.k)?, e0: finite("e0", spec.e0)?, n: finite("n", spec.n)? }
        }
        "table" => {
            foreign(&["table"])?;
            let rows = spec.table.as_ref().ok_or_else(|| err("", "missing `table` = [[plastic strain, yield stress], ...] of hardening = \"table\"".into()))?;
            Hardening::Table(rows.iter().map(|r| (r[0], r[1])).collect())
        }
        other => return Err(err(".hardening", format!("unknown hardening \"{}\": expected \"linear\" (yield, H), \"swift\" (K, e0, n) or \"table\" (table)", stamp::quote(other)))),
    };
    let plasticity = Plasticity { hardening, r_values: spec.r };
    plasticity.validate().map_err(|e| err(if e.to_string().contains("r-values") { ".r" } else { "" }, e.to_string().trim_start_matches("material: ").to_string()))?;
    Ok(plasticity)
}

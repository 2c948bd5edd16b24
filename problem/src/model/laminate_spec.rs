//! Laminates in a problem file: the `[[material]]` tables and `[plate] layers`, checked against
//! each other and turned into a [`Laminate`] of the elements crate.
//!
//! ```toml
//! [[material]]
//! name = "ply"
//! E = [25.0, 1.0, 1.0]      # E1, E2, E3 in the ply's axes (orthotropic), or one number (isotropic)
//! G = [0.5, 0.5, 0.2]       # G12, G13, G23 (orthotropic only)
//! nu = [0.25, 0.25, 0.25]   # nu12, nu13, nu23, or one number (isotropic)
//!
//! [plate]
//! layers = [{ thickness = 0.5, material = "ply", angle = 0.0 }, ...]   # from the bottom face up
//! surfaces = 4              # in each layer
//! ```

use crate::schema::limits::{MAX_MAGNITUDE, MIN_MAGNITUDE};
use crate::schema::{num, OneOrThree, Problem};
use stamp::Result;
use stamp_elements::{Isotropic, Laminate, Orthotropic, Ply, PlyMaterial};

/// The materials by name, each checked (isotropic: numbers E and nu, no G; orthotropic: three E,
/// G and nu), with errors that name `material[i].key`.
pub(crate) fn materials(p: &Problem) -> Result<Vec<(String, PlyMaterial)>> {
    let mut out: Vec<(String, PlyMaterial)> = Vec::new();
    for (i, m) in p.spec.material.iter().enumerate() {
        let spec = m.get_ref();
        let key = format!("material[{i}]");
        let err = |k: &str, msg: String| p.error_at(m.span(), &format!("{key}{k}"), msg);
        if spec.name.is_empty() || spec.name.len() > 64 {
            return Err(err(".name", "must be 1 to 64 characters".into()));
        }
        if out.iter().any(|(n, _)| *n == spec.name) {
            return Err(err(".name", format!("two materials are named '{}'", stamp::quote(&spec.name))));
        }
        // the ranges of [plate]'s E (a modulus of 1e-300 or 1e300 ended "converged" undeformed or
        // in NaN after 12 cut-backs)
        let moduli = |v: &OneOrThree| -> Vec<f64> {
            match v {
                OneOrThree::One(x) => vec![*x],
                OneOrThree::Three(x) => x.to_vec(),
            }
        };
        for (k, v) in std::iter::once(("E", &spec.young)).chain(spec.shear.as_ref().map(|g| ("G", g))) {
            if let Some(bad) = moduli(v).into_iter().find(|x| !(MIN_MAGNITUDE..=MAX_MAGNITUDE).contains(x)) {
                return Err(err(&format!(".{k}"), format!("expected positive moduli from {MIN_MAGNITUDE:e} to {MAX_MAGNITUDE:e} (the range of [plate] E), got {}", num(bad))));
            }
        }
        let material = match (&spec.young, &spec.shear, &spec.nu) {
            (OneOrThree::One(e), None, OneOrThree::One(nu)) => PlyMaterial::Isotropic(Isotropic::new(*e, *nu).map_err(|e| err("", e.to_string()))?),
            (OneOrThree::One(_), Some(_), _) => return Err(err(".G", "an isotropic material (one number E) takes no G: G = E / (2 (1 + nu))".into())),
            (OneOrThree::One(_), None, OneOrThree::Three(_)) => {
                return Err(err(".nu", "an isotropic material (one number E) takes one number nu".into()));
            }
            (OneOrThree::Three(e), Some(OneOrThree::Three(g)), OneOrThree::Three(nu)) => {
                PlyMaterial::Orthotropic(Orthotropic::new(*e, *g, *nu).map_err(|e| err("", e.to_string()))?)
            }
            (OneOrThree::Three(_), None, _) | (OneOrThree::Three(_), Some(OneOrThree::One(_)), _) => {
                return Err(err(".G", "an orthotropic material (three numbers E) needs G = [G12, G13, G23]".into()));
            }
            (OneOrThree::Three(_), _, OneOrThree::One(_)) => {
                return Err(err(".nu", "an orthotropic material (three numbers E) needs nu = [nu12, nu13, nu23]".into()));
            }
        };
        out.push((spec.name.clone(), material));
    }
    Ok(out)
}

/// The laminate of `[plate] layers` and the surfaces in each layer, or None for a plate without
/// layers. Checks the keys that go with layers (not `E`, `nu`, `thickness`, `delta_minus`,
/// `delta_plus`, `shear_factor`, `normal_stress`; `surfaces` 3 to 5) and that every `[[material]]`
/// is used only with layers.
pub fn laminate(p: &Problem) -> Result<Option<(Laminate, usize)>> {
    let s = &p.spec;
    let ps = s.plate.get_ref();
    let Some(layers) = &ps.layers else {
        if let Some(m) = s.material.first().filter(|_| ps.material.is_none()) {
            return Err(p.error_at(m.span(), "material[0]", "a [[material]] is used by [plate] layers or [plate] material, and the plate names none: give `layers`, or `material` = its name in [plate]"));
        }
        return Ok(None);
    };
    let given: Vec<&str> = [
        ("E", ps.young.is_some()),
        ("nu", ps.nu.is_some()),
        ("thickness", ps.thickness.is_some()),
        ("delta_minus", ps.delta_minus.is_some()),
        ("delta_plus", ps.delta_plus.is_some()),
        ("shear_factor", ps.shear_factor.is_some()),
        ("normal_stress", ps.normal_stress != stamp_elements::NormalStress::Dropped),
    ]
    .into_iter()
    .filter_map(|(k, g)| g.then_some(k))
    .collect();
    if let Some(k) = given.first() {
        let why = match *k {
            "E" | "nu" => "the layers' [[material]] tables give the material",
            "thickness" | "delta_minus" | "delta_plus" => "the layers give the thickness, the stack's mid-plane at x3 = 0",
            _ => "it is a correction of the two-surface plate; layers have the full 3D law",
        };
        return Err(p.error_at(s.plate.span(), &format!("plate.{k}"), format!("`layers` and `{k}` exclude each other: {why}")));
    }
    let per_layer = match ps.surfaces {
        Some(n) if (3..=5).contains(&n.0) => n.0,
        Some(n) => return Err(p.error_at(s.plate.span(), "plate.surfaces", format!("with layers, the surfaces in each layer (its faces included): 3 to 5, got {}", n.0))),
        None => return Err(p.error_at(s.plate.span(), "plate.surfaces", "with layers, give `surfaces` = 3 to 5, the surfaces in each layer (its faces included; 5 for stresses within 1 % of 3D elasticity on thick plates, docs/verification/laminates.md)")),
    };
    let materials = materials(p)?;
    let list = layers.get_ref();
    if list.is_empty() {
        return Err(p.error_at(layers.span(), "plate.layers", "needs at least one layer"));
    }
    if list.len() > 64 {
        return Err(p.error_at(layers.span(), "plate.layers", format!("at most 64 layers, got {}", list.len())));
    }
    let mut plies = Vec::with_capacity(list.len());
    for (k, l) in list.iter().enumerate() {
        let spec = l.get_ref();
        let key = format!("plate.layers[{k}]");
        if !(MIN_MAGNITUDE..=MAX_MAGNITUDE).contains(&spec.thickness) {
            return Err(p.error_at(l.span(), &format!("{key}.thickness"), format!("must be a positive length from {MIN_MAGNITUDE:e} to {MAX_MAGNITUDE:e} (the range of [plate] thickness), got {}", num(spec.thickness))));
        }
        if !(spec.angle.is_finite() && spec.angle.abs() <= 1e6) {
            return Err(p.error_at(l.span(), &format!("{key}.angle"), format!("must be a finite angle in degrees, got {}", num(spec.angle))));
        }
        let Some((_, material)) = materials.iter().find(|(n, _)| *n == spec.material) else {
            let known: Vec<String> = materials.iter().map(|(n, _)| format!("'{}'", stamp::quote(n))).collect();
            return Err(p.error_at(
                l.span(),
                &format!("{key}.material"),
                format!("no [[material]] is named '{}'; the materials are: {}", stamp::quote(&spec.material), if known.is_empty() { "none".into() } else { known.join(", ") }),
            ));
        };
        let index = s.material.iter().position(|m| m.get_ref().name == spec.material).expect("found above");
        if s.material[index].get_ref().plasticity.is_some() {
            return Err(p.error_at(
                l.span(),
                &format!("{key}.material"),
                format!("'{}' is plastic, and plastic layers are not supported yet: a plastic plate is one material, `[plate] material = \"{}\"` with surfaces = 3 to 5", stamp::quote(&spec.material), stamp::quote(&spec.material)),
            ));
        }
        plies.push(Ply { thickness: spec.thickness, material: *material, angle: spec.angle });
    }
    let lam = Laminate::new(plies).map_err(|e| p.error_at(layers.span(), "plate.layers", e))?;
    Ok(Some((lam, per_layer)))
}

/// A modulus that stands for the stack where one number is needed (the automatic eps_reg of the
/// punches): the thickness-weighted mean over the plies of (E1 + E2) / 2 (E of an isotropic ply).
pub fn reference_modulus(lam: &Laminate) -> f64 {
    let h = lam.thickness();
    lam.plies
        .iter()
        .map(|p| {
            p.thickness / h
                * match p.material {
                    PlyMaterial::Isotropic(m) => m.young,
                    PlyMaterial::Orthotropic(m) => 0.5 * (m.young[0] + m.young[1]),
                }
        })
        .sum()
}

/// The stack in one line per layer, for `stamp check`.
pub fn describe(p: &Problem, lam: &Laminate, per_layer: usize) -> Vec<String> {
    let names: Vec<&str> = p.spec.plate.get_ref().layers.as_ref().map(|l| l.get_ref().iter().map(|s| s.get_ref().material.as_str()).collect()).unwrap_or_default();
    let b = lam.boundaries();
    lam.plies
        .iter()
        .enumerate()
        .map(|(k, ply)| {
            let kind = match ply.material {
                PlyMaterial::Isotropic(m) => format!("isotropic E = {}, nu = {}", num(m.young), num(m.poisson)),
                PlyMaterial::Orthotropic(m) => format!(
                    "orthotropic E = [{}], G = [{}], nu = [{}]",
                    m.young.map(num).join(", "),
                    m.shear.map(num).join(", "),
                    m.poisson.map(num).join(", ")
                ),
            };
            format!(
                "layer {k}: x3 from {} to {} (thickness {}), '{}' ({kind}), angle {} degrees, {per_layer} surfaces",
                num(b[k]),
                num(b[k + 1]),
                num(ply.thickness),
                stamp::quote(names.get(k).copied().unwrap_or("")),
                num(ply.angle)
            )
        })
        .collect()
}

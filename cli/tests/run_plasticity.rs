//! Elastic-plastic plates in a problem file: `[[material]] plasticity = { ... }` with `[plate]
//! material`, the errors of bad plasticity keys, and a plate pressed by a sphere past yield and
//! let go: the punch leaves a permanent dent (the elastic plate springs back to flat), the sheet
//! thins, the plastic strain is written where users read it (history.csv, summary.json, the
//! .vtu's arrays), and the supports balance the punch at every step.

mod common;
use common::*;

fn error_of(name: &str, text: &str) -> String {
    build_error("bad-plastic", name, text)
}

/// A quarter plate 12 x 12 (6 x 6 cells, h = 1), clamped, pressed 1.2 by a sphere of radius 10 at
/// t = 0.5 and let go by t = 1; `material` and `plate` are the tables' extra lines.
fn indented(material: &str, plate: &str) -> String {
    format!(
        r#"
[mesh]
rectangle = {{ x = [0.0, 12.0], y = [0.0, 12.0], n = [6, 6] }}

[[material]]
name = "steel"
E = 210000.0
nu = 0.3
{material}

[plate]
thickness = 1.0
material = "steel"
{plate}

[[boundary]]
group = "left"
fix = ["symmetry_x1"]

[[boundary]]
group = "bottom"
fix = ["symmetry_x2"]

[[boundary]]
group = "right"
fix = ["clamped"]

[[boundary]]
group = "top"
fix = ["clamped"]

[[punch]]
name = "sphere"
shape = "sphere"
center = [0.0, 0.0, 10.5]
radius = 10.0
motion = [[0.5, 0.0, 0.0, -1.2], [1.0, 0.0, 0.0, 0.0]]

[solver]
targets = [0.25, 0.5, 0.75, 1.0]
max_increment = 0.125

[output]
plot = false
"#
    )
}

#[test]
fn bad_plasticity_keys_are_refused_with_the_reason() {
    let e = error_of("two-surface", &indented("plasticity = { yield = 250.0 }", ""));
    assert!(e.contains("plate.surfaces") && e.contains("two-surface plate stays elastic"), "{e}");
    let e = error_of("unknown-hardening", &indented("plasticity = { yield = 250.0, hardening = \"voce\" }", "surfaces = 3"));
    assert!(e.contains("material[0].plasticity.hardening") && e.contains("\"voce\""), "{e}");
    let e = error_of("foreign-key", &indented("plasticity = { yield = 250.0, K = 500.0 }", "surfaces = 3"));
    assert!(e.contains("material[0].plasticity.K") && e.contains("does not belong to hardening = \"linear\""), "{e}");
    let e = error_of("missing-key", &indented("plasticity = { hardening = \"swift\", K = 530.0, n = 0.25 }", "surfaces = 3"));
    assert!(e.contains("missing `e0`"), "{e}");
    let e = error_of("bad-table", &indented("plasticity = { table = [[0.0, 250.0], [0.1, 200.0]] }", "surfaces = 3"));
    assert!(e.contains("material[0].plasticity") && e.contains("must not decrease"), "{e}");
    let e = error_of("bad-r", &indented("plasticity = { yield = 250.0, r = [1.8, -1.0, 2.0] }", "surfaces = 3"));
    assert!(e.contains("material[0].plasticity.r"), "{e}");
    let e = error_of("unknown-field", &indented("plasticity = { yield = 250.0, hardness = 3.0 }", "surfaces = 3"));
    assert!(e.contains("hardness"), "{e}");
    let e = error_of("material-and-e", &indented("", "surfaces = 3\nE = 1.0"));
    assert!(e.contains("plate.E") && e.contains("exclude each other"), "{e}");
    let e = error_of("no-such-material", &indented("", "surfaces = 3").replace("material = \"steel\"", "material = \"stee\""));
    assert!(e.contains("plate.material") && e.contains("'steel'"), "{e}");
    // plastic layers are not supported yet: said so at the layer
    let layered = indented("plasticity = { yield = 250.0 }", "surfaces = 3").replace("thickness = 1.0\nmaterial = \"steel\"", "layers = [{ thickness = 1.0, material = \"steel\" }]");
    let e = error_of("plastic-layer", &layered);
    assert!(e.contains("plate.layers[0].material") && e.contains("not supported yet"), "{e}");
}

#[test]
fn a_sphere_leaves_a_permanent_dent_and_the_elastic_plate_springs_back() {
    let plastic = run_text("plastic-dent", &indented("plasticity = { hardening = \"swift\", K = 530.0, e0 = 0.005, n = 0.25 }", "surfaces = 3"));
    let elastic = run_text("elastic-dent", &indented("", "surfaces = 3"));
    let (hp, rp) = history(&plastic);
    let (he, re) = history(&elastic);
    let last = |h: &[String], r: &[Vec<f64>], c: &str| *column(h, r, c).last().unwrap();
    let deepest = |h: &[String], r: &[Vec<f64>]| column(h, r, "corner_ll_u3").into_iter().fold(0.0f64, f64::min);
    // the punch has left both plates
    assert_eq!(last(&hp, &rp, "sphere_force"), 0.0);
    assert_eq!(last(&he, &re, "sphere_force"), 0.0);
    // the elastic plate is flat again; the plastic one keeps most of its dent, less its springback
    let (dent, deepest_p) = (last(&hp, &rp, "corner_ll_u3"), deepest(&hp, &rp));
    assert!(last(&he, &re, "corner_ll_u3").abs() < 1e-9, "elastic: {}", last(&he, &re, "corner_ll_u3"));
    assert!(dent < 0.5 * deepest_p && dent > deepest_p, "plastic: dent {dent} after a deepest {deepest_p}");
    // yielding softens the plate: less force for the same travel
    let (fp, fe) = (column(&hp, &rp, "sphere_force"), column(&he, &re, "sphere_force"));
    let peak = |f: &[f64]| f.iter().cloned().fold(0.0, f64::max);
    assert!(peak(&fp) < 0.8 * peak(&fe), "peak force plastic {} against elastic {}", peak(&fp), peak(&fe));
    // plastic strain and thinning, in history.csv and summary.json
    let ep = column(&hp, &rp, "max_plastic_strain");
    let h = column(&hp, &rp, "min_thickness");
    assert!(*ep.last().unwrap() > 0.01 && h.iter().all(|&x| x < 1.0), "ep {ep:?}, thickness {h:?}");
    assert!(!he.iter().any(|c| c == "max_plastic_strain"), "an elastic plate writes no plastic columns");
    let s = summary(&plastic);
    let steps = s["steps"].as_array().unwrap();
    let final_step = steps.last().unwrap();
    assert_eq!(final_step["max_plastic_strain"].as_f64().unwrap(), *ep.last().unwrap());
    assert!(s["cell_arrays"].as_array().unwrap().iter().any(|a| a == "plastic_strain_surface0"));
    assert!(s["point_arrays"].as_array().unwrap().iter().any(|a| a == "thickness_strain"));
    // the supports hold the punch at every step
    for st in steps {
        let f = st["punches"]["sphere"]["reaction"][2].as_f64().unwrap();
        // (the total: the corner held by two groups counted once)
        let r = st["support_reaction"][2].as_f64().unwrap();
        assert!((f + r).abs() < 1e-6 * (1.0 + f.abs()), "step {}: punch {f}, supports {r}", st["step"]);
    }
}

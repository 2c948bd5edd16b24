//! `[plate] surfaces = 3 .. 5` through problem files: the 3D law's answer to a squeezed plate
//! (which the paper's plate cannot give), a cantilever converging to beam theory, a follower
//! pressure in equilibrium, summary.json and `stamp check` naming the model, and the keys it
//! refuses.

mod common;
use common::*;
use serde_json::Value;
use stamp_cli::run::{build::build, Problem};
use std::path::Path;

fn last_step(out: &Path) -> Value {
    summary(out)["steps"].as_array().unwrap().last().unwrap().clone()
}

const E: f64 = 2.0e5;
const NU: f64 = 0.3;
const H: f64 = 0.2;
const Q: f64 = 50.0;

/// A unit square plate resting on a frictionless rigid base (v3- = 0 everywhere), quarter-model
/// symmetry on two edges, the other two free, a pressure Q on the whole top face.
fn squeeze(surfaces: usize) -> String {
    format!(
        r#"[mesh]
rectangle = {{ x = [0.0, 1.0], y = [0.0, 1.0], n = [3, 2] }}

[plate]
thickness = {H}
E = {E}
nu = {NU}
kinematics = "linear"
surfaces = {surfaces}

[[boundary]]
group = "all"
fix = ["v3-"]

[[boundary]]
group = "left"
fix = ["symmetry_x1"]

[[boundary]]
group = "bottom"
fix = ["symmetry_x2"]

[[load]]
type = "pressure"
group = "all"
pressure = {Q}
face = "top"
"#
    )
}

/// 3D elasticity: S33 = -Q, S11 = S22 = 0, so the plate thins by Q h / E and spreads by nu Q / E
/// in each direction. The plates of 3 to 5 surfaces give this exactly; the paper's plate, whose in-plane
/// law ignores S33 (b_ab33 = 0), does not spread and thins by Q h / (lambda + 2 mu): the test tells
/// the two laws apart.
#[test]
fn a_squeezed_plate_thins_and_spreads_as_3d_elasticity_says() {
    let dir = temp_dir("multi-surface-squeeze");
    let lam_2mu = E * (1.0 - NU) / ((1.0 + NU) * (1.0 - 2.0 * NU));
    for (model, thinning, spread) in [(3, Q * H / E, NU * Q / E), (4, Q * H / E, NU * Q / E), (5, Q * H / E, NU * Q / E), (2, Q * H / lam_2mu, 0.0)] {
        let path = write(&dir, &format!("s{model}.toml"), &squeeze(model));
        let out = dir.join(format!("s{model}"));
        stamp_cli::run::run(&path, Some(&out), true).unwrap();
        let s = summary(&out);
        assert_eq!(s["surfaces"].as_u64(), Some(model as u64), "summary.json names the model");
        let corner = &last_step(&out)["points"]["corner_ur"];
        let top_w = corner["displacement_top"][2].as_f64().unwrap();
        let bottom_w = corner["displacement_bottom"][2].as_f64().unwrap();
        assert_eq!(bottom_w, 0.0);
        assert!((top_w + thinning).abs() <= 1e-9 * thinning, "{model}: the top face moves by {top_w}, 3D elasticity {}", -thinning);
        for c in 0..2 {
            let u = corner["displacement"][c].as_f64().unwrap();
            assert!((u - spread).abs() <= 1e-9 * (NU * Q / E), "{model}: the corner (1, 1) moves by {u} along x{}, expected {spread}", c + 1);
        }
    }
}

/// The cantilever strip of the paper's Table 1 (plane strain, linear): the tip deflection of the
/// three- and four-surface plates converges like h^2 to within 0.1 % of beam theory,
/// F L^3 / (3 D) + F L / (5/6 G h) (the parabolic shear they can represent; the rest is the 3D
/// clamp). Measured, three surfaces on 40, 80, 160 elements: -0.116, -0.097, -0.092 %; without
/// the element's E33 stabilisation it was -0.47, -0.24, -0.14 % (like h^1).
#[test]
fn cantilever_tip_deflection_converges_to_beam_theory() {
    let dir = temp_dir("multi-surface-cantilever");
    let (l, h, e, nu, f) = (100.0, 2.0, 2.0e4, 0.3, 0.05);
    let d = e * h * h * h / (12.0 * (1.0 - nu * nu));
    let g = e / (2.0 * (1.0 + nu));
    let beam = f * l * l * l / (3.0 * d) + f * l / (5.0 / 6.0 * g * h);
    for surfaces in [3, 4] {
        let mut tips = Vec::new();
        for n in [40, 80, 160] {
            let text = CANTILEVER
                .replace("plane_strain = true\n", &format!("plane_strain = true\nsurfaces = {surfaces}\n"))
                .replace("n = [1, 40]", &format!("n = [1, {n}]"));
            let path = write(&dir, &format!("c{surfaces}_{n}.toml"), &text);
            let out = dir.join(format!("c{surfaces}_{n}"));
            stamp_cli::run::run(&path, Some(&out), true).unwrap();
            tips.push(last_step(&out)["points"]["corner_ur"]["displacement"][2].as_f64().unwrap());
        }
        let errors: Vec<f64> = tips.iter().map(|w| (w - beam) / beam).collect();
        assert!(errors.iter().all(|&e| e < 0.0 && e > -1.5e-3), "{surfaces} surfaces: {errors:?} against beam theory");
        let (d1, d2) = (tips[1] - tips[0], tips[2] - tips[1]);
        assert!(d1 > 0.0 && d2 > 0.0 && d1 > 3.0 * d2, "{surfaces} surfaces: not converging like h^2: tips {tips:?}");
    }
}

/// A follower pressure on a three-surface plate is balanced by its clamp, as on the paper's.
#[test]
fn follower_pressure_is_in_equilibrium() {
    let dir = temp_dir("multi-surface-follower");
    let text = r#"[mesh]
rectangle = { x = [0.0, 10.0], y = [0.0, 1.0], n = [20, 1] }

[plate]
thickness = 0.1
E = 1.0e4
nu = 0.0
surfaces = 3

[[boundary]]
group = "left"
fix = ["clamped"]

[[load]]
type = "pressure"
group = "all"
pressure = 2.5e-3
face = "top"
follower = true

[solver]
max_increment = 0.1
"#;
    let path = write(&dir, "strip.toml", text);
    let out = dir.join("out");
    stamp_cli::run::run(&path, Some(&out), true).unwrap();
    let e = last_step(&out);
    let applied: Vec<f64> = (0..3).map(|c| e["applied_load"][c].as_f64().unwrap()).collect();
    let support: Vec<f64> = (0..3).map(|c| e["support_reaction"][c].as_f64().unwrap()).collect();
    for c in 0..3 {
        assert!((applied[c] + support[c]).abs() < 1e-9, "applied load {applied:?} and clamp reaction {support:?} do not balance");
    }
    assert!(applied[0] < -1e-4, "the follower pressure's resultant {applied:?} did not turn with the strip");
    assert!(e["points"]["corner_ur"]["displacement"][2].as_f64().unwrap() < -1.0, "the strip bends down");
}

/// `stamp check` states the model; its keys are checked.
#[test]
fn check_names_the_model_and_bad_keys_are_refused() {
    let dir = temp_dir("multi-surface-keys");
    let path = write(&dir, "ok.toml", &squeeze(4));
    let p = Problem::read(&path).unwrap();
    let setup = build(&p).unwrap();
    let report = stamp_cli::run::check::check(&p, &setup).unwrap().summary;
    assert!(report.contains("4 surfaces (displacement of degree 3 through the thickness, 3D law)"), "{report}");
    for (name, text, want) in [
        ("six", squeeze(6), vec!["plate.surfaces", "6: expected 2", "to 5"]),
        ("one", squeeze(1), vec!["plate.surfaces", "1: expected 2"]),
        ("word", squeeze(3).replace("surfaces = 3", "surfaces = \"three\""), vec!["plate.surfaces"]),
        ("shear", squeeze(3).replace("kinematics", "shear_factor = 0.8\nkinematics"), vec!["plate.shear_factor", "two-surface", "3D law"]),
        ("normal", squeeze(5).replace("kinematics", "normal_stress = \"mean\"\nkinematics"), vec!["plate.normal_stress", "surfaces = 5", "3D law"]),
    ] {
        let path = write(&dir, &format!("{name}.toml"), &text);
        let err = match Problem::read(&path).and_then(|p| build(&p).map(|_| ())) {
            Ok(()) => panic!("{name}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(err.contains(&format!("{name}.toml")), "{name}: the file is not named: {err}");
        for w in want {
            assert!(err.contains(w), "{name}: '{w}' missing from: {err}");
        }
    }
}

/// The 3D stresses of a plate of four surfaces without layers, at every surface in the .vtu and
/// through the thickness in a thickness probe: a uniform stretch e along x1, free to contract (a
/// face offset from x3 = 0: delta- = -0.05, delta+ = 0.15), is 3D elasticity's uniaxial stress
/// s11 = E e, the other five 0, u = (e x1, -nu e x2, -nu e (x3 - delta-)), exactly (a patch test),
/// in every cell, at every surface, inside a cell, at a node and at a corner on two symmetry planes.
#[test]
fn stresses_of_a_plate_without_layers_at_every_surface() {
    let dir = temp_dir("multi-surface-stresses");
    let (e, l, dm) = (1.0e-3, 2.0, -0.05);
    let text = format!(
        r#"[mesh]
rectangle = {{ x = [0.0, {l}], y = [0.0, 1.0], n = [3, 2] }}

[plate]
delta_minus = {dm}
delta_plus = 0.15
E = {E}
nu = {NU}
surfaces = 4
kinematics = "linear"

[[boundary]]
group = "left"
fix = ["symmetry_x1", "v3-"]

[[boundary]]
group = "bottom"
fix = ["symmetry_x2"]

[[boundary]]
group = "right"
prescribe = {{ "v1" = {} }}

[[output.thickness_probe]]
name = "inside"
at = [0.7, 0.4]
points_per_layer = 5

[[output.thickness_probe]]
name = "node"
at = [{}, 0.5]

[[output.thickness_probe]]
name = "corner"
at = [0.0, 0.0]
"#,
        e * l,
        l / 3.0
    );
    let path = write(&dir, "stretch.toml", &text);
    let out = dir.join("out");
    stamp_cli::run::run(&path, Some(&out), true).unwrap();
    let s11 = E * e;
    let arrays = summary(&out)["cell_arrays"].clone();
    // the .vtu: [s11, s22, s33, s12, s23, s13] in every cell at each of the four surfaces
    // the last written step: load factor 1
    let last = |prefix: &str| {
        let mut f: Vec<String> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).filter(|f| f.starts_with(prefix)).collect();
        f.sort();
        out.join(f.last().unwrap())
    };
    assert_eq!(last_step(&out)["load_factor"].as_f64(), Some(1.0));
    let vtk = vtkio::Vtk::import(last("stretch_0")).unwrap();
    let vtkio::model::DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!("not an unstructured grid") };
    let vtkio::model::Piece::Inline(piece) = &pieces[0] else { panic!("not inline") };
    for s in 0..4 {
        let name = format!("stress_layer0_surface{s}");
        assert!(arrays.as_array().unwrap().iter().any(|a| a == &Value::from(name.clone())), "{name} not in {arrays}");
        let data = piece.data.cell.iter().find_map(|a| match a {
            vtkio::model::Attribute::DataArray(d) if d.name == name => Some(d.data.clone().cast_into::<f64>().unwrap()),
            _ => None,
        });
        let data = data.unwrap_or_else(|| panic!("{name} missing from the .vtu"));
        assert_eq!(data.len(), 6 * 6);
        for cell in data.chunks(6) {
            let want = [s11, 0.0, 0.0, 0.0, 0.0, 0.0];
            for c in 0..6 {
                assert!((cell[c] - want[c]).abs() <= 1e-9 * s11, "{name}: {cell:?} against {want:?}");
            }
        }
    }
    for (probe, x1, x2) in [("inside", 0.7, 0.4), ("node", l / 3.0, 0.5), ("corner", 0.0, 0.0)] {
        let text = std::fs::read_to_string(last(&format!("thickness_{probe}_"))).unwrap();
        let rows: Vec<Vec<f64>> = text.lines().skip(1).map(|r| r.split(',').map(|v| v.parse().unwrap()).collect()).collect();
        assert_eq!(rows.len(), if probe == "inside" { 5 } else { 9 });
        assert!((rows[0][0] - dm).abs() < 1e-15 && (rows.last().unwrap()[0] - 0.15).abs() < 1e-15, "x3 from the bottom face to the top: {text}");
        for r in &rows {
            let want = [r[0], 0.0, e * x1, -NU * e * x2, -NU * e * (r[0] - dm), s11, 0.0, 0.0, 0.0, 0.0, 0.0];
            for c in 2..11 {
                let scale = if c < 5 { e } else { s11 };
                assert!((r[c] - want[c]).abs() <= 1e-9 * scale, "{probe}, column {c}: {r:?} against {want:?}");
            }
        }
    }
}

//! Laminates through problem files: `[[material]]` tables and `[plate] layers` with `surfaces` per
//! layer, a pressure written as an expression in x1, x2. Pagano's cross-ply plate run by the
//! program against the exact 3D solution; a squeezed orthotropic stack against 3D elasticity's
//! uniform state; `stamp check` listing the stack; the keys refused with their names.

#[path = "../../tests/common/pagano.rs"]
#[allow(dead_code)]
mod pagano;
mod common;
use common::*;
use serde_json::Value;
use stamp_cli::run::{build::build, Problem};
use stamp_elements::orthotropic::rotate;
use stamp_elements::{Orthotropic, PlyMaterial};

fn last_step(out: &std::path::Path) -> Value {
    summary(out)["steps"].as_array().unwrap().last().unwrap().clone()
}

const PLY: &str = r#"[[material]]
name = "ply"
E = [25.0, 1.0, 1.0]
G = [0.5, 0.5, 0.2]
nu = [0.25, 0.25, 0.25]
"#;

/// The quarter [0, a/2]^2 of Pagano's simply supported square [0/90/90/0] plate (a = 10, h = 1)
/// under q0 sin(pi x1/a) sin(pi x2/a) on the top face, diaphragm supports (v2, v3 on x1 = 0; v1, v3
/// on x2 = 0: both faces, hence the whole fibre), symmetry on the other two edges.
fn pagano_problem(n: usize, per_layer: usize) -> String {
    format!(
        r#"[mesh]
rectangle = {{ x = [0.0, 5.0], y = [0.0, 5.0], n = [{n}, {n}] }}

{PLY}
[plate]
layers = [
  {{ thickness = 0.25, material = "ply", angle = 0.0 }},
  {{ thickness = 0.25, material = "ply", angle = 90.0 }},
  {{ thickness = 0.25, material = "ply", angle = 90.0 }},
  {{ thickness = 0.25, material = "ply", angle = 0.0 }},
]
surfaces = {per_layer}
kinematics = "linear"

[[boundary]]
group = "left"
fix = ["v2", "v3"]

[[boundary]]
group = "bottom"
fix = ["v1", "v3"]

[[boundary]]
group = "right"
fix = ["symmetry_x1"]

[[boundary]]
group = "top"
fix = ["symmetry_x2"]

[[load]]
type = "pressure"
group = "all"
pressure = "sin(pi*x1/10)*sin(pi*x2/10)"
face = "top"
"#
    )
}

/// Pagano's plate of the `angles` (equal plies, h = 1, a = S) as a problem file, with thickness
/// probes at the centre (a/2, a/2) and the edge midpoints (0, a/2) and (a/2, 0).
fn pagano_general(angles: &[f64], sr: f64, n: usize, per_layer: usize) -> String {
    let t = 1.0 / angles.len() as f64;
    let layers: Vec<String> = angles.iter().map(|a| format!("  {{ thickness = {t}, material = \"ply\", angle = {a} }},")).collect();
    let half = 0.5 * sr;
    pagano_problem(n, per_layer)
        .replace("x = [0.0, 5.0], y = [0.0, 5.0]", &format!("x = [0.0, {half}], y = [0.0, {half}]"))
        .replace(&pagano_problem(n, per_layer)[pagano_problem(n, per_layer).find("  {").unwrap()..pagano_problem(n, per_layer).find("]\nsurfaces").unwrap()], &format!("{}\n", layers.join("\n")))
        .replace("sin(pi*x1/10)*sin(pi*x2/10)", &format!("sin(pi*x1/{sr})*sin(pi*x2/{sr})"))
        + &format!(
            "\n[[output.thickness_probe]]\nname = \"centre\"\nat = [{half}, {half}]\n\n[[output.thickness_probe]]\nname = \"edge1\"\nat = [0.0, {half}]\npoints_per_layer = 5\n\n[[output.thickness_probe]]\nname = \"edge2\"\nat = [{half}, 0.0]\n"
        )
}

/// Run the problem `text` as `<name>.toml` in `dir`; per step its load factor, the x3 reaction of
/// the punch named "sphere" and the x3 displacement of the point group `corner_ll`.
fn sphere_steps(dir: &std::path::Path, name: &str, text: &str) -> Vec<(f64, f64, f64)> {
    let path = write(dir, &format!("{name}.toml"), text);
    let out = dir.join(name);
    stamp_cli::run::run(&path, Some(&out), true).unwrap();
    let s = summary(&out);
    s["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|st| (st["load_factor"].as_f64().unwrap(), st["punches"]["sphere"]["reaction"][2].as_f64().unwrap(), st["points"]["corner_ll"]["displacement"][2].as_f64().unwrap()))
        .collect()
}

fn read_csv(path: &std::path::Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("x3,layer,u1,u2,u3,s11,s22,s33,s12,s13,s23"));
    lines.map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect()
}

/// The thickness probes against the exact solution: per column, the largest difference over the
/// rows relative to the column's largest exact value (s11, s22, s33, u3 at the centre, s13 at
/// (0, a/2), s23 at (a/2, 0)), and at the interfaces the jump of s13 and s23 between the two
/// layers' rows relative to the same.
fn probe_errors(angles: &[f64], sr: f64, n: usize, per_layer: usize) -> ([f64; 6], f64) {
    probe_errors_with(angles, sr, n, per_layer, "law")
}

fn probe_errors_with(angles: &[f64], sr: f64, n: usize, per_layer: usize, shear: &str) -> ([f64; 6], f64) {
    let dir = temp_dir(&format!("laminate-probe-{}-{sr}-{per_layer}-{n}-{shear}", angles.len()));
    let path = write(&dir, "p.toml", &pagano_general(angles, sr, n, per_layer).replace("at = [", &format!("transverse_shear = \"{shear}\"\nat = [")));
    let out = dir.join("out");
    stamp_cli::run::run(&path, Some(&out), true).unwrap();
    let m = PlyMaterial::Orthotropic(Orthotropic::new([25.0, 1.0, 1.0], [0.5, 0.5, 0.2], [0.25; 3]).unwrap());
    let t = 1.0 / angles.len() as f64;
    let layers = angles.iter().map(|a| pagano::Layer { thickness: t, c: rotate(&m.stiffness(), a.to_radians()) }).collect();
    let exact = pagano::Pagano::new(layers, sr, sr, -1.0); // the pressure pushes down
    let half = 0.5 * sr;
    let mut err = [0.0f64; 6];
    let mut jump = 0.0f64;
    for (probe, x, y, cols) in [("centre", half, half, vec![(5, 0, 0), (6, 1, 1), (7, 2, 2), (4, 9, 3)]), ("edge1", 0.0, half, vec![(9, 4, 4)]), ("edge2", half, 0.0, vec![(10, 3, 5)])] {
        // the last written step: load factor 1
        let mut files: Vec<_> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).filter(|f| f.starts_with(&format!("thickness_{probe}_"))).collect();
        files.sort();
        let rows = read_csv(&out.join(files.last().unwrap()));
        for (col, comp, slot) in cols {
            let want = |r: &Vec<f64>| if comp == 9 { exact.displacement(x, y, r[0])[2] } else { exact.stress(r[1] as usize, x, y, r[0])[comp] };
            let scale = rows.iter().map(|r| want(r).abs()).fold(0.0, f64::max);
            for r in &rows {
                err[slot] = err[slot].max((r[col] - want(r)).abs() / scale);
            }
            if col == 9 || col == 10 {
                for w in rows.windows(2) {
                    if w[0][0] == w[1][0] {
                        jump = jump.max((w[0][col] - w[1][col]).abs() / scale);
                    }
                }
            }
        }
    }
    (err, jump)
}

/// The stresses through the thickness (3D law at each point, thickness probes) against Pagano's
/// exact solution, [0/90/90/0] and [0/90] at a/h = 4 and 10, 12 x 12 quarter elements; the .vtu
/// has the stresses at every surface of every layer.
#[test]
fn thickness_probes_against_the_exact_solution() {
    println!("largest error over the thickness, % of the column's largest exact value: s11 s22 s33 u3 (centre) s13 (0, a/2) s23 (a/2, 0) | jump of s13, s23 at an interface");
    for angles in [&[0.0, 90.0, 90.0, 0.0][..], &[0.0, 90.0][..]] {
        for sr in [4.0, 10.0] {
            for per_layer in [3, 4, 5] {
                let (e, jump) = probe_errors(angles, sr, 12, per_layer);
                println!("{angles:?} S = {sr} N = {per_layer}: {} | {:.3}", e.map(|x| format!("{:.3}", 100.0 * x)).join(" "), 100.0 * jump);
                if per_layer == 5 {
                    // the transverse stresses of thick dissimilar plies ([0/90]: two plies of h/2)
                    // converge last: the shear 3 % at a/h = 4, s33 1.05 % at a/h = 10
                    let shear_bound = if angles.len() == 4 { 0.01 } else { 0.04 };
                    for (i, x) in e.iter().enumerate() {
                        let bound = match i {
                            4 | 5 => shear_bound,
                            2 if angles.len() == 2 => 0.02,
                            _ => 0.01,
                        };
                        assert!(*x < bound, "{angles:?}, S = {sr}: column {i} off by {:.3} % of its largest value", 100.0 * x);
                    }
                    assert!(jump < shear_bound, "{angles:?}, S = {sr}: the transverse shear jumps by {:.3} % at an interface", 100.0 * jump);
                }
            }
        }
    }
}

/// The program's centre deflection within 0.1 % of the exact one (the element's own convergence
/// is in tests/laminate_pagano.rs); `stamp check` lists the stack.
#[test]
fn paganos_plate_through_a_problem_file() {
    let dir = temp_dir("laminate-pagano");
    let path = write(&dir, "pagano.toml", &pagano_problem(12, 4));
    let p = Problem::read(&path).unwrap();
    let setup = build(&p).unwrap();
    let report = stamp_cli::run::check::check(&p, &setup).unwrap().summary;
    for want in ["4 layers of 4 surfaces each (13 surfaces", "layer 0: x3 from -0.5 to -0.25", "'ply' (orthotropic E = [25, 1, 1]", "angle 90 degrees"] {
        assert!(report.contains(want), "'{want}' missing from the summary:\n{report}");
    }
    let out = dir.join("out");
    stamp_cli::run::run(&path, Some(&out), true).unwrap();
    assert_eq!(summary(&out)["surfaces"].as_u64(), Some(13));
    let layers = summary(&out)["layers"].clone();
    assert_eq!(layers[1], serde_json::json!({"bottom": -0.25, "top": 0.0, "material": "ply", "angle": 90.0, "surfaces": 4}), "{layers}");
    let arrays = summary(&out)["cell_arrays"].clone();
    assert!(arrays.as_array().unwrap().iter().any(|a| a == "stress_layer3_surface3"), "{arrays}");
    let vtu = std::fs::read_to_string(out.join("pagano_0001.vtu")).unwrap();
    assert!(vtu.contains("stress_layer0_surface0") && vtu.contains("NumberOfComponents=\"6\""), "the .vtu lacks the stresses");
    let w = last_step(&out)["points"]["corner_ur"]["displacement"][2].as_f64().unwrap();
    let m = PlyMaterial::Orthotropic(Orthotropic::new([25.0, 1.0, 1.0], [0.5, 0.5, 0.2], [0.25; 3]).unwrap());
    let layers = [0.0, 90.0, 90.0, 0.0].map(|a: f64| pagano::Layer { thickness: 0.25, c: rotate(&m.stiffness(), a.to_radians()) }).to_vec();
    // the exact solution for an upward load; the problem's pressure pushes down
    let exact = -pagano::Pagano::new(layers, 10.0, 10.0, 1.0).displacement(5.0, 5.0, 0.0)[2];
    println!("centre deflection {w}, exact {exact} ({:+.4} %)", 100.0 * (w / exact - 1.0));
    assert!((w / exact - 1.0).abs() < 1e-3, "centre deflection {w} against the exact {exact}");
}

/// Two plies of one orthotropic material turned by 90 degrees, on a frictionless rigid base
/// (v3- = 0), pressed by q on the top face, free to spread: 3D elasticity gives the uniform state
/// S33 = -q, so the plate thins by q h / E3 and spreads by nu23 q / E2 along x1 (the plies' axis 2)
/// and nu13 q / E1 along x2 (their fibres). Exact for any number of surfaces: also for 44 plies of
/// 3 surfaces (89 surfaces, 267 unknowns a node, past the 255 a u8 counted: "singular" before).
#[test]
fn a_squeezed_orthotropic_stack_is_3d_elasticity_exactly() {
    let dir = temp_dir("laminate-squeeze");
    let (e1, e2, e3, n13, n23, q, h) = (25.0, 1.0, 1.3, 0.3, 0.35, 0.01, 0.2);
    for (plies, per_layer) in [(2, 3), (2, 5), (44, 3)] {
        let layers = vec![format!("{{ thickness = {}, material = \"ply\", angle = 90.0 }}", h / plies as f64); plies].join(", ");
        let text = format!(
            r#"[mesh]
rectangle = {{ x = [0.0, 1.0], y = [0.0, 1.0], n = [3, 2] }}

[[material]]
name = "ply"
E = [{e1}, {e2}, {e3}]
G = [0.5, 0.4, 0.2]
nu = [0.25, {n13}, {n23}]

[plate]
layers = [{layers}]
surfaces = {per_layer}
kinematics = "linear"

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
pressure = {q}
face = "top"
"#
        );
        let path = write(&dir, &format!("s{plies}-{per_layer}.toml"), &text);
        let out = dir.join(format!("s{plies}-{per_layer}"));
        stamp_cli::run::run(&path, Some(&out), true).unwrap();
        let corner = &last_step(&out)["points"]["corner_ur"];
        let top = corner["displacement_top"][2].as_f64().unwrap();
        assert!((top + q * h / e3).abs() <= 1e-8 * q * h / e3, "{per_layer}: the top face moves by {top}, 3D: {}", -q * h / e3);
        for (c, want) in [(0, n23 * q / e2), (1, n13 * q / e1)] {
            let u = corner["displacement"][c].as_f64().unwrap();
            assert!((u - want).abs() <= 1e-8 * want, "{per_layer}: the corner moves by {u} along x{}, 3D: {want}", c + 1);
        }
    }
}

/// The keys of laminates refused with the key's name and the reason.
#[test]
fn bad_laminate_keys_are_refused_by_name() {
    let dir = temp_dir("laminate-keys");
    let good = pagano_problem(2, 3);
    for (name, text, want) in [
        ("with_e", good.replace("surfaces = 3", "surfaces = 3\nE = 1.0"), vec!["plate.E", "`layers` and `E` exclude each other"]),
        ("with_h", good.replace("surfaces = 3", "surfaces = 3\nthickness = 1.0"), vec!["plate.thickness", "exclude each other"]),
        ("no_surfaces", good.replace("surfaces = 3\n", ""), vec!["plate.surfaces", "3 to 5"]),
        ("two_surfaces", good.replace("surfaces = 3", "surfaces = 2"), vec!["plate.surfaces", "3 to 5, got 2"]),
        ("unknown", good.replacen("material = \"ply\", angle = 90.0", "material = \"carbon\", angle = 90.0", 1), vec!["plate.layers[1].material", "no [[material]] is named 'carbon'", "'ply'"]),
        ("no_g", good.replace("G = [0.5, 0.5, 0.2]\n", ""), vec!["material[0].G", "orthotropic"]),
        ("iso_g", good.replace("E = [25.0, 1.0, 1.0]", "E = 25.0"), vec!["material[0].G", "isotropic"]),
        ("two_e", good.replace("E = [25.0, 1.0, 1.0]", "E = [25.0, 1.0]"), vec!["E", "three numbers", "got 2"]),
        ("unstable", good.replace("nu = [0.25, 0.25, 0.25]", "nu = [0.25, 0.25, 1.5]"), vec!["material[0]", "not positive definite"]),
        ("thin", good.replacen("thickness = 0.25", "thickness = -0.25", 1), vec!["plate.layers[0].thickness", "positive"]),
        ("ply_1e-101", good.replacen("thickness = 0.25", "thickness = 1e-101", 1), vec!["plate.layers[0].thickness", "from 1e-100 to 1e100"]),
        ("tiny_e", good.replace("E = [25.0, 1.0, 1.0]", "E = [25.0, 1e-300, 1.0]"), vec!["material[0].E", "positive moduli from 1e-100 to 1e100"]),
        ("huge_g", good.replace("G = [0.5, 0.5, 0.2]", "G = [0.5, 1e300, 0.2]"), vec!["material[0].G", "positive moduli from 1e-100 to 1e100"]),
        ("unused", pagano_problem(2, 3).replace("layers = [", "E = 1.0\nnu = 0.3\nthickness = 1.0\nxlayers = ["), vec!["unknown field `xlayers`"]),
        ("no_e", good.replace("layers = [", "xx = [").replace("surfaces = 3", ""), vec!["unknown field `xx`"]),
        ("expression", good.replace("sin(pi*x1/10)", "sin(pi*x1/10"), vec!["load[0].pressure", "')'"]),
        ("overflow", good.replace("sin(pi*x1/10)", "1.7e308*sin(pi*x1/10)"), vec!["load[0].pressure", "beyond 1e100, the largest magnitude"]),
        ("huge", good.replace("sin(pi*x1/10)", "1e300*sin(pi*x1/10)"), vec!["load[0].pressure", "beyond 1e100, the largest magnitude"]),
        ("x3", good.replace("sin(pi*x1/10)", "sin(pi*x3/10)"), vec!["load[0].pressure", "cannot use x3"]),
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
    // a [[material]] without layers
    let text = format!("{}\n{PLY}", include_str!("../../meshes/sphere-ss-displacement.toml"));
    let err = Problem::parse(std::path::Path::new("m.toml"), text).and_then(|p| build(&p).map(|_| ())).err().expect("refused").to_string();
    assert!(err.contains("material[0]") && err.contains("[plate] layers"), "{err}");
    // E without nu in a homogeneous plate
    let err = Problem::parse(std::path::Path::new("n.toml"), include_str!("../../meshes/sphere-ss-displacement.toml").replace("nu = 0.3", "")).err().expect("refused").to_string();
    assert!(err.contains("plate.nu") && err.contains("missing"), "{err}");
}

/// One isotropic layer of four surfaces is the plate of `surfaces = 4`, through the whole program:
/// a sphere pressed into the top face (nonlinear, displacement driven, the coarse predictor), the
/// same reaction and deflection at every step to Newton's tolerance (the two assemble the same
/// element in another order: measured 2e-9 relative); `--refine` runs the laminate too.
#[test]
fn one_layer_runs_as_the_multi_surface_plate_with_contact_and_the_coarse_predictor() {
    let dir = temp_dir("laminate-sphere");
    let base = include_str!("../../meshes/sphere-ss-displacement.toml").replace("\n[solver]\n", "\n[solver]\npredictor = \"coarse\"\n");
    assert!(base.contains("predictor = \"coarse\"\n"));
    let plain = base.replace("nu = 0.3\n", "nu = 0.3\nsurfaces = 4\n");
    let layered = format!(
        "{}\n[[material]]\nname = \"steel\"\nE = 2.1e5\nnu = 0.3\n",
        base.replace("thickness = 1.0\nE = 2.1e5\nnu = 0.3\n", "layers = [{ thickness = 1.0, material = \"steel\" }]\nsurfaces = 4\n")
    );
    assert!(layered.contains("layers") && plain.contains("surfaces = 4"));
    let results: Vec<_> = [("plain", &plain), ("layered", &layered)].into_iter().map(|(name, text)| sphere_steps(&dir, name, text)).collect();
    assert_eq!(results[0].len(), results[1].len(), "the same steps");
    for (a, b) in results[0].iter().zip(&results[1]) {
        assert_eq!(a.0, b.0);
        assert!((a.1 - b.1).abs() <= 1e-7 * a.1.abs() && a.1.abs() > 0.0, "force {} against {}", a.1, b.1);
        assert!((a.2 - b.2).abs() <= 1e-7 * a.2.abs(), "deflection {} against {}", a.2, b.2);
    }
    let path = write(&dir, "refine.toml", &layered);
    stamp_cli::run::refine::run_refined(&path, Some(&dir.join("refined")), true, 1).unwrap();
    assert!(summary(&dir.join("refined"))["status"].as_str().is_some());
}

/// Thickness probes refused with their key: without layers, outside the plate, bad counts and names.
#[test]
fn bad_thickness_probes_are_refused_by_name() {
    let dir = temp_dir("laminate-probe-keys");
    let probe = |at: &str, extra: &str| format!("\n[[output.thickness_probe]]\nname = \"c\"\nat = {at}\n{extra}");
    let homogeneous = include_str!("../../meshes/sphere-ss-displacement.toml").to_string() + &probe("[1.0, 1.0]", "");
    for (name, text, want) in [
        ("no_layers", homogeneous, vec!["output.thickness_probe[0]", "needs `layers`"]),
        ("count", pagano_problem(2, 3) + &probe("[1.0, 1.0]", "points_per_layer = 1\n"), vec!["output.thickness_probe[0].points_per_layer", "got 1"]),
        ("name", pagano_problem(2, 3) + &probe("[1.0, 1.0]", "").replace("\"c\"", "\"a b\""), vec!["output.thickness_probe[0].name"]),
        ("twice", pagano_problem(2, 3) + &probe("[1.0, 1.0]", "") + &probe("[2.0, 1.0]", ""), vec!["output.thickness_probe[1].name", "two thickness probes"]),
        ("shear", pagano_problem(2, 3) + &probe("[1.0, 1.0]", "transverse_shear = \"both\"\n"), vec!["output.thickness_probe[0].transverse_shear", "\"law\" or \"equilibrium\"", "both"]),
        ("stresses", pagano_problem(2, 3) + &probe("[1.0, 1.0]", "stresses = \"both\"\n"), vec!["output.thickness_probe[0].stresses", "\"recovered\" or \"law\"", "both"]),
        (
            "recovered_shear",
            pagano_problem(2, 3) + &probe("[1.0, 1.0]", "stresses = \"recovered\"\ntransverse_shear = \"equilibrium\"\n"),
            vec!["output.thickness_probe[0].transverse_shear", "applies to stresses = \"law\""],
        ),
    ] {
        let path = write(&dir, &format!("{name}.toml"), &text);
        let err = Problem::read(&path).err().unwrap_or_else(|| panic!("{name}: accepted")).to_string();
        for w in want {
            assert!(err.contains(w), "{name}: '{w}' missing from: {err}");
        }
    }
    let path = write(&dir, "strip.toml", &(pagano_problem(2, 3).replace("n = [2, 2]", "n = [4, 1]") + &probe("[1.0, 1.0]", "transverse_shear = \"equilibrium\"\n")));
    let err = stamp_cli::run::run(&path, Some(&dir.join("strip")), true).err().expect("refused").to_string();
    assert!(err.contains("output.thickness_probe[0].transverse_shear") && err.contains("one cell wide"), "{err}");
    let path = write(&dir, "strip_recovered.toml", &(pagano_problem(2, 3).replace("n = [2, 2]", "n = [4, 1]") + &probe("[1.0, 1.0]", "stresses = \"recovered\"\n")));
    let err = stamp_cli::run::run(&path, Some(&dir.join("strip_recovered")), true).err().expect("refused").to_string();
    assert!(err.contains("output.thickness_probe[0].stresses") && err.contains("one cell wide"), "{err}");
    let path = write(&dir, "outside.toml", &(pagano_problem(2, 3) + &probe("[7.0, 1.0]", "")));
    let err = stamp_cli::run::run(&path, Some(&dir.join("outside")), true).err().expect("refused").to_string();
    assert!(err.contains("output.thickness_probe[0].at") && err.contains("not on the plate"), "{err}");
}

/// A thickness probe on a node or an edge averages the cells that hold the point, and on a
/// symmetry plane their mirror images: Pagano's [0/90/90/0] plate (a/h = 4) whole on 8 x 8
/// elements and its quarter on 4 x 4 give the same rows to round-off at the centre (a node of four
/// cells in the whole plate, a corner on both symmetry planes of the quarter), on the symmetry
/// line between two nodes (an inner edge of the whole plate) and inside a cell; at the centre the
/// transverse shears and s12 vanish (to round-off in the whole plate, exactly in the quarter).
#[test]
fn thickness_probes_average_cells_and_mirror_images() {
    let dir = temp_dir("laminate-probe-nodes");
    let (sr, le) = (4.0, 0.5);
    let probes = [("centre", 2.0, 2.0), ("edge", 2.0, 2.0 - 0.5 * le), ("inside", 2.0 - 0.3 * le, 2.0 - 0.2 * le)];
    let mut text = pagano_general(&[0.0, 90.0, 90.0, 0.0], sr, 4, 3);
    text.truncate(text.find("\n[[output.thickness_probe]]").unwrap());
    for (name, x, y) in probes {
        text += &format!("\n[[output.thickness_probe]]\nname = \"{name}\"\nat = [{x}, {y}]\npoints_per_layer = 4\n");
    }
    let whole = text
        .replace("x = [0.0, 2], y = [0.0, 2], n = [4, 4]", "x = [0.0, 4], y = [0.0, 4], n = [8, 8]")
        .replace("fix = [\"symmetry_x1\"]", "fix = [\"v2\", \"v3\"]")
        .replace("fix = [\"symmetry_x2\"]", "fix = [\"v1\", \"v3\"]");
    assert!(whole.contains("n = [8, 8]") && !whole.contains("symmetry"), "{whole}");
    let mut tables = Vec::new();
    for (name, t) in [("quarter", &text), ("whole", &whole)] {
        let path = write(&dir, &format!("{name}.toml"), t);
        let out = dir.join(name);
        stamp_cli::run::run(&path, Some(&out), true).unwrap();
        tables.push(probes.map(|(p, _, _)| read_csv(&out.join(format!("thickness_{p}_0001.csv")))));
    }
    for (i, (p, _, _)) in probes.iter().enumerate() {
        let (q, w) = (&tables[0][i], &tables[1][i]);
        assert_eq!(q.len(), 16);
        for col in 2..11 {
            // the column's largest value over the three probes
            let scale = tables[1].iter().flatten().map(|r| r[col].abs()).fold(0.0, f64::max);
            for (a, b) in q.iter().zip(w) {
                assert!((a[col] - b[col]).abs() <= 1e-8 * scale, "{p}, column {col}: quarter {} whole {}", a[col], b[col]);
            }
        }
    }
    let (q, w) = (&tables[0][0], &tables[1][0]);
    // round-off against the stresses' size: the largest s11 at the centre
    let s11_max = w.iter().map(|r| r[5].abs()).fold(0.0, f64::max);
    assert!(s11_max > 0.0);
    for (a, b) in q.iter().zip(w) {
        for col in [8, 9, 10] {
            assert_eq!(a[col], 0.0, "quarter's centre, column {col}");
            assert!(b[col].abs() <= 1e-12 * s11_max, "whole plate's centre, column {col}: {} (s11 up to {s11_max})", b[col]);
        }
        assert!(a[5].abs() > 0.0 && a[4] != 0.0);
    }
}

/// `transverse_shear = "equilibrium"`: s13 and s23 integrated from the bottom face through the
/// thickness (equilibrium_shear.rs) against Pagano's exact solution, beside the 3D law's: continuous
/// at the interfaces by construction, converging with the mesh (like l^2), and far better than the
/// law where the law is poor ([0/90] at a/h = 4, the plies h/2 thick: 0.37 % on 24 x 24 quarter
/// elements against the law's 2.9 %).
#[test]
fn equilibrium_transverse_shear_against_the_exact_solution() {
    println!("largest error of s13 (0, a/2) and s23 (a/2, 0) over the thickness, % of the largest exact value; n x n quarter elements");
    for (angles, sr, per_layer) in [(&[0.0, 90.0, 90.0, 0.0][..], 10.0, 4), (&[0.0, 90.0][..], 4.0, 5)] {
        let mut eq = Vec::new();
        for n in [12, 24] {
            let (law, law_jump) = probe_errors_with(angles, sr, n, per_layer, "law");
            let (e, jump) = probe_errors_with(angles, sr, n, per_layer, "equilibrium");
            println!(
                "{angles:?} S = {sr} N = {per_layer} n = {n}: law {:.3} / {:.3} (interface jump {:.3}), equilibrium {:.3} / {:.3} (jump {:.1e})",
                100.0 * law[4],
                100.0 * law[5],
                100.0 * law_jump,
                100.0 * e[4],
                100.0 * e[5],
                100.0 * jump
            );
            assert!(jump < 1e-12, "{angles:?}: the integrated shear jumps at an interface by {jump}");
            // the other columns are the law's, unchanged
            for c in 0..4 {
                assert_eq!(e[c], law[c], "{angles:?}: column {c} changed");
            }
            eq.push(e[4].max(e[5]));
            if n == 24 {
                assert!(e[4].max(e[5]) < 0.006, "{angles:?}, S = {sr}: the integrated shear is off by {:.3} %", 100.0 * e[4].max(e[5]));
                if angles.len() == 2 {
                    assert!(e[4].max(e[5]) < 0.25 * law[4].max(law[5]), "[0/90]: the integrated shear {:?} is not clearly better than the law's {:?}", e, law);
                }
            }
        }
        assert!(eq[1] < 0.4 * eq[0], "{angles:?}: the integrated shear does not converge with the mesh: {eq:?}");
    }
}

/// Contact and a follower pressure on either face of a laminate: an unsymmetric [0/90] stack
/// pressed from above (a sphere and a follower pressure on the top face, moving down) is the
/// mirror image (x3 -> -x3) of the [90/0] stack pressed from below (the same on the bottom
/// face, moving up): the same punch force, opposite, and the mirrored deflection at every step,
/// to Newton's tolerance; and a face that does not hold the stack's own order differs.
#[test]
fn a_laminate_pressed_from_below_is_the_mirror_of_one_pressed_from_above() {
    let dir = temp_dir("laminate-mirror");
    let problem = |bottom_angle: f64, top_angle: f64, face: &str| {
        let (z, dz) = if face == "top" { (200.5, -0.3) } else { (-200.5, 0.3) };
        format!(
            r#"[mesh]
rectangle = {{ x = [0.0, 20.0], y = [0.0, 20.0], n = [6, 6] }}

[[material]]
name = "ply"
E = [2.5e4, 1.0e3, 1.0e3]
G = [500.0, 500.0, 200.0]
nu = [0.25, 0.25, 0.25]

[plate]
layers = [{{ thickness = 0.5, material = "ply", angle = {bottom_angle} }}, {{ thickness = 0.5, material = "ply", angle = {top_angle} }}]
surfaces = 3

[[boundary]]
group = "left"
fix = ["symmetry_x1"]

[[boundary]]
group = "bottom"
fix = ["symmetry_x2"]

[[boundary]]
group = "right"
fix = ["simply_supported"]

[[boundary]]
group = "top"
fix = ["simply_supported"]

[[load]]
type = "pressure"
group = "all"
pressure = "0.001*(1 + x1/20)"
follower = true
face = "{face}"

[[punch]]
name = "sphere"
shape = "sphere"
center = [0.0, 0.0, {z}]
radius = 200.0
motion = [0.0, 0.0, {dz}]
face = "{face}"

[solver]
steps = 3
rel_tol = 1e-11
"#
        )
    };
    let results: Vec<_> = [("above", problem(0.0, 90.0, "top")), ("below", problem(90.0, 0.0, "bottom")), ("below-unmirrored", problem(0.0, 90.0, "bottom"))]
        .into_iter()
        .map(|(name, text)| sphere_steps(&dir, name, &text))
        .collect();
    assert_eq!(results[0].len(), results[1].len(), "the same steps");
    for (a, b) in results[0].iter().zip(&results[1]) {
        assert_eq!(a.0, b.0);
        assert!(a.1 < 0.0 && b.1 > 0.0, "pressed down from above, up from below: {} {}", a.1, b.1);
        assert!((a.1 + b.1).abs() <= 1e-7 * a.1.abs(), "force {} against {}", a.1, b.1);
        assert!((a.2 + b.2).abs() <= 1e-7 * a.2.abs() && a.2 < 0.0, "deflection {} against {}", a.2, b.2);
    }
    // the stack's order matters: [0/90] from below is not the mirror of [0/90] from above
    let (a, c) = (results[0].last().unwrap(), results[2].last().unwrap());
    assert!((a.1 + c.1).abs() > 1e-5 * a.1.abs(), "force {} against {}", a.1, c.1);
}

/// `transverse_shear = "equilibrium"` in the cell next but one to a symmetry plane: the quarter
/// plate's probe reads what the half plate's reads at the same point (the fit's patch unfolded
/// across the plane; before, the quarter's patch stopped at the plane and its s13 was 9 % off).
#[test]
fn equilibrium_shear_near_a_symmetry_plane_reads_as_on_the_larger_model() {
    let dir = temp_dir("laminate-equilibrium-symmetry");
    let probe = "\n[[output.thickness_probe]]\nname = \"near\"\nat = [4.0625, 1.5625]\ntransverse_shear = \"equilibrium\"\n";
    let quarter = pagano_problem(8, 3) + probe;
    // the half plate [0, 10] x [0, 5]: diaphragms on x1 = 0 and 10, the symmetry plane x2 = 5
    let half = quarter
        .replace("x = [0.0, 5.0], y = [0.0, 5.0], n = [8, 8]", "x = [0.0, 10.0], y = [0.0, 5.0], n = [16, 8]")
        .replace("group = \"right\"\nfix = [\"symmetry_x1\"]", "group = \"right\"\nfix = [\"v2\", \"v3\"]");
    assert_ne!(half, quarter);
    let mut tables = Vec::new();
    for (name, text) in [("quarter", &quarter), ("half", &half)] {
        let path = write(&dir, &format!("{name}.toml"), text);
        let out = dir.join(name);
        stamp_cli::run::run(&path, Some(&out), true).unwrap();
        tables.push(read_csv(&out.join("thickness_near_0001.csv")));
    }
    let largest = tables[1].iter().map(|r| r[9].abs()).fold(0.0, f64::max);
    assert!(largest > 0.0);
    for (q, h) in tables[0].iter().zip(&tables[1]) {
        for c in [9, 10] {
            assert!((q[c] - h[c]).abs() <= 1e-6 * largest, "x3 = {}: column {c}: quarter {} half {}", q[0], q[c], h[c]);
        }
    }
}

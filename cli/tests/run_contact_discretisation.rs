//! `[[punch]] contact = "nodal" | "integrated"` through `stamp run`, and the warning for a contact
//! zone narrower than the cells.

mod common;
use common::*;
use std::process::Command;

fn run(problem: &std::path::Path) -> (bool, String, serde_json::Value) {
    let out = problem.with_extension("out");
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("run").arg(problem).arg("--out").arg(&out).arg("--quiet").output().unwrap();
    let stderr = String::from_utf8(o.stderr).unwrap();
    let s = if o.status.success() { summary(&out) } else { serde_json::Value::Null };
    (o.status.success(), stderr, s)
}

fn last_punch(s: &serde_json::Value, name: &str) -> serde_json::Value {
    s["steps"].as_array().unwrap().last().unwrap()["punches"][name].clone()
}

#[test]
fn the_integrated_discretisation_gives_the_force_of_the_nodal_one() {
    // the force-driven sphere on the quarter plate: the punch's travel under the same force
    let nodal = variant("contact-nodal", "sphere-ss.toml", &[]);
    let integrated = variant("contact-integrated", "sphere-ss.toml", &[("penetration_tolerance = 1e-6", "penetration_tolerance = 1e-6\ncontact = \"integrated\"")]);
    let (ok_n, err_n, sn) = run(&nodal);
    let (ok_i, err_i, si) = run(&integrated);
    assert!(ok_n && ok_i, "{err_n}\n{err_i}");
    let (tn, ti) = (last_punch(&sn, "sphere")["drive_displacement"].as_f64().unwrap(), last_punch(&si, "sphere")["drive_displacement"].as_f64().unwrap());
    println!("travel under the full force: nodal {tn}, integrated {ti}");
    assert!((tn - ti).abs() < 0.01 * tn, "travel {tn} (nodal) against {ti} (integrated)");
    // the punch carries the applied force in both
    for s in [&sn, &si] {
        let r = last_punch(s, "sphere")["reaction"][2].as_f64().unwrap();
        assert!((r + 500.0).abs() < 1e-6 * 500.0, "reaction {r}");
    }
}

#[test]
fn integrated_contact_needs_a_surface_group() {
    let p = variant("contact-curve-group", "sphere-ss.toml", &[("penetration_tolerance = 1e-6", "penetration_tolerance = 1e-6\ncontact = \"integrated\"\ngroup = \"left\"")]);
    let (ok, err, _) = run(&p);
    assert!(!ok);
    assert!(err.contains("punch[0].contact") && err.contains("not a surface group") && err.contains("'left'"), "{err}");
    let p = variant("contact-bad-word", "sphere-ss.toml", &[("penetration_tolerance = 1e-6", "penetration_tolerance = 1e-6\ncontact = \"mortar\"")]);
    let (ok, err, _) = run(&p);
    assert!(!ok && err.contains("nodal") && err.contains("integrated"), "{err}");
}

/// A cylinder lying across the width of a plate clamped on its short edges (the problem of the
/// users' report, on 4 x 4 cells): a line load at the scale of the cells.
const ROLLER: &str = r#"title = "roller across a clamped plate"
[mesh]
rectangle = { x = [0.0, 120.0], y = [0.0, 60.0], n = [30, 15] }
[plate]
thickness = 2.0
E = 2.1e5
nu = 0.3
[[boundary]]
group = "left"
fix = ["clamped"]
[[boundary]]
group = "right"
fix = ["clamped"]
[[punch]]
name = "roller"
shape = "cylinder"
point = [60.0, 0.0, 41.0]
axis = [0.0, 1.0, 0.0]
radius = 40.0
motion = [0.0, 0.0, -3.0]
[solver]
steps = 2
[output]
plot = true
[[output.probe]]
name = "across"
from = [50.0, 30.0]
to = [70.0, 30.0]
points = 201
"#;

#[test]
fn a_line_contact_is_reported_narrower_than_the_cells_and_a_probe_reads_its_load_per_length() {
    let dir = temp_dir("roller");
    let p = write(&dir, "roller.toml", ROLLER);
    let (ok, err, s) = run(&p);
    assert!(ok, "{err}");
    let roller = last_punch(&s, "roller");
    assert_eq!(roller["zone_narrower_than_cells"], serde_json::Value::Bool(true), "{roller}");
    assert!(err.contains("narrower than the cells") && err.contains("roller_line_load"), "{err}");
    // the probe across the middle of the plate reads about the mean load per unit length, the
    // force over the width (the free edges carry a little more: 127 in the middle against a mean
    // of 124 on finer meshes)
    let step = s["steps"].as_array().unwrap().last().unwrap()["step"].as_u64().unwrap();
    let csv = std::fs::read_to_string(p.with_extension("out").join(format!("probe_across_{step:04}.csv"))).unwrap();
    let last: Vec<f64> = csv.lines().last().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    let per_length = -roller["reaction"][2].as_f64().unwrap() / 60.0;
    println!("load per unit length {per_length}: integral {} band {}", last[8], last[9]);
    assert!((last[8] - per_length).abs() < 0.04 * per_length, "integral {} against {per_length}", last[8]);
    // the band is 8 cells (32) wide here: it averages the rise towards the free edges in
    assert!((last[9] - per_length).abs() < 0.08 * per_length, "band {} against {per_length}", last[9]);
    // the probe plot's title (a second line under the first) gives both integrals
    let svg = std::fs::read_to_string(p.with_extension("out").join("probe_across.svg")).unwrap();
    assert!(svg.contains("contact pressure along probe &apos;across&apos;"), "{svg}");
    let line = svg.split("at the last step its integral is ").nth(1).and_then(|t| t.split('<').next()).map(str::trim).expect("the title's second line");
    let numbers: Vec<f64> = line.split(|c: char| c == ' ' || c == '(').filter_map(|w| w.parse().ok()).collect();
    assert!(line.ends_with("across a band of 8 cells)") && numbers.len() == 3, "{line}");
    for (shown, exact) in [(numbers[0], last[7]), (numbers[1], last[8])] {
        assert!((shown - exact).abs() <= 1e-3 * exact, "{line}: {shown} against {exact}");
    }
    // a sphere on a plate presses a disc: no warning
    let (ok, err, s) = run(&variant("sphere-wide", "sphere-ss.toml", &[]));
    assert!(ok && !err.contains("narrower"), "{err}");
    assert_eq!(last_punch(&s, "sphere")["zone_narrower_than_cells"], serde_json::Value::Bool(false));
}

/// `contact = "integrated"` works with every punch shape and driver, the multi-surface plates and
/// the coarse predictor: each shipped example run with it converges, a force-driven punch carries
/// its force, and the punch's force (or travel) is within a few
/// percent of the nodal discretisation's on these coarse meshes (both converge to the same
/// answer, docs/verification.md).
#[test]
fn the_integrated_discretisation_runs_every_punch_shape_and_feature() {
    // (example, what it adds, extra solver key, tolerance on the force or travel)
    let cases = [
        ("ellipsoid-expression", "an expression, force-driven", "", 0.02),
        ("stl-die", "an STL die", "", 0.02),
        ("sphere-slide", "a path", "", 0.06),
        ("sphere-ss-4surfaces", "four surfaces", "", 0.02),
        ("plane-cantilever", "a plane", "", 0.02),
        ("cylinder-30deg", "a cylinder, force-driven", "", 0.05),
        ("sphere-ss-displacement", "the coarse predictor", "predictor = \"coarse\"\n", 0.02),
    ];
    for (name, what, solver, tol) in cases {
        let integrated = variant(&format!("integrated-{name}"), &format!("{name}.toml"), &[("\n[[punch]]\n", "\n[[punch]]\ncontact = \"integrated\"\n"), ("\n[solver]\n", &format!("\n[solver]\n{solver}"))]);
        let nodal = variant(&format!("nodal-{name}"), &format!("{name}.toml"), &[("\n[solver]\n", &format!("\n[solver]\n{solver}"))]);
        let (ok_i, err_i, si) = run(&integrated);
        let (ok_n, err_n, sn) = run(&nodal);
        assert!(ok_i && ok_n, "{name} ({what}): {err_i}\n{err_n}");
        assert_eq!(si["status"], "converged", "{name} ({what})");
        let punch = |s: &serde_json::Value| s["steps"].as_array().unwrap().last().unwrap()["punches"].as_object().unwrap().values().next().unwrap().clone();
        let (pi, pn) = (punch(&si), punch(&sn));
        let (a, b) = match pi["drive_displacement"].as_f64() {
            // force-driven: the punch carries the force; compare the travels
            Some(travel) => {
                let f = pi["applied_force"].as_f64().unwrap();
                let r = pi["reaction"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap().powi(2)).sum::<f64>().sqrt();
                assert!((r - f).abs() < 1e-6 * f, "{name}: reaction {r} against the force {f}");
                (travel, pn["drive_displacement"].as_f64().unwrap())
            }
            None => (pi["reaction"][2].as_f64().unwrap(), pn["reaction"][2].as_f64().unwrap()),
        };
        println!("{name} ({what}): integrated {a}, nodal {b}");
        assert!((a - b).abs() <= tol * b.abs(), "{name} ({what}): integrated {a} against nodal {b}");
    }
}

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
    for (shown, exact) in [(numbers[0], last[8]), (numbers[1], last[9])] {
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
/// answer, docs/verification/contact-pressure.md).
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

/// The pooled deviation of `v` from its mean over rings 0.5 wide, over the nodes with r < `inside`,
/// over its mean there (the node-to-node variation at equal radius).
fn ring_cv(r: &[f64], v: &[f64], inside: f64) -> f64 {
    let rings = (inside / 0.5).ceil() as usize;
    let (mut sum, mut count) = (vec![0.0; rings], vec![0usize; rings]);
    for (r, v) in r.iter().zip(v) {
        if *r < inside {
            sum[(r / 0.5) as usize] += v;
            count[(r / 0.5) as usize] += 1;
        }
    }
    let (mut dev, mut total, mut n) = (0.0, 0.0, 0usize);
    for (r, v) in r.iter().zip(v) {
        if *r < inside {
            let k = (r / 0.5) as usize;
            dev += (v - sum[k] / count[k] as f64).powi(2);
            total += v;
            n += 1;
        }
    }
    (dev / n as f64).sqrt() / (total / n as f64)
}

#[test]
fn the_recovered_pressure_carries_the_force_and_is_smoother_than_the_nodal_one_on_triangles() {
    // meshes/sphere-ss-full.toml on gmsh triangles of size 2 (meshes/sphere-ss-full-tri.geo),
    // cut into quadrilaterals: the nodal pressure inside the contact zone varies by about 16 %
    // from node to node, the rectangles' by 0.1 % (docs/verification/contact-pressure.md)
    let dir = temp_dir("recovered-pressure");
    std::fs::copy(repo().join("tests/data/sphere_ss_full_tri2.msh"), dir.join("tri2.msh")).unwrap();
    let text = std::fs::read_to_string(repo().join("meshes/sphere-ss-full.toml")).unwrap().replace("sphere-ss-full.msh", "tri2.msh").replace("plot = true", "plot = false");
    std::fs::write(dir.join("tri2.toml"), text).unwrap();
    let p = stamp_problem::Problem::read(&dir.join("tri2.toml")).unwrap();
    let opts = stamp_problem::solve::SolveOptions { quiet: true, keep: true, ..Default::default() };
    let outcome = stamp_problem::solve_problem(&p, &dir.join("out"), &opts).unwrap();
    let kept = outcome.kept.unwrap();
    let step = kept.steps.last().unwrap();
    let field = |name: &str| step.point_fields.iter().find(|f| f.name == name).unwrap_or_else(|| panic!("no point array {name}")).values.clone();
    let (q, rec) = (field("contact_pressure"), field("contact_pressure_recovered"));
    let mesh = stamp::mesh::QuadMesh { coords: kept.nodes.clone(), cells: kept.cells.clone(), ..Default::default() };
    let area = mesh.nodal_areas();
    // conservative: the integral of the bilinear field, sum A_i p_i, is the sum of the nodal
    // normal forces A_i q_i
    let force: f64 = area.iter().zip(&q).map(|(a, q)| a * q).sum();
    let integral: f64 = area.iter().zip(&rec).map(|(a, p)| a * p).sum();
    println!("normal force {force}, integral of the recovered field {integral}");
    assert!(force > 1990.0, "the punch presses 2000: {force}");
    assert!((integral - force).abs() <= 1e-12 * force, "integral {integral} against {force}");
    assert!(rec.iter().all(|p| *p >= 0.0), "the smoothing of a nonnegative field is nonnegative");
    // inside the zone where the pressure is low and smooth (r < 0.35 of the contact radius; the
    // ring of contact beyond it is not axisymmetric on the square plate)
    let r: Vec<f64> = kept.nodes.iter().map(|x| x[0].hypot(x[1])).collect();
    let a = r.iter().zip(&q).filter(|(_, q)| **q > 0.0).map(|(r, _)| *r).fold(0.0, f64::max);
    let (cv_nodal, cv_rec) = (ring_cv(&r, &q, 0.35 * a), ring_cv(&r, &rec, 0.35 * a));
    println!("contact radius {a}: CV over r < {}: nodal {cv_nodal}, recovered {cv_rec}", 0.35 * a);
    assert!(cv_nodal > 0.1, "the nodal pressure is noisy on triangles: {cv_nodal}");
    assert!(cv_rec < 0.5 * cv_nodal, "recovered CV {cv_rec} against nodal {cv_nodal}");
}

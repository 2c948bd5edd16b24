//! `stamp run --refine`: the Richardson estimate against closed forms, the estimate columns of the
//! table, history.csv and summary.json against the refined run's own outputs, and a gmsh mesh
//! refined with its groups (the supports hold on the new edge nodes).

mod common;
use common::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// `stamp run <args>` (not quiet unless asked).
fn stamp(args: &[&str], problem: &Path, out: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stamp")).arg("run").args(args).arg(problem).arg("--out").arg(out).output().unwrap()
}

fn ok(o: &Output) -> String {
    let (stdout, stderr) = (String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert!(o.status.success(), "stamp run failed:\n{stdout}\n{stderr}");
    stdout.into_owned()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

// The quarter of a square plate (side A = 100, h = 1) with hard simple supports (v3 and the
// tangential in-plane displacement of both faces held), symmetry on x1 = 0 and x2 = 0, under a
// uniform pressure Q, linear kinematics. The shear-deformable plate's centre deflection is
// w = q a^4 / D (0.00406235 + 0.0736713 D / (G h a^2)) (Navier's series plus the Marcus moment's
// shear term; tests/verify_kirchhoff.rs checks the element converges to it).
const E: f64 = 1.0e4;
const NU: f64 = 0.3;
const Q: f64 = 1.0e-3;
const A: f64 = 100.0;

fn navier_plate(n: usize) -> String {
    format!(
        r#"title = "hard simply supported square plate under a uniform pressure (quarter)"
[mesh]
rectangle = {{ x = [0.0, 50.0], y = [0.0, 50.0], n = [{n}, {n}] }}
[plate]
thickness = 1.0
E = {E:e}
nu = {NU}
kinematics = "linear"
[[boundary]]
group = "left"
fix = ["symmetry_x1"]
[[boundary]]
group = "bottom"
fix = ["symmetry_x2"]
[[boundary]]
group = "right"
fix = ["simply_supported", "v2"]
[[boundary]]
group = "top"
fix = ["simply_supported", "v1"]
[[load]]
type = "pressure"
group = "all"
pressure = {Q:e}
face = "top"
[solver]
steps = 2
max_increment = 0.5
[output]
vtu = false
plot = false
"#
    )
}

fn navier_exact() -> f64 {
    let d = E / (12.0 * (1.0 - NU * NU));
    let g = E / (2.0 * (1.0 + NU));
    -Q * A.powi(4) / d * (0.00406235 + 0.0736713 * d / (g * A * A))
}

#[test]
fn the_estimate_is_closer_to_navier_than_the_refined_mesh() {
    let dir = temp_dir("refine-navier");
    let path = dir.join("plate.toml");
    std::fs::write(&path, navier_plate(4)).unwrap();
    let exact = navier_exact();
    for (levels, gain) in [(1, 5.0), (2, 5.0)] {
        let out = dir.join(format!("out{levels}"));
        let args: Vec<String> = vec!["--refine".into(), levels.to_string(), "-q".into()];
        ok(&stamp(&args.iter().map(|s| s.as_str()).collect::<Vec<_>>(), &path, &out));
        let s = summary(&out);
        assert_eq!(s["status"], "converged");
        let r = &s["refinement"];
        assert_eq!((r["status"].as_str(), r["levels"].as_u64()), (Some("converged"), Some(levels)));
        let steps = r["steps"].as_array().unwrap();
        assert_eq!(steps.len(), 2);
        for key in ["max_deflection", "corner_ll_u3"] {
            let last = &steps[1]["results"][key];
            let values: Vec<f64> = last["values"].as_array().unwrap().iter().map(f).collect();
            let (fine, est) = (values[levels as usize], f(&last["estimate"]));
            let (e_fine, e_est) = ((fine - exact) / exact, (est - exact) / exact);
            println!("--refine {levels}: {key}: meshes {values:?}, estimate {est:.7} ({:+.4} %), exact {exact:.7}; refined {:+.4} %, order {}", 100.0 * e_est, 100.0 * e_fine, last["order"]);
            assert!(e_est.abs() * gain < e_fine.abs(), "{key}: the estimate {est} is not {gain} times closer to {exact} than the refined result {fine}");
            // the estimated error of each run is about its true error
            for (k, v) in values.iter().enumerate() {
                let estimated = f(&last["errors_percent"][k]) / 100.0;
                let truth = (v - exact) / exact.abs();
                assert!((estimated - truth).abs() < 0.2 * truth.abs(), "{key}: mesh {k}: estimated error {estimated:.3e}, true {truth:.3e}");
            }
            if levels == 2 {
                let p = f(&last["observed_order"]);
                assert!((1.7..2.3).contains(&p), "{key}: observed order {p}");
                assert_eq!(f(&last["order"]), p, "the observed order is used");
            } else {
                assert_eq!(f(&last["order"]), 2.0);
                assert!(last["observed_order"].is_null());
            }
        }
        // the deflection is linear in the load: step 1 has half the estimate of step 2
        let half = f(&steps[0]["results"]["max_deflection"]["estimate"]) / f(&steps[1]["results"]["max_deflection"]["estimate"]);
        assert!((half - 0.5).abs() < 1e-9, "{half}");
        for level in 1..=levels as usize {
            let folder = if level == 1 { "refined".to_string() } else { format!("refined{level}") };
            let sub = summary(&out.join(&folder));
            assert_eq!(sub["status"], "converged", "{folder}");
            assert_eq!(sub["cells"].as_u64(), Some(16 * 4u64.pow(level as u32)));
        }
    }
}

/// A copy of a shipped example in `dir` (with the mesh it names).
fn example(dir: &Path, name: &str, mesh: Option<&str>) -> PathBuf {
    let p = dir.join(format!("{name}.toml"));
    std::fs::copy(repo().join(format!("meshes/{name}.toml")), &p).unwrap();
    if let Some(m) = mesh {
        std::fs::copy(repo().join("meshes").join(m), dir.join(m)).unwrap();
    }
    p
}

#[test]
fn table_history_and_summary_agree_with_the_refined_run() {
    let dir = temp_dir("refine-columns");
    let path = example(&dir, "sphere-ss-displacement", None);
    let out = dir.join("out");
    let stdout = ok(&stamp(&["--refine"], &path, &out));
    let s = summary(&out);
    let fine = summary(&out.join("refined"));
    assert_eq!((s["status"].as_str(), fine["status"].as_str()), (Some("converged"), Some("converged")));
    assert_eq!(s["refinement"]["order"], 2.0);
    assert_eq!(s["refinement"]["order_assumed"], true);
    let keys: Vec<&str> = s["refinement"]["quantities"].as_array().unwrap().iter().map(|k| k.as_str().unwrap()).collect();
    assert_eq!(keys[..2], ["sphere_force", "max_deflection"], "{keys:?}");
    for point in ["center", "corner_ll", "corner_lr", "corner_ul", "corner_ur"] {
        assert!(keys.contains(&format!("{point}_u3").as_str()), "{point}: {keys:?}");
    }
    let meshes = s["refinement"]["meshes"].as_array().unwrap();
    assert_eq!(meshes[0]["nodes"], s["nodes"]);
    assert_eq!(meshes[1]["nodes"], fine["nodes"]);
    assert_eq!(f(&meshes[1]["cells"]), 4.0 * f(&s["cells"]));
    // the refined run went through the coarse run's load factors
    let coarse_lf: Vec<f64> = s["steps"].as_array().unwrap().iter().map(|e| f(&e["load_factor"])).collect();
    assert_eq!(fine["targets"].as_array().unwrap().iter().map(f).collect::<Vec<_>>(), coarse_lf);

    let (h, rows) = read_csv(&out.join("history.csv"));
    let (hf, rows_f) = read_csv(&out.join("refined/history.csv"));
    assert_eq!(h[..7], ["step", "load_factor", "path", "sphere_travel", "sphere_force", "sphere_contact_area", "sphere_max_pressure"]);
    assert_eq!(hf.len(), col(&h, "max_deflection"), "the plain columns first, the new ones at the end: {h:?}");
    assert_eq!(rows.len(), coarse_lf.len());
    let table: Vec<&str> = stdout.lines().collect();
    // under the run's table, one table per key result: its name, the header, a row per step
    for (name, unit) in [("sphere force:", "force"), ("max deflection:", "length")] {
        let at = table.iter().position(|l| l.trim() == name).unwrap_or_else(|| panic!("no table of {name}\n{stdout}"));
        for needle in [format!("this mesh ({unit})"), format!("refined ({unit})"), format!("estimate ({unit})"), "error %".into(), "refined error %".into()] {
            assert!(table[at + 1].contains(&needle), "{needle}: {stdout}");
        }
        assert_eq!(table[at + 2].split_whitespace().next(), Some("1"), "{stdout}");
    }
    let head = table.iter().position(|l| l.trim() == "sphere force:").unwrap() + 1;
    // the refinement's tables and explanation fit a terminal (the run's own table is as without --refine)
    assert!(table[head..].iter().filter(|l| !l.starts_with("stamp run:")).all(|l| l.chars().count() <= 100), "a line wider than 100 characters:\n{stdout}");
    assert!(stdout.contains("p = 2 assumed"), "the table says which order it assumed:\n{stdout}");
    for (i, row) in rows.iter().enumerate() {
        let entry = &s["refinement"]["steps"][i];
        let force = &entry["results"]["sphere_force"];
        // the refined value is the refined run's force at the same load factor
        let k = f(&entry["refined_steps"][0]) as usize - 1;
        assert_eq!(rows_f[k][1], row[1], "step {}: load factors", i + 1);
        let (f0, f1) = (row[col(&h, "sphere_force")], rows_f[k][col(&hf, "sphere_force")]);
        assert!((row[col(&h, "sphere_force_refined")] - f1).abs() <= 1e-12 * f1.abs());
        assert!((f(&force["values"][0]) - f0).abs() <= 1e-9 * f0.abs() && (f(&force["values"][1]) - f1).abs() <= 1e-9 * f1.abs());
        let est = f1 + (f1 - f0) / 3.0;
        assert!((row[col(&h, "sphere_force_estimate")] - est).abs() <= 1e-9 * est.abs());
        assert!((f(&force["estimate"]) - est).abs() <= 1e-9 * est.abs());
        let pct = 100.0 * (f0 - est) / est.abs();
        assert!((row[col(&h, "sphere_force_error_pct")] - pct).abs() < 1e-6, "step {}", i + 1);
        assert!((row[col(&h, "sphere_force_refined_error_pct")] - 100.0 * (f1 - est) / est.abs()).abs() < 1e-6);
        // the force table's row shows the same numbers
        let cells: Vec<&str> = table[head + 1 + i].split_whitespace().collect();
        let text = stamp_cli::run::refine_report::percent(Some(pct));
        assert!(cells.contains(&text.as_str()), "step {}: {text} not in {:?}", i + 1, cells);
        // the largest deflection is the plate centre's (corner_ll of the quarter)
        assert!((row[col(&h, "max_deflection")] - row[col(&h, "corner_ll_u3")]).abs() < 1e-12, "step {}", i + 1);
        // the contact force converges from above: the finer mesh is softer
        assert!(f1 < f0, "step {}: {f0} -> {f1}", i + 1);
    }
    // the refined run's .vtu can be opened beside the coarse one's
    assert!(out.join("refined/sphere-ss-displacement.pvd").is_file());
    assert!(out.join("refined/sphere-ss-displacement_0001.vtu").is_file());
}

#[test]
fn plain_run_is_unchanged() {
    let dir = temp_dir("refine-plain");
    let path = dir.join("plate.toml");
    std::fs::write(&path, navier_plate(4)).unwrap();
    let out = dir.join("out");
    let stdout = ok(&stamp(&[], &path, &out));
    let s = summary(&out);
    assert!(s.get("refinement").is_none(), "no refinement object without --refine");
    assert!(!out.join("refined").exists());
    let (h, _) = read_csv(&out.join("history.csv"));
    assert!(!h.iter().any(|c| c.contains("estimate") || c == "max_deflection"), "{h:?}");
    assert!(!stdout.contains("estimate"), "{stdout}");
}

#[test]
fn bad_levels_are_refused_clearly() {
    let dir = temp_dir("refine-bad");
    let path = dir.join("plate.toml");
    std::fs::write(&path, navier_plate(4)).unwrap();
    for levels in ["0", "4", "300"] {
        let o = stamp(&["--refine", levels], &path, &dir.join("out"));
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && e.contains(&format!("invalid value '{levels}' for '--refine")) && e.contains("1..=3"), "{levels}: {e}");
    }
    assert!(!dir.join("out").exists(), "nothing is written");
}

#[test]
fn a_gmsh_mesh_refines_with_its_groups() {
    // the simply supported quarter plate under a sphere pressed 0.9 on gmsh's default triangles
    // (cut into quadrilaterals by the reader); the converged force is about 404.4 (README: 404.44
    // on 11327 nodes)
    let dir = temp_dir("refine-gmsh");
    let mesh = repo().join("tests/data/quarter/tri.msh");
    let mut text = format!("[mesh]\nfile = {:?}\n[plate]\nthickness = 1.0\nE = 2.1e5\nnu = 0.3\n", mesh.display().to_string());
    text += "[[boundary]]\ngroup = \"left\"\nfix = [\"symmetry_x1\"]\n[[boundary]]\ngroup = \"bottom\"\nfix = [\"symmetry_x2\"]\n";
    text += "[[boundary]]\ngroup = \"edge\"\nfix = [\"simply_supported\"]\n";
    text += "[[punch]]\nname = \"sphere\"\nshape = \"sphere\"\ncenter = [0.0, 0.0, 200.5]\nradius = 200.0\nmotion = [0.0, 0.0, -0.9]\npenetration_tolerance = 1e-6\n";
    text += "[solver]\nsteps = 3\nmax_increment = 0.34\nline_search_steps = 4\n[output]\nvtu = false\nplot = false\n";
    let path = dir.join("tri.toml");
    std::fs::write(&path, &text).unwrap();

    // the groups of the refined mesh: every supported edge is cut at its midpoints, which are
    // supported too
    let p = stamp_cli::run::Problem::read(&path).unwrap();
    let coarse = stamp_cli::run::mesh::MeshData::load(&p).unwrap();
    let fine = coarse.refined();
    for g in ["edge", "left", "bottom"] {
        assert_eq!(fine.curves[g].len(), 2 * coarse.curves[g].len(), "{g}");
        let nodes = fine.nodes(g).unwrap();
        assert_eq!(nodes.len(), 2 * coarse.nodes(g).unwrap().len() - 1, "{g}: a chain of n nodes gets n - 1 midpoints");
        for &n in &nodes {
            let x = fine.mesh.coords[n];
            let on = match g {
                "left" => x[0].abs() < 1e-9,
                "bottom" => x[1].abs() < 1e-9,
                _ => (x[0] - 20.0).abs() < 1e-9 || (x[1] - 20.0).abs() < 1e-9,
            };
            assert!(on, "{g}: node at {x:?} is off its line");
        }
    }
    assert_eq!(fine.points["center"], coarse.points["center"]);
    assert_eq!(fine.surfaces["plate"].len(), 4 * coarse.surfaces["plate"].len());
    assert_eq!(fine.node_tags.as_ref().unwrap()[..coarse.mesh.num_nodes()], coarse.node_tags.as_ref().unwrap()[..]);
    assert!(fine.node_tags.as_ref().unwrap()[coarse.mesh.num_nodes()..].iter().all(|&t| t == 0));

    let out = dir.join("out");
    ok(&stamp(&["--refine", "-q"], &path, &out));
    let s = summary(&out);
    let fs = summary(&out.join("refined"));
    for (name, run) in [("coarse", &s), ("refined", &fs)] {
        for e in run["steps"].as_array().unwrap() {
            // equilibrium: the punch's force is carried by the supports
            let (r, sup) = (f(&e["reaction"][2]), f(&e["support_reaction"][2]));
            assert!((r + sup).abs() < 1e-6 * r.abs(), "{name}: step {}: reaction {r}, supports {sup}", e["step"]);
        }
    }
    let last = s["refinement"]["steps"].as_array().unwrap().last().unwrap();
    let force = &last["results"]["sphere_force"];
    let (f0, f1, est) = (f(&force["values"][0]), f(&force["values"][1]), f(&force["estimate"]));
    println!("gmsh triangles: force {f0:.3} ({} nodes), {f1:.3} ({} nodes), estimate {est:.3}; reference 404.44", s["nodes"], fs["nodes"]);
    // the midpoints of the supported edge are supported: the refined plate is not much softer
    assert!(f1 < f0 && (f0 - f1) / f0 < 0.03, "{f0} -> {f1}");
    assert!((est - 404.44).abs() < (f1 - 404.44).abs(), "estimate {est} not closer to 404.44 than the refined {f1}");
}

#[test]
fn a_failed_refined_run_is_told_in_summary_json() {
    // a file where the refined run's folder should go: the refined run cannot write
    let dir = temp_dir("refine-fails");
    let path = dir.join("plate.toml");
    std::fs::write(&path, navier_plate(4)).unwrap();
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("refined"), "not a folder").unwrap();
    let o = stamp(&["--refine", "-q"], &path, &out);
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{e}");
    assert!(e.contains("the mesh refined once") && e.contains("plate.toml"), "{e}");
    let s = summary(&out);
    assert_eq!(s["status"], "failed");
    assert!(s["error"].as_str().unwrap().contains("the mesh refined once"), "{}", s["error"]);
    assert_eq!(s["refinement"]["status"], "failed: the mesh refined once");
    assert!(s["refinement"].get("steps").is_none(), "no estimates without the refined run");
    // the run on the problem's mesh itself is complete
    assert_eq!(s["steps"].as_array().unwrap().len(), 2);
    let (h, _) = read_csv(&out.join("history.csv"));
    assert!(!h.iter().any(|c| c.ends_with("_estimate")), "{h:?}");
}

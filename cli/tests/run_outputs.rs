//! What users read after `stamp run`: the table on stdout, history.csv, the force-travel plots and
//! the probes, checked against summary.json and the nodal CSV files by running the `stamp` binary.

mod common;
use common::*;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Run `stamp run problem --out out` (not quiet; stdout and stderr are pipes). Returns stdout,
/// stderr and summary.json.
fn stamp_run(problem: &Path, out: &Path) -> (String, String, Value) {
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("run").arg(problem).arg("--out").arg(out).output().unwrap();
    let (stdout, stderr) = (String::from_utf8(o.stdout).unwrap(), String::from_utf8(o.stderr).unwrap());
    assert!(o.status.success(), "stamp run {} failed:\n{stdout}\n{stderr}", problem.display());
    let s: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    (stdout, stderr, s)
}

/// A problem file from meshes/ with text replaced, written into `dir` (meshes it names are copied).
fn variant(dir: &Path, name: &str, edits: &[(&str, &str)], mesh: Option<&str>) -> PathBuf {
    let mut text = std::fs::read_to_string(repo().join(format!("meshes/{name}.toml"))).unwrap();
    for (a, b) in edits {
        assert!(text.contains(a), "{name}.toml has no {a:?}");
        text = text.replacen(a, b, 1);
    }
    if let Some(m) = mesh {
        std::fs::copy(repo().join("meshes").join(m), dir.join(m)).unwrap();
    }
    let p = dir.join(format!("{name}.toml"));
    std::fs::write(&p, text).unwrap();
    p
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// |a - b| <= rel * max(|a|, |b|, floor).
fn close(a: f64, b: f64, rel: f64, floor: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()).max(floor)
}

#[test]
fn table_and_history_agree_with_summary() {
    let dir = temp_dir("outputs-table");
    let units = "[units]\nlength = \"mm\"\nforce = \"N\"\n\n[output]";
    let problem = variant(&dir, "sphere-ss", &[("[output]", units)], None);
    let out = dir.join("out");
    let (stdout, stderr, s) = stamp_run(&problem, &out);
    let steps: Vec<&Value> = s["steps"].as_array().unwrap().iter().collect();
    assert_eq!(steps.len(), 5);

    // the table: a header with units, then one row per converged step
    let lines: Vec<&str> = stdout.lines().collect();
    let h = lines.iter().position(|l| l.trim_start().starts_with("step") && l.contains("load factor")).unwrap_or_else(|| panic!("no table header:\n{stdout}"));
    for head in ["travel (mm)", "force (N)", "contact area (mm^2)", "peak pressure (N/mm^2)", "penetration (mm)", "Newton"] {
        assert!(lines[h].contains(head), "{head} not in the header:\n{stdout}");
    }
    assert!(lines[h - 1].contains("sphere:"), "the punch's name is not above its columns:\n{stdout}");
    let rows: Vec<Vec<f64>> = lines[h + 1..].iter().take_while(|l| !l.starts_with("stamp run:")).map(|l| l.split_whitespace().map(|v| v.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), steps.len(), "one row per converged step:\n{stdout}");
    for (r, e) in rows.iter().zip(&steps) {
        let p = &e["punches"]["sphere"];
        assert_eq!(r[0] as u64, e["step"].as_u64().unwrap());
        // printed with 6 significant digits: agree to 5e-6 relative
        assert!(close(r[1], f(&e["load_factor"]), 5e-6, 0.0), "load factor {r:?}");
        assert!(close(r[2], f(&p["drive_displacement"]), 5e-6, 0.0), "travel {r:?}");
        // force driven along -x3: the force is -reaction_3, and it equals the applied force
        assert!(close(r[3], -f(&p["reaction"][2]), 5e-6, 0.0), "force {r:?}");
        assert!(close(r[3], f(&p["applied_force"]), 1e-5, 0.0), "force {r:?}");
        assert!(close(r[5], f(&p["max_pressure"]), 5e-6, 0.0), "peak pressure {r:?}");
        assert!(close(r[6], f(&p["max_penetration"]), 5e-6, 1e-300), "penetration {r:?}");
        assert_eq!(r[7] as u64, e["newton_iterations"].as_u64().unwrap());
        // l_e = 2: the active nodes' tributary areas are 1 (corner), 2 (edge) or 4 (interior)
        let n_active = p["active_nodes"].as_u64().unwrap() as f64;
        assert!(r[4] >= n_active && r[4] <= 4.0 * n_active, "contact area {} with {n_active} active nodes", r[4]);
    }
    // the terse lines on stderr (not a terminal) carry the force
    let terse: Vec<&str> = stderr.lines().filter(|l| l.contains(" converged at t = ")).collect();
    assert_eq!(terse.len(), steps.len(), "{stderr}");
    for (l, e) in terse.iter().zip(&steps) {
        let force: f64 = l.split("sphere force ").nth(1).unwrap_or_else(|| panic!("no force in {l}")).split_whitespace().next().unwrap().parse().unwrap();
        assert!(close(force, -f(&e["punches"]["sphere"]["reaction"][2]), 5e-6, 0.0), "{l}");
    }

    // history.csv: the same steps, exact numbers
    let (hd, hist) = read_csv(&out.join("history.csv"));
    assert_eq!(&hd[..7], ["step", "load_factor", "path", "sphere_travel", "sphere_force", "sphere_contact_area", "sphere_max_pressure"]);
    assert_eq!(hist.len(), steps.len());
    for (r, e) in hist.iter().zip(&steps) {
        let p = &e["punches"]["sphere"];
        assert_eq!(r[0] as u64, e["step"].as_u64().unwrap());
        assert!(close(r[1], f(&e["load_factor"]), 1e-14, 0.0) && close(r[2], f(&e["path"]), 1e-14, 0.0));
        assert!(close(r[col(&hd, "sphere_travel")], f(&p["drive_displacement"]), 1e-14, 0.0));
        assert!(close(r[col(&hd, "sphere_force")], -f(&p["reaction"][2]), 1e-14, 0.0));
        assert!(close(r[col(&hd, "sphere_max_pressure")], f(&p["max_pressure"]), 1e-14, 0.0));
        for (i, c) in ["center_u1", "center_u2", "center_u3"].iter().enumerate() {
            assert!(close(r[col(&hd, c)], f(&e["points"]["center"]["displacement"][i]), 1e-14, 1e-300), "{c}");
        }
    }
    // the table's contact area is history's, to printed precision
    for (r, h) in rows.iter().zip(&hist) {
        assert!(close(r[4], h[col(&hd, "sphere_contact_area")], 5e-6, 0.0));
    }
    for name in ["force_travel_sphere.png", "probe_sphere.png"] {
        assert_eq!(&std::fs::read(out.join(name)).unwrap()[..4], b"\x89PNG", "{name}");
    }
    let svg = std::fs::read_to_string(out.join("force_travel_sphere.svg")).unwrap();
    assert!(svg.contains("travel (mm)") && svg.contains("force (N)"), "the axes carry the units");
}

#[test]
fn a_probe_across_the_full_gmsh_model_is_symmetric_about_the_centre() {
    let dir = temp_dir("outputs-symmetric");
    // a diagonal line through the centre, crossing the cells obliquely (only the centre is a node)
    let problem = variant(&dir, "sphere-ss-full", &[("plot = true", "plot = false")], Some("sphere-ss-full.msh"));
    let probe = "\n[[output.probe]]\nname = \"diagonal\"\nfrom = [-17.0, -7.0]\nto = [17.0, 7.0]\npoints = 101\n";
    let text = std::fs::read_to_string(&problem).unwrap() + probe;
    std::fs::write(&problem, text).unwrap();
    let out = dir.join("out");
    let (_, _, s) = stamp_run(&problem, &out);
    let last = s["steps"].as_array().unwrap().last().unwrap()["step"].as_u64().unwrap();
    let (hd, rows) = read_csv(&out.join(format!("probe_diagonal_{last:04}.csv")));
    assert_eq!(&hd[..], ["distance", "x1", "x2", "u1", "u2", "u3", "sphere_pressure", "sphere_pressure_recovered", "sphere_integral", "sphere_line_load"]);
    assert_eq!(rows.len(), 101, "every point lies in the plate");
    let len = 34.0f64.hypot(14.0);
    let q_max = rows.iter().map(|r| r[6]).fold(0.0, f64::max);
    assert!(q_max > 1.0, "the line crosses the contact zone: max q_n {q_max}");
    assert!(rows[50][1].abs() < 1e-12 && rows[50][2].abs() < 1e-12, "the middle point is the centre");
    let mut worst = 0.0f64;
    for i in 0..rows.len() {
        let (a, b) = (&rows[i], &rows[rows.len() - 1 - i]);
        assert!((a[0] + b[0] - len).abs() < 1e-9 * len, "distances {} and {}", a[0], b[0]);
        // the mesh and the problem are symmetric under (x1, x2) -> (-x1, -x2): q_n and u3 agree,
        // u1 and u2 change sign. The discrete solutions differ only by the Newton tolerance.
        worst = worst.max((a[6] - b[6]).abs() / q_max);
        assert!((a[6] - b[6]).abs() <= 1e-6 * q_max, "q_n at s = {}: {} against {}", a[0], a[6], b[6]);
        assert!((a[5] - b[5]).abs() <= 1e-6 * rows[50][5].abs(), "u3 at s = {}: {} against {}", a[0], a[5], b[5]);
        assert!((a[3] + b[3]).abs() <= 1e-6 * rows[50][5].abs(), "u1 at s = {}: {} against {}", a[0], a[3], b[3]);
    }
    eprintln!("largest asymmetry of q_n: {worst:e} of max q_n");
    // the integral column is the trapezoidal integral of the pressure along the line, from 0
    let mut integral = 0.0;
    for i in 0..rows.len() {
        if i > 0 {
            integral += 0.5 * (rows[i][0] - rows[i - 1][0]) * (rows[i][6] + rows[i - 1][6]);
        }
        assert!((rows[i][8] - integral).abs() <= 1e-6 * integral.max(q_max), "integral at s = {}: {} against {integral}", rows[i][0], rows[i][8]);
    }
    // the band's integral grows along the line, and the whole line crosses the zone in both
    assert!(rows.windows(2).all(|w| w[1][9] >= w[0][9]) && rows[100][9] > 0.0 && rows[100][8] > 0.0);
}

#[test]
fn a_probe_through_nodes_of_the_rectangle_gives_the_nodal_values() {
    let dir = temp_dir("outputs-nodal");
    // nodes every 2 along x2 = 0: 11 points from 0 to 20 are nodes; 200 points meet only the ends,
    // and the 9 nodes in between are added
    let probes = "[[output.probe]]\nname = \"nodes\"\nfrom = [0.0, 0.0]\nto = [20.0, 0.0]\npoints = 11\n\n\
                  [[output.probe]]\nname = \"fine\"\nfrom = [0.0, 0.0]\nto = [20.0, 0.0]\n\n[output]";
    let problem = variant(&dir, "sphere-ss", &[("[output]", probes)], None);
    let out = dir.join("out");
    let (_, _, s) = stamp_run(&problem, &out);
    assert!(!out.join("probe_sphere.png").exists(), "no default probe when probes are named");
    for e in s["steps"].as_array().unwrap() {
        let step = e["step"].as_u64().unwrap();
        let (ph, pressure) = read_csv(&out.join(format!("pressure_sphere_{step:04}.csv")));
        let nodal = |x1: f64| -> f64 {
            let r = pressure.iter().find(|r| (r[col(&ph, "x1")] - x1).abs() < 1e-12 && r[col(&ph, "x2")] == 0.0).unwrap_or_else(|| panic!("no node at ({x1}, 0)"));
            r[col(&ph, "q_n")]
        };
        let (_, coarse) = read_csv(&out.join(format!("probe_nodes_{step:04}.csv")));
        assert_eq!(coarse.len(), 11);
        for r in &coarse {
            assert!((r[6] - nodal(r[1])).abs() <= 1e-12 * nodal(r[1]).abs().max(1e-300), "step {step}, x1 = {}: {} against {}", r[1], r[6], nodal(r[1]));
        }
        // the centre is the point group corner_ll: its mid-surface displacement
        for i in 0..3 {
            assert!((coarse[0][3 + i] - f(&e["points"]["corner_ll"]["displacement"][i])).abs() < 1e-14);
        }
        let (_, fine) = read_csv(&out.join(format!("probe_fine_{step:04}.csv")));
        assert_eq!(fine.len(), 209, "200 points and 9 nodes");
        assert!(fine.windows(2).all(|w| w[1][0] > w[0][0]), "rows in order of distance");
        let at_nodes: Vec<&Vec<f64>> = fine.iter().filter(|r| (r[1] / 2.0 - (r[1] / 2.0).round()).abs() < 1e-12).collect();
        assert_eq!(at_nodes.len(), 11);
        for r in at_nodes {
            assert!((r[6] - nodal(r[1])).abs() <= 1e-12 * nodal(r[1]).abs().max(1e-300));
        }
        // between nodes the pressure is the linear interpolation of its two nodes (x2 = 0 is a cell edge)
        for r in &fine {
            let a = (r[1] / 2.0).floor() * 2.0;
            let b = (a + 2.0).min(20.0);
            let w = if b > a { (r[1] - a) / (b - a) } else { 0.0 };
            let lin = (1.0 - w) * nodal(a) + w * nodal(b);
            assert!((r[6] - lin).abs() <= 1e-10 * lin.abs().max(1.0), "x1 = {}: {} against {lin}", r[1], r[6]);
        }
    }
    for name in ["probe_nodes.png", "probe_fine.svg", "force_travel_sphere.png"] {
        assert!(out.join(name).exists(), "{name}");
    }
    // the title gives the line's ends to 4 significant digits
    let svg = std::fs::read_to_string(out.join("probe_fine.svg")).unwrap();
    assert!(svg.contains("from (0, 0) to (20.00, 0)"), "the probe's title");
}

#[test]
fn bad_probes_and_units_name_the_file_line_and_key() {
    let dir = temp_dir("outputs-bad");
    let cases = [
        ("points", "[[output.probe]]\nname = \"a\"\nfrom = [0.0, 0.0]\nto = [1.0, 0.0]\npoints = 1\n\n[output]", "output.probe[0].points", "2 to 100000"),
        ("length", "[[output.probe]]\nname = \"a\"\nfrom = [1.0, 2.0]\nto = [1.0, 2.0]\n\n[output]", "output.probe[0].to", "no length"),
        ("name", "[[output.probe]]\nname = \"a b\"\nfrom = [0.0, 0.0]\nto = [1.0, 0.0]\n\n[output]", "output.probe[0].name", "names files"),
        ("twice", "[[output.probe]]\nname = \"a\"\nfrom = [0.0, 0.0]\nto = [1.0, 0.0]\n\n[[output.probe]]\nname = \"a\"\nfrom = [0.0, 0.0]\nto = [2.0, 0.0]\n\n[output]", "output.probe[1].name", "two probes"),
        ("outside", "[[output.probe]]\nname = \"a\"\nfrom = [30.0, 0.0]\nto = [40.0, 5.0]\n\n[output]", "output.probe[0]", "does not cross the mesh"),
        ("unit", "[units]\nlength = \"\"\n\n[output]", "length", "unit name"),
        ("unknown", "[units]\nmass = \"kg\"\n\n[output]", "mass", "unknown field"),
    ];
    for (name, edit, key, what) in cases {
        let sub = dir.join(name);
        std::fs::create_dir_all(&sub).unwrap();
        let problem = variant(&sub, "sphere-ss", &[("[output]", edit)], None);
        let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("run").arg(&problem).arg("--quiet").arg("--out").arg(sub.join("out")).output().unwrap();
        let err = String::from_utf8(o.stderr).unwrap();
        assert!(!o.status.success(), "{name}: accepted");
        assert!(err.contains("sphere-ss.toml") && err.contains("line ") && err.contains(key) && err.contains(what), "{name}: {err}");
    }
}

#[test]
fn after_a_failure_the_table_history_and_plots_hold_what_converged() {
    let dir = temp_dir("outputs-failure");
    // the first target converges (5 iterations over its augmented-Lagrangian solves, each under
    // 3); the next step, 2.5 times the force, cannot in 3 iterations without cut-back
    let problem = variant(&dir, "sphere-ss", &[("steps = 5", "targets = [0.2, 50.0]"), ("max_increment = 0.2", "max_increment = 100.0\nmax_iterations = 3\nmax_cutbacks = 0")], None);
    let out = dir.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("run").arg(&problem).arg("--out").arg(&out).output().unwrap();
    let (stdout, stderr) = (String::from_utf8(o.stdout).unwrap(), String::from_utf8(o.stderr).unwrap());
    assert!(!o.status.success() && stderr.contains("did not converge"), "{stderr}");
    let s: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let done: Vec<&Value> = s["steps"].as_array().unwrap().iter().filter(|e| e["converged"] == true).collect();
    assert_eq!(done.len(), 1, "{s}");
    // the failed step's 3 iterations (max_iterations, no cut-back) are reported, in its entry and
    // in all, beside the converged step's
    let failed = s["steps"].as_array().unwrap().last().unwrap();
    assert_eq!(failed["converged"], false);
    assert_eq!(failed["failed_iterations"], 3, "{failed}");
    assert_eq!(s["failed_iterations"], 3);
    assert_eq!(s["newton_iterations"], done[0]["newton_iterations"]);
    let (_, hist) = read_csv(&out.join("history.csv"));
    assert_eq!(hist.len(), 1);
    assert!(close(hist[0][4], -f(&done[0]["punches"]["sphere"]["reaction"][2]), 1e-14, 0.0));
    let row = stdout.lines().find(|l| l.trim_start().starts_with("1 ")).unwrap_or_else(|| panic!("no table row:\n{stdout}"));
    assert!(close(row.split_whitespace().nth(3).unwrap().parse().unwrap(), hist[0][4], 5e-6, 0.0), "{row}");
    for name in ["force_travel_sphere.png", "force_travel_sphere.svg", "probe_sphere.png"] {
        assert!(out.join(name).is_file(), "{name}");
    }
}

//! gmsh's default meshes give the quadrilateral answer: the simply supported quarter plate under a
//! sphere pressed 0.9 (meshes/sphere-ss-displacement.toml's problem) on gmsh's default triangles,
//! a mixed triangle/quadrilateral mesh and second-order meshes (6-node triangles, 9- and 8-node
//! quadrilaterals), each cut into 4-node cells by the reader, against the structured quadrilateral
//! mesh with about as many nodes: the punch force agrees within 1 % at every load step.
//! The meshes are made by tests/data/quarter/make.sh.

mod common;
use common::*;
use std::path::Path;
use std::process::Command;

/// The problem on `mesh` (a `[mesh]` line), with the edge group(s) simply supported.
fn problem(mesh_line: &str, edges: &[&str]) -> String {
    let mut s = format!("[mesh]\n{mesh_line}\n[plate]\nthickness = 1.0\nE = 2.1e5\nnu = 0.3\n");
    s += "[[boundary]]\ngroup = \"left\"\nfix = [\"symmetry_x1\"]\n[[boundary]]\ngroup = \"bottom\"\nfix = [\"symmetry_x2\"]\n";
    for e in edges {
        s += &format!("[[boundary]]\ngroup = \"{e}\"\nfix = [\"simply_supported\"]\n");
    }
    s += "[[punch]]\nname = \"sphere\"\nshape = \"sphere\"\ncenter = [0.0, 0.0, 200.5]\nradius = 200.0\nmotion = [0.0, 0.0, -0.9]\npenetration_tolerance = 1e-6\n";
    s += "[solver]\nsteps = 5\nmax_increment = 0.2\nline_search_steps = 4\n[output]\nvtu = false\nplot = false\n";
    s
}

/// Runs the problem; returns (nodes, the punch force at each of the 5 steps).
fn forces(dir: &Path, name: &str, text: &str) -> (usize, Vec<f64>) {
    let file = dir.join(format!("{name}.toml"));
    std::fs::write(&file, text).unwrap();
    let out = dir.join(format!("{name}-out"));
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).args(["run", "-q", "--out"]).arg(&out).arg(&file).output().unwrap();
    assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
    let s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let steps = s["steps"].as_array().unwrap();
    let f: Vec<f64> = steps.iter().map(|st| -st["reaction"][2].as_f64().unwrap()).collect();
    (s["nodes"].as_u64().unwrap() as usize, f)
}

fn compare(kind: &str, file: &str, n_quad: usize) {
    let dir = temp_dir(&format!("split-{kind}"));
    let mesh = repo().join("tests/data/quarter").join(file);
    let (nodes, f) = forces(&dir, kind, &problem(&format!("file = {:?}", mesh.display().to_string()), &["edge"]));
    let rect = format!("rectangle = {{ x = [0.0, 20.0], y = [0.0, 20.0], n = [{n_quad}, {n_quad}] }}");
    let (nodes_q, fq) = forces(&dir, "quad", &problem(&rect, &["right", "top"]));
    assert_eq!(f.len(), 5, "{kind}: {f:?}");
    assert_eq!(fq.len(), 5);
    let ratio = nodes as f64 / nodes_q as f64;
    assert!((0.85..1.15).contains(&ratio), "{kind}: {nodes} nodes against {nodes_q}: not comparable");
    for k in 0..5 {
        let d = (f[k] - fq[k]) / fq[k];
        println!("{kind}: step {} force {:.3} ({nodes} nodes) against {:.3} ({nodes_q} nodes): {:+.3} %", k + 1, f[k], fq[k], 100.0 * d);
        assert!(d.abs() < 0.01, "{kind}: step {}: force {} against the quadrilaterals' {} ({:+.2} %)", k + 1, f[k], fq[k], 100.0 * d);
    }
}

#[test]
fn default_triangles_give_the_quadrilateral_answer() {
    compare("tri", "tri.msh", 22);
}

#[test]
fn a_mixed_mesh_gives_the_quadrilateral_answer() {
    compare("mixed", "mixed.msh", 26);
}

#[test]
fn six_node_triangles_give_the_quadrilateral_answer() {
    compare("tri6", "tri6.msh", 14);
}

#[test]
fn nine_node_quadrilaterals_give_the_quadrilateral_answer() {
    compare("quad9", "quad9.msh", 14);
}

#[test]
fn eight_node_quadrilaterals_give_the_quadrilateral_answer() {
    compare("quad8", "quad8.msh", 14);
}

#[test]
fn check_says_what_the_reader_cut() {
    let dir = temp_dir("split-check");
    let mesh = repo().join("tests/data/quarter/mixed.msh");
    let file = dir.join("mixed.toml");
    std::fs::write(&file, problem(&format!("file = {:?}", mesh.display().to_string()), &["edge"])).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("check").arg(&file).output().unwrap();
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let line = text.lines().find(|l| l.contains("cut into 4-node plate elements")).unwrap_or_else(|| panic!("{text}"));
    assert!(line.contains("3-node triangles split into") && line.contains("quadrilaterals"), "{line}");
}

#[test]
fn a_mesh_given_for_the_problem_file_is_named_as_such() {
    let mesh = repo().join("tests/data/quarter/mixed.msh");
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("check").arg(&mesh).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("mixed.msh") && err.contains("is a gmsh mesh, not a problem file"), "{err}");
}

/// Navier's series for the centre deflection of a simply supported square plate (side a) under a
/// uniform load q: w D / (q a^4) (Timoshenko & Woinowsky-Krieger, eq. 137: 0.00406235).
fn navier_coefficient() -> f64 {
    let pi = std::f64::consts::PI;
    let mut sum = 0.0;
    for m in (1..400).step_by(2) {
        for n in (1..400).step_by(2) {
            let (mf, nf) = (m as f64, n as f64);
            let sign = if ((m + n) / 2 - 1) % 2 == 0 { 1.0 } else { -1.0 }; // sin(m pi/2) sin(n pi/2)
            sum += sign / (mf * nf * (mf * mf + nf * nf).powi(2));
        }
    }
    16.0 / pi.powi(6) * sum
}

/// No shear locking on a cut triangle mesh: a very thin (a/h = 1000) simply supported square plate
/// under a uniform pressure, linear kinematics, quarter model on gmsh's default triangles, deflects
/// as Kirchhoff's plate (Navier's series) to the discretisation error; a locking element would be
/// orders of magnitude too stiff at this slenderness.
#[test]
fn a_very_thin_plate_on_cut_triangles_does_not_lock() {
    let (a, h, e, nu, q): (f64, f64, f64, f64, f64) = (40.0, 0.04, 2.1e5, 0.3, 1e-6);
    assert!((navier_coefficient() - 0.00406235).abs() < 1e-7, "{}", navier_coefficient());
    let dir = temp_dir("split-locking");
    let mesh = repo().join("tests/data/quarter/tri.msh");
    let text = format!(
        "[mesh]\nfile = {:?}\n[plate]\nthickness = {h}\nE = {e}\nnu = {nu}\nkinematics = \"linear\"\n\
         [[boundary]]\ngroup = \"left\"\nfix = [\"symmetry_x1\"]\n[[boundary]]\ngroup = \"bottom\"\nfix = [\"symmetry_x2\"]\n\
         [[boundary]]\ngroup = \"edge\"\nfix = [\"simply_supported\"]\n\
         [[load]]\ntype = \"pressure\"\ngroup = \"plate\"\npressure = {q}\nface = \"top\"\n[output]\nvtu = false\nplot = false\n",
        mesh.display().to_string()
    );
    let file = dir.join("thin.toml");
    std::fs::write(&file, text).unwrap();
    let out = dir.join("out");
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).args(["run", "-q", "--out"]).arg(&out).arg(&file).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let step = s["steps"].as_array().unwrap().last().unwrap().clone();
    let w = -step["points"]["center"]["displacement"][2].as_f64().unwrap_or_else(|| panic!("{step}"));
    let d = e * h.powi(3) / (12.0 * (1.0 - nu * nu));
    let kirchhoff = navier_coefficient() * q * a.powi(4) / d;
    let err = w / kirchhoff - 1.0;
    println!("thin plate on cut triangles: w = {w:e}, Kirchhoff {kirchhoff:e} ({:+.3} %)", 100.0 * err);
    assert!(err.abs() < 0.02, "w = {w:e} against Kirchhoff's {kirchhoff:e} ({:+.2} %)", 100.0 * err);
}

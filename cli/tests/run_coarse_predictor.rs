//! `[solver] predictor = "coarse"` and `stamp run --refine`: load steps started from the solution
//! on a coarser mesh give the answer of the secant predictor (the same converged equations) in
//! fewer Newton iterations, on the built-in rectangle (the coarse mesh nested in it) and on two
//! independent gmsh meshes of a curved plate; summary.json reports the coarse solve; bad
//! combinations of keys are refused with the file, the line and the key.

mod common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::Command;

/// `stamp run -q` into `out`; (exit code, stderr).
fn stamp_run(problem: &Path, out: &Path, extra: &[&str]) -> (Option<i32>, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("run").args(extra).args(["-q", "--out"]).arg(out).arg(problem).output().unwrap();
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// Run `problem` into a fresh folder `name` and return it (the run must converge).
fn run(problem: &Path, name: &str) -> PathBuf {
    let out = temp_dir(name);
    let (code, err) = stamp_run(problem, &out, &[]);
    assert_eq!(code, Some(0), "{}: {err}", problem.display());
    out
}

/// (punch force, Newton iterations) of every converged step of summary.json.
fn steps(out: &Path) -> Vec<(f64, usize)> {
    summary(out)["steps"].as_array().unwrap().iter().map(|s| (-s["reaction"][2].as_f64().unwrap(), s["newton_iterations"].as_u64().unwrap() as usize)).collect()
}

/// Same forces at every step (to `tol` relative); the total Newton iterations of `a` and `b`.
fn same_forces(a: &[(f64, usize)], b: &[(f64, usize)], tol: f64) -> (usize, usize) {
    assert_eq!(a.len(), b.len());
    for (k, (x, y)) in a.iter().zip(b).enumerate() {
        assert!(x.0 > 0.0 && (x.0 - y.0).abs() <= tol * x.0, "step {}: force {} against {}", k + 1, x.0, y.0);
    }
    (a.iter().map(|s| s.1).sum(), b.iter().map(|s| s.1).sum())
}

#[test]
fn the_rectangle_with_half_its_n_starts_every_step_and_saves_iterations() {
    // meshes/sphere-ss-displacement.toml on 40 x 40 (measured: 33 Newton iterations with the
    // secant predictor, 28 from the 20 x 20 mesh's solution, which took 32 of its own)
    let n40 = [("n = [10, 10]", "n = [40, 40]"), ("plot = true", "plot = false")];
    let secant = run(&variant("coarse-off", "sphere-ss-displacement.toml", &n40), "coarse-off-out");
    let mut edits = n40.to_vec();
    edits.push(("line_search_steps = 4", "line_search_steps = 4\npredictor = \"coarse\""));
    let problem = variant("coarse-on", "sphere-ss-displacement.toml", &edits);
    let check = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("check").arg(&problem).output().unwrap();
    let said = String::from_utf8_lossy(&check.stdout);
    assert!(said.contains("predictor: every step starts from the solution on the coarse mesh (441 nodes, 400 elements"), "{said}");
    let coarse = run(&problem, "coarse-on-out");
    let (a, b) = same_forces(&steps(&secant), &steps(&coarse), 1e-7);
    assert!(b < a, "{b} Newton iterations from the coarse mesh against {a} from the secant predictor");
    let s = summary(&coarse);
    let c = &s["coarse_predictor"];
    assert_eq!(c["nodes"], 21 * 21, "{c}");
    assert_eq!(c["steps"], 5);
    assert_eq!(c["reached_load_factor"], 1.0);
    assert!(c["error"].is_null() && c["newton_iterations"].as_u64().unwrap() > 0, "{c}");
    assert_eq!(s["status"], "converged");
    assert!(summary(&secant).get("coarse_predictor").is_none());
}

#[test]
fn two_independent_gmsh_meshes_of_a_curved_plate() {
    // meshes/disk-clamped.toml on gmsh's lc = 1 triangles, started from the shipped lc = 2 mesh:
    // neither nested nor with the same boundary (the arc's chords differ), measured 53 Newton
    // iterations with the secant predictor against 25
    let fine = [("file = \"disk-clamped.msh\"", "file = \"disk-clamped-lc1.msh\"")];
    let secant = run(&variant("disk-secant", "disk-clamped.toml", &fine), "disk-secant-out");
    let coarse = variant(
        "disk-coarse",
        "disk-clamped.toml",
        &[("file = \"disk-clamped.msh\"", "file = \"disk-clamped-lc1.msh\"\ncoarse_file = \"disk-clamped.msh\""), ("[solver]", "[solver]\npredictor = \"coarse\"")],
    );
    let coarse = run(&coarse, "disk-coarse-out");
    let (a, b) = same_forces(&steps(&secant), &steps(&coarse), 1e-7);
    assert!(2 * b < a + 10, "{b} Newton iterations from the coarse mesh against {a} from the secant predictor");
    assert_eq!(summary(&coarse)["coarse_predictor"]["nodes"], summary(&run(&repo().join("meshes/disk-clamped.toml"), "disk-shipped"))["nodes"]);
}

#[test]
fn refine_starts_every_finer_mesh_from_the_one_before() {
    // --refine 2 from 10 x 10: its 20 x 20 and 40 x 40 runs give what plain runs on those meshes
    // give, in fewer iterations (measured 30 and 28 against 32 and 33)
    let problem = variant("refine-nested", "sphere-ss-displacement.toml", &[("plot = true", "plot = false")]);
    let out = temp_dir("refine-nested-out");
    let (code, err) = stamp_run(&problem, &out, &["--refine=2"]);
    assert_eq!(code, Some(0), "{err}");
    for (level, n) in [("refined", 20), ("refined2", 40)] {
        let plain = variant(&format!("plain-{n}"), "sphere-ss-displacement.toml", &[("n = [10, 10]", &format!("n = [{n}, {n}]")), ("plot = true", "plot = false")]);
        let plain = run(&plain, &format!("plain-{n}-out"));
        let (a, b) = same_forces(&steps(&plain), &steps(&out.join(level)), 1e-7);
        assert!(b < a, "{level}: {b} Newton iterations from the mesh before against {a} from the secant predictor");
        let note = summary(&out.join(level))["refinement"]["note"].as_str().unwrap().to_string();
        assert!(note.contains("started from the solution on the mesh before"), "{note}");
    }
}

/// `stamp run` and `stamp check` refuse `text` (written as `case`.toml beside the shipped meshes)
/// naming the file, "line L" of the first line that starts with `at`, and every one of `wanted`.
fn refused(case: &str, shipped: &str, edits: &[(&str, &str)], at: &str, wanted: &[&str]) {
    refused_at(&variant(case, shipped, edits), case, at, wanted);
}

/// [`refused`] for a problem file written already.
fn refused_at(path: &std::path::Path, case: &str, at: &str, wanted: &[&str]) {
    let path = path.to_path_buf();
    let text = std::fs::read_to_string(&path).unwrap();
    let line = text.lines().position(|l| l.trim_start().starts_with(at)).unwrap_or_else(|| panic!("no line starts with {at} in {case}")) + 1;
    let (code, err) = stamp_run(&path, &path.with_extension("out"), &[]);
    let check = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("check").arg(&path).output().unwrap();
    let check_err = String::from_utf8_lossy(&check.stderr).into_owned();
    for (what, code, err) in [("run", code, &err), ("check", check.status.code(), &check_err)] {
        assert_eq!(code, Some(1), "{case} ({what}): {err}");
        assert!(err.contains(&format!("{case}.toml: ")) && err.contains(&format!("line {line}, column")), "{case} ({what}): not at line {line}: {err}");
        // the line itself under the message
        let shown = text.lines().nth(line - 1).unwrap().chars().take(20).collect::<String>();
        assert!(err.contains(&format!("\n  {line} | {shown}")), "{case} ({what}): line {line} not shown: {err}");
        for w in wanted {
            assert!(err.contains(w), "{case} ({what}): no '{w}' in: {err}");
        }
        assert!(!err.contains("panicked"), "{err}");
    }
}

#[test]
fn bad_combinations_are_refused_with_the_key_and_the_line() {
    let coarse = ("line_search_steps = 4", "line_search_steps = 4\npredictor = \"coarse\"");
    refused("odd-n", "sphere-ss-displacement.toml", &[("n = [10, 10]", "n = [9, 10]"), coarse], "predictor", &["solver.predictor", "[9, 10]", "even"]);
    refused("unknown-predictor", "sphere-ss-displacement.toml", &[("line_search_steps = 4", "line_search_steps = 4\npredictor = \"quadratic\"")], "predictor", &["predictor", "`secant` or `coarse`"]);
    refused("rectangle-coarse-file", "sphere-ss-displacement.toml", &[("n = [10, 10] }", "n = [10, 10] }\ncoarse_file = \"disk-clamped.msh\""), coarse], "coarse_file", &["mesh.coarse_file", "rectangle"]);
    // a gmsh mesh: the coarse file is needed, read only with the predictor, must exist, must hold
    // the groups the problem names, and must be coarser
    let gmsh = ("[solver]", "[solver]\npredictor = \"coarse\"");
    let file = "file = \"disk-clamped.msh\"";
    refused("no-coarse-file", "disk-clamped.toml", &[gmsh], "predictor", &["solver.predictor", "coarse_file"]);
    refused("coarse-file-alone", "disk-clamped.toml", &[(file, "file = \"disk-clamped.msh\"\ncoarse_file = \"disk-clamped.msh\"")], "coarse_file", &["mesh.coarse_file", "predictor = \"coarse\""]);
    refused("coarse-file-missing", "disk-clamped.toml", &[(file, "file = \"disk-clamped.msh\"\ncoarse_file = \"nothere.msh\""), gmsh], "coarse_file", &["mesh.coarse_file", "nothere.msh", "does not exist"]);
    // (the disk meshed coarser, its group 'left' named 'side')
    let path = variant("coarse-file-groups", "disk-clamped.toml", &[(file, "file = \"disk-clamped-lc1.msh\"\ncoarse_file = \"renamed.msh\""), gmsh]);
    let disk = std::fs::read_to_string(repo().join("meshes/disk-clamped.msh")).unwrap();
    write(path.parent().unwrap(), "renamed.msh", &disk.replacen("1 2 \"left\"", "1 2 \"side\"", 1));
    refused_at(&path, "coarse-file-groups", "group = \"left\"", &["coarse mesh renamed.msh", "boundary[0].group", "'left'"]);
    // a mesh of another plate with other groups: refused as another plate first
    refused("coarse-file-square", "disk-clamped.toml", &[(file, "file = \"disk-clamped.msh\"\ncoarse_file = \"sphere-ss-full.msh\""), gmsh], "coarse_file", &["coarse mesh sphere-ss-full.msh", "not the same plate", "(-20, -20)"]);
    // a mesh of another plate (the paper's strip, 1 x 100): the disk's node at (20, 0) is 19 away
    refused("coarse-file-elsewhere", "disk-clamped.toml", &[(file, "file = \"disk-clamped.msh\"\ncoarse_file = \"paper-r100.msh\""), gmsh], "coarse_file", &["mesh.coarse_file", "does not cover the plate", "gmsh node", "(20, 0)", "19 outside"]);
    // a larger plate (the coarse disk scaled by 2, the same groups) covers the plate: refused
    // the other way round, its node at (20 cos 45, 20 sin 45) x 2 lies 20 outside the disk
    let path = variant("coarse-file-larger", "disk-clamped.toml", &[(file, "file = \"disk-clamped-lc1.msh\"\ncoarse_file = \"big.msh\""), gmsh]);
    write(path.parent().unwrap(), "big.msh", &scaled_msh(&std::fs::read_to_string(repo().join("meshes/disk-clamped.msh")).unwrap(), 2.0));
    refused_at(&path, "coarse-file-larger", "coarse_file", &["mesh.coarse_file", "not the same plate", "(28.284271, 28.284271)", "20.01", "outside the mesh"]);
    // a smaller one, scaled by 0.5 (the disk's nodes outside it) and one squeezed along x2 by a
    // few per cent (every node within a fifth of a cell both ways: its area tells)
    let path = variant("coarse-file-smaller", "disk-clamped.toml", &[(file, "file = \"disk-clamped-lc1.msh\"\ncoarse_file = \"small.msh\""), gmsh]);
    write(path.parent().unwrap(), "small.msh", &scaled_msh(&std::fs::read_to_string(repo().join("meshes/disk-clamped.msh")).unwrap(), 0.5));
    refused_at(&path, "coarse-file-smaller", "coarse_file", &["mesh.coarse_file", "does not cover the plate"]);
    // an unreadable coarse file: the reader's message names it, and says which key of which
    // problem file asked for it
    let path = variant("coarse-file-msh22", "disk-clamped.toml", &[(file, "file = \"disk-clamped.msh\"\ncoarse_file = \"old.msh\""), gmsh]);
    write(path.parent().unwrap(), "old.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n");
    let (code, err) = stamp_run(&path, &path.with_extension("out"), &[]);
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("old.msh: MSH format version 2.2") && err.contains("read as mesh.coarse_file of") && err.contains("coarse-file-msh22.toml"), "{err}");
    refused("coarse-file-finer", "disk-clamped.toml", &[(file, "file = \"disk-clamped.msh\"\ncoarse_file = \"disk-clamped-lc1.msh\""), gmsh], "coarse_file", &["mesh.coarse_file", "2359 nodes", "fewer"]);
}

/// An ASCII MSH 4.1 text with every node's coordinates times `factor` (the lines of three numbers
/// in $Nodes).
fn scaled_msh(text: &str, factor: f64) -> String {
    let mut inside = false;
    let mut out = String::new();
    for line in text.lines() {
        match line {
            "$Nodes" => inside = true,
            "$EndNodes" => inside = false,
            _ => {}
        }
        let words: Vec<&str> = line.split_whitespace().collect();
        if inside && words.len() == 3 {
            out += &words.iter().map(|w| (w.parse::<f64>().unwrap() * factor).to_string()).collect::<Vec<_>>().join(" ");
        } else {
            out += line;
        }
        out.push('\n');
    }
    out
}

//! Punch shapes and motions without writing Rust: `shape = "expression"` (Psi in x1, x2, x3) and
//! `motion = [[t, d1, d2, d3], ...]` (a path in the load factor). The expression sphere gives the
//! built-in sphere's answers, a path equal to a linear motion gives identical results, a sphere
//! that comes down and slides carries its contact zone along at the same force, and bad
//! expressions and paths are refused at their place in the file.

mod common;
use common::*;
use std::path::{Path, PathBuf};
use std::process::Command;

struct Out {
    ok: bool,
    stderr: String,
}

fn stamp(args: &[&str], file: &Path) -> Out {
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).args(args).arg(file).output().unwrap();
    Out { ok: o.status.success(), stderr: String::from_utf8_lossy(&o.stderr).into_owned() }
}

/// Runs a problem into `out` (which it creates) and returns the folder.
fn run(problem: &Path, out: &str) -> PathBuf {
    let dir = temp_dir(out).join("out");
    let o = stamp(&["run", "-q", "--out", dir.to_str().unwrap()], problem);
    assert!(o.ok, "{}: {}", problem.display(), o.stderr);
    dir
}

/// The column `name` of history.csv, one value per step.
fn history(dir: &Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(dir.join("history.csv")).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let c = head.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name} in {head:?}"));
    lines.map(|l| l.split(',').nth(c).unwrap().parse().unwrap()).collect()
}

fn newton_per_step(dir: &Path) -> Vec<u64> {
    summary(dir)["steps"].as_array().unwrap().iter().map(|s| s["newton_iterations"].as_u64().unwrap()).collect()
}

/// The expression is the built-in sphere's Psi about its pole (0, 0, 0.5), |x - c|^2 - R^2 with
/// x - c = y + R e: written as (x3 - 200.5)^2 - 200^2 it carries that cancellation's round-off
/// (9e-12 in Psi), and the forces differ by 1e-8.
#[test]
fn the_sphere_written_as_an_expression_gives_the_built_in_spheres_answers() {
    let built_in = run(&repo().join("meshes/sphere-ss-displacement.toml"), "expr-builtin");
    let problem = variant(
        "expr-sphere",
        "sphere-ss-displacement.toml",
        &[("shape = \"sphere\"\ncenter = [0.0, 0.0, 200.5]     # touches the top face (x3 = 0.5) at the centre\nradius = 200.0", "shape = \"expression\"\npsi = \"(x1)^2 + (x2)^2 + (x3 - 0.5)^2 - 400 * (x3 - 0.5)\"")],
    );
    let expr = run(&problem, "expr-expr-out");
    let (a, b) = (history(&built_in, "sphere_force"), history(&expr, "sphere_force"));
    assert_eq!(a.len(), 5);
    assert_eq!(a.len(), b.len());
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        assert!(*x > 0.0 && (x - y).abs() <= 1e-8 * x.abs(), "step {}: force {x} (sphere) against {y} (expression)", k + 1);
    }
    // The same path up to round-off: Psi is summed in another order, so the last iterate of a
    // step may land on either side of the round-off criterion "|R| no longer halves" and take one
    // chord step more (measured: step 4 at |R| 7.3e-7 after 1.46e-6, 4 against 5 iterations).
    let (na, nb) = (newton_per_step(&built_in), newton_per_step(&expr));
    assert_eq!(na.len(), nb.len());
    for (k, (x, y)) in na.iter().zip(&nb).enumerate() {
        assert!(x.abs_diff(*y) <= 1, "step {}: {x} Newton iterations (sphere) against {y} (expression)", k + 1);
    }
    assert!(summary(&expr)["punches"][0]["surface"].as_str().unwrap().starts_with("expression psi = (x1)^2"));
}

#[test]
fn a_path_equal_to_the_linear_motion_gives_identical_results() {
    let linear = run(&repo().join("meshes/sphere-ss-displacement.toml"), "path-linear");
    let problem = variant("path-path", "sphere-ss-displacement.toml", &[("motion = [0.0, 0.0, -0.9]", "motion = [[1.0, 0.0, 0.0, -0.9]]")]);
    let path = run(&problem, "path-path-out");
    let a = std::fs::read_to_string(linear.join("history.csv")).unwrap();
    let b = std::fs::read_to_string(path.join("history.csv")).unwrap();
    assert_eq!(a, b);
    assert_eq!(summary(&path)["punches"][0]["motion_path"], serde_json::json!([[0.0, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, -0.9]]));
    assert_eq!(summary(&path)["punches"][0]["motion"], serde_json::json!([0.0, 0.0, -0.9]));
}

#[test]
fn a_sphere_that_comes_down_then_slides_carries_its_contact_zone_at_the_same_force() {
    let dir = run(&repo().join("meshes/sphere-slide.toml"), "slide");
    let t = history(&dir, "load_factor");
    let force = history(&dir, "sphere_force");
    let travel = history(&dir, "sphere_travel");
    assert_eq!(t.len(), 10);
    let pressed = force[4];
    assert!((t[4] - 0.5).abs() < 1e-12 && pressed > 0.0);
    for k in 0..10 {
        // travel is along the approach direction -x3: the depth, 0.05 from t = 0.5 on
        let depth = 0.05 * (t[k] / 0.5).min(1.0);
        assert!((travel[k] - depth).abs() <= 1e-12, "step {}: travel {} against {depth}", k + 1, travel[k]);
        // the contact zone's centre (the pressure-weighted mean of x1 over the nodes) follows the
        // slide: l_e = 2, and between nodes the nodal centroid leans towards the nearer nodes
        // (0.09 at most here); a tenth of an element is the tolerance
        let csv = std::fs::read_to_string(dir.join(format!("pressure_sphere_{:04}.csv", k + 1))).unwrap();
        let (mut sq, mut sqx) = (0.0, 0.0);
        for line in csv.lines().skip(1) {
            let f: Vec<f64> = line.split(',').take(7).map(|v| v.parse().unwrap()).collect();
            sq += f[6];
            sqx += f[6] * f[1];
        }
        let centre = sqx / sq;
        let expected = -6.0 + 12.0 * ((t[k] - 0.5) / 0.5).max(0.0);
        assert!((centre - expected).abs() <= 0.2, "step {}: contact centre x1 = {centre}, the sphere is at {expected}", k + 1);
        if t[k] > 0.5 {
            // frictionless on a uniformly supported plate: the force stays the same up to the
            // discretisation (the zone sampled at nodes differently between them: 3 % here)
            assert!((force[k] - pressed).abs() <= 0.05 * pressed, "step {}: force {} against {pressed} when the slide began", k + 1, force[k]);
        }
    }
    // the end is the start moved by six whole elements: the same discrete problem up to the edges,
    // 24 away from the zone
    assert!((force[9] - pressed).abs() <= 1e-6 * pressed, "force {} after the slide against {pressed} before", force[9]);
    // the slide is symmetric about x1 = 0: steps at -3.6 and +3.6, -1.2 and +1.2
    assert!((force[5] - force[8]).abs() <= 1e-6 * pressed && (force[6] - force[7]).abs() <= 1e-6 * pressed, "{force:?}");
}

/// The error of `stamp check` on the ellipsoid problem with `psi` replaced by `psi_text`.
fn psi_error(name: &str, psi_text: &str) -> String {
    let p = variant(name, "ellipsoid-expression.toml", &[("psi = \"(x1 / 120)^2 + (x2 / 80)^2 + ((x3 - 40.5) / 40)^2 - 1\"", &format!("psi = \"{psi_text}\""))]);
    let o = stamp(&["check"], &p);
    assert!(!o.ok, "{psi_text} was accepted");
    assert!(!o.stderr.contains("panicked"), "{}", o.stderr);
    o.stderr
}

#[test]
fn bad_expressions_are_refused_at_their_column_in_the_file() {
    let line = std::fs::read_to_string(repo().join("meshes/ellipsoid-expression.toml")).unwrap().lines().position(|l| l.starts_with("psi = ")).unwrap() + 1;
    // `psi = "` is 7 characters: the expression's column c is the file's column 7 + c
    let e = psi_error("psi-var", "(x1 / 120)^2 + (y / 80)^2 - 1");
    assert!(e.contains(&format!("line {line}, column 24: punch[0].psi: unknown variable 'y'")), "{e}");
    let e = psi_error("psi-func", "x1 + foo(x2) - 1");
    assert!(e.contains(&format!("line {line}, column 13: punch[0].psi: unknown function 'foo'")), "{e}");
    let e = psi_error("psi-end", "x1 * (x2 + 1");
    assert!(e.contains(&format!("line {line}, column 20: punch[0].psi: expected ')' to close the '(' at column 6")), "{e}");
    let e = psi_error("psi-op", "x1 + * x2");
    assert!(e.contains(&format!("line {line}, column 13: punch[0].psi: unexpected '*'")), "{e}");
    let e = psi_error("psi-args", "atan2(x1) - 1");
    assert!(e.contains(&format!("line {line}, column 8: punch[0].psi: atan2 takes 2 arguments, got 1")), "{e}");
    // a string with escapes: the column inside the expression is named
    let e = psi_error("psi-escape", "x1 + \\u0079");
    assert!(e.contains("punch[0].psi: column 6 of the expression: unknown variable 'y'"), "{e}");
    // not finite where the plate may touch: refused before the solve, with the point
    let e = psi_error("psi-nan", "sqrt(x1) - 1 + x3");
    assert!(e.contains(&format!("line {line}, column 7: punch[0].psi: psi is NaN at x = (-20, -20, 0.5)")), "{e}");
    // an expression needs psi, and psi belongs to an expression
    let p = variant("psi-missing", "ellipsoid-expression.toml", &[("psi = ", "# psi = ")]);
    let o = stamp(&["check"], &p);
    assert!(!o.ok && o.stderr.contains("an expression punch needs `psi`"), "{}", o.stderr);
    let p = variant("psi-sphere", "sphere-ss-displacement.toml", &[("radius = 200.0", "radius = 200.0\npsi = \"x1\"")]);
    let o = stamp(&["check"], &p);
    assert!(!o.ok && o.stderr.contains("punch[0].psi: `psi` belongs to shape = \"expression\""), "{}", o.stderr);
}

#[test]
fn a_psi_that_is_not_finite_during_the_solve_stops_the_run_with_the_point() {
    // finite on the plate at the start (x3 = 0.5 > 0.4) but not below x3 = 0.4, where the plate's
    // top face goes when the punch pushes it down
    let p = variant("psi-nan-run", "ellipsoid-expression.toml", &[("psi = \"(x1 / 120)^2 + (x2 / 80)^2 + ((x3 - 40.5) / 40)^2 - 1\"", "psi = \"(x1 / 120)^2 + (x2 / 80)^2 + ((x3 - 40.5) / 40)^2 - 1 + 0 * sqrt(x3 - 0.4)\"")]);
    let dir = temp_dir("psi-nan-run-out");
    let o = stamp(&["run", "-q", "--out", dir.to_str().unwrap()], &p);
    assert!(!o.ok, "the run went on");
    assert!(o.stderr.contains("punch[0].psi: psi is NaN at x = ("), "{}", o.stderr);
}

#[test]
fn bad_paths_are_refused_with_the_row() {
    let bad = |name: &str, motion: &str| {
        let p = variant(name, "sphere-slide.toml", &[("motion = [[0.5, 0.0, 0.0, -0.05], [1.0, 12.0, 0.0, -0.05]]", &format!("motion = {motion}"))]);
        let o = stamp(&["check"], &p);
        assert!(!o.ok, "{motion} was accepted");
        o.stderr
    };
    let line = std::fs::read_to_string(repo().join("meshes/sphere-slide.toml")).unwrap().lines().position(|l| l.starts_with("motion = [[")).unwrap() + 1;
    let e = bad("path-order", "[[0.5, 0.0, 0.0, -0.05], [0.5, 12.0, 0.0, -0.05]]");
    assert!(e.contains(&format!("line {line}")) && e.contains("row 1: the load factors must increase strictly"), "{e}");
    let e = bad("path-width", "[[0.5, 0.0, -0.05]]");
    assert!(e.contains("path row 0: expected [t, d1, d2, d3], got 3 numbers"), "{e}");
    let e = bad("path-start", "[[0.0, 1.0, 0.0, 0.0], [1.0, 0.0, 0.0, -0.05]]");
    assert!(e.contains("at t = 0 the displacement must be [0, 0, 0]"), "{e}");
    let e = bad("path-form", "\"down\"");
    assert!(e.contains("expected [d1, d2, d3] (the displacement at load factor 1) or rows [[t, d1, d2, d3], ...]"), "{e}");
    let e = bad("path-two", "[0.0, -0.05]");
    assert!(e.contains("got 2 numbers"), "{e}");
}

/// `stamp run` and `stamp check` on the ellipsoid problem with `psi` replaced and the punch moved
/// 0.5 into the plate: both refuse, with `wanted` in the message.
fn psi_refused(name: &str, psi_text: &str, wanted: &[&str]) {
    let ellipsoid = "psi = \"(x1 / 120)^2 + (x2 / 80)^2 + ((x3 - 40.5) / 40)^2 - 1\"";
    let p = variant(name, "ellipsoid-expression.toml", &[(ellipsoid, &format!("psi = \"{psi_text}\"")), ("force = 4000.0", "motion = [0.0, 0.0, -0.5]")]);
    let line = std::fs::read_to_string(&p).unwrap().lines().position(|l| l.starts_with("psi = ")).unwrap() + 1;
    let dir = temp_dir(&format!("{name}-out"));
    for o in [stamp(&["check"], &p), stamp(&["run", "-q", "--out", dir.to_str().unwrap()], &p)] {
        assert!(!o.ok, "{psi_text} was accepted: {}", o.stderr);
        assert!(o.stderr.contains(&format!("{name}.toml: line {line}, column 7: punch[0].psi: 'ellipsoid'")), "{}", o.stderr);
        for w in wanted {
            assert!(o.stderr.contains(w), "{w:?} not in {}", o.stderr);
        }
    }
}

#[test]
fn a_psi_without_a_usable_gradient_is_refused_before_the_solve() {
    // the ellipsoid scaled by 1e-170: Psi and its gradient are tiny, the gradient's square
    // underflows (the run "converged" with force 0)
    psi_refused("psi-tiny", "1e-170 * ((x1 / 120)^2 + (x2 / 80)^2 + ((x3 - 40.5) / 40)^2 - 1)", &["no surface near the plate", "underflows"]);
    // constants: no surface at all
    psi_refused("psi-minus-one", "-1", &["no surface near the plate", "|grad Psi| = 0"]);
    psi_refused("psi-zero", "0", &["no surface near the plate", "|grad Psi| = 0"]);
    psi_refused("psi-one", "1", &["no surface near the plate"]);
    // a surface far beyond the model: 1e-20 x3 + 1 is zero at x3 = -1e20
    psi_refused("psi-far", "1 + 1e-20 * x3", &["model sizes away"]);
    // a Psi flat (zero) over half the plate, which it covers: usable elsewhere, refused there
    psi_refused("psi-flat", "min(x3 - 0.5 + 0.01 * x1, 0 * x1)", &["covers the node at", "|grad Psi| = 0", "no force"]);
}

#[test]
fn a_path_that_carries_the_punch_through_the_plate_within_a_step_is_refused() {
    // a roller 1 above a strip (thickness 2) goes 20 down and back up by load factor 1
    let base = CANTILEVER.to_string()
        + "\n[[punch]]\nname = \"roller\"\nshape = \"cylinder\"\npoint = [0.0, 50.0, 5.0]\naxis = [1.0, 0.0, 0.0]\nradius = 4.0\nmotion = [[0.5, 0.0, 0.0, -20.0], [1.0, 0.0, 0.0, 0.0]]\n";
    for (case, solver, wanted) in [
        ("sweep-one-step", "steps = 1\nmax_increment = 1.0", "step 1 from load factor 0 to 1: the motion carries 'roller' through the plate"),
        ("sweep-increments", "steps = 1", "step 1 from load factor 0 to 0.25: the motion carries 'roller' through the plate"),
    ] {
        let dir = temp_dir(case);
        let p = write(&dir, &format!("{case}.toml"), &format!("{base}\n[solver]\n{solver}\n"));
        // stamp check foresees it (a warning: the solver's increments may be smaller)
        let o = stamp(&["check"], &p);
        assert!(o.ok && o.stderr.contains(&format!("warning: {}: increments of max_increment", p.display())) && o.stderr.contains("carries 'roller' through the plate"), "{case}: {}", o.stderr);
        let out = dir.join("out");
        let o = stamp(&["run", "-q", "--out", out.to_str().unwrap()], &p);
        assert!(!o.ok, "{case}: the run passed");
        assert!(o.stderr.contains(&format!("{case}.toml: line 21, column 1: punch[0].motion: {wanted}")), "{case}: {}", o.stderr);
        assert!(o.stderr.contains("use more steps: [solver] max_increment at most 0.025"), "{case}: {}", o.stderr);
        let s = summary(&out);
        assert_eq!(s["status"], "failed", "{s}");
        assert!(s["steps"].as_array().unwrap().iter().all(|e| e["converged"] != true), "no step is listed as converged: {s}");
    }
    // the path row in the step is named
    let dir = temp_dir("sweep-row");
    let p = write(&dir, "sweep-row.toml", &format!("{base}\n[solver]\nsteps = 1\nmax_increment = 1.0\n"));
    let o = stamp(&["run", "-q", "--out", dir.join("out").to_str().unwrap()], &p);
    assert!(o.stderr.contains("(the path's row at t = 0.5 lies inside the step)"), "{}", o.stderr);
    // down by 1 and back (into the plate, not through it): no complaint
    let dir = temp_dir("sweep-none");
    let p = write(&dir, "sweep-none.toml", &format!("{}\n[solver]\nsteps = 2\n", base.replace("-20.0]", "-0.5]")));
    let o = stamp(&["run", "-q", "--out", dir.join("out").to_str().unwrap()], &p);
    assert!(o.ok, "{}", o.stderr);
    let o = stamp(&["check"], &p);
    assert!(o.ok && !o.stderr.contains("through the plate"), "{}", o.stderr);
}

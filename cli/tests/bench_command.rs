//! `stamp bench`: the JSON interface scripts rely on, and the physics of the benchmark problem
//! (the timings themselves are measured by the benchmark, not asserted by tests).

use std::process::Command;

fn stamp() -> Command {
    Command::new(env!("CARGO_BIN_EXE_stamp"))
}

#[test]
fn bench_json_has_every_field_and_consistent_counts() {
    let out = stamp().args(["bench", "--sizes", "4,8", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let runs = v["runs"].as_array().expect("runs");
    assert_eq!(runs.len(), 2);
    for (r, n) in runs.iter().zip([4usize, 8]) {
        assert_eq!(r["n"].as_u64(), Some(n as u64));
        // (n+1)^2 nodes x 6 dofs; fixed: v1 on x1 = 0, v2 on x2 = 0, v3 on the two supported
        // edges (2 dofs each per node, the far corner counted once)
        let expected = 6 * (n + 1) * (n + 1) - (8 * (n + 1) - 2);
        assert_eq!(r["unknowns"].as_u64(), Some(expected as u64), "{r}");
        let steps = r["steps"].as_u64().unwrap();
        let its = r["newton_iterations"].as_u64().unwrap();
        assert!(steps >= 1 && its >= steps, "{r}");
        let s = &r["seconds"];
        for key in ["assembly", "contact", "symbolic", "factorization", "solve", "output", "total"] {
            let x = s[key].as_f64().unwrap_or_else(|| panic!("seconds.{key} missing in {r}"));
            assert!(x >= 0.0 && x.is_finite(), "seconds.{key} = {x}");
        }
        let parts: f64 = ["assembly", "contact", "symbolic", "factorization", "solve", "output"].iter().map(|k| s[*k].as_f64().unwrap()).sum();
        assert!(parts <= s["total"].as_f64().unwrap() * 1.0001, "phases exceed the total: {r}");
        assert!(r["peak_rss_bytes"].as_u64().unwrap() > 1 << 20, "{r}");
        // the sphere travels 2 (twice the thickness): the plate centre follows it within the
        // penalty's penetration, and the punch pushes down on the plate
        let w = r["centre_deflection"].as_f64().unwrap();
        assert!((w + 2.0).abs() < 0.05, "centre deflection {w}");
        assert!(r["reaction"].as_f64().unwrap() > 0.0, "{r}");
        // each factorisation follows an assembly with the tangent
        assert!(r["assemblies"].as_u64().unwrap() >= r["factorizations"].as_u64().unwrap());
    }
}

#[test]
fn bench_table_lists_each_size_and_rejects_a_zero_size() {
    let out = stamp().args(["bench", "--sizes", "3"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("unknowns") && text.contains("factor") && text.contains("peak RSS"), "{text}");
    assert!(text.lines().any(|l| l.trim_start().starts_with("3 ")), "{text}");

    let out = stamp().args(["bench", "--sizes", "0"]).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("positive"), "{}", String::from_utf8_lossy(&out.stderr));
}

#[test]
fn bench_with_reuse_gives_the_same_answer_with_fewer_factorisations() {
    let run = |extra: &[&str]| {
        let out = stamp().args(["bench", "--sizes", "12", "--json"]).args(extra).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        v["runs"][0].clone()
    };
    let (plain, reuse) = (run(&[]), run(&["--reuse"]));
    let f = |r: &serde_json::Value, k: &str| r[k].as_f64().unwrap();
    let ls = |r: &serde_json::Value, k: &str| r["linear_solver"][k].as_u64().unwrap();
    // the plate's tangent is not symmetric: GMRES preconditioned by the LDL^T of its symmetric part
    assert_eq!(ls(&plain, "lu_fallbacks"), 0, "{plain}");
    assert_eq!(ls(&plain, "reused"), 0, "{plain}");
    assert_eq!(ls(&plain, "preconditioned"), plain["factorizations"].as_u64().unwrap(), "{plain}");
    assert!(ls(&reuse, "reused") > 0, "{reuse}");
    assert!(reuse["factorizations"].as_u64().unwrap() < plain["factorizations"].as_u64().unwrap(), "{plain}\n{reuse}");
    // reuse is decided by measured times (a reused preconditioner while it is cheaper than a new
    // factorisation), so on a loaded machine the inexact solves may differ and cost an iteration:
    // the answer must be the same, the iterations about the same
    let (ni, nr) = (plain["newton_iterations"].as_i64().unwrap(), reuse["newton_iterations"].as_i64().unwrap());
    assert!((ni - nr).abs() <= 2, "Newton iterations {ni} without reuse, {nr} with");
    for k in ["centre_deflection", "reaction"] {
        assert!((f(&plain, k) / f(&reuse, k) - 1.0).abs() < 1e-8, "{k}: {plain}\n{reuse}");
    }
}

#[test]
fn bench_runs_the_displacement_driven_problem_file_on_n_by_n_meshes() {
    let out = stamp().args(["bench", "--problem", "sphere-displacement", "--sizes", "4,6", "--json"]).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON on stdout");
    let runs = v["runs"].as_array().expect("runs");
    assert_eq!(runs.len(), 2);
    for (r, n) in runs.iter().zip([4u64, 6]) {
        assert_eq!(r["n"].as_u64(), Some(n));
        // meshes/sphere-ss-displacement.toml on an n x n mesh: the same dofs as the default bench
        let n = n as usize;
        assert_eq!(r["unknowns"].as_u64(), Some((6 * (n + 1) * (n + 1) - (8 * (n + 1) - 2)) as u64), "{r}");
        // its 5 equal targets, each a converged step (cut-backs would add steps)
        let (steps, cutbacks) = (r["steps"].as_u64().unwrap(), r["cutbacks"].as_u64().unwrap());
        assert_eq!(steps, 5 + cutbacks, "{r}");
        assert!(r["newton_iterations"].as_u64().unwrap() >= steps, "{r}");
        // the sphere moves down 0.9 and the augmented Lagrangian holds the penetration below 1e-6:
        // the top face at the centre is at -0.9 (the mid-surface a little less: the thickness shrinks)
        let w = r["centre_deflection"].as_f64().unwrap();
        assert!(w < -0.89 && w > -0.9, "centre deflection {w}");
        assert!(r["reaction"].as_f64().unwrap() > 0.0, "{r}");
    }
    // the table names the problem and has the per-step and cut-back columns
    let out = stamp().args(["bench", "--problem", "sphere-displacement", "--sizes", "4"]).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("sphere-ss-displacement.toml") && text.contains("cuts") && text.contains("/step"), "{text}");
    let out = stamp().args(["bench", "--problem", "cube"]).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("sphere-displacement"), "{}", String::from_utf8_lossy(&out.stderr));
}

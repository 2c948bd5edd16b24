//! A run owns its output folder: `stamp run` removes what the previous run wrote there (and only
//! that) before it writes, so a 2-step run after a 10-step run leaves the 2-step run's files and
//! the user's own files, nothing else.

mod common;
use common::*;
use std::collections::BTreeSet;
use std::path::Path;
use std::process::Command;

/// A small clamped plate under a fixed sphere pushed into it (linear, quick), `steps` equal steps.
fn problem(steps: usize, plot: bool) -> String {
    format!(
        r#"[mesh]
rectangle = {{ x = [0.0, 8.0], y = [0.0, 8.0], n = [4, 4] }}
[plate]
thickness = 1.0
E = 1000.0
nu = 0.3
kinematics = "linear"
[[boundary]]
group = "boundary"
fix = ["clamped"]
[[punch]]
name = "ball"
shape = "sphere"
center = [4.0, 4.0, 20.5]
radius = 20.0
motion = [0.0, 0.0, -0.05]
[solver]
steps = {steps}
max_increment = 1.0
[output]
plot = {plot}
"#
    )
}

fn names(dir: &Path) -> BTreeSet<String> {
    std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect()
}

fn run(problem: &Path, out: &Path) {
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).args(["run", "-q", "--out"]).arg(out).arg(problem).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

fn set(v: &[&str]) -> BTreeSet<String> {
    v.iter().map(|s| s.to_string()).collect()
}

#[test]
fn a_rerun_leaves_only_its_own_files_and_the_users() {
    let dir = temp_dir("rerun");
    let out = dir.join("out");
    std::fs::create_dir_all(&out).unwrap();
    // the user's files: one from before any run, named like an output, and one added between runs
    std::fs::write(out.join("mine.vtu"), "the user's").unwrap();
    let long = dir.join("p.toml");
    std::fs::write(&long, problem(10, true)).unwrap();
    run(&long, &out);
    let first = names(&out);
    assert_eq!(first.iter().filter(|n| n.ends_with(".vtu")).count(), 11, "10 steps and the user's: {first:?}");
    assert_eq!(first.iter().filter(|n| n.starts_with("pressure_") && n.ends_with(".csv")).count(), 10, "{first:?}");
    assert_eq!(first.iter().filter(|n| n.starts_with("probe_") && n.ends_with(".csv")).count(), 10, "{first:?}");
    assert!(first.contains("history.csv") && first.contains("force_travel_ball.png") && first.contains("probe_ball.svg"), "{first:?}");
    std::fs::write(out.join("notes.txt"), "the user's").unwrap();

    let short = dir.join("p.toml");
    std::fs::write(&short, problem(2, false)).unwrap();
    run(&short, &out);
    let want = set(&[".stamp-lock", ".stamp-run", "mine.vtu", "notes.txt", "summary.json", "p.pvd", "p_0001.vtu", "p_0002.vtu", "pressure_ball_0001.csv", "pressure_ball_0002.csv", "history.csv"]);
    assert_eq!(names(&out), want);
    assert_eq!(std::fs::read_to_string(out.join("mine.vtu")).unwrap(), "the user's");
    // the .pvd names the new run's steps only
    let pvd = std::fs::read_to_string(out.join("p.pvd")).unwrap();
    assert!(pvd.contains("p_0002.vtu") && !pvd.contains("p_0003.vtu"), "{pvd}");

    // a run of another problem file into the same folder: the first problem's files go too
    let other = dir.join("q.toml");
    std::fs::write(&other, problem(1, false)).unwrap();
    run(&other, &out);
    assert_eq!(names(&out), set(&[".stamp-lock", ".stamp-run", "mine.vtu", "notes.txt", "summary.json", "q.pvd", "q_0001.vtu", "pressure_ball_0001.csv", "history.csv"]));
}

#[test]
fn a_refused_problem_leaves_the_previous_run_alone() {
    let dir = temp_dir("refused");
    let out = dir.join("out");
    let good = dir.join("p.toml");
    std::fs::write(&good, problem(2, false)).unwrap();
    run(&good, &out);
    let before = names(&out);
    // the sphere sunk into the plate: refused by the checks, before anything is removed or written
    let bad = dir.join("bad.toml");
    std::fs::write(&bad, problem(2, false).replace("20.5]", "19.5]")).unwrap();
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).args(["run", "-q", "--out"]).arg(&out).arg(&bad).output().unwrap();
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("starts inside the plate"));
    assert_eq!(names(&out), before);
}

//! A run against what happens around it: a second run into its folder, signals, kill -9, files of
//! the folder that are not regular files, input files in the output folder.

mod common;
use common::*;
use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A run of about 10 000 quick steps (a small clamped plate pushed down by 1e-4 of the path at a
/// time; only the target is written): long enough to be interrupted.
const LONG: &str = r#"[mesh]
rectangle = { x = [0.0, 8.0], y = [0.0, 8.0], n = [16, 16] }
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
max_increment = 1e-4
[output]
every_step = false
plot = false
"#;

/// The same plate in two written steps: quick.
fn short() -> String {
    LONG.replace("max_increment = 1e-4", "steps = 2").replace("every_step = false", "every_step = true")
}

fn stamp() -> Command {
    Command::new(env!("CARGO_BIN_EXE_stamp"))
}

fn run_out(problem: &Path, out: &Path) -> Output {
    stamp().args(["run", "-q", "--out"]).arg(out).arg(problem).output().unwrap()
}

/// Start a run of `problem` into `out` and wait until its summary.json says "running" with a
/// converged step in history.csv (it is then inside the solve).
fn start(problem: &Path, out: &Path) -> Child {
    let mut child = stamp().args(["run", "-q", "--out"]).arg(out).arg(problem).stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
    let t0 = Instant::now();
    loop {
        let ready = std::fs::read_to_string(out.join("history.csv")).map(|h| h.lines().count() > 3).unwrap_or(false);
        if ready {
            return child;
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("the run ended before it was under way: {status}");
        }
        assert!(t0.elapsed() < Duration::from_secs(60), "the run did not start");
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn kill(child: &Child, signal: &str) {
    let ok = Command::new("kill").args([signal, &child.id().to_string()]).status().unwrap().success();
    assert!(ok, "kill {signal} failed");
}

#[test]
fn a_second_run_into_a_folder_in_use_is_refused_until_the_first_is_gone() {
    let dir = temp_dir("lock");
    let out = dir.join("out");
    let long = write(&dir, "long.toml", LONG);
    let other = write(&dir, "other.toml", &short());
    let mut first = start(&long, &out);
    let o = run_out(&other, &out);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "the second run was let in: {err}");
    assert!(err.contains("in use") && err.contains(&format!("process {}", first.id())), "{err}");
    // the first run's files are still there, and it still runs
    assert!(out.join("summary.json").is_file() && out.join("history.csv").is_file());
    assert!(first.try_wait().unwrap().is_none(), "the first run ended");
    assert!(!out.join("other.pvd").exists());
    // killed without a chance to clean up: its lock is stale and taken over
    kill(&first, "-KILL");
    first.wait().unwrap();
    let o = run_out(&other, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(summary(&out)["status"], "converged");
}

/// Run `stamp run` on `problem` into `out`; a run still going after `secs` seconds is killed and
/// reported as hanging.
fn run_within(problem: &Path, out: &Path, secs: u64) -> Output {
    let mut child = stamp().args(["run", "-q", "--out"]).arg(out).arg(problem).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > Duration::from_secs(secs) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("stamp run hangs (killed after {secs} s)");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

#[test]
fn a_fifo_in_place_of_the_runs_own_files_is_refused_at_once() {
    let dir = temp_dir("fifo");
    let p = write(&dir, "p.toml", &short());
    for name in [".stamp-run", "summary.json", ".stamp-lock"] {
        let out = dir.join(format!("out{}", name.replace('.', "_")));
        std::fs::create_dir_all(&out).unwrap();
        let fifo = out.join(name);
        assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
        let o = run_within(&p, &out, 20);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{name}: {err}");
        assert!(err.contains(&fifo.display().to_string()) && err.contains("is a FIFO, not a regular file"), "{name}: {err}");
        // nothing written, the FIFO left alone
        assert!(!out.join("p.pvd").exists() && !out.join("history.csv").exists(), "{name}");
        assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo(), "{name}");
    }
}

#[test]
fn an_input_named_like_an_output_in_the_output_folder_is_refused() {
    let meshes = repo().join("meshes");
    let cases = [
        ("disk-clamped.toml", "file = \"disk-clamped.msh\"", "disk-clamped.msh", "history.csv", "mesh.file"),
        ("stl-die.toml", "file = \"stl-die.stl\"", "stl-die.stl", "probe_die_0001.csv", "punch[0].file"),
        ("stl-die.toml", "file = \"stl-die.stl\"", "stl-die.stl", "p_0001.vtu", "punch[0].file"),
    ];
    for (k, (shipped, line, input, name, key)) in cases.into_iter().enumerate() {
        let dir = temp_dir(&format!("inputs{k}"));
        let out = dir.join("out");
        std::fs::create_dir_all(&out).unwrap();
        std::fs::copy(meshes.join(input), out.join(name)).unwrap();
        let original = std::fs::read(out.join(name)).unwrap();
        let text = std::fs::read_to_string(meshes.join(shipped)).unwrap().replace(line, &format!("file = \"out/{name}\""));
        let p = write(&dir, "p.toml", &text);
        let o = run_out(&p, &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{name}: {err}");
        assert!(err.contains(key) && err.contains(name) && err.contains("named like one of stamp's outputs"), "{name}: {err}");
        assert_eq!(std::fs::read(out.join(name)).unwrap(), original, "{name} was changed");
        assert!(!out.join("summary.json").exists(), "{name}");
    }
    // the problem file itself
    let dir = temp_dir("inputs-problem");
    let p = write(&dir, "summary.json", &short());
    let o = run_out(&p, &dir);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("the problem file") && err.contains("summary.json"), "{err}");
    assert_eq!(std::fs::read_to_string(&p).unwrap(), short());
}

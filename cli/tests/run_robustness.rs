//! A run against what happens around it: a second run into its folder, signals, kill -9, files of
//! the folder that are not regular files, input files in the output folder, a full disk, a limit
//! on the address space, a load path that crawls.

mod common;
use common::*;
use std::collections::BTreeSet;
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

/// Wait at most `secs` seconds for `child` to end (killing it and failing after that).
fn finish(mut child: Child, secs: u64) -> Output {
    let t0 = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if t0.elapsed() > Duration::from_secs(secs) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("stamp run did not end within {secs} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
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

/// [`LONG`] listing every step in summary.json (no file per step).
fn long_listing_steps() -> String {
    LONG.replace("every_step = false", "every_step = true\nvtu = false\ncsv = false")
}

/// The data rows of history.csv.
fn history_rows(out: &Path) -> usize {
    std::fs::read_to_string(out.join("history.csv")).unwrap().lines().count() - 1
}

#[test]
fn ctrl_c_and_sigterm_end_a_run_cleanly_with_the_steps_written() {
    for (signal, status) in [("-INT", 130), ("-TERM", 143)] {
        let dir = temp_dir(&format!("signal{signal}"));
        let out = dir.join("out");
        let p = write(&dir, "p.toml", &long_listing_steps());
        let child = start(&p, &out);
        kill(&child, signal);
        let o = finish(child, 60);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(status), "{signal}: {err}");
        assert!(err.contains("interrupted") && !err.contains("panicked"), "{signal}: {err}");
        let s = summary(&out);
        assert_eq!(s["status"], "interrupted", "{signal}");
        let name = if signal == "-INT" { "SIGINT" } else { "SIGTERM" };
        assert!(s["error"].as_str().unwrap().contains(name), "{signal}: {}", s["error"]);
        // every step listed converged and written, the abandoned one not listed; history.csv the same
        let steps = s["steps"].as_array().unwrap();
        assert!(!steps.is_empty() && steps.iter().all(|e| e["converged"] == true), "{signal}: {steps:?}");
        assert_eq!(steps.len(), history_rows(&out), "{signal}");
        // the folder is free again: the manifest says the run is over
        let manifest = std::fs::read_to_string(out.join(".stamp-run")).unwrap();
        assert!(manifest.contains("\"complete\""), "{signal}: {manifest}");
    }
}

#[test]
fn the_next_run_cleans_up_after_a_run_killed_with_sigkill() {
    let dir = temp_dir("sigkill");
    let out = dir.join("out");
    let long = write(&dir, "long.toml", &LONG.replace("every_step = false", "every_step = true"));
    let child = start(&long, &out);
    kill(&child, "-KILL");
    let mut child = child;
    child.wait().unwrap();
    // what a kill in the middle of a write leaves: a temporary file (and maybe a step's files
    // that summary.json does not list yet)
    std::fs::write(out.join(".summary.json.tmp-999999-7"), "{\"status\": \"runn").unwrap();
    std::fs::write(out.join(".long_0042.vtu.tmp-999999-8"), "<VTKFile").unwrap();
    std::fs::write(out.join("notes.tmp-1-2"), "the user's").unwrap();
    assert!(std::fs::read_dir(&out).unwrap().count() > 5);
    let short = write(&dir, "long.toml", &short());
    let o = run_out(&short, &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // left: the new run's files (those summary.json lists and the others it writes) and the user's
    let left: BTreeSet<String> = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    let mut want: BTreeSet<String> = [".stamp-lock", ".stamp-run", "history.csv", "long.pvd", "notes.tmp-1-2", "summary.json"].iter().map(|s| s.to_string()).collect();
    for step in summary(&out)["steps"].as_array().unwrap() {
        want.insert(step["vtu"].as_str().unwrap().to_string());
        want.extend(step["csv"].as_array().unwrap().iter().map(|c| c.as_str().unwrap().to_string()));
    }
    assert_eq!(left, want);
}

/// A tmpfs of `size` mounted on a fresh folder, unmounted when dropped (mounting needs root, which
/// the project's machines and CI are).
struct SmallDisk(std::path::PathBuf);

impl SmallDisk {
    fn mount(name: &str, size: &str) -> SmallDisk {
        let dir = temp_dir(name);
        let o = Command::new("mount").args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"]).arg(&dir).output().unwrap();
        assert!(o.status.success(), "this test needs root to mount a small tmpfs: {}", String::from_utf8_lossy(&o.stderr));
        SmallDisk(dir)
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
    }
}

#[test]
fn a_full_disk_never_leaves_summary_json_saying_running() {
    let problem = repo().join("meshes/sphere-clamped.toml");
    let mut ended_failed = 0;
    for size in ["40k", "48k", "64k", "96k", "128k"] {
        let disk = SmallDisk::mount(&format!("full-{size}"), size);
        let out = disk.0.join("out");
        let o = run_out(&problem, &out);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains("No space left on device") && !err.contains("panicked"), "{size}: {err}");
        match std::fs::read_to_string(out.join("summary.json")) {
            // refused before the run (no room for its summary), or summary.json removed
            Err(_) => assert!(err.contains("cannot set aside") || err.contains("was removed"), "{size}: {err}"),
            Ok(text) => {
                let s: serde_json::Value = serde_json::from_str(&text).unwrap();
                assert_eq!(s["status"], "failed", "{size}: {err}");
                assert!(s["error"].as_str().unwrap().contains("No space left on device"), "{size}");
                ended_failed += 1;
            }
        }
        assert!(!out.join(".stamp-reserve").exists(), "{size}");
    }
    assert!(ended_failed >= 2, "the disks were not filled during the runs");
}

/// `stamp` with these arguments under an address-space limit (`ulimit -v`) of `kib` KiB.
fn under_ulimit_v(kib: u64, args: &[&std::ffi::OsStr]) -> Output {
    Command::new("sh").arg("-c").arg(format!("ulimit -v {kib} && exec \"$0\" \"$@\"")).arg(env!("CARGO_BIN_EXE_stamp")).args(args).output().unwrap()
}

#[test]
fn a_model_beyond_the_address_space_limit_is_refused_before_the_solve() {
    // the sphere-displacement plate on 100 x 100 cells: about 0.37 GiB, under a limit of 0.7 GiB
    // (0.2 GiB once the threads' stacks and heaps are set aside)
    let p = variant("ulimit", "sphere-ss-displacement.toml", &[("n = [10, 10]", "n = [100, 100]")]);
    let out = p.parent().unwrap().join("out");
    let o = under_ulimit_v(700 * 1024, &["run".as_ref(), "-q".as_ref(), "--out".as_ref(), out.as_os_str(), p.as_os_str()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("mesh.rectangle") && err.contains("ulimit -v") && err.contains("0.37 GiB") && !err.contains("allocation"), "{err}");
    assert!(!out.join("summary.json").exists(), "refused before anything is written");
    // a limit with room for the shipped 10 x 10 plate (0.06 GiB beside the 0.5 GiB of stacks and
    // heaps): solved. A dense kernel that reserves twice the L3 cache per thread (faer's "std"
    // feature, private-gemm-x86) aborted here on a CPU reporting 260 MiB of L3, and under 700 MiB
    // on one reporting 480 MiB
    let small = variant("ulimit-small", "sphere-ss-displacement.toml", &[]);
    let out = small.parent().unwrap().join("out");
    let o = under_ulimit_v(600 * 1024, &["run".as_ref(), "-q".as_ref(), "--out".as_ref(), out.as_os_str(), small.as_os_str()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

#[test]
fn an_stl_die_counts_in_the_memory_estimate() {
    // a binary STL of 400 000 facets (20 MB): about 0.15 GiB once read; the model itself 0.06 GiB.
    // Under a limit that leaves 0.15 GiB it is refused before it is read.
    let p = variant("stl-memory", "stl-die.toml", &[("file = \"stl-die.stl\"", "file = \"big.stl\"")]);
    let n: u32 = 400_000;
    let mut bytes = vec![0u8; 84 + 50 * n as usize];
    bytes[80..84].copy_from_slice(&n.to_le_bytes());
    std::fs::write(p.parent().unwrap().join("big.stl"), &bytes).unwrap();
    let o = under_ulimit_v((512 + 150) * 1024, &["check".as_ref(), p.as_os_str()]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(err.contains("STL die big.stl 0.15 GiB") && err.contains("ulimit -v"), "{err}");
}

#[test]
fn a_path_that_crawls_stops_with_the_reason_and_is_warned_about() {
    // cells 2 wide and 1e5 long: Newton needs increments of about 1e-4 of the load, step after step
    let p = variant("crawl", "sphere-ss-displacement.toml", &[("y = [0.0, 20.0], n = [10, 10]", "y = [0.0, 1e6], n = [10, 10]")]);
    let o = stamp().arg("check").arg(&p).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success() && err.contains("mesh.rectangle: 100 of 100 cells have an aspect ratio above 1000 (the worst 5.000e4"), "{err}");
    let out = p.parent().unwrap().join("out");
    let t0 = Instant::now();
    let o = run_within(&p, &out, 120);
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let s = summary(&out);
    assert_eq!(s["status"], "failed");
    let e = s["error"].as_str().unwrap();
    assert!(e.contains("the path crawls") && e.contains("max_steps = 1000"), "{e}");
    // stopped after a converged (and written) step: every step listed converged
    let steps = s["steps"].as_array().unwrap();
    assert!(steps.len() >= 50 && steps.iter().all(|e| e["converged"] == true), "{}", steps.len());
    assert!(t0.elapsed() < Duration::from_secs(100));
}

#[test]
fn max_steps_bounds_the_path_and_cannot_be_fewer_than_it_needs() {
    // 4 targets at increments growing from 1e-3 of the first: far more than 6 steps
    let text = short().replace("steps = 2", "targets = [0.25, 0.5, 0.75, 1.0]\ninitial_increment = 0.001\nmax_steps = 6");
    let dir = temp_dir("max-steps");
    let p = write(&dir, "p.toml", &text);
    let out = dir.join("out");
    let o = run_out(&p, &out);
    assert_eq!(o.status.code(), Some(1), "{}", String::from_utf8_lossy(&o.stderr));
    let s = summary(&out);
    assert_eq!(s["status"], "failed");
    assert!(s["error"].as_str().unwrap().contains("max_steps = 6 steps converged"), "{}", s["error"]);
    assert_eq!(s["steps"].as_array().unwrap().len(), 6);
    // fewer than the 4 targets: refused where it is written
    let p = write(&dir, "q.toml", &text.replace("max_steps = 6", "max_steps = 3"));
    let o = stamp().arg("check").arg(&p).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("solver.max_steps: 3 is fewer than the 4 steps the path needs"), "{err}");
}

#[test]
fn an_abort_leaves_summary_json_saying_failed_not_running() {
    // SIGABRT is what an allocation that fails ends the process with
    let dir = temp_dir("abort");
    let out = dir.join("out");
    let p = write(&dir, "p.toml", &long_listing_steps());
    let child = start(&p, &out);
    kill(&child, "-ABRT");
    let o = finish(child, 60);
    assert!(!o.status.success());
    let s = summary(&out);
    assert_eq!(s["status"], "failed");
    assert!(s["error"].as_str().unwrap().contains("the process aborted (SIGABRT)"), "{}", s["error"]);
    let steps = s["steps"].as_array().unwrap();
    assert!(!steps.is_empty() && steps.iter().all(|e| e["converged"] == true));
    assert!(steps.len() <= history_rows(&out));
    // the next run into the folder is let in and cleans up
    let o = run_out(&write(&dir, "p.toml", &short()), &out);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(!out.join(".stamp-reserve").exists());
}

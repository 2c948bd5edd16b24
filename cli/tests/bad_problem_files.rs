//! Bad problem files through `stamp run`: every setting out of its range, a model too large for
//! the memory, a problem file that is not a regular file, long user strings and write failures
//! give a short error naming the file, the key and the line, exit status 1, and never a panic, an
//! abort or a hang; summary.json always tells the truth.

mod common;
use common::*;
use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

/// A cantilever strip on the built-in rectangle (fast to solve: 4 steps).
const BASE: &str = CANTILEVER;

/// A cylinder punch above the strip, for the punch keys.
const PUNCH: &str = "\n[[punch]]\nname = \"roller\"\nshape = \"cylinder\"\npoint = [0.0, 50.0, 5.0]\naxis = [1.0, 0.0, 0.0]\nradius = 4.0\nmotion = [0.0, 0.0, -1.0]\n";

/// The longest message we accept (the message, and under it the problem file's line: at most 60 of
/// its characters).
const MAX_MESSAGE: usize = 480;

/// 1-based line of the first line of `text` that contains `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap_or_else(|| panic!("{needle} not in the text")) + 1
}

/// Run `stamp run --quiet` on `path` with a time limit; (exit code, stderr).
fn stamp_run(path: &Path, out: &Path, limit: Duration) -> (Option<i32>, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_stamp"))
        .args(["run", "--quiet", "--out"])
        .arg(out)
        .arg(path)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    loop {
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            std::io::Read::read_to_string(child.stderr.as_mut().unwrap(), &mut err).unwrap();
            return (status.code(), err);
        }
        if start.elapsed() > limit {
            let _ = child.kill();
            let _ = child.wait();
            panic!("stamp run {} did not finish within {limit:?}", path.display());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// `stamp run` on `text` must fail with exit status 1 within 20 s, with one short message naming
/// the file, every one of `wanted` and "line L" of the line containing `at` (when given).
fn refused(case: &str, text: &str, at: Option<&str>, wanted: &[&str]) -> String {
    let dir = temp_dir(&format!("badfile-{case}"));
    let path = write(&dir, &format!("{case}.toml"), text);
    let (code, err) = stamp_run(&path, &dir.join("out"), Duration::from_secs(20));
    eprintln!("{case}: {err}");
    assert_eq!(code, Some(1), "{case}: exit code {code:?}, stderr {err}");
    assert!(err.contains(&format!("{case}.toml")), "{case}: the file is not named: {err}");
    if let Some(at) = at {
        let line = format!("line {}", line_of(text, at));
        assert!(err.contains(&line), "{case}: {line} not named: {err}");
    }
    for w in wanted {
        assert!(err.contains(w), "{case}: {w:?} not in: {err}");
    }
    // the length without the file's path (which is the user's own)
    let len = err.replace(&path.display().to_string(), "").chars().count();
    assert!(len <= MAX_MESSAGE, "{case}: a message of {len} characters: {err}");
    assert!(!err.contains("panicked"), "{case}: {err}");
    err
}

/// `stamp check` on the problem written by [`refused`] (or any file): (exit code, stderr).
fn stamp_check(path: &Path) -> (Option<i32>, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("check").arg(path).output().unwrap();
    (o.status.code(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// [`refused`] by `stamp run`, and by `stamp check` with the same message.
fn refused_by_both(case: &str, text: &str, at: Option<&str>, wanted: &[&str]) -> String {
    let err = refused(case, text, at, wanted);
    let dir = temp_dir(&format!("badfile-check-{case}"));
    let path = write(&dir, &format!("{case}.toml"), text);
    let (code, check_err) = stamp_check(&path);
    assert_eq!(code, Some(1), "{case}: stamp check: exit code {code:?}, stderr {check_err}");
    for w in wanted {
        assert!(check_err.contains(w), "{case}: stamp check: {w:?} not in: {check_err}");
    }
    err
}

fn solver(keys: &str) -> String {
    format!("{BASE}\n[solver]\n{keys}\n")
}

#[test]
fn step_counts_and_rectangle_sizes_out_of_range_are_refused() {
    refused("steps_max", &solver("steps = 9223372036854775807"), Some("steps ="), &["solver.steps", "from 1 to 100000"]);
    refused("steps_float", &solver("steps = 1e12"), Some("steps ="), &["solver.steps", "from 1 to 100000, got the decimal number 1000000000000"]);
    refused("steps_zero", &solver("steps = 0"), Some("steps ="), &["solver.steps", "from 1 to 100000"]);
    let rect = |n: &str| BASE.replace("n = [1, 40]", n);
    refused("n_2e32", &rect("n = [4294967296, 4294967296]"), Some("rectangle"), &["mesh.rectangle.n", "1 to 1000000"]);
    refused("n_u64max", &rect("n = [18446744073709551615, 1]"), Some("rectangle"), &["mesh.rectangle.n", "1 to 1000000, got [18446744073709551615, 1]"]);
    refused("n_negative", &rect("n = [-3, 4]"), Some("rectangle"), &["mesh.rectangle.n", "[-3, 4]"]);
    // a model far beyond any machine's memory: refused up front with the estimate, in no time
    let start = Instant::now();
    let e = refused("n_5000", &rect("n = [5000, 5000]"), Some("rectangle"), &["mesh.rectangle.n", "25010001 nodes", "GiB", "coarser mesh"]);
    assert!(start.elapsed() < Duration::from_secs(5), "{e}");
    // extents: finite, increasing, with a finite length, cells distinguishable
    refused("x_huge", &BASE.replace("x = [0.0, 1.0]", "x = [-1e308, 1e308]"), Some("rectangle"), &["mesh.rectangle.x", "magnitude at most 1e100", "[-1e308, 1e308]"]);
    refused("x_backwards", &BASE.replace("x = [0.0, 1.0]", "x = [1.0, 0.0]"), Some("rectangle"), &["mesh.rectangle.x", "increasing"]);
    // a third number is not dropped
    refused("x_three", &BASE.replace("x = [0.0, 1.0]", "x = [0.0, 1.0, 30.0]"), Some("rectangle"), &["mesh.rectangle.x", "exactly two numbers", "got 3"]);
    refused("y_one", &BASE.replace("y = [0.0, 100.0]", "y = [100.0]"), Some("rectangle"), &["mesh.rectangle.y", "exactly two numbers", "got 1"]);
    refused("n_three", &rect("n = [1, 40, 2]"), Some("rectangle"), &["mesh.rectangle.n", "exactly two numbers", "got 3"]);
    refused("y_tiny_cells", &BASE.replace("y = [0.0, 100.0]", "y = [1e6, 1.0000000000001e6]"), Some("rectangle"), &["mesh.rectangle.y", "too small to tell their nodes apart"]);
}

#[test]
fn a_plot_group_the_mesh_lacks_is_refused_by_check_as_by_run() {
    refused_by_both("plot_group", &format!("{BASE}\n[output]\nplot_group = \"nosuch\"\n"), Some("plot_group"), &["output.plot_group", "no group named 'nosuch'"]);
    // arc needs a curve: the surface 'all' is not one
    refused_by_both("plot_group_arc", &format!("{BASE}\n[output]\nplot_axis = \"arc\"\nplot_group = \"all\"\n"), Some("plot_group"), &["output.plot_group", "no curve group named 'all'"]);
}

#[test]
fn a_number_with_a_unit_is_told_that_units_are_labels() {
    for (case, from, to, shown) in [
        ("unit_E", "E = 2.0e4", "E = 210 GPa", "'210 GPa'"),
        ("unit_glued", "E = 2.0e4", "E = 2e4MPa", "'2e4 MPa'"),
        ("unit_thickness", "thickness = 2.0", "thickness = 2 mm", "'2 mm'"),
        ("unit_in_array", "force = [0.0, 0.0, 0.05]", "force = [0.0, 0.0, 0.05 N/mm]", "'0.05 N/mm'"),
    ] {
        let e = refused(case, &BASE.replace(from, to), Some(to), &[shown, "number followed by a unit", "[units]"]);
        assert!(!e.contains("must be quoted"), "{case}: {e}");
    }
    // with [units] pressure = "MPa": the value converted (not "write 210": 1000 times too soft);
    // quoted the same
    let mpa = format!("{BASE}\n[units]\nlength = \"mm\"\nforce = \"N\"\npressure = \"MPa\"\n");
    for (case, to) in [("unit_mpa", "E = 210 GPa"), ("unit_quoted", "E = \"210 GPa\"")] {
        let e = refused(case, &mpa.replace("E = 2.0e4", to), Some(to), &["'210 GPa'", "stamp converts nothing", "with [units] pressure = \"MPa\", write 210000"]);
        assert!(!e.contains("write 210)") && !e.contains("invalid type"), "{case}: {e}");
    }
    // without [units]: converted into MPa as an example, and told to name the unit
    refused("unit_no_table", &BASE.replace("E = 2.0e4", "E = 210 GPa"), Some("E = 210 GPa"), &["210 GPa is 210000 in MPa", "name that unit in [units] pressure"]);
    // a word that is no number keeps toml's message
    refused("bare_word", &BASE.replace("E = 2.0e4", "E = steel"), Some("E = steel"), &["plate.E"]);
}

#[test]
fn a_punch_that_starts_between_the_faces_is_refused() {
    // thickness 2000 where 2 was meant: the roller (z from 1 to 9) sits inside the plate
    let text = format!("{}{PUNCH}", BASE.replace("thickness = 2.0", "thickness = 2000"));
    refused_by_both("buried", &text, Some("[[punch]]"), &["punch[0]", "'roller' starts inside the plate's volume", "between the faces x3 = -1000 and 1000", "plate.thickness"]);
    // a ball in the lower half of the thick plate
    let ball = PUNCH.replace("shape = \"cylinder\"\npoint = [0.0, 50.0, 5.0]\naxis = [1.0, 0.0, 0.0]\nradius = 4.0", "shape = \"sphere\"\ncenter = [0.5, 50.0, -500.0]\nradius = 10.0");
    let text = format!("{}{ball}", BASE.replace("thickness = 2.0", "thickness = 2000"));
    refused_by_both("buried_ball", &text, Some("[[punch]]"), &["punch[0]", "starts inside the plate's volume", "x3 = -490"]);
    // the thickness meant: no error
    let dir = temp_dir("badfile-buried-ok");
    let (code, err) = stamp_check(&write(&dir, "ok.toml", &format!("{BASE}{PUNCH}")));
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn load_paths_and_increments_that_cannot_end_are_refused() {
    refused("target_1e300", &solver("targets = [1e300]"), Some("targets ="), &["solver.targets", "at most 1e6", "1e300"]);
    refused("target_1e10", &solver("targets = [0.1, 1e10]"), Some("targets ="), &["solver.targets", "at most 1e6"]);
    // a path of 4 million increments of 0.25
    refused("long_path", &solver("targets = [1e6]"), Some("targets ="), &["solver.max_increment", "4000000 increments", "at most 100000"]);
    refused("max_increment_tiny", &solver("max_increment = 1e-300"), Some("max_increment ="), &["solver.max_increment", "[1e-12, 1e6]", "1e-300"]);
    refused("initial_increment_denormal", &solver("initial_increment = 5e-324"), Some("initial_increment ="), &["solver.initial_increment", "5e-324"]);
    refused("min_above_max", &solver("min_increment = 0.5\nmax_increment = 0.2"), Some("min_increment ="), &["solver.min_increment", "0.5 exceeds max_increment = 0.2"]);
    // the default max_increment is 0.25
    refused("min_above_default_max", &solver("min_increment = 0.5"), Some("min_increment ="), &["0.5 exceeds max_increment = 0.25"]);
    refused("min_below_roundoff", &solver("targets = [1e5]\nmax_increment = 1e3\nmin_increment = 1e-12"), Some("min_increment ="), &["solver.min_increment", "round-off", "smallest allowed is 1e-7"]);
}

#[test]
fn iteration_counts_and_unreachable_tolerances_are_refused() {
    refused("iterations_zero", &solver("max_iterations = 0"), Some("max_iterations ="), &["solver.max_iterations", "from 1 to 1000", "got 0"]);
    refused("iterations_huge", &solver("max_iterations = 4000000000"), Some("max_iterations ="), &["solver.max_iterations", "from 1 to 1000"]);
    refused("line_search_huge", &solver("line_search_steps = 1000000"), Some("line_search_steps ="), &["solver.line_search_steps", "from 0 to 60"]);
    refused("cutbacks_huge", &solver("max_cutbacks = 1000000"), Some("max_cutbacks ="), &["solver.max_cutbacks", "from 0 to 100"]);
    refused("cycling_huge", &solver("cycling_after = 1000000"), Some("cycling_after ="), &["solver.cycling_after", "from 0 to 1000"]);
    refused("rel_tol_tiny", &solver("rel_tol = 1e-20"), Some("rel_tol ="), &["solver.rel_tol", "1e-15", "1e-20"]);
    refused("abs_tol_nan", &solver("abs_tol = nan"), Some("abs_tol ="), &["solver.abs_tol", "NaN"]);
    // physical sizes whose squares would overflow or vanish
    refused("thickness_tiny", &BASE.replace("thickness = 2.0", "thickness = 5e-324"), Some("thickness ="), &["plate.thickness", "from 1e-100 to 1e100", "5e-324"]);
    refused("young_huge", &BASE.replace("E = 2.0e4", "E = 1e300"), Some("E ="), &["plate.E", "1e300"]);
    // the plate's model choices
    let plate_key = |k: &str| BASE.replace("E = 2.0e4", &format!("E = 2.0e4\n{k}"));
    refused("shear_factor_big", &plate_key("shear_factor = 1.5"), Some("[plate]"), &["plate.shear_factor", "(0, 1]", "1.5"]);
    refused("shear_factor_zero", &plate_key("shear_factor = 0.0"), Some("shear_factor"), &["plate.shear_factor"]);
    refused("normal_stress_bad", &plate_key("normal_stress = \"full\""), Some("normal_stress"), &["normal_stress", "dropped", "mean"]);
    refused("force_huge", &BASE.replace("force = [0.0, 0.0, 0.05]", "force = [0.0, 0.0, -1e308]"), Some("force ="), &["load[0].force", "-1e308"]);
    // a penetration far below the round-off of a 100-long model
    let text = format!("{BASE}{PUNCH}penetration_tolerance = 1e-300\n");
    refused("penetration_1e-300", &text, Some("penetration_tolerance"), &["punch[0].penetration_tolerance", "1e-300", "from 1e-100"]);
    let text = format!("{BASE}{PUNCH}penetration_tolerance = 1e-20\n");
    refused("penetration_tiny", &text, Some("penetration_tolerance"), &["punch[0].penetration_tolerance", "1e-20", "smallest allowed is 1.0e-10"]);
}

#[test]
fn user_strings_are_bounded_and_vectors_show_tiny_values() {
    // a punch name is a file name: at most 64 characters
    let name = "n".repeat(230);
    let text = format!("{BASE}{}", PUNCH.replace("roller", &name));
    refused("long_name", &text, None, &["punch[0].name", "(230 characters)", "1 to 64"]);
    // a 100 000-character group name is cut
    let group = "g".repeat(100_000);
    refused("long_group", &BASE.replace("group = \"bottom\"", &format!("group = \"{group}\"")), Some("group = \"ggg"), &["boundary[0].group", "(100000 characters)"]);
    // a toml syntax error on a 100 000-character line: toml would quote the whole line
    refused("long_line", &BASE.replace("title = \"cantilever\"", &format!("title = {}", "x".repeat(100_000))), Some("title ="), &["title"]);
    // an unknown key of 100 000 characters
    refused("long_key", &BASE.replace("nu = 0.3", &format!("nu = 0.3\n{} = 1", "k".repeat(100_000))), Some("kkkk"), &["unknown field"]);
    // a direction too small to normalise: its value in {:e}, not [0, 0, 0]
    let text = format!("{BASE}{}", PUNCH.replace("axis = [1.0, 0.0, 0.0]", "axis = [1e-200, 0.0, 0.0]"));
    refused("tiny_axis", &text, Some("axis ="), &["punch[0].axis", "1e-200", "too small to normalise"]);
    let text = format!("{BASE}{}", PUNCH.replace("axis = [1.0, 0.0, 0.0]", "axis = [0.0, 0.0, 0.0]"));
    refused("zero_axis", &text, Some("axis ="), &["punch[0].axis", "non-zero"]);
    // an unknown constraint word of any length
    refused("long_word", &BASE.replace("\"clamped\"", &format!("\"{}\"", "w".repeat(5000))), Some("fix ="), &["boundary[0].fix", "unknown displacement", "(5000 characters)"]);
}

#[test]
fn long_file_names_are_shortened_in_messages() {
    // a mesh or STL file key of 5000 characters: the message keeps the path's start and end
    let mesh = format!("{}.msh", "m".repeat(5000));
    let e = refused("long_mesh", &BASE.replace("rectangle = { x = [0.0, 1.0], y = [0.0, 100.0], n = [1, 40] }", &format!("file = \"{mesh}\"")), Some("file ="), &["mesh.file", "does not exist", "characters)...mmm", "mmm.msh"]);
    assert!(e.chars().count() < 480, "{e}");
    let stl = format!("{}.stl", "s".repeat(5000));
    let text = format!("{BASE}{}", PUNCH.replace("shape = \"cylinder\"\npoint = [0.0, 50.0, 5.0]\naxis = [1.0, 0.0, 0.0]\nradius = 4.0\n", &format!("shape = \"stl\"\nfile = \"{stl}\"\n")));
    let e = refused("long_stl", &text, Some("file ="), &["punch[0].file", "sss.stl"]);
    assert!(e.chars().count() < 480, "{e}");
    // a problem file 2000 characters deep (folders of 200): the message names it short, and the
    // warnings of stamp check too
    let mut dir = temp_dir("badfile-deep");
    for _ in 0..10 {
        dir = dir.join("d".repeat(200));
    }
    std::fs::create_dir_all(&dir).unwrap();
    let path = write(&dir, "deep.toml", &BASE.replace("E = 2.0e4", "E = -1.0"));
    let (code, err) = stamp_run(&path, &dir.join("out"), Duration::from_secs(20));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("dd/deep.toml: line 7") && err.contains("characters)...") && err.chars().count() < 480, "{err}");
    let away = format!("{BASE}{}", PUNCH.replace("motion = [0.0, 0.0, -1.0]", "motion = [0.0, 0.0, 1.0]"));
    let path = write(&dir, "away.toml", &away);
    let (code, err) = stamp_check(&path);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("dd/away.toml: punch[0]") && err.contains("moves it away") && err.chars().count() < 480, "{err}");
}

#[test]
fn only_regular_files_are_read() {
    let dir = temp_dir("badfile-fifo");
    let fifo = dir.join("fifo.toml");
    let ok = Command::new("mkfifo").arg(&fifo).status().map(|s| s.success()).unwrap_or(false);
    assert!(ok, "mkfifo failed");
    let start = Instant::now();
    let (code, err) = stamp_run(&fifo, &dir.join("out"), Duration::from_secs(10));
    assert!(start.elapsed() < Duration::from_secs(1), "a FIFO took {:?}", start.elapsed());
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("fifo.toml") && err.contains("not a regular file"), "{err}");
    // a folder and a device
    let (code, err) = stamp_run(&dir, &dir.join("out"), Duration::from_secs(10));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("is a folder"), "{err}");
    let (code, err) = stamp_run(Path::new("/dev/zero"), &dir.join("out"), Duration::from_secs(10));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("/dev/zero") && err.contains("not a regular file"), "{err}");
    // binary bytes: not UTF-8, with the line
    let binary = dir.join("binary.toml");
    std::fs::write(&binary, b"title = \"x\"\n\xff\xfe\x00junk\n").unwrap();
    let (code, err) = stamp_run(&binary, &dir.join("out"), Duration::from_secs(10));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("binary.toml") && err.contains("line 2") && err.contains("not UTF-8"), "{err}");
    // a file too large for a problem file
    let big = write(&dir, "big.toml", &format!("{BASE}\n#{}\n", "x".repeat(2 << 20)));
    let (code, err) = stamp_run(&big, &dir.join("out"), Duration::from_secs(10));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("big.toml") && err.contains("at most 1048576 bytes"), "{err}");
}

/// Steps of the .pvd in order.
fn pvd_steps(out: &Path, stem: &str) -> Vec<String> {
    let pvd = std::fs::read_to_string(out.join(format!("{stem}.pvd"))).unwrap();
    pvd.split("file=\"").skip(1).map(|s| s.split('"').next().unwrap().to_string()).collect()
}

#[test]
fn a_failed_step_write_fails_the_run_and_summary_lists_exactly_the_written_steps() {
    let dir = temp_dir("badfile-write");
    let text = format!("{BASE}\n[output]\nvtu = true\n");
    let path = write(&dir, "strip.toml", &text);
    let out = dir.join("out");
    // the third step's .vtu cannot be written: a folder is in its way
    std::fs::create_dir_all(out.join("strip_0003.vtu").join("x")).unwrap();
    let (code, err) = stamp_run(&path, &out, Duration::from_secs(60));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("strip_0003.vtu"), "{err}");
    let s = summary(&out);
    assert_eq!(s["status"], "failed", "{s}");
    assert!(s["error"].as_str().unwrap().contains("strip_0003.vtu"), "{s}");
    let steps = s["steps"].as_array().unwrap();
    let vtus: Vec<String> = steps.iter().map(|e| e["vtu"].as_str().unwrap().to_string()).collect();
    assert_eq!(vtus, ["strip_0001.vtu", "strip_0002.vtu"]);
    assert_eq!(pvd_steps(&out, "strip"), vtus, "the .pvd lists the same steps");
    for v in &vtus {
        assert!(out.join(v).is_file());
    }
    assert!(!out.join("strip_0004.vtu").exists(), "no step is written after the failure");
    assert_eq!(s["pid"].as_u64().unwrap() as u32 > 0, true);

    // a contact CSV in the way: its step is not listed and its .vtu is removed
    let text = format!("{BASE}{PUNCH}\n[solver]\nsteps = 4\n");
    let path = write(&dir, "punched.toml", &text);
    let out = dir.join("out2");
    std::fs::create_dir_all(out.join("pressure_roller_0002.csv").join("x")).unwrap();
    let (code, err) = stamp_run(&path, &out, Duration::from_secs(120));
    assert_eq!(code, Some(1), "{err}");
    let s = summary(&out);
    assert_eq!(s["status"], "failed");
    let steps = s["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 1, "{s}");
    assert_eq!(pvd_steps(&out, "punched"), ["punched_0001.vtu"]);
    assert!(!out.join("punched_0002.vtu").exists(), "a step whose CSV failed leaves no .vtu");
}

#[test]
fn an_unwritable_summary_is_an_error_that_says_so() {
    let dir = temp_dir("badfile-summary");
    let path = write(&dir, "strip.toml", BASE);
    let out = dir.join("out");
    std::fs::create_dir_all(out.join("summary.json").join("x")).unwrap();
    let (code, err) = stamp_run(&path, &out, Duration::from_secs(60));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("summary.json") && err.contains("cannot write summary.json"), "{err}");
}

#[test]
fn summary_names_the_process_and_its_start() {
    let dir = temp_dir("badfile-pid");
    let path = write(&dir, "strip.toml", BASE);
    let out = dir.join("out");
    let before = std::time::SystemTime::now();
    stamp_cli::run::run(&path, Some(&out), true).unwrap();
    let s = summary(&out);
    assert_eq!(s["status"], "converged");
    assert_eq!(s["pid"].as_u64().unwrap(), std::process::id() as u64);
    let started = s["started"].as_str().unwrap();
    // RFC 3339 UTC to the second, the same (or the next) second as `before`
    let expect = stamp_cli::run::solve::rfc3339_utc(before);
    assert_eq!(started.len(), 20, "{started}");
    assert!(started.ends_with('Z') && started[..17] == expect[..17], "{started} against {expect}");
    // a known instant
    let t = std::time::UNIX_EPOCH + Duration::from_secs(1_709_210_096); // 2024-02-29T12:34:56Z
    assert_eq!(stamp_cli::run::solve::rfc3339_utc(t), "2024-02-29T12:34:56Z");
    assert_eq!(stamp_cli::run::solve::rfc3339_utc(std::time::UNIX_EPOCH), "1970-01-01T00:00:00Z");
}

#[test]
fn mesh_errors_name_the_mesh_file_and_the_gmsh_tag() {
    use stamp_cli::run::{build::mesh_error, mesh::MeshData, Problem};
    let dir = temp_dir("badfile-mesherr");
    std::fs::copy(repo().join("tests/data/rect.msh"), dir.join("rect.msh")).unwrap();
    let text = "[mesh]\nfile = \"rect.msh\"\n[plate]\nthickness = 0.1\nE = 1000.0\nnu = 0.3\n";
    let path = write(&dir, "plate.toml", text);
    let p = Problem::read(&path).unwrap();
    let mesh = MeshData::load(&p).unwrap();
    let tags = mesh.cell_tags.clone().unwrap();
    let e = mesh_error(&p, &mesh, stamp::StampError::Mesh("element 1 is inverted or too distorted: det J = -1e-3 at Gauss point 2".into())).to_string();
    assert!(e.contains("rect.msh") && e.contains(&format!("gmsh element {} is inverted", tags[1])), "{e}");
    // the built-in rectangle: the problem file and the cell counted from 1
    let path = write(&dir, "rect.toml", BASE);
    let p = Problem::read(&path).unwrap();
    let mesh = MeshData::load(&p).unwrap();
    let e = mesh_error(&p, &mesh, stamp::StampError::Mesh("element 0 is degenerate or inverted (centre Jacobian 0e0)".into())).to_string();
    assert!(e.contains("rect.toml") && e.contains("line 2") && e.contains("mesh.rectangle") && e.contains("cell 1 (counted from 1) is degenerate"), "{e}");
}

#[test]
fn every_shipped_problem_file_passes_the_checks() {
    use stamp_cli::run::{build::build, Problem};
    for entry in std::fs::read_dir(repo().join("meshes")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().and_then(|e| e.to_str()) == Some("toml") {
            let p = Problem::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            build(&p).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        }
    }
}

#[test]
fn an_unknown_key_is_named_with_its_table() {
    // toml points at the key itself, which its message names: the table is named before it (and
    // the inline table it sits in), not the key before it
    let text = format!("{BASE}{PUNCH}radios = 3\n");
    let err = refused("unknown_punch_key", &text, Some("radios = 3"), &["punch[0]: unknown field `radios`"]);
    assert!(!err.contains("punch[0].motion"), "{err}");
    let text = format!("{BASE}{PUNCH}").replace("[plate]", "[plate]\npoisson = 0.3");
    refused("unknown_plate_key", &text, Some("poisson = 0.3"), &["plate: unknown field `poisson`"]);
}

//! `path = [[t, factor], ...]` on a `[[load]]` and on a `[[boundary]]`'s `prescribe`: the load or
//! the prescribed values are their value times the factor, piecewise linear in the load factor t
//! (as a punch's `motion` rows), instead of times t. On a linear cantilever every answer is the
//! factor times the answer at factor 1, so a path that loads and unloads is checked exactly; a
//! path [[1, 1]] gives the plain load factor's answers; a follower pressure follows its path; bad
//! rows are refused naming the key and the row.

mod common;
use common::*;
use std::process::Command;

/// The cantilever of common.rs with `extra` appended and its own targets.
fn cantilever(load_extra: &str, extra: &str) -> String {
    format!("{}{load_extra}\n{extra}\n[solver]\ntargets = [0.25, 0.5, 0.75, 1.0, 1.5]\n", CANTILEVER)
}

/// The free end's mid-surface u3 at the targets (history.csv has the point groups; the
/// rectangle's corner at (1, 100) is `corner_ur`).
fn tip(out: &std::path::Path) -> Vec<f64> {
    at_targets(out, "corner_ur_u3")
}

/// A history.csv column at the targets 0.25, 0.5, 0.75, 1, 1.5 (or those of them the run has).
fn at_targets(out: &std::path::Path, name: &str) -> Vec<f64> {
    let (h, r) = history(out);
    let (t, v) = (column(&h, &r, "load_factor"), column(&h, &r, name));
    [0.25, 0.5, 0.75, 1.0, 1.5].iter().filter_map(|&x| t.iter().position(|&ti| ti == x).map(|k| v[k])).collect()
}

#[test]
fn a_load_follows_its_path_and_unloads() {
    let plain = tip(&run_text("path-plain", &cantilever("", "")));
    // up to the full load at t = 0.5, held, then off again by t = 1.5
    let path = tip(&run_text("path-load", &cantilever("path = [[0.5, 1.0], [1.0, 1.0], [1.5, 0.0]]", "")));
    let one = plain[3]; // the answer at load factor 1 (linear: the load's own)
    let want = [0.5, 1.0, 1.0, 1.0, 0.0];
    println!("tip u3 along the path: {path:?} (at factor 1: {one})");
    for (k, w) in want.iter().enumerate() {
        // to the solve's tolerance (rel_tol 1e-10 of the forces)
        assert!((path[k] - w * one).abs() <= 1e-7 * one.abs(), "target {k}: {} against {}", path[k], w * one);
    }
    // [[1, 1]] is the load factor itself up to 1, and holds the load beyond
    let same = tip(&run_text("path-identity", &cantilever("path = [[1.0, 1.0]]", "")));
    for k in 0..4 {
        assert!((same[k] - plain[k]).abs() <= 1e-12 * one.abs(), "target {k}: {} against {}", same[k], plain[k]);
    }
    assert!((same[4] - one).abs() <= 1e-7 * one.abs() && (plain[4] - 1.5 * one).abs() <= 1e-7 * one.abs());
}

#[test]
fn a_prescribed_displacement_follows_its_path_and_its_reaction_with_it() {
    // the free end pushed to v3 = 0.1 by t = 0.5, back to -0.1 by t = 1 and held
    let text = cantilever("", "[[boundary]]\ngroup = \"top\"\nprescribe = { \"v3\" = 0.1 }\npath = [[0.5, 1.0], [1.0, -1.0]]\n").replace("force = [0.0, 0.0, 0.05]", "force = [0.0, 0.0, 0.0]");
    let out = run_text("path-boundary", &text);
    let (u, react) = (at_targets(&out, "corner_ur_u3"), at_targets(&out, "top_reaction_x3"));
    let want = [0.5, 1.0, 0.0, -1.0, -1.0];
    println!("end u3 {u:?}, reaction {react:?}");
    for (k, w) in want.iter().enumerate() {
        assert!((u[k] - 0.1 * w).abs() <= 1e-12, "target {k}: u3 = {}", u[k]);
        // linear: the reaction is the factor times the one at full push (to the solve's tolerance)
        assert!((react[k] - w * react[1]).abs() <= 1e-7 * react[1].abs(), "target {k}: reaction {}", react[k]);
    }
    // the clamp carries the reaction back: the two sum to zero (no load)
    let clamp = at_targets(&out, "bottom_reaction_x3");
    assert!(react[1].abs() > 0.0 && clamp.iter().zip(&react).all(|(c, p)| (c + p).abs() <= 1e-7 * react[1].abs()));
}

#[test]
fn a_follower_pressure_follows_its_path() {
    let base = |extra: &str, q: &str| {
        format!(
            "{}\n[[load]]\ntype = \"pressure\"\ngroup = \"all\"\nface = \"top\"\npressure = {q}\nfollower = true\n{extra}\n[solver]\ntargets = [0.5, 1.0]\nmax_increment = 0.1\n",
            CANTILEVER.replace("force = [0.0, 0.0, 0.05]", "force = [0.0, 0.0, 0.0]").replace("kinematics = \"linear\"", "kinematics = \"nonlinear\"")
        )
    };
    // twice the pressure by t = 0.5, then held: both steps give the plain run's answer at t = 1
    let plain = tip(&run_text("follower-plain", &base("", "-0.02")));
    let path = tip(&run_text("follower-path", &base("path = [[0.5, 2.0]]", "-0.01")));
    println!("follower: plain {plain:?}, on the path {path:?}");
    assert!(plain[1].abs() > 10.0, "the strip should bend well into the nonlinear range: {}", plain[1]);
    // at t = 0.5 and 1 the path's pressure is the plain run's at t = 1
    for k in 0..2 {
        assert!((path[k] - plain[1]).abs() <= 1e-7 * plain[1].abs(), "target {k}: {} against {}", path[k], plain[1]);
    }
}

#[test]
fn bad_paths_are_refused_with_the_key_and_the_row() {
    let dir = temp_dir("path-bad");
    for (extra, want) in [
        ("path = [[0.5, 1.0], [0.5, 2.0]]", "load[0].path: path row 1: the load factors must increase strictly"),
        ("path = [[0.0, 1.0]]", "load[0].path: path row 0: at t = 0 the factor must be 0"),
        ("path = [[0.5]]", "load[0].path: path row 0: expected [t, factor], got 1 numbers"),
        ("path = [[-0.5, 0.0]]", "load[0].path: path row 0: the load factor t = -0.5 must be at least 0"),
        ("path = 3", "load[0].path: expected rows [[t, factor], ...]"),
        ("path = []", "load[0].path: a path needs at least one row [t, factor]"),
        ("path = [[2e6, 1.0]]", "load[0].path: path row 0: the load factor t = 2000000 is above"),
    ] {
        let file = write(&dir, "p.toml", &cantilever(extra, ""));
        for args in [vec!["check"], vec!["run", "-q", "--out", dir.join("out").to_str().unwrap()]] {
            let o = Command::new(env!("CARGO_BIN_EXE_stamp")).args(&args).arg(&file).output().unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert!(!o.status.success() && err.contains(want) && err.contains("line 20"), "{args:?} {extra}: {err}");
        }
    }
    // a path on a boundary that prescribes nothing; two paths for one component
    for (extra, want) in [
        ("[[boundary]]\ngroup = \"top\"\nfix = [\"v2\"]\npath = [[1.0, 1.0]]\n", "boundary[1].path: a path scales the values of `prescribe`"),
        (
            "[[boundary]]\ngroup = \"top\"\nprescribe = { \"v2\" = 1.0 }\npath = [[1.0, 1.0]]\n[[boundary]]\ngroup = \"top\"\nprescribe = { \"v2\" = 1.0 }\npath = [[1.0, 2.0]]\n",
            "boundary[2].prescribe: invalid problem definition: component 1 of node 80 is prescribed twice, along two different paths",
        ),
    ] {
        let file = write(&dir, "p.toml", &cantilever("", extra));
        let o = Command::new(env!("CARGO_BIN_EXE_stamp")).args(["run", "-q", "--out", dir.join("out").to_str().unwrap()]).arg(&file).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(want), "{extra}: {err}");
        println!("{}", err.lines().next().unwrap_or(""));
    }
}

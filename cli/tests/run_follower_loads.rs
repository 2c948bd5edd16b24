//! Follower loads through problem files: meshes/cantilever-roll.toml rolls its strip onto the
//! exact circles and passes `stamp check`; a follower pressure's applied load and reactions
//! balance in summary.json; bad moment and follower keys are refused with the key and line.

mod common;
use common::*;
use stamp_cli::run::{build::build, Problem};

#[test]
fn cantilever_roll_example_follows_the_exact_circles_and_closes_at_full_load() {
    let path = repo().join("meshes/cantilever-roll.toml");
    stamp_cli::commands::check_command(&path).unwrap();
    let out = temp_dir("cantilever-roll");
    stamp_cli::run::run(&path, Some(&out), true).unwrap();
    let s = summary(&out);
    let (l, ei) = (100.0, 1.0);
    let mut seen = 0;
    for e in s["steps"].as_array().unwrap().iter().filter(|e| e["is_target"].as_bool() == Some(true)) {
        let t = e["load_factor"].as_f64().unwrap();
        let theta = t * 2.0 * std::f64::consts::PI * ei; // M L / EI
        let r = l / theta;
        let want = [r * theta.sin(), r * (1.0 - theta.cos())];
        for corner in ["corner_lr", "corner_ur"] {
            let d = &e["points"][corner]["displacement"];
            let got = [l + d[0].as_f64().unwrap(), d[2].as_f64().unwrap()];
            let err = ((got[0] - want[0]).powi(2) + (got[1] - want[1]).powi(2)).sqrt();
            assert!(err < 0.01 * l, "t = {t}, {corner}: tip {got:?}, exact circle {want:?}: off by {err} (more than 1 % of L)");
        }
        // a couple has no resultant: the clamp carries no force
        for c in 0..3 {
            let f = e["support_reaction"][c].as_f64().unwrap();
            assert!(f.abs() < 1e-8, "t = {t}: the clamp carries the force {f} under a pure couple");
        }
        seen += 1;
    }
    assert_eq!(seen, 4, "the four targets 0.25, 0.5, 0.75, 1");
}

/// A strip along x1 clamped at x1 = 0 under a pressure on its top face.
const STRIP: &str = r#"[mesh]
rectangle = { x = [0.0, 10.0], y = [0.0, 1.0], n = [40, 1] }

[plate]
thickness = 0.1
E = 1.0e4
nu = 0.0

[[boundary]]
group = "left"
fix = ["clamped"]

[[load]]
type = "pressure"
group = "all"
pressure = 2.5e-3
face = "top"
follower = true

[solver]
max_increment = 0.1
"#;

#[test]
fn follower_pressure_applied_load_is_balanced_by_the_clamp_and_bends_further_than_dead() {
    let dir = temp_dir("follower-pressure");
    let mut tips = Vec::new();
    for follower in [true, false] {
        let text = if follower { STRIP.to_string() } else { STRIP.replace("follower = true\n", "") };
        let path = write(&dir, &format!("strip-{follower}.toml"), &text);
        let out = dir.join(format!("out-{follower}"));
        stamp_cli::run::run(&path, Some(&out), true).unwrap();
        let s = summary(&out);
        let e = s["steps"].as_array().unwrap().last().unwrap();
        let applied: Vec<f64> = (0..3).map(|c| e["applied_load"][c].as_f64().unwrap()).collect();
        let support: Vec<f64> = (0..3).map(|c| e["support_reaction"][c].as_f64().unwrap()).collect();
        for c in 0..3 {
            assert!((applied[c] + support[c]).abs() < 1e-9, "follower = {follower}: applied load {applied:?} and clamp reaction {support:?} do not balance");
        }
        if follower {
            // the pressure turned with the strip: its resultant leans towards the clamp (-x1)
            assert!(applied[0] < -1e-4, "the follower pressure's resultant {applied:?} has no part along -x1");
        } else {
            assert!((applied[2] + 2.5e-3 * 10.0).abs() < 1e-12 && applied[0] == 0.0, "dead pressure resultant {applied:?}");
        }
        tips.push(-e["points"]["corner_ur"]["displacement"][2].as_f64().unwrap());
    }
    assert!(tips[0] > 1.05 * tips[1], "follower tip deflection {} is not clearly above the dead pressure's {}", tips[0], tips[1]);
}

fn error_of(name: &str, text: &str) -> String {
    let dir = temp_dir(&format!("bad-follower-{name}"));
    let path = write(&dir, &format!("{name}.toml"), text);
    let err = match Problem::read(&path).and_then(|p| build(&p).map(|_| ())) {
        Ok(()) => panic!("{name}: the problem was accepted:\n{text}"),
        Err(e) => e.to_string(),
    };
    assert!(err.contains(&format!("{name}.toml")), "{name}: the error does not name the file: {err}");
    err
}

#[test]
fn bad_moment_and_follower_keys_name_the_key_and_line() {
    let roll = std::fs::read_to_string(repo().join("meshes/cantilever-roll.toml")).unwrap();
    let line = |e: &str| roll.lines().position(|l| l.contains("type = \"moment\"")).map(|i| e.contains(&format!("line {}", i))).unwrap();
    // a twist about the normal cannot be carried by a fixed couple
    let e = error_of("twist", &roll.replace("\nfollower = true\n", "\nfollower = false\n").replace("0.06283185307179587, 0.0]", "0.06283185307179587, 0.5]"));
    assert!(e.contains("load[0].moment") && e.contains("m3 must be 0") && line(&e), "{e}");
    // ... nor by a follower one: about the normal only, the whole load would be dropped
    let e = error_of("twist_follower", &roll.replace("[0.0, -0.06283185307179587, 0.0]", "[0.0, 0.0, 0.5]"));
    assert!(e.contains("load[0].moment") && e.contains("follower couple") && e.contains("m3 must be 0") && e.contains("whole load") && line(&e), "{e}");
    let e = error_of("twist_follower_mixed", &roll.replace("0.06283185307179587, 0.0]", "0.06283185307179587, 0.5]"));
    assert!(e.contains("load[0].moment") && e.contains("m3 must be 0, got 0.5") && !e.contains("whole load"), "{e}");
    // no moment vector
    let e = error_of("no_moment", &roll.replace("moment = [", "#moment = ["));
    assert!(e.contains("load[0]") && e.contains("needs `moment`"), "{e}");
    // a moment with a face
    let e = error_of("moment_face", &roll.replace("\nfollower = true\n", "\nfollower = true\nface = \"top\"\n"));
    assert!(e.contains("load[0]") && e.contains("no `force`, `pressure` or `face`"), "{e}");
    // follower on a dead-only load
    let e = error_of("follower_line", &STRIP.replace("type = \"pressure\"", "type = \"surface\"").replace("pressure = 2.5e-3", "force = [0.0, 0.0, -1.0]"));
    assert!(e.contains("load[0].follower") && e.contains("only a pressure or a moment"), "{e}");
    // a moment on a surface group
    let e = error_of("moment_surface", &roll.replace("group = \"right\"", "group = \"all\""));
    assert!(e.contains("load[0].group") && e.contains("curve"), "{e}");
}

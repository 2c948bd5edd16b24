//! Follower loads through problem files: meshes/cantilever-roll.toml rolls its strip onto the
//! exact circles and passes `stamp check`; a follower pressure's applied load and reactions
//! balance in summary.json; bad moment and follower keys are refused with the key and line.

mod common;
use common::*;

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
    build_error("bad-follower", name, text)
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

/// The total force of a pressure given as an expression p(x1, x2) on the top face of one cell
/// [0, 2] x [0, 1] (three surfaces, nonlinear) whose face nodes are all prescribed to the affine
/// motion x -> R S x at load factor 1 (S stretches x1 by 1.2 and x2 by 0.9, R turns by 60 degrees
/// about x2; the mid-surface is free). A follower pressure acts on the deformed face: its total is
/// -1.2 * 0.9 * int p dA * R e3, R e3 = (sin 60, 0, cos 60), to round-off (p bilinear: the 2 x 2
/// Gauss points integrate it exactly); a dead one stays -int p dA e3. Both balanced by the supports.
#[test]
fn expression_pressure_totals_on_a_turned_and_stretched_face() {
    let dir = temp_dir("follower-expression");
    let (l, w, h, l1, l2, theta) = (2.0f64, 1.0f64, 0.1f64, 1.2f64, 0.9f64, 60f64.to_radians());
    let (s, c) = theta.sin_cos();
    // u = R S X - X on each face x3 = -+h/2 of the left (x1 = 0) and right (x1 = l) edges
    let face = |x1: f64, x3: f64| (l1 * x1 * c + x3 * s - x1, -l1 * x1 * s + x3 * c - x3);
    let edge = |group: &str, x1: f64| {
        let (bot, top) = (face(x1, -0.5 * h), face(x1, 0.5 * h));
        format!("[[boundary]]\ngroup = \"{group}\"\nprescribe = {{ \"v1-\" = {:e}, \"v3-\" = {:e}, \"v1+\" = {:e}, \"v3+\" = {:e} }}\n\n", bot.0, bot.1, top.0, top.1)
    };
    let base = format!(
        r#"[mesh]
rectangle = {{ x = [0.0, {l}], y = [0.0, {w}], n = [1, 1] }}

[plate]
thickness = {h}
E = 1.0e3
nu = 0.3
surfaces = 3

{}{}[[boundary]]
group = "bottom"
fix = ["v2"]

[[boundary]]
group = "top"
prescribe = {{ "v2" = {:e} }}

[[load]]
type = "pressure"
group = "all"
pressure = "1 + 0.5*x1 + 0.25*x2 + 0.1*x1*x2"
face = "top"
follower = true

[solver]
max_increment = 0.1
"#,
        edge("left", 0.0),
        edge("right", l),
        (l2 - 1.0) * w
    );
    // int p dA over [0, l] x [0, w]
    let total = l * w + 0.5 * 0.5 * l * l * w + 0.25 * 0.5 * l * w * w + 0.1 * 0.25 * l * l * w * w;
    for follower in [true, false] {
        let text = if follower { base.clone() } else { base.replace("follower = true\n", "") };
        let path = write(&dir, &format!("face-{follower}.toml"), &text);
        let out = dir.join(format!("out-{follower}"));
        stamp_cli::run::run(&path, Some(&out), true).unwrap();
        let e = summary(&out)["steps"].as_array().unwrap().last().unwrap().clone();
        assert_eq!(e["load_factor"].as_f64(), Some(1.0));
        let applied: Vec<f64> = (0..3).map(|k| e["applied_load"][k].as_f64().unwrap()).collect();
        let support: Vec<f64> = (0..3).map(|k| e["support_reaction"][k].as_f64().unwrap()).collect();
        let want = if follower { [-l1 * l2 * total * s, 0.0, -l1 * l2 * total * c] } else { [0.0, 0.0, -total] };
        println!("follower = {follower}: applied {applied:?}, closed form {want:?}");
        for k in 0..3 {
            assert!((applied[k] - want[k]).abs() <= 1e-10 * total, "follower = {follower}: applied load {applied:?} against {want:?}");
            assert!((applied[k] + support[k]).abs() <= 1e-8 * total, "follower = {follower}: applied {applied:?} and supports {support:?} do not balance");
        }
        // the face really turned and stretched: the top-right corner's top face at R S X
        let d = &e["points"]["corner_ur"]["displacement_top"];
        let (u1, u3) = face(l, 0.5 * h);
        assert!((d[0].as_f64().unwrap() - u1).abs() < 1e-12 && (d[2].as_f64().unwrap() - u3).abs() < 1e-12, "{d}");
    }
}

/// A dead pressure given as an expression on a simply supported plate on a mesh of unequal cells:
/// the supports carry its integral, int p dA over [0, 4] x [0, 3] = 52.2 for p = 1 + 0.5 x1 +
/// 0.25 x2^2 + 0.1 x1^3 (cubic at most along each axis: the 2 x 2 Gauss points are exact), to
/// round-off.
#[test]
fn expression_pressure_reactions_carry_its_integral() {
    let dir = temp_dir("expression-pressure-total");
    let text = r#"[mesh]
rectangle = { x = [0.0, 4.0], y = [0.0, 3.0], n = [7, 5] }

[plate]
thickness = 0.2
E = 1.0e4
nu = 0.3
kinematics = "linear"

[[boundary]]
group = "left"
fix = ["v1", "v2", "v3"]

[[boundary]]
group = "right"
fix = ["v3"]

[[boundary]]
group = "bottom"
fix = ["v3"]

[[boundary]]
group = "top"
fix = ["v3"]

[[load]]
type = "pressure"
group = "all"
pressure = "1 + 0.5*x1 + 0.25*x2*x2 + 0.1*x1*x1*x1"
face = "top"
"#;
    let path = write(&dir, "p.toml", text);
    let out = dir.join("out");
    stamp_cli::run::run(&path, Some(&out), true).unwrap();
    let e = summary(&out)["steps"].as_array().unwrap().last().unwrap().clone();
    let total = 4.0 * 3.0 + 0.5 * 8.0 * 3.0 + 0.25 * 4.0 * 9.0 + 0.1 * 64.0 * 3.0;
    let support = e["support_reaction"][2].as_f64().unwrap();
    let applied = e["applied_load"][2].as_f64().unwrap();
    println!("supports {support}, applied {applied}, int p dA {total}");
    assert!((support - total).abs() <= 1e-10 * total && (applied + total).abs() <= 1e-12 * total, "supports {support}, applied {applied}, integral {total}");
}

//! Problems that used to end "converged" with a wrong answer, or fail slowly for a reason the user
//! could not see: a punch pressing onto supported nodes, a plate in other units (E = 1e-20), a
//! punch force the solve cannot tell from round-off, a tiny initial increment, a contact so soft
//! that the punch sinks into the plate.

mod common;
use common::*;
use std::process::{Command, Output};

fn stamp(args: &[&std::ffi::OsStr]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_stamp")).args(args).output().unwrap()
}

fn run(problem: &std::path::Path) -> (Output, std::path::PathBuf) {
    let out = problem.parent().unwrap().join("out");
    let o = stamp(&["run".as_ref(), "-q".as_ref(), "--out".as_ref(), out.as_os_str(), problem.as_os_str()]);
    (o, out)
}

fn steps(out: &std::path::Path) -> Vec<serde_json::Value> {
    summary(out)["steps"].as_array().unwrap().clone()
}

/// A roller across the plate of cylinder-30deg (axis along x2, over the two hinged edges at
/// x2 = +-20, which hold v3), pressed 4 into a plate 3 thick: refused by `stamp check` naming a held
/// node, and `stamp run` writes nothing. Before, 10 steps "converged" with forces of 1e7.
#[test]
fn a_punch_pressing_onto_supported_nodes_is_refused_before_the_run() {
    let p = variant(
        "roller-on-supports",
        "cylinder-30deg.toml",
        &[
            ("thickness = 1.0", "thickness = 3.0"),
            ("point = [0.0, 0.0, 20.5]", "point = [0.0, 0.0, 21.5]"),
            ("axis = [0.8660254037844387, 0.5, 0.0]", "axis = [0.0, 1.0, 0.0]"),
            ("force = 6000.0", "motion = [0.0, 0.0, -4.0]"),
        ],
    );
    for cmd in ["check", "run"] {
        let out = p.parent().unwrap().join("out");
        let o = if cmd == "check" { stamp(&["check".as_ref(), p.as_os_str()]) } else { stamp(&["run".as_ref(), "--out".as_ref(), out.as_os_str(), p.as_os_str()]) };
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{cmd}: {err}");
        assert!(err.contains("punch[0]: 'cylinder' presses onto the node at (x1, x2) = (") && err.contains(", -20)") && err.contains("the supports hold along x3"), "{cmd}: {err}");
        assert!(!out.join("summary.json").exists());
    }
    // the shipped roller at 30 degrees, which leaves the plate through its free edges, driven by a
    // displacement: accepted
    let inside = variant("roller-between-supports", "cylinder-30deg.toml", &[("force = 6000.0", "motion = [0.0, 0.0, -0.2]")]);
    let o = stamp(&["check".as_ref(), inside.as_os_str()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// sphere-ss-displacement with E = 1e-20 instead of 2.1e5: the same problem in other units. Newton's
/// absolute tolerance follows the plate's stiffness, so the force is the shipped run's times
/// 1e-20 / 2.1e5 (before: "converged" at once, undeformed, the punch 0.3 inside the plate).
#[test]
fn a_plate_in_other_units_gives_the_same_answer_scaled() {
    let (o, shipped) = run(&variant("units-shipped", "sphere-ss-displacement.toml", &[]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (o, soft) = run(&variant("units-soft", "sphere-ss-displacement.toml", &[("E = 2.1e5", "E = 1e-20")]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let force = |out: &std::path::Path| steps(out).last().unwrap()["reaction"][2].as_f64().unwrap();
    let pen = |out: &std::path::Path| steps(out).last().unwrap()["max_penetration"].as_f64().unwrap();
    let ratio = force(&soft) / force(&shipped) * 2.1e5 / 1e-20;
    assert!((ratio - 1.0).abs() < 1e-6, "force {:e} against {:e}: ratio {ratio}", force(&soft), force(&shipped));
    assert!(pen(&soft) <= 1e-6, "penetration {:e}", pen(&soft));
}

/// A force-driven punch whose force is below 1e-9 of E h L is refused with the numbers (1e-15 on
/// sphere-ss "converged" with the punch unmoved and a reaction of 0; 1e-6 failed after 12
/// cut-backs); 0.01 is solved, its reaction the force.
#[test]
fn a_punch_force_below_the_round_off_is_refused_and_a_small_one_is_solved() {
    for f in ["1e-15", "1e-6"] {
        let p = variant(&format!("force-{f}"), "sphere-ss.toml", &[("force = 500.0", &format!("force = {f}"))]);
        let o = stamp(&["check".as_ref(), p.as_os_str()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(1), "{err}");
        assert!(err.contains(&format!("punch[0].force: {f} is below 4.2e-3, 1e-9 of the plate's stiffness as a force (E h L = 4.200e6")), "{err}");
    }
    let (o, out) = run(&variant("force-small", "sphere-ss.toml", &[("force = 500.0", "force = 0.01"), ("plot = true", "plot = false")]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let last = steps(&out).last().unwrap().clone();
    let reaction = last["reaction"][2].as_f64().unwrap().abs();
    assert!((reaction - 0.01).abs() < 1e-6 * 0.01, "reaction {reaction:e}");
}

/// `initial_increment = 1e-12`: the first steps' forces are round-off, judged by the tolerance of
/// the plate's stiffness, and the increments grow to the target (before: step 1 failed without
/// a cut-back, then the growing path was taken for a crawl).
#[test]
fn a_tiny_initial_increment_grows_to_the_target() {
    let (o, out) = run(&variant("tiny-increment", "sphere-ss-displacement.toml", &[("\n[solver]\n", "\n[solver]\ninitial_increment = 1e-12\n")]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = steps(&out);
    assert!(s.len() > 50 && s.last().unwrap()["load_factor"].as_f64().unwrap() == 1.0, "{} steps", s.len());
}

/// A contact 3 000 times softer than the automatic one (eps_reg = 0.01) and no penetration_tolerance:
/// the default tolerance (1e-3 of the thickness) presses the punch out by augmented updates at every
/// step (before: 1 % of the thickness inside the plate, "converged").
#[test]
fn a_soft_contact_is_not_converged_deep_inside_the_plate() {
    let (o, out) = run(&variant("soft-contact", "sphere-ss-displacement.toml", &[("penetration_tolerance = 1e-6", "eps_reg = 0.01")]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for s in steps(&out) {
        let pen = s["max_penetration"].as_f64().unwrap();
        assert!(pen <= 1e-3 * 1.0, "step {}: penetration {pen:e} (thickness 1)", s["step"]);
    }
}

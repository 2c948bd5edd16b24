//! `[solver] newton`: the mixed-integration-point iteration (the default) reaches the answer of
//! the standard Newton iteration in fewer iterations; and first contact under a load step
//! without cut-backs on a die that touches a plate of gmsh triangles along a ring.

mod common;
use common::*;
use std::path::Path;
use std::process::Command;

/// `stamp run` into the problem's `.out` folder: its summary.json, or the error.
fn run(problem: &Path) -> serde_json::Value {
    let out = problem.with_extension("out");
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("run").arg(problem).arg("--out").arg(&out).arg("--quiet").output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    summary(&out)
}

/// history.csv's numbers, row by row.
fn history(problem: &Path) -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(problem.with_extension("out").join("history.csv")).unwrap();
    text.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect()
}

fn newton(s: &serde_json::Value) -> u64 {
    s["newton_iterations"].as_u64().unwrap()
}

fn cutbacks(s: &serde_json::Value) -> u64 {
    s["steps"].as_array().unwrap().iter().map(|x| x["cutbacks"].as_u64().unwrap()).sum()
}

#[test]
fn the_mixed_iteration_rolls_the_cantilever_up_in_fewer_iterations_to_the_same_answer() {
    // the strip rolled into a full circle by a follower couple: 20 steps of 18 degrees
    let mip = variant("newton-mip", "cantilever-roll.toml", &[]);
    let standard = variant("newton-standard", "cantilever-roll.toml", &[("[solver]", "[solver]\nnewton = \"standard\"")]);
    let (sm, ss) = (run(&mip), run(&standard));
    assert_eq!((cutbacks(&sm), cutbacks(&ss)), (0, 0));
    println!("Newton iterations: mip {}, standard {}", newton(&sm), newton(&ss));
    assert!(newton(&sm) * 10 < newton(&ss) * 8, "mip {} against standard {}", newton(&sm), newton(&ss));
    // the same answer: every column of every step within 1e-8 of the largest displacement
    let (hm, hs) = (history(&mip), history(&standard));
    assert_eq!(hm.len(), hs.len());
    let scale = hs.iter().flat_map(|r| r[3..].iter()).fold(0.0f64, |m, x| m.max(x.abs()));
    for (a, b) in hm.iter().zip(&hs) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-8 * scale, "{a:?}\n{b:?}");
        }
    }
}

#[test]
fn an_unknown_newton_is_refused_with_the_choices() {
    let p = variant("newton-bad", "cantilever-roll.toml", &[("[solver]", "[solver]\nnewton = \"fast\"")]);
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("check").arg(&p).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success() && err.contains("newton") && err.contains("mip") && err.contains("standard"), "{err}");
}

/// A torus-shaped die (ring radius 15, tube radius 5; Psi as an expression) pressed 2 into a
/// clamped plate 60 x 60 x 1 of gmsh triangles of size 2, in 4 steps: the contact is a ring
/// narrower than the cells. Its first contact took a cut-back and 11 Newton iterations a step
/// before entering points got the Gauss-Newton tangent and converging tensions were held.
const TORUS: &str = r#"title = "torus die on a clamped plate"
[mesh]
file = "plate60_tri2.msh"
[plate]
thickness = 1.0
E = 2.1e5
nu = 0.3
[[boundary]]
group = "edge"
fix = ["clamped"]
[[punch]]
name = "die"
shape = "expression"
psi = "(sqrt((x1 - 30)^2 + (x2 - 30)^2) - 15)^2 + (x3 - 5.5)^2 - 25"
motion = [0.0, 0.0, -2.0]
[solver]
steps = 4
[output]
plot = false
"#;

#[test]
fn a_torus_die_presses_a_plate_of_triangles_without_a_cut_back() {
    let dir = temp_dir("torus-die");
    std::fs::copy(repo().join("tests/data/plate60_tri2.msh"), dir.join("plate60_tri2.msh")).unwrap();
    let p = write(&dir, "torus.toml", TORUS);
    let s = run(&p);
    let steps = s["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 4);
    assert_eq!(cutbacks(&s), 0, "{s}");
    assert_eq!(s["failed_iterations"].as_u64().unwrap(), 0);
    println!("Newton iterations: {} in 4 steps", newton(&s));
    assert!(newton(&s) <= 40, "{} Newton iterations", newton(&s));
    // the die carries its ring: the force grows with the travel
    let force: Vec<f64> = steps.iter().map(|x| -x["punches"]["die"]["reaction"][2].as_f64().unwrap()).collect();
    assert!(force.windows(2).all(|w| w[1] > w[0]) && force[0] > 0.0, "{force:?}");
}

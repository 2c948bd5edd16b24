//! Coulomb friction (`[[punch]] friction = mu`): a flat punch pressed into a plate glued to a rigid
//! table (its bottom face held) and then dragged along x1
//! (a flat punch on a clamped plate would press onto the held edge nodes, which `stamp check`
//! refuses). Once every point slides, each point's tangential traction is mu times its
//! normal pressure along the sliding direction, so the punch's tangential force is mu times its
//! normal force: read in history.csv (`<punch>_force_x1`, `<punch>_force_x3`), and again as the
//! inclined plane's ratio F/G = (tan a + mu) / (1 - mu tan a) in axes turned by a (tan a = 0.1).
//! Also the outputs (columns, arrays, summary counts), mu = 0 giving the frictionless answers, and
//! bad values refused with the key.

mod common;
use common::*;
use std::path::Path;
use std::process::Command;

fn problem(mu: &str, extra: &str) -> String {
    format!(
        r#"title = "a flat punch pressed into a plate on a table, then dragged along x1"
[mesh]
rectangle = {{ x = [-10.0, 10.0], y = [-10.0, 10.0], n = [6, 6] }}

[plate]
thickness = 1.0
E = 2.1e5
nu = 0.3

[[boundary]]
group = "all"
fix = ["v1-", "v2-", "v3-"]

[[punch]]
name = "flat"
shape = "plane"
point = [0.0, 0.0, 0.5]
normal = [0.0, 0.0, -1.0]
motion = [[0.5, 0.0, 0.0, -0.01], [1.0, 0.05, 0.0, -0.01]]
friction = {mu}
{extra}
[solver]
max_increment = 0.1
"#
    )
}

/// With the nodal and the integrated contact (friction at the face's quadrature points).
#[test]
fn sliding_drag_is_mu_times_the_normal_force() {
    for contact in ["nodal", "integrated"] {
        sliding_drag(contact);
    }
}

fn sliding_drag(contact: &str) {
    let tan_a = 0.1f64;
    for (mu, inclined) in [(0.1, 0.20202020202020202), (0.2, 0.30612244897959184), (0.3, 0.41237113402061855)] {
        let out = run_text(&format!("friction-{contact}-{mu}"), &problem(&mu.to_string(), &format!("contact = \"{contact}\"")));
        let (head, rows) = history(&out);
        let (f1, f2, f3) = (column(&head, &rows, "flat_force_x1"), column(&head, &rows, "flat_force_x2"), column(&head, &rows, "flat_force_x3"));
        let dissipation = column(&head, &rows, "flat_dissipation");
        let t = column(&head, &rows, "load_factor");
        let last = rows.len() - 1;
        // the plate pushes the punch up and drags against its motion (+x1)
        assert!(f3[last] > 0.0 && f1[last] < 0.0, "force on the punch {:?}", (f1[last], f2[last], f3[last]));
        let ratio = -f1[last] / f3[last];
        // the inclined plane: the same forces in axes turned by a about x2
        let (c, s) = (1.0 / (1.0 + tan_a * tan_a).sqrt(), tan_a / (1.0 + tan_a * tan_a).sqrt());
        let (h, v) = (-f1[last] * c + f3[last] * s, f3[last] * c + f1[last] * s);
        println!("{contact}, mu = {mu}: drag/normal {ratio:.12} (error {:.2e}), F/G {:.12} against {inclined:.12} (error {:.2e}), |F2| / F3 {:.1e}, dissipation {:e}", ratio / mu - 1.0, h / v, h / v / inclined - 1.0, f2[last].abs() / f3[last], dissipation[last]);
        assert!((ratio / mu - 1.0).abs() < 1e-6, "{contact}, mu = {mu}: drag / normal force = {ratio}");
        assert!((h / v / inclined - 1.0).abs() < 1e-6, "{contact}, mu = {mu}: F/G = {}, expected {inclined}", h / v);
        assert!(f2[last].abs() < 1e-6 * f3[last]);
        // before the slide (pressing only, t <= 0.5) no net drag (the points that slide as the plate
        // bends cancel); the dissipation never decreases
        for k in 0..rows.len() {
            if t[k] <= 0.5 {
                assert!(f1[k].abs() < 1e-9 * f3[last], "step {k}: drag {} before the slide", f1[k]);
            }
            if k > 0 {
                assert!(dissipation[k] >= dissipation[k - 1]);
            }
        }
        assert!(dissipation[last] > 0.0);
        // summary.json: every candidate point that touches slides at the end
        let s = summary(&out);
        let p = &s["steps"].as_array().unwrap()[last]["punches"]["flat"];
        assert!(p["slipping_nodes"].as_u64().unwrap() > 0 && p["sticking_nodes"].as_u64().unwrap() == 0, "{p}");
        // the .vtu arrays
        let vtu = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "vtu")).max().unwrap();
        let text = std::fs::read_to_string(vtu).unwrap();
        for a in ["flat_traction", "flat_slip", "flat_state"] {
            assert!(text.contains(&format!("Name=\"{a}\"")), "no array {a}");
        }
        // the default probe's CSV carries the traction's components: every sliding node's traction
        // is mu times its pressure against the motion, and so is the bilinear interpolation
        // between nodes along the line (nodal contact; the integrated scheme's nodal view is a
        // consistent force over an area)
        let csv = std::fs::read_dir(&out).unwrap().map(|e| e.unwrap().path()).filter(|p| p.file_name().unwrap().to_string_lossy().starts_with("probe_flat_") && p.extension().is_some_and(|e| e == "csv")).max().unwrap();
        let (ph, pr) = read_csv(&csv);
        let (q, tx, ty, tz) = (column(&ph, &pr, "flat_pressure"), column(&ph, &pr, "flat_traction_x1"), column(&ph, &pr, "flat_traction_x2"), column(&ph, &pr, "flat_traction_x3"));
        let qmax = q.iter().cloned().fold(0.0, f64::max);
        assert!(qmax > 0.0 && tx.iter().any(|&t| t < 0.0), "no traction along the probe");
        if contact == "nodal" {
            for k in 0..q.len() {
                assert!((tx[k] + mu * q[k]).abs() < 1e-6 * mu * qmax && ty[k].abs() < 1e-6 * mu * qmax && tz[k].abs() < 1e-6 * mu * qmax, "probe row {k}: traction ({}, {}, {}) against mu q = {}", tx[k], ty[k], tz[k], mu * q[k]);
            }
        }
    }
}

/// mu = 0 is frictionless: no friction columns or arrays, the force columns there, and the
/// frictionless drag zero.
#[test]
fn zero_friction_is_frictionless() {
    let out = run_text("friction-zero", &problem("0.0", ""));
    let (head, rows) = history(&out);
    assert!(!head.iter().any(|h| h.contains("dissipation")));
    let f1 = column(&head, &rows, "flat_force_x1");
    let f3 = column(&head, &rows, "flat_force_x3");
    assert!(f1.iter().zip(&f3).all(|(a, b)| a.abs() < 1e-12 * b.abs()), "{f1:?}");
    let s = summary(&out);
    assert!(s["steps"][0]["punches"]["flat"].get("slipping_nodes").is_none());
}

#[test]
fn bad_friction_is_refused_with_the_key() {
    let dir = temp_dir("friction-bad");
    for (mu, extra, want) in [
        ("-0.1", "", "friction"),
        ("11.0", "", "friction"),
        ("0.2", "kinematics = \"shallow\"", "punch[0].friction"),
    ] {
        let file = write(&dir, "p.toml", &problem(mu, extra));
        let o = Command::new(env!("CARGO_BIN_EXE_stamp")).args(["run", "-q", "--out", dir.join("out").to_str().unwrap()]).arg(&file).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(want), "friction = {mu} {extra}: {err}");
        println!("{mu} {extra}: {}", err.lines().next().unwrap_or(""));
    }
}

/// A sphere pressed into the centre of a clamped plate, then moved along x1 by 1e-4, far below
/// the sliding limit: the centre node sticks to the punch (its slip in pressing is zero by
/// symmetry), so its top face moves by exactly 1e-4. With `penetration_tolerance` the
/// augmented-Lagrangian updates make the stick exact to that tolerance; without, the penalty
/// leaves an elastic creep t / eps_T (3e-7 here).
#[test]
fn a_sticking_point_follows_the_punch_exactly_with_augmented_updates() {
    let text = |tolerance: &str| {
        format!(
            r#"title = "a sphere pressed into a clamped plate, then moved along x1 below the stick limit"
[mesh]
rectangle = {{ x = [-10.0, 10.0], y = [-10.0, 10.0], n = [20, 20] }}
[plate]
thickness = 1.0
E = 2.1e5
nu = 0.3
[[boundary]]
group = "boundary"
fix = ["clamped"]
[[punch]]
name = "ball"
shape = "sphere"
center = [0.0, 0.0, 50.5]
radius = 50.0
motion = [[0.5, 0.0, 0.0, -0.2], [1.0, 0.0001, 0.0, -0.2]]
friction = 1.0
{tolerance}
[solver]
max_increment = 0.25
"#
        )
    };
    let centre_u1 = |out: &Path| {
        let last = std::fs::read_dir(out).unwrap().map(|e| e.unwrap().path()).filter(|p| p.file_name().unwrap().to_str().unwrap().starts_with("pressure_ball_")).max().unwrap();
        let text = std::fs::read_to_string(last).unwrap();
        // node, x1, x2, x1_deformed, ...: the centre node (0, 0)
        let row: Vec<f64> = text.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect::<Vec<f64>>()).find(|r| r[1] == 0.0 && r[2] == 0.0).unwrap();
        row[3] - row[1]
    };
    let exact = run_text("friction-stick-al", &text("penetration_tolerance = 1e-9"));
    let s = summary(&exact);
    let last = s["steps"].as_array().unwrap().last().unwrap()["punches"]["ball"].clone();
    assert!(last["sticking_nodes"].as_u64().unwrap() >= 1, "{last}");
    let e_al = (centre_u1(&exact) - 1e-4).abs();
    let penalty = run_text("friction-stick-penalty", &text(""));
    let e_pen = (centre_u1(&penalty) - 1e-4).abs();
    println!("centre node's u1 - punch's travel: {e_al:e} with the updates, {e_pen:e} without");
    assert!(e_al < 1e-9, "the sticking centre is {e_al:e} off the punch with the updates");
    assert!(e_pen > 1e-8, "the penalty's creep should show: {e_pen:e}");
}

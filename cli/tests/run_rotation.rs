//! Punches that turn (`[[punch]] rotation = [[t, angle], ...]` about `axis` through `pivot`):
//! a die tilted before it presses gives the forces of the same tilted plane given directly; a
//! cylinder rolled along a plate with friction (its angle its travel over its radius) drags it
//! far less than the same cylinder slid without turning (mu times the normal force); a
//! force-driven sphere turning about its centre presses as one that does not turn; the keys'
//! bad uses are refused naming the key.

mod common;
use common::*;
use std::path::Path;
use std::process::Command;

/// A plate glued to a rigid table (its bottom face held) pressed by `punch`.
fn on_table(size: f64, n: usize, punch: &str, max_increment: f64) -> String {
    format!(
        r#"title = "a plate on a table under a punch that turns"
[mesh]
rectangle = {{ x = [{a}, {size}], y = [{a}, {size}], n = [{n}, {n}] }}

[plate]
thickness = 1.0
E = 2.1e5
nu = 0.3

[[boundary]]
group = "all"
fix = ["v1-", "v2-", "v3-"]

[[punch]]
{punch}
[solver]
max_increment = {max_increment}
"#,
        a = -size
    )
}

/// The largest difference between two runs' history.csv, column by column, over the column's
/// largest magnitude, or for a displacement or force that of all the displacements or forces (a
/// component that is round-off is judged on the size of its kin); the same load factors, the
/// same columns.
fn history_difference(a: &Path, b: &Path) -> f64 {
    let (ha, ra) = history(a);
    let (hb, rb) = history(b);
    assert_eq!(ha, hb);
    assert_eq!(ra.len(), rb.len(), "the same steps");
    let family = |h: &str| if h.ends_with("_u1") || h.ends_with("_u2") || h.ends_with("_u3") || h.ends_with("_travel") { 1 } else if h.contains("_force") || h.contains("_reaction_x") { 2 } else { 0 };
    let largest = |f: usize| (0..ha.len()).filter(|&c| family(&ha[c]) == f).flat_map(|c| ra.iter().map(move |r| r[c].abs())).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for c in 0..ha.len() {
        let own = ra.iter().map(|r| r[c].abs()).fold(0.0, f64::max);
        let scale = if family(&ha[c]) == 0 { own } else { own.max(largest(family(&ha[c]))) };
        if scale == 0.0 {
            continue;
        }
        let d = ra.iter().zip(&rb).map(|(x, y)| (x[c] - y[c]).abs()).fold(0.0, f64::max);
        worst = worst.max(d / scale);
    }
    worst
}

/// A plane die above the plate turned by 1 degree about x2 (through a pivot 0.5 above the top
/// face) while it is still clear of the plate, then pressed down with friction: the same
/// history as the plane given tilted from the start, to round-off.
#[test]
fn a_tilted_die_presses_as_the_tilted_plane_it_is() {
    let degrees = 1.0f64;
    let (s, c) = degrees.to_radians().sin_cos();
    // R about x2 turns the normal [0, 0, -1] into [-sin, 0, -cos]
    let motion = "motion = [[0.5, 0.0, 0.0, 0.0], [1.0, 0.0, 0.0, -0.51]]";
    let common = "name = \"die\"\nshape = \"plane\"\npoint = [0.0, 0.0, 1.0]\nfriction = 0.2\npenetration_tolerance = 1e-6\n";
    let turned = format!("{common}normal = [0.0, 0.0, -1.0]\n{motion}\nrotation = [[0.5, {degrees}]]\naxis = [0.0, 1.0, 0.0]\npivot = [0.0, 0.0, 1.0]\n");
    let direct = format!("{common}normal = [{}, 0.0, {}]\n{motion}\n", -s, -c);
    let a = run_text("rotation-tilted-die", &on_table(2.0, 8, &turned, 0.1));
    let b = run_text("rotation-tilted-plane", &on_table(2.0, 8, &direct, 0.1));
    let (head, rows) = history(&a);
    let f3 = column(&head, &rows, "die_force_x3");
    let f1 = column(&head, &rows, "die_force_x1");
    let last = rows.len() - 1;
    assert!(f3[last] > 0.0 && f1[last].abs() > 1e-3 * f3[last], "the die presses and friction holds it sideways: {:?}", (f1[last], f3[last]));
    let d = history_difference(&a, &b);
    println!("tilted die against the tilted plane: history.csv differs by {d:e} (force {:e})", f3[last]);
    assert!(d < 1e-9, "history.csv differs by {d:e}");
}

/// meshes/cylinder-rolling-friction.toml (a cylinder of radius 20 pressed 0.02 into a plate on a
/// table, then rolled along x1 with friction 0.3, its angle its travel over its radius) up to
/// load factor 0.35 (rolled 1.875): it barely drags the plate; the same cylinder slid without
/// turning makes every point in contact slip, and drags mu times its normal force.
#[test]
fn a_rolling_cylinder_barely_drags_where_a_sliding_one_drags_mu_times_its_load() {
    let targets = ("targets = [0.2, 0.4, 0.6, 0.8, 1.0]", "targets = [0.2, 0.35]");
    let rolled = variant("rotation-rolling", "cylinder-rolling-friction.toml", &[targets]);
    let rotation = std::fs::read_to_string(repo().join("meshes/cylinder-rolling-friction.toml")).unwrap().lines().find(|l| l.starts_with("rotation = ")).unwrap().to_string();
    let slid = variant("rotation-sliding", "cylinder-rolling-friction.toml", &[targets, (rotation.as_str(), "")]);
    let mut results = Vec::new();
    for (name, file) in [("rolling", rolled), ("sliding", slid)] {
        let out = file.with_extension("out");
        let o = Command::new(env!("CARGO_BIN_EXE_stamp")).args(["run", "-q", "--out", out.to_str().unwrap()]).arg(&file).output().unwrap();
        assert!(o.status.success(), "{name}: {}", String::from_utf8_lossy(&o.stderr));
        let (head, rows) = history(&out);
        let (f1, f3) = (column(&head, &rows, "roller_force_x1"), column(&head, &rows, "roller_force_x3"));
        let dissipation = column(&head, &rows, "roller_dissipation");
        let last = rows.len() - 1;
        let ratio = (f1[last] / f3[last]).abs();
        let s = summary(&out);
        let punch = &s["steps"][last]["punches"]["roller"];
        println!("{name}: {} steps; at t = 0.35 drag / normal force {ratio:.4e}, dissipation {:.4e}, normal force {:.4e}, {} sticking and {} slipping nodes", rows.len(), dissipation[last], f3[last], punch["sticking_nodes"], punch["slipping_nodes"]);
        assert!(f3[last] > 0.0);
        results.push((ratio, dissipation[last], punch["slipping_nodes"].as_u64().unwrap(), punch["sticking_nodes"].as_u64().unwrap()));
    }
    let (rolling, sliding) = (results[0], results[1]);
    assert!((sliding.0 - 0.3).abs() < 0.02 * 0.3 && sliding.3 == 0, "sliding: drag / normal {} against mu = 0.3, {} sticking", sliding.0, sliding.3);
    assert!(rolling.0 < 0.1 * 0.3 && rolling.2 == 0, "rolling: drag / normal {} against mu = 0.3, {} slipping", rolling.0, rolling.2);
    assert!(rolling.1 < 1e-3 * sliding.1, "dissipation rolling {} against sliding {}", rolling.1, sliding.1);
}

/// A force-driven sphere turning 40 degrees about a tilted axis through its centre (the default
/// pivot) has the same Psi at every load factor: frictionless, the same history to round-off,
/// with nodal and with integrated contact.
#[test]
fn a_force_driven_sphere_turning_about_its_centre_presses_as_one_that_does_not() {
    for contact in ["nodal", "integrated"] {
        let sphere = format!("name = \"ball\"\nshape = \"sphere\"\ncenter = [0.0, 0.0, 20.5]\nradius = 20.0\nforce = 2000.0\npenetration_tolerance = 1e-6\ncontact = \"{contact}\"\n");
        let a = run_text(&format!("rotation-ball-still-{contact}"), &on_table(4.0, 8, &sphere, 0.25));
        let b = run_text(&format!("rotation-ball-turning-{contact}"), &on_table(4.0, 8, &format!("{sphere}rotation = [[1.0, 40.0]]\naxis = [1.0, 1.0, 0.3]\n"), 0.25));
        let d = history_difference(&a, &b);
        println!("force-driven sphere turning about its centre, {contact} contact: history.csv differs by {d:e}");
        assert!(d < 1e-9, "{contact}: history.csv differs by {d:e}");
    }
}

#[test]
fn bad_rotations_are_refused_with_the_key() {
    let dir = temp_dir("rotation-bad");
    let plane = "shape = \"plane\"\npoint = [0.0, 0.0, 0.6]\nnormal = [0.0, 0.0, -1.0]\nmotion = [0.0, 0.0, -0.2]\n";
    let cylinder = "shape = \"cylinder\"\npoint = [0.0, 0.0, 10.6]\naxis = [0.0, 1.0, 0.0]\nradius = 10.0\nmotion = [0.0, 0.0, -0.15]\n";
    for (punch, want) in [
        (format!("{plane}rotation = [[1.0, 5.0]]\n"), "punch[0].axis: a plane turned by `rotation` needs `axis`"),
        (format!("{plane}rotation = [[1.0, 5.0]]\naxis = [0.0, 1.0, 0.0]\n"), "punch[0].pivot: a plane turned by `rotation` needs `pivot`"),
        (format!("{plane}pivot = [0.0, 0.0, 1.0]\n"), "punch[0].pivot: `pivot` is the point a `rotation` turns the punch about; it needs `rotation`"),
        (format!("{plane}axis = [0.0, 1.0, 0.0]\n"), "`axis` only as the axis of a `rotation`"),
        (format!("{plane}rotation = [[1.0, 5.0]]\nrotation_axis = [0.0, 1.0, 0.0]\npivot = [0.0, 0.0, 1.0]\n"), "punch[0].rotation_axis: `rotation_axis` is a cylinder's"),
        (format!("{cylinder}rotation_axis = [0.0, 0.0, 1.0]\n"), "punch[0].rotation_axis: `rotation_axis` is the axis of a cylinder's `rotation`; it needs `rotation`"),
        (format!("{cylinder}rotation = [[0.5, 1.0], [0.5, 2.0]]\n"), "rotation row 1: the load factors must increase strictly"),
        (format!("{cylinder}rotation = [[0.0, 1.0]]\n"), "rotation row 0: at t = 0 the angle must be 0"),
        (format!("{cylinder}rotation = [[0.5, 1.0, 2.0]]\n"), "rotation row 0: expected [t, angle], got 3 numbers"),
        (format!("{cylinder}rotation = 30.0\n"), "expected rows [[t, angle], ...]"),
        // a die that only turns, tilting down onto nodes the table holds: the check sees the turned surface
        ("shape = \"plane\"\npoint = [0.0, 0.0, 0.6]\nnormal = [0.0, 0.0, -1.0]\nrotation = [[1.0, 10.0]]\naxis = [0.0, 1.0, 0.0]\npivot = [0.0, 0.0, 0.6]\n".to_string(), "at load factor 1 its surface lies"),
    ] {
        let file = write(&dir, "p.toml", &on_table(2.0, 4, &punch, 0.5));
        let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("check").arg(&file).output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success() && err.contains(want) && err.contains("p.toml: line"), "{punch}: {err}");
        println!("{}", err.lines().next().unwrap_or(""));
    }
    // a cylinder turns about its own axis through its point by default, or about rotation_axis
    for extra in ["rotation = [[1.0, 5.0]]\n", "rotation = [[1.0, 5.0]]\nrotation_axis = [0.0, 0.0, 1.0]\n"] {
        let file = write(&dir, "p.toml", &on_table(2.0, 4, &format!("{cylinder}{extra}"), 0.5));
        let o = Command::new(env!("CARGO_BIN_EXE_stamp")).arg("check").arg(&file).output().unwrap();
        let out = String::from_utf8_lossy(&o.stdout);
        assert!(o.status.success() && out.contains("turning about") && out.contains("through (0, 0, 10.6)"), "{extra}: {out}{}", String::from_utf8_lossy(&o.stderr));
    }
}

//! The reaction of each support (`[[boundary]]` group) per step: summary.json's
//! `support_reactions` and history.csv's `<group>_reaction_x1`, `_x2`, `_x3` (the last columns).
//!
//! * Global equilibrium on pressed plates (a sphere with a follower pressure, a cylinder, a plate
//!   of four surfaces, a laminate): the groups' reactions, the punches' forces and the applied
//!   loads add up to zero to Newton's tolerance at every step, and the groups' reactions (a dof held
//!   by two groups taken once) are summary.json's total `support_reaction`.
//! * A simply supported square under a uniform pressure: by symmetry the four edges carry the same
//!   reaction, as do the four corners (each counted in both its edges and in a corner group of
//!   its own), and the edges less the corners carry the load q a^2; the edges hold no in-plane force.
//! * A cantilever (plate of 2, 3 and 5 surfaces): the clamp carries the end force.
//! * A strip pulled by a prescribed displacement: the reaction of each end is E h b delta / L.

mod common;
use common::*;
use serde_json::Value;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn vec3(v: &Value) -> [f64; 3] {
    [0, 1, 2].map(|i| v[i].as_f64().unwrap())
}

fn run(problem: &Path, name: &str) -> PathBuf {
    let out = problem.parent().unwrap().join(format!("{name}-out"));
    stamp_cli::run::run(problem, Some(&out), true).unwrap();
    out
}

/// The converged steps of summary.json by step number.
fn steps(out: &Path) -> BTreeMap<u64, Value> {
    let s = summary(out);
    assert_eq!(s["status"], "converged");
    s["steps"].as_array().unwrap().iter().map(|e| (e["step"].as_u64().unwrap(), e.clone())).collect()
}

/// The bound of an imbalance left by Newton: the residual R of the converged iterate, over the
/// free equations, sums along an axis to at most sqrt(equations) |R| (Cauchy-Schwarz); and the
/// round-off of forces of size `scale`.
fn newton_bound(summary: &Value, step: &Value, scale: f64) -> f64 {
    let equations = summary["equations"].as_f64().unwrap();
    let residual = step["residual_history"].as_array().unwrap().last().unwrap().as_f64().unwrap();
    equations.sqrt() * residual + 1e-13 * scale
}

/// The imbalance of every step: the groups' reactions (weighted by `weights`, so that a dof held by
/// several groups counts once), the applied load and the forces of the punches on the plate (minus
/// history.csv's force of the plate on each punch). Returns the largest imbalance relative to the
/// step's largest force, and relative to [`newton_bound`]. Also checks that history.csv and
/// summary.json agree on every reaction and that the weighted groups are summary.json's total
/// `support_reaction`.
fn imbalance(out: &Path, weights: &[(&str, f64)], punches: &[&str]) -> (f64, f64) {
    let (header, rows) = history(out);
    let steps = steps(out);
    // the reaction columns come last, three per group in the order of [[boundary]]
    let tail: Vec<&String> = header[header.len() - 3 * weights.len()..].iter().collect();
    let want: Vec<String> = weights.iter().flat_map(|(g, _)| (1..=3).map(move |k| format!("{g}_reaction_x{k}"))).collect();
    assert_eq!(tail, want.iter().collect::<Vec<_>>(), "the reaction columns at the end of history.csv");
    assert!(!rows.is_empty());
    let (mut worst, mut worst_bound) = (0.0f64, 0.0f64);
    let whole = summary(out);
    for row in &rows {
        let step = &steps[&(row[col(&header, "step")] as u64)];
        let supports = step["support_reactions"].as_object().unwrap();
        assert_eq!(supports.len(), weights.len(), "support_reactions: {supports:?}");
        let mut sum = [0.0; 3];
        let mut scale = 0.0f64;
        for (g, w) in weights {
            let r = [1, 2, 3].map(|k| row[col(&header, &format!("{g}_reaction_x{k}"))]);
            // (serde_json's parser may be an ulp off)
            let json = vec3(&supports[*g]);
            assert!((0..3).all(|i| (r[i] - json[i]).abs() <= 1e-15 * r[i].abs()), "{g}: history.csv {r:?} and summary.json {json:?}");
            for i in 0..3 {
                sum[i] += w * r[i];
                scale = scale.max(r[i].abs());
            }
        }
        let total = vec3(&step["support_reaction"]);
        for i in 0..3 {
            assert!((sum[i] - total[i]).abs() <= 1e-12 * scale, "the groups' reactions {sum:?} against the total support_reaction {total:?}");
        }
        let applied = vec3(&step["applied_load"]);
        for i in 0..3 {
            sum[i] += applied[i];
            scale = scale.max(applied[i].abs());
        }
        for p in punches {
            let f = [1, 2, 3].map(|k| row[col(&header, &format!("{p}_force_x{k}"))]);
            for i in 0..3 {
                sum[i] -= f[i];
                scale = scale.max(f[i].abs());
            }
        }
        assert!(scale > 0.0);
        let off = sum.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        worst = worst.max(off / scale);
        worst_bound = worst_bound.max(off / newton_bound(&whole, step, scale));
    }
    (worst, worst_bound)
}

/// The corner (20, 20) of the quarter models, held by the edges `right` and `top` both (and by a
/// group of its own, so that the test can take it once), and a follower pressure on the top face.
fn corner_and_pressure(pressure: f64) -> String {
    format!(
        r#"[[boundary]]
group = "corner_ur"
fix = ["simply_supported"]

[[load]]
type = "pressure"
group = "all"
pressure = {pressure}
face = "top"
follower = true

[[punch]]"#
    )
}

const QUARTER: [(&str, f64); 5] = [("left", 1.0), ("bottom", 1.0), ("right", 1.0), ("top", 1.0), ("corner_ur", -1.0)];

#[test]
fn support_reactions_balance_the_punches_and_the_loads() {
    // (steel: a pressure of 0.5, 200 on the quarter against the sphere's 500; the laminate, E2 =
    // 1e4, 0.01)
    let (steel, soft) = (corner_and_pressure(0.5), corner_and_pressure(0.01));
    // (name, shipped problem, its edits, the groups' weights, the punch)
    type Case<'a> = (&'a str, &'a str, Vec<(&'a str, &'a str)>, Vec<(&'a str, f64)>, &'a str);
    let cases: Vec<Case> = vec![
        ("sphere-pressure", "sphere-ss.toml", vec![("[[punch]]", &steel)], QUARTER.to_vec(), "sphere"),
        ("cylinder", "cylinder-30deg.toml", vec![], vec![("bottom", 1.0), ("top", 1.0)], "cylinder"),
        ("four-surfaces", "sphere-ss-4surfaces.toml", vec![("[[punch]]", &steel)], QUARTER.to_vec(), "sphere"),
        ("laminate", "laminate-sphere.toml", vec![("n = [40, 40]", "n = [12, 12]"), ("[[punch]]", &soft)], QUARTER.to_vec(), "sphere"),
    ];
    for (name, shipped, edits, weights, punch) in cases {
        let problem = variant(name, shipped, &edits);
        let out = run(&problem, name);
        // the punch pressed the plate at every step
        let (header, rows) = history(&out);
        assert!(rows.iter().all(|r| r[col(&header, &format!("{punch}_contact_area"))] > 0.0), "{name}: a step without contact");
        let (worst, bound) = imbalance(&out, &weights, &[punch]);
        eprintln!("{name}: largest imbalance {worst:.2e} of the step's largest force, {bound:.2e} of the bound of Newton's residual");
        assert!(bound <= 1.0, "{name}: supports, loads and punch out of balance by {worst:e} of the forces, beyond Newton's residual");
    }
}

const Q: f64 = 1.0e-3;
const A: f64 = 10.0;

/// A square a x a, simply supported on its four edges (the rigid in-plane motions held at two
/// corners of the bottom face only: v1 or v2 of both faces would hold the fibre's rotation there),
/// under a uniform pressure Q on its top face; every corner has a group of its own.
fn square(surfaces: usize) -> String {
    format!(
        r#"[mesh]
rectangle = {{ x = [0.0, {A}], y = [0.0, {A}], n = [8, 8] }}

[plate]
thickness = 0.2
E = 2.1e5
nu = 0.3
kinematics = "linear"
surfaces = {surfaces}

[[boundary]]
group = "left"
fix = ["simply_supported"]

[[boundary]]
group = "right"
fix = ["simply_supported"]

[[boundary]]
group = "bottom"
fix = ["simply_supported"]

[[boundary]]
group = "top"
fix = ["simply_supported"]

[[boundary]]
group = "corner_ll"
fix = ["simply_supported", "v1-", "v2-"]

[[boundary]]
group = "corner_lr"
fix = ["simply_supported", "v2-"]

[[boundary]]
group = "corner_ur"
fix = ["simply_supported"]

[[boundary]]
group = "corner_ul"
fix = ["simply_supported"]

[[load]]
type = "pressure"
group = "all"
pressure = {Q}
face = "top"
"#
    )
}

#[test]
fn simply_supported_square_edges_share_the_pressure_by_symmetry() {
    let dir = temp_dir("reactions-square");
    let load = Q * A * A;
    for surfaces in [2, 4] {
        let path = write(&dir, &format!("square{surfaces}.toml"), &square(surfaces));
        let out = run(&path, &format!("square{surfaces}"));
        let step = steps(&out).into_values().last().unwrap();
        let r = |g: &str| vec3(&step["support_reactions"][g]);
        let edges = ["left", "right", "bottom", "top"].map(r);
        let corners = ["corner_ll", "corner_lr", "corner_ur", "corner_ul"].map(r);
        for e in &edges {
            // a simply supported edge holds v3 only: nothing along x1 and x2
            assert_eq!([e[0], e[1]], [0.0, 0.0], "{surfaces} surfaces: an edge's in-plane reaction");
            assert!((e[2] - edges[0][2]).abs() <= 1e-9 * load, "{surfaces} surfaces: edges {edges:?}");
        }
        for c in &corners {
            assert!((c[2] - corners[0][2]).abs() <= 1e-9 * load, "{surfaces} surfaces: corners {corners:?}");
        }
        // each corner is in two edges and in its own group: the edges less the corners hold each
        // dof once, and carry the load
        let (e, c) = (edges[0][2], corners[0][2]);
        assert!((4.0 * e - 4.0 * c - load).abs() <= 1e-9 * load, "{surfaces} surfaces: 4 x {e} - 4 x {c} against the load {load}");
        let total = vec3(&step["support_reaction"]);
        assert!((total[2] - load).abs() <= 1e-9 * load, "{surfaces} surfaces: total {total:?}");
        eprintln!("{surfaces} surfaces: each edge {e:.6e} (q a^2 / 4 = {:.6e}), each corner {c:.6e}; 4 e - 4 c - q a^2 = {:.1e}", load / 4.0, 4.0 * e - 4.0 * c - load);
    }
}

#[test]
fn the_clamp_of_a_cantilever_carries_its_end_force() {
    let dir = temp_dir("reactions-cantilever");
    // CANTILEVER: width 1, end force 0.05 per unit width along +x3 on the edge x2 = 100
    let f = 0.05;
    for surfaces in [2, 3, 5] {
        let text = CANTILEVER.replace("plane_strain = true\n", &format!("plane_strain = true\nsurfaces = {surfaces}\n"));
        let path = write(&dir, &format!("c{surfaces}.toml"), &text);
        let out = run(&path, &format!("c{surfaces}"));
        let (header, rows) = history(&out);
        let last = rows.last().unwrap();
        let r = [1, 2, 3].map(|k| last[col(&header, &format!("bottom_reaction_x{k}"))]);
        assert_eq!(header.last().map(String::as_str), Some("bottom_reaction_x3"));
        // to the converged iterate's residual (Newton's tolerance is relative to its force scale:
        // here the internal forces of the clamped end's couple, far above the end force)
        let bound = newton_bound(&summary(&out), steps(&out).values().last().unwrap(), f);
        eprintln!("{surfaces} surfaces: the clamp's reaction {r:?}: x3 off -F by {:.1e} of F, {:.2} of the bound of Newton's residual", (r[2] + f).abs() / f, (r[2] + f).abs() / bound);
        assert!((r[2] + f).abs() <= bound, "{surfaces} surfaces: the clamp's x3 reaction {} against {}", r[2], -f);
        // the clamp's couple is a pair of opposite forces along x2 on the faces: no net force
        assert!(r[1].abs() <= bound, "{surfaces} surfaces: the clamp's x2 reaction {}", r[1]);
    }
}

/// A strip L x b pulled along x1 by prescribing v1 = delta on its right end (its left end held
/// along x1 only, a corner along x2, the bottom face at three corners along x3: v3 of both faces
/// would hold the thickness there): uniaxial stress, each end's reaction E h b delta / L.
#[test]
fn a_prescribed_displacement_reports_its_force() {
    let dir = temp_dir("reactions-pull");
    let (l, b, h, e, delta) = (10.0, 2.0, 0.5, 7.0e4, 1e-3);
    let exact = e * h * b * delta / l;
    for surfaces in [2, 3] {
        let text = format!(
            r#"[mesh]
rectangle = {{ x = [0.0, {l}], y = [0.0, {b}], n = [5, 2] }}

[plate]
thickness = {h}
E = {e}
nu = 0.3
kinematics = "linear"
surfaces = {surfaces}

[[boundary]]
group = "left"
fix = ["v1"]

[[boundary]]
group = "corner_ll"
fix = ["v2-", "v3-"]

[[boundary]]
group = "corner_ul"
fix = ["v3-"]

[[boundary]]
group = "right"
prescribe = {{ v1 = {delta} }}

[[boundary]]
group = "corner_lr"
fix = ["v3-"]
"#
        );
        let path = write(&dir, &format!("pull{surfaces}.toml"), &text);
        let out = run(&path, &format!("pull{surfaces}"));
        let step = steps(&out).into_values().last().unwrap();
        let right = vec3(&step["support_reactions"]["right"]);
        let left = vec3(&step["support_reactions"]["left"]);
        assert!((right[0] - exact).abs() <= 1e-9 * exact, "{surfaces} surfaces: the prescribed end pulls with {} against E h b delta / L = {exact}", right[0]);
        assert!((left[0] + exact).abs() <= 1e-9 * exact, "{surfaces} surfaces: the held end {} against {}", left[0], -exact);
        assert_eq!([right[1], right[2], left[1], left[2]], [0.0; 4], "{surfaces} surfaces: v1 alone is held on the ends");
    }
}

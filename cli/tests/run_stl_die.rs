//! The STL die through `stamp run`: a triangulated sphere, finer and finer, converges to the
//! analytic sphere's reaction on meshes/sphere-ss-displacement.toml (error ~ h_f^2) with as few
//! Newton iterations; the shipped example meshes/stl-die.toml; a bad STL is refused with the
//! problem file's line and key and the STL file's name.

mod common;
#[path = "../../contact/tests/common/mod.rs"]
mod stl_common;

use common::*;
use std::path::Path;

/// (reaction x3 at load factor 1, Newton iterations over all steps) of a problem.
fn run(problem: &Path, out: &Path) -> (f64, u64) {
    stamp_cli::run::run(problem, Some(out), true).unwrap_or_else(|e| panic!("{}: {e}", problem.display()));
    let s = summary(out);
    assert_eq!(s["status"], "converged");
    let steps = s["steps"].as_array().unwrap();
    let last = steps.last().unwrap();
    assert_eq!(last["load_factor"].as_f64().unwrap(), 1.0);
    let iterations = steps.iter().map(|st| st["newton_iterations"].as_u64().unwrap()).sum();
    (last["reaction"][2].as_f64().unwrap(), iterations)
}

#[test]
fn a_triangulated_sphere_converges_to_the_analytic_sphere() {
    let dir = temp_dir("stl-sphere");
    let text = std::fs::read_to_string(repo().join("meshes/sphere-ss-displacement.toml")).unwrap();
    let sphere_lines = "shape = \"sphere\"\ncenter = [0.0, 0.0, 200.5]     # touches the top face (x3 = 0.5) at the centre\nradius = 200.0\n";
    assert!(text.contains(sphere_lines), "the sphere's punch lines changed");
    std::fs::write(dir.join("analytic.toml"), &text).unwrap();
    let (exact, exact_iterations) = run(&dir.join("analytic.toml"), &dir.join("analytic"));
    let mut rows = Vec::new();
    // facets finer than the plate's elements (l_e = 2): coarser, the nodes fall on facets' corners
    // or middles by chance and the error (the facets' sagitta h_f^2 / (8 R) at the nodes in
    // contact) jumps about instead of falling steadily
    for levels in [7u32, 8, 9, 10] {
        // the lower cap (12 degrees about the lowest point: past the plate's corner at 8 degrees)
        // of an icosphere R = 200 about (0, 0, 200.5): symmetric about x1 = 0 and x2 = 0, its
        // lowest point (a vertex) touches the plate at the centre
        let facets = stl_common::icosphere_cap(levels, 200.0, [0.0, 0.0, 200.5], 12f64.to_radians());
        let h_f = 200.0 * 1.0515 / 2f64.powi(levels as i32); // the icosahedron's edge / 2^levels
        let stl = dir.join(format!("sphere{levels}.stl"));
        stl_common::write(&stl, &stl_common::binary_stl(&facets));
        let problem = dir.join(format!("sphere{levels}.toml"));
        let punch = format!("shape = \"stl\"\nfile = \"sphere{levels}.stl\"\n");
        std::fs::write(&problem, text.replace(sphere_lines, &punch)).unwrap();
        let (reaction, iterations) = run(&problem, &dir.join(format!("out{levels}")));
        rows.push((h_f, facets.len(), reaction, (reaction - exact).abs() / exact.abs(), iterations));
    }
    eprintln!("analytic sphere: reaction {exact:.6}, {exact_iterations} Newton iterations");
    eprintln!("h_f, facets, reaction, relative error, Newton iterations:");
    for r in &rows {
        eprintln!("  {:.3} {:7} {:.6} {:.3e} {}", r.0, r.1, r.2, r.3, r.4);
    }
    for w in rows.windows(2) {
        assert!(w[1].3 < w[0].3, "the error does not decrease: {rows:?}");
        let rate = (w[0].3 / w[1].3).log2();
        eprintln!("  rate {:.2}", rate);
    }
    // the error is bounded by the facets' sagitta ~ h_f^2 at the nodes in contact, which the nodes
    // sample unevenly: from the coarsest to the finest (3 halvings) it falls at a rate of about
    // 1.5 (measured: 6.5e-3, 2.1e-3, 1.1e-3, 2.6e-4)
    let overall = (rows[0].3 / rows[3].3).log2() / 3.0;
    eprintln!("  overall rate {overall:.2}");
    assert!(overall > 1.3, "rate {overall:.2}: {rows:?}");
    assert!(rows[3].3 < 5e-4, "finest: {rows:?}");
    for r in &rows {
        // (measured: 74, 69, 62, 65 against 55, augmented-Lagrangian rounds included)
        assert!(r.4 as f64 <= 1.4 * exact_iterations as f64, "Newton iterations {} against {exact_iterations} for the sphere: {rows:?}", r.4);
    }
}

#[test]
fn the_shipped_stl_die_forms_the_plate() {
    let out = temp_dir("stl-die");
    let (reaction, iterations) = run(&repo().join("meshes/stl-die.toml"), &out);
    let s = summary(&out);
    let last = s["steps"].as_array().unwrap().last().unwrap().clone();
    let pen = last["max_penetration"].as_f64().unwrap();
    assert!(pen < 1e-3, "penetration {pen}");
    // the plate's centre (corner_ll of the quarter) follows the die's tip (moved by 0.9)
    let t = last["points"]["corner_ll"]["displacement_top"][2].as_f64().unwrap();
    assert!((t + 0.9).abs() <= 1.01 * pen + 1e-9, "v3+ at the centre {t}");
    // the die is flatter along x1 (radius 200) than along x2 (50): the loaded zone is longer in x1
    let zone = &last["loaded_zone"];
    let (lx, ly) = (zone["max"][0].as_f64().unwrap(), zone["max"][1].as_f64().unwrap());
    assert!(lx > ly, "loaded zone {zone}");
    assert!(reaction < -100.0, "reaction {reaction}");
    // (measured: 45, augmented-Lagrangian rounds included)
    assert!(iterations <= 60, "{iterations} Newton iterations");
}

#[test]
fn a_bad_stl_die_names_the_problem_key_and_the_stl_file() {
    let dir = temp_dir("stl-bad");
    let text = std::fs::read_to_string(repo().join("meshes/stl-die.toml")).unwrap();
    let mut bytes = std::fs::read(repo().join("meshes/stl-die.stl")).unwrap();
    bytes.truncate(bytes.len() - 7);
    std::fs::write(dir.join("stl-die.stl"), &bytes).unwrap();
    std::fs::write(dir.join("p.toml"), &text).unwrap();
    let e = stamp_cli::run::run(&dir.join("p.toml"), Some(&dir.join("out")), true).unwrap_err().to_string();
    assert!(e.contains("p.toml: line ") && e.contains("punch[0].file") && e.contains("stl-die.stl") && e.contains("announces 3008 facets"), "{e}");
    std::fs::write(dir.join("q.toml"), text.replace("file = \"stl-die.stl\"", "file = \"nowhere.stl\"")).unwrap();
    let e = stamp_cli::run::run(&dir.join("q.toml"), Some(&dir.join("out")), true).unwrap_err().to_string();
    assert!(e.contains("q.toml: line ") && e.contains("nowhere.stl") && e.contains("cannot read"), "{e}");
    std::fs::write(dir.join("r.toml"), text.replace("file = \"stl-die.stl\"", "radius = 3.0")).unwrap();
    let e = stamp_cli::run::run(&dir.join("r.toml"), Some(&dir.join("out")), true).unwrap_err().to_string();
    assert!(e.contains("an stl die needs `file`"), "{e}");
}

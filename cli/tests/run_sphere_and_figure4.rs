//! The sphere example of meshes/ through `stamp run`, and the redrawn Figure 4 of the paper.

mod common;
use common::*;
use serde_json::Value;

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap()
}

#[test]
fn sphere_demo_presses_the_plate_symmetrically() {
    let out = temp_dir("sphere-demo");
    stamp_cli::run::run(&repo().join("meshes/sphere-demo.toml"), Some(&out), true).expect("the sphere example converges");
    let s: Value = serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(s["status"], "converged");
    assert_eq!(s["punches"][0]["eps_reg_automatic"], true);
    // automatic eps_reg = 100 E h / (l_e^2 (2R)^2), l_e = 2
    let eps = 100.0 * 2.1e5 * 1.0 / (4.0 * 80.0 * 80.0);
    assert!((f(&s["punches"][0]["eps_reg"]) - eps).abs() < 1e-9 * eps);
    let steps = s["steps"].as_array().unwrap();
    let last = steps.last().unwrap();
    assert_eq!(f(&last["load_factor"]), 1.0);
    // the centre of the top face follows the sphere's tip (moved by 2) up to the penetration
    let top = &last["points"]["center"]["displacement_top"];
    let pen = f(&last["max_penetration"]);
    assert!(pen < 1e-3, "penetration {pen}");
    assert!((f(&top[2]) + 2.0).abs() <= 1.01 * pen + 1e-9, "v3+ at the centre {}", top[2]);
    assert!(f(&top[0]).abs() < 1e-9 && f(&top[1]).abs() < 1e-9);
    // the sphere pushes the plate down; the in-plane resultant vanishes by symmetry
    let r = &last["reaction"];
    assert!(f(&r[2]) < -1000.0, "reaction {r}");
    assert!(f(&r[0]).abs() < 1e-6 * f(&r[2]).abs() && f(&r[1]).abs() < 1e-6 * f(&r[2]).abs());
    // the loaded zone is centred and grows with the load
    let zone = &last["loaded_zone"];
    for i in 0..2 {
        assert!((f(&zone["min"][i]) + f(&zone["max"][i])).abs() < 1e-9, "{zone}");
    }
    let width = |e: &Value| f(&e["loaded_zone"]["max"][0]) - f(&e["loaded_zone"]["min"][0]);
    assert!(width(last) > width(&steps[0]), "{} vs {}", width(last), width(&steps[0]));
    // the reaction grows monotonically with the punch travel
    for w in steps.windows(2) {
        assert!(f(&w[1]["reaction"][2]) < f(&w[0]["reaction"][2]));
    }
    for name in ["probe_sphere.png", "probe_sphere.svg", "force_travel_sphere.png", "history.csv", "sphere-demo.pvd"] {
        assert!(out.join(name).is_file(), "{name}");
    }
}

#[test]
fn figure4_is_drawn_with_its_data() {
    let out = temp_dir("figure4");
    let written = stamp_cli::paper::figure4::write_figure4(&out).unwrap();
    assert_eq!(written, [out.join("figure4.png"), out.join("figure4.svg"), out.join("figure4.csv")]);
    let png = std::fs::read(out.join("figure4.png")).unwrap();
    assert_eq!(&png[..4], b"\x89PNG");
    let svg = std::fs::read_to_string(out.join("figure4.svg")).unwrap();
    assert!(svg.contains("<svg") && svg.contains("P~ = 80"));
    let csv = std::fs::read_to_string(out.join("figure4.csv")).unwrap();
    let rows: Vec<Vec<f64>> = csv.lines().skip(1).map(|l| l.split(',').map(|x| x.parse().unwrap()).collect()).collect();
    assert_eq!(rows.len(), 7 * 41);
    for r in &rows {
        // P~ = 16 P R^2 / (E h) with R = 100, E = 2e4, h = 2; q~ = 16 q R^2 l / (E h^3) = 100 q
        assert!((r[0] - 16.0 * r[1] * 1e4 / 4e4).abs() < 1e-9 * r[0]);
        assert!((r[6] - 100.0 * r[5]).abs() <= 1e-12 * r[6].abs().max(1.0));
        assert!(r[5] >= 0.0);
    }
    // the largest load parameter is Table 2's last row
    let last: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] == 80.0).collect();
    assert_eq!(last.len(), 41);
    assert!((last[0][1] - 20.0).abs() < 1e-12, "P~ = 80 is Table 2's P = 20");
}

#[test]
fn stamp_paper_plot_says_where_figure4_was_written() {
    let out = temp_dir("paper-plot");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_stamp")).arg("paper").arg("--plot").arg(&out).output().unwrap();
    assert!(run.status.success(), "stamp paper --plot failed: {}", String::from_utf8_lossy(&run.stderr));
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(stdout.contains("Table 2."), "the tables are printed first: {stdout}");
    // what it cites is in the repository: the document and its section
    assert!(!stdout.contains("SPEC"), "{stdout}");
    let cited = stdout.split_whitespace().filter(|w| w.starts_with("docs/")).collect::<Vec<_>>();
    assert!(!cited.is_empty(), "{stdout}");
    for doc in cited {
        let text = std::fs::read_to_string(repo().join(doc.trim_end_matches(|c: char| !c.is_alphanumeric()))).unwrap_or_else(|e| panic!("{doc}: {e}"));
        assert!(text.contains("# The paper's benchmark"), "{doc}");
    }
    let line = format!("stamp paper: Figure 4 written to {}, .svg, .csv", out.join("figure4.png").display());
    assert_eq!(stdout.lines().last(), Some(line.as_str()), "{stdout}");
    for name in ["figure4.png", "figure4.svg", "figure4.csv"] {
        assert!(out.join(name).is_file(), "{name}");
    }
    // with --json stdout stays one JSON document; the message goes to stderr
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_stamp")).args(["paper", "--json", "--plot"]).arg(&out).output().unwrap();
    assert!(run.status.success());
    let _: Value = serde_json::from_slice(&run.stdout).expect("stdout is JSON");
    assert_eq!(String::from_utf8_lossy(&run.stderr).trim_end(), line);
}

//! What README.md shows a program printing is what it prints: the tutorial's gmsh file is the
//! shipped `meshes/plate.geo`, and its problem file, run on the shipped `meshes/plate.msh` (the mesh
//! gmsh makes of it), prints exactly the `stamp check` summary and the `stamp run` table the README
//! shows; the README's example error is the one `stamp check` gives for `nu = 0.5` in that file;
//! and `stamp paper --plot DIR` says where Figure 4 went as the README says.

mod common;
use common::*;
use std::path::Path;
use std::process::Command;

/// README.md's text.
fn readme() -> String {
    std::fs::read_to_string(repo().join("README.md")).unwrap()
}

/// The body of the first fenced code block of `text` whose first line starts with `first`
/// (without the fences, with its final newline).
fn block(text: &str, first: &str) -> String {
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.starts_with("```") {
            let body: Vec<&str> = lines.by_ref().take_while(|l| !l.starts_with("```")).collect();
            if body.first().is_some_and(|l| l.starts_with(first)) {
                return body.iter().map(|l| format!("{l}\n")).collect();
            }
        }
    }
    panic!("README.md has no code block starting with '{first}'")
}

/// The tutorial's folder: its problem file from the README beside the shipped mesh.
fn tutorial(name: &str) -> std::path::PathBuf {
    let dir = temp_dir(name);
    std::fs::copy(repo().join("meshes/plate.msh"), dir.join("plate.msh")).unwrap();
    write(&dir, "plate.toml", &block(&readme(), "title = \"clamped plate pressed by a ball\""));
    dir
}

/// `stamp ARGS` run in `dir`: (success, stdout, stderr).
fn stamp(dir: &Path, args: &[&str]) -> (bool, String, String) {
    let o = Command::new(env!("CARGO_BIN_EXE_stamp")).current_dir(dir).args(args).output().unwrap();
    (o.status.success(), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

/// Line-by-line comparison with the line that differs in the message.
fn assert_same(what: &str, readme: &str, printed: &str) {
    let (r, p): (Vec<&str>, Vec<&str>) = (readme.lines().collect(), printed.lines().collect());
    for (i, (a, b)) in r.iter().zip(&p).enumerate() {
        assert_eq!(a, b, "{what}: line {} of README.md's block differs from what the program prints:\n{printed}", i + 1);
    }
    assert_eq!(r.len(), p.len(), "{what}: README.md shows {} lines, the program prints {}:\n{printed}", r.len(), p.len());
}

#[test]
fn the_tutorials_gmsh_file_is_the_shipped_one() {
    let shipped = std::fs::read_to_string(repo().join("meshes/plate.geo")).unwrap();
    assert_same("plate.geo", &block(&readme(), "// plate.geo"), &shipped);
    // the shipped mesh is gmsh's mesh of that file: its physical groups and its size as the README's
    // check output gives them (2931 nodes from 950 triangles; checked exactly by the next test)
    let msh = std::fs::read_to_string(repo().join("meshes/plate.msh")).unwrap();
    assert!(msh.starts_with("$MeshFormat\n4.1 0 8\n"), "meshes/plate.msh is not ASCII MSH 4.1");
    for group in ["\"edge\"", "\"plate\"", "\"center\""] {
        assert!(msh.contains(group), "meshes/plate.msh has no physical group {group}");
    }
}

#[test]
fn the_tutorials_check_and_run_print_what_the_readme_shows() {
    let dir = tutorial("readme-tutorial");
    let text = readme();
    assert!(text.contains("stamp run plate.toml "), "README.md no longer runs `stamp run plate.toml`");

    let (ok, out, err) = stamp(&dir, &["check", "plate.toml"]);
    assert!(ok && err.is_empty(), "stamp check plate.toml: {err}");
    assert_same("stamp check plate.toml", &block(&text, "problem: plate.toml"), &out);

    let shown = block(&text, "                   ball:");
    let rows = shown.lines().filter(|l| l.trim_start().starts_with(|c: char| c.is_ascii_digit())).count();
    assert!(rows >= 2, "README.md's table has {rows} step rows");
    let (ok, out, err) = stamp(&dir, &["run", "plate.toml"]);
    assert!(ok, "stamp run plate.toml failed: {err}");
    assert_same("stamp run plate.toml", &shown, &out);
    // the README's claims around the table: the steps are the targets, no cut-backs
    let summary = summary(&dir.join("plate-out"));
    assert_eq!(summary["status"], "converged");
    assert_eq!(summary["steps"].as_array().unwrap().len(), rows);
    assert!(text.contains("(here 0.25, 0.5, 0.75, 1)"), "README.md's targets sentence changed");
    for (step, target) in summary["steps"].as_array().unwrap().iter().zip([0.25, 0.5, 0.75, 1.0]) {
        assert_eq!(step["load_factor"].as_f64(), Some(target));
    }
}

#[test]
fn the_readmes_example_error_is_what_stamp_check_prints() {
    let dir = tutorial("readme-error");
    let problem = std::fs::read_to_string(dir.join("plate.toml")).unwrap();
    assert_eq!(problem.lines().nth(8), Some("nu = 0.3"), "the README's error example is about line 9 of the tutorial's plate.toml");
    write(&dir, "plate.toml", &problem.replacen("nu = 0.3", "nu = 0.5", 1));
    let (ok, out, err) = stamp(&dir, &["check", "plate.toml"]);
    assert!(!ok && out.is_empty(), "nu = 0.5 must be refused: {out}");
    assert_same("stamp check with nu = 0.5", &block(&readme(), "error: plate.toml: line 9"), &err);
}

#[test]
fn stamp_paper_plot_says_where_figure_4_went_as_the_readme_says() {
    let dir = temp_dir("readme-paper");
    let (ok, out, err) = stamp(&dir, &["paper", "--plot", "figs"]);
    assert!(ok, "stamp paper --plot figs: {err}");
    let shown = "stamp paper: Figure 4 written to DIR/figure4.png, .svg, .csv";
    assert!(readme().contains(shown), "README.md no longer shows `{shown}`");
    let printed = shown.replace("DIR", "figs");
    assert!(out.lines().chain(err.lines()).any(|l| l == printed), "stamp paper --plot figs does not print '{printed}':\n{out}\n{err}");
    for f in ["figure4.png", "figure4.svg", "figure4.csv"] {
        assert!(dir.join("figs").join(f).is_file(), "no figs/{f}");
    }
}

//! stamp's problem files as a library: read, build, check, solve and write the problem a TOML
//! file (or the same table built in memory) describes. The `stamp` program (`stamp run`,
//! `stamp check`) and the Python package are thin shells around it.
//!
//! * [`problem`]: the TOML schema (serde, `deny_unknown_fields`) and its checks; it depends on no
//!   module below but [`units`] (the modules that build and run the model read it, not the reverse);
//! * [`mesh`]: the gmsh mesh or the built-in rectangle, with groups by dimension (refused before it
//!   is built when its model cannot fit in memory: [`memory`]);
//! * [`build`]: section, plate elements, constraints, loads, punches, solver settings;
//! * [`check`]: what is wrong with a built problem, said before the solve (`stamp check`), with
//!   [`rigid_modes`] (rigid motions held by nothing), [`travel_modes`] (force-driven punches'
//!   travels held by nothing) and [`punch_start`] (gaps at the start);
//! * [`out_dir`]: a run owns its output folder (removes the previous run's files, only those),
//!   locked by [`folder_lock`] against a second run; [`regular`] refuses FIFOs and the like there;
//! * [`solve`]: Newton-Raphson along the targets with a progress bar, writing every step;
//! * [`output`]: the .vtu fields, summary.json entries and contact CSV of a step ([`kept`]: the
//!   same kept in memory for the Python package);
//! * [`refine`]: `stamp run --refine`, the run on refined meshes, with [`richardson`] and
//!   [`refine_report`] (the estimates in the table, history.csv and summary.json);
//! * [`plot`]: PNG/SVG line plots (contact pressure here, the paper's Figure 4 in the CLI).

pub mod abort_note;
pub mod build;
pub mod cell_shape;
pub mod coarse;
pub mod folder_lock;
pub mod check;
pub mod history;
pub mod interrupt;
pub mod kept;
pub mod laminate_spec;
pub mod memory;
pub mod mesh;
pub mod out_dir;
pub mod output;
pub mod own_inputs;
pub mod parallel;
pub mod plate_model;
pub mod plot;
pub mod pressure;
pub mod probe;
pub mod psi_checks;
pub mod problem;
pub mod punch_start;
pub mod refine;
pub mod refine_report;
pub mod regular;
pub mod reserve;
pub mod richardson;
pub mod rigid_modes;
pub mod solve;
pub mod table;
pub mod equilibrium_shear;
pub mod thickness_probe;
pub mod travel_modes;
pub mod units;
pub mod stdout;

pub use problem::Problem;
pub use solve::{default_out_dir, RunOutcome};

use std::path::Path;

/// Read, build, check, solve and write the problem file `problem` into `out` (default
/// `<problem dir>/<problem stem>-out`): [`solve_problem`] on the file's problem.
pub fn run(problem: &Path, out: Option<&Path>, quiet: bool) -> stamp::Result<RunOutcome> {
    let p = Problem::read(problem)?;
    let out_dir = out.map(|o| o.to_path_buf()).unwrap_or_else(|| default_out_dir(problem));
    solve_problem(&p, &out_dir, &solve::SolveOptions { quiet, ..Default::default() })
}

/// Build, check, solve and write the problem `p` into `out_dir`: the pipeline of `stamp run` and
/// of the Python package's `Problem.solve`. The checks of [`check::check`] come first: an error
/// stops the run before anything is written, warnings go to stderr (also when quiet), and so do,
/// after the run, the warnings of [`check::after_the_run`] (a punch that never touched the plate,
/// a contact zone narrower than the cells). On a Newton failure the converged steps are written
/// and the error is returned.
pub fn solve_problem(p: &Problem, out_dir: &Path, options: &solve::SolveOptions) -> stamp::Result<RunOutcome> {
    let setup = build::build(p)?;
    let report = check::check(p, &setup)?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    let outcome = solve::solve_and_write(p, setup, out_dir, options);
    if parallel::writes_outputs() {
        for w in check::after_the_run(p, &out_dir.join("summary.json")) {
            eprintln!("warning: {w}");
        }
    }
    outcome
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    /// Each module of this folder and the modules of this folder its code names (`super::x`,
    /// `crate::x`; comments left out).
    fn uses() -> BTreeMap<String, Vec<String>> {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut graph = BTreeMap::new();
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            let Some(name) = path.file_stem().and_then(|s| s.to_str()).filter(|_| path.extension().is_some_and(|e| e == "rs")) else { continue };
            if name == "lib" || name == "stdout" {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            // the module's own code, not its tests (whose `use super::*` is the module itself)
            let code = text.split("#[cfg(test)]").next().unwrap();
            let mut deps: Vec<String> = Vec::new();
            for line in code.lines().map(str::trim).filter(|l| !l.starts_with("//")) {
                for prefix in ["super::", "crate::"] {
                    for part in line.split(prefix).skip(1) {
                        let dep: String = part.chars().take_while(|c| c.is_ascii_lowercase() || *c == '_').collect();
                        if !dep.is_empty() && !deps.contains(&dep) {
                            deps.push(dep);
                        }
                    }
                }
            }
            graph.insert(name.to_string(), deps);
        }
        graph
    }

    #[test]
    fn the_problem_schema_depends_on_no_model_module_and_no_module_imports_in_a_circle() {
        let graph = uses();
        assert_eq!(graph["problem"], vec!["units".to_string()], "problem.rs (the TOML schema) names {:?}", graph["problem"]);
        assert!(graph["memory"].is_empty(), "{:?}", graph["memory"]);
        // depth-first search for a cycle
        fn visit(u: &str, graph: &BTreeMap<String, Vec<String>>, state: &mut BTreeMap<String, u8>, path: &mut Vec<String>) {
            state.insert(u.to_string(), 1);
            path.push(u.to_string());
            for v in graph.get(u).into_iter().flatten().filter(|v| graph.contains_key(*v)) {
                match state.get(v) {
                    Some(1) => panic!("modules import each other in a circle: {} -> {v}", path.join(" -> ")),
                    Some(_) => {}
                    None => visit(v, graph, state, path),
                }
            }
            path.pop();
            state.insert(u.to_string(), 2);
        }
        let mut state = BTreeMap::new();
        for u in graph.keys() {
            if !state.contains_key(u) {
                visit(u, &graph, &mut state, &mut Vec::new());
            }
        }
        assert!(graph.len() > 15 && graph["check"].contains(&"build".to_string()), "the scan found the modules: {graph:?}");
    }
}

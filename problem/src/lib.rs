//! stamp's problem files as a library: read, build, check, solve and write the problem a TOML
//! file (or the same table built in memory) describes. The `stamp` program (`stamp run`,
//! `stamp check`) and the Python package are thin shells around it.
//!
//! The folders, in the order of the pipeline ([`solve_problem`]):
//!
//! * [`schema`]: read: the problem file (serde, `deny_unknown_fields`) and its checks, a module per
//!   table (mesh, plate, materials, boundary, loads, punches, solver, output, units); it depends on
//!   nothing outside its folder (the modules that build and run the model read it, not the reverse);
//! * [`model`]: build: the mesh (refused before it is built when its model cannot fit in memory),
//!   the plate model, and the section, plate elements, constraints, loads, punches and solver
//!   settings, one builder per table; the coarse-mesh predictor;
//! * [`checks`]: check: what is wrong with a built problem, said before the solve (`stamp check`):
//!   rigid motions and force-driven punches' travels held by nothing, gaps at the start, a punch's
//!   Psi, the cells' shape;
//! * [`mod@run`]: solve: Newton-Raphson along the targets with a progress bar, writing every step,
//!   on one process or several, ended cleanly on Ctrl-C; the output folder a run owns (locked
//!   against a second run, never over its inputs);
//! * [`outputs`]: write: the .vtu fields, summary.json entries and contact CSV of a step,
//!   history.csv, the table on stdout, the probes, PNG/SVG line plots;
//! * [`refine`]: `stamp run --refine`, the run on refined meshes, with the Richardson estimates.
//!
//! The modules that the program, the Python package and the tests name by their place before the
//! folders (`stamp_problem::build`, `stamp_problem::check`, ...) are re-exported there.

pub mod checks;
pub mod model;
pub mod outputs;
pub mod refine;
pub mod run;
pub mod schema;

pub use run::{default_out_dir, RunOutcome};
pub use schema::Problem;

// The modules by their place before the folders.
pub use checks::check;
pub use model::{build, coarse, mesh, plate_model};
pub use outputs::plot;
pub use refine::refine_report;
pub use run::{abort_note, folder_lock, interrupt, kept, out_dir, parallel, solve, stdout};

use std::path::Path;

/// Read, build, check, solve and write the problem file `problem` into `out` (default
/// `<problem dir>/<problem stem>-out`): [`solve_problem`] on the file's problem.
pub fn run(problem: &Path, out: Option<&Path>, quiet: bool) -> stamp::Result<RunOutcome> {
    let p = Problem::read(problem)?;
    let out_dir = out.map(|o| o.to_path_buf()).unwrap_or_else(|| default_out_dir(problem));
    solve_problem(&p, &out_dir, &run::SolveOptions { quiet, ..Default::default() })
}

/// Build, check, solve and write the problem `p` into `out_dir`: the pipeline of `stamp run` and
/// of the Python package's `Problem.solve` ([`run::solve_and_write`] writes the [`outputs`] of
/// every step as soon as it converges). The checks of [`checks::check()`] come first: an error stops the run before anything is written,
/// warnings go to stderr (also when quiet), and so do, after the run, the warnings of
/// [`checks::after_the_run`] (a punch that never touched the plate, a contact zone narrower than
/// the cells). On a Newton failure the converged steps are written and the error is returned.
pub fn solve_problem(p: &Problem, out_dir: &Path, options: &run::SolveOptions) -> stamp::Result<RunOutcome> {
    let setup = model::build(p)?;
    let report = checks::check(p, &setup)?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    let outcome = run::solve_and_write(p, setup, out_dir, options);
    if run::parallel::writes_outputs() {
        for w in checks::after_the_run(p, &out_dir.join("summary.json")) {
            eprintln!("warning: {w}");
        }
    }
    outcome
}

#[cfg(test)]
mod tests {
    use std::collections::{BTreeMap, BTreeSet};
    use std::path::Path;

    /// The module a file of `src/` holds, as its path below the crate (`model::build`,
    /// `schema` for schema/mod.rs, "" for lib.rs).
    fn module_of(file: &Path, src: &Path) -> String {
        let mut parts: Vec<String> = file.strip_prefix(src).unwrap().iter().map(|s| s.to_string_lossy().into_owned()).collect();
        let last = parts.pop().unwrap();
        let stem = last.trim_end_matches(".rs");
        if stem != "mod" && stem != "lib" {
            parts.push(stem.to_string());
        }
        parts.join("::")
    }

    /// The .rs files below `dir`, in every folder.
    fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                rust_files(&path, out);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }

    /// Each module of `src/` (folders included, lib.rs left out) and the modules its code names by
    /// `crate::a::b` or `super::x` (comments and the module's own tests left out), each resolved
    /// to the longest module path it names; and the names that resolve to no module (an old path
    /// through the re-exports of lib.rs).
    fn uses() -> (BTreeMap<String, BTreeSet<String>>, Vec<String>) {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut files = Vec::new();
        rust_files(&src, &mut files);
        let modules: BTreeSet<String> = files.iter().map(|f| module_of(f, &src)).collect();
        let mut graph = BTreeMap::new();
        let mut unresolved = Vec::new();
        for file in &files {
            let name = module_of(file, &src);
            if name.is_empty() {
                continue;
            }
            let here: Vec<&str> = name.split("::").collect();
            let text = std::fs::read_to_string(file).unwrap();
            // the module's own code, not its tests (whose `use super::*` is the module itself)
            let code = text.split("#[cfg(test)]").next().unwrap();
            let mut deps = BTreeSet::new();
            for line in code.lines().map(str::trim).filter(|l| !l.starts_with("//")) {
                for (at, _) in line.match_indices("crate::").chain(line.match_indices("super::")) {
                    if line[..at].ends_with("super::") || line[..at].ends_with('$') || line[..at].ends_with(|c: char| c.is_alphanumeric() || c == '_') {
                        continue; // the middle of a `super::super::` chain, `$crate`, `stamp_problem::`
                    }
                    let mut rest = &line[at..];
                    let mut base: Vec<&str> = if rest.starts_with("crate::") {
                        rest = &rest["crate::".len()..];
                        Vec::new()
                    } else {
                        let mut up = 0;
                        while let Some(r) = rest.strip_prefix("super::") {
                            rest = r;
                            up += 1;
                        }
                        here[..here.len() - up].to_vec()
                    };
                    // the path's names: up to the first piece that is more than a name
                    let mut segments = Vec::new();
                    for piece in rest.split("::") {
                        let end = piece.find(|c: char| !(c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_')).unwrap_or(piece.len());
                        if end > 0 {
                            segments.push(&piece[..end]);
                        }
                        if end == 0 || end < piece.len() {
                            break;
                        }
                    }
                    // a name followed by `::` is a module's (a macro's is followed by `!`)
                    let a_path = segments.first().is_some_and(|s| rest[s.len()..].starts_with("::"));
                    let mut found = None;
                    for s in segments {
                        base.push(s);
                        if modules.contains(&base.join("::")) {
                            found = Some(base.join("::"));
                        }
                    }
                    match found {
                        Some(dep) if dep != name => {
                            deps.insert(dep);
                        }
                        Some(_) => {}
                        None if a_path => unresolved.push(format!("{name}: {line}")),
                        None => {} // an item of the crate root (the macros out! and outln!) or of `super`
                    }
                }
            }
            graph.insert(name, deps);
        }
        (graph, unresolved)
    }

    #[test]
    fn the_schema_depends_on_nothing_outside_its_folder_and_no_module_imports_in_a_circle() {
        let (graph, unresolved) = uses();
        let in_schema = |m: &str| m == "schema" || m.starts_with("schema::");
        assert!(graph.len() > 15 && graph.keys().filter(|m| in_schema(m)).count() > 8, "the scan found the modules: {graph:?}");
        assert!(graph["checks::check"].contains("model::build"), "the scan resolves names: {:?}", graph["checks::check"]);
        assert!(graph["schema::plate"].contains("schema::materials"), "the scan resolves super: {:?}", graph["schema::plate"]);
        assert!(unresolved.is_empty(), "names through no module (an old path?): {unresolved:#?}");
        for (m, deps) in graph.iter().filter(|(m, _)| in_schema(m)) {
            let outside: Vec<&String> = deps.iter().filter(|d| !in_schema(d)).collect();
            assert!(outside.is_empty(), "{m} (the problem file's schema) names {outside:?}");
        }
        assert!(graph["model::memory"].is_empty(), "{:?}", graph["model::memory"]);
        // depth-first search for a cycle
        fn visit(u: &str, graph: &BTreeMap<String, BTreeSet<String>>, state: &mut BTreeMap<String, u8>, path: &mut Vec<String>) {
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
    }
}

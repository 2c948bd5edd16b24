//! `stamp run --refine [LEVELS]`: how far a run is from the mesh-converged answer. The problem is
//! solved on its mesh, then on the mesh refined once (every cell into four, [`MeshData::refined`]),
//! and twice with LEVELS = 2, ...; every finer run passes through exactly the load factors the run
//! on the problem's mesh converged at, so each step compares the same load. The key results of
//! every step are extrapolated ([`crate::refine::richardson`], [`crate::refine::refine_report`]).
//!
//! Outputs: the run on the problem's mesh writes its folder as `stamp run` does, the finer runs
//! write theirs into `refined/`, `refined2/`, ... inside it (complete runs of their own, with
//! their own summary.json). The folder's history.csv gains the estimate columns, summary.json the
//! `refinement` object, the table on stdout the estimate columns.
//!
//! summary.json tells the truth at every moment: `status` stays "running" (with our pid) until
//! the last mesh is solved, `refinement.status` says which mesh is being solved; a failure on a
//! finer mesh makes the status "failed" with the error, and the estimates are left out.

pub mod refine_report;
pub mod richardson;

use crate::model::build::{build, build_on};
use crate::model::coarse::PreviousLevel;
use crate::model::mesh::MeshData;
use crate::refine::refine_report::{quantities, times, Report};
use crate::run::solve::{default_out_dir, solve_and_write, RunOutcome, SolveOptions};
use crate::schema::Problem;
use crate::schema::units::Units;
use serde_json::{json, Value};
use stamp::io::write_string_atomically;
use stamp::{Result, StampError};
use std::path::Path;
use std::time::Instant;

/// The most refinements asked for at once (each multiplies the unknowns by 4).
pub const MAX_LEVELS: usize = 3;

/// The command line with `--refine N` (N a whole number) joined into `--refine=N`: `--refine`
/// takes an optional value, which must follow an `=` so that `stamp run --refine P.toml` leaves
/// the problem file alone; `stamp run --refine 2 P.toml` still reads as two levels.
pub fn join_refine_value<I: IntoIterator<Item = std::ffi::OsString>>(args: I) -> Vec<std::ffi::OsString> {
    let mut out: Vec<std::ffi::OsString> = Vec::new();
    let mut args = args.into_iter().peekable();
    while let Some(a) = args.next() {
        let number = args.peek().and_then(|n| n.to_str()).is_some_and(|n| !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()));
        if a == "--refine" && number {
            let mut joined = std::ffi::OsString::from("--refine=");
            joined.push(args.next().expect("peeked"));
            out.push(joined);
        } else {
            out.push(a);
        }
    }
    out
}

/// The subfolder of the output folder for refinement level `level` (1-based): the level's name.
pub use refine_report::level_name as level_folder;

/// Ok if the problem's mesh refined 1 ..= levels times fits in `available` bytes (None: unknown)
/// with `dofs_per_node` unknowns per node; else what the largest that fits is and what to do.
pub fn check_levels_fit(sizes: &[(u64, u64)], levels: usize, dofs_per_node: u64, available: Option<f64>) -> std::result::Result<(), String> {
    for (k, &(nodes, _)) in sizes.iter().enumerate() {
        if let Err(m) = crate::model::memory::check_against(nodes, dofs_per_node, available) {
            let advice = if k == 0 { "solve without --refine".to_string() } else { format!("use --refine {k}") };
            return Err(format!("--refine {levels}: the mesh refined {}: {m}; or {advice}", times(k + 1)));
        }
    }
    Ok(())
}

/// Rewrite summary.json in `dir` with `edit` applied (atomically), on the process that writes the
/// outputs (collective under MPI: the outcome is agreed, see [`crate::run::parallel::on_writer`]).
fn edit_summary(dir: &Path, edit: impl FnOnce(&mut Value)) -> Result<()> {
    crate::run::parallel::on_writer(|| edit_summary_here(dir, edit)).map(|_| ())
}

fn edit_summary_here(dir: &Path, edit: impl FnOnce(&mut Value)) -> Result<()> {
    let path = dir.join("summary.json");
    let text = crate::run::regular::read_regular(&path)?.ok_or_else(|| StampError::io(&path, std::io::ErrorKind::NotFound.into()))?;
    let mut v: Value = serde_json::from_str(&text).map_err(|e| StampError::Problem(format!("{}: cannot read back summary.json: {e}", stamp::show_path(&path))))?;
    edit(&mut v);
    let text = serde_json::to_string_pretty(&v).map_err(|e| StampError::Problem(format!("cannot encode summary.json: {e}")))?;
    write_string_atomically(&path, &text)
}

/// One mesh's line of `refinement.meshes`.
fn mesh_entry(level: usize, mesh: &MeshData) -> Value {
    let folder = if level == 0 { ".".to_string() } else { level_folder(level) };
    json!({ "level": level, "nodes": mesh.mesh.num_nodes(), "cells": mesh.mesh.num_cells(), "folder": folder })
}

/// Solve `problem` on its mesh and `levels` refinements of it, write everything into `out` (see the
/// module notes) and print the table with the estimates (unless `quiet`).
pub fn run_refined(problem: &Path, out: Option<&Path>, quiet: bool, levels: usize) -> Result<RunOutcome> {
    let start = Instant::now();
    let p = Problem::read(problem)?;
    if levels == 0 || levels > MAX_LEVELS {
        return Err(StampError::Problem(format!("--refine takes 1 to {MAX_LEVELS} levels, got {levels}")));
    }
    let setup = build(&p)?;
    let report = crate::checks::check::check(&p, &setup)?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    // every refined model must fit before anything is solved
    let sizes = stamp::mesh::refine::refined_sizes(&setup.mesh.mesh, levels);
    check_levels_fit(&sizes, levels, p.spec.plate.get_ref().dofs_per_node(), crate::model::memory::available_bytes()).map_err(|m| p.error_at(p.spec.mesh.span(), "mesh", m))?;
    let out_dir = out.map(|o| o.to_path_buf()).unwrap_or_else(|| default_out_dir(problem));
    // the folder is this run's until the last mesh is solved (the runs below claim it again)
    let _lock = crate::run::parallel::on_writer(|| {
        std::fs::create_dir_all(&out_dir).map_err(|e| StampError::io(&out_dir, e))?;
        crate::run::folder_lock::FolderLock::acquire(&out_dir)
    })?;
    let units = Units::new(p.spec.units.as_ref());
    let force_driven: Vec<bool> = p.spec.punch.iter().map(|s| s.get_ref().force.is_some()).collect();
    let mut meshes = vec![mesh_entry(0, &setup.mesh)];
    let mut next = Some(setup.mesh.refined());
    let refinement = |status: String, meshes: &[Value]| {
        json!({ "status": status, "levels": levels, "order": crate::refine::richardson::ASSUMED_ORDER, "order_assumed": levels == 1, "meshes": meshes })
    };

    let running = refinement("solving the problem's mesh".into(), &meshes);
    let mut previous_mesh = setup.mesh.mesh.clone();
    let opts = SolveOptions { quiet, no_table: true, targets: None, refinement: Some(running), caller_finishes: true, record_states: true, previous: None, ..Default::default() };
    let coarse = solve_and_write(&p, setup, &out_dir, &opts);
    if crate::run::parallel::writes_outputs() {
        for w in crate::checks::check::after_the_run(&p, &out_dir.join("summary.json")) {
            eprintln!("warning: {w}");
        }
    }
    let mut coarse = match coarse {
        Ok(c) => c,
        Err(e) => {
            let _ = edit_summary(&out_dir, |v| v["refinement"] = refinement("not run: the run on the problem's mesh failed".into(), &meshes));
            return Err(e);
        }
    };
    let load_factors: Vec<f64> = coarse.history.rows.iter().map(|r| r.load_factor).collect();
    let mut fines = Vec::with_capacity(levels);
    let mut files = coarse.files.clone();
    // (the states move on to the next level: the outcome keeps none)
    let mut previous_states = std::sync::Arc::new(std::mem::take(&mut coarse.states));
    for level in 1..=levels {
        let mesh = next.take().expect("refined before the loop or in the level before");
        if level < levels {
            next = Some(mesh.refined());
        }
        meshes.push(mesh_entry(level, &mesh));
        let dir = out_dir.join(level_folder(level));
        let status = format!("solving the mesh refined {} ({} nodes) into {}", times(level), mesh.mesh.num_nodes(), level_folder(level));
        edit_summary(&out_dir, |v| v["refinement"] = refinement(status.clone(), &meshes))?;
        if !quiet {
            eprintln!("stamp run --refine: {status}");
        }
        // the level before starts this one's steps; this one the next level's
        let previous = PreviousLevel { mesh: std::mem::replace(&mut previous_mesh, mesh.mesh.clone()), states: previous_states.clone() };
        let fine = build_on(&p, mesh).and_then(|setup| {
            let note = json!({ "level": level, "note": format!("the problem's mesh refined {}, driven through the load factors of ../summary.json, every step started from the solution on the mesh before", times(level)) });
            let opts = SolveOptions { quiet, no_table: true, targets: Some(load_factors.clone()), refinement: Some(note), caller_finishes: false, record_states: level < levels, previous: Some(previous), ..Default::default() };
            solve_and_write(&p, setup, &dir, &opts)
        });
        match fine {
            Ok(f) => {
                previous_states = std::sync::Arc::new(f.states);
                files.extend(f.files.iter().cloned());
                fines.push(f.history);
            }
            Err(e) => {
                let e = StampError::Problem(format!("{}: the mesh refined {} (results in {}): {e}", stamp::show_path(&p.path), times(level), stamp::show_path(&dir)));
                let message = e.to_string();
                let status = if crate::run::interrupt::received().is_some() { "interrupted" } else { "failed" };
                edit_summary(&out_dir, |v| {
                    v["status"] = json!(status);
                    v["error"] = json!(message);
                    v["refinement"] = refinement(format!("{status}: the mesh refined {}", times(level)), &meshes);
                })?;
                return Err(e);
            }
        }
    }

    let q = quantities(&coarse.history, &force_driven, &units);
    let rep = Report::new(&coarse.history, &fines, q).map_err(StampError::Problem);
    let rep = match rep {
        Ok(r) => r,
        Err(e) => {
            let message = e.to_string();
            edit_summary(&out_dir, |v| {
                v["status"] = json!("failed");
                v["error"] = json!(message);
                v["refinement"] = refinement("failed".into(), &meshes);
            })?;
            return Err(e);
        }
    };
    crate::run::parallel::on_writer(|| write_string_atomically(&out_dir.join("history.csv"), &rep.csv(&coarse.history)))?;
    let mut object = refinement("converged".into(), &meshes);
    object["order"] = json!(rep.assumed_order());
    object["quantities"] = json!(rep.quantities.iter().map(|q| q.key.clone()).collect::<Vec<_>>());
    object["steps"] = rep.json_steps(&coarse.history);
    let seconds = start.elapsed().as_secs_f64();
    edit_summary(&out_dir, |v| {
        v["status"] = json!("converged");
        v["refinement"] = object;
        v["refinement"]["seconds"] = json!(seconds);
    })?;
    if !quiet && crate::run::parallel::writes_outputs() {
        crate::out!("{}", crate::outputs::table::render(&coarse.history, &units));
        crate::out!("{}", rep.tables(&coarse.history));
        crate::outln!("{}", explanation(levels));
    }
    Ok(RunOutcome { files, ..coarse })
}

/// The lines under the tables that say how to read the estimate (each under 100 characters).
pub fn explanation(levels: usize) -> String {
    let error = "error %: each run's estimated error, 100 (F - estimate) / |estimate|.";
    if levels == 1 {
        format!(
            "\nrefined: the same steps on the mesh refined once (each cell into 4).\n\
             estimate: Richardson extrapolation F_refined + (F_refined - F) / (2^p - 1), p = {} assumed\n\
             (the element's order); contact forces on coarse meshes often converge more slowly, p = 1 .. 1.5,\n\
             and their error can then be up to about 1.6 times the estimated one: --refine 2 observes p.\n{error}",
            crate::refine::richardson::ASSUMED_ORDER
        )
    } else {
        format!(
            "\nrefined, refined 2, ...: the same steps on the mesh refined once, twice, ... (each cell into 4).\n\
             estimate: Richardson extrapolation of the two finest with the order observed on the last three\n\
             (the assumed p = {} where the observed one is not between {} and {}).\n{error}",
            crate::refine::richardson::ASSUMED_ORDER,
            crate::refine::richardson::MIN_OBSERVED,
            crate::refine::richardson::MAX_OBSERVED
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_number_after_refine_is_its_value() {
        let args = |v: &[&str]| v.iter().map(std::ffi::OsString::from).collect::<Vec<_>>();
        assert_eq!(join_refine_value(args(&["stamp", "run", "--refine", "2", "a.toml"])), args(&["stamp", "run", "--refine=2", "a.toml"]));
        assert_eq!(join_refine_value(args(&["stamp", "run", "--refine", "a.toml"])), args(&["stamp", "run", "--refine", "a.toml"]));
        assert_eq!(join_refine_value(args(&["stamp", "run", "a.toml", "--refine"])), args(&["stamp", "run", "a.toml", "--refine"]));
        assert_eq!(join_refine_value(args(&["stamp", "run", "--refine", "17", "a.toml"])), args(&["stamp", "run", "--refine=17", "a.toml"]));
        assert_eq!(join_refine_value(args(&["stamp", "run", "--out", "2", "a.toml"])), args(&["stamp", "run", "--out", "2", "a.toml"]));
    }

    #[test]
    fn a_refinement_beyond_memory_is_refused_before_the_solve() {
        const GIB: f64 = 1024.0 * 1024.0 * 1024.0;
        // 100 x 100 cells: 10201 nodes, 20200 edges; refined: 40401, 160801, 641601 nodes
        let mesh = stamp::mesh::QuadMesh::rectangle(0.0, 1.0, 0.0, 1.0, 100, 100).unwrap();
        let sizes = stamp::mesh::refine::refined_sizes(&mesh, 3);
        assert_eq!(sizes.iter().map(|s| s.0).collect::<Vec<_>>(), [201 * 201, 401 * 401, 801 * 801]);
        // estimates: 1.44, 6.13 and 26.8 GiB
        assert!(check_levels_fit(&sizes, 3, 6, Some(64.0 * GIB)).is_ok());
        assert!(check_levels_fit(&sizes[..2], 2, 6, Some(10.0 * GIB)).is_ok());
        let e = check_levels_fit(&sizes, 3, 6, Some(10.0 * GIB)).unwrap_err();
        assert!(e.contains("--refine 3: the mesh refined 3 times: the model has 641601 nodes") && e.contains("use --refine 2"), "{e}");
        let e = check_levels_fit(&sizes[..1], 1, 6, Some(1.0 * GIB)).unwrap_err();
        assert!(e.contains("refined once") && e.contains("solve without --refine"), "{e}");
    }
}

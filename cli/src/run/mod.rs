//! `stamp run`: problem files, the generic solve pipeline and its outputs.
//!
//! * [`problem`]: the TOML schema (serde, `deny_unknown_fields`) and its checks;
//! * [`mesh`]: the gmsh mesh or the built-in rectangle, with groups by dimension;
//! * [`build`]: section, plate elements, constraints, loads, punches, solver settings;
//! * [`solve`]: Newton-Raphson along the targets with a progress bar, writing every step;
//! * [`output`]: the .vtu fields, summary.json entries and contact CSV of a step;
//! * [`plot`]: PNG/SVG line plots (contact pressure here, the paper's Figure 4 in [`crate::paper`]).

pub mod build;
pub mod mesh;
pub mod output;
pub mod plot;
pub mod problem;
pub mod solve;

pub use problem::Problem;
pub use solve::{default_out_dir, RunOutcome};

use std::path::Path;

/// Read, build, solve and write the problem file `problem` into `out` (default
/// `<problem dir>/<problem stem>-out`). On a Newton failure the converged steps are written and the
/// error is returned.
pub fn run(problem: &Path, out: Option<&Path>, quiet: bool) -> stamp::Result<RunOutcome> {
    let p = Problem::read(problem)?;
    let setup = build::build(&p)?;
    let out_dir = out.map(|o| o.to_path_buf()).unwrap_or_else(|| default_out_dir(problem));
    solve::solve_and_write(&p, setup, &out_dir, quiet)
}

/// Run the problem file `problem`, writing into `out`.
pub fn run_command(problem: &Path, out: Option<&Path>, quiet: bool) -> stamp::Result<()> {
    let outcome = run(problem, out, quiet)?;
    if !quiet {
        println!(
            "stamp run: {} converged steps; results in {} (summary.json, .pvd/.vtu, CSV)",
            outcome.converged_steps,
            outcome.out_dir.display()
        );
    }
    Ok(())
}

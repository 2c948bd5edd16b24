//! `stamp run` and `stamp check`: the problem-file library ([`stamp_problem`]) with what the
//! program prints around it.

use std::path::Path;

/// `stamp check`: read and build the problem file, run the checks, print the model's summary on
/// stdout and the warnings on stderr; an error is returned as it is.
pub fn check_command(problem: &Path) -> stamp::Result<()> {
    let p = stamp_problem::Problem::read(problem)?;
    let setup = stamp_problem::build::build(&p)?;
    let report = stamp_problem::check::check(&p, &setup)?;
    stamp_problem::outln!("{}", report.summary);
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    stamp_problem::outln!("check: no errors{}", match report.warnings.len() {
        0 => String::new(),
        1 => ", 1 warning".into(),
        n => format!(", {n} warnings"),
    });
    Ok(())
}

/// Run the problem file `problem`, writing into `out`; with `refine` = Some(levels) also on the mesh
/// refined `levels` times (see [`stamp_problem::refine`]).
pub fn run_command(problem: &Path, out: Option<&Path>, quiet: bool, refine: Option<usize>) -> stamp::Result<()> {
    let outcome = match refine {
        None => stamp_problem::run(problem, out, quiet)?,
        Some(levels) => stamp_problem::refine::run_refined(problem, out, quiet, levels)?,
    };
    if !quiet {
        let refined = match refine {
            Some(1) => format!("; the refined mesh's in {}", outcome.out_dir.join(stamp_problem::refine::level_folder(1)).display()),
            Some(n) => format!("; the refined meshes' in {} ... {}", outcome.out_dir.join(stamp_problem::refine::level_folder(1)).display(), stamp_problem::refine::level_folder(n)),
            None => String::new(),
        };
        stamp_problem::outln!(
            "stamp run: {} converged steps; results in {} (summary.json, .pvd/.vtu, CSV){refined}",
            outcome.converged_steps,
            outcome.out_dir.display()
        );
    }
    Ok(())
}


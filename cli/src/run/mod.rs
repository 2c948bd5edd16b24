//! `stamp run`: problem files, the generic solve pipeline and its outputs.
//!
//! * [`problem`]: the TOML schema (serde, `deny_unknown_fields`) and its checks;
//! * [`mesh`]: the gmsh mesh or the built-in rectangle, with groups by dimension;
//! * [`build`]: section, plate elements, constraints, loads, punches, solver settings;
//! * [`check`]: what is wrong with a built problem, said before the solve (`stamp check`), with
//!   [`rigid_modes`] (rigid motions held by nothing) and [`punch_start`] (gaps at the start);
//! * [`out_dir`]: a run owns its output folder (removes the previous run's files, only those);
//! * [`solve`]: Newton-Raphson along the targets with a progress bar, writing every step;
//! * [`output`]: the .vtu fields, summary.json entries and contact CSV of a step;
//! * [`plot`]: PNG/SVG line plots (contact pressure, the paper's Figure 4).

pub mod build;
pub mod check;
pub mod history;
pub mod memory;
pub mod mesh;
pub mod out_dir;
pub mod output;
pub mod plot;
pub mod probe;
pub mod problem;
pub mod punch_start;
pub mod rigid_modes;
pub mod solve;
pub mod table;
pub mod units;

pub use problem::Problem;
pub use solve::{default_out_dir, RunOutcome};

use crate::paper::{solve_strip, StripProblem};
use plot::{write_plot, Plot, Series};
use stamp::io::write_string_atomically;
use stamp::StampError;
use stamp_elements::Kinematics;
use std::path::Path;

/// Read, build, check, solve and write the problem file `problem` into `out` (default
/// `<problem dir>/<problem stem>-out`). The checks of [`check::check`] come first: an error stops
/// the run before anything is written, warnings go to stderr (also with `quiet`), and so does,
/// after the run, a warning for every punch that never touched the plate. On a Newton failure the
/// converged steps are written and the error is returned.
pub fn run(problem: &Path, out: Option<&Path>, quiet: bool) -> stamp::Result<RunOutcome> {
    let p = Problem::read(problem)?;
    let setup = build::build(&p)?;
    let report = check::check(&p, &setup)?;
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    let out_dir = out.map(|o| o.to_path_buf()).unwrap_or_else(|| default_out_dir(problem));
    let outcome = solve::solve_and_write(&p, setup, &out_dir, quiet);
    for w in check::never_touched(&p, &out_dir.join("summary.json")) {
        eprintln!("warning: {w}");
    }
    outcome
}

/// `stamp check`: read and build the problem file, run the checks, print the model's summary on
/// stdout and the warnings on stderr; an error is returned as it is.
pub fn check_command(problem: &Path) -> stamp::Result<()> {
    let p = Problem::read(problem)?;
    let setup = build::build(&p)?;
    let report = check::check(&p, &setup)?;
    println!("{}", report.summary);
    for w in &report.warnings {
        eprintln!("warning: {w}");
    }
    println!("check: no errors{}", match report.warnings.len() {
        0 => String::new(),
        1 => ", 1 warning".into(),
        n => format!(", {n} warnings"),
    });
    Ok(())
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

/// The load parameters P~ = 16 P R^2 / (E h) of the redrawn Figure 4.
pub const FIGURE4_LOADS: [f64; 7] = [1.0, 2.0, 5.0, 10.0, 20.0, 40.0, 80.0];

/// Redraw the paper's Figure 4 into `dir`: the dimensionless contact pressure
/// q~ = 16 q_n R^2 l / (E h^3) along the deformed plate against the deformed x2, for the load
/// parameters [`FIGURE4_LOADS`] (R = 100, nonlinear), as figure4.png, figure4.svg and figure4.csv.
pub fn plot_paper_figure4(dir: &Path) -> stamp::Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| StampError::io(dir, e))?;
    let problem = StripProblem::paper(100.0, Kinematics::Nonlinear);
    let (e, h, r, l) = (problem.young, problem.thickness, problem.radius, problem.half_length);
    let loads: Vec<f64> = FIGURE4_LOADS.iter().map(|pt| pt * e * h / (16.0 * r * r)).collect();
    let results = solve_strip(&problem, &loads)?;
    let scale = 16.0 * r * r * l / (e * h * h * h);
    let mut csv = String::from("P_tilde,P_per_end,x2,x2_deformed,x3_deformed,q_n,q_tilde\n");
    let mut series = Vec::new();
    for (pt, res) in FIGURE4_LOADS.iter().zip(&results) {
        let mut pts = Vec::new();
        for k in 0..res.x2.len() {
            let q = res.pressure[k];
            csv.push_str(&format!("{pt},{:e},{:e},{:e},{:e},{:e},{:e}\n", res.load_per_end, res.x2[k], res.deformed[k][0], res.deformed[k][1], q, scale * q));
            pts.push((res.deformed[k][0], scale * q));
        }
        series.push(Series { label: format!("P~ = {pt}"), points: pts, markers: Vec::new() });
    }
    write_string_atomically(&dir.join("figure4.csv"), &csv)?;
    let plot = Plot {
        title: "Figure 4: contact pressure along the deformed plate (R = 100)",
        x_label: "deformed x2 (mm)",
        y_label: "q~ = 16 q_n R^2 l / (E h^3)",
        series: &series,
    };
    write_plot(&dir.join("figure4"), &plot)?;
    Ok(())
}

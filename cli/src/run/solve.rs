//! Driving the solve: Newton-Raphson along the load targets, a progress bar, and the outputs of
//! every converged step written as soon as it converges (so a failure keeps what converged).

use super::build::Setup;
use super::output::{contact_csv, step_data, Context};
use super::plot::{write_plot, Plot, Series};
use super::problem::{PlotAxis, Problem};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use stamp::io::{write_pvd, write_string_atomically, write_vtu};
use stamp::linalg::bordered::BorderedSolver;
use stamp::nonlinear::{NewtonRaphson, NonlinearProblem, NonlinearSolver};
use stamp::{Result, StampError};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// What a run produced.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    pub out_dir: PathBuf,
    pub summary: PathBuf,
    pub converged_steps: usize,
    pub files: Vec<PathBuf>,
}

#[derive(Serialize)]
struct PunchMeta {
    name: String,
    surface: String,
    face: String,
    motion: [f64; 3],
    /// Force-driven punches: the force at load factor 1 and its direction.
    force: Option<f64>,
    direction: Option<[f64; 3]>,
    eps_reg: f64,
    /// Augmented-Lagrangian tolerance on the penetration (null: plain perturbed Lagrangian).
    penetration_tolerance: Option<f64>,
    eps_reg_automatic: bool,
    candidate_nodes: usize,
}

#[derive(Serialize)]
struct Summary {
    problem: String,
    title: Option<String>,
    /// "running" while the solve goes on, then "converged" or "failed".
    status: String,
    error: Option<String>,
    nodes: usize,
    cells: usize,
    equations: usize,
    thickness: f64,
    delta_minus: f64,
    delta_plus: f64,
    targets: Vec<f64>,
    punches: Vec<PunchMeta>,
    loaded_threshold: f64,
    newton_iterations: usize,
    seconds: f64,
    point_arrays: Vec<String>,
    cell_arrays: Vec<String>,
    /// One entry per converged load step; a failure adds a last entry with converged = false.
    steps: Vec<serde_json::Value>,
}

/// The progress bar: the load path along the bar, Newton iteration and residual in the message.
/// Without a terminal (and without --quiet) one terse line per converged step on stderr.
struct Progress {
    bar: Option<ProgressBar>,
    terse: bool,
    state: Arc<Mutex<(usize, f64)>>,
    /// Total path length sum |delta t| over the targets.
    path_end: f64,
}

impl Progress {
    fn new(visible: bool, terse: bool, path_end: f64) -> Progress {
        let bar = visible.then(|| {
            let b = ProgressBar::with_draw_target(Some(1000), ProgressDrawTarget::stderr());
            b.set_style(
                ProgressStyle::with_template("{elapsed_precise} [{bar:30}] load {percent:>3}% {msg}")
                    .unwrap_or_else(|_| ProgressStyle::default_bar())
                    .progress_chars("=> "),
            );
            b
        });
        Progress { bar, terse: terse && !visible, state: Arc::new(Mutex::new((0, 0.0))), path_end }
    }

    fn callback(&self) -> Option<Box<dyn FnMut(usize, f64, f64)>> {
        let bar = self.bar.clone()?;
        let state = self.state.clone();
        Some(Box::new(move |it, r, scale| {
            let (step, t) = *state.lock().unwrap();
            let rel = if scale > 0.0 { r / scale } else { r };
            bar.set_message(format!("step {} from t = {t:.4}: Newton iteration {it}, |R| = {r:.2e} (relative {rel:.1e})", step + 1));
        }))
    }

    fn step(&self, step: usize, t: f64, path: f64, iterations: usize, active: usize, penetration: f64) {
        *self.state.lock().unwrap() = (step, t);
        let msg = format!("step {step} converged at t = {t:.4} in {iterations} iterations, {active} nodes in contact, max penetration {penetration:.2e}");
        if let Some(b) = &self.bar {
            b.set_position(((path / self.path_end) * 1000.0).round().clamp(0.0, 1000.0) as u64);
            b.set_message(msg);
        } else if self.terse {
            eprintln!("{msg}");
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}

fn json_err(e: serde_json::Error) -> StampError {
    StampError::Problem(format!("cannot encode summary.json: {e}"))
}

/// The default output folder: `<problem dir>/<problem stem>-out`.
pub fn default_out_dir(problem: &Path) -> PathBuf {
    let stem = problem.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "problem".into());
    let dir = problem.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    dir.join(format!("{stem}-out"))
}

/// Solve the problem and write every output into `out_dir`.
pub fn solve_and_write(p: &Problem, setup: Setup, out_dir: &Path, quiet: bool) -> Result<RunOutcome> {
    let start = Instant::now();
    std::fs::create_dir_all(out_dir).map_err(|e| StampError::io(out_dir, e))?;
    let Setup { mesh, mut model, section, punches, targets, settings } = setup;
    let out = &p.spec.output;
    let stem = p.path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "step".into());
    let path_end = targets.iter().fold((0.0, 0.0), |(len, last), &t| (len + (t - last).abs(), t)).0.max(f64::MIN_POSITIVE);

    // point groups reported in summary.json: named ones, and numbered ones without a name
    let mut point_groups: Vec<(String, Vec<usize>)> = mesh.points.iter().filter(|(k, _)| !k.starts_with('#')).map(|(k, v)| (k.clone(), v.clone())).collect();
    for (k, v) in mesh.points.iter().filter(|(k, _)| k.starts_with('#')) {
        if !point_groups.iter().any(|(_, w)| w == v) {
            point_groups.push((k.clone(), v.clone()));
        }
    }

    // plot abscissa of every node (None: not plotted)
    let mut axis: Vec<Option<f64>> = vec![None; mesh.mesh.num_nodes()];
    let (axis_label, plot_nodes): (String, Option<Vec<usize>>) = match (&out.plot_group, out.plot_axis) {
        (Some(g), PlotAxis::Arc) => {
            let chain = mesh.curve_chain(g.get_ref()).ok_or_else(|| super::mesh::group_error(p, g.span(), "output.plot_group", g.get_ref(), "curve", &mesh))?;
            for &(n, s) in &chain {
                axis[n] = Some(s);
            }
            (format!("arc length along '{}' (reference)", g.get_ref()), Some(chain.iter().map(|c| c.0).collect()))
        }
        (g, a) => {
            let c = if a == PlotAxis::X1 { 0 } else { 1 };
            let nodes = match g {
                Some(g) => Some(mesh.nodes(g.get_ref()).ok_or_else(|| super::mesh::group_error(p, g.span(), "output.plot_group", g.get_ref(), "", &mesh))?),
                None => None,
            };
            for n in nodes.clone().unwrap_or_else(|| (0..mesh.mesh.num_nodes()).collect()) {
                axis[n] = Some(mesh.mesh.coords[n][c]);
            }
            (format!("reference x{}", c + 1), nodes)
        }
    };
    let _ = plot_nodes;

    let mut summary = Summary {
        problem: p.path.display().to_string(),
        title: p.spec.title.clone(),
        status: "running".into(),
        error: None,
        nodes: mesh.mesh.num_nodes(),
        cells: mesh.mesh.num_cells(),
        equations: model.dofs.num_equations(),
        thickness: section.thickness(),
        delta_minus: section.delta_minus,
        delta_plus: section.delta_plus,
        targets: targets.clone(),
        punches: punches
            .iter()
            .zip(&model.contacts)
            .map(|(i, c)| PunchMeta {
                name: i.name.clone(),
                surface: i.surface.describe(),
                face: format!("{:?}", i.face).to_lowercase(),
                motion: c.motion,
                force: c.drive.map(|f| f.force),
                direction: c.drive.map(|f| f.direction),
                eps_reg: i.eps_reg,
                penetration_tolerance: model.augmented_tolerance,
                eps_reg_automatic: i.eps_automatic,
                candidate_nodes: c.points.len(),
            })
            .collect(),
        loaded_threshold: out.loaded_threshold.0,
        newton_iterations: 0,
        seconds: 0.0,
        point_arrays: super::output::POINT_ARRAYS.iter().filter(|n| **n != "gap" || !punches.is_empty()).map(|s| s.to_string()).collect(),
        cell_arrays: super::output::CELL_ARRAYS.iter().map(|s| s.to_string()).collect(),
        steps: Vec::new(),
    };
    let summary_path = out_dir.join("summary.json");
    let pvd_path = out_dir.join(format!("{stem}.pvd"));
    let mut pvd: Vec<(f64, String)> = Vec::new();
    let mut files: Vec<PathBuf> = Vec::new();
    // per punch: (label, points) of every written step, for the plot
    let mut plot_data: Vec<Vec<Series>> = punches.iter().map(|_| Vec::new()).collect();
    let mut write_error: Option<StampError> = None;
    let mut total_iterations = 0;

    let cx = Context { mesh: &mesh, punches: &punches, section: &section, threshold: out.loaded_threshold.0, point_groups: &point_groups };
    let progress = Progress::new(!quiet && std::io::stderr().is_terminal() && std::io::stdout().is_terminal(), !quiet, path_end);
    // force-driven punches border the system: block elimination keeps the sparse LU on the nodal part
    let mut newton = NewtonRaphson::new(BorderedSolver::new(model.num_drives()), settings);
    newton.on_iteration = progress.callback();
    let mut u = vec![0.0; model.num_dofs()];
    let (mut path_len, mut t_last) = (0.0, 0.0);
    let result = newton.solve_path(&mut model, &mut u, 0.0, &targets, &mut |rep, u, m| {
        total_iterations += rep.iterations;
        let t = rep.load_factor;
        path_len += (t - t_last).abs();
        t_last = t;
        let penetration = m.contacts.iter().map(|c| c.max_penetration()).fold(0.0, f64::max);
        let active = m.contacts.iter().map(|c| c.state.iter().filter(|s| s.active).count()).sum();
        progress.step(rep.step, t, path_len, rep.iterations, active, penetration);
        if write_error.is_some() || !(out.every_step || rep.is_target) {
            return;
        }
        let mut data = step_data(&cx, m, u, t, path_len, rep);
        let step_result: Result<()> = (|| {
            if out.vtu {
                let name = format!("{stem}_{:04}.vtu", rep.step);
                let path = out_dir.join(&name);
                write_vtu(&path, &mesh.mesh, &data.point_fields, &data.cell_fields)?;
                files.push(path);
                // the .pvd time is the path length: it increases when the load goes down again
                pvd.push((path_len, name.clone()));
                write_pvd(&pvd_path, &pvd)?;
                data.entry.vtu = Some(name);
            }
            for (k, info) in punches.iter().enumerate() {
                let mut rows = data.punch_rows[k].clone();
                rows.sort_by(|a, b| {
                    let ka = (axis[a.node].unwrap_or(f64::INFINITY), a.x[1], a.x[0]);
                    let kb = (axis[b.node].unwrap_or(f64::INFINITY), b.x[1], b.x[0]);
                    ka.partial_cmp(&kb).unwrap_or(std::cmp::Ordering::Equal)
                });
                if out.csv {
                    let name = format!("pressure_{}_{:04}.csv", info.name, rep.step);
                    let path = out_dir.join(&name);
                    write_string_atomically(&path, &contact_csv(&rows))?;
                    files.push(path);
                    data.entry.csv.push(name);
                }
                if out.plot {
                    let pts: Vec<(f64, f64)> = rows.iter().filter_map(|r| axis[r.node].map(|s| (s, r.q_n))).collect();
                    plot_data[k].push(Series { label: format!("t = {t:.4}"), points: pts });
                }
            }
            summary.steps.push(serde_json::to_value(&data.entry).map_err(json_err)?);
            summary.newton_iterations = total_iterations;
            summary.seconds = start.elapsed().as_secs_f64();
            write_string_atomically(&summary_path, &serde_json::to_string_pretty(&summary).map_err(json_err)?)
        })();
        if let Err(e) = step_result {
            write_error = Some(e);
        }
    });
    progress.finish();
    drop(cx);
    if let Some(e) = write_error {
        return Err(e);
    }
    summary.newton_iterations = total_iterations;
    summary.seconds = start.elapsed().as_secs_f64();
    let failure = result.err();
    match &failure {
        None => summary.status = "converged".into(),
        Some(e) => {
            summary.status = "failed".into();
            summary.error = Some(e.to_string());
            let lf = match e {
                StampError::NoConvergence { load_factor, .. } => Some(*load_factor),
                _ => None,
            };
            summary.steps.push(serde_json::json!({
                "load_factor": lf,
                "converged": false,
                "error": e.to_string(),
            }));
        }
    }
    write_string_atomically(&summary_path, &serde_json::to_string_pretty(&summary).map_err(json_err)?)?;
    files.push(summary_path.clone());
    if out.vtu {
        write_pvd(&pvd_path, &pvd)?;
        files.push(pvd_path);
    }
    if out.plot {
        for (k, info) in punches.iter().enumerate() {
            let mut series = std::mem::take(&mut plot_data[k]);
            // at most 10 curves: keep them evenly spread, always the last
            if series.len() > 10 {
                let n = series.len();
                let keep: Vec<usize> = (0..10).map(|i| (i * (n - 1)) / 9).collect();
                series = series.into_iter().enumerate().filter(|(i, _)| keep.contains(i)).map(|(_, s)| s).collect();
            }
            let title = format!("contact pressure under '{}'", info.name);
            let plot = Plot { title: &title, x_label: &axis_label, y_label: "contact pressure q_n", series: &series };
            files.extend(write_plot(&out_dir.join(format!("pressure_{}", info.name)), &plot)?);
        }
    }
    let converged_steps = summary.steps.iter().filter(|s| s["converged"] == serde_json::Value::Bool(true)).count();
    match failure {
        Some(e) => Err(e),
        None => Ok(RunOutcome { out_dir: out_dir.to_path_buf(), summary: summary_path, converged_steps, files }),
    }
}

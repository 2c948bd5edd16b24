//! Driving the solve: Newton-Raphson along the load targets, a progress bar, and the outputs of
//! every converged step written as soon as it converges (so a failure keeps what converged).

use crate::model::build::Setup;
use crate::model::plate_model::Layout;
use crate::outputs::history::History;
use crate::outputs::output::{contact_csv, step_data, Context};
use crate::outputs::probe::Probes;
use crate::schema::units::Units;
use crate::schema::{PlotAxis, Problem};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use serde_json::Value;
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
    /// The steps summary.json lists as converged (0 on the ranks that write nothing, see
    /// [`crate::run::parallel::writes_outputs`]).
    pub converged_steps: usize,
    /// The files written (none on the ranks that write nothing).
    pub files: Vec<PathBuf>,
    /// The converged steps' punch forces, travels and deflections.
    pub history: History,
    /// The converged states (load factor, unknowns) of every step, with
    /// [`SolveOptions::record_states`] (empty otherwise).
    pub states: Vec<(f64, Vec<f64>)>,
    /// The mesh and the written steps' results, with [`SolveOptions::keep`].
    pub kept: Option<crate::run::kept::Kept>,
}

/// How [`solve_and_write`] runs beyond the problem file.
#[derive(Debug, Clone, Default)]
pub struct SolveOptions {
    /// No progress bar, no table.
    pub quiet: bool,
    /// Leave the end-of-run table of a converged run to the caller (who prints its own); a failed
    /// run prints its table of the converged steps all the same.
    pub no_table: bool,
    /// Pass through exactly these load factors instead of the problem's targets (every one is a
    /// target: the outputs are written at each).
    pub targets: Option<Vec<f64>>,
    /// summary.json's "refinement" object while the run goes on.
    pub refinement: Option<Value>,
    /// The caller finishes summary.json after a converged run: its status stays "running".
    pub caller_finishes: bool,
    /// Keep every converged state in [`RunOutcome::states`].
    pub record_states: bool,
    /// Start every load step from this run's solution (interpolated onto this mesh) instead of
    /// the secant predictor; it takes precedence over `[solver] predictor = "coarse"`, whose
    /// coarse setup is then not solved.
    pub previous: Option<crate::model::coarse::PreviousLevel>,
    /// Keep the mesh and every written step's results in [`RunOutcome::kept`].
    pub keep: bool,
    /// The flag that stops the solve, set by the caller's own handler
    /// ([`crate::run::interrupt::install_chained`]); None: the program's handlers for SIGINT and
    /// SIGTERM are installed ([`crate::run::interrupt::install`]).
    pub interrupt: Option<Arc<std::sync::atomic::AtomicBool>>,
}

#[derive(Serialize)]
struct PunchMeta {
    name: String,
    surface: String,
    face: String,
    /// The prescribed displacement at load factor 1.
    motion: [f64; 3],
    /// A motion along a path: its points [t, d1, d2, d3] (starting at [0, 0, 0, 0]).
    #[serde(skip_serializing_if = "Option::is_none")]
    motion_path: Option<Vec<[f64; 4]>>,
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
    /// The processes the run solved on (`mpirun -n P`; 1 without MPI).
    ranks: usize,
    /// The linear solver of the Newton iterations (see parallel.rs).
    linear_solver: String,
    problem: String,
    title: Option<String>,
    /// "running" while the solve goes on, then "converged" or "failed" (any error, a failed write
    /// of an output file included). A "running" summary whose `pid` no longer runs was killed.
    status: String,
    error: Option<String>,
    /// The process that writes this folder, and when it started (RFC 3339, UTC).
    pid: u32,
    started: String,
    nodes: usize,
    cells: usize,
    equations: usize,
    /// Surfaces through the thickness: `[plate] surfaces`, 2 (the paper's plate) to 5; with
    /// layers, all of them (L (N - 1) + 1).
    surfaces: usize,
    /// With `[plate] layers`: the stack from the bottom up (x3 of each layer's faces, its
    /// material's name, angle and surfaces); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    layers: Option<Value>,
    thickness: f64,
    delta_minus: f64,
    delta_plus: f64,
    targets: Vec<f64>,
    punches: Vec<PunchMeta>,
    loaded_threshold: f64,
    newton_iterations: usize,
    /// Newton iterations of the attempts cut back before the converged steps (not in
    /// `newton_iterations`).
    failed_iterations: usize,
    seconds: f64,
    point_arrays: Vec<String>,
    cell_arrays: Vec<String>,
    /// `[solver] predictor = "coarse"`: what the coarse solve cost (see model/coarse.rs); absent
    /// otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    coarse_predictor: Option<crate::model::coarse::CoarseReport>,
    /// `stamp run --refine`: the meshes and the estimates (see refine/mod.rs); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    refinement: Option<Value>,
    /// One entry per converged load step whose files were all written (the .pvd lists the same
    /// steps); a Newton failure adds a last entry with converged = false.
    steps: Vec<serde_json::Value>,
}

/// `time` as RFC 3339 in UTC to the second ("2026-11-24T17:48:33Z").
pub fn rfc3339_utc(time: std::time::SystemTime) -> String {
    let secs = time.duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0) as i64;
    let (days, rem) = (secs.div_euclid(86_400), secs.rem_euclid(86_400));
    // civil date from days since 1970-01-01 (H. Hinnant's algorithm)
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}Z", rem / 3600, rem % 3600 / 60, rem % 60)
}

/// Write summary.json and return its size; an error says that it was summary.json that could not
/// be written, and what had gone wrong before (`earlier`), if anything.
fn write_summary(path: &Path, summary: &Summary, earlier: Option<&StampError>) -> Result<usize> {
    let text = serde_json::to_string_pretty(summary).map_err(json_err)?;
    write_string_atomically(path, &text).map(|()| text.len()).map_err(|e| {
        let kind = match &e {
            StampError::Io { source, .. } => source.kind(),
            _ => std::io::ErrorKind::Other,
        };
        let cause = match &e {
            StampError::Io { source, .. } => source.to_string(),
            e => e.to_string(),
        };
        let message = match earlier {
            Some(first) => format!("cannot write summary.json ({cause}) after the run failed: {first}"),
            None => format!("cannot write summary.json: {cause}"),
        };
        StampError::Io { path: path.display().to_string(), source: std::io::Error::new(kind, message) }
    })
}

/// Write the final summary.json: as usual; if that fails (a full disk), again once the reserve
/// ([`crate::run::reserve`]) gave its space back; if that fails too, the summary.json of the run so far
/// (which says "running") is removed, so that none says what is no longer true, and a compact one
/// is tried in its place. The error, if any, says what became of summary.json.
fn write_final_summary(path: &Path, summary: &Summary, earlier: Option<&StampError>, reserve: &mut crate::run::reserve::Reserve) -> Result<()> {
    let first = match write_summary(path, summary, earlier) {
        Ok(_) => return Ok(()),
        Err(e) => e,
    };
    if reserve.release() && write_summary(path, summary, earlier).is_ok() {
        return Ok(());
    }
    let removed = std::fs::remove_file(path).is_ok();
    if let Ok(text) = serde_json::to_string(summary) {
        if write_string_atomically(path, &text).is_ok() {
            return Ok(());
        }
    }
    let tail = if removed { "; the summary.json of the run so far (status \"running\") was removed" } else { "" };
    Err(match first {
        StampError::Io { path, source } => StampError::Io { path, source: std::io::Error::new(source.kind(), format!("{source}{tail}")) },
        e => StampError::Problem(format!("{e}{tail}")),
    })
}

/// summary.json as it would be if the process aborted now: "failed", with the steps listed so far.
fn aborted(summary: &Summary) -> String {
    let mut v = serde_json::to_value(summary).unwrap_or_default();
    let steps = summary.steps.len();
    v["status"] = "failed".into();
    v["error"] = format!(
        "the process aborted (SIGABRT) after the {steps} steps listed here were written: most likely an allocation failed (out of memory), see stderr"
    )
    .into();
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// The error of an interrupted run as summary.json says it: "interrupted by SIGINT (Ctrl-C) after
/// load step ...".
fn interrupted_message(e: &StampError, signal: Option<i32>) -> String {
    let by = signal.map(|s| format!("interrupted by {}", crate::run::interrupt::name(s))).unwrap_or_else(|| "interrupted".into());
    e.to_string().replacen("interrupted", &by, 1)
}

/// summary.json as it would be if `signal` ended the run now, after `steps` converged steps (the
/// last at `load_factor`): "interrupted", with the steps listed so far.
fn interrupted(summary: &Summary, signal: i32, steps: usize, load_factor: f64) -> String {
    let mut v = serde_json::to_value(summary).unwrap_or_default();
    v["status"] = "interrupted".into();
    v["error"] = interrupted_message(&StampError::Interrupted { steps, load_factor }, Some(signal)).into();
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

/// Keep summary.json's notes ready (see abort_note.rs) after `steps` converged steps, the last at
/// `load_factor`: "failed" for an abort, "interrupted" for SIGINT and SIGTERM.
fn prepare_notes(note: Option<&crate::run::abort_note::AbortNote>, path: &Path, summary: &Summary, steps: usize, load_factor: f64) {
    if let Some(note) = note {
        note.prepare(path, aborted(summary), |signal| interrupted(summary, signal, steps, load_factor));
    }
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

    /// `forces`: the punches' forces and travels, appended to the terse line.
    fn step(&self, rep: &stamp::nonlinear::StepReport, path: f64, active: usize, penetration: f64, forces: &str) {
        let (step, t, iterations) = (rep.step, rep.load_factor, rep.iterations);
        *self.state.lock().unwrap() = (step, t);
        // a step cut back says so, with the iterations of its failed attempts
        let cut = match rep.cutbacks {
            0 => String::new(),
            c => format!(" (after {c} cut-back{}, {} iterations in the failed attempts)", if c == 1 { "" } else { "s" }, rep.failed_iterations),
        };
        if let Some(b) = &self.bar {
            b.set_position(((path / self.path_end) * 1000.0).round().clamp(0.0, 1000.0) as u64);
            b.set_message(format!("step {step} converged at t = {t:.4} in {iterations} iterations{cut}, {active} nodes in contact, max penetration {penetration:.2e}"));
        } else if self.terse {
            eprintln!("step {step} converged at t = {t:.4} in {iterations} iterations{cut}, {active} nodes in contact{forces}, max penetration {penetration:.2e}");
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.bar {
            // the last state stays on the terminal
            b.finish();
        }
    }
}

fn json_err(e: serde_json::Error) -> StampError {
    StampError::Problem(format!("cannot encode summary.json: {e}"))
}

/// The default output folder: `<problem dir>/<problem stem>-out`.
/// The first punch whose surface reports a non-finite evaluation, as an error at its `psi` key.
/// Collective under MPI: each rank evaluates its own contact points, so a failure one rank saw is
/// told on every rank.
fn surface_failure(p: &Problem, contacts: &[stamp::contact::ContactPair]) -> Option<StampError> {
    crate::run::parallel::agree(own_surface_failure(p, contacts).map_or(Ok(()), Err)).err()
}

fn own_surface_failure(p: &Problem, contacts: &[stamp::contact::ContactPair]) -> Option<StampError> {
    contacts.iter().enumerate().find_map(|(i, c)| {
        let m = c.surface.evaluation_error()?;
        let key = format!("punch[{i}].psi");
        Some(match p.spec.punch.get(i).and_then(|s| s.get_ref().psi.as_ref()) {
            Some(psi) => p.error_at(psi.span(), &key, m),
            None => StampError::Input { file: p.path.display().to_string(), message: format!("punch[{i}]: {m}") },
        })
    })
}

pub fn default_out_dir(problem: &Path) -> PathBuf {
    let stem = problem.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "problem".into());
    let dir = problem.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    dir.join(format!("{stem}-out"))
}

/// Solve the problem and write every output into `out_dir`.
pub fn solve_and_write(p: &Problem, setup: Setup, out_dir: &Path, opts: &SolveOptions) -> Result<RunOutcome> {
    let quiet = opts.quiet;
    let start = Instant::now();
    // under MPI only rank 0 writes (and prints the table); the others skip every file, and a
    // failed write is agreed over the ranks (parallel::on_writer) or stops them after the step
    let writer = crate::run::parallel::writes_outputs();
    // from here on Ctrl-C and SIGTERM abandon the step in progress (see interrupt.rs): a signal
    // that comes before the solve ends it at its first iteration
    let interrupt = match &opts.interrupt {
        Some(flag) => Some(flag.clone()),
        None => crate::run::interrupt::install(),
    };
    // removes the previous run's files; records this run's when dropped (see out_dir.rs)
    let _folder = crate::run::parallel::on_writer(|| {
        std::fs::create_dir_all(out_dir).map_err(|e| StampError::io(out_dir, e))?;
        crate::run::own_inputs::refuse_inputs_among_outputs(p, out_dir)?;
        crate::run::out_dir::RunFolder::claim(out_dir)
    })?;
    let Setup { mesh, mut model, section, punches, targets, settings, coarse, supports, .. } = setup;
    let targets = opts.targets.clone().unwrap_or(targets);
    // the step budget of the path (a refined run passes through the targets it is given)
    let mut settings = settings;
    settings.max_steps = match &opts.targets {
        Some(t) => p.max_steps().max(crate::schema::limits::STEP_BUDGET_FACTOR.saturating_mul(t.len())),
        None => p.max_steps(),
    };
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

    // sort key of the contact CSV rows: plot_axis coordinate (or arc length) of the plot_group nodes
    let mut axis: Vec<Option<f64>> = vec![None; mesh.mesh.num_nodes()];
    match (&out.plot_group, out.plot_axis) {
        (Some(g), PlotAxis::Arc) => {
            let chain = mesh.curve_chain(g.get_ref()).ok_or_else(|| crate::model::mesh::group_error(p, g.span(), "output.plot_group", g.get_ref(), "curve", &mesh))?;
            for &(n, s) in &chain {
                axis[n] = Some(s);
            }
        }
        (g, a) => {
            let c = if a == PlotAxis::X1 { 0 } else { 1 };
            let nodes = match g {
                Some(g) => Some(mesh.nodes(g.get_ref()).ok_or_else(|| crate::model::mesh::group_error(p, g.span(), "output.plot_group", g.get_ref(), "", &mesh))?),
                None => None,
            };
            for n in nodes.unwrap_or_else(|| (0..mesh.mesh.num_nodes()).collect()) {
                axis[n] = Some(mesh.mesh.coords[n][c]);
            }
        }
    }
    let units = Units::new(p.spec.units.as_ref());
    let punch_names: Vec<String> = punches.iter().map(|i| i.name.clone()).collect();
    let punch_keys: Vec<_> = punches.iter().zip(&model.contacts).map(|(i, c)| (i.name.clone(), i.face, c.drive.is_some() || c.motion.is_zero())).collect();
    let mut history = History::new(&punch_keys, &point_groups).with_layout(Layout::of(&model.element)).with_supports(supports.names());
    let mut probes = Probes::new(p, &mesh, &out.probe, &punch_names)?;
    let thickness_probes = crate::outputs::thickness_probe::ThicknessProbes::new(p, &mesh)?;

    // the linear solver (PETSc's under the feature `petsc`, see parallel.rs)
    let ranks = crate::run::parallel::ranks();
    let mut linear = {
        let layout = Layout::of(&model.element);
        let z = |c: usize| section.delta_minus + (layout.zeta_of_component(c) + 1.0) / 2.0 * section.thickness();
        let inner = model.num_equations() - model.num_drives();
        crate::run::parallel::linear_solver(p, &mesh.mesh.coords, model.dofs.equations(), model.dofs.dofs_per_node(), inner, z)?
    };
    // on P > 1 ranks each evaluates its own elements (see parallel.rs)
    crate::run::parallel::share(&mut model, &mut linear, crate::run::parallel::inputs_hash(p, &mesh.mesh))?;
    let mut summary = Summary {
        ranks,
        linear_solver: crate::run::parallel::describe(&linear),
        problem: p.path.display().to_string(),
        title: p.spec.title.clone(),
        status: "running".into(),
        error: None,
        pid: std::process::id(),
        started: rfc3339_utc(std::time::SystemTime::now()),
        nodes: mesh.mesh.num_nodes(),
        cells: mesh.mesh.num_cells(),
        equations: model.dofs.num_equations(),
        surfaces: model.element.surfaces(),
        layers: model.element.laminate().map(|(lam, per_layer)| {
            let names: Vec<String> = p.spec.plate.get_ref().layers.as_ref().map(|l| l.get_ref().iter().map(|s| s.get_ref().material.clone()).collect()).unwrap_or_default();
            let b = lam.boundaries();
            Value::Array(
                lam.plies
                    .iter()
                    .enumerate()
                    .map(|(k, ply)| serde_json::json!({"bottom": b[k], "top": b[k + 1], "material": names.get(k), "angle": ply.angle, "surfaces": per_layer}))
                    .collect(),
            )
        }),
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
                motion: c.motion.displacement(1.0),
                motion_path: match &c.motion {
                    stamp::contact::PunchMotion::Path(points) => Some(points.iter().map(|(t, d)| [*t, d[0], d[1], d[2]]).collect()),
                    stamp::contact::PunchMotion::Linear(_) => None,
                },
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
        failed_iterations: 0,
        seconds: 0.0,
        point_arrays: crate::outputs::output::POINT_ARRAYS
            .iter()
            .filter(|n| **n != "gap" || !punches.is_empty())
            .map(|s| s.to_string())
            .chain(model.element.is_plastic().then(|| "thickness_strain".to_string()))
            .collect(),
        cell_arrays: crate::outputs::output::cell_array_names(&model.element),
        coarse_predictor: None,
        refinement: opts.refinement.clone(),
        steps: Vec::new(),
    };
    let summary_path = out_dir.join("summary.json");
    let pvd_path = out_dir.join(format!("{stem}.pvd"));
    let mut pvd: Vec<(f64, String)> = Vec::new();
    let mut files: Vec<PathBuf> = Vec::new();
    let mut write_error: Option<StampError> = None;
    let mut total_iterations = 0;
    let mut total_failed = 0;
    // room for the final summary.json, whatever fills the disk meanwhile; a reader sees
    // "running" (with our pid) from the start
    let mut reserve = crate::run::parallel::on_writer(|| {
        let mut reserve = crate::run::reserve::Reserve::create(out_dir)?;
        reserve.cover(write_summary(&summary_path, &summary, None)?);
        Ok(reserve)
    })?;
    // what summary.json says if the process aborts or is interrupted from here on (see
    // abort_note.rs)
    let abort_note = writer.then(crate::run::abort_note::AbortNote::new);
    prepare_notes(abort_note.as_ref(), &summary_path, &summary, 0, 0.0);

    let cx = Context { mesh: &mesh, punches: &punches, section: &section, threshold: out.loaded_threshold.0, point_groups: &point_groups, supports: &supports };
    let progress = Progress::new(!quiet && std::io::stderr().is_terminal() && std::io::stdout().is_terminal(), !quiet, path_end);
    // force-driven punches border the system: block elimination keeps the sparse LU on the nodal part
    let mut newton = NewtonRaphson::new(BorderedSolver::with_inner(model.num_drives(), linear), settings);
    if let Some(previous) = &opts.previous {
        crate::model::coarse::predict_from(&mut newton, previous.path_onto(&mesh.mesh, model.dofs.dofs_per_node()));
    } else if let Some(coarse) = coarse {
        if !quiet {
            eprintln!("coarse predictor: solving on the coarse mesh ({} nodes) first", coarse.setup.mesh.mesh.num_nodes());
        }
        let mut coarse = coarse;
        coarse.setup.settings.max_steps = newton.settings.max_steps;
        let (path, report) = crate::model::coarse::solve_coarse(*coarse, &targets);
        if !quiet || report.error.is_some() {
            eprintln!("{}", report.line());
        }
        crate::model::coarse::predict_from(&mut newton, path);
        summary.coarse_predictor = Some(report);
        if let Some(bytes) = crate::run::parallel::on_writer(|| write_summary(&summary_path, &summary, None))? {
            reserve.as_mut().map(|r| r.cover(bytes));
        }
        prepare_notes(abort_note.as_ref(), &summary_path, &summary, 0, 0.0);
    }
    newton.on_iteration = progress.callback();
    // a failed output write ends the run after its step (what follows could not be written)
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    newton.stop = Some(stop.clone());
    newton.interrupt = interrupt;
    newton.agree_interrupt = crate::run::parallel::agreed_interrupt();
    let mut u = vec![0.0; model.num_dofs()];
    let (mut path_len, mut t_last) = (0.0, 0.0);
    let mut surface_error: Option<StampError> = None;
    let mut states: Vec<(f64, Vec<f64>)> = Vec::new();
    let mut kept = opts.keep.then(|| crate::run::kept::Kept {
        nodes: mesh.mesh.coords.clone(),
        cells: mesh.mesh.cells.clone(),
        surfaces: model.element.surfaces(),
        punches: punch_names.clone(),
        steps: Vec::new(),
    });
    // the state before each step, for the checks after it (crate::checks::psi_checks)
    let mut u_prev = u.clone();
    let layout = Layout::of(&model.element);
    let size = mesh.mesh.coords.iter().flat_map(|x| x.iter()).fold(section.thickness(), |m, v| m.max(v.abs()));
    let mut each_step = |rep: &stamp::nonlinear::StepReport, u: &[f64], m: &stamp::model::Model<crate::model::plate_model::Plate>| {
        total_iterations += rep.iterations;
        total_failed += rep.failed_iterations;
        if opts.record_states {
            states.push((rep.load_factor, u.to_vec()));
        }
        // a punch whose Psi was not finite somewhere (an expression's sqrt of a negative number)
        // stops the run: its answer would be wrong
        if surface_error.is_none() {
            // (psi_checks reads the points' state, whole on every rank after the step)
            surface_error = surface_failure(p, &m.contacts)
                .or_else(|| crate::checks::psi_checks::after_step(p, &mesh, &m.contacts, &layout, size, rep.step, (t_last, &u_prev), (rep.load_factor, u)));
            if surface_error.is_some() {
                stop.store(true, std::sync::atomic::Ordering::Relaxed);
                return;
            }
        }
        u_prev.copy_from_slice(u);
        let t = rep.load_factor;
        path_len += (t - t_last).abs();
        t_last = t;
        let penetration = m.contacts.iter().map(|c| c.max_penetration()).fold(0.0, f64::max);
        let active = m.contacts.iter().map(|c| c.state.iter().filter(|s| s.active).count()).sum();
        // (the reactions are the whole model's on every rank: its forces are summed over them)
        // (the writing process holds every element; the others only their own)
        let plastic = if writer { crate::outputs::plastic::plastic_extremes(&m.element, u, m.dofs.num_nodes()) } else { None };
        let row = history.record(rep.step, t, path_len, rep.iterations, &m.contacts, u, supports.reactions(m, t), plastic).clone();
        // an interrupt from here on says this step converged, whether or not it is written
        prepare_notes(abort_note.as_ref(), &summary_path, &summary, rep.step, t);
        progress.step(rep, path_len, active, penetration, &history.terse_forces());
        if write_error.is_some() || !writer {
            return;
        }
        if let Err(e) = history.write_csv(out_dir) {
            write_error = Some(e);
            return;
        }
        if !(out.every_step || rep.is_target) {
            return;
        }
        let mut data = step_data(&cx, m, u, t, path_len, rep);
        (data.entry.max_plastic_strain, data.entry.min_thickness) = (row.plastic.map(|p| p.0), row.plastic.map(|p| p.1));
        // the step's files first; only when all of them are written is the step listed (.pvd and
        // summary.json), and a step that failed half-way leaves no file behind
        let mut written: Vec<PathBuf> = Vec::new();
        let step_files: Result<()> = (|| {
            if out.vtu {
                let name = format!("{stem}_{:04}.vtu", rep.step);
                let path = out_dir.join(&name);
                write_vtu(&path, &mesh.mesh, &data.point_fields, &data.cell_fields)?;
                written.push(path);
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
                    written.push(path);
                    data.entry.csv.push(name);
                }
            }
            let (files, mismatches) = thickness_probes.write_step(out_dir, rep.step, t, m, &punches, &mesh.mesh.cells, u)?;
            for path in files {
                data.entry.csv.push(path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default());
                written.push(path);
            }
            data.entry.thickness_top_mismatch.extend(mismatches);
            for path in probes.write_step(out_dir, rep.step, &row, &punch_names, &m.contacts, &history.layout, u)? {
                data.entry.csv.push(path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default());
                written.push(path);
            }
            if let Some(name) = &data.entry.vtu {
                // the .pvd time is the path length: it increases when the load goes down again
                pvd.push((path_len, name.clone()));
                if let Err(e) = write_pvd(&pvd_path, &pvd) {
                    pvd.pop();
                    return Err(e);
                }
            }
            Ok(())
        })();
        let mut listed = false;
        let step_result = step_files.and_then(|()| {
            summary.steps.push(serde_json::to_value(&data.entry).map_err(json_err)?);
            listed = true;
            summary.newton_iterations = total_iterations;
            summary.failed_iterations = total_failed;
            summary.seconds = start.elapsed().as_secs_f64();
            // a failed write here is retried at the end (with the failure)
            write_summary(&summary_path, &summary, None).map(|bytes| {
                reserve.as_mut().map(|r| r.cover(bytes));
                prepare_notes(abort_note.as_ref(), &summary_path, &summary, rep.step, t);
            })
        });
        if let Some(kept) = kept.as_mut().filter(|_| listed) {
            kept.steps.push(crate::run::kept::KeptStep::new(&data, u, &layout, mesh.mesh.num_nodes()));
        }
        match step_result {
            Ok(()) => {
                files.append(&mut written);
            }
            Err(e) => {
                if listed {
                    // listed in summary.json, which is rewritten at the end: the files stay
                    files.append(&mut written);
                } else {
                    for f in &written {
                        let _ = std::fs::remove_file(f);
                    }
                }
                write_error = Some(e);
                stop.store(true, std::sync::atomic::Ordering::Relaxed);
            }
        }
    };
    let result = newton.solve_path(&mut model, &mut u, 0.0, &targets, &mut |rep, u, m| {
        each_step(rep, u, m);
        // under MPI the outputs are rank 0's: a failed write there stops every rank after this step
        if ranks > 1 {
            stop.store(crate::run::parallel::any_rank(stop.load(std::sync::atomic::Ordering::Relaxed)), std::sync::atomic::Ordering::Relaxed);
        }
    });
    progress.finish();
    drop(cx);
    summary.newton_iterations = total_iterations;
    // every iteration not in a converged attempt: those of the steps that converged after cut-backs
    // and of the attempts of a step that failed for good
    summary.failed_iterations = newton.iterations_done().saturating_sub(total_iterations);
    // after a write failure the solve stopped on request: that is no failure of its own
    let surface_error = surface_error.or_else(|| surface_failure(p, &model.contacts));
    let solve_failure = if write_error.is_some() { None } else { surface_error.or(result.err()) };
    // an interrupted step is no failed step, nor is a path stopped after a converged step for its
    // step budget (the error says why): summary.json lists the written steps only
    let no_failed_step = matches!(solve_failure, Some(StampError::Interrupted { .. } | StampError::StepLimit { .. }));
    if let Some(e) = solve_failure.as_ref().filter(|_| !no_failed_step) {
        let lf = match e {
            StampError::NoConvergence { load_factor, .. } => Some(*load_factor),
            _ => None,
        };
        summary.steps.push(serde_json::json!({
            "load_factor": lf,
            "converged": false,
            "failed_iterations": summary.failed_iterations.saturating_sub(total_failed),
            "error": e.to_string(),
        }));
    }
    // the first error decides the status: a write failure stopped the outputs, a solve failure the
    // run; the .pvd and the plots are written either way (they list the written steps)
    let mut failure: Option<StampError> = write_error.or(solve_failure);
    if out.vtu && writer {
        match write_pvd(&pvd_path, &pvd) {
            Ok(()) => files.push(pvd_path),
            Err(e) => failure = failure.or(Some(e)),
        }
    }
    let finals: Result<()> = (|| {
        if !writer {
            return Ok(());
        }
        files.push(history.write_csv(out_dir)?);
        if out.plot {
            files.extend(history.plot_force_travel(out_dir, &units)?);
            files.extend(probes.plot(out_dir, &history, &units)?);
        }
        Ok(())
    })();
    if let Err(e) = finals {
        failure = failure.or(Some(e));
    }
    if writer && !quiet && (!opts.no_table || failure.is_some()) {
        crate::out!("{}", crate::outputs::table::render(&history, &units));
    }
    summary.seconds = start.elapsed().as_secs_f64();
    summary.linear_solver = crate::run::parallel::describe(newton.linear.inner());
    match &failure {
        None if opts.caller_finishes => {}
        None => summary.status = "converged".into(),
        Some(e @ StampError::Interrupted { .. }) => {
            summary.status = "interrupted".into();
            summary.error = Some(interrupted_message(e, crate::run::interrupt::received()));
        }
        Some(e) => {
            summary.status = "failed".into();
            summary.error = Some(e.to_string());
        }
    }
    if let Some(note) = &abort_note {
        note.withdraw();
    }
    crate::run::parallel::on_writer(|| reserve.as_mut().map_or(Ok(()), |r| write_final_summary(&summary_path, &summary, failure.as_ref(), r)))?;
    drop(reserve);
    if writer {
        files.push(summary_path.clone());
    }
    let converged_steps = summary.steps.iter().filter(|s| s["converged"] == serde_json::Value::Bool(true)).count();
    // the same outcome on every rank (a write that failed on rank 0 fails them all), so that a
    // caller going on to more collective work (--refine) goes on, or stops, on every rank
    crate::run::parallel::agree(match failure {
        Some(e) => Err(e),
        None => Ok(RunOutcome { out_dir: out_dir.to_path_buf(), summary: summary_path, converged_steps, files, history, states, kept }),
    })
}

//! `stamp bench`: the simply supported square plate pressed by a rigid sphere at its centre (the
//! quarter model), solved on n x n structured meshes with the same loads at every size, timing
//! each phase of the solve.
//!
//! Three problems ([`BenchProblem`]): the default one built here (side 100, R = 50, the sphere
//! moved down 2 in one load target, growing increments), `meshes/sphere-ss-displacement.toml`
//! (side 40, R = 200, moved down 0.9 in 5 targets, augmented Lagrangian) and
//! `meshes/sphere-slide.toml` (a sphere pressed into a plate on a table, then slid 12 along x1),
//! the two files built by `stamp run`'s own pipeline with their mesh's `n` replaced, so that they
//! are the users' problems. `--friction mu` gives the punch Coulomb friction: the cost of a Newton
//! iteration with and without it on the same problem (docs/performance.md, "Friction").
//!
//! Every size runs in a child process of its own (`stamp bench --one N`), so that its peak
//! resident memory is its own and no size warms the caches of the next.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use stamp::contact::{ContactKinematics, ContactPair, ContactPoint};
use stamp::dofs::DofMap;
use stamp::io::{write_vtu, Field};
use stamp::linalg::linear_solver::LinearSolver;
use stamp::linalg::ldlt_gmres::{LdltGmres, LdltGmresStats};
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearProblem, NonlinearSolver};
use stamp::{Result, StampError};
use stamp_contact::Sphere;
use stamp_problem::plate_model::Plate;
use stamp_elements::{Face, Isotropic, Kinematics, PlateElements, Section};
use std::sync::Arc;
use std::time::Instant;

/// The benchmark problem: a square plate of side `SIDE` (the quarter [0, SIDE/2]^2 is meshed),
/// thickness `THICKNESS`, steel, simply supported on its edges, pressed by a sphere of radius
/// `RADIUS` moved down by `PUNCH_TRAVEL` (twice the thickness: bending and membrane action).
pub const SIDE: f64 = 100.0;
pub const THICKNESS: f64 = 1.0;
pub const YOUNG: f64 = 2.1e5;
pub const POISSON: f64 = 0.3;
pub const RADIUS: f64 = 50.0;
pub const PUNCH_TRAVEL: f64 = 2.0;
/// The default sizes of `stamp bench`.
pub const DEFAULT_SIZES: [usize; 5] = [25, 50, 100, 200, 400];
/// The default sizes of `stamp bench --problem sphere-displacement`.
pub const DISPLACEMENT_SIZES: [usize; 5] = [10, 20, 40, 80, 160];
/// The default sizes of `stamp bench --problem sphere-slide` (4n x n cells).
pub const SLIDE_SIZES: [usize; 4] = [8, 16, 32, 64];

/// Which problem `stamp bench` solves.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchProblem {
    /// The sphere (R = 50) moved down 2 onto the plate of side 100, one load target (the default).
    #[default]
    Sphere,
    /// `meshes/sphere-ss-displacement.toml`: the sphere (R = 200) moved down 0.9 onto the plate of
    /// side 40 in 5 equal targets (max_increment 0.2), augmented Lagrangian to a penetration of 1e-6.
    SphereDisplacement,
    /// `meshes/sphere-slide.toml`: a sphere (R = 200) pressed 0.05 into a plate (h = 1) on a
    /// table, then slid 12 along x1, half model on 4n x n cells (the file's 30 x 8 at about n = 8).
    SphereSlide,
}

impl BenchProblem {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            BenchProblem::Sphere => "sphere",
            BenchProblem::SphereDisplacement => "sphere-displacement",
            BenchProblem::SphereSlide => "sphere-slide",
        }
    }

    /// The sizes `stamp bench` runs without --sizes.
    pub fn default_sizes(self) -> &'static [usize] {
        match self {
            BenchProblem::Sphere => &DEFAULT_SIZES,
            BenchProblem::SphereDisplacement => &DISPLACEMENT_SIZES,
            BenchProblem::SphereSlide => &SLIDE_SIZES,
        }
    }
}

/// Where each load step of [`BenchProblem::SphereDisplacement`] starts: `[solver] predictor`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BenchPredictor {
    /// The problem file's own: the secant predictor (the last converged increment again).
    #[default]
    Secant,
    /// The solution on the mesh with half the n, interpolated (`predictor = "coarse"`).
    Coarse,
}

/// The problem file of [`BenchProblem::SphereDisplacement`], its mesh line as in the file.
const DISPLACEMENT_PROBLEM: &str = include_str!("../../meshes/sphere-ss-displacement.toml");
const DISPLACEMENT_MESH_N: &str = "n = [10, 10]";
/// Its [solver] table's header, after which `--predictor coarse` adds its key.
const DISPLACEMENT_SOLVER: &str = "[solver]\n";
/// The problem file of [`BenchProblem::SphereSlide`], its mesh line as in the file.
const SLIDE_PROBLEM: &str = include_str!("../../meshes/sphere-slide.toml");
const SLIDE_MESH_N: &str = "n = [30, 8]";

/// Seconds spent in each phase.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize)]
pub struct Seconds {
    pub assembly: f64,
    pub contact: f64,
    pub symbolic: f64,
    pub factorization: f64,
    pub solve: f64,
    pub output: f64,
    pub total: f64,
}

/// One size of the benchmark.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct BenchRun {
    pub n: usize,
    pub unknowns: usize,
    pub steps: usize,
    /// Load increments given up and cut back (failed attempts).
    #[serde(default)]
    pub cutbacks: usize,
    pub newton_iterations: usize,
    /// Newton iterations of the attempts that were cut back (not in `newton_iterations`; their
    /// factorisations are in `factorizations`).
    #[serde(default)]
    pub failed_iterations: usize,
    pub seconds: Seconds,
    pub peak_rss_bytes: u64,
    pub assemblies: usize,
    pub factorizations: usize,
    pub threads: usize,
    /// Threads of the numeric factorisations: the solver measures faer's parallel setting
    /// against one thread on the first two and keeps the faster (`LdltGmres`).
    pub factorization_threads: usize,
    /// What the linear solver did: LDL^T factorisations used directly or as GMRES preconditioner,
    /// GMRES iterations, hand-overs to the LU.
    pub linear_solver: LdltGmresStats,
    /// Centre deflection of the mid-surface and the total contact force on the whole plate: the
    /// same problem at every size, so these converge with n.
    pub centre_deflection: f64,
    pub reaction: f64,
    /// `[solver] predictor = "coarse"` (the sphere-displacement problem file): the coarse solve
    /// that started every step, included in `seconds.total`.
    #[serde(default)]
    pub coarse: Option<CoarseRun>,
}

/// The coarse solve of a run with `predictor = "coarse"`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CoarseRun {
    pub unknowns: usize,
    pub steps: usize,
    pub newton_iterations: usize,
    pub seconds: f64,
}

/// Build the quarter model on an n x n mesh.
fn build(n: usize) -> Result<Model<Plate>> {
    let half = 0.5 * SIDE;
    let mesh = QuadMesh::rectangle(0.0, half, 0.0, half, n, n)?;
    let section = Section::homogeneous(THICKNESS, Isotropic::new(YOUNG, POISSON)?)?;
    let plate = PlateElements::new(&mesh, section, Kinematics::Nonlinear)?;
    let mut dofs = DofMap::new(mesh.num_nodes(), 6)?;
    dofs.fix(mesh.group_nodes("left")?, &[0, 3])?; // symmetry x1 = 0: v1- = v1+ = 0
    dofs.fix(mesh.group_nodes("bottom")?, &[1, 4])?; // symmetry x2 = 0
    dofs.fix(mesh.group_nodes("right")?, &[2, 5])?; // simply supported: v3- = v3+ = 0
    dofs.fix(mesh.group_nodes("top")?, &[2, 5])?;
    let mut model = Model::new(Plate::TwoSurface(plate), dofs)?;
    // the Newton iteration of `stamp run` (its default `[solver] newton = "mip"`)
    model.mixed_tangent = true;
    let z = 0.5 * THICKNESS;
    let sphere = Arc::new(Sphere::new(Vector3::new(0.0, 0.0, z + RADIUS), RADIUS)?);
    let areas = mesh.nodal_areas();
    let points = (0..mesh.num_nodes())
        .map(|k| {
            let x = mesh.coords[k];
            ContactPoint { node: k, x_ref: [x[0], x[1], z], dofs: [0, 1, 2].map(|c| Face::Top.dof(k, c)), weight: areas[k] }
        })
        .collect();
    let le = half / n as f64;
    let grad = 2.0 * RADIUS;
    let eps_reg = 100.0 * YOUNG * THICKNESS / (le * le * grad * grad);
    let mut pair = ContactPair::new("sphere", sphere, points, eps_reg, ContactKinematics::Exact);
    pair.motion = [0.0, 0.0, -PUNCH_TRAVEL].into();
    model.contacts.push(pair);
    Ok(model)
}

/// The load stepping and Newton settings of the benchmark. First contact of a fine mesh swings
/// the active set wholesale: such a step is given up early (`cycling_after`).
fn settings() -> NewtonSettings {
    NewtonSettings { initial_increment: 0.1, max_increment: 1.0, line_search_steps: 4, cycling_after: 8, ..NewtonSettings::default() }
}

/// Sizes for the ignored measurements below: the comma-separated list in environment variable
/// `var`, else `default`.
#[cfg(test)]
fn sizes_from_env(var: &str, default: &str) -> Vec<usize> {
    std::env::var(var).unwrap_or(default.into()).split(',').map(|s| s.trim().parse().unwrap()).collect()
}

/// Peak resident memory of this process (Linux: VmHWM of /proc/self/status), 0 where unknown.
pub fn peak_rss_bytes() -> u64 {
    let Ok(status) = std::fs::read_to_string("/proc/self/status") else { return 0 };
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<u64>().ok())
        .map(|kb| kb * 1024)
        .unwrap_or(0)
}

/// The linear solver's options and the problem of a benchmark run.
#[derive(Debug, Clone, Copy, Default)]
pub struct SolverOptions {
    /// `LdltGmres::reuse`.
    pub reuse: bool,
    /// Factorise the tangent's symmetric part instead of the plate's P
    /// (`LdltGmres::with_preconditioner(false)`).
    pub symmetric_part: bool,
    /// The problem solved.
    pub problem: BenchProblem,
    /// Where each load step starts (sphere-displacement only).
    pub predictor: BenchPredictor,
    /// The punch's Coulomb friction coefficient (0: frictionless, the problem as it is).
    pub friction: f64,
}

/// The model, the load targets and the settings of the problem file `path` whose text, with its
/// mesh's n replaced, is `source`, built as `stamp run` builds them.
fn build_file(path: &str, source: String) -> Result<(stamp_problem::build::Setup, Vec<f64>)> {
    let p = stamp_problem::Problem::parse(std::path::Path::new(path), source)?;
    let setup = stamp_problem::build::build(&p)?;
    let targets = setup.targets.clone();
    Ok((setup, targets))
}

/// `meshes/sphere-ss-displacement.toml` on an n x n mesh.
fn build_displacement(n: usize, predictor: BenchPredictor) -> Result<(stamp_problem::build::Setup, Vec<f64>)> {
    debug_assert!(DISPLACEMENT_PROBLEM.contains(DISPLACEMENT_MESH_N));
    let mut source = DISPLACEMENT_PROBLEM.replacen(DISPLACEMENT_MESH_N, &format!("n = [{n}, {n}]"), 1);
    if predictor == BenchPredictor::Coarse {
        source = source.replacen(DISPLACEMENT_SOLVER, &format!("{DISPLACEMENT_SOLVER}predictor = \"coarse\"\n"), 1);
    }
    build_file("meshes/sphere-ss-displacement.toml", source)
}

/// `meshes/sphere-slide.toml` on 4n x n cells.
fn build_slide(n: usize) -> Result<(stamp_problem::build::Setup, Vec<f64>)> {
    debug_assert!(SLIDE_PROBLEM.contains(SLIDE_MESH_N));
    build_file("meshes/sphere-slide.toml", SLIDE_PROBLEM.replacen(SLIDE_MESH_N, &format!("n = [{}, {n}]", 4 * n), 1))
}

/// Solve one size in this process and time it. The deformed plate of the last step is written as
/// a .vtu file into a temporary folder (timed as output) and removed.
pub fn run_one(n: usize, options: SolverOptions) -> Result<BenchRun> {
    if n == 0 {
        return Err(StampError::Problem("bench sizes must be positive".into()));
    }
    check_predictor(options)?;
    let start = Instant::now();
    let (mut model, mesh, settings, targets, coarse) = match options.problem {
        BenchProblem::Sphere => (build(n)?, QuadMesh::rectangle(0.0, 0.5 * SIDE, 0.0, 0.5 * SIDE, n, n)?, settings(), vec![1.0], None),
        BenchProblem::SphereDisplacement => {
            let (setup, targets) = build_displacement(n, options.predictor)?;
            // (the key goes in after the [solver] header: a file without one would run secant)
            if options.predictor == BenchPredictor::Coarse && setup.coarse.is_none() {
                return Err(StampError::Problem("--predictor coarse: the problem file's [solver] table was not found to add predictor = \"coarse\"".into()));
            }
            let coarse = setup.coarse.map(|c| stamp_problem::coarse::solve_coarse(*c, &targets));
            (setup.model, setup.mesh.mesh, setup.settings, targets, coarse)
        }
        BenchProblem::SphereSlide => {
            let (setup, targets) = build_slide(n)?;
            (setup.model, setup.mesh.mesh, setup.settings, targets, None)
        }
    };
    if options.friction != 0.0 {
        model.contacts[0].set_friction(options.friction)?;
    }
    // (no force-driven punch in either problem: `stamp run`'s BorderedSolver would be this solver)
    let mut newton = NewtonRaphson::new(LdltGmres::new().reuse(options.reuse).with_preconditioner(!options.symmetric_part), settings);
    let coarse = match coarse {
        Some((path, report)) => {
            if let Some(e) = &report.error {
                return Err(StampError::Problem(format!("the coarse solve of predictor = \"coarse\" failed: {e}")));
            }
            stamp_problem::coarse::predict_from(&mut newton, path);
            Some(CoarseRun { unknowns: report.equations, steps: report.steps, newton_iterations: report.newton_iterations, seconds: report.seconds })
        }
        None => None,
    };
    let mut u = vec![0.0; model.num_dofs()];
    let summary = newton.solve_path(&mut model, &mut u, 0.0, &targets, &mut |_, _, _| {})?;

    let t_out = Instant::now();
    let dir = std::env::temp_dir().join(format!("stamp-bench-{}-{n}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| StampError::io(&dir, e))?;
    let nn = mesh.num_nodes();
    let mid: Vec<f64> = (0..nn).flat_map(|k| (0..3).map(move |c| (k, c))).map(|(k, c)| 0.5 * (u[6 * k + c] + u[6 * k + 3 + c])).collect();
    let pressure = model.contacts[0].pressures();
    let written = write_vtu(&dir.join("bench.vtu"), &mesh, &[Field::new("displacement", 3, mid), Field::scalar("contact_pressure", pressure)], &[]);
    let _ = std::fs::remove_dir_all(&dir);
    written?;
    let output = t_out.elapsed().as_secs_f64();

    let mt = model.timings;
    let st = newton.linear.timings();
    // the quarter models' force times 4, the half model's times 2
    let copies = if options.problem == BenchProblem::SphereSlide { 2.0 } else { 4.0 };
    let reaction = -copies * model.contacts[0].reaction()[2];
    Ok(BenchRun {
        n,
        unknowns: model.num_equations(),
        steps: summary.steps,
        cutbacks: summary.cutbacks,
        newton_iterations: summary.newton_iterations,
        failed_iterations: summary.failed_iterations,
        seconds: Seconds {
            assembly: mt.assembly,
            contact: mt.contact,
            symbolic: st.symbolic,
            factorization: st.factorization,
            solve: st.solve,
            output,
            total: start.elapsed().as_secs_f64(),
        },
        peak_rss_bytes: peak_rss_bytes(),
        assemblies: mt.assemblies,
        factorizations: st.factorizations,
        threads: rayon::current_num_threads(),
        factorization_threads: if newton.linear.factorizes_in_parallel() == Some(true) { rayon::current_num_threads() } else { 1 },
        linear_solver: newton.linear.stats(),
        centre_deflection: 0.5 * (u[2] + u[5]),
        reaction,
        coarse,
    })
}

/// Run every size in a child process (`<this program> bench --one n`) and collect the results.
pub fn run_sizes(sizes: &[usize], options: SolverOptions, mut on_run: impl FnMut(&BenchRun)) -> Result<Vec<BenchRun>> {
    let exe = std::env::current_exe().map_err(|e| StampError::io("the stamp program itself", e))?;
    let mut runs = Vec::new();
    for &n in sizes {
        let out = std::process::Command::new(&exe)
            .args(["bench", "--one", &n.to_string()])
            .args(if options.reuse { &["--reuse"][..] } else { &[][..] })
            .args(if options.symmetric_part { &["--symmetric-part"][..] } else { &[][..] })
            .args(["--problem", options.problem.name()])
            .args(if options.predictor == BenchPredictor::Coarse { &["--predictor", "coarse"][..] } else { &[][..] })
            .args(["--friction", &options.friction.to_string()])
            .output()
            .map_err(|e| StampError::io(&exe, e))?;
        if !out.status.success() {
            return Err(StampError::Problem(format!("bench size n = {n} failed: {}", String::from_utf8_lossy(&out.stderr).trim())));
        }
        let run: BenchRun = serde_json::from_slice(&out.stdout).map_err(|e| StampError::Problem(format!("bench size n = {n}: unreadable result: {e}")))?;
        on_run(&run);
        runs.push(run);
    }
    Ok(runs)
}

/// The table header of the text report.
pub fn header(options: SolverOptions) -> String {
    let mut title = match options.problem {
        BenchProblem::Sphere => format!("simply supported square plate (side {SIDE}, h = {THICKNESS}, quarter model) under a sphere (R = {RADIUS}, travel {PUNCH_TRAVEL})"),
        BenchProblem::SphereDisplacement => "meshes/sphere-ss-displacement.toml: simply supported square plate (side 40, h = 1, quarter model) under a sphere (R = 200, travel 0.9, 5 targets)".into(),
        BenchProblem::SphereSlide => "meshes/sphere-slide.toml: a sphere (R = 200) pressed 0.05 into a plate (h = 1) on a table, then slid 12 along x1 (half model, 4n x n cells, 10 targets)".into(),
    };
    if options.friction != 0.0 {
        title.push_str(&format!(";\nfriction = {} between the punch and the plate", options.friction));
    }
    if options.predictor == BenchPredictor::Coarse {
        title.push_str(";\npredictor = \"coarse\": every load step starts from the solution on the mesh with half the n");
    }
    format!(
        "stamp bench: {title}\n\
         {:>5} {:>9} {:>5} {:>4} {:>6} {:>5} {:>7} {:>7} {:>4} {:>6} | {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} | {:>9} | {:>10} {:>9}",
        "n", "unknowns", "steps", "cuts", "newton", "/step", "coarse", "factors", "fthr", "gmres", "assembly", "contact", "symbolic", "factor", "solve", "output", "total", "peak RSS", "w_centre", "reaction"
    )
}

/// One row of the text report (seconds; memory in MiB).
pub fn row(r: &BenchRun) -> String {
    let s = &r.seconds;
    format!(
        "{:>5} {:>9} {:>5} {:>4} {:>6} {:>5.1} {:>7} {:>7} {:>4} {:>6} | {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.3} {:>8.3} | {:>6.0} MiB | {:>10.6} {:>9.3}",
        r.n,
        r.unknowns,
        r.steps,
        r.cutbacks,
        r.newton_iterations,
        r.newton_iterations as f64 / r.steps.max(1) as f64,
        r.coarse.as_ref().map(|c| c.newton_iterations.to_string()).unwrap_or_else(|| "-".into()),
        r.factorizations,
        r.factorization_threads,
        r.linear_solver.gmres_iterations,
        s.assembly,
        s.contact,
        s.symbolic,
        s.factorization,
        s.solve,
        s.output,
        s.total,
        r.peak_rss_bytes as f64 / (1024.0 * 1024.0),
        r.centre_deflection,
        r.reaction
    )
}

/// `--predictor coarse` needs the problem file's [solver] predictor.
fn check_predictor(options: SolverOptions) -> Result<()> {
    if options.predictor == BenchPredictor::Coarse && options.problem != BenchProblem::SphereDisplacement {
        return Err(StampError::Problem("--predictor coarse is for --problem sphere-displacement (a problem file with a [solver] predictor)".into()));
    }
    Ok(())
}

/// `stamp bench`: all sizes, as a table or as JSON.
pub fn bench_command(sizes: &[usize], json: bool, options: SolverOptions) -> Result<()> {
    check_predictor(options)?;
    if json {
        let runs = run_sizes(sizes, options, |_| {})?;
        let text = serde_json::to_string_pretty(&serde_json::json!({ "runs": runs })).map_err(|e| StampError::Problem(e.to_string()))?;
        crate::outln!("{text}");
    } else {
        crate::outln!("{}", header(options));
        run_sizes(sizes, options, |r| crate::outln!("{}", row(r)))?;
        crate::outln!("threads: {} (RAYON_NUM_THREADS); seconds are wall time per phase, summed over the solve; cuts: load increments cut back, newton: iterations of the converged steps (/step: per step), coarse: Newton iterations of the coarse solve that started every step (predictor = \"coarse\", a quarter of the unknowns; its time is in total), factors: numeric factorisations (--reuse: a factor serves later Newton iterations while that is cheaper), fthr: their threads (the first two measure faer's parallel setting against one thread; the faster is kept), gmres: GMRES iterations", rayon::current_num_threads());
    }
    Ok(())
}

/// `stamp bench --one n`: one size, as one JSON object on stdout.
pub fn one_command(n: usize, options: SolverOptions) -> Result<()> {
    let run = run_one(n, options)?;
    crate::outln!("{}", serde_json::to_string(&run).map_err(|e| StampError::Problem(e.to_string()))?);
    Ok(())
}

#[cfg(test)]
mod ordering_measurement {
    //! Not tests: the measurements behind `stamp::linalg::ldlt_gmres::Ordering` (ignored; run with
    //! `STAMP_ORDERING_SIZES=100,200 cargo test --release -p stamp-cli --lib ordering_ -- --ignored --nocapture --test-threads 1`;
    //! STAMP_ORDERING_NUMERIC=0 skips the numeric factorisations of `ordering_comparison`).
    use super::*;
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymmetricOrdering};
    use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
    use faer::perm::PermRef;
    use faer::Side;

    /// The bench model's tangent at load factor t (punch travel 2 t: contact active), its pattern
    /// and the values of its symmetric part.
    fn tangent(n: usize, t: f64) -> (usize, Vec<usize>, Vec<usize>, Vec<f64>) {
        let mut model = build(n).unwrap();
        let mut u = vec![0.0; model.num_dofs()];
        model.apply_prescribed(&mut u, t);
        model.evaluate(&u, t, true).unwrap();
        let a = model.matrix();
        let (cp, ri, v) = (a.symbolic().col_ptr().to_vec(), a.symbolic().row_idx().to_vec(), a.val());
        let mut s = vec![0.0; v.len()];
        for j in 0..a.ncols() {
            for k in cp[j]..cp[j + 1] {
                let i = ri[k];
                let p = cp[i] + ri[cp[i]..cp[i + 1]].binary_search(&j).expect("symmetric pattern");
                s[k] = 0.5 * (v[k] + v[p]);
            }
        }
        (a.ncols(), cp, ri, s)
    }

    /// The symbolic LDL^T of the pattern (`cp`, `ri`) ordered by nested dissection (METIS) if
    /// `nested`, else by faer's AMD, and the seconds METIS took.
    fn ordered_symbolic(neq: usize, cp: &[usize], ri: &[usize], nested: bool) -> (faer::sparse::linalg::cholesky::SymbolicCholesky<usize>, f64) {
        let t0 = Instant::now();
        let perm = nested.then(|| stamp::linalg::ordering::nested_dissection(cp, ri).unwrap());
        let t_order = t0.elapsed().as_secs_f64();
        let inv = perm.as_ref().map(|p| stamp::linalg::ordering::inverse(p));
        let ord = match (&perm, &inv) {
            (Some(p), Some(i)) => SymmetricOrdering::Custom(PermRef::new_checked(p, i, neq)),
            _ => SymmetricOrdering::Amd,
        };
        let pattern = SymbolicSparseColMatRef::new_checked(neq, neq, cp, None, ri);
        (factorize_symbolic_cholesky(pattern, Side::Lower, ord, Default::default()).unwrap(), t_order)
    }

    /// Multiply-adds of the LDL^T: sum over the columns of L of (entries below the diagonal)^2.
    fn flops(sym: &faer::sparse::linalg::cholesky::SymbolicCholesky<usize>) -> f64 {
        use faer::sparse::linalg::cholesky::SymbolicCholeskyRaw;
        let count = |c: usize| (c * c) as f64;
        match sym.raw() {
            SymbolicCholeskyRaw::Supernodal(s) => (0..s.n_supernodes())
                .map(|k| {
                    let w = s.supernode_end()[k] - s.supernode_begin()[k];
                    let r = s.col_ptr_for_row_idx()[k + 1] - s.col_ptr_for_row_idx()[k];
                    (0..w).map(|i| count(w - 1 - i + r)).sum::<f64>()
                })
                .sum(),
            SymbolicCholeskyRaw::Simplicial(s) => (0..s.ncols()).map(|j| count(s.col_ptr()[j + 1] - s.col_ptr()[j] - 1)).sum(),
        }
    }

    #[test]
    #[ignore]
    fn ordering_comparison() {
        let sizes = sizes_from_env("STAMP_ORDERING_SIZES", "100,200");
        let numeric = std::env::var("STAMP_ORDERING_NUMERIC").map(|v| v != "0").unwrap_or(true);
        let par = faer::get_global_parallelism();
        println!("n | unknowns | nnz(A) | ordering | nnz(L) | flops | ordering s | symbolic s (incl. ordering) | numeric s (min of 3)");
        for n in sizes {
            let (neq, cp, ri, s) = tangent(n, 0.3);
            let pattern = SymbolicSparseColMatRef::new_checked(neq, neq, &cp, None, &ri);
            let a = SparseColMatRef::new(pattern, &s);
            // symbolic phases first, then the numeric factorisations of both orderings in turns,
            // so that both meet the same load of the (shared) machine
            let mut runs = Vec::new();
            for name in ["AMD", "ND"] {
                let t0 = Instant::now();
                let (sym, t_order) = ordered_symbolic(neq, &cp, &ri, name == "ND");
                let t_sym = t0.elapsed().as_secs_f64();
                runs.push((name, sym, t_order, t_sym, f64::INFINITY));
            }
            if numeric {
                for _ in 0..3 {
                    for run in runs.iter_mut() {
                        let sym = &run.1;
                        let scratch = sym.factorize_numeric_ldlt_scratch::<f64>(par, Default::default());
                        let mut buffer = MemBuffer::new(scratch);
                        let mut factor = vec![0.0; sym.len_val()];
                        // touch the memory first, as a solver that keeps its factor would have
                        factor.iter_mut().for_each(|x| *x = 1.0);
                        let t1 = Instant::now();
                        sym.factorize_numeric_ldlt(&mut factor, a, Side::Lower, Default::default(), par, MemStack::new(&mut buffer), Default::default()).unwrap();
                        run.4 = run.4.min(t1.elapsed().as_secs_f64());
                    }
                }
            }
            for (name, sym, t_order, t_sym, best) in &runs {
                println!("{n} | {neq} | {} | {name} | {} | {:.3e} | {t_order:.3} | {t_sym:.3} | {best:.3}", ri.len(), sym.len_val(), flops(sym));
            }
        }
    }

    /// One solve pair (forward and backward substitution) with the LDL^T factor of the bench
    /// tangent's symmetric part (LdltGmres's ordering: nested dissection from
    /// `ND_MIN_UNKNOWNS` unknowns on), faer's solve against `stamp::linalg::supernodal_solve` (its
    /// sequential path, and its parallel one), with 1 and 2 rayon threads, each the minimum of 10
    /// runs taking turns (run with
    /// `STAMP_ORDERING_SIZES=100,200 cargo test --release -p stamp-cli --lib solve_pair -- --ignored --nocapture --test-threads 1`).
    #[test]
    #[ignore]
    fn solve_pair() {
        use faer::sparse::linalg::cholesky::LdltRef;
        use faer::{Conj, MatMut, Par};
        use stamp::linalg::supernodal_solve::SupernodalSolve;
        let sizes = sizes_from_env("STAMP_ORDERING_SIZES", "100,200");
        println!("n | unknowns | nnz(L) | ordering | splits | faer 1 thread s | faer 2 threads s | ours sequential s | ours 1 thread s | ours 2 threads s | max rel. difference");
        for n in sizes {
            let (neq, cp, ri, s) = tangent(n, 0.3);
            let pattern = SymbolicSparseColMatRef::new_checked(neq, neq, &cp, None, &ri);
            let a = SparseColMatRef::new(pattern, &s);
            let nested = neq >= stamp::linalg::ldlt_gmres::ND_MIN_UNKNOWNS;
            let (sym, _) = ordered_symbolic(neq, &cp, &ri, nested);
            let par = Par::rayon(2);
            let mut buffer = MemBuffer::new(sym.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()).or(sym.solve_in_place_scratch::<f64>(1, par)));
            let mut factor = vec![0.0; sym.len_val()];
            sym.factorize_numeric_ldlt(&mut factor, a, Side::Lower, Default::default(), par, MemStack::new(&mut buffer), Default::default()).unwrap();
            let t = Instant::now();
            let ours = SupernodalSolve::new(&sym);
            let t_schedule = t.elapsed().as_secs_f64();
            assert!(ours.is_parallel());
            let (work, span) = ours.work_and_span(&sym);
            println!("n = {n}: schedule built in {t_schedule:.3} s, work / critical path {:.2}", work / span);
            let b: Vec<f64> = (0..neq).map(|i| (i * 7919 % 1000) as f64 / 1000.0 - 0.5).collect();
            let pools: Vec<_> = [1, 2].iter().map(|&t| rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap()).collect();
            // variants: faer 1, faer 2, ours sequential, ours 1 thread, ours 2 threads
            let mut best = [f64::INFINITY; 5];
            let mut results: Vec<Vec<f64>> = vec![Vec::new(); 5];
            let mut x = b.clone();
            for _ in 0..10 {
                for (v, best) in best.iter_mut().enumerate() {
                    x.copy_from_slice(&b);
                    let pool = &pools[if v == 0 || v == 3 { 0 } else { 1 }];
                    let t = Instant::now();
                    pool.install(|| match v {
                        0 | 1 => LdltRef::new(&sym, &factor).solve_in_place_with_conj(
                            Conj::No,
                            MatMut::from_column_major_slice_mut(&mut x, neq, 1),
                            if v == 0 { Par::Seq } else { par },
                            MemStack::new(&mut buffer),
                        ),
                        2 => ours.solve_in_place(&sym, &factor, &mut x, false),
                        _ => ours.solve_in_place(&sym, &factor, &mut x, true),
                    });
                    *best = best.min(t.elapsed().as_secs_f64());
                    results[v].clone_from(&x);
                }
            }
            let scale = results[0].iter().fold(0.0f64, |m, v| m.max(v.abs()));
            let diff = results[1..].iter().map(|r| r.iter().zip(&results[0]).fold(0.0f64, |m, (a, b)| m.max((a - b).abs())) / scale).fold(0.0, f64::max);
            println!(
                "{n} | {neq} | {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} | {diff:.1e}",
                sym.len_val(),
                if nested { "ND" } else { "AMD" },
                ours.splits(),
                best[0],
                best[1],
                best[2],
                best[3],
                best[4]
            );
        }
    }

    /// The whole benchmark solve (as `stamp bench`) under each ordering.
    #[test]
    #[ignore]
    fn ordering_bench() {
        use stamp::linalg::ldlt_gmres::Ordering;
        let sizes = sizes_from_env("STAMP_ORDERING_SIZES", "100,200");
        println!("n | ordering | Newton | factorisations | GMRES | symbolic s | factor s | solve s | total s | centre deflection");
        for n in sizes {
            for ordering in [Ordering::Amd, Ordering::NestedDissection] {
                let start = Instant::now();
                let mut model = build(n).unwrap();
                let mut newton = NewtonRaphson::new(LdltGmres::new().ordering(ordering), settings());
                let mut u = vec![0.0; model.num_dofs()];
                let summary = newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
                let st = newton.linear.timings();
                let centre = 0.5 * (u[2] + u[5]);
                println!(
                    "{n} | {ordering:?} | {} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {centre:.9}",
                    summary.newton_iterations,
                    st.factorizations,
                    newton.linear.stats().gmres_iterations,
                    st.symbolic,
                    st.factorization,
                    st.solve,
                    start.elapsed().as_secs_f64()
                );
            }
        }
    }
}

#[cfg(test)]
mod assembly_measurement {
    //! Not a test: one full assembly (residual, tangent and P; no P with STAMP_ASSEMBLY_SYMMETRIC set) of the bench model with one and with
    //! two threads, and a residual-only one (ignored; run with
    //! `STAMP_ASSEMBLY_SIZES=200,400 cargo test --release -p stamp-cli --lib assembly_threads -- --ignored --nocapture`).
    use super::*;

    #[test]
    #[ignore]
    fn assembly_threads() {
        let sizes = sizes_from_env("STAMP_ASSEMBLY_SIZES", "200");
        println!("n | unknowns | full assembly s, 1 thread | 2 threads | speed-up | residual only s, 2 threads (min of 5)");
        for n in sizes {
            let mut model = build(n).unwrap();
            // with the plate's preconditioner P, as `stamp bench` assembles it; without it when
            // STAMP_ASSEMBLY_SYMMETRIC is set (as `stamp bench --symmetric-part`)
            model.want_preconditioner(std::env::var_os("STAMP_ASSEMBLY_SYMMETRIC").is_none());
            let mut u = vec![0.0; model.num_dofs()];
            model.apply_prescribed(&mut u, 0.3);
            let mut time = |threads: usize, tangent: bool| {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                pool.install(|| {
                    model.evaluate(&u, 0.3, tangent).unwrap();
                    (0..5)
                        .map(|_| {
                            let t = Instant::now();
                            model.evaluate(&u, 0.3, tangent).unwrap();
                            t.elapsed().as_secs_f64()
                        })
                        .fold(f64::INFINITY, f64::min)
                })
            };
            let (one, two, residual) = (time(1, true), time(2, true), time(2, false));
            println!("{n} | {} | {one:.3} | {two:.3} | {:.2} | {residual:.3}", model.num_equations(), one / two);
        }
    }
}

#[cfg(test)]
mod element_measurement {
    //! Not a test: the plate element's kernel alone (no scatter), every element of the bench mesh
    //! evaluated on one thread at a deformed state: tangent and preconditioner, tangent, residual only;
    //! the minimum of 15 sweeps (ignored; run with
    //! `STAMP_ELEMENT_SIZES=100 cargo test --release -p stamp-cli --lib element_kernel -- --ignored --nocapture`;
    //! STAMP_ELEMENT_ORDER picks the sweeps and their order).
    use super::*;
    use stamp::element::{Element, LocalSystem};

    #[test]
    #[ignore]
    fn element_kernel() {
        for n in sizes_from_env("STAMP_ELEMENT_SIZES", "100") {
            let model = build(n).unwrap();
            let plate = &model.element;
            let mut u = vec![0.0; model.num_dofs()];
            for (k, x) in u.iter_mut().enumerate() {
                *x = 1e-3 * ((k * 7919 % 1000) as f64 / 1000.0 - 0.5);
            }
            let mut ws = plate.new_workspace();
            let mut ue = [0.0; 24];
            let mut sweep = |tangent: bool, preconditioner: bool| {
                let mut out = if preconditioner { LocalSystem::with_preconditioner(24) } else { LocalSystem::new(24) };
                (0..15)
                    .map(|_| {
                        let t = Instant::now();
                        let mut check = 0.0;
                        for e in 0..plate.num_elements() {
                            for (a, &node) in plate.element_nodes(e).iter().enumerate() {
                                ue[6 * a..6 * a + 6].copy_from_slice(&u[6 * node..6 * node + 6]);
                            }
                            out.clear(tangent);
                            plate.evaluate(e, &ue, &mut ws, &mut out, tangent);
                            check += out.tangent[25] + out.residual[3];
                        }
                        assert!(check.is_finite());
                        t.elapsed().as_secs_f64() / plate.num_elements() as f64
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            // STAMP_ELEMENT_ORDER=tr, say: only these sweeps, in this order (p tangent and
            // preconditioner, t tangent, r residual), e.g. to see whether one sweep slows the next
            if let Ok(order) = std::env::var("STAMP_ELEMENT_ORDER") {
                for ch in order.chars() {
                    let (t, p) = match ch {
                        'p' => (true, true),
                        't' => (true, false),
                        _ => (false, false),
                    };
                    println!("n {n}, sweep {ch}: {:.3} microseconds per element", 1e6 * sweep(t, p));
                }
                continue;
            }
            let (full, tangent, residual) = (sweep(true, true), sweep(true, false), sweep(false, false));
            println!(
                "n {n}: {} elements, microseconds per element: tangent and preconditioner {:.3}, tangent {:.3}, residual only {:.3}",
                plate.num_elements(),
                1e6 * full,
                1e6 * tangent,
                1e6 * residual
            );
        }
    }
}

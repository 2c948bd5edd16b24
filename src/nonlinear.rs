//! Nonlinear solution: the [`NonlinearProblem`] interface a model offers, the [`NonlinearSolver`]
//! interface a strategy implements, and [`NewtonRaphson`] with load stepping, automatic growth and
//! cut-back of the load increment (paper eq. 4.13, with the active set updated at every iteration:
//! the paper's trial-and-error loop, eqs. 4.14-4.15).
//!
//! Economies that change the work and not the answer (`tests/newton_economy.rs`):
//! near the solution a chord step with the last factorisation replaces a new tangent and
//! factorisation ([`NewtonSettings::chord_tol`]); an iterative linear solver may stop at a
//! relative residual min(forcing, |R| / force scale) (inexact Newton,
//! [`NewtonSettings::forcing`]); the residual a line-search trial computed serves the next
//! iteration. A step whose active set swings at every iteration without progress may be given up
//! early ([`NewtonSettings::cycling_after`], off by default).

use crate::error::{Result, StampError};
use crate::linalg::linear_solver::LinearSolver;
use crate::linearised_contact::{resolve, ConstraintRow, Resolve};
use faer::sparse::SparseColMatRef;
use std::time::Instant;

/// What one evaluation of the residual found.
#[derive(Debug, Clone, Copy, Default)]
pub struct Evaluation {
    /// Euclidean norm of the residual over the equations.
    pub residual_norm: f64,
    /// The size of the forces in play (external, internal with reactions, contact), the scale the
    /// residual is measured against.
    pub force_scale: f64,
    /// Contact points whose active state changed in this evaluation.
    pub active_changes: usize,
}

/// A discretised problem R(u, t) = 0, t the load factor.
pub trait NonlinearProblem {
    /// Length of the full dof vector.
    fn num_dofs(&self) -> usize;
    /// Number of equations (free dofs).
    fn num_equations(&self) -> usize;
    /// Set the prescribed dofs of `u` for load factor `t`.
    fn apply_prescribed(&self, u: &mut [f64], t: f64);
    /// Evaluate the residual (and the tangent) at `u`, load factor `t`.
    fn evaluate(&mut self, u: &[f64], t: f64, with_tangent: bool) -> Result<Evaluation>;
    /// The residual of the last evaluation, per equation.
    fn residual(&self) -> &[f64];
    /// The tangent of the last evaluation with `with_tangent`.
    fn matrix(&self) -> SparseColMatRef<'_, usize, f64>;
    /// A symmetric matrix of the same pattern close to the tangent, if the problem has one, for
    /// [`LinearSolver::factorize_preconditioned`] (see [`crate::element::Element::has_preconditioner`]).
    fn preconditioner(&self) -> Option<SparseColMatRef<'_, usize, f64>> {
        None
    }
    /// Whether the evaluations with the tangent should also build the preconditioner (the
    /// nonlinear solver says so when its linear solver uses one); off until asked.
    fn want_preconditioner(&mut self, _on: bool) {}
    /// Add an increment given per equation.
    fn add_increment(&self, u: &mut [f64], du: &[f64]);
    /// The inequality constraints linearised at the last evaluation, for the re-solve of the
    /// linearised contact problem on each factorisation ([`crate::linearised_contact`]); empty
    /// (the default) where the problem has none or the re-solve does not apply to them. On
    /// several processes every process must get every row, the same (a collective call).
    fn constraint_rows(&self) -> Result<Vec<ConstraintRow>> {
        Ok(Vec::new())
    }
    /// Set a constraint's state (active or not) for the next evaluation, as the re-solve found it.
    fn set_constraint_state(&mut self, id: (usize, usize), active: bool) {
        let _ = (id, active);
    }
    /// Update any inequality constraints' active sets after Newton converged on them; returns the
    /// number of changes (0: the solution stands).
    fn update_active_set(&mut self) -> usize {
        0
    }
    /// Called before the first iteration of every load step; `predicted` is true when the step
    /// starts from an outside prediction of its answer ([`NewtonRaphson::predictor`]: the
    /// solution on a coarse mesh) rather than from the extrapolated path: the problem may trust
    /// the start (the contact pairs then let every penetrating point into the active set at once).
    fn start_step(&mut self, _predicted: bool) {}
    /// Called after a load step converged. Returning true asks for the step to be solved again at
    /// the same load (an augmented-Lagrangian update, say).
    fn end_step(&mut self, _u: &[f64], _t: f64) -> bool {
        false
    }
    /// Update the multipliers of the problem's constraints (augmented Lagrangian) at the iterate
    /// of the last evaluation, inside Newton, when they are not converged yet; true when anything
    /// changed (the residual must then be evaluated again). Called once the active set stopped
    /// changing and |R| is small ([`NewtonSettings::multiplier_tol`]).
    fn update_multipliers(&mut self) -> bool {
        false
    }
    /// Save the history-dependent state (contact) of the last converged step.
    fn checkpoint(&mut self) {}
    /// Go back to the last checkpoint (after a failed step).
    fn restore(&mut self) {}
}

/// Settings of Newton-Raphson and of the load stepping.
#[derive(Debug, Clone, serde::Serialize)]
pub struct NewtonSettings {
    /// Converged when |R| <= rel_tol * force scale + abs_tol and the active set did not change.
    pub rel_tol: f64,
    pub abs_tol: f64,
    /// Round-off floor: once |R| <= floor_tol * force scale and an iteration no longer halves |R|
    /// (with an unchanged active set), the iterate is as converged as floating point allows. So it
    /// is, at once, when |R| <= loose_tol * force scale and the correction that led there had an
    /// energy below [`energy_tol`](Self::energy_tol) times the first's (quadratic convergence: the
    /// next iteration would only confirm the stall).
    pub floor_tol: f64,
    /// Also converged when the last correction was below disp_tol * max |u| (the displacements are
    /// fixed to round-off) and |R| <= loose_tol * force scale: the residual of a stiff penalty
    /// cannot be smaller than the round-off of Psi times the contact stiffness.
    pub disp_tol: f64,
    pub loose_tol: f64,
    /// Also converged when |R| stopped decreasing and the energy of the last correction, |du . R|,
    /// fell below energy_tol times
    /// that of the first (the classical energy criterion; immune to round-off in stiff modes such
    /// as the thickness stretch of a very thin plate, whose conditioning grows like (l/h)^4).
    pub energy_tol: f64,
    /// Most Newton iterations of one solve; a multiplier update inside Newton
    /// ([`multiplier_tol`](Self::multiplier_tol)) starts the count afresh, as a re-solve after
    /// [`NonlinearProblem::end_step`] does.
    pub max_iterations: usize,
    /// Most halvings of the Newton correction in the line search (0: plain Newton).
    pub line_search_steps: usize,
    /// First load increment, as a fraction of the distance to the first target.
    pub initial_increment: f64,
    /// Largest load increment (in load factor).
    pub max_increment: f64,
    /// Smallest load increment before giving up.
    pub min_increment: f64,
    /// The increment grows by this factor after a step whose last solve took at most
    /// `easy_iterations` (counted from the last multiplier update inside Newton, if any).
    pub growth: f64,
    pub easy_iterations: usize,
    /// Most cut-backs in a row.
    pub max_cutbacks: usize,
    /// Most multiplier updates of one load step (augmented Lagrangian): inside Newton
    /// ([`multiplier_tol`](Self::multiplier_tol)) and by re-solves the problem asks for, together.
    pub max_restarts: usize,
    /// Start each load step from the secant extrapolation of the last two converged states,
    /// u_n + (t - t_n)/(t_n - t_{n-1}) (u_n - u_{n-1}), instead of u_n: the body follows a moving
    /// punch instead of being overrun by it, which saves most of the iterations of a step.
    pub extrapolate: bool,
    /// Scale the secant extrapolation by how well the last step's predicted that step's answer:
    /// theta = (du . s) / (s . s), du the converged increment and s the secant it started from,
    /// clamped to [[`SECANT_FIT_MIN`], 1], and 1 where that fit is at least
    /// [`SECANT_FIT_TRUSTED`]. A force-driven punch's secant overshoots (its first touch
    /// stiffens the plate: fits of 0.2 to 0.6) and sends the plate deep into the punch; a moving
    /// punch's does not (fits above 0.9). Measured on the shipped problems (docs/performance.md):
    /// sphere-ss 38 -> 33, squeeze 38 -> 32 Newton iterations, paper-r100 99 in 11 steps -> 75 in
    /// 9, none more. False: the plain secant.
    pub fit_secant: bool,
    /// Solve the linearised contact problem again on each factorisation and take the step with
    /// the set it finds ([`crate::linearised_contact`]), for the problems that give constraint
    /// rows (nodal contact on one process). Measured on the shipped problems, the README
    /// tutorial, the torus die and a cylinder on triangles (docs/performance.md): the torus on
    /// triangles of size 1 43 -> 25 Newton iterations in 4 steps, paper-r100 75 in 9 steps -> 50
    /// in 8, the cylinder on triangles of size 1 28 -> 13 (37 -> 18 s). False: one guess of the
    /// set per factorisation.
    pub resolve_contact: bool,
    /// Largest forcing term of the inexact Newton method: the linear solve of an iteration may
    /// leave a relative residual min(forcing, |R| / force scale) (an iterative linear solver
    /// stops there; a direct one solves exactly). 0: every solve to full accuracy.
    ///
    /// The default 1e-5: with the plate's preconditioner GMRES gains about three decades in its
    /// second iteration and reaches round-off in its third, so a cap of 1e-6 made most solves take
    /// the third; with 1e-5 many stop after two. While |R| / force scale <= 1e-5 the forcing is
    /// |R| / force scale either way, so the convergence stays quadratic. Measured with `stamp
    /// bench` (2026-11-24): the same factorisations at n = 25-200, GMRES iterations 89 -> 81 at
    /// n = 200; `stamp paper` the same to its printed digits (1182 Newton iterations against
    /// 1189). 1e-4 and looser added Newton iterations (n = 100: 23 factorisations against 22,
    /// n = 200 with 1e-3: 39 against 24).
    pub forcing: f64,
    /// From this iteration on, a step whose active set changed at each of the last
    /// [`CYCLING_WINDOW`] iterations while |R| made no progress (the least |R| of the window's
    /// second half above half that of its first half) is given up and cut back (0: never, the
    /// default). For an active set that swings wholesale at every iteration (first contact of a
    /// fine mesh under a large increment: `stamp bench` at 961 600 unknowns, a thousand points
    /// in and out at each iteration) a smaller increment is cheaper than 25 iterations. Off by
    /// default because it costs more than it saves on paths whose active set settles late:
    /// measured on `stamp paper`, 2146 Newton iterations in all without, 3006 with 8.
    pub cycling_after: usize,
    /// Once |R| <= chord_tol * force scale (with an unchanged active set), correct with the
    /// factorisation of the last iterate instead of a new tangent (a chord step); 0: never.
    pub chord_tol: f64,
    /// Once |R| <= multiplier_tol * force scale with an unchanged active set, the problem's
    /// augmented-Lagrangian multipliers are updated inside Newton
    /// ([`NonlinearProblem::update_multipliers`]) and the iterations go on from the same iterate,
    /// instead of after Newton converged, with a re-solve of the step
    /// ([`NonlinearProblem::end_step`], still asked at the end); 0: never. The update moves the
    /// solution by the penetration the penalty left, a small perturbation the next one or two
    /// Newton iterations absorb, while a re-solve costs its own convergence down to round-off:
    /// measured on `stamp bench --problem sphere-displacement` (2026-11-24), 49 / 57 / 54 Newton
    /// iterations at n = 10 / 20 / 40 became 40 / 49 / 51 (1e-5: 40 / 51 / 52), the reactions of
    /// every step the same to 2e-8 relative (docs/performance.md).
    pub multiplier_tol: f64,
    /// Most converged load steps of a path (`usize::MAX`: no limit). The path also stops as soon
    /// as the pace of the last [`PACE_WINDOW`] steps (their mean increment) would need more steps
    /// than are left to finish it: a path that crawls (ever smaller increments that converge)
    /// ends with the reason instead of running for hours.
    pub max_steps: usize,
}

/// The steps over which [`NewtonSettings::max_steps`] measures the pace of a path.
pub const PACE_WINDOW: usize = 50;

/// Iterations in a row with a changing active set that count as cycling.
pub const CYCLING_WINDOW: usize = 6;

impl Default for NewtonSettings {
    fn default() -> Self {
        NewtonSettings {
            rel_tol: 1e-10,
            abs_tol: 1e-14,
            floor_tol: 1e-8,
            disp_tol: 1e-12,
            loose_tol: 1e-6,
            energy_tol: 1e-12,
            max_iterations: 25,
            line_search_steps: 0,
            initial_increment: 1.0,
            max_increment: 1.0,
            min_increment: 1e-6,
            growth: 1.5,
            easy_iterations: 5,
            max_cutbacks: 12,
            max_restarts: 20,
            extrapolate: true,
            fit_secant: true,
            resolve_contact: true,
            forcing: 1e-5,
            cycling_after: 0,
            chord_tol: 1e-6,
            multiplier_tol: 1e-3,
            max_steps: usize::MAX,
        }
    }
}

impl NewtonSettings {
    /// Refuse settings with which a solve cannot work or cannot end: no iterations, increments that
    /// are not positive finite numbers or in the wrong order, tolerances that are not numbers
    /// or that floating point cannot reach, loop counts beyond any use.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(StampError::Problem(format!("Newton settings: {m}")));
        if self.max_iterations == 0 || self.max_iterations > 100_000 {
            return bad(format!("max_iterations must be from 1 to 100000, got {}", self.max_iterations));
        }
        if self.line_search_steps > 1000 || self.max_cutbacks > 1000 || self.max_restarts > 100_000 {
            return bad(format!(
                "line_search_steps ({}) and max_cutbacks ({}) must be at most 1000, max_restarts ({}) at most 100000",
                self.line_search_steps, self.max_cutbacks, self.max_restarts
            ));
        }
        for (name, v) in [("max_increment", self.max_increment), ("initial_increment", self.initial_increment), ("min_increment", self.min_increment)] {
            if !(v.is_finite() && v >= f64::MIN_POSITIVE) {
                return bad(format!("{name} must be a positive finite (normal) number, got {v:e}"));
            }
        }
        if self.min_increment > self.max_increment {
            return bad(format!("min_increment {:e} exceeds max_increment {:e}", self.min_increment, self.max_increment));
        }
        if !(self.growth.is_finite() && self.growth >= 1.0) {
            return bad(format!("growth must be a finite number >= 1, got {:e}", self.growth));
        }
        if !(self.rel_tol.is_finite() && self.rel_tol >= 0.0 && self.abs_tol.is_finite() && self.abs_tol >= 0.0 && self.rel_tol + self.abs_tol > 0.0) {
            return bad(format!("rel_tol ({:e}) and abs_tol ({:e}) must be finite, >= 0 and not both 0", self.rel_tol, self.abs_tol));
        }
        if self.rel_tol > 0.0 && self.rel_tol < 1e-16 {
            return bad(format!("rel_tol {:e} is below round-off; the smallest allowed is 1e-16", self.rel_tol));
        }
        for (name, v) in [("floor_tol", self.floor_tol), ("disp_tol", self.disp_tol), ("loose_tol", self.loose_tol), ("energy_tol", self.energy_tol), ("forcing", self.forcing), ("chord_tol", self.chord_tol), ("multiplier_tol", self.multiplier_tol)] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(format!("{name} must be a finite number >= 0, got {v:e}"));
            }
        }
        Ok(())
    }
}

/// One converged load step.
#[derive(Debug, Clone, serde::Serialize)]
pub struct StepReport {
    pub step: usize,
    pub load_factor: f64,
    /// Newton iterations of the step, those of the re-solves the problem asked for
    /// ([`NonlinearProblem::end_step`]: augmented-Lagrangian updates) included.
    pub iterations: usize,
    /// Residual norm at every iteration of the final (converged) attempt, the last one converged.
    pub residual_history: Vec<f64>,
    pub cutbacks: usize,
    /// Newton iterations of this step's attempts that failed and were cut back (not in
    /// `iterations`).
    pub failed_iterations: usize,
    /// True when this step ends at one of the requested targets.
    pub is_target: bool,
    pub target_index: Option<usize>,
}

/// Summary of a whole solve.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct SolveSummary {
    pub steps: usize,
    /// Of the converged steps (see [`StepReport::iterations`]).
    pub newton_iterations: usize,
    pub cutbacks: usize,
    /// Of the attempts that failed and were cut back.
    pub failed_iterations: usize,
    pub seconds: f64,
}

/// A strategy that drives a [`NonlinearProblem`] through a sequence of load factors.
pub trait NonlinearSolver {
    /// Solve from the converged state `u` at load factor `t0` through each of `targets` in turn (up or down: loading, then unloading),
    /// calling `on_step` after every converged step. On failure `u` holds the last converged state
    /// and the error says where and why it stopped.
    fn solve_path<P: NonlinearProblem>(
        &mut self,
        problem: &mut P,
        u: &mut [f64],
        t0: f64,
        targets: &[f64],
        on_step: &mut dyn FnMut(&StepReport, &[f64], &P),
    ) -> Result<SolveSummary>;
}

/// Attempts of a load step started from [`NewtonRaphson::predictor`]; its later retries (cut
/// back) start from the secant extrapolation, in case the prediction is what fails (a coarse
/// mesh far from the answer).
pub const PREDICTED_ATTEMPTS: usize = 2;

/// The smallest scale of the secant extrapolation ([`NewtonSettings::fit_secant`]).
pub const SECANT_FIT_MIN: f64 = 0.2;

/// A fit of the last step's secant at least this good keeps the next secant whole
/// ([`NewtonSettings::fit_secant`]): scaling a good secant by its fit (0.96 to 0.99 on the torus
/// die) moved the torus's first-contact path and cost it 2 to 11 iterations.
pub const SECANT_FIT_TRUSTED: f64 = 0.9;

/// The scale of the next secant from the last step's: its increment `end - start` projected on
/// its secant `s`, (du . s) / (s . s), clamped to [SECANT_FIT_MIN, 1], 1 from SECANT_FIT_TRUSTED on.
fn secant_scale(s: &[f64], end: &[f64], start: &[f64]) -> f64 {
    let ss: f64 = s.iter().map(|x| x * x).sum();
    let ds: f64 = s.iter().zip(end.iter().zip(start)).map(|(s, (a, b))| s * (a - b)).sum();
    let fit = ds / ss;
    if std::env::var_os("STAMP_DEBUG").is_some() {
        eprintln!("  secant fit {fit:.3}");
    }
    if !(ss > 0.0 && fit.is_finite()) || fit >= SECANT_FIT_TRUSTED {
        1.0
    } else {
        fit.clamp(SECANT_FIT_MIN, 1.0)
    }
}

/// Most halvings of a Newton correction whose iterate an element refuses
/// ([`StampError::Inadmissible`]: turned inside out) before the attempt is given up (a step of
/// 2^-12 of the correction).
pub const ADMISSIBLE_HALVINGS: usize = 12;

/// Newton-Raphson with a direct linear solver, load stepping and cut-back.
pub struct NewtonRaphson<L: LinearSolver> {
    pub settings: NewtonSettings,
    pub linear: L,
    /// Called after every Newton iteration with (iteration, residual norm, force scale): for
    /// progress bars.
    pub on_iteration: Option<Box<dyn FnMut(usize, f64, f64)>>,
    /// Set (by the step callback, say, after its output failed) to end the path after the current
    /// step: `solve_path` then returns [`StampError::Problem`] "stopped on request".
    pub stop: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// Set (by a signal handler, say) to abandon the step in progress: checked before every
    /// Newton iteration; `solve_path` then returns [`StampError::Interrupted`] with `u` at the
    /// last converged state.
    pub interrupt: Option<std::sync::Arc<std::sync::atomic::AtomicBool>>,
    /// For a solve that several processes run together in lockstep (a model shared over MPI
    /// ranks, see [`crate::share`]): called with this process's [`interrupt`](Self::interrupt)
    /// flag at every check of it, returns whether any process's is set (a collective call), so
    /// that a signal that reached some processes, or reached them at different iterations, ends
    /// every process at the same check. None: the flag alone.
    pub agree_interrupt: Option<Box<dyn Fn(bool) -> bool>>,
    /// The start of each load step, when given: called with (converged steps so far, load factor
    /// of the last converged state, load factor of the step, the start to set); true when it set
    /// the start (then used instead of the secant extrapolation, see
    /// [`NonlinearProblem::start_step`]), false to keep the extrapolation. A
    /// [`crate::mesh::coarse_path::CoarsePath`], say. Not asked for the retries of a step after
    /// [`PREDICTED_ATTEMPTS`] failed attempts in a row.
    pub predictor: Option<Box<dyn FnMut(usize, f64, f64, &mut [f64]) -> bool>>,
    /// Newton iterations done so far, failed attempts included.
    iterations_done: usize,
}

impl<L: LinearSolver> NewtonRaphson<L> {
    pub fn new(linear: L, settings: NewtonSettings) -> Self {
        NewtonRaphson { settings, linear, on_iteration: None, stop: None, interrupt: None, agree_interrupt: None, predictor: None, iterations_done: 0 }
    }

    /// Newton iterations done so far by this solver, those of attempts that failed included (a
    /// path that failed returns no [`SolveSummary`]: the caller subtracts what its steps
    /// reported).
    pub fn iterations_done(&self) -> usize {
        self.iterations_done
    }

    /// Why the path must stop after `steps` converged steps with `remaining` load path left to go
    /// ([`NewtonSettings::max_steps`]); `recent`: the load factors of the last steps.
    fn over_budget(&self, steps: usize, recent: &std::collections::VecDeque<f64>, remaining: f64) -> Option<String> {
        let max = self.settings.max_steps;
        if remaining <= 0.0 || max == usize::MAX {
            return None;
        }
        if steps >= max {
            return Some(format!("max_steps = {max} steps converged with {remaining:.3e} of the load path still to go"));
        }
        let window = recent.len() - 1;
        if window < PACE_WINDOW {
            return None;
        }
        let pace = (recent[window] - recent[0]).abs() / window as f64;
        let needed = remaining / pace;
        (needed > (max - steps) as f64).then(|| {
            format!(
                "the path crawls: its last {window} steps took increments of {pace:.2e} on average; at that pace the {remaining:.3e} of the load path still to go \
                 needs about {needed:.3e} more steps, beyond max_steps = {max} (a mesh of extreme cell aspect ratio, a stiff contact: see `stamp check`)"
            )
        })
    }

    /// Whether [`interrupt`](Self::interrupt) was set (on any process, with
    /// [`agree_interrupt`](Self::agree_interrupt)).
    fn interrupted(&self) -> bool {
        let local = self.interrupt.as_ref().is_some_and(|f| f.load(std::sync::atomic::Ordering::Relaxed));
        match &self.agree_interrupt {
            Some(agree) => agree(local),
            None => local,
        }
    }

    /// Newton iterations at fixed load factor `t` starting from `u`. Returns the residual history
    /// and the iterations before the last multiplier update inside Newton (0 without one), or the
    /// reason for failure.
    /// `updates` counts the multiplier updates of the load step, inside Newton and by re-solves
    /// (at most `max_restarts` in all).
    /// `peak_energy` is the largest first-correction energy of the path's converged steps:
    /// the energy criterion compares with it too, because a step that starts from a good predictor
    /// has a first correction already at round-off.
    fn iterate<P: NonlinearProblem>(&mut self, p: &mut P, u: &mut [f64], t: f64, updates: &mut usize, peak_energy: &mut f64, last_tol: &mut f64) -> std::result::Result<(Vec<f64>, usize), (String, f64, f64)> {
        let s = &self.settings;
        let mut history = Vec::new();
        let mut du = vec![0.0; p.num_equations()];
        let mut first = f64::NAN;
        let mut last_correction = f64::INFINITY;
        let mut first_energy = f64::NAN;
        // the first correction's energy of this solve, kept through the restarts after a
        // multiplier update or an active-set change (which reset first_energy)
        let mut solve_first_energy = f64::NAN;
        let mut last_energy = f64::INFINITY;
        let debug = std::env::var_os("STAMP_DEBUG").is_some();
        let mut scaled = if s.line_search_steps > 0 { vec![0.0; du.len()] } else { Vec::new() };
        let mut trial = if s.line_search_steps > 0 { u.to_vec() } else { Vec::new() };
        // the residual at u found by the line search (its tangent not yet assembled)
        let mut known: Option<Evaluation> = None;
        // the linear solver holds the factorisation of an earlier iterate of this solve
        let mut factored = false;
        // iterations in a row, up to this one, whose active set changed
        let mut changing = 0;
        // the last correction was a chord step; chord steps taken (for the debug output)
        let mut last_chord = false;
        let mut chords = 0usize;
        // the iteration from which the budget of max_iterations counts: the last multiplier
        // update inside Newton (a re-solve of the step after end_step had a budget of its own)
        let mut budget_start = 0;
        // `du` holds the correction added to `u` at the end of the last iteration
        let mut applied = false;
        for it in 0.. {
            if it > 0 {
                self.iterations_done += 1;
            }
            if self.interrupted() {
                return Err(("interrupted".into(), history.last().copied().unwrap_or(f64::NAN), *last_tol));
            }
            let (mut ev, mut with_tangent) = match known.take() {
                Some(ev) => (ev, false),
                None => {
                    let mut ev = p.evaluate(u, t, true);
                    // A correction that turned an element inside out (a Newton step from a
                    // contact state far from the answer: points released or taken in wholesale
                    // swing the plate through the punch) is halved back towards the last
                    // admissible iterate until the state is admissible, instead of abandoning
                    // the load step for a cut-back.
                    let mut halvings = 0;
                    while applied && halvings < ADMISSIBLE_HALVINGS && matches!(ev, Err(StampError::Inadmissible { .. })) {
                        for x in du.iter_mut() {
                            *x *= -0.5;
                        }
                        p.add_increment(u, &du);
                        for x in du.iter_mut() {
                            *x = -*x;
                        }
                        halvings += 1;
                        if debug {
                            eprintln!("  inadmissible iterate: correction halved ({halvings})");
                        }
                        ev = p.evaluate(u, t, true);
                    }
                    (ev.map_err(|e| (e.to_string(), history.last().copied().unwrap_or(f64::NAN), *last_tol))?, true)
                }
            };
            applied = false;
            // augmented Lagrangian inside Newton: once the active set stopped changing and |R| is
            // small, the multipliers are updated here and Newton goes on from this iterate (the
            // update moves the solution a little; the last iterations converge both). The
            // residual evaluated again replaces this one: no iteration is counted for it.
            if s.multiplier_tol > 0.0 && *updates < s.max_restarts && ev.active_changes == 0 && ev.residual_norm <= s.multiplier_tol * ev.force_scale && p.update_multipliers() {
                *updates += 1;
                budget_start = it;
                ev = p.evaluate(u, t, true).map_err(|e| (e.to_string(), history.last().copied().unwrap_or(f64::NAN), *last_tol))?;
                with_tangent = true;
                if debug {
                    eprintln!("  multipliers updated: |R|={:.3e} changes={}", ev.residual_norm, ev.active_changes);
                }
                last_energy = f64::INFINITY;
                first_energy = f64::NAN;
                last_correction = f64::INFINITY;
            }
            // the tolerance of this iterate (that of the last one when the force scale is not a number)
            let tol = if ev.force_scale.is_finite() { s.rel_tol * ev.force_scale + s.abs_tol } else { *last_tol };
            *last_tol = tol;
            history.push(ev.residual_norm);
            // a chord step may follow a Newton step, or a chord step that reduced |R| a hundredfold
            let chord_allowed = !last_chord || (history.len() > 1 && ev.residual_norm <= 1e-2 * history[history.len() - 2]);
            if debug {
                eprintln!("t={t:.6e} it={it} |R|={:.3e} scale={:.3e} changes={} energy={:.3e}/{:.3e} chords={chords}", ev.residual_norm, ev.force_scale, ev.active_changes, last_energy, first_energy);
            }
            if let Some(cb) = self.on_iteration.as_mut() {
                cb(it, ev.residual_norm, ev.force_scale);
            }
            if !ev.residual_norm.is_finite() || !ev.force_scale.is_finite() {
                let what = if ev.residual_norm.is_nan() || ev.force_scale.is_nan() { "NaN" } else { "infinite" };
                return Err((format!("the residual became {what} at iteration {it}"), ev.residual_norm, tol));
            }
            if it == 0 {
                first = ev.residual_norm.max(tol);
            }
            let stalled = it > 0 && ev.residual_norm > 0.5 * history[history.len() - 2];
            let u_max = u.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let fixed = last_correction <= s.disp_tol * u_max && ev.residual_norm <= s.loose_tol * ev.force_scale;
            // a step that starts at the solution (a predictor that hit it: first residual within the
            // energy criterion's bound and first correction at round-off) measures its energies
            // against the path's; a step that starts farther off (an augmented-Lagrangian restart
            // crawling along a kink) must converge on its own terms
            let at_solution = history[0] <= 1e2 * s.loose_tol * ev.force_scale && first_energy < s.energy_tol * *peak_energy;
            let reference = if at_solution { *peak_energy } else { first_energy };
            let own_energy = last_energy <= s.energy_tol * reference && ev.residual_norm <= 1e2 * s.loose_tol * ev.force_scale;
            // a good predictor leaves a first correction far below the path's but not at round-off;
            // the next one is (quadratic convergence): measured against the path, with the tight
            // bound on |R| and only once |R| truly stalls (a damped crawl along a kink halves |R| at
            // every iteration and is not converged)
            let flat = it > 0 && ev.residual_norm > 0.8 * history[history.len() - 2];
            let path_energy = flat && last_energy <= s.energy_tol * *peak_energy && ev.residual_norm <= s.loose_tol * ev.force_scale;
            let energy = it > 1 && stalled && (own_energy || path_energy);
            // near the round-off floor after a correction whose energy fell below energy_tol of the
            // first: Newton has converged quadratically, and a further iteration can only confirm
            // the stall (the penalty's |R| floor lies above rel_tol, and on fine meshes above
            // floor_tol)
            let settled = it > 1 && ev.residual_norm <= s.loose_tol * ev.force_scale && last_energy <= s.energy_tol * first_energy.max(solve_first_energy);
            if ev.residual_norm <= tol || (stalled && ev.residual_norm <= s.floor_tol * ev.force_scale) || settled || fixed || energy {
                if ev.active_changes == 0 {
                    if first_energy.is_finite() {
                        *peak_energy = peak_energy.max(first_energy);
                    }
                    return Ok((history, budget_start));
                }
                if p.update_active_set() > 0 && it - budget_start < s.max_iterations {
                    // converged on the old set: re-solve with the new one (whose tangent is new)
                    factored = false;
                    last_energy = f64::INFINITY;
                    first_energy = f64::NAN;
                    last_correction = f64::INFINITY;
                    continue;
                }
            }
            changing = if ev.active_changes > 0 { changing + 1 } else { 0 };
            if s.cycling_after > 0 && it >= s.cycling_after && changing >= CYCLING_WINDOW {
                // cycling without progress: the smallest |R| of the window's second half is no
                // better than half that of its first half
                let window = &history[history.len() - CYCLING_WINDOW..];
                let (older, newer) = window.split_at(CYCLING_WINDOW / 2);
                let least = |h: &[f64]| h.iter().cloned().fold(f64::INFINITY, f64::min);
                if least(newer) > 0.5 * least(older) {
                    return Err((format!("the active set changed at each of the last {changing} iterations without reducing |R| (cycling)"), ev.residual_norm, tol));
                }
            }
            if it - budget_start == s.max_iterations {
                let why = if ev.active_changes > 0 { " (the active set kept changing)" } else { "" };
                return Err((format!("no convergence in {} iterations{why}", s.max_iterations), ev.residual_norm, tol));
            }
            if ev.residual_norm > 1e30 * first {
                return Err(("the residual diverged".into(), ev.residual_norm, tol));
            }
            // Near the solution the tangent hardly changes from one iterate to the next: a chord
            // step (modified Newton) with the factorisation of the last iterate contracts |R| as
            // well as a Newton step would, for one solve instead of a tangent and a
            // factorisation; it aims at a tenth of the tolerance. A chord step that does not
            // reduce |R| a hundredfold is followed by a Newton step.
            let chord = factored
                && chord_allowed
                && ev.active_changes == 0
                && ev.residual_norm <= s.chord_tol * ev.force_scale
                && ev.residual_norm > 0.0;
            du.copy_from_slice(p.residual());
            if chord {
                let rtol = (0.1 * tol / ev.residual_norm).clamp(1e-14, 0.1);
                self.linear.solve_in_place_to(&mut du, rtol).map_err(|e| (e.to_string(), ev.residual_norm, tol))?;
                chords += 1;
            } else {
                if !with_tangent {
                    p.evaluate(u, t, true).map_err(|e| (e.to_string(), ev.residual_norm, tol))?;
                    du.copy_from_slice(p.residual());
                }
                self.linear.factorize_preconditioned(p.matrix(), p.preconditioner()).map_err(|e| (e.to_string(), ev.residual_norm, tol))?;
                factored = true;
                // inexact Newton (Dembo, Eisenstat & Steihaug 1982; Eisenstat & Walker 1996): a
                // linear residual of eta |R|, eta <= |R| / force scale, keeps the convergence
                // quadratic, and an iterative linear solver stops early while |R| is large
                let forcing = s.forcing.min(ev.residual_norm / ev.force_scale.max(f64::MIN_POSITIVE));
                self.linear.solve_in_place_to(&mut du, forcing).map_err(|e| (e.to_string(), ev.residual_norm, tol))?;
            }
            last_chord = chord;
            for x in du.iter_mut() {
                *x = -*x;
            }
            if !chord && s.resolve_contact {
                let rows = p.constraint_rows().map_err(|e| (e.to_string(), ev.residual_norm, tol))?;
                if !rows.is_empty() {
                    let mut report = Resolve::default();
                    let changes = resolve(&mut self.linear, &rows, &mut du, &mut report).map_err(|e| (e.to_string(), ev.residual_norm, tol))?;
                    if debug {
                        eprintln!("  linearised contact: {} rounds, {} columns, settled {}, {} changes", report.rounds, report.columns, report.settled, report.changed);
                    }
                    for (id, active) in changes {
                        p.set_constraint_state(id, active);
                    }
                }
            }
            last_correction = du.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            last_energy = du.iter().zip(p.residual()).map(|(a, b)| a * b).sum::<f64>().abs();
            if first_energy.is_nan() {
                first_energy = last_energy;
            }
            if solve_first_energy.is_nan() {
                solve_first_energy = last_energy;
            }
            // backtracking line search on |R|: keeps a far-off predictor from pushing the body deep
            // into the punch (and the active set from swinging wholesale)
            let r0 = ev.residual_norm;
            let mut alpha = 1.0;
            for _ in 0..s.line_search_steps {
                trial.copy_from_slice(u);
                for (d, x) in scaled.iter_mut().zip(&du) {
                    *d = alpha * x;
                }
                p.add_increment(&mut trial, &scaled);
                let e = p.evaluate(&trial, t, false);
                if debug {
                    match &e {
                        Ok(e) => eprintln!("  line search alpha={alpha} |R|={:.3e} changes={}", e.residual_norm, e.active_changes),
                        Err(err) => eprintln!("  line search alpha={alpha} refused: {err}"),
                    }
                }
                let e = e.ok().filter(|e| e.residual_norm.is_finite());
                if let Some(e) = e.filter(|e| e.residual_norm <= (1.0 - 1e-4 * alpha) * r0) {
                    // accepted: the next iterate is this trial, whose residual is known
                    known = Some(e);
                    break;
                }
                alpha *= 0.5;
            }
            if alpha < 1.0 {
                for x in du.iter_mut() {
                    *x *= alpha.max(0.5f64.powi(s.line_search_steps as i32));
                }
            }
            p.add_increment(u, &du);
            applied = true;
        }
        Err((format!("no convergence in {} iterations", s.max_iterations), history.last().copied().unwrap_or(f64::NAN), *last_tol))
    }
}

/// The length of the path through `targets` in turn from the first: sum |t_{k+1} - t_k|.
fn path_length(targets: &[f64]) -> f64 {
    targets.windows(2).map(|w| (w[1] - w[0]).abs()).sum()
}

impl<L: LinearSolver> NonlinearSolver for NewtonRaphson<L> {
    fn solve_path<P: NonlinearProblem>(
        &mut self,
        p: &mut P,
        u: &mut [f64],
        t0: f64,
        targets: &[f64],
        on_step: &mut dyn FnMut(&StepReport, &[f64], &P),
    ) -> Result<SolveSummary> {
        let start = Instant::now();
        self.settings.validate()?;
        p.want_preconditioner(self.linear.uses_preconditioner());
        // the tolerance of the last evaluation, for an error whose own iterate has none
        let mut last_tol = self.settings.abs_tol;
        let mut summary = SolveSummary::default();
        let mut t = t0;
        let mut trial = u.to_vec();
        // the converged state before the last one, for the predictor
        let mut previous: Option<(Vec<f64>, f64)> = None;
        // the secant of the step in progress, and the scale of the next one (see fit_secant)
        let mut secant: Vec<f64> = Vec::new();
        let mut theta = 1.0f64;
        let mut peak_energy = 0.0f64;
        let first_span = targets.first().map(|&x| (x - t0).abs()).unwrap_or(1.0);
        let mut dt = (self.settings.initial_increment * first_span).min(self.settings.max_increment);
        // the load factors of the last PACE_WINDOW converged steps (and the start), for max_steps
        let mut recent: std::collections::VecDeque<f64> = std::collections::VecDeque::from([t0]);
        p.checkpoint();
        for (ti, &target) in targets.iter().enumerate() {
            if !target.is_finite() {
                return Err(StampError::Problem(format!("load target {target} is not a finite number")));
            }
            // Targets may go up or down (loading, then unloading): step towards each in turn.
            let mut cutbacks_in_row = 0;
            // iterations of the attempts of this step that failed
            let mut failed_iterations = 0;
            while t != target {
                if self.interrupted() {
                    return Err(StampError::Interrupted { steps: summary.steps, load_factor: t });
                }
                let remaining = target - t;
                let step_t = if dt >= remaining.abs() * (1.0 - 1e-12) { target } else { t + dt.copysign(remaining) };
                if step_t == t || !step_t.is_finite() {
                    // an increment below the round-off of t would repeat the same step for ever
                    return Err(StampError::Problem(format!(
                        "the load increment {dt:e} does not change the load factor {t:e} (round-off); raise min_increment"
                    )));
                }
                trial.copy_from_slice(u);
                secant.clear();
                if let (true, Some((u_prev, t_prev))) = (self.settings.extrapolate, previous.as_ref()) {
                    let ratio = (step_t - t) / (t - t_prev);
                    if ratio > 0.0 && ratio.is_finite() {
                        secant.extend(u.iter().zip(u_prev).map(|(a, b)| ratio * (a - b)));
                        for (x, d) in trial.iter_mut().zip(&secant) {
                            *x += theta * d;
                        }
                    }
                }
                // a step the prediction failed twice in a row retries from the extrapolation
                let trusted = cutbacks_in_row < PREDICTED_ATTEMPTS;
                let predicted = trusted && self.predictor.as_mut().is_some_and(|predict| predict(summary.steps, t, step_t, &mut trial));
                p.apply_prescribed(&mut trial, step_t);
                p.start_step(predicted);
                // multiplier updates of this attempt, inside Newton and by re-solves
                let mut updates = 0;
                // iterations of the re-solves of this step before the last one
                let mut restart_iterations = 0;
                let attempt_start = self.iterations_done;
                let result = loop {
                    match self.iterate(p, &mut trial, step_t, &mut updates, &mut peak_energy, &mut last_tol) {
                        Ok((h, before_update)) => {
                            if p.end_step(&trial, step_t) {
                                // the problem's own condition (the augmented Lagrangian's penetration
                                // tolerance) does not hold yet: solve again, but never call the step
                                // converged while it does not hold
                                if updates < self.settings.max_restarts {
                                    updates += 1;
                                    summary.newton_iterations += h.len() - 1;
                                    restart_iterations += h.len() - 1;
                                    continue;
                                }
                                let r = h.last().copied().unwrap_or(f64::NAN);
                                break Err((
                                    format!("the contact constraints were still violated beyond the penetration tolerance after {} augmented-Lagrangian updates", self.settings.max_restarts),
                                    r,
                                    last_tol,
                                ));
                            }
                            break Ok((h, before_update));
                        }
                        Err(e) => break Err(e),
                    }
                };
                match result {
                    Ok((history, before_update)) => {
                        // the iterations since the last multiplier update, in the last solve, decide
                        // the growth of the increment (as before re-solves and updates inside
                        // Newton were counted), the report counts them all
                        let iterations = history.len() - 1;
                        let last_round = iterations - before_update;
                        summary.newton_iterations += iterations;
                        summary.steps += 1;
                        if self.settings.fit_secant && !secant.is_empty() {
                            theta = secant_scale(&secant, &trial, u);
                        }
                        match previous.as_mut() {
                            Some((u_prev, t_prev)) => {
                                u_prev.copy_from_slice(u);
                                *t_prev = t;
                            }
                            None => previous = Some((u.to_vec(), t)),
                        }
                        u.copy_from_slice(&trial);
                        t = step_t;
                        p.checkpoint();
                        let is_target = step_t == target;
                        let report = StepReport {
                            step: summary.steps,
                            load_factor: t,
                            iterations: restart_iterations + iterations,
                            residual_history: history,
                            cutbacks: cutbacks_in_row,
                            failed_iterations,
                            is_target,
                            target_index: is_target.then_some(ti),
                        };
                        on_step(&report, u, p);
                        recent.push_back(t);
                        if recent.len() > PACE_WINDOW + 1 {
                            recent.pop_front();
                        }
                        if let Some(reason) = self.over_budget(summary.steps, &recent, (target - t).abs() + path_length(&targets[ti..])) {
                            summary.seconds = start.elapsed().as_secs_f64();
                            return Err(StampError::StepLimit { steps: summary.steps, load_factor: t, reason });
                        }
                        if self.stop.as_ref().is_some_and(|s| s.load(std::sync::atomic::Ordering::Relaxed)) {
                            summary.seconds = start.elapsed().as_secs_f64();
                            return Err(StampError::Problem(format!("stopped on request after load step {} (load factor {t:.6e})", summary.steps)));
                        }
                        cutbacks_in_row = 0;
                        failed_iterations = 0;
                        if last_round <= self.settings.easy_iterations {
                            dt = (dt * self.settings.growth).min(self.settings.max_increment);
                        }
                    }
                    Err((reason, residual, tolerance)) => {
                        if std::env::var_os("STAMP_DEBUG").is_some() {
                            eprintln!("  attempt failed: {reason}");
                        }
                        let spent = self.iterations_done - attempt_start;
                        failed_iterations += spent;
                        summary.failed_iterations += spent;
                        p.restore();
                        if self.interrupted() {
                            return Err(StampError::Interrupted { steps: summary.steps, load_factor: t });
                        }
                        cutbacks_in_row += 1;
                        summary.cutbacks += 1;
                        dt = 0.5 * (step_t - t).abs();
                        if cutbacks_in_row > self.settings.max_cutbacks || dt < self.settings.min_increment {
                            summary.seconds = start.elapsed().as_secs_f64();
                            return Err(StampError::NoConvergence {
                                step: summary.steps + 1,
                                load_factor: step_t,
                                cutbacks: cutbacks_in_row - 1,
                                residual,
                                tolerance,
                                reason: format!("{reason}; last converged load factor {t:.6e}"),
                            });
                        }
                    }
                }
            }
        }
        summary.seconds = start.elapsed().as_secs_f64();
        Ok(summary)
    }
}

#[cfg(test)]
mod tests {
    //! What Newton calls converged holds, and what it reports is the truth: a one-unknown problem
    //! R(u, t) = u - t whose residual can be made NaN past a load factor, and whose end_step can
    //! refuse every converged state (an augmented-Lagrangian tolerance that is never met).
    use super::*;
    use crate::linalg::linear_solver::SparseLu;
    use faer::sparse::SymbolicSparseColMatRef;

    struct Line {
        residual: [f64; 1],
        col_ptr: [usize; 2],
        row_idx: [usize; 1],
        tangent: [f64; 1],
        /// The residual is NaN for t above this.
        nan_above: f64,
        /// end_step asks for another solve every time.
        never_satisfied: bool,
        restarts: usize,
        /// end_step asks for this many re-solves in all, shifting the solution by 0.01 each time
        /// (as an augmented-Lagrangian update moves the contact forces).
        extra_solves: usize,
        shift: f64,
        /// update_multipliers shifts the solution by 0.01 this many times in all (an
        /// augmented-Lagrangian update inside Newton); |R| at each call that did.
        multiplier_updates: usize,
        updated_at: Vec<f64>,
    }

    impl Line {
        fn new() -> Self {
            Line { residual: [0.0], col_ptr: [0, 1], row_idx: [0], tangent: [1.0], nan_above: f64::INFINITY, never_satisfied: false, restarts: 0, extra_solves: 0, shift: 0.0, multiplier_updates: 0, updated_at: Vec::new() }
        }
    }

    impl NonlinearProblem for Line {
        fn num_dofs(&self) -> usize {
            1
        }
        fn num_equations(&self) -> usize {
            1
        }
        fn apply_prescribed(&self, _u: &mut [f64], _t: f64) {}
        fn evaluate(&mut self, u: &[f64], t: f64, _with_tangent: bool) -> Result<Evaluation> {
            self.residual[0] = if t > self.nan_above { f64::NAN } else { u[0] - t - self.shift };
            Ok(Evaluation { residual_norm: self.residual[0].abs(), force_scale: 1.0, active_changes: 0 })
        }
        fn residual(&self) -> &[f64] {
            &self.residual
        }
        fn matrix(&self) -> SparseColMatRef<'_, usize, f64> {
            SparseColMatRef::new(SymbolicSparseColMatRef::new_checked(1, 1, &self.col_ptr, None, &self.row_idx), &self.tangent)
        }
        fn add_increment(&self, u: &mut [f64], du: &[f64]) {
            u[0] += du[0];
        }
        fn update_multipliers(&mut self) -> bool {
            if self.updated_at.len() == self.multiplier_updates {
                return false;
            }
            self.updated_at.push(self.residual[0].abs());
            self.shift += 0.01;
            true
        }
        fn end_step(&mut self, _u: &[f64], _t: f64) -> bool {
            self.restarts += 1;
            if self.restarts <= self.extra_solves {
                self.shift += 0.01;
                return true;
            }
            self.never_satisfied
        }
    }

    fn settings() -> NewtonSettings {
        NewtonSettings { max_increment: 0.25, max_cutbacks: 2, ..NewtonSettings::default() }
    }

    /// A predictor that hits the answer (u = t) starts every step converged: no iteration; it
    /// sees each step's start and end load factors, with the converged steps so far, and a step
    /// it declines (false) starts from the secant extrapolation.
    #[test]
    fn a_predictor_that_hits_the_answer_saves_every_iteration() {
        let mut newton = NewtonRaphson::new(SparseLu::new(), settings());
        let calls = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
        let seen = calls.clone();
        newton.predictor = Some(Box::new(move |steps, from, to, u| {
            seen.borrow_mut().push((steps, from, to));
            u[0] = to;
            true
        }));
        let mut p = Line::new();
        let mut u = vec![0.0];
        let mut iterations = Vec::new();
        newton.solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |r, _, _| iterations.push(r.iterations)).unwrap();
        assert_eq!(iterations, vec![0; 4], "four steps of 0.25, each started at its answer");
        assert_eq!(*calls.borrow(), vec![(0, 0.0, 0.25), (1, 0.25, 0.5), (2, 0.5, 0.75), (3, 0.75, 1.0)]);
        assert!((u[0] - 1.0).abs() < 1e-12);
        // declined: the first step starts from u = 0 (one iteration), the others from the exact
        // secant of the linear path
        newton.predictor = Some(Box::new(|_, _, _, _| false));
        let mut u = vec![0.0];
        let mut iterations = Vec::new();
        newton.solve_path(&mut Line::new(), &mut u, 0.0, &[1.0], &mut |r, _, _| iterations.push(r.iterations)).unwrap();
        assert_eq!(iterations[0], 1);
    }

    /// A prediction that makes the residual NaN fails the step; after PREDICTED_ATTEMPTS such
    /// attempts the retries start from the secant extrapolation and the path goes on.
    #[test]
    fn a_failing_prediction_is_dropped_after_two_attempts() {
        let mut newton = NewtonRaphson::new(SparseLu::new(), NewtonSettings { max_increment: 1.0, ..settings() });
        let calls = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
        let seen = calls.clone();
        // the first step's predictions are NaN, the later steps are not predicted
        newton.predictor = Some(Box::new(move |steps, from, to, u| {
            seen.borrow_mut().push((steps, from, to));
            if steps == 0 {
                u[0] = f64::NAN;
            }
            steps == 0
        }));
        let mut u = vec![0.0];
        let summary = newton.solve_path(&mut Line::new(), &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
        assert_eq!(PREDICTED_ATTEMPTS, 2);
        // the first step was asked for in full and in half, then no more: the quarter step
        // converged from the secant start
        let first: Vec<_> = calls.borrow().iter().filter(|c| c.0 == 0).cloned().collect();
        assert_eq!(first, vec![(0, 0.0, 1.0), (0, 0.0, 0.5)]);
        // the next call is the next step's, from the quarter step's converged 0.25
        assert_eq!((calls.borrow()[2].0, calls.borrow()[2].1), (1, 0.25));
        assert_eq!(summary.cutbacks, 2);
        assert!((u[0] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn settings_without_iterations_or_with_crossed_increments_are_refused() {
        assert!(settings().validate().is_ok());
        let e = NewtonSettings { max_iterations: 0, ..settings() }.validate().unwrap_err().to_string();
        assert!(e.contains("max_iterations must be from 1"), "{e}");
        let e = NewtonSettings { min_increment: 0.5, max_increment: 0.2, ..settings() }.validate().unwrap_err().to_string();
        assert!(e.contains("min_increment 5e-1 exceeds max_increment 2e-1"), "{e}");
        let e = NewtonSettings { initial_increment: 5e-324, ..settings() }.validate().unwrap_err().to_string();
        assert!(e.contains("initial_increment"), "{e}");
        // solve_path validates too: no iteration is run
        let mut p = Line::new();
        let mut u = [0.0];
        let r = NewtonRaphson::new(SparseLu::new(), NewtonSettings { max_iterations: 0, ..settings() }).solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |_, _, _| {});
        assert!(r.unwrap_err().to_string().contains("max_iterations"));
    }

    #[test]
    fn a_nan_residual_is_reported_as_such_with_the_real_tolerance() {
        let mut p = Line { nan_above: 0.5, ..Line::new() };
        let mut u = [0.0];
        let mut steps = Vec::new();
        let e = NewtonRaphson::new(SparseLu::new(), settings()).solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |r, _, _| steps.push(r.load_factor)).unwrap_err();
        assert_eq!(steps, vec![0.25, 0.5]);
        let msg = e.to_string();
        assert!(msg.contains("the residual became NaN at iteration 0"), "{msg}");
        match e {
            StampError::NoConvergence { tolerance, .. } => {
                // rel_tol * force scale 1 + abs_tol
                let want = 1e-10 + 1e-14;
                assert!((tolerance - want).abs() < 1e-20, "tolerance {tolerance:e}, want {want:e}");
            }
            e => panic!("{e}"),
        }
        assert!(!msg.contains("tolerance 0.000e0"), "{msg}");
    }

    #[test]
    fn a_step_whose_end_condition_never_holds_is_not_converged() {
        let mut p = Line { never_satisfied: true, ..Line::new() };
        let mut u = [0.0];
        let mut converged = 0;
        let s = NewtonSettings { max_restarts: 3, max_cutbacks: 1, ..settings() };
        let e = NewtonRaphson::new(SparseLu::new(), s).solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |_, _, _| converged += 1).unwrap_err();
        assert_eq!(converged, 0, "no step may be reported converged");
        let msg = e.to_string();
        assert!(msg.contains("still violated") && msg.contains("after 3 augmented-Lagrangian updates"), "{msg}");
        // two attempts (one cut-back), each with 1 + 3 solves asking end_step
        assert_eq!(p.restarts, 8);
    }

    #[test]
    fn a_path_is_stopped_by_its_step_budget_or_its_pace() {
        // increments of 1e-3 towards 1: the pace of the first 50 steps needs 950 more, beyond 100
        let s = NewtonSettings { max_increment: 1e-3, min_increment: 1e-4, max_steps: 100, ..settings() };
        let (mut p, mut u, mut steps) = (Line::new(), [0.0], 0);
        let e = NewtonRaphson::new(SparseLu::new(), s.clone()).solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |_, _, _| steps += 1).unwrap_err();
        assert!(matches!(e, StampError::StepLimit { steps: 50, .. }) && e.to_string().contains("crawls"), "{e}");
        assert_eq!(steps, 50);
        assert!((u[0] - 0.05).abs() < 1e-9, "{u:?}");
        // the budget itself: 20 steps of the 30 a path of 0.03 needs
        let (mut p, mut u) = (Line::new(), [0.0]);
        let e = NewtonRaphson::new(SparseLu::new(), NewtonSettings { max_steps: 20, ..s.clone() }).solve_path(&mut p, &mut u, 0.0, &[0.03], &mut |_, _, _| {}).unwrap_err();
        assert!(matches!(e, StampError::StepLimit { steps: 20, .. }) && e.to_string().contains("max_steps = 20 steps converged"), "{e}");
        // a path that fits is not stopped
        let (mut p, mut u) = (Line::new(), [0.0]);
        NewtonRaphson::new(SparseLu::new(), NewtonSettings { max_steps: 30, ..s }).solve_path(&mut p, &mut u, 0.0, &[0.03], &mut |_, _, _| {}).unwrap();
    }

    #[test]
    fn an_interrupt_abandons_the_step_in_progress() {
        // set at the first Newton iteration of the first step
        let mut p = Line::new();
        let mut u = [0.0];
        let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let mut newton = NewtonRaphson::new(SparseLu::new(), settings());
        newton.interrupt = Some(flag.clone());
        let f = flag.clone();
        newton.on_iteration = Some(Box::new(move |_, _, _| f.store(true, std::sync::atomic::Ordering::Relaxed)));
        let mut steps = Vec::new();
        let e = newton.solve_path(&mut p, &mut u, 0.0, &[0.25, 0.5], &mut |r, _, _| steps.push(r.load_factor)).unwrap_err();
        assert!(matches!(e, StampError::Interrupted { steps: 0, load_factor: 0.0 }), "{e}");
        assert!(steps.is_empty() && u[0] == 0.0, "{steps:?} {u:?}");
        assert!(e.to_string().contains("interrupted after load step 0"), "{e}");
    }

    /// With `agree_interrupt`, an interrupt set on another process only (the hook says so at
    /// the third check) ends this one's path at that check too, and every check asks the hook,
    /// flag or no flag.
    #[test]
    fn an_interrupt_agreed_with_other_processes_ends_the_path_at_the_same_check() {
        let mut p = Line::new();
        let mut u = [0.0];
        let mut newton = NewtonRaphson::new(SparseLu::new(), settings());
        let checks = std::sync::Arc::new(std::sync::atomic::AtomicUsize::new(0));
        let c = checks.clone();
        newton.agree_interrupt = Some(Box::new(move |local| {
            assert!(!local, "no flag on this process");
            c.fetch_add(1, std::sync::atomic::Ordering::Relaxed) + 1 >= 3
        }));
        let mut steps = Vec::new();
        let e = newton.solve_path(&mut p, &mut u, 0.0, &[0.25, 0.5], &mut |r, _, _| steps.push(r.load_factor)).unwrap_err();
        assert!(matches!(e, StampError::Interrupted { steps: 0, load_factor: 0.0 }), "{e}");
        // before the step, iterations 0 and 1 (interrupted), and after the abandoned attempt
        assert_eq!(checks.load(std::sync::atomic::Ordering::Relaxed), 4);
        assert!(steps.is_empty() && u[0] == 0.0, "{steps:?} {u:?}");
        // without the hook's say the same path converges
        let (mut p, mut u) = (Line::new(), [0.0]);
        NewtonRaphson::new(SparseLu::new(), settings()).solve_path(&mut p, &mut u, 0.0, &[0.25, 0.5], &mut |_, _, _| {}).unwrap();
    }

    #[test]
    fn a_step_reports_the_iterations_of_its_re_solves_too() {
        let mut p = Line { extra_solves: 2, ..Line::new() };
        let mut u = [0.0];
        let mut reports = Vec::new();
        let summary = NewtonRaphson::new(SparseLu::new(), settings()).solve_path(&mut p, &mut u, 0.0, &[0.25], &mut |r, _, _| reports.push(r.clone())).unwrap();
        assert_eq!(reports.len(), 1);
        let r = &reports[0];
        // each of the three solves (the first and two re-solves) takes a Newton iteration
        assert!(r.iterations >= 3, "{r:?}");
        assert!(r.iterations > r.residual_history.len() - 1, "the last solve's history only: {r:?}");
        assert_eq!(r.iterations, summary.newton_iterations);
        assert!((u[0] - 0.27).abs() < 1e-12, "{}", u[0]);
    }

    #[test]
    fn each_multiplier_update_inside_newton_gets_its_own_iteration_budget() {
        // one iteration per solve: each of the three updates needs one more, as a re-solve would
        let mut p = Line { multiplier_updates: 3, ..Line::new() };
        let mut u = [0.0];
        let s = NewtonSettings { max_iterations: 1, ..settings() };
        let summary = NewtonRaphson::new(SparseLu::new(), s).solve_path(&mut p, &mut u, 0.0, &[0.25], &mut |_, _, _| {}).unwrap();
        assert_eq!(p.updated_at.len(), 3);
        assert_eq!(summary.newton_iterations, 4);
        assert!((u[0] - 0.28).abs() < 1e-12, "{}", u[0]);
        // max_restarts bounds the updates inside Newton and the re-solves together: two inside,
        // then end_step's shift and a re-solve make three
        let mut p = Line { multiplier_updates: 2, extra_solves: 1, ..Line::new() };
        let mut u = [0.0];
        let s = NewtonSettings { max_restarts: 3, ..settings() };
        NewtonRaphson::new(SparseLu::new(), s).solve_path(&mut p, &mut u, 0.0, &[0.25], &mut |_, _, _| {}).unwrap();
        assert_eq!((p.updated_at.len(), p.restarts), (2, 2));
        assert!((u[0] - 0.28).abs() < 1e-12, "{}", u[0]);
        // with 2 allowed, the re-solve is refused: the step fails with the count
        let mut p = Line { multiplier_updates: 2, extra_solves: 1, ..Line::new() };
        let mut u = [0.0];
        let s = NewtonSettings { max_restarts: 2, max_cutbacks: 0, ..settings() };
        let e = NewtonRaphson::new(SparseLu::new(), s).solve_path(&mut p, &mut u, 0.0, &[0.25], &mut |_, _, _| {}).unwrap_err().to_string();
        assert!(e.contains("still violated") && e.contains("after 2 augmented-Lagrangian updates"), "{e}");
        // a solve that never meets its end condition stops at max_restarts updates in all
        let mut p = Line { multiplier_updates: usize::MAX, never_satisfied: true, ..Line::new() };
        let mut u = [0.0];
        let s = NewtonSettings { max_restarts: 5, max_cutbacks: 0, ..settings() };
        assert!(NewtonRaphson::new(SparseLu::new(), s).solve_path(&mut p, &mut u, 0.0, &[0.25], &mut |_, _, _| {}).is_err());
        assert_eq!(p.updated_at.len(), 5);
    }

    #[test]
    fn multipliers_updated_inside_newton_need_no_re_solve() {
        let mut p = Line { multiplier_updates: 3, ..Line::new() };
        let mut u = [0.0];
        let mut reports = Vec::new();
        let summary = NewtonRaphson::new(SparseLu::new(), settings()).solve_path(&mut p, &mut u, 0.0, &[0.25], &mut |r, _, _| reports.push(r.clone())).unwrap();
        // the three updates moved the solution, inside one solve: end_step was asked once
        assert_eq!(p.updated_at.len(), 3);
        assert!((u[0] - 0.28).abs() < 1e-12, "{}", u[0]);
        assert_eq!(p.restarts, 1, "no re-solve of the step");
        // only once |R| <= multiplier_tol * force scale (1): never at the first residual 0.25
        let tol = NewtonSettings::default().multiplier_tol;
        assert!(p.updated_at.iter().all(|&r| r <= tol), "{:?}", p.updated_at);
        // each update costs one Newton iteration here (a linear problem), counted once
        assert_eq!(reports[0].iterations, 4);
        assert_eq!(summary.newton_iterations, 4);
        // multiplier_tol = 0: no update inside Newton, the same answer through end_step's re-solves
        let mut p = Line { extra_solves: 3, multiplier_updates: 3, ..Line::new() };
        let mut u = [0.0];
        let s = NewtonSettings { multiplier_tol: 0.0, ..settings() };
        NewtonRaphson::new(SparseLu::new(), s).solve_path(&mut p, &mut u, 0.0, &[0.25], &mut |_, _, _| {}).unwrap();
        assert!(p.updated_at.is_empty());
        assert_eq!(p.restarts, 4);
        assert!((u[0] - 0.28).abs() < 1e-12, "{}", u[0]);
        // a negative or NaN tolerance is refused
        let e = NewtonSettings { multiplier_tol: f64::NAN, ..settings() }.validate().unwrap_err().to_string();
        assert!(e.contains("multiplier_tol"), "{e}");
    }

    #[test]
    fn a_stop_request_ends_the_path_after_the_step() {
        let mut p = Line::new();
        let mut u = [0.0];
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let mut newton = NewtonRaphson::new(SparseLu::new(), settings());
        newton.stop = Some(stop.clone());
        let mut steps = 0;
        let e = newton
            .solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |r, _, _| {
                steps += 1;
                if r.step == 2 {
                    stop.store(true, std::sync::atomic::Ordering::Relaxed);
                }
            })
            .unwrap_err();
        assert_eq!(steps, 2);
        assert!(e.to_string().contains("stopped on request after load step 2"), "{e}");
        assert!((u[0] - 0.5).abs() < 1e-12, "u holds the last converged state: {}", u[0]);
    }

    #[test]
    fn an_ordinary_path_still_converges() {
        let mut p = Line::new();
        let mut u = [0.0];
        let summary = NewtonRaphson::new(SparseLu::new(), settings()).solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
        assert_eq!(summary.steps, 4);
        assert!((u[0] - 1.0).abs() < 1e-12);
    }

    #[test]
    fn the_secant_scale_is_the_fit_of_the_last_step_clamped_and_whole_when_good() {
        let s = [2.0, -1.0, 0.5];
        let start = [1.0, 1.0, 1.0];
        // the converged increment = f times the secant: the fit is f
        let scale = |f: f64| secant_scale(&s, &s.iter().zip(&start).map(|(d, a)| a + f * d).collect::<Vec<_>>(), &start);
        assert!((scale(0.5) - 0.5).abs() < 1e-12, "{}", scale(0.5));
        assert!((scale(0.3) - 0.3).abs() < 1e-12);
        assert_eq!(scale(0.05), SECANT_FIT_MIN, "an overshoot of twentyfold is scaled by the floor");
        assert_eq!(scale(-0.4), SECANT_FIT_MIN, "a secant pointing the wrong way");
        assert_eq!(scale(0.95), 1.0, "a good secant stays whole");
        assert_eq!(scale(1.7), 1.0, "an undershoot is not amplified");
        assert_eq!(secant_scale(&[0.0; 3], &start, &start), 1.0, "no secant");
    }
}

#[cfg(test)]
mod resolve_tests {
    use super::*;
    use crate::linalg::linear_solver::SparseLu;
    use crate::linearised_contact::ConstraintRow;
    use faer::sparse::SymbolicSparseColMatRef;

    /// A taut string of `n` inner nodes (tension 1, spacing 1, ends held) pulled down by a load
    /// t * f at every node onto a convex obstacle: node i may not go below -gap_i, gap_i =
    /// 0.05 + 0.02 (i - mid)^2 (a punch seen from below), penalty eps. Piecewise linear: with
    /// the right set one Newton step is the answer.
    struct String {
        n: usize,
        f: f64,
        eps: f64,
        active: Vec<bool>,
        psi: Vec<f64>,
        residual: Vec<f64>,
        col_ptr: Vec<usize>,
        row_idx: Vec<usize>,
        values: Vec<f64>,
    }

    impl String {
        fn new(n: usize, f: f64, eps: f64) -> Self {
            let (mut col_ptr, mut row_idx) = (vec![0], Vec::new());
            for j in 0..n {
                for i in j.saturating_sub(1)..(j + 2).min(n) {
                    row_idx.push(i);
                }
                col_ptr.push(row_idx.len());
            }
            let values = vec![0.0; row_idx.len()];
            String { n, f, eps, active: vec![false; n], psi: vec![0.0; n], residual: vec![0.0; n], col_ptr, row_idx, values }
        }
        fn gap(&self, i: usize) -> f64 {
            let x = i as f64 - (self.n - 1) as f64 / 2.0;
            0.05 + 0.02 * x * x
        }
    }

    impl NonlinearProblem for String {
        fn num_dofs(&self) -> usize {
            self.n
        }
        fn num_equations(&self) -> usize {
            self.n
        }
        fn apply_prescribed(&self, _u: &mut [f64], _t: f64) {}
        fn evaluate(&mut self, u: &[f64], t: f64, with_tangent: bool) -> Result<Evaluation> {
            let n = self.n;
            let mut changes = 0;
            for i in 0..n {
                self.psi[i] = u[i] + self.gap(i);
                let want = self.eps * self.psi[i] <= 0.0;
                if want != self.active[i] {
                    changes += 1;
                    if with_tangent {
                        self.active[i] = want;
                    }
                }
            }
            for i in 0..n {
                let left = if i > 0 { u[i - 1] } else { 0.0 };
                let right = if i + 1 < n { u[i + 1] } else { 0.0 };
                let contact = if self.active[i] { self.eps * self.psi[i] } else { 0.0 };
                self.residual[i] = 2.0 * u[i] - left - right - t * self.f + contact;
            }
            for j in 0..n {
                for p in self.col_ptr[j]..self.col_ptr[j + 1] {
                    let i = self.row_idx[p];
                    self.values[p] = if i == j { 2.0 + if self.active[i] { self.eps } else { 0.0 } } else { -1.0 };
                }
            }
            let norm = self.residual.iter().map(|r| r * r).sum::<f64>().sqrt();
            Ok(Evaluation { residual_norm: norm, force_scale: (n as f64).sqrt() * self.f.abs().max(1.0), active_changes: changes })
        }
        fn residual(&self) -> &[f64] {
            &self.residual
        }
        fn matrix(&self) -> SparseColMatRef<'_, usize, f64> {
            SparseColMatRef::new(SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx), &self.values)
        }
        fn add_increment(&self, u: &mut [f64], du: &[f64]) {
            u.iter_mut().zip(du).for_each(|(a, b)| *a += b);
        }
        fn constraint_rows(&self) -> crate::error::Result<Vec<ConstraintRow>> {
            Ok((0..self.n).map(|i| ConstraintRow { coef: vec![(i, 1.0)], weight: 1.0, eps: self.eps, trial: self.eps * self.psi[i], active: self.active[i], id: (0, i) }).collect())
        }
        fn set_constraint_state(&mut self, id: (usize, usize), active: bool) {
            self.active[id.1] = active;
        }
    }

    fn solve(resolve_contact: bool) -> (Vec<f64>, usize, Vec<bool>) {
        let settings = NewtonSettings { max_increment: 1.0, resolve_contact, ..NewtonSettings::default() };
        let mut newton = NewtonRaphson::new(SparseLu::new(), settings);
        let mut p = String::new(41, -0.02, 1e4);
        let mut u = vec![0.0; 41];
        let mut iterations = Vec::new();
        newton.solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |r, _, _| iterations.push(r.iterations)).unwrap();
        assert_eq!(iterations.len(), 1, "one load step");
        (u, iterations[0], p.active)
    }

    /// The string's whole load in one step: re-solving the linearised (here exact) contact
    /// problem on the first factorisation finds the contact zone, and the next iterations
    /// confirm it; one guess of the set per factorisation takes several iterations to the same
    /// answer.
    #[test]
    fn a_piecewise_linear_contact_problem_is_solved_in_one_newton_step() {
        let (u, resolved, set) = solve(true);
        let (u_plain, plain, set_plain) = solve(false);
        assert_eq!(set, set_plain, "the same contact zone");
        let zone = set.iter().filter(|&&a| a).count();
        assert!(zone >= 5 && zone < 35, "a zone of {zone} nodes inside the string");
        let diff = u.iter().zip(&u_plain).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(diff < 1e-9, "answers differ by {diff:e}");
        // measured: 3 against 10 (the first iteration's re-solve finds the zone of 9 nodes)
        assert!(resolved <= 3, "{resolved} Newton iterations with the re-solve");
        assert!(plain >= 2 * resolved, "{plain} Newton iterations without it, {resolved} with");
    }
}

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
//!
//! The files: `settings.rs` the knobs of Newton and of the load stepping; `newton.rs` the Newton
//! iteration at one load factor and what it calls converged; `load_path.rs` the load steps towards
//! the targets, their increments and cut-backs, the secant predictor; `contact_resolve.rs` the
//! re-solve of the linearised contact problem after a Newton step's solve.

mod contact_resolve;
mod load_path;
mod newton;
mod settings;
#[cfg(test)]
mod test_line;

pub use load_path::{PACE_WINDOW, PREDICTED_ATTEMPTS, SECANT_FIT_MIN, SECANT_FIT_TRUSTED};
pub use newton::{NewtonRaphson, ADMISSIBLE_HALVINGS, CYCLING_WINDOW};
pub use settings::NewtonSettings;

use crate::error::Result;
use crate::linearised_contact::ConstraintRow;
use faer::sparse::SparseColMatRef;

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
    /// [`LinearSolver::factorize_preconditioned`](crate::linalg::linear_solver::LinearSolver::factorize_preconditioned) (see [`crate::element::Element::has_preconditioner`]).
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
    /// The load factors where the loading turns (a punch's path changes direction): a load step
    /// is not extrapolated across them. Default: none.
    fn path_corners(&self) -> Vec<f64> {
        Vec::new()
    }
    /// Save the history-dependent state (contact) of the last converged step.
    fn checkpoint(&mut self) {}
    /// Go back to the last checkpoint (after a failed step).
    fn restore(&mut self) {}
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

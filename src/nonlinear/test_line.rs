//! What Newton calls converged holds, and what it reports is the truth: a one-unknown problem
//! R(u, t) = u - t whose residual can be made NaN past a load factor, and whose end_step can
//! refuse every converged state (an augmented-Lagrangian tolerance that is never met).

use super::{Evaluation, NewtonSettings, NonlinearProblem};
use crate::error::Result;
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};

pub(super) struct Line {
    pub(super) residual: [f64; 1],
    pub(super) col_ptr: [usize; 2],
    pub(super) row_idx: [usize; 1],
    pub(super) tangent: [f64; 1],
    /// The residual is NaN for t above this.
    pub(super) nan_above: f64,
    /// end_step asks for another solve every time.
    pub(super) never_satisfied: bool,
    pub(super) restarts: usize,
    /// end_step asks for this many re-solves in all, shifting the solution by 0.01 each time
    /// (as an augmented-Lagrangian update moves the contact forces).
    pub(super) extra_solves: usize,
    pub(super) shift: f64,
    /// update_multipliers shifts the solution by 0.01 this many times in all (an
    /// augmented-Lagrangian update inside Newton); |R| at each call that did.
    pub(super) multiplier_updates: usize,
    pub(super) updated_at: Vec<f64>,
}

impl Line {
    pub(super) fn new() -> Self {
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

/// Steps of a quarter, two cut-backs.
pub(super) fn settings() -> NewtonSettings {
    NewtonSettings { max_increment: 0.25, max_cutbacks: 2, ..NewtonSettings::default() }
}

//! Newton backs off from states the problem refuses ([`StampError::Inadmissible`], e.g. a plate
//! element turned inside out): the line search halves a refused trial, and without a line search
//! the refused iterate's correction is halved back towards the last admissible one; only a
//! refused start (nothing to halve) cuts the load step back. A one-unknown problem whose full Newton step from the start lands
//! outside its admissible half-line: R(u, t) = ln u - (1 - t) ln 3 on u > 0, the root 3^(1-t);
//! from u = 3 at t = 1 the Newton step goes to 3 - 3 ln 3 = -0.30.

use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use stamp::linalg::linear_solver::SparseLu;
use stamp::nonlinear::{Evaluation, NewtonRaphson, NewtonSettings, NonlinearProblem, NonlinearSolver};
use stamp::{Result, StampError};

struct Log {
    residual: [f64; 1],
    col_ptr: [usize; 2],
    row_idx: [usize; 1],
    tangent: [f64; 1],
    refused: usize,
}

impl Log {
    fn new() -> Self {
        Log { residual: [0.0], col_ptr: [0, 1], row_idx: [0], tangent: [0.0], refused: 0 }
    }
}

impl NonlinearProblem for Log {
    fn num_dofs(&self) -> usize {
        1
    }
    fn num_equations(&self) -> usize {
        1
    }
    fn apply_prescribed(&self, _u: &mut [f64], _t: f64) {}
    fn evaluate(&mut self, u: &[f64], t: f64, _with_tangent: bool) -> Result<Evaluation> {
        if u[0] <= 0.0 {
            self.refused += 1;
            return Err(StampError::Inadmissible { element: 0, reason: format!("u = {} <= 0", u[0]) });
        }
        self.residual[0] = u[0].ln() - (1.0 - t) * 3f64.ln();
        self.tangent[0] = 1.0 / u[0];
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
}

fn solve(line_search_steps: usize) -> (f64, usize, usize) {
    let settings = NewtonSettings { initial_increment: 1.0, max_increment: 1.0, line_search_steps, ..NewtonSettings::default() };
    let mut p = Log::new();
    let mut u = [3.0];
    let summary = NewtonRaphson::new(SparseLu::new(), settings).solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
    (u[0], p.refused, summary.cutbacks)
}

#[test]
fn the_line_search_halves_a_refused_trial() {
    let (u, refused, cutbacks) = solve(4);
    assert!((u - 1.0).abs() < 1e-9, "u = {u}");
    assert!(refused >= 1, "the full step must have been tried and refused");
    assert_eq!(cutbacks, 0);
}

#[test]
fn without_a_line_search_the_refused_correction_is_halved_not_cut_back() {
    let (u, refused, cutbacks) = solve(0);
    assert!((u - 1.0).abs() < 1e-9, "u = {u}");
    assert!(refused >= 1, "the full step must have been tried and refused");
    assert_eq!(cutbacks, 0);
}

#[test]
fn a_refused_start_is_cut_back_and_fails() {
    let settings = NewtonSettings { initial_increment: 1.0, max_increment: 1.0, max_cutbacks: 3, ..NewtonSettings::default() };
    let mut p = Log::new();
    let mut u = [-1.0];
    let e = NewtonRaphson::new(SparseLu::new(), settings).solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).err().expect("refused");
    assert!(matches!(e, StampError::NoConvergence { cutbacks: 3, .. }), "{e}");
    assert_eq!(p.refused, 4, "the start refused at each of the four attempts");
}

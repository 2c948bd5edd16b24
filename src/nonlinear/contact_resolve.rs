//! The hook of the linearised contact problem's re-solve ([`crate::linearised_contact`],
//! [`NewtonSettings::resolve_contact`](super::NewtonSettings::resolve_contact)): after a Newton
//! step's linear solve, the contact constraints linearised at the iterate are solved as a small
//! complementarity problem on the same factorisation, so that one Newton step finds the contact
//! zone a piecewise-linear problem would need several guesses of the set for.

use super::NonlinearProblem;
use crate::error::Result;
use crate::linalg::linear_solver::LinearSolver;
use crate::linearised_contact::{resolve, Resolve};

/// Re-solve the Newton correction `du` (solved with `linear`'s factorisation of the tangent) with
/// the problem's linearised constraint rows, and hand each constraint's new state back to the
/// problem. Nothing without rows.
pub(super) fn resolve_contact<P: NonlinearProblem, L: LinearSolver>(linear: &mut L, p: &mut P, du: &mut [f64], debug: bool) -> Result<()> {
    let rows = p.constraint_rows()?;
    if !rows.is_empty() {
        let mut report = Resolve::default();
        let changes = resolve(linear, &rows, du, &mut report)?;
        if debug {
            eprintln!("  linearised contact: {} rounds, {} columns, settled {}, {} changes", report.rounds, report.columns, report.settled, report.changed);
        }
        for (id, active) in changes {
            p.set_constraint_state(id, active);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::error::Result;
    use crate::linalg::linear_solver::SparseLu;
    use crate::linearised_contact::ConstraintRow;
    use crate::nonlinear::{Evaluation, NewtonRaphson, NewtonSettings, NonlinearProblem, NonlinearSolver};
    use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};

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

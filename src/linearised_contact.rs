//! The linearised contact problem solved again on each Newton factorisation.
//!
//! A Newton step solves K du = -R with the active set of the last evaluation: one guess of the
//! set per factorisation. Where that guess is far off (a first contact, a set that overshot), the
//! set is corrected at the next evaluation only, one layer of points at a time, and a load step
//! takes 10 to 20 iterations (the torus die, the paper's strip: docs/performance.md). Here the
//! linearised complementarity problem of the perturbed Lagrangian (eq. 4.14 of the paper with the
//! gaps linearised, lambda_k = min(0, lambda_bar_k + eps (Psi_k + g_k . du))) is solved on the same
//! factorisation before the step is taken: a point whose linearised trial disagrees with its
//! state changes state, and the step is corrected by the Woodbury formula
//!
//!   (K + U S U^T)^-1 b = x0 - K^-1 U (S^-1 + U^T K^-1 U)^-1 U^T x0,
//!
//! U the changed points' gradients g_k, S their +-w_k eps_k, until no point disagrees (a few
//! rounds). The compliance U^T K^-1 U between the changed points comes from the forward halves of
//! the factor ([`LinearSolver::forward_columns`]: the rows on their paths to the root of the
//! elimination tree), from selected entries of its inverse ([`LinearSolver::compliance`]: MUMPS
//! under PETSc) or, for a factor without either, from whole solves of the changed points'
//! columns at once ([`LinearSolver::solve_many_approx`]); all with the symmetric factor (the
//! preconditioner of an unsymmetric tangent), an estimate that only chooses the set. Each round
//! costs one solve with the factor (the trials of every point); the step is corrected with one
//! accurate solve. The set found is handed to the problem for its next evaluation
//! ([`crate::nonlinear::NonlinearProblem::set_constraint_state`]), where the usual rules apply to it.
//!
//! Rounds enter the deepest [`ROUND_ENTRY_FRACTION`] of the penetrating points and at most as
//! many as are in the set ([`ROUND_ENTRY_MIN`] at least): a first contact's linearised overlap
//! is wide (the set would swing out and back in the next rounds, a column each); a point whose
//! trial is tensile at the iterate itself (held by the evaluation's rules) is not released here.
//! A cycling set, [`MAX_ROUNDS`] rounds without settling, more than [`MAX_COLUMNS`] points
//! changing, or a singular system leave the step as it was.

use crate::error::Result;
use crate::linalg::linear_solver::LinearSolver;
use crate::linalg::supernodal_solve::ForwardColumn;
use nalgebra::{DMatrix, DVector};
use std::collections::HashSet;

/// Rounds before the re-solve gives up (the step is then left as it was). Measured on the shipped
/// problems and the torus die: settled sets take 1 to 8 rounds; 20 rounds cost torus on triangles
/// of size 1 21 s in sets that never settled.
pub const MAX_ROUNDS: usize = 10;

/// The most points that may change state in one re-solve (each a forward column of the factor,
/// their compliance and a capacitance system of their size solved every round): past it the step
/// is left as it was. Sets that settle took up to 341 (the torus die on triangles of size 1);
/// sets that never settle took thousands: unbounded, the force-driven sphere of
/// meshes/sphere-ss.toml on 100 x 100 cells took 95 s (34 Newton iterations) against 20.8 s (35)
/// at 512 and 17.6 s (40) at 256 and 19.6 s (80) without the re-solve; `stamp bench --problem
/// sphere-displacement` at n = 80 12.9 s against 4.6 s at 512 and 5.6 s without; 256 cost the
/// torus of size 1 five iterations more.
pub const MAX_COLUMNS: usize = 512;

/// A round enters the penetrating points whose linearised trial is at most this fraction of the
/// deepest one's.
pub const ROUND_ENTRY_FRACTION: f64 = 0.5;

/// A round enters at most as many points as are in the set, and at least this many.
pub const ROUND_ENTRY_MIN: usize = 16;

/// One inequality constraint linearised at the current iterate: the trial multiplier
/// `trial + eps * (coef . du)` of a point, its force `weight * lambda * coef` while active.
#[derive(Debug, Clone)]
pub struct ConstraintRow {
    /// The constraint's gradient by equation (the unknowns of the linear system).
    pub coef: Vec<(usize, f64)>,
    /// The point's weight (its tributary area).
    pub weight: f64,
    /// The penalty.
    pub eps: f64,
    /// lambda_bar + eps Psi at the iterate.
    pub trial: f64,
    /// Active in the tangent the step was solved with.
    pub active: bool,
    /// Which constraint (the problem's own numbering).
    pub id: (usize, usize),
}

/// What a re-solve did (for STAMP_DEBUG).
#[derive(Debug, Clone, Copy, Default)]
pub struct Resolve {
    pub rounds: usize,
    pub columns: usize,
    pub changed: usize,
    pub settled: bool,
}

/// Solves the linearised complementarity problem of `rows` on `linear`'s factorisation, starting
/// from the Newton correction `du` (solved with the rows' current states); on success corrects
/// `du` in place and returns the rows whose state changes, with their new state.
pub fn resolve<L: LinearSolver + ?Sized>(linear: &mut L, rows: &[ConstraintRow], du: &mut [f64], report: &mut Resolve) -> Result<Vec<((usize, usize), bool)>> {
    *report = Resolve::default();
    let n = du.len();
    // the gaps' changes under the plain step, and under the corrected one
    let g0: Vec<f64> = rows.iter().map(|r| row_dot(r, du)).collect();
    let mut v = g0.clone();
    let mut on: Vec<bool> = rows.iter().map(|r| r.active).collect();
    // the rows that changed state in some round, and the compliance between them
    let mut changed_rows: Vec<usize> = Vec::new();
    let mut slot = vec![usize::MAX; rows.len()];
    let mut compliance: Vec<Vec<f64>> = Vec::new();
    let mut forward: Vec<ForwardColumn> = Vec::new();
    // x = du0 - K^-1 sum_j c_j g_j over the changed rows
    let mut coef: Vec<f64> = Vec::new();
    let mut seen: HashSet<Vec<usize>> = HashSet::new();
    let trial = |k: usize, v: &[f64]| rows[k].trial + rows[k].eps * v[k];
    report.settled = loop {
        let mut changing = Vec::new();
        let mut deepest = 0.0f64;
        for (k, r) in rows.iter().enumerate() {
            let t = trial(k, &v);
            // a point tensile at the iterate itself stays: the evaluation holds it (a convex
            // punch's curvature brings it back), and its release is the evaluation's to decide
            let want = t <= 0.0 || (r.active && r.trial > 0.0);
            if want != on[k] {
                changing.push(k);
                if want {
                    deepest = deepest.min(t);
                }
            }
        }
        // damped entry: the deepest of the entering points, the set at most doubling
        changing.retain(|&k| on[k] || trial(k, &v) <= ROUND_ENTRY_FRACTION * deepest);
        let cap = on.iter().filter(|&&o| o).count().max(ROUND_ENTRY_MIN);
        let mut entering: Vec<(f64, usize)> = changing.iter().filter(|&&k| !on[k]).map(|&k| (trial(k, &v), k)).collect();
        if entering.len() > cap {
            entering.sort_by(|a, b| a.0.total_cmp(&b.0));
            let keep: HashSet<usize> = entering[..cap].iter().map(|e| e.1).collect();
            changing.retain(|&k| on[k] || keep.contains(&k));
        }
        if changing.is_empty() {
            break true;
        }
        if report.rounds == MAX_ROUNDS {
            break false;
        }
        let state: Vec<usize> = (0..rows.len()).filter(|&k| on[k] != rows[k].active).collect();
        if !seen.insert(state) {
            break false;
        }
        report.rounds += 1;
        for &k in &changing {
            on[k] = !on[k];
        }
        let new: Vec<usize> = changing.into_iter().filter(|&k| slot[k] == usize::MAX).collect();
        if changed_rows.len() + new.len() > MAX_COLUMNS {
            break false;
        }
        if !new.is_empty() {
            add_columns(linear, rows, &new, &mut changed_rows, &mut slot, &mut compliance, &mut forward, n)?;
            report.columns += new.len();
        }
        // the changed rows whose state differs from the tangent's: c = S (trial + eps G x),
        // x = du0 - Z c, solved through the capacitance (S^-1 + W) y = G du0 - W S trial
        let idx: Vec<usize> = (0..changed_rows.len()).filter(|&j| on[changed_rows[j]] != rows[changed_rows[j]].active).collect();
        let m = idx.len();
        coef = vec![0.0; changed_rows.len()];
        if m > 0 {
            let sign = |k: usize| if on[k] { 1.0 } else { -1.0 };
            let f: Vec<f64> = idx.iter().map(|&j| sign(changed_rows[j]) * rows[changed_rows[j]].weight * rows[changed_rows[j]].trial).collect();
            let mut cap = DMatrix::<f64>::zeros(m, m);
            let mut rhs = DVector::<f64>::zeros(m);
            for (a, &ja) in idx.iter().enumerate() {
                let ka = changed_rows[ja];
                cap[(a, a)] += 1.0 / (sign(ka) * rows[ka].weight * rows[ka].eps);
                let mut x = g0[ka];
                for (b, &jb) in idx.iter().enumerate() {
                    x -= f[b] * compliance[jb][ja];
                    cap[(a, b)] += compliance[jb][ja];
                }
                rhs[a] = x;
            }
            let Some(y) = cap.lu().solve(&rhs) else {
                break false;
            };
            for (a, &ja) in idx.iter().enumerate() {
                coef[ja] = f[a] + y[a];
            }
        }
        // every row's gap change under the corrected step: one solve with the factor
        let mut b = vec![0.0; n];
        scatter(rows, &changed_rows, &coef, &mut b);
        linear.solve_many_approx(&mut b, 1)?;
        for (k, vk) in v.iter_mut().enumerate() {
            *vk = g0[k] - row_dot(&rows[k], &b);
        }
    };
    if !report.settled {
        return Ok(Vec::new());
    }
    if coef.iter().any(|c| *c != 0.0) {
        // du = du0 - K^-1 sum_j c_j g_j, solved accurately
        let mut b = vec![0.0; n];
        scatter(rows, &changed_rows, &coef, &mut b);
        linear.solve_in_place_to(&mut b, 1e-10)?;
        for (x, d) in du.iter_mut().zip(&b) {
            *x -= d;
        }
    }
    let out: Vec<((usize, usize), bool)> = rows.iter().zip(&on).filter(|(r, o)| r.active != **o).map(|(r, o)| (r.id, *o)).collect();
    report.changed = out.len();
    Ok(out)
}

/// g . v for the row's gradient g.
fn row_dot(r: &ConstraintRow, v: &[f64]) -> f64 {
    r.coef.iter().map(|&(e, c)| c * v[e]).sum()
}

/// b = sum_j c_j g_j.
fn scatter(rows: &[ConstraintRow], changed_rows: &[usize], coef: &[f64], b: &mut [f64]) {
    for (j, &k) in changed_rows.iter().enumerate() {
        for &(e, g) in &rows[k].coef {
            b[e] += coef[j] * g;
        }
    }
}

/// Appends a new changed row's compliance column `col` (over every changed row) as the last
/// column, and its entries as the new row of the `base` columns there before this round.
fn push_column(compliance: &mut Vec<Vec<f64>>, base: usize, col: Vec<f64>) {
    let j = compliance.len();
    for (i, w) in compliance.iter_mut().take(base).enumerate() {
        w[j] = col[i];
    }
    compliance.push(col);
}

/// Appends the rows `new` to the changed rows and their compliance with every changed row,
/// g_i . K^-1 g_j (symmetric: the symmetric factor).
#[allow(clippy::too_many_arguments)]
fn add_columns<L: LinearSolver + ?Sized>(linear: &mut L, rows: &[ConstraintRow], new: &[usize], changed_rows: &mut Vec<usize>, slot: &mut [usize], compliance: &mut Vec<Vec<f64>>, forward: &mut Vec<ForwardColumn>, n: usize) -> Result<()> {
    let base = changed_rows.len();
    for (c, &k) in new.iter().enumerate() {
        slot[k] = base + c;
        changed_rows.push(k);
    }
    let total = changed_rows.len();
    for w in compliance.iter_mut() {
        w.resize(total, 0.0);
    }
    let coefs: Vec<Vec<(usize, f64)>> = new.iter().map(|&k| rows[k].coef.clone()).collect();
    // forward columns, kept for later rounds, when the solver has them and had them before
    let fc = if forward.len() == base { linear.forward_columns(&coefs)? } else { None };
    match fc {
        Some(fc) => {
            forward.extend(fc);
            for j in base..total {
                // g_i K^-1 g_j, as the whole columns' below (K bordered is not symmetric)
                let col: Vec<f64> = (0..total).map(|i| forward[i].dot(&forward[j])).collect();
                push_column(compliance, base, col);
            }
        }
        None => {
            forward.clear();
            // selected entries of the factor's inverse (MUMPS), else whole columns
            let all: Vec<Vec<(usize, f64)>> = changed_rows.iter().map(|&k| rows[k].coef.clone()).collect();
            if let Some(c) = linear.compliance(&all, &coefs)? {
                for ci in 0..new.len() {
                    push_column(compliance, base, c.column(ci).iter().copied().collect());
                }
                return Ok(());
            }
            let m = new.len();
            let mut cols = vec![0.0; n * m];
            for (c, g) in coefs.iter().enumerate() {
                for &(e, x) in g {
                    cols[c * n + e] += x;
                }
            }
            linear.solve_many_approx(&mut cols, m)?;
            for z in cols.chunks(n) {
                push_column(compliance, base, changed_rows.iter().map(|&k| row_dot(&rows[k], z)).collect());
            }
        }
    }
    Ok(())
}

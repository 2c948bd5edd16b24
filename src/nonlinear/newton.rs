//! Newton-Raphson at one load factor: the iteration, its chord steps, line search and halvings
//! of inadmissible iterates, the multiplier updates inside it, and what it calls converged.

use super::contact_resolve::resolve_contact;
use super::{Evaluation, NewtonSettings, NonlinearProblem};
use crate::error::StampError;
use crate::linalg::linear_solver::LinearSolver;

/// Iterations in a row with a changing active set that count as cycling.
pub const CYCLING_WINDOW: usize = 6;
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
    /// [`PREDICTED_ATTEMPTS`](super::PREDICTED_ATTEMPTS) failed attempts in a row.
    pub predictor: Option<Box<dyn FnMut(usize, f64, f64, &mut [f64]) -> bool>>,
    /// Newton iterations done so far, failed attempts included.
    pub(super) iterations_done: usize,
}

impl<L: LinearSolver> NewtonRaphson<L> {
    pub fn new(linear: L, settings: NewtonSettings) -> Self {
        NewtonRaphson { settings, linear, on_iteration: None, stop: None, interrupt: None, agree_interrupt: None, predictor: None, iterations_done: 0 }
    }

    /// Newton iterations done so far by this solver, those of attempts that failed included (a
    /// path that failed returns no [`SolveSummary`](super::SolveSummary): the caller subtracts what its steps
    /// reported).
    pub fn iterations_done(&self) -> usize {
        self.iterations_done
    }
    /// Whether [`interrupt`](Self::interrupt) was set (on any process, with
    /// [`agree_interrupt`](Self::agree_interrupt)).
    pub(super) fn interrupted(&self) -> bool {
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
    pub(super) fn iterate<P: NonlinearProblem>(&mut self, p: &mut P, u: &mut [f64], t: f64, updates: &mut usize, peak_energy: &mut f64, last_tol: &mut f64) -> std::result::Result<(Vec<f64>, usize), (String, f64, f64)> {
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
            // a failure of the linear algebra from here on ends the attempt at this iterate
            let failed = |e: StampError| (e.to_string(), ev.residual_norm, tol);
            du.copy_from_slice(p.residual());
            if chord {
                let rtol = (0.1 * tol / ev.residual_norm).clamp(1e-14, 0.1);
                self.linear.solve_in_place_to(&mut du, rtol).map_err(failed)?;
                chords += 1;
            } else {
                if !with_tangent {
                    p.evaluate(u, t, true).map_err(failed)?;
                    du.copy_from_slice(p.residual());
                }
                self.linear.factorize_preconditioned(p.matrix(), p.preconditioner()).map_err(failed)?;
                factored = true;
                // inexact Newton (Dembo, Eisenstat & Steihaug 1982; Eisenstat & Walker 1996): a
                // linear residual of eta |R|, eta <= |R| / force scale, keeps the convergence
                // quadratic, and an iterative linear solver stops early while |R| is large
                let forcing = s.forcing.min(ev.residual_norm / ev.force_scale.max(f64::MIN_POSITIVE));
                self.linear.solve_in_place_to(&mut du, forcing).map_err(failed)?;
            }
            last_chord = chord;
            for x in du.iter_mut() {
                *x = -*x;
            }
            if !chord && s.resolve_contact {
                resolve_contact(&mut self.linear, p, &mut du, debug).map_err(failed)?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::linear_solver::SparseLu;
    use crate::nonlinear::test_line::{settings, Line};
    use crate::nonlinear::{NewtonSettings, NonlinearSolver};

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
}

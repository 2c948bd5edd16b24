//! The load path: steps towards each target in turn, the increment grown after easy steps and
//! cut back after failed ones, the start of each step (secant extrapolation scaled by its last
//! fit, or an outside prediction), and the budget of steps.

use super::{NewtonRaphson, NonlinearProblem, NonlinearSolver, SolveSummary, StepReport};
use crate::error::{Result, StampError};
use crate::linalg::linear_solver::LinearSolver;
use std::time::Instant;

/// The steps over which [`NewtonSettings::max_steps`](super::NewtonSettings::max_steps) measures the pace of a path.
pub const PACE_WINDOW: usize = 50;
/// Attempts of a load step started from [`NewtonRaphson::predictor`]; its later retries (cut
/// back) start from the secant extrapolation, in case the prediction is what fails (a coarse
/// mesh far from the answer).
pub const PREDICTED_ATTEMPTS: usize = 2;

/// The smallest scale of the secant extrapolation ([`NewtonSettings::fit_secant`](super::NewtonSettings::fit_secant)).
pub const SECANT_FIT_MIN: f64 = 0.2;

/// A fit of the last step's secant at least this good keeps the next secant whole
/// ([`NewtonSettings::fit_secant`](super::NewtonSettings::fit_secant)): scaling a good secant by its fit (0.96 to 0.99 on the torus
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
impl<L: LinearSolver> NewtonRaphson<L> {
    /// Why the path must stop after `steps` converged steps with `remaining` load path left to go
    /// ([`NewtonSettings::max_steps`](super::NewtonSettings::max_steps)); `recent`: the load factors of the last steps.
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
        // increments still growing (a path started with a tiny initial_increment, taken up by
        // 1.5 a step): not a crawl, the pace of the past says nothing of the steps to come
        let first = (recent[1] - recent[0]).abs();
        let last = (recent[window] - recent[window - 1]).abs();
        if last >= ACCELERATING * first {
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
}

/// A path whose last increment is this many times the first of the pace window is accelerating
/// (the increment grows by `growth` after easy steps), not crawling.
const ACCELERATING: f64 = 8.0;

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
        let corners = p.path_corners();
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
                    // not across a corner of the loading (the secant of the segment before it
                    // points elsewhere: a punch lifted after pressing would start deeper still)
                    let (lo, hi) = (t_prev.min(step_t), t_prev.max(step_t));
                    let turns = corners.iter().any(|&c| c > lo && c < hi);
                    if ratio > 0.0 && ratio.is_finite() && !turns {
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
    use super::*;
    use crate::linalg::linear_solver::SparseLu;
    use crate::nonlinear::test_line::{settings, Line};
    use crate::nonlinear::{NewtonSettings, NonlinearSolver};

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
        // a path started at an increment of 1e-12 grows by 1.5 a step: 70 steps, more than the
        // pace window, and no crawl
        let (mut p, mut u, mut steps) = (Line::new(), [0.0], 0);
        let s = NewtonSettings { initial_increment: 1e-12, min_increment: 1e-12, max_increment: 0.25, max_steps: 1000, ..settings() };
        NewtonRaphson::new(SparseLu::new(), s).solve_path(&mut p, &mut u, 0.0, &[1.0], &mut |_, _, _| steps += 1).unwrap();
        assert!(steps > 50 && (u[0] - 1.0).abs() < 1e-9, "{steps} steps, u = {u:?}");
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

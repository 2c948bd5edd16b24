//! The settings of Newton-Raphson and of the load stepping, and their check.

use crate::error::{Result, StampError};

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
    /// [`NonlinearProblem::end_step`](super::NonlinearProblem::end_step) does.
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
    /// clamped to [[`SECANT_FIT_MIN`](super::SECANT_FIT_MIN), 1], and 1 where that fit is at least
    /// [`SECANT_FIT_TRUSTED`](super::SECANT_FIT_TRUSTED). A force-driven punch's secant overshoots (its first touch
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
    /// [`CYCLING_WINDOW`](super::CYCLING_WINDOW) iterations while |R| made no progress (the least |R| of the window's
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
    /// ([`NonlinearProblem::update_multipliers`](super::NonlinearProblem::update_multipliers)) and the iterations go on from the same iterate,
    /// instead of after Newton converged, with a re-solve of the step
    /// ([`NonlinearProblem::end_step`](super::NonlinearProblem::end_step), still asked at the end); 0: never. The update moves the
    /// solution by the penetration the penalty left, a small perturbation the next one or two
    /// Newton iterations absorb, while a re-solve costs its own convergence down to round-off:
    /// measured on `stamp bench --problem sphere-displacement` (2026-11-24), 49 / 57 / 54 Newton
    /// iterations at n = 10 / 20 / 40 became 40 / 49 / 51 (1e-5: 40 / 51 / 52), the reactions of
    /// every step the same to 2e-8 relative (docs/performance.md).
    pub multiplier_tol: f64,
    /// Most converged load steps of a path (`usize::MAX`: no limit). The path also stops as soon
    /// as the pace of the last [`PACE_WINDOW`](super::PACE_WINDOW) steps (their mean increment) would need more steps
    /// than are left to finish it: a path that crawls (ever smaller increments that converge)
    /// ends with the reason instead of running for hours.
    pub max_steps: usize,
}
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

#[cfg(test)]
mod tests {
    use crate::linalg::linear_solver::SparseLu;
    use crate::nonlinear::test_line::{settings, Line};
    use crate::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearSolver};

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
}

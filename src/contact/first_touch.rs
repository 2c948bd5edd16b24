//! The active-set rules (docs/design.md, "Active-set rules at a first touch"): which penetrating
//! points enter in an evaluation with a tangent and which tensile points leave (damped entry and
//! release, the first touch at the deepest point), which are held one iteration more (after
//! entering, after an augmented-Lagrangian update, while their tension converges away, the last
//! point of a set that would empty), the Gauss-Newton tangent of a deep entry, and the points
//! that cycle: their changes counted per load step, frozen after too many. Also the paper's
//! update of a fixed set between Newton solves (eqs. 4.14b, 4.15a).

use crate::surface::ContactSurface;
use super::kinematics::Kinematics;
use super::normal_law::trial_multiplier;
use super::{ContactPair, PointShare};
use nalgebra::Vector3;

/// The default [`ContactPair::release_fraction`]. A Newton step that puts a band of points onto
/// the punch's tangent plane leaves most of them just outside a convex punch, barely tensile
/// beside the few that truly lift off; released together, the plate around them springs back
/// through the punch at the next iterate (measured on a cylinder pressed across a plate of gmsh
/// triangles: 128 of 134 points released at once, 3913 penetrating at the next iterate, and a
/// torus-shaped die cut its steps back twice). Measured on every shipped example, the torus die
/// and the README tutorial (docs/performance.md, "Today: the shipped problems"): 0.05 removes the
/// torus die's cut-backs and takes the paper's R = 100 strip from 153 + 25 failed to 122 Newton
/// iterations, leaving the others within one iteration; 0.2 and 0.5 cost ellipsoid-expression 4
/// and 5 more and disk-clamped 1 and 15 more.
pub const RELEASE_FRACTION: f64 = 0.05;

/// An active point whose trial multiplier is tensile but at most this fraction of its trial at
/// the last evaluation with a tangent (also tensile) is not released ([`ContactPair::hold_converging`]).
/// A Newton step puts a point that is pressed onto a convex punch on the punch's tangent plane,
/// which leaves it outside by the remainder d^T H d / 2 of its step d: tensile, although the
/// answer presses it. The next step leaves it outside again by the square of that, and so on:
/// the tension falls quadratically while the plate settles onto the punch, and releasing the
/// points then (a whole line of them under a cylinder) lets the plate spring through the punch.
/// A tension from a lift-off does not fall like that. Measured (docs/performance.md): the
/// cylinder across the 120 x 60 plate of gmsh triangles of size 1 took its first step without a
/// cut-back (28 Newton iterations in 4 steps instead of 43 and 19 in failed attempts).
pub const CONVERGING_TENSION: f64 = 0.1;

/// An entering point (compressive, not active at the last evaluation with a tangent) gets the
/// Gauss-Newton tangent w eps G G^T, without the curvature term w lambda H, at the body's first
/// contact with the punch and wherever its Psi is deep relative to the punch's curvature:
/// |Psi| |H| > DEEP_ENTRY_RATIO |grad Psi|^2 (for a sphere or cylinder written as
/// |x - c|^2 - R^2 about 4 times the penetration over the radius). Its
/// multiplier eps Psi then measures how far the iterate overran the punch, not a contact pressure,
/// and the curvature term built from it, negative in every direction, makes the tangent
/// indefinite: the Newton step throws the point sideways and far beyond the punch's surface.
/// Measured on every shipped example, the README tutorial, a torus die and the cylinder across
/// gmsh triangles (docs/performance.md): cylinder-30deg 33 -> 26 Newton iterations, the paper's
/// R = 100 strip 108 -> 99, the torus die on triangles of size 1 without its two cut-backs;
/// dropping it for every entering point instead cost the sphere problems up to 5 iterations
/// (their entries are shallow, and the term is the sliding stiffness of a pressed point on a
/// curved punch).
pub const DEEP_ENTRY_RATIO: f64 = 1e-3;

/// The default [`ContactPair::entry_fraction`].
pub const ENTRY_FRACTION: f64 = 0.5;

/// The entry fraction when the active set is empty (the first evaluation, or every point
/// released): only the deepest penetration enters (a body first touches a punch at a point), with
/// those within round-off of it. Measured on `stamp bench --problem sphere-displacement`
/// (2026-11-24, docs/performance.md): the first load step takes 6 / 7 / 6 / 8 Newton iterations at
/// n = 10 / 20 / 40 / 80 against 12 / 13 / 18 / 23 with 0.7 (a disc of the overlap that enters
/// takes every point to the punch's tangent plane, whence the convex Psi releases them and the
/// set shrinks ring by ring). Needs [`LONE_MAX_FLIPS`]: a lone point at a first touch under a
/// large increment swings in and out.
pub const FIRST_TOUCH_FRACTION: f64 = 1.0 - 1e-6;

/// The default [`ContactPair::lone_max_flips`]. A single point in contact (the first touch)
/// under a large increment swings in and out at every iteration: with the punch's force the
/// Newton step puts it on the tangent plane less the penalty's penetration, the convex Psi
/// leaves it outside, it is released and the plate springs back into the punch. With
/// [`FIRST_TOUCH_FRACTION`] that start is common; frozen after three changes, the point keeps
/// the active-side tangent and the step converges (with the ten of `max_flips`, `stamp bench`
/// gave its first step up twice: its cycling check fires at 8 iterations).
pub const LONE_MAX_FLIPS: u32 = 3;

/// The entry fraction at the first evaluation with a tangent of a load step (after the
/// predictor, which overshoots: a point that entered contact in the last step is predicted to
/// penetrate by its previous gap).
pub const STEP_START_ENTRY_FRACTION: f64 = 0.9;

impl ContactPair {
    /// Forget the cycling history (at the start of a load step); `predicted`: the step starts from
    /// an outside prediction of its answer (see `predicted_step`).
    pub fn start_step(&mut self, predicted: bool) {
        self.predicted_step = predicted;
        self.entered.fill(false);
        self.entered_deep.fill(false);
        self.flips.fill(0);
        self.frozen.fill(false);
        if let Some(f) = &mut self.friction {
            f.laws.start_step();
        }
        self.step_start = true;
        self.kept_last = false;
        // over this process's points: the next evaluation takes the largest over the processes
        self.lambda_scale = self.state.iter().enumerate().filter(|(k, _)| self.owns(*k)).map(|(_, s)| s.lambda.abs()).fold(0.0, f64::max);
        self.converged_scale = self.lambda_scale;
    }

    /// The paper's active-set update (eqs. 4.14b, 4.15a) after Newton converged on a fixed set: add
    /// the points with Psi < 0, drop those with lambda > 0. A point that changes `max_flips` times
    /// in one load step is held where it is (it sits at the kink, lambda ~ 0 either way). Returns the
    /// number of changes (of every process's points: collective with a share).
    pub fn update_active_set(&mut self) -> crate::Result<usize> {
        let mut changes = 0;
        for k in 0..self.points.len() {
            if self.frozen[k] || !self.evaluates(k) {
                continue;
            }
            let wanted = self.trial(k, self.state[k].psi) <= 0.0;
            if wanted != self.last_active[k] {
                self.last_active[k] = wanted;
                changes += usize::from(self.owns(k));
                record_flip(&mut self.flips[k], &mut self.frozen[k], self.max_flips);
            }
        }
        // the stick/slip criterion: the points held on the other branch of the friction cone
        let share = self.share.take();
        if let Some(f) = &mut self.friction {
            changes += f.laws.update(|k| share.as_ref().is_none_or(|s| s.own[k]), |k| share.as_ref().is_none_or(|s| s.evaluated[k]));
        }
        self.share = share;
        if let Some(sh) = &self.share {
            let mut c = [changes as f64];
            sh.reduce.sum(&mut c)?;
            changes = c[0] as usize;
        }
        Ok(changes)
    }
}

/// Count one change of state of a point; after `max_flips` changes in a load step it is frozen.
pub(super) fn record_flip(flips: &mut u32, frozen: &mut bool, max_flips: u32) {
    *flips += 1;
    if *flips >= max_flips {
        *frozen = true;
    }
}

/// What the active-set rules decided for one evaluation before its points are visited.
pub(super) struct ActiveSetRules {
    /// The entry fraction from an empty set, where entry is damped in this evaluation.
    pub(super) first_touch: Option<f64>,
    /// A penetrating inactive point enters only where its trial multiplier is at most this (0:
    /// every penetrating point).
    pub(super) entry_cut: f64,
    /// An active point whose trial turned tensile leaves only where its trial is at least this
    /// (0: every tensile point).
    pub(super) release_cut: f64,
    /// At most one point was active before this evaluation: a change is a lone point swinging.
    pub(super) lone: bool,
    /// The trial of the least tensile point of a set this evaluation would empty, kept one
    /// iteration more (infinity: none).
    pub(super) least_tensile: f64,
    /// "Near the kink" for a frozen point: 1 % of the largest multiplier now, or of the largest
    /// in this load step when every point is momentarily inactive.
    pub(super) band: f64,
}

impl ContactPair {
    /// The rules of this evaluation from every point's kinematics `kin` (collective with a
    /// share: the deepest and most tensile trials, the counts and the scales over the
    /// processes); `first`: the pair's first evaluation.
    pub(super) fn active_set_rules(&mut self, kin: &[Kinematics], first: bool, with_tangent: bool, share: Option<&PointShare>) -> crate::Result<ActiveSetRules> {
        let own = |k: usize| share.is_none_or(|s| s.own[k]);
        // "near the kink" is 1 % of the largest multiplier now, or of the largest in this step
        // when every point is momentarily inactive (a lone point swinging in and out)
        let mut current = self.state.iter().enumerate().filter(|(k, _)| own(*k)).map(|(_, s)| s.lambda.abs()).fold(0.0, f64::max);
        // Damped growth of the active set (see `entry_fraction`): in an evaluation with a tangent,
        // an inactive point enters only where its trial multiplier is at or below entry_fraction
        // times the most negative trial of the inactive points
        // Contact starting from an empty set (the first evaluation, or every point released)
        // starts at the deepest points only (FIRST_TOUCH_FRACTION): a body first touches a punch
        // at a point, and taking the whole overlap in puts every point on the punch's tangent
        // plane, from where the convex Psi releases them all (the set then ping-pongs and
        // shrinks ring by ring). The first iteration of a step damps harder
        // (STEP_START_ENTRY_FRACTION): the predictor's penetrations overshoot. A step started from
        // an outside prediction (`predicted_step`) is not damped at all.
        let damped = with_tangent && !self.hold_active_set && self.entry_fraction > 0.0 && !self.predicted_step;
        let first_touch = self.first_touch_fraction.filter(|_| damped);
        // the most negative trial of the inactive points, the most tensile of the active ones,
        // how many points are active and how many active or frozen: over this process's points,
        // then over the processes
        let trial_of = |k: usize, q: &Kinematics| trial_multiplier(self.lambda_bar[k], self.eps_reg, q.0);
        let mut deepest = kin.iter().enumerate().filter(|(k, _)| own(*k) && (first || (!self.last_active[*k] && !self.frozen[*k]))).map(|(k, q)| trial_of(k, q)).fold(0.0f64, f64::min);
        let mut most = kin.iter().enumerate().filter(|(k, _)| own(*k) && self.last_active[*k] && !self.frozen[*k]).map(|(k, q)| trial_of(k, q)).fold(0.0f64, f64::max);
        let mut active_before = (0..self.points.len()).filter(|&k| own(k) && self.last_active[k]).count() as f64;
        let mut held_before = (0..self.points.len()).filter(|&k| own(k) && (self.last_active[k] || self.frozen[k])).count() as f64;
        if let Some(sh) = share {
            let mut m = [current, -deepest, most, self.lambda_scale, self.converged_scale];
            sh.reduce.max_f64(&mut m)?;
            [current, deepest, most, self.lambda_scale, self.converged_scale] = [m[0], -m[1], m[2], m[3], m[4]];
            let mut c = [active_before, held_before];
            sh.reduce.sum(&mut c)?;
            [active_before, held_before] = c;
        }
        self.lambda_scale = self.lambda_scale.max(current);
        let band = 1e-2 * if current > 0.0 { current } else { self.lambda_scale };
        let empty = first || held_before == 0.0;
        let entry_cut = if damped && (!first || first_touch.is_some()) {
            if let (true, Some(f)) = (empty, first_touch) {
                f * deepest
            } else if let (true, Some(f)) = (self.step_start, self.step_start_entry_fraction) {
                f * deepest
            } else {
                self.entry_fraction * deepest
            }
        } else {
            0.0
        };
        // Damped release (see `release_fraction`): an active point whose trial turned tensile
        // leaves only where its trial is at least release_fraction times the most tensile one
        let release_cut = if damped && !first && self.release_fraction > 0.0 { self.release_fraction * most } else { 0.0 };
        // at most one point active before this evaluation: a change is a lone point swinging
        let lone = !first && active_before <= 1.0;
        // An evaluation that would release every point of a set that held some (no active point
        // still pressed, none penetrating to enter) keeps the least tensile one for one more
        // iteration, once: a body that the punch alone holds against its load (the paper's strip
        // around the cylinder) is otherwise left free, its tangent singular, and the step is
        // cut back; a real lift-off costs one iteration more.
        let mut least_tensile = f64::INFINITY;
        if damped && !first && active_before > 0.0 && !self.kept_last && deepest == 0.0 && self.guard_empty {
            let mut pressed = kin.iter().enumerate().filter(|(k, q)| own(*k) && (self.frozen[*k] || (self.last_active[*k] && trial_of(*k, q) <= 0.0))).count() as f64;
            let mut least = kin.iter().enumerate().filter(|(k, _)| own(*k) && self.last_active[*k]).map(|(k, q)| trial_of(k, q)).fold(f64::INFINITY, f64::min);
            if let Some(sh) = share {
                let mut c = [pressed];
                sh.reduce.sum(&mut c)?;
                pressed = c[0];
                let mut m = [least];
                sh.reduce.min_f64(&mut m)?;
                least = m[0];
            }
            if pressed == 0.0 {
                least_tensile = least;
            }
        }
        if with_tangent {
            self.kept_last = least_tensile.is_finite();
        }
        Ok(ActiveSetRules { first_touch, entry_cut, release_cut, lone, least_tensile, band })
    }

    /// Whether point k, of trial multiplier `trial`, is active in this evaluation by `rules`,
    /// and whether it was at the last evaluation with a tangent: returns (was active, active).
    /// Its changes go into `changes`, and when `own` (this process's point) into the debug
    /// `tally` (deferred, released, entering, penetrating, held); an evaluation with a tangent
    /// records the new state, its flips and freezing.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn decide_point(&mut self, k: usize, trial: f64, first: bool, with_tangent: bool, own: bool, rules: &ActiveSetRules, changes: &mut usize, tally: &mut [usize; 5]) -> (bool, bool) {
        let was_active = self.last_active[k] && !first;
        // touching points (Psi = 0) belong to the active set
        let wanted = trial <= 0.0;
        if first {
            self.last_active[k] = if rules.first_touch.is_some() { false } else { wanted };
        }
        // a penetrating point held back by the entry rule: still a change (the step is not
        // converged), but neither force nor tangent in this evaluation
        let deferred = with_tangent && !self.hold_active_set && wanted && !self.last_active[k] && !self.frozen[k] && trial > rules.entry_cut;
        // a tension that fell at least tenfold since the last tangent: the remainder of a
        // convex punch's linearisation converging away, not a lift-off (see CONVERGING_TENSION)
        let converging = self.hold_converging && self.last_trial[k] > 0.0 && trial < CONVERGING_TENSION * self.last_trial[k];
        if with_tangent && own {
            for (i, on) in [deferred, was_active && !wanted, !was_active && wanted, wanted].into_iter().enumerate() {
                tally[i] += on as usize;
            }
        }
        let active = if deferred {
            *changes += 1;
            false
        } else if with_tangent && (self.hold_after_update || (self.entered[k] && self.hold_after_entry && !self.hold_active_set && (!self.predicted_step || self.entered_deep[k])) || trial < rules.release_cut || converging || trial == rules.least_tensile) && self.last_active[k] && !wanted && !self.frozen[k] {
            // right after an augmented-Lagrangian update (hold_after_update), or right after
            // the point entered: not released yet. A Newton step puts a point that enters onto
            // the punch's tangent plane at its last position; on a convex punch Psi is positive
            // there by about d^T H d / 2 (d its step), so the point would be released at once
            // and the plate, free of its force, spring back into the punch at the next iterate:
            // a first touch under a whole load step swung in and out until it froze, and the
            // step was cut back seven times on the README's ball. Kept for one iteration, its
            // force is the exact lambda_bar + eps Psi (briefly tensile) and the curvature term
            // lambda H of the tangent brings it back onto the punch (not in a step started
            // from a coarse mesh's solution, which has no such overshoot). Likewise a point whose
            // tension is a small fraction of the most tensile point's (release_cut): it leaves
            // after the points that pull hardest. A held point counts as a change (no state
            // with a tensile force is converged) but not as a flip.
            if !self.hold_after_update {
                *changes += 1;
            }
            tally[4] += usize::from(own);
            true
        } else if self.hold_active_set {
            // the paper's trial and error: the set stays fixed while Newton converges on it
            if wanted != self.last_active[k] && !self.frozen[k] {
                *changes += 1;
            }
            self.last_active[k]
        } else {
            // a residual-only evaluation (a line-search trial) reports the changes against
            // the set of the last tangent but records nothing: the trial may be discarded
            if wanted != self.last_active[k] && !self.frozen[k] {
                *changes += 1;
                if with_tangent {
                    record_flip(&mut self.flips[k], &mut self.frozen[k], if rules.lone { self.lone_max_flips } else { self.max_flips });
                }
            }
            if with_tangent {
                self.last_active[k] = wanted;
            }
            wanted
        };
        (was_active, active)
    }

    /// An entering point (active now, not before) deep inside the punch, or at the body's first
    /// contact, of multiplier `lambda`: it gets the Gauss-Newton tangent (see [`DEEP_ENTRY_RATIO`]).
    pub(super) fn deep_entry(&self, active: bool, was_active: bool, lambda: f64, psi: f64, grad: &Vector3<f64>, hess_at: Option<&Vector3<f64>>) -> bool {
        self.gauss_newton_entry
            && active
            && !was_active
            && lambda < 0.0
            && hess_at.is_some_and(|x| self.converged_scale == 0.0 || psi.abs() * self.placed().hessian(x).norm() > DEEP_ENTRY_RATIO * grad.norm_squared())
    }
}

//! The constraint of one punch: the pair (the punch, its motion, the points that may touch it, the
//! settings of the rules), each point's state after an evaluation, and what is read off it (the
//! penetration, the constraint's violation, the reaction, the pressures); the perturbed
//! Lagrangian's multipliers lambda_bar and their augmented-Lagrangian update.

use super::first_touch::{ENTRY_FRACTION, FIRST_TOUCH_FRACTION, LONE_MAX_FLIPS, RELEASE_FRACTION, STEP_START_ENTRY_FRACTION};
use super::kinematics::{Kinematics, SurfaceAtPoint};
use super::friction_law::Friction;
use super::rotation::Turn;
use super::{ContactFace, ForceDrive, PointShare, PunchMotion, PunchRotation, Turned};
use crate::surface::ContactSurface;
use nalgebra::Vector3;
use std::sync::Arc;

/// How the constraint is evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ContactKinematics {
    /// Psi at the current position of the point (large displacements, eq. 3.5).
    Exact,
    /// The shallow, geometrically linear constraint: Psi linearised about the reference position
    /// along a fixed direction n, Psi(X) + (grad Psi(X) . n)(u . n). The force acts along n on the
    /// undeformed body and lambda is the pressure itself (eq. 3.9).
    Shallow { direction: [f64; 3] },
}

/// One point that may touch the punch: its reference position, the global dofs of its
/// displacement (three components) and its weight (tributary area).
#[derive(Debug, Clone, Copy)]
pub struct ContactPoint {
    pub node: usize,
    pub x_ref: [f64; 3],
    pub dofs: [usize; 3],
    pub weight: f64,
}

/// The state of one contact point after an evaluation.
#[derive(Debug, Clone, Copy, Default)]
pub struct PointState {
    /// Psi at the current position (the gap function, <0 means penetration).
    pub psi: f64,
    /// grad Psi at the current position.
    pub grad: [f64; 3],
    /// The multiplier (<= 0 in contact).
    pub lambda: f64,
    /// In the active set.
    pub active: bool,
}

/// A rigid punch, its motion, and the points of the body that may touch it.
pub struct ContactPair {
    pub name: String,
    pub surface: Arc<dyn ContactSurface>,
    /// The prescribed punch displacement as a function of the load factor t (t times a vector, or a
    /// path), plus s * direction when it is force-driven.
    pub motion: PunchMotion,
    /// Pressed by a prescribed force: its displacement along a direction is an unknown.
    pub drive: Option<ForceDrive>,
    pub points: Vec<ContactPoint>,
    /// The regularisation parameter eps_reg (force per unit area per unit of Psi).
    pub eps_reg: f64,
    pub kinematics: ContactKinematics,
    /// Augmented-Lagrangian multipliers lambda_bar (zero: plain perturbed Lagrangian).
    pub lambda_bar: Vec<f64>,
    /// State at the last evaluation.
    pub state: Vec<PointState>,
    /// How often each point changed between active and inactive during the current load step.
    pub flips: Vec<u32>,
    /// Active flags at the last evaluation with a tangent (line-search probes do not count).
    pub last_active: Vec<bool>,
    /// Keep the active set fixed during Newton iterations and update it only through
    /// [`update_active_set`](Self::update_active_set) (the paper's trial and error). When false the
    /// set follows every iterate (semi-smooth Newton).
    pub hold_active_set: bool,
    /// The active set was initialised from a first evaluation (points with Psi <= 0).
    pub initialized: bool,
    /// Points that cycled in this step (see [`ContactPair::max_flips`]).
    pub frozen: Vec<bool>,
    /// After this many changes of state inside one load step a point stops counting as a change
    /// and keeps the active-side tangent for the rest of the step, with its force still exact
    /// (lambda = min(0, lambda_bar + eps Psi)): a damped Newton step at the kink that ends the
    /// cycling and converges to the exact (non-adhesive) solution.
    pub max_flips: u32,
    /// The same for a change made while at most one point of the pair was active (a lone point
    /// swinging in and out, the set empty every other iteration; also every point of a set that
    /// was emptied and enters again): default [`LONE_MAX_FLIPS`].
    pub lone_max_flips: u32,
    /// The largest |lambda| seen in the current load step (the scale of "near the kink" for
    /// frozen points while every point is momentarily inactive).
    pub lambda_scale: f64,
    /// Where the surface was last queried for each point, and Psi and its gradient there:
    /// computed in parallel before the points are visited in order (a die given by a triangle
    /// mesh or an expression costs microseconds per point), and not again while the point stays
    /// where it was (Newton's next iteration starts where the line search's accepted trial
    /// evaluated).
    pub(super) surface_at_points: Vec<SurfaceAtPoint>,
    /// Damped growth of the active set: in an evaluation with a tangent, a penetrating inactive
    /// point enters the active set only where its trial multiplier lambda_bar + eps Psi is at
    /// most `entry_fraction` times the most negative trial of the inactive points (the deepest
    /// half of the new penetrations with the default [`ENTRY_FRACTION`]); the others count as
    /// changes and enter at a later iteration if they still penetrate. 0: every penetrating
    /// point enters at once (plain semi-smooth Newton). A Newton step from too small a set
    /// leaves the plate free around it, so it penetrates the punch far beyond the contact zone
    /// of the solution; taking all of that band in overshoots, and an overshooting set comes
    /// back one ring of nodes per iteration (only its outermost ring turns tensile, the
    /// multipliers inside a conforming zone being close to zero). From an empty set (the first
    /// evaluation, or every point released) the fraction is [`FIRST_TOUCH_FRACTION`], at the
    /// first evaluation with a tangent of a load step [`STEP_START_ENTRY_FRACTION`].
    pub entry_fraction: f64,
    /// The entry fraction from an empty active set (default [`FIRST_TOUCH_FRACTION`]); None:
    /// every penetrating point enters at the first evaluation, `entry_fraction` after a release.
    pub first_touch_fraction: Option<f64>,
    /// The entry fraction at the first evaluation with a tangent of a load step (default
    /// [`STEP_START_ENTRY_FRACTION`]); None: `entry_fraction`.
    pub step_start_entry_fraction: Option<f64>,
    /// No evaluation with a tangent yet in this load step.
    pub(super) step_start: bool,
    /// This load step started from an outside prediction of its answer (the solution on a
    /// coarse mesh, [`crate::mesh::coarse_path`]): no damped entry in it, every penetrating point
    /// enters at once. The damping guards against the secant predictor's overshoot, which a
    /// prediction within the coarse mesh's error does not have: on `stamp bench --problem
    /// sphere-displacement` at n = 80 the damped rules took 34 Newton iterations from the coarse
    /// start (the set grew by the deepest half of a thin band at each), undamped 26.
    pub(super) predicted_step: bool,
    /// An augmented-Lagrangian update ([`augment`](Self::augment)) came since the last evaluation
    /// with a tangent: that evaluation keeps every active point active. The update (lambda_bar <-
    /// lambda, at the iterate where it was made) makes a point with a small gap and a negative
    /// lambda_bar look tensile at that same iterate (trial lambda_bar + 2 eps Psi), before the
    /// plate has answered the new multipliers; released, it penetrates again at the next iterate
    /// and re-enters. Measured on `stamp run` of sphere-ss-displacement at n = 20: 22 points out
    /// and the same 22 back in at each step's update, one Newton iteration each (40 -> 32 Newton
    /// iterations in 5 steps; docs/performance.md).
    pub(super) hold_after_update: bool,
    /// The last evaluation with a tangent kept the least tensile point of a set it would have
    /// emptied (see `evaluate`): the next one may empty it.
    pub(super) kept_last: bool,
    /// Keep the least tensile point of a set an evaluation would empty (default true).
    pub guard_empty: bool,
    /// The point kinematics of the last evaluation (scratch, reused).
    pub(super) kinematics_scratch: Vec<Kinematics>,
    /// The integrated discretisation's face ([`ContactFace`]); None: the paper's nodal collocation.
    pub(super) face: Option<ContactFace>,
    /// The kinematics at the face's quadrature points at the last evaluation (integrated only).
    pub(super) site_scratch: Vec<Kinematics>,
    /// The points that gave a tangent in the last evaluation (integrated only, scratch).
    pub(super) tangent_points: Vec<bool>,
    /// Integrated only: the points whose patch the model's sparse pattern couples (see
    /// [`coupled_nodes`](Self::coupled_nodes)). Coupling every candidate's patch would make the
    /// factor of a large face several times denser, so only the points near contact are coupled,
    /// and more when contact reaches points that are not ([`extend_coupling`](Self::extend_coupling)).
    pub(super) coupled: Vec<bool>,
    /// Bumped whenever `coupled` grows (the model rebuilds its pattern then).
    pub(super) coupling_version: u64,
    /// A point that gave a tangent in the last evaluation is not coupled: its tangent lost the
    /// entries outside the pattern (an inexact Newton step) until the model couples it.
    pub(super) needs_coupling: bool,
    /// A point is coupled once its gap (Psi / |grad Psi|) is at most this length (set by the
    /// caller: the plate's thickness, say); default 0: only points in contact.
    pub coupling_reach: f64,
    /// The points that entered the active set at the last evaluation with a tangent: the next
    /// such evaluation does not release them (see [`ContactPair::evaluate`]).
    pub(super) entered: Vec<bool>,
    /// The points that entered with the Gauss-Newton tangent at that evaluation (see
    /// [`DEEP_ENTRY_RATIO`](super::DEEP_ENTRY_RATIO)): held at the next one also in a step started from an outside
    /// prediction, whose other entries are not held.
    pub(super) entered_deep: Vec<bool>,
    /// Hold a point that entered for one iteration (default true; false: the plain semi-smooth
    /// rule, which releases it at once).
    pub hold_after_entry: bool,
    /// Damped release of the active set, the counterpart of `entry_fraction`: in an evaluation
    /// with a tangent, an active point whose trial multiplier turned tensile is released only
    /// where its trial is at least `release_fraction` times the most tensile trial of the active
    /// points; the others stay active for this iteration (with their exact, briefly tensile,
    /// force) and count as changes. Default [`RELEASE_FRACTION`]; 0: every tensile point leaves
    /// at once.
    pub release_fraction: f64,
    /// Hold an active point whose trial multiplier turned tensile while that tension fell at
    /// least [`CONVERGING_TENSION`](super::CONVERGING_TENSION)-fold since the last evaluation with a tangent (see
    /// [`ContactPair::evaluate`]); default true.
    pub hold_converging: bool,
    /// The Gauss-Newton tangent for a point that enters the active set deep inside the punch or
    /// at the body's first contact (see [`DEEP_ENTRY_RATIO`](super::DEEP_ENTRY_RATIO)); default true. False: every active
    /// point's tangent is the exact derivative.
    pub gauss_newton_entry: bool,
    /// The body touched the punch in a converged state before this load step: its largest
    /// |lambda| then (0: this step is the first contact).
    pub(super) converged_scale: f64,
    /// Each point's trial multiplier at the last evaluation with a tangent.
    pub(super) last_trial: Vec<f64>,
    /// The points this process evaluates in a distributed run (see [`PointShare`]); None: all.
    pub(super) share: Option<PointShare>,
    /// Coulomb friction ([`set_friction`](Self::set_friction)); None: frictionless.
    pub friction: Option<Friction>,
    /// The punch's prescribed rotation about a pivot that travels with its translation
    /// (docs/design.md, "Punches that turn"); None: it only translates.
    pub rotation: Option<PunchRotation>,
    /// The rotation at the last evaluation's load factor (None: not turned).
    pub(super) turn: Option<Turn>,
}

impl ContactPair {
    pub fn new(name: impl Into<String>, surface: Arc<dyn ContactSurface>, points: Vec<ContactPoint>, eps_reg: f64, kinematics: ContactKinematics) -> Self {
        let n = points.len();
        ContactPair {
            name: name.into(),
            surface,
            motion: PunchMotion::default(),
            drive: None,
            points,
            eps_reg,
            kinematics,
            lambda_bar: vec![0.0; n],
            state: vec![PointState::default(); n],
            flips: vec![0; n],
            frozen: vec![false; n],
            last_active: vec![false; n],
            hold_active_set: false,
            initialized: false,
            max_flips: 10,
            lone_max_flips: LONE_MAX_FLIPS,
            lambda_scale: 0.0,
            surface_at_points: SurfaceAtPoint::none(n),
            entry_fraction: ENTRY_FRACTION,
            first_touch_fraction: Some(FIRST_TOUCH_FRACTION),
            step_start_entry_fraction: Some(STEP_START_ENTRY_FRACTION),
            step_start: true,
            predicted_step: false,
            hold_after_update: false,
            kept_last: false,
            guard_empty: true,
            kinematics_scratch: Vec::new(),
            face: None,
            site_scratch: Vec::new(),
            tangent_points: Vec::new(),
            coupled: vec![false; n],
            coupling_version: 0,
            needs_coupling: false,
            coupling_reach: 0.0,
            entered: vec![false; n],
            entered_deep: vec![false; n],
            hold_after_entry: true,
            release_fraction: RELEASE_FRACTION,
            hold_converging: true,
            gauss_newton_entry: true,
            converged_scale: 0.0,
            last_trial: vec![0.0; n],
            share: None,
            friction: None,
            rotation: None,
            turn: None,
        }
    }

    /// Coulomb friction of coefficient `mu` between the body and this punch (docs/design.md,
    /// "Friction"); 0: none (frictionless, the same operations as without this call). Exact
    /// kinematics only, set after eps_reg (the tangential regularisation is eps_reg |grad Psi|^2
    /// where the punch touches) and after the integrated face if any ([`with_face`](Self::with_face):
    /// the friction state is then at the face's quadrature points).
    pub fn set_friction(&mut self, mu: f64) -> crate::Result<()> {
        if !(mu.is_finite() && mu >= 0.0) {
            return Err(crate::StampError::Problem(format!("the friction coefficient must be a finite number >= 0, got {mu}")));
        }
        if mu == 0.0 {
            self.friction = None;
            return Ok(());
        }
        if self.kinematics != ContactKinematics::Exact {
            return Err(crate::StampError::Problem("friction needs the exact contact kinematics, not the shallow constraint".into()));
        }
        if self.face.is_some() && self.rotation.is_some() {
            // the integrated scheme's friction sites are held in the translated frame only
            return Err(crate::StampError::Problem("friction on a punch that turns (`rotation`) is implemented for contact = \"nodal\" only, not \"integrated\"".into()));
        }
        let g = self.contact_gradient_norm();
        // the friction's sites: the points (nodal), the face's quadrature points (integrated)
        let sites: Vec<[f64; 3]> = match &self.face {
            None => self.points.iter().map(|p| p.x_ref).collect(),
            Some(face) => face.quadrature.iter().map(|q| (0..4).fold([0.0; 3], |x, a| std::array::from_fn(|i| x[i] + q.shape[a] * self.points[q.points[a] as usize].x_ref[i]))).collect(),
        };
        self.friction = Some(Friction::new(mu, self.eps_reg * g * g, sites.into_iter()));
        Ok(())
    }

    /// Evaluate only the points of `own` nodes from now on (`own[n]`: this process owns node n),
    /// with the punch's totals reduced over the processes by `reduce`; `leader`: this process
    /// adds the force-driven punch's load and prints the debug lines. None: every point again.
    /// See [`PointShare`].
    pub fn set_share(&mut self, own: Option<(&[bool], Arc<dyn crate::share::Reduce>, bool)>) {
        self.share = own.map(|(nodes, reduce, leader)| {
            let own_points = self.points.iter().map(|p| nodes.get(p.node).copied().unwrap_or(false)).collect();
            PointShare::new(own_points, self.face.as_ref(), reduce, leader)
        });
    }

    /// The points this process evaluates (all without a share).
    pub(super) fn evaluates(&self, k: usize) -> bool {
        self.share.as_ref().is_none_or(|s| s.evaluated[k])
    }

    /// The points this process owns (all without a share).
    pub(super) fn owns(&self, k: usize) -> bool {
        self.share.as_ref().is_none_or(|s| s.own[k])
    }

    /// Make every point's state (and the integrated face's kinematics) whole on every process
    /// from their owners' (collective; nothing without a share): after a converged step, for the
    /// outputs and [`reaction`](Self::reaction), [`pressures`](Self::pressures),
    /// [`max_penetration`](Self::max_penetration), which read every point; with friction, every
    /// point's friction state too (`PointShare::gather_friction`), so that the step's commit and
    /// the friction outputs are the whole punch's.
    pub fn gather_state(&mut self) -> crate::Result<()> {
        let Some(share) = &self.share else { return Ok(()) };
        let mut buf = vec![0.0; 6 * self.points.len()];
        for (k, s) in self.state.iter().enumerate().filter(|(k, _)| share.own[*k]) {
            buf[6 * k..6 * k + 6].copy_from_slice(&[s.psi, s.grad[0], s.grad[1], s.grad[2], s.lambda, f64::from(u8::from(s.active))]);
        }
        share.reduce.sum(&mut buf)?;
        for (s, b) in self.state.iter_mut().zip(buf.chunks_exact(6)) {
            *s = PointState { psi: b[0], grad: [b[1], b[2], b[3]], lambda: b[4], active: b[5] != 0.0 };
        }
        if let Some(f) = &mut self.friction {
            share.gather_friction(f, if self.face.is_some() { &share.gathers_site } else { &share.own })?;
        }
        if let Some(face) = &self.face {
            let n = face.quadrature.len();
            self.site_scratch.resize(n, (0.0, Vector3::zeros(), 0.0, None));
            let mut buf = vec![0.0; 5 * n];
            for (q, site) in self.site_scratch.iter().enumerate().filter(|(q, _)| share.gathers_site[*q]) {
                buf[5 * q..5 * q + 5].copy_from_slice(&[site.0, site.1[0], site.1[1], site.1[2], site.2]);
            }
            share.reduce.sum(&mut buf)?;
            for ((site, b), &mine) in self.site_scratch.iter_mut().zip(buf.chunks_exact(5)).zip(&share.sites) {
                let hess = if mine { site.3 } else { None };
                *site = (b[0], Vector3::new(b[1], b[2], b[3]), b[4], hess);
            }
        }
        Ok(())
    }

    /// The punch's surface at load factor `t` in the translated frame (positions x - d, d the
    /// punch displacement): turned by its rotation at t, if it has one. Psi, the gradient and the
    /// Hessian the constraint uses; the checks and outputs query the punch through it.
    pub fn surface_at(&self, t: f64) -> Turned<'_> {
        Turned { surface: &*self.surface, turn: self.rotation.as_ref().and_then(|r| r.turn(t)) }
    }

    /// The punch's surface as turned at the last evaluation.
    pub(super) fn placed(&self) -> Turned<'_> {
        Turned { surface: &*self.surface, turn: self.turn }
    }

    /// The punch displacement at load factor `t` for the unknowns `u`: the prescribed motion at t,
    /// plus s * direction when force-driven.
    pub fn punch_displacement(&self, u: &[f64], t: f64) -> [f64; 3] {
        let mut d = Vector3::from(self.motion.displacement(t));
        if let Some(f) = &self.drive {
            d += Vector3::from(f.direction) * u[f.dof];
        }
        d.into()
    }

    /// The unknown displacement s of a force-driven punch along its direction.
    pub fn drive_displacement(&self, u: &[f64]) -> Option<f64> {
        self.drive.as_ref().map(|f| u[f.dof])
    }

    /// Augmented-Lagrangian update: lambda_bar <- lambda (of the points this process evaluates).
    pub fn augment(&mut self) {
        self.hold_after_update = true;
        for k in 0..self.points.len() {
            if self.evaluates(k) {
                self.lambda_bar[k] = self.state[k].lambda;
            }
        }
        if let Some(n) = self.friction.as_ref().map(|f| f.status.len()) {
            let evaluated: Vec<bool> = (0..n).map(|k| self.evaluates_friction(k)).collect();
            if let Some(f) = &mut self.friction {
                f.augment(|k| evaluated[k]);
            }
        }
    }

    /// How far the augmented-Lagrangian multipliers are from converged, as a length: the largest
    /// penetration over all points and the largest gap |Psi| / |grad Psi| of the active points
    /// (an active point with a gap carries more than its share, lambda_bar too large: after
    /// unloading it would press the plate down with a force the load no longer provides).
    /// With a share: of this process's own points at its last evaluation (the largest over the
    /// processes is the punch's).
    pub fn constraint_violation(&self) -> f64 {
        let gaps = self
            .state
            .iter()
            .zip(&self.lambda_bar)
            .enumerate()
            .filter(|(k, (s, lb))| self.owns(*k) && s.active && **lb < 0.0)
            .map(|(_, (s, _))| {
                let g = Vector3::from(s.grad).norm();
                if g > 0.0 { s.psi.abs() / g } else { 0.0 }
            })
            .fold(0.0, f64::max);
        let violation = gaps.max(self.penetration_where(|k| self.owns(k)));
        match &self.friction {
            None => violation,
            Some(f) => violation.max(f.stick_violation(|k| self.friction_normal(k), |k| self.counts_friction(k))),
        }
    }

    /// The largest penetration max(0, -Psi) over the points, in units of Psi divided by
    /// |grad Psi| (a length for any surface). With a share: of every point after a converged
    /// step ([`gather_state`](Self::gather_state)).
    pub fn max_penetration(&self) -> f64 {
        self.penetration_where(|_| true)
    }

    fn penetration_where(&self, at: impl Fn(usize) -> bool) -> f64 {
        self.state
            .iter()
            .enumerate()
            .filter(|(k, _)| at(*k))
            .map(|(_, s)| {
                let g = Vector3::from(s.grad).norm();
                if g > 0.0 { (-s.psi / g).max(0.0) } else { 0.0 }
            })
            .fold(0.0, f64::max)
    }

    /// Euclidean norm of the nodal contact forces w lambda grad Psi (the size of the forces in play,
    /// whether or not they cancel in the total). With a share: its square over this process's own
    /// points is [`force_norm_squared`](Self::force_norm_squared), to be summed over the processes.
    pub fn force_norm(&self) -> f64 {
        self.force_norm_squared().sqrt()
    }

    /// The square of [`force_norm`](Self::force_norm) over this process's own points (all without
    /// a share) at its last evaluation.
    pub fn force_norm_squared(&self) -> f64 {
        self.points
            .iter()
            .zip(&self.state)
            .enumerate()
            .filter(|(k, _)| self.owns(*k))
            .map(|(_, (p, s))| (p.weight * s.lambda).powi(2) * Vector3::from(s.grad).norm_squared())
            .sum::<f64>()
    }

    /// Total force of the punch on the body, sum of -w lambda grad Psi, and with friction the sum
    /// of the tangential forces -w t.
    pub fn reaction(&self) -> [f64; 3] {
        let mut r = [0.0; 3];
        for (p, s) in self.points.iter().zip(&self.state) {
            for i in 0..3 {
                r[i] -= p.weight * s.lambda * s.grad[i];
            }
        }
        if let Some(f) = &self.friction {
            for (k, t) in f.traction.iter().enumerate() {
                let w = self.friction_weight(k);
                for i in 0..3 {
                    r[i] -= w * t[i];
                }
            }
        }
        r
    }

    /// The friction force of the body on the punch, sum of w t (zero without friction).
    pub fn friction_force(&self) -> [f64; 3] {
        let mut r = [0.0; 3];
        if let Some(f) = &self.friction {
            for (k, t) in f.traction.iter().enumerate() {
                let w = self.friction_weight(k);
                for i in 0..3 {
                    r[i] += w * t[i];
                }
            }
        }
        r
    }

    /// The energy friction dissipated over the converged steps (None without friction).
    pub fn friction_dissipation(&self) -> Option<f64> {
        self.friction.as_ref().map(|f| f.dissipation.iter().sum())
    }

    /// The numbers of sticking and slipping points at the last evaluation (None without friction;
    /// integrated: of the points' states of [`friction_at_points`](Self::friction_at_points)).
    pub fn stick_slip_counts(&self) -> Option<(usize, usize)> {
        let status = match &self.face {
            None => self.friction.as_ref()?.status.clone(),
            Some(_) => self.friction_at_points()?.status,
        };
        Some((status.iter().filter(|&&s| s == super::STICK).count(), status.iter().filter(|&&s| s == super::SLIP).count()))
    }

    /// Contact pressure q_n = -lambda |grad Psi| (>= 0 in compression) at every point. With the
    /// integrated discretisation: the contact force on the point along its mean normal per unit
    /// area, -f_j . n_j / A_j (f_j = int N_j lambda_h grad Psi dA), the nodal value of a field
    /// whose integral sum_j A_j q_j is the punch's normal force.
    pub fn pressures(&self) -> Vec<f64> {
        match &self.face {
            None => self.state.iter().map(|s| -s.lambda * Vector3::from(s.grad).norm()).collect(),
            Some(face) => self.integrated_pressures(face),
        }
    }
}

//! Frictionless contact of a set of points with a rigid punch, by the perturbed Lagrangian method
//! (paper eqs. 3.8, 3.15-3.16, 4.6, 4.9-4.10, 4.13-4.15), written against [`ContactSurface`] only.
//!
//! Every contact point carries a multiplier lambda (a force per unit reference area: the nodal
//! weights are tributary areas). On the active set the regularised constraint
//! Psi - (lambda - lambda_bar) / eps_reg = 0 holds, off it lambda = 0; lambda <= 0 in contact. The
//! multiplier is condensed point by point, lambda = min(0, lambda_bar + eps_reg * Psi), so the
//! global system keeps only displacement unknowns and its pattern never changes; the solution is
//! that of the paper's (V, Lambda) system. lambda_bar = 0 is the paper's perturbed Lagrangian;
//! updating lambda_bar to the converged lambda (augmented Lagrangian, Uzawa) drives the
//! penetration to zero whatever eps_reg is.
//!
//! The contact force on the body is -lambda grad Psi per unit area (eq. 3.13), the contact pressure
//! q_n = -lambda |grad Psi| >= 0 (eq. 3.14 with compression counted positive).
//!
//! A punch is moved either by a prescribed displacement ([`PunchMotion`]: a vector times the load
//! factor, or a piecewise-linear path in the load factor) or by a
//! prescribed force ([`ForceDrive`]): then its rigid displacement s along a fixed direction n is one
//! more unknown, with the punch's equilibrium as its equation,
//! R_s = sum_k w_k lambda_k dPsi_k/ds - t F = -n . sum_k w_k lambda_k grad Psi_k - t F = 0
//! (dPsi/ds = -grad Psi . n since the punch sits at x - d, d = motion(t) + s n). This is the
//! derivative of the penalty energy sum w eps Psi^2 / 2 minus the work t F s, so the bordered
//! tangent stays symmetric wherever the plate's is. The model appends these unknowns after the
//! nodal dofs (see [`crate::model::Model`]).
//!
//! The default eps_reg is [`automatic_eps_reg`]: a contact spring per node that is a fixed multiple
//! of the plate's membrane stiffness around it.

use crate::surface::ContactSurface;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
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

/// A punch pressed by a prescribed force instead of moved by a prescribed displacement: the force
/// `force * t` (t the load factor) pushes the punch along the unit `direction`, and its rigid
/// displacement s along `direction` is an unknown. `dof` is the index of s in the full unknown
/// vector; [`crate::model::Model`] assigns it (after the nodal dofs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceDrive {
    pub direction: [f64; 3],
    pub force: f64,
    pub dof: usize,
}

impl ForceDrive {
    /// A force `force` (at load factor 1) along `direction` (normalised here; must be non-zero).
    pub fn new(direction: [f64; 3], force: f64) -> crate::Result<Self> {
        let n = Vector3::from(direction);
        let len = n.norm();
        if !(len > 0.0 && len.is_finite() && force.is_finite()) {
            return Err(crate::StampError::Problem(format!("a force-driven punch needs a finite, non-zero direction and a finite force, got {direction:?} and {force}")));
        }
        Ok(ForceDrive { direction: (n / len).into(), force, dof: usize::MAX })
    }
}

/// How a displacement-driven punch moves with the load factor t. The punch position is data, not
/// an unknown: the model only evaluates [`displacement`](PunchMotion::displacement) at each t.
#[derive(Debug, Clone, PartialEq)]
pub enum PunchMotion {
    /// t times this displacement (the displacement at load factor 1).
    Linear([f64; 3]),
    /// Piecewise linear in t through the points (t_k, d_k), t strictly increasing from t_0 = 0
    /// with d_0 = 0 (see [`PunchMotion::path`]); held at the last displacement beyond the last t,
    /// and at zero below 0.
    Path(Vec<(f64, [f64; 3])>),
}

impl From<[f64; 3]> for PunchMotion {
    fn from(m: [f64; 3]) -> Self {
        PunchMotion::Linear(m)
    }
}

impl Default for PunchMotion {
    fn default() -> Self {
        PunchMotion::Linear([0.0; 3])
    }
}

impl PunchMotion {
    /// A path through `rows` (t, displacement). The rows' t must be finite and strictly
    /// increasing, the first at least 0; when the first t is 0 its displacement must be zero (the
    /// punch starts where its geometry puts it), and when it is above 0 the path starts at (0, 0)
    /// implicitly. The error says what is wrong with which row (0-based).
    pub fn path(rows: &[(f64, [f64; 3])]) -> Result<PunchMotion, String> {
        if rows.is_empty() {
            return Err("a path needs at least one row [t, d1, d2, d3]".into());
        }
        for (k, (t, d)) in rows.iter().enumerate() {
            if !(t.is_finite() && d.iter().all(|x| x.is_finite())) {
                return Err(format!("row {k}: every number must be finite"));
            }
            if k == 0 && *t < 0.0 {
                return Err(format!("row 0: the load factor t = {t} must be at least 0"));
            }
            if k == 0 && *t == 0.0 && *d != [0.0; 3] {
                return Err("row 0: at t = 0 the displacement must be [0, 0, 0] (place the punch by its geometry; the path starts there)".into());
            }
            if k > 0 && !(*t > rows[k - 1].0) {
                return Err(format!("row {k}: the load factors must increase strictly, but t = {t} follows t = {}", rows[k - 1].0));
            }
        }
        let mut points = Vec::with_capacity(rows.len() + 1);
        if rows[0].0 > 0.0 {
            points.push((0.0, [0.0; 3]));
        }
        points.extend_from_slice(rows);
        Ok(PunchMotion::Path(points))
    }

    /// The punch displacement at load factor `t`.
    pub fn displacement(&self, t: f64) -> [f64; 3] {
        match self {
            PunchMotion::Linear(m) => m.map(|x| x * t),
            PunchMotion::Path(points) => {
                let Some(k) = points.iter().position(|p| p.0 > t) else {
                    return points.last().map_or([0.0; 3], |p| p.1);
                };
                if k == 0 {
                    return points[0].1;
                }
                let ((t0, a), (t1, b)) = (points[k - 1], points[k]);
                let s = (t - t0) / (t1 - t0);
                [0, 1, 2].map(|i| a[i] + s * (b[i] - a[i]))
            }
        }
    }

    /// True when the punch never moves.
    pub fn is_zero(&self) -> bool {
        match self {
            PunchMotion::Linear(m) => *m == [0.0; 3],
            PunchMotion::Path(points) => points.iter().all(|p| p.1 == [0.0; 3]),
        }
    }

    /// The direction in which the punch first moves, not normalised: the linear motion itself, or
    /// the first non-zero displacement of a path (its approach: a die that comes down then slides
    /// approaches along -x3). Zero for a punch that never moves.
    pub fn approach(&self) -> [f64; 3] {
        match self {
            PunchMotion::Linear(m) => *m,
            PunchMotion::Path(points) => points.iter().map(|p| p.1).find(|d| *d != [0.0; 3]).unwrap_or([0.0; 3]),
        }
    }
}

/// The default regularisation parameter: the penalty stiffness of a contact point per unit area and
/// unit penetration, k = eps_reg |grad Psi|^2 (q_n = eps_reg |grad Psi|^2 g for a penetration
/// g = -Psi / |grad Psi|), is set to [`AUTO_EPS_FACTOR`] times `membrane_stiffness / element_size^2`
/// (E h / l_e^2 for a plate): the contact spring k l_e^2 of one node is 100 times the membrane
/// stiffness E h of the plate around it: far stiffer than the plate's bending, yet far from the
/// round-off floor of the residual (a multiple of the stiffest element stiffness, not 1e7 times it).
/// The penetration is then about q_n l_e^2 / (100 E h); [`ContactPair::augment`] removes it when a
/// tolerance is asked for. `grad_norm` is |grad Psi| on the punch surface where it touches
/// ([`ContactPair::contact_gradient_norm`]: 2R for a sphere or cylinder written as |x - c|^2 - R^2,
/// 1 for a plane).
pub fn automatic_eps_reg(membrane_stiffness: f64, element_size: f64, grad_norm: f64) -> f64 {
    AUTO_EPS_FACTOR * membrane_stiffness / (element_size * element_size * grad_norm * grad_norm)
}

/// The factor c of [`automatic_eps_reg`].
pub const AUTO_EPS_FACTOR: f64 = 100.0;

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

/// Psi and its gradient at a point's last position (see `ContactPair::surface_at_points`).
#[derive(Debug, Clone, Copy)]
struct SurfaceAtPoint {
    x: Vector3<f64>,
    psi: f64,
    grad: Vector3<f64>,
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
    surface_at_points: Vec<SurfaceAtPoint>,
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
    step_start: bool,
    /// This load step started from an outside prediction of its answer (the solution on a
    /// coarse mesh, [`crate::coarse_path`]): no damped entry in it, every penetrating point
    /// enters at once. The damping guards against the secant predictor's overshoot, which a
    /// prediction within the coarse mesh's error does not have: on `stamp bench --problem
    /// sphere-displacement` at n = 80 the damped rules took 34 Newton iterations from the coarse
    /// start (the set grew by the deepest half of a thin band at each), undamped 26.
    predicted_step: bool,
    /// An augmented-Lagrangian update ([`augment`](Self::augment)) came since the last evaluation
    /// with a tangent: that evaluation keeps every active point active. The update (lambda_bar <-
    /// lambda, at the iterate where it was made) makes a point with a small gap and a negative
    /// lambda_bar look tensile at that same iterate (trial lambda_bar + 2 eps Psi), before the
    /// plate has answered the new multipliers; released, it penetrates again at the next iterate
    /// and re-enters. Measured on `stamp run` of sphere-ss-displacement at n = 20: 22 points out
    /// and the same 22 back in at each step's update, one Newton iteration each (40 -> 32 Newton
    /// iterations in 5 steps; docs/performance.md).
    hold_after_update: bool,
    /// The point kinematics of the last evaluation (scratch, reused).
    kinematics_scratch: Vec<(f64, Vector3<f64>, f64, Option<Vector3<f64>>)>,
}

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
            surface_at_points: vec![SurfaceAtPoint { x: Vector3::repeat(f64::NAN), psi: 0.0, grad: Vector3::zeros() }; n],
            entry_fraction: ENTRY_FRACTION,
            first_touch_fraction: Some(FIRST_TOUCH_FRACTION),
            step_start_entry_fraction: Some(STEP_START_ENTRY_FRACTION),
            step_start: true,
            predicted_step: false,
            hold_after_update: false,
            kinematics_scratch: Vec::new(),
        }
    }

    /// Forget the cycling history (at the start of a load step); `predicted`: the step starts from
    /// an outside prediction of its answer (see `predicted_step`).
    pub fn start_step(&mut self, predicted: bool) {
        self.predicted_step = predicted;
        self.flips.fill(0);
        self.frozen.fill(false);
        self.step_start = true;
        self.lambda_scale = self.state.iter().map(|s| s.lambda.abs()).fold(0.0, f64::max);
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

    /// |grad Psi| at the candidate point closest to the punch (smallest Psi / |grad Psi|) in the
    /// reference configuration: the gradient scale of [`automatic_eps_reg`]. 1 with no points.
    pub fn contact_gradient_norm(&self) -> f64 {
        let mut best = (f64::INFINITY, 1.0);
        for p in &self.points {
            let x = Vector3::from(p.x_ref);
            let g = self.surface.gradient(&x).norm();
            if g > 0.0 && g.is_finite() {
                let gap = self.surface.psi(&x) / g;
                if gap < best.0 {
                    best = (gap, g);
                }
            }
        }
        best.1
    }

    /// Evaluate Psi, the multipliers and the active set at the full unknown vector `u` and load
    /// factor `t`, add the contact forces lambda * w * grad Psi into `force` and, through
    /// `add_tangent(row, col, value)` (indices into `u`), the tangent w (eps G G^T + lambda H) of the
    /// active points, G and H the gradient and Hessian of Psi with respect to the point's
    /// displacement (and to s for a force-driven punch, whose equation R_s = sum w lambda dPsi/ds
    /// - t F is added into `force[drive.dof]`). Returns the number of points whose active state
    /// changed against the set of the last evaluation with a tangent (only such an evaluation
    /// records the new set).
    pub fn evaluate(&mut self, u: &[f64], t: f64, force: &mut [f64], mut add_tangent: Option<&mut dyn FnMut(usize, usize, f64)>) -> usize {
        let d = Vector3::from(self.punch_displacement(u, t));
        let drive = self.drive;
        let dn = drive.map(|f| Vector3::from(f.direction)).unwrap_or_else(Vector3::zeros);
        let mut changes = 0;
        let with_tangent = add_tangent.is_some();
        let first = !self.initialized;
        // "near the kink" is 1 % of the largest multiplier now, or of the largest in this step
        // when every point is momentarily inactive (a lone point swinging in and out)
        let current = self.state.iter().map(|s| s.lambda.abs()).fold(0.0, f64::max);
        self.lambda_scale = self.lambda_scale.max(current);
        let band = 1e-2 * if current > 0.0 { current } else { self.lambda_scale };
        let mut any_tangent = false;
        // Psi, its gradient with respect to the point's displacement and to s, and where the
        // Hessian is taken, for every point first (the entry rule below needs the deepest
        // penetration), in parallel. The surface is queried at x (exact kinematics) or at the
        // reference position moved back by the prescribed motion (shallow: linearised about it),
        // and not again while that point stays where it was.
        let mut kin = std::mem::take(&mut self.kinematics_scratch);
        kin.resize(self.points.len(), (0.0, Vector3::zeros(), 0.0, None));
        let surface = &*self.surface;
        let kinematics = self.kinematics;
        let prescribed = Vector3::from(self.motion.displacement(t));
        let s = drive.map(|f| u[f.dof]).unwrap_or(0.0);
        (kin.par_iter_mut(), self.surface_at_points.par_iter_mut(), self.points.par_iter()).into_par_iter().with_min_len(512).for_each(|(out, at, p)| {
            // (a worker thread may come from faer's kernels: see crate::linalg::vector_state)
            crate::linalg::vector_state::clean_upper_vector_state();
            let x_ref = Vector3::from(p.x_ref);
            let disp = Vector3::new(u[p.dofs[0]], u[p.dofs[1]], u[p.dofs[2]]);
            let x = match kinematics {
                ContactKinematics::Exact => x_ref + disp - d,
                ContactKinematics::Shallow { .. } => x_ref - prescribed,
            };
            // (NaN at the start: never equal)
            if x != at.x {
                let (psi, grad) = surface.psi_and_gradient(&x);
                *at = SurfaceAtPoint { x, psi, grad };
            }
            let SurfaceAtPoint { psi, grad: g, .. } = *at;
            *out = match kinematics {
                ContactKinematics::Exact => (psi, g, -g.dot(&dn), Some(x)),
                ContactKinematics::Shallow { direction } => {
                    // in the plate's displacement along n and in the punch's unknown s
                    let n = Vector3::from(direction);
                    let gn = g.dot(&n);
                    (psi + gn * disp.dot(&n) - g.dot(&dn) * s, n * gn, -g.dot(&dn), None)
                }
            };
        });
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
        let empty = first || !self.last_active.iter().zip(&self.frozen).any(|(a, f)| *a || *f);
        let entry_cut = if damped && (!first || first_touch.is_some()) {
            let deepest = kin
                .iter()
                .enumerate()
                .filter(|(k, _)| first || (!self.last_active[*k] && !self.frozen[*k]))
                .map(|(k, q)| self.lambda_bar[k] + self.eps_reg * q.0)
                .fold(0.0f64, f64::min);
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
        // at most one point active before this evaluation: a change is a lone point swinging
        let lone = !first && self.last_active.iter().filter(|a| **a).count() <= 1;
        for (k, p) in self.points.iter().enumerate() {
            let (psi, grad, grad_s, hess) = kin[k];
            let trial = self.lambda_bar[k] + self.eps_reg * psi;
            // touching points (Psi = 0) belong to the active set
            let wanted = trial <= 0.0;
            if first {
                self.last_active[k] = if first_touch.is_some() { false } else { wanted };
            }
            // a penetrating point held back by the entry rule: still a change (the step is not
            // converged), but neither force nor tangent in this evaluation
            let deferred = with_tangent && !self.hold_active_set && wanted && !self.last_active[k] && !self.frozen[k] && trial > entry_cut;
            let active = if deferred {
                changes += 1;
                false
            } else if with_tangent && self.hold_after_update && self.last_active[k] && !wanted && !self.frozen[k] {
                // right after an augmented-Lagrangian update: not released yet (hold_after_update)
                true
            } else if self.hold_active_set {
                // the paper's trial and error: the set stays fixed while Newton converges on it
                if wanted != self.last_active[k] && !self.frozen[k] {
                    changes += 1;
                }
                self.last_active[k]
            } else {
                // a residual-only evaluation (a line-search trial) reports the changes against
                // the set of the last tangent but records nothing: the trial may be discarded
                if wanted != self.last_active[k] && !self.frozen[k] {
                    changes += 1;
                    if with_tangent {
                        record_flip(&mut self.flips[k], &mut self.frozen[k], if lone { self.lone_max_flips } else { self.max_flips });
                    }
                }
                if with_tangent {
                    self.last_active[k] = wanted;
                }
                wanted
            };
            let lambda = if active { trial } else { 0.0 };
            self.state[k] = PointState { psi, grad: grad.into(), lambda, active };
            // a point that cycled keeps the active-side tangent near the kink (its force stays exact)
            let near_kink = !self.hold_active_set && self.frozen[k] && with_tangent && trial <= band;
            if !active && !near_kink {
                continue;
            }
            any_tangent = true;
            let w = p.weight;
            for i in 0..3 {
                force[p.dofs[i]] += w * lambda * grad[i];
            }
            if let Some(f) = &drive {
                force[f.dof] += w * lambda * grad_s;
            }
            if let Some(add) = add_tangent.as_deref_mut() {
                point_tangent(&*self.surface, p, drive.as_ref(), &dn, &grad, grad_s, hess.as_ref(), w * self.eps_reg, w * lambda, add);
            }
        }
        if let Some(f) = &drive {
            force[f.dof] -= t * f.force;
            // With no point in contact the punch's equation has no stiffness (it floats) and no state
            // is an equilibrium unless t F = 0. Keep the point closest to the punch on its active
            // branch, lambda = lambda_bar + eps Psi even where that pulls: Newton then brings the
            // punch onto the plate in one step instead of creeping towards it. Once a point
            // touches, this stops; at t F = 0 the punch rests touching the plate with no force.
            if !any_tangent {
                let closest = self
                    .state
                    .iter()
                    .enumerate()
                    .filter(|(_, s)| Vector3::from(s.grad).norm() > 0.0)
                    .min_by(|a, b| (a.1.psi / Vector3::from(a.1.grad).norm()).total_cmp(&(b.1.psi / Vector3::from(b.1.grad).norm())))
                    .map(|(k, _)| k);
                if let Some(k) = closest {
                    let p = &self.points[k];
                    let g = Vector3::from(self.state[k].grad);
                    let lambda = self.lambda_bar[k] + self.eps_reg * self.state[k].psi;
                    let (grad_s, hess_at) = match self.kinematics {
                        ContactKinematics::Exact => {
                            let disp = Vector3::new(u[p.dofs[0]], u[p.dofs[1]], u[p.dofs[2]]);
                            (-g.dot(&dn), Some(Vector3::from(p.x_ref) + disp - d))
                        }
                        ContactKinematics::Shallow { .. } => {
                            let x0 = Vector3::from(p.x_ref) - Vector3::from(self.motion.displacement(t));
                            (-self.surface.gradient(&x0).dot(&dn), None)
                        }
                    };
                    self.state[k].lambda = lambda;
                    for i in 0..3 {
                        force[p.dofs[i]] += p.weight * lambda * g[i];
                    }
                    force[f.dof] += p.weight * lambda * grad_s;
                    if let Some(add) = add_tangent.as_deref_mut() {
                        point_tangent(&*self.surface, p, Some(f), &dn, &g, grad_s, hess_at.as_ref(), p.weight * self.eps_reg, p.weight * lambda, add);
                    }
                }
            }
        }
        if first {
            self.initialized = true;
        }
        if with_tangent {
            self.step_start = false;
            self.hold_after_update = false;
        }
        self.kinematics_scratch = kin;
        changes
    }

    /// The paper's active-set update (eqs. 4.14b, 4.15a) after Newton converged on a fixed set: add
    /// the points with Psi < 0, drop those with lambda > 0. A point that changes `max_flips` times
    /// in one load step is held where it is (it sits at the kink, lambda ~ 0 either way). Returns the
    /// number of changes.
    pub fn update_active_set(&mut self) -> usize {
        let mut changes = 0;
        for k in 0..self.points.len() {
            if self.frozen[k] {
                continue;
            }
            let wanted = self.lambda_bar[k] + self.eps_reg * self.state[k].psi <= 0.0;
            if wanted != self.last_active[k] {
                self.last_active[k] = wanted;
                changes += 1;
                record_flip(&mut self.flips[k], &mut self.frozen[k], self.max_flips);
            }
        }
        changes
    }

    /// Augmented-Lagrangian update: lambda_bar <- lambda. Returns the largest penetration (-Psi) of
    /// the active points before the update.
    pub fn augment(&mut self) -> f64 {
        self.hold_after_update = true;
        for (lb, s) in self.lambda_bar.iter_mut().zip(&self.state) {
            *lb = s.lambda;
        }
        self.max_penetration()
    }

    /// How far the augmented-Lagrangian multipliers are from converged, as a length: the largest
    /// penetration over all points and the largest gap |Psi| / |grad Psi| of the active points
    /// (an active point with a gap carries more than its share, lambda_bar too large: after
    /// unloading it would press the plate down with a force the load no longer provides).
    pub fn constraint_violation(&self) -> f64 {
        let gaps = self
            .state
            .iter()
            .zip(&self.lambda_bar)
            .filter(|(s, lb)| s.active && **lb < 0.0)
            .map(|(s, _)| {
                let g = Vector3::from(s.grad).norm();
                if g > 0.0 { s.psi.abs() / g } else { 0.0 }
            })
            .fold(0.0, f64::max);
        gaps.max(self.max_penetration())
    }

    /// The largest penetration max(0, -Psi) over the points, in units of Psi divided by
    /// |grad Psi| (a length for any surface).
    pub fn max_penetration(&self) -> f64 {
        self.state
            .iter()
            .map(|s| {
                let g = Vector3::from(s.grad).norm();
                if g > 0.0 { (-s.psi / g).max(0.0) } else { 0.0 }
            })
            .fold(0.0, f64::max)
    }

    /// Euclidean norm of the nodal contact forces w lambda grad Psi (the size of the forces in play,
    /// whether or not they cancel in the total).
    pub fn force_norm(&self) -> f64 {
        self.points
            .iter()
            .zip(&self.state)
            .map(|(p, s)| (p.weight * s.lambda).powi(2) * Vector3::from(s.grad).norm_squared())
            .sum::<f64>()
            .sqrt()
    }

    /// Total force of the punch on the body, sum of -w lambda grad Psi.
    pub fn reaction(&self) -> [f64; 3] {
        let mut r = [0.0; 3];
        for (p, s) in self.points.iter().zip(&self.state) {
            for i in 0..3 {
                r[i] -= p.weight * s.lambda * s.grad[i];
            }
        }
        r
    }

    /// Contact pressure q_n = -lambda |grad Psi| (>= 0 in compression) at every point.
    pub fn pressures(&self) -> Vec<f64> {
        self.state.iter().map(|s| -s.lambda * Vector3::from(s.grad).norm()).collect()
    }
}

/// Add the tangent of one contact point: w eps G G^T + w lambda H over the point's three
/// displacement dofs and, for a force-driven punch, its unknown s (G_s = dPsi/ds = -grad Psi . n,
/// H_us = -H n, H_ss = n^T H n). `hess_at` is where the Hessian is taken (None: no curvature term).
#[allow(clippy::too_many_arguments)]
fn point_tangent(surface: &dyn ContactSurface, p: &ContactPoint, drive: Option<&ForceDrive>, dn: &Vector3<f64>, grad: &Vector3<f64>, grad_s: f64, hess_at: Option<&Vector3<f64>>, w_eps: f64, w_lambda: f64, add: &mut dyn FnMut(usize, usize, f64)) {
    let mut kt: Matrix3<f64> = grad * grad.transpose() * w_eps;
    let mut hn = Vector3::zeros();
    let mut nhn = 0.0;
    if let Some(x) = hess_at {
        let h = surface.hessian(x);
        kt += h * w_lambda;
        hn = h * dn;
        nhn = dn.dot(&hn);
    }
    for i in 0..3 {
        for j in 0..3 {
            add(p.dofs[i], p.dofs[j], kt[(i, j)]);
        }
    }
    if let Some(f) = drive {
        for i in 0..3 {
            // d(force_i)/ds and d(R_s)/du_i
            let v = w_eps * grad[i] * grad_s - w_lambda * hn[i];
            add(p.dofs[i], f.dof, v);
            add(f.dof, p.dofs[i], v);
        }
        add(f.dof, f.dof, w_eps * grad_s * grad_s + w_lambda * nhn);
    }
}

/// Count one change of state of a point; after `max_flips` changes in a load step it is frozen.
fn record_flip(flips: &mut u32, frozen: &mut bool, max_flips: u32) {
    *flips += 1;
    if *flips >= max_flips {
        *frozen = true;
    }
}

#[cfg(test)]
mod motion_tests {
    use super::PunchMotion;

    #[test]
    fn a_path_interpolates_holds_and_starts_at_zero() {
        let p = PunchMotion::path(&[(0.5, [0.0, 0.0, -1.0]), (1.0, [2.0, 0.0, -1.0])]).unwrap();
        assert_eq!(p.displacement(0.0), [0.0, 0.0, 0.0]);
        assert_eq!(p.displacement(0.25), [0.0, 0.0, -0.5]);
        assert_eq!(p.displacement(0.5), [0.0, 0.0, -1.0]);
        assert_eq!(p.displacement(0.75), [1.0, 0.0, -1.0]);
        assert_eq!(p.displacement(1.0), [2.0, 0.0, -1.0]);
        // held beyond the last row, zero below 0
        assert_eq!(p.displacement(3.0), [2.0, 0.0, -1.0]);
        assert_eq!(p.displacement(-1.0), [0.0, 0.0, 0.0]);
        assert_eq!(p.approach(), [0.0, 0.0, -1.0]);
        assert!(!p.is_zero());
        // a path equal to a linear motion gives the same displacements
        let lin = PunchMotion::Linear([0.1, 0.2, -0.3]);
        let path = PunchMotion::path(&[(1.0, [0.1, 0.2, -0.3])]).unwrap();
        for t in [0.0, 0.125, 0.5, 0.9, 1.0] {
            assert_eq!(lin.displacement(t), path.displacement(t), "t = {t}");
        }
        assert_eq!(path.approach(), lin.approach());
    }

    #[test]
    fn bad_paths_are_refused_with_the_row() {
        let e = |rows: &[(f64, [f64; 3])]| PunchMotion::path(rows).unwrap_err();
        assert!(e(&[]).contains("at least one row"));
        assert!(e(&[(0.5, [0.0; 3]), (0.5, [1.0; 3])]).contains("row 1: the load factors must increase strictly"));
        assert!(e(&[(-0.5, [0.0; 3])]).contains("row 0"));
        assert!(e(&[(0.0, [1.0, 0.0, 0.0])]).contains("at t = 0 the displacement must be [0, 0, 0]"));
        assert!(e(&[(1.0, [f64::NAN, 0.0, 0.0])]).contains("finite"));
        assert!(PunchMotion::path(&[(0.0, [0.0; 3]), (1.0, [0.0, 0.0, -1.0])]).is_ok());
    }
}

#[cfg(test)]
mod entry_tests {
    //! The damped growth of the active set: which penetrating points enter in an evaluation with
    //! a tangent, and that the held-back ones still count as changes until they are in.
    use super::*;
    use crate::surface::ContactSurface;

    /// The punch's underside is the plane x3 = 0 (Psi = -x3: a point above it, x3 > 0, penetrates).
    struct Plane;
    impl ContactSurface for Plane {
        fn psi(&self, x: &Vector3<f64>) -> f64 {
            -x[2]
        }
        fn gradient(&self, _x: &Vector3<f64>) -> Vector3<f64> {
            Vector3::new(0.0, 0.0, -1.0)
        }
    }

    /// Four points at x3 = 0 below the plane (touching), each with its own dofs.
    fn pair(entry_fraction: f64) -> ContactPair {
        let points = (0..4).map(|k| ContactPoint { node: k, x_ref: [k as f64, 0.0, -1e-3], dofs: [3 * k, 3 * k + 1, 3 * k + 2], weight: 1.0 }).collect();
        let mut pair = ContactPair::new("plane", Arc::new(Plane), points, 10.0, ContactKinematics::Exact);
        pair.entry_fraction = entry_fraction;
        pair
    }

    /// Evaluate with a tangent at the points' upward displacements `w` (x3 = -1e-3 + w);
    /// returns the changes and the active flags.
    fn evaluate(pair: &mut ContactPair, w: [f64; 4]) -> (usize, Vec<bool>) {
        let mut u = vec![0.0; 12];
        for k in 0..4 {
            u[3 * k + 2] = w[k];
        }
        let mut force = vec![0.0; 12];
        let mut add = |_: usize, _: usize, _: f64| {};
        let changes = pair.evaluate(&u, 0.0, &mut force, Some(&mut add));
        (changes, pair.state.iter().map(|s| s.active).collect())
    }

    #[test]
    fn only_the_deepest_half_of_the_new_penetrations_enters() {
        let mut p = pair(0.5);
        // first evaluation: the last point touches (Psi = 0), the others are clear
        assert_eq!(evaluate(&mut p, [0.0, 0.0, 0.0, 1e-3]), (1, vec![false, false, false, true]));
        // penetrations 1, 0.6, 0.4 (x3 = w - 1e-3): the deepest is 0.999, half of it 0.4995;
        // 0.599 enters, 0.399 is held back but counts as a change
        let w = [1.0, 0.6, 0.4, 1e-3];
        let (changes, active) = evaluate(&mut p, w);
        assert_eq!(active, vec![true, true, false, true]);
        assert_eq!(changes, 3, "two points entered, one is held back");
        // the held-back point gets no force
        assert_eq!(p.state[2].lambda, 0.0);
        assert!(p.state[0].lambda < 0.0 && p.state[1].lambda < 0.0);
        // next time it is the deepest of the inactive points: it enters, and then nothing changes
        let (changes, active) = evaluate(&mut p, w);
        assert_eq!((changes, active), (1, vec![true, true, true, true]));
        assert_eq!(evaluate(&mut p, w).0, 0);
    }

    #[test]
    fn from_an_empty_set_only_the_deepest_penetrations_enter() {
        // the very first evaluation already overlaps: only the deepest trial (-9.99) enters:
        // -5.99 and -3.99 are held back
        let mut p = pair(0.5);
        let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 0.0]);
        assert_eq!(active, vec![true, false, false, false]);
        assert_eq!(changes, 3, "one point entered, two are held back");
        assert_eq!(p.state[1].lambda, 0.0);
        // then the set grows by the damped rule (0.599 and 0.399 against half of 0.599: both)
        assert_eq!(evaluate(&mut p, [1.0, 0.6, 0.4, 0.0]), (2, vec![true, true, true, false]));
        // every point released, then two equally deep penetrations: both enter, the shallower
        // (-2.99 against -4.99) is held back
        let mut p = pair(0.5);
        assert_eq!(evaluate(&mut p, [0.0; 4]), (0, vec![false; 4]));
        let (changes, active) = evaluate(&mut p, [0.5, 0.5, 0.3, 0.0]);
        assert_eq!((changes, active), (3, vec![true, true, false, false]));
        // a residual-only evaluation (line-search trial) still sees every penetration
        let mut p = pair(0.5);
        let mut u = vec![0.0; 12];
        u[2] = 1.0;
        u[5] = 0.6;
        let mut force = vec![0.0; 12];
        assert_eq!(p.evaluate(&u, 0.0, &mut force, None), 0, "the first evaluation records its set");
        assert!(force[2] != 0.0 && force[5] != 0.0);
    }

    #[test]
    fn a_lone_point_swinging_in_and_out_is_frozen_after_lone_max_flips_changes() {
        // nothing penetrates, then point 0 alone: in, out, in (three changes with at most one
        // point active): frozen, its next swing is no change
        let mut p = pair(0.5);
        assert_eq!(evaluate(&mut p, [0.0; 4]).0, 0);
        let (inside, outside) = ([1.0, 0.0, 0.0, 0.0], [0.0; 4]);
        for (k, w) in [inside, outside, inside].into_iter().enumerate() {
            assert_eq!(evaluate(&mut p, w).0, 1, "change {k}");
        }
        assert_eq!(LONE_MAX_FLIPS, 3);
        assert!(p.frozen[0] && !p.frozen[1]);
        assert_eq!(evaluate(&mut p, outside), (0, vec![false; 4]), "a frozen point follows Psi without counting");
        // the same swings next to two active points: not lone, counted up to max_flips (10)
        let mut p = pair(0.5);
        let (inside, outside) = ([1.0, 0.0, 1.0, 1.0], [0.0, 0.0, 1.0, 1.0]);
        assert_eq!(evaluate(&mut p, outside).1, vec![false, false, true, true]);
        for k in 0..9 {
            assert_eq!(evaluate(&mut p, if k % 2 == 0 { inside } else { outside }).0, 1, "change {k}");
        }
        assert!(!p.frozen[0]);
        assert_eq!(evaluate(&mut p, outside).0, 1);
        assert!(p.frozen[0], "frozen at the tenth change");
    }

    #[test]
    fn the_first_iteration_of_a_load_step_takes_only_the_deepest_tenth() {
        let mut p = pair(0.5);
        evaluate(&mut p, [0.0, 0.0, 0.0, 1e-3]);
        p.start_step(false);
        // trials -9.99, -5.99, -3.99 against 0.9 * -9.99: only the first enters
        let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 1e-3]);
        assert_eq!((changes, active), (3, vec![true, false, false, true]));
        // the next iteration uses entry_fraction (half of -5.99): both enter
        assert_eq!(evaluate(&mut p, [1.0, 0.6, 0.4, 1e-3]), (2, vec![true; 4]));
    }

    #[test]
    fn a_predicted_step_takes_every_penetrating_point_at_once_and_the_next_step_damps_again() {
        // from the coarse mesh's solution: no damping, not even at the first evaluation (which
        // would take the deepest point only and count the others as changes): every
        // penetrating point is in the set it records
        let mut p = pair(0.5);
        p.start_step(true);
        let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 0.0]);
        assert_eq!((changes, active), (0, vec![true, true, true, false]));
        // later evaluations of the step too: a point that starts penetrating enters at once
        let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 1.0]);
        assert_eq!((changes, active), (1, vec![true; 4]));
        // a step from the secant predictor damps as before: of the new penetrations (trials
        // -9.99, -5.99, -3.99 against 0.9 * -9.99) only the deepest enters
        let mut p = pair(0.5);
        p.start_step(true);
        assert_eq!(evaluate(&mut p, [1.0, 0.0, 0.0, 0.0]), (0, vec![true, false, false, false]));
        p.start_step(false);
        let (changes, active) = evaluate(&mut p, [1.0, 1.0, 0.6, 0.4]);
        assert_eq!((changes, active), (3, vec![true, true, false, false]));
    }

    #[test]
    fn right_after_an_augmented_lagrangian_update_no_point_is_released() {
        // points 0 and 1 in contact (lambda -9.99 each), an update (lambda_bar <- lambda), then
        // point 1 lifts off by 2 (trial -9.99 + 10 * 2.001 > 0): the next evaluation with a
        // tangent keeps it, the one after releases it
        let mut p = pair(0.5);
        assert_eq!(evaluate(&mut p, [1.0, 1.0, 0.0, 0.0]).1, vec![true, true, false, false]);
        p.augment();
        let lifted = [1.0, -2.0, 0.0, 0.0];
        let (changes, active) = evaluate(&mut p, lifted);
        assert_eq!((changes, active.clone()), (0, vec![true, true, false, false]), "held right after the update");
        let (changes, active) = evaluate(&mut p, lifted);
        assert_eq!((changes, active), (1, vec![true, false, false, false]), "released at the next evaluation");
        // without an update in between it is released at once
        let mut q = pair(0.5);
        evaluate(&mut q, [1.0, 1.0, 0.0, 0.0]);
        assert_eq!(evaluate(&mut q, lifted), (1, vec![true, false, false, false]));
    }

    #[test]
    fn with_entry_fraction_zero_every_penetrating_point_enters_at_once() {
        let mut p = pair(0.0);
        evaluate(&mut p, [0.0; 4]);
        let (changes, active) = evaluate(&mut p, [1.0, 0.6, 0.4, 0.0]);
        assert_eq!((changes, active), (3, vec![true, true, true, false]));
    }

    #[test]
    fn a_residual_only_evaluation_reports_the_true_changes_and_holds_nothing_back() {
        let mut p = pair(0.5);
        evaluate(&mut p, [0.0; 4]);
        let mut u = vec![0.0; 12];
        u[2] = 1.0;
        u[8] = 0.4;
        let mut force = vec![0.0; 12];
        // a line-search trial: the force of every penetrating point, nothing recorded
        assert_eq!(p.evaluate(&u, 0.0, &mut force, None), 2);
        assert!(force[8] != 0.0, "the shallow penetration acts in a residual-only evaluation");
        assert_eq!(p.last_active, vec![false; 4]);
    }
}

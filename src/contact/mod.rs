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

use crate::linearised_contact::ConstraintRow;
use crate::surface::ContactSurface;
use nalgebra::{Matrix3, Vector3};
use rayon::prelude::*;
use std::sync::Arc;

mod face;
mod motion;
mod share;
pub use face::ContactFace;
pub use motion::{ForceDrive, PunchMotion};
pub use share::PointShare;

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
    /// coarse mesh, [`crate::mesh::coarse_path`]): no damped entry in it, every penetrating point
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
    /// The last evaluation with a tangent kept the least tensile point of a set it would have
    /// emptied (see `evaluate`): the next one may empty it.
    kept_last: bool,
    /// Keep the least tensile point of a set an evaluation would empty (default true).
    pub guard_empty: bool,
    /// The point kinematics of the last evaluation (scratch, reused).
    kinematics_scratch: Vec<Kinematics>,
    /// The integrated discretisation's face ([`ContactFace`]); None: the paper's nodal collocation.
    face: Option<ContactFace>,
    /// The kinematics at the face's quadrature points at the last evaluation (integrated only).
    site_scratch: Vec<Kinematics>,
    /// The points that gave a tangent in the last evaluation (integrated only, scratch).
    tangent_points: Vec<bool>,
    /// Integrated only: the points whose patch the model's sparse pattern couples (see
    /// [`coupled_nodes`](Self::coupled_nodes)). Coupling every candidate's patch would make the
    /// factor of a large face several times denser, so only the points near contact are coupled,
    /// and more when contact reaches points that are not ([`extend_coupling`](Self::extend_coupling)).
    coupled: Vec<bool>,
    /// Bumped whenever `coupled` grows (the model rebuilds its pattern then).
    coupling_version: u64,
    /// A point that gave a tangent in the last evaluation is not coupled: its tangent lost the
    /// entries outside the pattern (an inexact Newton step) until the model couples it.
    needs_coupling: bool,
    /// A point is coupled once its gap (Psi / |grad Psi|) is at most this length (set by the
    /// caller: the plate's thickness, say); default 0: only points in contact.
    pub coupling_reach: f64,
    /// The points that entered the active set at the last evaluation with a tangent: the next
    /// such evaluation does not release them (see [`ContactPair::evaluate`]).
    entered: Vec<bool>,
    /// The points that entered with the Gauss-Newton tangent at that evaluation (see
    /// [`DEEP_ENTRY_RATIO`]): held at the next one also in a step started from an outside
    /// prediction, whose other entries are not held.
    entered_deep: Vec<bool>,
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
    /// least [`CONVERGING_TENSION`]-fold since the last evaluation with a tangent (see
    /// [`ContactPair::evaluate`]); default true.
    pub hold_converging: bool,
    /// The Gauss-Newton tangent for a point that enters the active set deep inside the punch or
    /// at the body's first contact (see [`DEEP_ENTRY_RATIO`]); default true. False: every active
    /// point's tangent is the exact derivative.
    pub gauss_newton_entry: bool,
    /// The body touched the punch in a converged state before this load step: its largest
    /// |lambda| then (0: this step is the first contact).
    converged_scale: f64,
    /// Each point's trial multiplier at the last evaluation with a tangent.
    last_trial: Vec<f64>,
    /// The points this process evaluates in a distributed run (see [`PointShare`]); None: all.
    share: Option<PointShare>,
}

/// Psi, its gradient with respect to the displacement of the point (or quadrature point), its
/// derivative with respect to a force-driven punch's unknown s, and where the Hessian is taken
/// (None: no curvature term, the shallow constraint).
type Kinematics = (f64, Vector3<f64>, f64, Option<Vector3<f64>>);

/// What the kinematics of a point of the face needs at one evaluation.
struct SiteContext<'a> {
    surface: &'a dyn ContactSurface,
    kinematics: ContactKinematics,
    /// The punch displacement (prescribed plus s n).
    d: Vector3<f64>,
    /// The prescribed part of it.
    prescribed: Vector3<f64>,
    /// A force-driven punch's direction n (zero otherwise) and its unknown s.
    dn: Vector3<f64>,
    s: f64,
}

impl SiteContext<'_> {
    /// The kinematics of the point at reference position `x_ref` displaced by `disp`: the surface
    /// is queried at x (exact kinematics) or at the reference position moved back by the
    /// prescribed motion (shallow: linearised about it), and not again while the point stays
    /// where it was (`at`).
    fn kinematics(&self, x_ref: Vector3<f64>, disp: Vector3<f64>, at: &mut SurfaceAtPoint) -> Kinematics {
        // (a worker thread may come from faer's kernels: see crate::linalg::vector_state)
        crate::linalg::vector_state::clean_upper_vector_state();
        let x = match self.kinematics {
            ContactKinematics::Exact => x_ref + disp - self.d,
            ContactKinematics::Shallow { .. } => x_ref - self.prescribed,
        };
        // (NaN at the start: never equal)
        if x != at.x {
            let (psi, grad) = self.surface.psi_and_gradient(&x);
            *at = SurfaceAtPoint { x, psi, grad };
        }
        let SurfaceAtPoint { psi, grad: g, .. } = *at;
        let dn = self.dn;
        match self.kinematics {
            ContactKinematics::Exact => (psi, g, -g.dot(&dn), Some(x)),
            ContactKinematics::Shallow { direction } => {
                // in the plate's displacement along n and in the punch's unknown s
                let n = Vector3::from(direction);
                let gn = g.dot(&n);
                (psi + gn * disp.dot(&n) - g.dot(&dn) * self.s, n * gn, -g.dot(&dn), None)
            }
        }
    }
}

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
        }
    }

    /// Use the integrated discretisation on `face`, whose contact points are this pair's points
    /// (in order): each point's weight becomes its area int N_i dA on the face.
    pub fn with_face(mut self, face: ContactFace) -> crate::Result<Self> {
        if face.num_points() != self.points.len() {
            return Err(crate::StampError::Problem(format!("the contact face has {} points, the punch {}", face.num_points(), self.points.len())));
        }
        for (p, &a) in self.points.iter_mut().zip(&face.area) {
            p.weight = a;
        }
        self.surface_at_points = vec![SurfaceAtPoint { x: Vector3::repeat(f64::NAN), psi: 0.0, grad: Vector3::zeros() }; face.quadrature.len()];
        self.face = Some(face);
        Ok(self)
    }

    /// The integrated discretisation's face, if any.
    pub fn face(&self) -> Option<&ContactFace> {
        self.face.as_ref()
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
    fn evaluates(&self, k: usize) -> bool {
        self.share.as_ref().is_none_or(|s| s.evaluated[k])
    }

    /// The points this process owns (all without a share).
    fn owns(&self, k: usize) -> bool {
        self.share.as_ref().is_none_or(|s| s.own[k])
    }

    /// Make every point's state (and the integrated face's kinematics) whole on every process
    /// from their owners' (collective; nothing without a share): after a converged step, for the
    /// outputs and [`reaction`](Self::reaction), [`pressures`](Self::pressures),
    /// [`max_penetration`](Self::max_penetration), which read every point.
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

    /// Groups of nodes whose dofs the contact tangent couples beyond the nodes of one cell: the
    /// patch of each coupled point for the integrated discretisation (see [`ContactFace`]), none
    /// for the nodal.
    pub fn coupled_nodes(&self) -> Vec<Vec<usize>> {
        match &self.face {
            None => Vec::new(),
            Some(f) => (0..self.points.len())
                .filter(|&i| self.coupled[i])
                .map(|i| f.patch(i).iter().map(|&k| self.points[k as usize].node).collect())
                .collect(),
        }
    }

    /// Changes whenever the set of [`coupled_nodes`](Self::coupled_nodes) grows.
    pub fn coupling_version(&self) -> u64 {
        self.coupling_version
    }

    /// A point gave a tangent at the last evaluation without being coupled.
    pub fn needs_coupling(&self) -> bool {
        self.needs_coupling
    }

    /// Couple every point that gave a tangent at the last evaluation and every point within
    /// `coupling_reach` of the punch (its gap Psi / |grad Psi| at the last evaluation); true when
    /// the set grew.
    pub fn extend_coupling(&mut self) -> bool {
        if self.face.is_none() {
            return false;
        }
        let mut grew = false;
        for (i, s) in self.state.iter().enumerate() {
            if !self.evaluates(i) {
                continue;
            }
            let g = Vector3::from(s.grad).norm();
            let near = g > 0.0 && s.psi / g <= self.coupling_reach;
            let wanted = near || self.tangent_points.get(i).copied().unwrap_or(false) || s.lambda != 0.0;
            if wanted && !self.coupled[i] {
                self.coupled[i] = true;
                grew = true;
            }
        }
        if grew {
            self.coupling_version += 1;
        }
        self.needs_coupling = false;
        grew
    }

    /// Forget the cycling history (at the start of a load step); `predicted`: the step starts from
    /// an outside prediction of its answer (see `predicted_step`).
    pub fn start_step(&mut self, predicted: bool) {
        self.predicted_step = predicted;
        self.entered.fill(false);
        self.entered_deep.fill(false);
        self.flips.fill(0);
        self.frozen.fill(false);
        self.step_start = true;
        self.kept_last = false;
        // over this process's points: the next evaluation takes the largest over the processes
        self.lambda_scale = self.state.iter().enumerate().filter(|(k, _)| self.owns(*k)).map(|(_, s)| s.lambda.abs()).fold(0.0, f64::max);
        self.converged_scale = self.lambda_scale;
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
    /// displacement (and to s for a force-driven punch, whose equation
    /// R_s = sum w lambda dPsi/ds - t F is added into `force[drive.dof]`). Returns the number of points whose active state
    /// changed against the set of the last evaluation with a tangent (only such an evaluation
    /// records the new set).
    ///
    /// With a share ([`set_share`](Self::set_share); collective) only this process's points are
    /// evaluated: the forces and tangent rows of its own points, the shares of the force-driven
    /// punch's row, column and equation (the model sums them over the processes), the number of
    /// changes of all.
    pub fn evaluate(&mut self, u: &[f64], t: f64, force: &mut [f64], add_tangent: Option<&mut dyn FnMut(usize, usize, f64)>) -> crate::Result<usize> {
        let share = self.share.take();
        let out = self.evaluate_share(u, t, force, add_tangent, share.as_ref());
        self.share = share;
        out
    }

    fn evaluate_share(&mut self, u: &[f64], t: f64, force: &mut [f64], mut add_tangent: Option<&mut dyn FnMut(usize, usize, f64)>, share: Option<&PointShare>) -> crate::Result<usize> {
        let own = |k: usize| share.is_none_or(|s| s.own[k]);
        let evaluated = |k: usize| share.is_none_or(|s| s.evaluated[k]);
        let d = Vector3::from(self.punch_displacement(u, t));
        let drive = self.drive;
        let dn = drive.map(|f| Vector3::from(f.direction)).unwrap_or_else(Vector3::zeros);
        let mut changes = 0;
        let with_tangent = add_tangent.is_some();
        let first = !self.initialized;
        // "near the kink" is 1 % of the largest multiplier now, or of the largest in this step
        // when every point is momentarily inactive (a lone point swinging in and out)
        let mut current = self.state.iter().enumerate().filter(|(k, _)| own(*k)).map(|(_, s)| s.lambda.abs()).fold(0.0, f64::max);
        let mut any_tangent = false;
        // Psi, its gradient with respect to the point's displacement and to s, and where the
        // Hessian is taken, for every point first (the entry rule below needs the deepest
        // penetration), in parallel. The surface is queried at x (exact kinematics) or at the
        // reference position moved back by the prescribed motion (shallow: linearised about it),
        // and not again while that point stays where it was.
        // With the integrated discretisation the same is done at the face's quadrature points,
        // and each point's kinematics is its weighted mean over its cells (see ContactFace).
        let mut kin = std::mem::take(&mut self.kinematics_scratch);
        kin.resize(self.points.len(), (0.0, Vector3::zeros(), 0.0, None));
        let mut sites = std::mem::take(&mut self.site_scratch);
        let site = SiteContext {
            surface: &*self.surface,
            kinematics: self.kinematics,
            d,
            prescribed: Vector3::from(self.motion.displacement(t)),
            dn,
            s: drive.map(|f| u[f.dof]).unwrap_or(0.0),
        };
        let points = &self.points;
        let displacement = |p: &ContactPoint| Vector3::new(u[p.dofs[0]], u[p.dofs[1]], u[p.dofs[2]]);
        match &self.face {
            None => {
                (kin.par_iter_mut(), self.surface_at_points.par_iter_mut(), points.par_iter()).into_par_iter().enumerate().with_min_len(512).filter(|(k, _)| evaluated(*k)).for_each(|(_, (out, at, p))| {
                    *out = site.kinematics(Vector3::from(p.x_ref), displacement(p), at);
                });
            }
            Some(face) => {
                sites.resize(face.quadrature.len(), (0.0, Vector3::zeros(), 0.0, None));
                let computed = |q: usize| share.is_none_or(|s| s.sites[q]);
                (sites.par_iter_mut(), self.surface_at_points.par_iter_mut(), face.quadrature.par_iter()).into_par_iter().enumerate().with_min_len(512).filter(|(q, _)| computed(*q)).for_each(|(_, (out, at, q))| {
                    let (mut x_ref, mut disp) = (Vector3::zeros(), Vector3::zeros());
                    for a in 0..4 {
                        let p = &points[q.points[a] as usize];
                        x_ref += Vector3::from(p.x_ref) * q.shape[a];
                        disp += displacement(p) * q.shape[a];
                    }
                    *out = site.kinematics(x_ref, disp, at);
                });
                let sites = &sites;
                kin.par_iter_mut().enumerate().with_min_len(512).filter(|(i, _)| evaluated(*i)).for_each(|(i, out)| {
                    let (mut psi, mut grad, mut grad_s) = (0.0, Vector3::zeros(), 0.0);
                    for &(q, a) in face.of_point(i) {
                        let w = face.quadrature[q as usize].weight * face.quadrature[q as usize].shape[a as usize];
                        let (sp, sg, ss, _) = sites[q as usize];
                        psi += w * sp;
                        grad += sg * w;
                        grad_s += w * ss;
                    }
                    let inv = 1.0 / face.area[i];
                    *out = (psi * inv, grad * inv, grad_s * inv, None);
                });
            }
        }
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
        let trial_of = |k: usize, q: &Kinematics| self.lambda_bar[k] + self.eps_reg * q.0;
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
        // for STAMP_DEBUG: points deferred, released, entering, penetrating, held
        let mut tally = [0usize; 5];
        let integrated = self.face.is_some();
        if integrated {
            self.tangent_points.clear();
            self.tangent_points.resize(self.points.len(), false);
        }
        for (k, p) in self.points.iter().enumerate() {
            if !evaluated(k) {
                continue;
            }
            // a halo point (integrated) goes through the same rules as on its owner's process,
            // which counts it
            let changes_before = changes;
            let (psi, grad, grad_s, hess) = kin[k];
            let trial = self.lambda_bar[k] + self.eps_reg * psi;
            let was_active = self.last_active[k] && !first;
            // touching points (Psi = 0) belong to the active set
            let wanted = trial <= 0.0;
            if first {
                self.last_active[k] = if first_touch.is_some() { false } else { wanted };
            }
            // a penetrating point held back by the entry rule: still a change (the step is not
            // converged), but neither force nor tangent in this evaluation
            let deferred = with_tangent && !self.hold_active_set && wanted && !self.last_active[k] && !self.frozen[k] && trial > entry_cut;
            // a tension that fell at least tenfold since the last tangent: the remainder of a
            // convex punch's linearisation converging away, not a lift-off (see CONVERGING_TENSION)
            let converging = self.hold_converging && self.last_trial[k] > 0.0 && trial < CONVERGING_TENSION * self.last_trial[k];
            if with_tangent && own(k) {
                for (i, on) in [deferred, was_active && !wanted, !was_active && wanted, wanted].into_iter().enumerate() {
                    tally[i] += on as usize;
                }
            }
            let active = if deferred {
                changes += 1;
                false
            } else if with_tangent && (self.hold_after_update || (self.entered[k] && self.hold_after_entry && !self.hold_active_set && (!self.predicted_step || self.entered_deep[k])) || trial < release_cut || converging || trial == least_tensile) && self.last_active[k] && !wanted && !self.frozen[k] {
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
                    changes += 1;
                }
                tally[4] += usize::from(own(k));
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
            if !own(k) {
                changes = changes_before;
            }
            let lambda = if active { trial } else { 0.0 };
            // an entering point deep inside the punch, or at the first contact: the Gauss-Newton
            // tangent (see DEEP_ENTRY_RATIO)
            let deep = self.gauss_newton_entry
                && active
                && !was_active
                && lambda < 0.0
                && hess.as_ref().is_some_and(|x| self.converged_scale == 0.0 || psi.abs() * self.surface.hessian(x).norm() > DEEP_ENTRY_RATIO * grad.norm_squared());
            if with_tangent {
                self.entered[k] = active && !was_active;
                self.entered_deep[k] = deep;
                self.last_trial[k] = trial;
            }
            self.state[k] = PointState { psi, grad: grad.into(), lambda, active };
            // a point that cycled keeps the active-side tangent near the kink (its force stays exact)
            let near_kink = !self.hold_active_set && self.frozen[k] && with_tangent && trial <= band;
            if !active && !near_kink {
                continue;
            }
            any_tangent |= own(k);
            if integrated {
                // forces and tangent from the quadrature points below
                self.tangent_points[k] = true;
                continue;
            }
            let w = p.weight;
            for i in 0..3 {
                force[p.dofs[i]] += w * lambda * grad[i];
            }
            if let Some(f) = &drive {
                force[f.dof] += w * lambda * grad_s;
            }
            if let Some(add) = add_tangent.as_deref_mut() {
                let curvature = if deep { 0.0 } else { lambda };
                point_tangent(&*self.surface, p, drive.as_ref(), &dn, &grad, grad_s, hess.as_ref(), w * self.eps_reg, w * curvature, add);
            }
        }
        let debug = with_tangent && std::env::var_os("STAMP_DEBUG").is_some();
        let mut act = if debug { self.state.iter().enumerate().filter(|(k, s)| own(*k) && evaluated(*k) && s.active).count() } else { 0 };
        if let Some(sh) = share {
            // the changes, whether any point gives a tangent, and the debug counts of every process
            let mut c = [changes, usize::from(any_tangent), act, tally[0], tally[1], tally[2], tally[3], tally[4]].map(|x| x as f64);
            sh.reduce.sum(&mut c)?;
            [changes, act, tally[0], tally[1], tally[2], tally[3], tally[4]] = [c[0], c[2], c[3], c[4], c[5], c[6], c[7]].map(|x| x as usize);
            any_tangent = c[1] > 0.0;
        }
        if debug && share.is_none_or(|s| s.leader) {
            let [deferred, tensile, entering, penetrating, held] = tally;
            eprintln!("  {}: {act} active, {penetrating} penetrating; {entering} would enter ({deferred} deferred), {tensile} would leave ({held} held)", self.name);
        }
        if let Some(f) = &drive {
            // the load once over the processes
            if share.is_none_or(|s| s.leader) {
                force[f.dof] -= t * f.force;
            }
            // With no point in contact the punch's equation has no stiffness (it floats) and no state
            // is an equilibrium unless t F = 0. Keep the point closest to the punch on its active
            // branch, lambda = lambda_bar + eps Psi even where that pulls: Newton then brings the
            // punch onto the plate in one step instead of creeping towards it. Once a point
            // touches, this stops; at t F = 0 the punch rests touching the plate with no force.
            if !any_tangent {
                let gap = |s: &PointState| s.psi / Vector3::from(s.grad).norm();
                let mut closest = self
                    .state
                    .iter()
                    .enumerate()
                    .filter(|(k, s)| own(*k) && Vector3::from(s.grad).norm() > 0.0)
                    .min_by(|a, b| gap(a.1).total_cmp(&gap(b.1)))
                    .map(|(k, _)| k);
                if let Some(sh) = share {
                    // the closest over the processes (the lowest-numbered point of equal gaps)
                    let mut g = [closest.map_or(f64::INFINITY, |k| gap(&self.state[k]))];
                    sh.reduce.min_f64(&mut g)?;
                    let mut at = [closest.filter(|&k| gap(&self.state[k]) == g[0]).map_or(u64::MAX, |k| k as u64)];
                    sh.reduce.min(&mut at)?;
                    closest = usize::try_from(at[0]).ok().filter(|&k| k < self.points.len());
                }
                if let (Some(k), true) = (closest, integrated) {
                    // on every process that evaluates it (its cells' forces are theirs)
                    if evaluated(k) {
                        self.state[k].lambda = self.lambda_bar[k] + self.eps_reg * self.state[k].psi;
                        self.tangent_points[k] = true;
                    }
                } else if let Some(k) = closest.filter(|&k| own(k)) {
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
        if integrated {
            if with_tangent {
                self.needs_coupling = self.tangent_points.iter().zip(&self.coupled).any(|(t, c)| *t && !*c);
            }
            self.add_integrated(&sites, &dn, force, add_tangent, share);
        }
        self.site_scratch = sites;
        if first {
            self.initialized = true;
        }
        if with_tangent {
            self.step_start = false;
            self.hold_after_update = false;
        }
        self.kinematics_scratch = kin;
        Ok(changes)
    }

    /// The multiplier field lambda_h = sum_a N_a lambda_a at a quadrature point of the face.
    fn traction_at(&self, q: &face::FacePoint) -> f64 {
        (0..4).map(|a| q.shape[a] * self.state[q.points[a] as usize].lambda).sum()
    }

    /// The integrated discretisation's forces and tangent (see [`ContactFace`]) from the
    /// multipliers in `state` and the kinematics `sites` of the quadrature points: at each
    /// quadrature point lambda_q = sum_a N_a lambda_a, the force w_q lambda_q N_j grad Psi on its
    /// points (and w_q lambda_q dPsi/ds on a force-driven punch) with the curvature tangent
    /// w_q lambda_q N_j N_k H; for every point of `tangent_points` the penalty tangent
    /// eps / A_i a_i a_i^T, a_i = sum_q w_q N_i(q) (N_j(q) grad Psi_q, dPsi_q/ds).
    ///
    /// With a share: the quadrature points of the cells around its own points, their forces and
    /// tangent rows on its own points only, and of the punch's row, column and equation the parts
    /// of its own points (a quadrature point's by the shape functions of its own points).
    fn add_integrated(&self, sites: &[Kinematics], dn: &Vector3<f64>, force: &mut [f64], mut add_tangent: Option<&mut dyn FnMut(usize, usize, f64)>, share: Option<&PointShare>) {
        let face = self.face.as_ref().expect("integrated");
        let drive = self.drive;
        let own = |k: u32| share.is_none_or(|s| s.own[k as usize]);
        for (k, (q, site)) in face.quadrature.iter().zip(sites).enumerate() {
            if share.is_some_and(|s| !s.force_sites[k]) {
                continue;
            }
            let lambda_q = self.traction_at(q);
            if lambda_q == 0.0 {
                continue;
            }
            let (_, grad, grad_s, hess_at) = site;
            let wl = q.weight * lambda_q;
            for a in (0..4).filter(|&a| own(q.points[a])) {
                let p = &self.points[q.points[a] as usize];
                for i in 0..3 {
                    force[p.dofs[i]] += wl * q.shape[a] * grad[i];
                }
            }
            // this process's part of the quadrature point's share in the punch's equation (1 times
            // a number is that number: the whole model's sums are unchanged)
            let part = match share {
                None => 1.0,
                Some(_) => (0..4).filter(|&a| own(q.points[a])).map(|a| q.shape[a]).sum::<f64>(),
            };
            if let Some(f) = &drive {
                force[f.dof] += part * wl * grad_s;
            }
            let (Some(add), Some(x)) = (add_tangent.as_deref_mut(), hess_at) else { continue };
            let h = self.surface.hessian(x) * wl;
            let hn = h * dn;
            for a in 0..4 {
                if !own(q.points[a]) {
                    continue;
                }
                let pa = &self.points[q.points[a] as usize];
                for b in 0..4 {
                    let pb = &self.points[q.points[b] as usize];
                    let nn = q.shape[a] * q.shape[b];
                    for i in 0..3 {
                        for j in 0..3 {
                            add(pa.dofs[i], pb.dofs[j], nn * h[(i, j)]);
                        }
                    }
                }
                if let Some(f) = &drive {
                    for i in 0..3 {
                        add(pa.dofs[i], f.dof, -q.shape[a] * hn[i]);
                        add(f.dof, pa.dofs[i], -q.shape[a] * hn[i]);
                    }
                }
            }
            if let Some(f) = &drive {
                add(f.dof, f.dof, part * dn.dot(&hn));
            }
        }
        let Some(add) = add_tangent else { return };
        let mut a_i: Vec<Vector3<f64>> = Vec::new();
        for (i, _) in self.tangent_points.iter().enumerate().filter(|(_, t)| **t) {
            let patch = face.patch(i);
            a_i.clear();
            a_i.resize(patch.len(), Vector3::zeros());
            let mut a_s = 0.0;
            for &(qk, ai) in face.of_point(i) {
                let q = &face.quadrature[qk as usize];
                let (_, grad, grad_s, _) = &sites[qk as usize];
                let wi = q.weight * q.shape[ai as usize];
                for b in 0..4 {
                    let j = patch.binary_search(&q.points[b]).expect("a cell's points are in the patch");
                    a_i[j] += grad * (wi * q.shape[b]);
                }
                a_s += wi * grad_s;
            }
            let c = self.eps_reg / face.area[i];
            for (j, aj) in a_i.iter().enumerate() {
                if !own(patch[j]) {
                    continue;
                }
                let pj = &self.points[patch[j] as usize];
                for (k, ak) in a_i.iter().enumerate() {
                    let pk = &self.points[patch[k] as usize];
                    for r in 0..3 {
                        for cc in 0..3 {
                            add(pj.dofs[r], pk.dofs[cc], c * aj[r] * ak[cc]);
                        }
                    }
                }
                if let Some(f) = &drive {
                    for r in 0..3 {
                        add(pj.dofs[r], f.dof, c * aj[r] * a_s);
                        add(f.dof, pj.dofs[r], c * aj[r] * a_s);
                    }
                }
            }
            if let Some(f) = drive.filter(|_| own(i as u32)) {
                add(f.dof, f.dof, c * a_s * a_s);
            }
        }
    }

    /// Each point's constraint linearised at the last evaluation, for the re-solve of the
    /// linearised contact problem ([`crate::linearised_contact`]), its coefficients by dof (the
    /// point's three displacements, and the force-driven punch's travel) and its id (0, point):
    /// the model renumbers them to equations and sets the pair. Nodal contact only (the
    /// integrated scheme's rows couple a node's cells), not with the paper's fixed set
    /// (`hold_active_set`), not the points that cycled (they keep the active side) nor those with
    /// no gradient. Collective with a share: every process gets every point's row.
    pub fn linearised_rows(&self) -> crate::Result<Vec<ConstraintRow>> {
        if self.face.is_some() || self.hold_active_set {
            return Ok(Vec::new());
        }
        // with a share, each point's numbers from its owner, summed over the processes (the
        // others add zeros), so that every process holds every row, the same to the bit:
        // (in the re-solve, gradient, trial, active) per point
        const W: usize = 6;
        let mut whole = vec![0.0; W * self.points.len()];
        for (k, s) in self.state.iter().enumerate() {
            let g = Vector3::from(s.grad);
            if !self.owns(k) || self.frozen[k] || g.norm() == 0.0 {
                continue;
            }
            let trial = self.lambda_bar[k] + self.eps_reg * s.psi;
            whole[W * k..W * k + W].copy_from_slice(&[1.0, g[0], g[1], g[2], trial, f64::from(u8::from(s.active))]);
        }
        if let Some(share) = &self.share {
            share.reduce.sum(&mut whole)?;
        }
        let dn = self.drive.map(|f| Vector3::from(f.direction)).unwrap_or_else(Vector3::zeros);
        let mut out = Vec::new();
        for (k, (p, b)) in self.points.iter().zip(whole.chunks_exact(W)).enumerate() {
            if b[0] == 0.0 {
                continue;
            }
            let g = Vector3::new(b[1], b[2], b[3]);
            let mut coef: Vec<(usize, f64)> = (0..3).map(|i| (p.dofs[i], g[i])).collect();
            // the force-driven punch's travel s moves the point against the punch by -dn
            if let Some(f) = &self.drive {
                coef.push((f.dof, -g.dot(&dn)));
            }
            coef.retain(|&(_, c)| c != 0.0);
            out.push(ConstraintRow { coef, weight: p.weight, eps: self.eps_reg, trial: b[4], active: b[5] != 0.0, id: (0, k) });
        }
        Ok(out)
    }

    /// The state the re-solve found for point k, for the next evaluation: an entering point is
    /// held one iteration as every entering point is.
    pub fn set_linearised_state(&mut self, k: usize, active: bool) {
        self.last_active[k] = active;
        self.entered[k] = active;
        self.entered_deep[k] = false;
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
            let wanted = self.lambda_bar[k] + self.eps_reg * self.state[k].psi <= 0.0;
            if wanted != self.last_active[k] {
                self.last_active[k] = wanted;
                changes += usize::from(self.owns(k));
                record_flip(&mut self.flips[k], &mut self.frozen[k], self.max_flips);
            }
        }
        if let Some(sh) = &self.share {
            let mut c = [changes as f64];
            sh.reduce.sum(&mut c)?;
            changes = c[0] as usize;
        }
        Ok(changes)
    }

    /// Augmented-Lagrangian update: lambda_bar <- lambda (of the points this process evaluates).
    pub fn augment(&mut self) {
        self.hold_after_update = true;
        for k in 0..self.points.len() {
            if self.evaluates(k) {
                self.lambda_bar[k] = self.state[k].lambda;
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
        gaps.max(self.penetration_where(|k| self.owns(k)))
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

    /// Contact pressure q_n = -lambda |grad Psi| (>= 0 in compression) at every point. With the
    /// integrated discretisation: the contact force on the point along its mean normal per unit
    /// area, -f_j . n_j / A_j (f_j = int N_j lambda_h grad Psi dA), the nodal value of a field
    /// whose integral sum_j A_j q_j is the punch's normal force.
    pub fn pressures(&self) -> Vec<f64> {
        let Some(face) = &self.face else {
            return self.state.iter().map(|s| -s.lambda * Vector3::from(s.grad).norm()).collect();
        };
        let mut f = vec![Vector3::zeros(); self.points.len()];
        for (q, site) in face.quadrature.iter().zip(&self.site_scratch) {
            let lambda_q = self.traction_at(q);
            for a in 0..4 {
                f[q.points[a] as usize] += site.1 * (q.weight * lambda_q * q.shape[a]);
            }
        }
        f.iter()
            .zip(&self.state)
            .zip(&face.area)
            .map(|((f, s), a)| {
                let g = Vector3::from(s.grad);
                let n = g.norm();
                if n > 0.0 { -f.dot(&g) / (n * a) } else { 0.0 }
            })
            .collect()
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
mod entry_tests;

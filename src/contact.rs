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

use crate::surface::ContactSurface;
use nalgebra::{Matrix3, Vector3};
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
    /// Punch displacement at load factor 1; at load factor t the punch is moved by t * motion.
    pub motion: [f64; 3],
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
    /// The largest |lambda| seen in the current load step (the scale of "near the kink" for
    /// frozen points while every point is momentarily inactive).
    pub lambda_scale: f64,
}

impl ContactPair {
    pub fn new(name: impl Into<String>, surface: Arc<dyn ContactSurface>, points: Vec<ContactPoint>, eps_reg: f64, kinematics: ContactKinematics) -> Self {
        let n = points.len();
        ContactPair {
            name: name.into(),
            surface,
            motion: [0.0; 3],
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
            lambda_scale: 0.0,
        }
    }

    /// Forget the cycling history (at the start of a load step).
    pub fn start_step(&mut self) {
        self.flips.fill(0);
        self.frozen.fill(false);
        self.lambda_scale = self.state.iter().map(|s| s.lambda.abs()).fold(0.0, f64::max);
    }

    /// Evaluate Psi, the multipliers and the active set at the full displacement vector `u` and
    /// load factor `t`, add the contact forces lambda * w * grad Psi into `force` and, through
    /// `add_tangent(row_dof, col_dof, value)`, the tangent w (eps grad Psi grad Psi^T + lambda Hess Psi)
    /// of the active points. Returns the number of points whose active state changed.
    pub fn evaluate(&mut self, u: &[f64], t: f64, force: &mut [f64], mut add_tangent: Option<&mut dyn FnMut(usize, usize, f64)>) -> usize {
        let d = Vector3::from(self.motion) * t;
        let mut changes = 0;
        let with_tangent = add_tangent.is_some();
        let first = !self.initialized;
        // "near the kink" is 1 % of the largest multiplier now, or of the largest in this step
        // when every point is momentarily inactive (a lone point swinging in and out)
        let current = self.state.iter().map(|s| s.lambda.abs()).fold(0.0, f64::max);
        self.lambda_scale = self.lambda_scale.max(current);
        let band = 1e-2 * if current > 0.0 { current } else { self.lambda_scale };
        for (k, p) in self.points.iter().enumerate() {
            let x_ref = Vector3::from(p.x_ref);
            let disp = Vector3::new(u[p.dofs[0]], u[p.dofs[1]], u[p.dofs[2]]);
            let (psi, grad, hess) = match self.kinematics {
                ContactKinematics::Exact => {
                    let x = x_ref + disp - d;
                    (self.surface.psi(&x), self.surface.gradient(&x), Some(x))
                }
                ContactKinematics::Shallow { direction } => {
                    let n = Vector3::from(direction);
                    let x0 = x_ref - d;
                    let g0 = self.surface.gradient(&x0);
                    let gn = g0.dot(&n);
                    (self.surface.psi(&x0) + gn * disp.dot(&n), n * gn, None)
                }
            };
            let trial = self.lambda_bar[k] + self.eps_reg * psi;
            // touching points (Psi = 0) belong to the active set
            let wanted = trial <= 0.0;
            if first {
                self.last_active[k] = wanted;
            }
            let active = if self.hold_active_set {
                // the paper's trial and error: the set stays fixed while Newton converges on it
                if with_tangent && wanted != self.last_active[k] && !self.frozen[k] {
                    changes += 1;
                }
                self.last_active[k]
            } else {
                if with_tangent && wanted != self.last_active[k] && !self.frozen[k] {
                    changes += 1;
                    record_flip(&mut self.flips[k], &mut self.frozen[k], self.max_flips);
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
            let w = p.weight;
            for i in 0..3 {
                force[p.dofs[i]] += w * lambda * grad[i];
            }
            if let Some(add) = add_tangent.as_deref_mut() {
                let mut kt: Matrix3<f64> = grad * grad.transpose() * (w * self.eps_reg);
                if let Some(x) = hess {
                    kt += self.surface.hessian(&x) * (w * lambda);
                }
                for i in 0..3 {
                    for j in 0..3 {
                        add(p.dofs[i], p.dofs[j], kt[(i, j)]);
                    }
                }
            }
        }
        if first {
            self.initialized = true;
        }
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
        for (lb, s) in self.lambda_bar.iter_mut().zip(&self.state) {
            *lb = s.lambda;
        }
        self.max_penetration()
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

/// Count one change of state of a point; after `max_flips` changes in a load step it is frozen.
fn record_flip(flips: &mut u32, frozen: &mut bool, max_flips: u32) {
    *flips += 1;
    if *flips >= max_flips {
        *frozen = true;
    }
}

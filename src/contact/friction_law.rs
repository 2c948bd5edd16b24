//! Coulomb friction of one nodal contact point (docs/design.md, "Friction"): an augmented
//! Lagrangian with a return map (Simo & Laursen 1992, Alart & Curnier 1991).
//!
//! Each point has a stick anchor a, the punch's material point it sticks to, in the punch's body
//! frame (positions R^T (x - d - pivot) + pivot, d the punch's translation, R its rotation: x - d
//! for a punch that does not turn), and an augmented tangential multiplier lambda_T_bar in the
//! same frame. At an evaluation, with x the point's position in the punch's body frame,
//! n = grad Psi / |grad Psi| and P = I - n n^T:
//!
//! - the trial traction t_tr = P (lambda_T_bar + eps_T (x - a)),
//! - the bound mu q with q = -lambda |grad Psi| the current normal pressure (0 where lambda >= 0),
//! - stick where |t_tr| <= mu q: t = t_tr; slip otherwise: t = mu q t_tr / |t_tr|.
//!
//! t is the tangential force per unit area of the plate on the punch; the plate's residual gets
//! w t on the point's displacement (the derivative of the stick energy w eps_T |P (x - a)|^2 / 2,
//! like the normal force w lambda grad Psi). The augmented-Lagrangian update sets lambda_T_bar to
//! t with the anchor kept, so that at convergence of the updates a sticking point does not move
//! against the punch at all; a converged step moves the anchor of a slipping point by its slip,
//! a <- x - (t - lambda_T_bar) / eps_T (the return map: the next trial at the same place is t),
//! and sets an open point's anchor where it is. The law is evaluated in the body frame, with
//! Psi0's gradient and Hessian there, and its traction and tangent turned to global axes by R: a
//! point sticking to a punch that turns is carried with it, and makes no slip.

use super::stick_slip::StickSlip;
use super::ContactPair;
use nalgebra::{Matrix3, Vector3};

impl ContactPair {
    /// The friction of point k at an evaluation (the pair has friction): its return map at its
    /// position `x` in the translated frame (where the Hessian is taken; taken to the body frame
    /// here when the punch has turned), its force w t on the
    /// point's displacement and -w t . n on a force-driven punch's equation (direction `dn`: the
    /// point's position in the punch's frame moves by -dn with the punch's travel), and with
    /// `with_tangent` its tangent entries into the friction's list (the model adds them). The
    /// point is held on the stick or slip branch that the stick/slip criterion chose
    /// ([`StickSlip`]); returns true when that branch is not the return map's own (a change of
    /// the active set: Newton does not stop on it).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn add_friction(&mut self, k: usize, lambda: f64, active: bool, grad: &Vector3<f64>, x: Option<&Vector3<f64>>, dn: &Vector3<f64>, force: &mut [f64], with_tangent: bool) -> bool {
        let (p, eps_reg, drive) = (self.points[k], self.eps_reg, self.drive);
        let Some(y) = x.copied() else { return false };
        let turn = self.turn;
        // the body frame (the translated one when the punch has not turned)
        let (x, grad) = match &turn {
            None => (y, *grad),
            Some(t) => (t.to_body(&y), t.r.tr_mul(grad)),
        };
        let grad = &grad;
        let hess = if active { Some(self.surface.hessian(&x)) } else { None };
        let Some(f) = &mut self.friction else { return false };
        f.turn = turn.map(|t| t.r);
        f.position[k] = x.into();
        let Some(hess) = hess else {
            f.traction[k] = [0.0; 3];
            f.status[k] = OPEN;
            f.laws.open(k, with_tangent);
            return false;
        };
        let (a, lt) = (Vector3::from(f.anchor[k]), Vector3::from(f.lambda_t_bar[k]));
        let natural = return_map(f.mu, f.eps_t, &x, &a, &lt, lambda, &(grad * eps_reg), grad, &hess);
        // the branch the stick/slip criterion holds this point on (stick_slip.rs), decided in the
        // body frame
        let branch = f.laws.branch(k, &natural, with_tangent);
        let inconsistent = with_tangent && f.laws.inconsistent(k, &natural);
        let pf = if branch == natural.status { natural } else { return_map_on(Some(branch), f.mu, f.eps_t, &x, &a, &lt, lambda, &(grad * eps_reg), grad, &hess) };
        let pf = match &turn {
            None => pf,
            Some(t) => pf.turned(&t.r),
        };
        f.traction[k] = pf.traction.into();
        f.status[k] = pf.status;
        let w = p.weight;
        for i in 0..3 {
            force[p.dofs[i]] += w * pf.traction[i];
        }
        if let Some(d) = &drive {
            force[d.dof] -= w * pf.traction.dot(dn);
        }
        if !with_tangent {
            return inconsistent;
        }
        let j = pf.jacobian * w;
        for r in 0..3 {
            for c in 0..3 {
                f.entries.push((p.dofs[r], p.dofs[c], j[(r, c)], w * pf.symmetric[(r, c)]));
            }
        }
        if let Some(d) = &drive {
            let jn = j * dn;
            let nj = j.transpose() * dn;
            for i in 0..3 {
                f.entries.push((p.dofs[i], d.dof, -jn[i], 0.0));
                f.entries.push((d.dof, p.dofs[i], -nj[i], 0.0));
            }
            f.entries.push((d.dof, d.dof, dn.dot(&jn), 0.0));
        }
        inconsistent
    }

    /// The friction's tangent entries of the last evaluation with a tangent (row dof, column dof,
    /// value, value for the symmetric preconditioner); empty without friction.
    pub fn friction_entries(&self) -> &[(usize, usize, f64, f64)] {
        self.friction.as_ref().map_or(&[], |f| f.entries.as_slice())
    }

    /// The friction's converged step: see [`Friction::commit`].
    pub fn commit_friction(&mut self) {
        let Some(n) = self.friction.as_ref().map(|f| f.status.len()) else { return };
        let weights: Vec<f64> = (0..n).map(|k| self.friction_weight(k)).collect();
        if let Some(f) = &mut self.friction {
            f.commit(|k| weights[k]);
        }
    }
}

/// Whether a point is open, sticking or slipping (the `<punch>_state` output: 0, 1, 2).
pub const OPEN: u8 = 0;
pub const STICK: u8 = 1;
pub const SLIP: u8 = 2;

/// The friction of one punch: its coefficient, its tangential regularisation and each point's
/// history and state.
#[derive(Debug, Clone)]
pub struct Friction {
    /// The Coulomb coefficient mu > 0.
    pub mu: f64,
    /// The tangential regularisation eps_T (force per unit area per unit length of slip): the
    /// pair's eps_reg times |grad Psi|^2 where the punch touches (eps_reg itself for a plane), the
    /// normal stiffness per unit penetration.
    pub eps_t: f64,
    /// The augmented tangential multipliers lambda_T_bar.
    pub lambda_t_bar: Vec<[f64; 3]>,
    /// The stick anchors, in the punch's body frame (x - d when it does not turn).
    pub anchor: Vec<[f64; 3]>,
    /// Each point's position in the punch's body frame at the last evaluation.
    pub position: Vec<[f64; 3]>,
    /// Each point's tangential traction t at the last evaluation (force per unit reference area of
    /// the plate on the punch), in global axes.
    pub traction: Vec<[f64; 3]>,
    /// The punch's rotation R at the last evaluation (None: not turned, the frames agree): the
    /// multipliers, anchors and positions are in its body frame, the traction in global axes.
    pub turn: Option<Matrix3<f64>>,
    /// [`OPEN`], [`STICK`] or [`SLIP`] at the last evaluation.
    pub status: Vec<u8>,
    /// The accumulated slip length of each point over the converged steps.
    pub slip: Vec<f64>,
    /// The energy dissipated by friction at each point over the converged steps (w t . slip).
    pub dissipation: Vec<f64>,
    /// The branch each point is held on while Newton converges (the stick/slip criterion).
    pub laws: StickSlip,
    /// The tangent entries of the last evaluation with a tangent: (row dof, column dof, value,
    /// value for the symmetric preconditioner).
    pub(super) entries: Vec<(usize, usize, f64, f64)>,
}

impl Friction {
    /// No slip yet, every anchor at its point's reference position.
    pub fn new(mu: f64, eps_t: f64, x_ref: impl Iterator<Item = [f64; 3]>) -> Self {
        let position: Vec<[f64; 3]> = x_ref.collect();
        let n = position.len();
        Friction {
            mu,
            eps_t,
            lambda_t_bar: vec![[0.0; 3]; n],
            anchor: position.clone(),
            position,
            traction: vec![[0.0; 3]; n],
            turn: None,
            status: vec![OPEN; n],
            slip: vec![0.0; n],
            dissipation: vec![0.0; n],
            laws: StickSlip::new(n),
            entries: Vec::new(),
        }
    }

    /// The augmented-Lagrangian update lambda_T_bar <- t of the points in contact (0 for the
    /// open ones); the anchors stay.
    pub fn augment(&mut self, evaluated: impl Fn(usize) -> bool) {
        for k in 0..self.status.len() {
            if evaluated(k) {
                self.lambda_t_bar[k] = if self.status[k] == OPEN { [0.0; 3] } else { self.body_traction(k).into() };
            }
        }
    }

    /// The largest distance of a sticking point from its anchor in the tangent plane: the
    /// tangential violation the augmented-Lagrangian updates drive to zero.
    pub fn stick_violation(&self, normals: impl Fn(usize) -> Vector3<f64>, at: impl Fn(usize) -> bool) -> f64 {
        (0..self.status.len())
            .filter(|&k| at(k) && self.status[k] == STICK)
            .map(|k| {
                let n = normals(k);
                let g = Vector3::from(self.position[k]) - Vector3::from(self.anchor[k]);
                (g - n * n.dot(&g)).norm()
            })
            .fold(0.0, f64::max)
    }

    /// Point k's traction in the punch's body frame, R^T t.
    fn body_traction(&self, k: usize) -> Vector3<f64> {
        let t = Vector3::from(self.traction[k]);
        self.turn.map_or(t, |r| r.tr_mul(&t))
    }

    /// A converged step: a slipping point's anchor follows its slip (return map), adding the slip's
    /// length and w t . slip to its totals; an open point's anchor is where it is, its multiplier
    /// zero; a sticking point keeps both.
    pub fn commit(&mut self, weights: impl Fn(usize) -> f64) {
        for k in 0..self.status.len() {
            match self.status[k] {
                SLIP => {
                    let t = self.body_traction(k);
                    let a_new = Vector3::from(self.position[k]) - (t - Vector3::from(self.lambda_t_bar[k])) / self.eps_t;
                    let ds = a_new - Vector3::from(self.anchor[k]);
                    self.slip[k] += ds.norm();
                    self.dissipation[k] += weights(k) * t.dot(&ds);
                    self.anchor[k] = a_new.into();
                }
                STICK => {}
                _ => {
                    self.anchor[k] = self.position[k];
                    self.lambda_t_bar[k] = [0.0; 3];
                }
            }
        }
    }
}

/// The tangential traction of one point in contact and its derivative with respect to the
/// point's position x in the punch's frame.
#[derive(Debug, Clone, Copy)]
pub struct PointFriction {
    pub traction: Vector3<f64>,
    /// dt/dx (not symmetric in slip, nor with a curved punch).
    pub jacobian: Matrix3<f64>,
    /// A symmetric positive semi-definite stand-in for `jacobian` in the preconditioner:
    /// eps_T P in stick, mu q eps_T (P - s s^T) / |t_tr| in slip.
    pub symmetric: Matrix3<f64>,
    /// The trial traction P (lambda_T_bar + eps_T (x - a)).
    pub trial: Vector3<f64>,
    /// Its size against the bound: |trial| / (mu q) (infinite without pressure).
    pub cone_ratio: f64,
    pub status: u8,
}

impl PointFriction {
    /// The law of a point evaluated in a body frame, in global axes: the traction R t, the
    /// tangent R (dt/dX) R^T (X = R^T y + const).
    pub fn turned(self, r: &Matrix3<f64>) -> PointFriction {
        let rt = r.transpose();
        PointFriction { traction: r * self.traction, jacobian: r * self.jacobian * rt, symmetric: r * self.symmetric * rt, trial: r * self.trial, cone_ratio: self.cone_ratio, status: self.status }
    }
}

/// The return map of one point: `x` its position in the punch's frame, `a` its anchor,
/// `lambda_t_bar` its tangential multiplier, `lambda` its normal multiplier and `dlambda` its
/// derivative with respect to x (eps_reg grad Psi on the active branch, zero off it), `grad` and
/// `hess` grad Psi and its Hessian at x. `hess` None: a flat punch (no rotation of n).
#[allow(clippy::too_many_arguments)]
pub fn return_map(mu: f64, eps_t: f64, x: &Vector3<f64>, a: &Vector3<f64>, lambda_t_bar: &Vector3<f64>, lambda: f64, dlambda: &Vector3<f64>, grad: &Vector3<f64>, hess: &Matrix3<f64>) -> PointFriction {
    return_map_on(None, mu, eps_t, x, a, lambda_t_bar, lambda, dlambda, grad, hess)
}

/// [`return_map`] on a given branch: `Some(STICK)` the trial traction whatever its size,
/// `Some(SLIP)` mu q along the trial traction wherever that points (inside the cone too), None
/// the branch the cone decides. A point out of contact (q = 0) slips with no traction whatever
/// the branch asked for.
#[allow(clippy::too_many_arguments)]
pub fn return_map_on(
    branch: Option<u8>,
    mu: f64,
    eps_t: f64,
    x: &Vector3<f64>,
    a: &Vector3<f64>,
    lambda_t_bar: &Vector3<f64>,
    lambda: f64,
    dlambda: &Vector3<f64>,
    grad: &Vector3<f64>,
    hess: &Matrix3<f64>,
) -> PointFriction {
    let gn = grad.norm();
    if gn == 0.0 {
        return PointFriction { traction: Vector3::zeros(), jacobian: Matrix3::zeros(), symmetric: Matrix3::zeros(), trial: Vector3::zeros(), cone_ratio: f64::INFINITY, status: OPEN };
    }
    let n = grad / gn;
    let p = Matrix3::identity() - n * n.transpose();
    // dn/dx = P H / |grad Psi|
    let dn = p * hess / gn;
    let v = lambda_t_bar + (x - a) * eps_t;
    let nv = n.dot(&v);
    let trial = v - n * nv;
    // d(trial)/dx = eps_T P - (dn/dx) (n . v) - n (v^T dn/dx)
    let dtrial = p * eps_t - dn * nv - n * (v.transpose() * dn);
    // the normal pressure q = -lambda |grad Psi| and its derivative
    let (q, dq) = if lambda < 0.0 { (-lambda * gn, -(dlambda * gn + hess * grad * (lambda / gn))) } else { (0.0, Vector3::zeros()) };
    let norm = trial.norm();
    let stick = match branch {
        Some(b) => b == STICK,
        None => norm <= mu * q,
    };
    let cone_ratio = if q > 0.0 { norm / (mu * q) } else { f64::INFINITY };
    if q > 0.0 && stick {
        return PointFriction { traction: trial, jacobian: dtrial, symmetric: p * eps_t, trial, cone_ratio, status: STICK };
    }
    if norm == 0.0 {
        return PointFriction { traction: Vector3::zeros(), jacobian: Matrix3::zeros(), symmetric: Matrix3::zeros(), trial, cone_ratio, status: SLIP };
    }
    let s = trial / norm;
    let ps = Matrix3::identity() - s * s.transpose();
    let jacobian = s * dq.transpose() * mu + ps * dtrial * (mu * q / norm);
    let symmetric = (p - s * s.transpose()) * (mu * q * eps_t / norm);
    PointFriction { traction: s * (mu * q), jacobian, symmetric, trial, cone_ratio, status: SLIP }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The return map's derivative against central differences, in stick and in slip, on a
    /// sphere Psi = |x - c|^2 - R^2 (n rotates with x, q depends on x).
    #[test]
    fn the_return_map_derivative_matches_finite_differences() {
        let c = Vector3::new(0.1, -0.2, 2.0);
        let r = 1.7;
        let eps = 50.0;
        let eps_t = eps * (2.0 * r) * (2.0 * r);
        let lambda_bar = -3.0;
        let eval = |x: &Vector3<f64>, a: &Vector3<f64>, lt: &Vector3<f64>, mu: f64| {
            let d = x - c;
            let psi = d.norm_squared() - r * r;
            let grad = d * 2.0;
            let hess = Matrix3::identity() * 2.0;
            let lambda = lambda_bar + eps * psi;
            return_map(mu, eps_t, x, a, lt, lambda, &(grad * eps), &grad, &hess)
        };
        let x = Vector3::new(0.3, -0.1, 0.32);
        let lt = Vector3::new(2.0, -1.0, 0.5);
        for (a, mu, want) in [(x + Vector3::new(1e-4, 2e-4, 0.0), 0.3, STICK), (x + Vector3::new(0.05, -0.02, 0.0), 0.3, SLIP), (x + Vector3::new(0.05, -0.02, 0.0), 0.01, SLIP)] {
            let f = eval(&x, &a, &lt, mu);
            assert_eq!(f.status, want);
            let h = 1e-7;
            let mut worst = 0.0f64;
            for j in 0..3 {
                let mut e = Vector3::zeros();
                e[j] = h;
                let (fp, fm) = (eval(&(x + e), &a, &lt, mu), eval(&(x - e), &a, &lt, mu));
                assert_eq!((fp.status, fm.status), (want, want));
                let fd = (fp.traction - fm.traction) / (2.0 * h);
                for i in 0..3 {
                    worst = worst.max((fd[i] - f.jacobian[(i, j)]).abs());
                }
            }
            let scale = f.jacobian.abs().max();
            assert!(worst < 1e-6 * scale, "status {want}: dt/dx differs from differences by {worst:e} (scale {scale:e})");
            if want == SLIP {
                // on the cone
                assert!((f.traction.norm() - mu * (-(lambda_bar + eps * ((x - c).norm_squared() - r * r))) * 2.0 * (x - c).norm()).abs() < 1e-9 * f.traction.norm());
            }
        }
    }
}

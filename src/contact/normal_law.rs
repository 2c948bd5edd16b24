//! The contact law of one point, frictionless (paper eqs. 3.8, 4.9-4.10): its trial multiplier
//! lambda_bar + eps_reg Psi, its multiplier lambda = min(0, trial) on the active set, its force
//! lambda grad Psi per unit area and its tangent eps G G^T + lambda H. The active-set rules
//! (`first_touch.rs`) decide which side of the kink a point is on; the schemes (`nodal.rs`,
//! `integrated.rs`) add the forces and tangents of the points where they act.

use super::{ContactPair, ContactPoint, ForceDrive};
use crate::surface::ContactSurface;
use nalgebra::{Matrix3, Vector3};

impl ContactPair {
    /// The trial multiplier of point k at a gap function `psi`: lambda_bar + eps_reg Psi (the
    /// regularised constraint Psi - (lambda - lambda_bar) / eps_reg = 0 solved for lambda).
    pub(super) fn trial(&self, k: usize, psi: f64) -> f64 {
        trial_multiplier(self.lambda_bar[k], self.eps_reg, psi)
    }
}

/// The trial multiplier lambda_bar + eps_reg Psi of a point (see [`ContactPair::trial`]).
pub(super) fn trial_multiplier(lambda_bar: f64, eps_reg: f64, psi: f64) -> f64 {
    lambda_bar + eps_reg * psi
}

/// The multiplier of a point of trial multiplier `trial`: the trial on the active set, 0 off it
/// (lambda = min(0, trial) where the active set is the compressive side).
pub(super) fn multiplier(trial: f64, active: bool) -> f64 {
    if active { trial } else { 0.0 }
}
/// Add the tangent of one contact point: w eps G G^T + w lambda H over the point's three
/// displacement dofs and, for a force-driven punch, its unknown s (G_s = dPsi/ds = -grad Psi . n,
/// H_us = -H n, H_ss = n^T H n). `hess_at` is where the Hessian is taken (None: no curvature term).
#[allow(clippy::too_many_arguments)]
pub(super) fn point_tangent(surface: &dyn ContactSurface, p: &ContactPoint, drive: Option<&ForceDrive>, dn: &Vector3<f64>, grad: &Vector3<f64>, grad_s: f64, hess_at: Option<&Vector3<f64>>, w_eps: f64, w_lambda: f64, add: &mut dyn FnMut(usize, usize, f64)) {
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

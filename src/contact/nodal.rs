//! The paper's nodal collocation: each node's constraint at the node itself, weighted by its
//! tributary area; its force and tangent on its own three displacements (and a force-driven
//! punch's travel); its linearised row for the re-solve of the linearised contact problem.

use super::kinematics::{point_displacement, Kinematics, SiteContext, SurfaceAtPoint};
use super::normal_law::point_tangent;
use super::{ContactPair, ContactPoint, PointShare};
use crate::linearised_contact::ConstraintRow;
use nalgebra::Vector3;
use rayon::prelude::*;

/// Each point's kinematics at the point itself, for the points this process evaluates (all
/// without a share), in parallel.
pub(super) fn nodal_kinematics(site: &SiteContext, points: &[ContactPoint], at: &mut [SurfaceAtPoint], u: &[f64], kin: &mut [Kinematics], share: Option<&PointShare>) {
    let evaluated = |k: usize| share.is_none_or(|s| s.evaluated[k]);
    (kin.par_iter_mut(), at.par_iter_mut(), points.par_iter()).into_par_iter().enumerate().with_min_len(512).filter(|(k, _)| evaluated(*k)).for_each(|(_, (out, at, p))| {
        *out = site.kinematics(Vector3::from(p.x_ref), point_displacement(u, p), at);
    });
}

impl ContactPair {
    /// Add the force w lambda grad Psi of point k (and w lambda dPsi/ds into a force-driven
    /// punch's equation) and, through `add_tangent`, its tangent with the curvature term of the
    /// multiplier `curvature` (see [`point_tangent`]).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn add_nodal_point(&self, k: usize, lambda: f64, curvature: f64, grad: &Vector3<f64>, grad_s: f64, hess_at: Option<&Vector3<f64>>, dn: &Vector3<f64>, force: &mut [f64], add_tangent: &mut Option<&mut dyn FnMut(usize, usize, f64)>) {
        let p = &self.points[k];
        let w = p.weight;
        for i in 0..3 {
            force[p.dofs[i]] += w * lambda * grad[i];
        }
        if let Some(f) = &self.drive {
            force[f.dof] += w * lambda * grad_s;
        }
        if let Some(add) = add_tangent.as_deref_mut() {
            point_tangent(&self.placed(), p, self.drive.as_ref(), dn, grad, grad_s, hess_at, w * self.eps_reg, w * curvature, add);
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
            let trial = self.trial(k, s.psi);
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
}

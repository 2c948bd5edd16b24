//! The integrated discretisation on a [`ContactFace`](super::ContactFace): the constraint at the
//! face's quadrature points, each point's gap its weighted mean over its cells, the force and
//! tangent of the multiplier field lambda_h = sum_a N_a lambda_a, the pressures of that field; the
//! points whose patches the model's sparse pattern couples.

use crate::surface::ContactSurface;
use super::face::FacePoint;
use super::kinematics::{point_displacement, Kinematics, SiteContext, SurfaceAtPoint};
use super::{ContactFace, ContactPair, ContactPoint, PointShare};
use nalgebra::Vector3;
use rayon::prelude::*;

/// The kinematics at the face's quadrature points (`sites`: those this process computes, all
/// without a share) and each evaluated point's as their weighted mean over its cells, in
/// parallel.
#[allow(clippy::too_many_arguments)]
pub(super) fn integrated_kinematics(site: &SiteContext, face: &ContactFace, points: &[ContactPoint], at: &mut [SurfaceAtPoint], u: &[f64], sites: &mut Vec<Kinematics>, kin: &mut [Kinematics], share: Option<&PointShare>) {
    let evaluated = |k: usize| share.is_none_or(|s| s.evaluated[k]);
    sites.resize(face.quadrature.len(), (0.0, Vector3::zeros(), 0.0, None));
    let computed = |q: usize| share.is_none_or(|s| s.sites[q]);
    (sites.par_iter_mut(), at.par_iter_mut(), face.quadrature.par_iter()).into_par_iter().enumerate().with_min_len(512).filter(|(q, _)| computed(*q)).for_each(|(_, (out, at, q))| {
        let (mut x_ref, mut disp) = (Vector3::zeros(), Vector3::zeros());
        for a in 0..4 {
            let p = &points[q.points[a] as usize];
            x_ref += Vector3::from(p.x_ref) * q.shape[a];
            disp += point_displacement(u, p) * q.shape[a];
        }
        *out = site.kinematics(x_ref, disp, at);
    });
    let sites = &*sites;
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

impl ContactPair {
    /// Use the integrated discretisation on `face`, whose contact points are this pair's points
    /// (in order): each point's weight becomes its area int N_i dA on the face.
    pub fn with_face(mut self, face: ContactFace) -> crate::Result<Self> {
        if face.num_points() != self.points.len() {
            return Err(crate::StampError::Problem(format!("the contact face has {} points, the punch {}", face.num_points(), self.points.len())));
        }
        for (p, &a) in self.points.iter_mut().zip(&face.area) {
            p.weight = a;
        }
        self.surface_at_points = SurfaceAtPoint::none(face.quadrature.len());
        self.face = Some(face);
        Ok(self)
    }

    /// The integrated discretisation's face, if any.
    pub fn face(&self) -> Option<&ContactFace> {
        self.face.as_ref()
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

    /// The multiplier field lambda_h = sum_a N_a lambda_a at a quadrature point of the face.
    fn traction_at(&self, q: &FacePoint) -> f64 {
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
    pub(super) fn add_integrated(&self, sites: &[Kinematics], dn: &Vector3<f64>, force: &mut [f64], mut add_tangent: Option<&mut dyn FnMut(usize, usize, f64)>, share: Option<&PointShare>) {
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
            let h = self.placed().hessian(x) * wl;
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
            let a_s = weighted_gap_gradient(face, sites, i, &mut a_i);
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

    /// The pressures of the integrated discretisation (see [`pressures`](Self::pressures)): the
    /// contact force on each point along its mean normal per unit area, -f_j . n_j / A_j.
    pub(super) fn integrated_pressures(&self, face: &ContactFace) -> Vec<f64> {
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

/// The derivative of point i's weighted gap times its area, a_i = A_i dg_i/du, into `a_i` (one
/// vector per point of its patch, [`ContactFace::patch`]'s order), and A_i dg_i/ds (returned):
/// a_i[j] = sum_q w_q N_i(q) N_j(q) grad Psi_q over the quadrature points of i's cells.
pub(super) fn weighted_gap_gradient(face: &ContactFace, sites: &[Kinematics], i: usize, a_i: &mut Vec<Vector3<f64>>) -> f64 {
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
    a_s
}

//! Coulomb friction with the integrated discretisation (docs/design.md, "Friction"): the friction
//! state lives at the face's quadrature points, each with its anchor, tangential multiplier,
//! traction, status, slip and dissipation, as a nodal point's does, and the same return map
//! ([`return_map`]) gives its traction from
//!
//! - its position x_q = sum_b N_b(q) x_b in the punch's frame (the Hessian taken there),
//! - grad Psi at x_q,
//! - the normal multiplier field there, lambda_q = sum_a N_a(q) lambda_a (the field whose
//!   pressure the frictionless integrated scheme applies), the bound mu q with
//!   q = -lambda_q |grad Psi(x_q)|.
//!
//! The traction t_q acts on the points of its cell through their shape functions: the force
//! w_q N_a(q) t_q on point a (and -w_q t_q . n on a force-driven punch's equation), so a uniform
//! tangential traction is carried by the consistent nodal forces, as the normal pressure is.
//!
//! Its tangent: x_q moves with N_b u_b (and by -n with a force-driven punch's travel s), giving
//! N_a N_b w_q dt/dx; in slip the bound also moves with lambda_q, whose points a on their active
//! branch have lambda_a = lambda_bar_a + eps g_a with g_a the weighted gap, so
//! dt_q/du_k = ... + mu s (-|grad Psi|) sum_a N_a(q) (eps / A_a) a_a[k] (a_a = A_a dg_a/du, over the
//! patch of a; [`weighted_gap_gradient`]). Those entries couple a cell's points with the patches
//! of its points, all inside the patches the model's pattern couples.
//!
//! With a share (`share.rs`) a process computes the quadrature points of the cells with an own
//! point (`force_sites`): the same numbers as on every other process that computes them, the
//! forces and tangent rows of its own points, and of the force-driven punch's row and equation the
//! quadrature point's part of its own points' shape functions (their sum over the processes is the
//! whole). The process that gathers a quadrature point's kinematics (`gathers_site`) counts it
//! and gives its state after a converged step.
//!
//! For the outputs each point gets a nodal view ([`ContactPair::friction_at_points`]): its
//! traction the consistent nodal friction force over its area, (1 / A_i) sum_q w_q N_i(q) t_q,
//! its slip the same mean of the quadrature points' slips, its state slip if any of its
//! quadrature points slips, else stick if any sticks, else open.

use super::friction_law::{return_map, OPEN, SLIP, STICK};
use super::integrated::weighted_gap_gradient;
use super::kinematics::Kinematics;
use super::{ContactPair, PointShare};
use nalgebra::Vector3;

/// The friction of every contact point as the outputs show it: the tangential traction (force per
/// unit area of the plate on the punch), the accumulated slip length and the state (0 open,
/// 1 stick, 2 slip), per point.
#[derive(Debug, Clone, PartialEq)]
pub struct FrictionAtPoints {
    pub traction: Vec<[f64; 3]>,
    pub slip: Vec<f64>,
    pub status: Vec<u8>,
}

impl ContactPair {
    /// The friction of the quadrature points of the integrated face (the pair has friction and a
    /// face; after [`add_integrated`](Self::add_integrated), with the points' multipliers of this
    /// evaluation): each one's return map, its forces, and with `with_tangent` its tangent
    /// entries into the friction's list (see the module documentation).
    pub(super) fn add_integrated_friction(&mut self, sites: &[Kinematics], dn: &Vector3<f64>, force: &mut [f64], with_tangent: bool, share: Option<&PointShare>) {
        let (Some(face), Some(f)) = (&self.face, &mut self.friction) else { return };
        let own = |k: u32| share.is_none_or(|s| s.own[k as usize]);
        let (points, state, drive, eps_reg) = (&self.points, &self.state, self.drive, self.eps_reg);
        // a_a of one point over its patch (scratch, reused)
        let mut a_buf: Vec<Vector3<f64>> = Vec::new();
        for (k, (q, site)) in face.quadrature.iter().zip(sites).enumerate() {
            if share.is_some_and(|s| !s.force_sites[k]) {
                continue;
            }
            let (_, grad, _, Some(x)) = site else { continue };
            f.position[k] = (*x).into();
            let lambda_q: f64 = (0..4).map(|a| q.shape[a] * state[q.points[a] as usize].lambda).sum();
            if lambda_q == 0.0 {
                f.traction[k] = [0.0; 3];
                f.status[k] = OPEN;
                continue;
            }
            let hess = self.surface.hessian(x);
            let pf = return_map(f.mu, f.eps_t, x, &Vector3::from(f.anchor[k]), &Vector3::from(f.lambda_t_bar[k]), lambda_q, &Vector3::zeros(), grad, &hess);
            f.traction[k] = pf.traction.into();
            f.status[k] = pf.status;
            let w = q.weight;
            // this process's part of the quadrature point in the punch's row and equation
            let part = match share {
                None => 1.0,
                Some(_) => (0..4).filter(|&a| own(q.points[a])).map(|a| q.shape[a]).sum::<f64>(),
            };
            for a in (0..4).filter(|&a| own(q.points[a])) {
                let p = &points[q.points[a] as usize];
                for i in 0..3 {
                    force[p.dofs[i]] += w * q.shape[a] * pf.traction[i];
                }
            }
            if let Some(d) = &drive {
                force[d.dof] -= part * w * pf.traction.dot(dn);
            }
            if !with_tangent {
                continue;
            }
            let j = pf.jacobian * w;
            let jn = j * dn;
            let nj = j.transpose() * dn;
            let sym = pf.symmetric * w;
            for a in (0..4).filter(|&a| own(q.points[a])) {
                let pa = &points[q.points[a] as usize];
                for b in 0..4 {
                    let pb = &points[q.points[b] as usize];
                    let nn = q.shape[a] * q.shape[b];
                    for r in 0..3 {
                        for c in 0..3 {
                            f.entries.push((pa.dofs[r], pb.dofs[c], nn * j[(r, c)], nn * sym[(r, c)]));
                        }
                    }
                }
                if let Some(d) = &drive {
                    for r in 0..3 {
                        f.entries.push((pa.dofs[r], d.dof, -q.shape[a] * jn[r], 0.0));
                    }
                }
            }
            if let Some(d) = &drive {
                for b in 0..4 {
                    let pb = &points[q.points[b] as usize];
                    for c in 0..3 {
                        f.entries.push((d.dof, pb.dofs[c], -part * q.shape[b] * nj[c], 0.0));
                    }
                }
                f.entries.push((d.dof, d.dof, part * dn.dot(&jn), 0.0));
            }
            // in slip the bound mu q follows lambda_q: dt/dlambda_q = -mu |grad Psi| s
            if pf.status != SLIP || lambda_q >= 0.0 {
                continue;
            }
            // (t = mu q s with q = -lambda_q |grad Psi| and s independent of lambda_q: t / lambda_q)
            let e = pf.traction / lambda_q;
            let en = dn.dot(&e);
            for a2 in 0..4 {
                let i = q.points[a2] as usize;
                if state[i].lambda == 0.0 {
                    continue;
                }
                let patch = face.patch(i);
                let a_s = weighted_gap_gradient(face, sites, i, &mut a_buf);
                let c2 = w * q.shape[a2] * eps_reg / face.area[i];
                for a in (0..4).filter(|&a| own(q.points[a])) {
                    let pa = &points[q.points[a] as usize];
                    let ce = e * (q.shape[a] * c2);
                    for (kk, ak) in patch.iter().zip(&a_buf) {
                        let pk = &points[*kk as usize];
                        for r in 0..3 {
                            for c in 0..3 {
                                f.entries.push((pa.dofs[r], pk.dofs[c], ce[r] * ak[c], 0.0));
                            }
                        }
                    }
                    if let Some(d) = &drive {
                        for r in 0..3 {
                            f.entries.push((pa.dofs[r], d.dof, ce[r] * a_s, 0.0));
                        }
                    }
                }
                if let Some(d) = &drive {
                    for (kk, ak) in patch.iter().zip(&a_buf) {
                        let pk = &points[*kk as usize];
                        for c in 0..3 {
                            f.entries.push((d.dof, pk.dofs[c], -part * en * c2 * ak[c], 0.0));
                        }
                    }
                    f.entries.push((d.dof, d.dof, -part * en * c2 * a_s, 0.0));
                }
            }
        }
    }

    /// The weight of friction site k: the point's tributary area (nodal), the quadrature point's
    /// weight (integrated).
    pub(super) fn friction_weight(&self, k: usize) -> f64 {
        match &self.face {
            None => self.points[k].weight,
            Some(face) => face.quadrature[k].weight,
        }
    }

    /// The unit normal of the punch at friction site k at the last evaluation.
    pub(super) fn friction_normal(&self, k: usize) -> Vector3<f64> {
        let g = match &self.face {
            None => Vector3::from(self.state[k].grad),
            Some(_) => self.site_scratch.get(k).map_or_else(Vector3::zeros, |s| s.1),
        };
        let n = g.norm();
        let n = if n > 0.0 { g / n } else { g };
        // the anchors are in the punch's body frame: so is the normal
        self.turn.map_or(n, |t| t.r.tr_mul(&n))
    }

    /// This process evaluates friction site k (all without a share).
    pub(super) fn evaluates_friction(&self, k: usize) -> bool {
        match (&self.share, &self.face) {
            (None, _) => true,
            (Some(s), None) => s.evaluated[k],
            (Some(s), Some(_)) => s.force_sites[k],
        }
    }

    /// This process counts friction site k in the punch's totals and gives its state (each site
    /// exactly one process; all without a share).
    pub(super) fn counts_friction(&self, k: usize) -> bool {
        match (&self.share, &self.face) {
            (None, _) => true,
            (Some(s), None) => s.own[k],
            (Some(s), Some(_)) => s.gathers_site[k],
        }
    }

    /// The friction of every contact point as the outputs show it (None without friction): the
    /// nodal state itself, or the integrated scheme's quadrature points seen at the points (see
    /// the module documentation).
    pub fn friction_at_points(&self) -> Option<FrictionAtPoints> {
        let f = self.friction.as_ref()?;
        let Some(face) = &self.face else {
            return Some(FrictionAtPoints { traction: f.traction.clone(), slip: f.slip.clone(), status: f.status.clone() });
        };
        let n = self.points.len();
        let mut out = FrictionAtPoints { traction: vec![[0.0; 3]; n], slip: vec![0.0; n], status: vec![OPEN; n] };
        for i in 0..n {
            let (mut t, mut slip) = (Vector3::zeros(), 0.0);
            let (mut stick, mut slips) = (false, false);
            for &(qk, a) in face.of_point(i) {
                let q = &face.quadrature[qk as usize];
                let wn = q.weight * q.shape[a as usize];
                t += Vector3::from(f.traction[qk as usize]) * wn;
                slip += wn * f.slip[qk as usize];
                stick |= f.status[qk as usize] == STICK;
                slips |= f.status[qk as usize] == SLIP;
            }
            let area = face.area[i];
            out.traction[i] = (t / area).into();
            out.slip[i] = slip / area;
            out.status[i] = if slips { SLIP } else if stick { STICK } else { OPEN };
        }
        Some(out)
    }
}

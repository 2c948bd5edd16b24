//! One evaluation of a pair: every point's kinematics, the active-set rules, each point's
//! multiplier by the normal law, and its force and tangent by the pair's scheme; a force-driven
//! punch's equation, and its hold on the plate while nothing touches.

use crate::surface::ContactSurface;
use super::integrated::integrated_kinematics;
use super::kinematics::{point_displacement, SiteContext};
use super::nodal::nodal_kinematics;
use super::normal_law::multiplier;
use super::{ContactKinematics, ContactPair, PointShare, PointState};
use nalgebra::Vector3;

impl ContactPair {
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
        self.turn = self.rotation.as_ref().and_then(|r| r.turn(t));
        let drive = self.drive;
        let dn = drive.map(|f| Vector3::from(f.direction)).unwrap_or_else(Vector3::zeros);
        let mut changes = 0;
        let with_tangent = add_tangent.is_some();
        let first = !self.initialized;
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
            turn: self.turn,
            kinematics: self.kinematics,
            d,
            prescribed: Vector3::from(self.motion.displacement(t)),
            dn,
            s: drive.map(|f| u[f.dof]).unwrap_or(0.0),
        };
        match &self.face {
            None => nodal_kinematics(&site, &self.points, &mut self.surface_at_points, u, &mut kin, share),
            Some(face) => integrated_kinematics(&site, face, &self.points, &mut self.surface_at_points, u, &mut sites, &mut kin, share),
        }
        let rules = self.active_set_rules(&kin, first, with_tangent, share)?;
        // for STAMP_DEBUG: points deferred, released, entering, penetrating, held
        let mut tally = [0usize; 5];
        let integrated = self.face.is_some();
        if let (Some(f), true) = (&mut self.friction, with_tangent) {
            f.entries.clear();
        }
        if integrated {
            self.tangent_points.clear();
            self.tangent_points.resize(self.points.len(), false);
        }
        for (k, &(psi, grad, grad_s, hess)) in kin.iter().enumerate() {
            if !evaluated(k) {
                continue;
            }
            // a halo point (integrated) goes through the same rules as on its owner's process,
            // which counts it
            let changes_before = changes;
            let trial = self.trial(k, psi);
            let (was_active, active) = self.decide_point(k, trial, first, with_tangent, own(k), &rules, &mut changes, &mut tally);
            if !own(k) {
                changes = changes_before;
            }
            let lambda = multiplier(trial, active);
            let deep = self.deep_entry(active, was_active, lambda, psi, &grad, hess.as_ref());
            if with_tangent {
                self.entered[k] = active && !was_active;
                self.entered_deep[k] = deep;
                self.last_trial[k] = trial;
            }
            self.state[k] = PointState { psi, grad: grad.into(), lambda, active };
            // a point that cycled keeps the active-side tangent near the kink (its force stays exact)
            let near_kink = !self.hold_active_set && self.frozen[k] && with_tangent && trial <= rules.band;
            if self.friction.is_some() && !integrated && self.add_friction(k, lambda, active, &grad, hess.as_ref(), &dn, force, with_tangent) && own(k) {
                // held on a branch of the friction cone that is not the cone's own
                changes += 1;
            }
            if !active && !near_kink {
                continue;
            }
            any_tangent |= own(k);
            if integrated {
                // forces and tangent from the quadrature points below
                self.tangent_points[k] = true;
                continue;
            }
            let curvature = if deep { 0.0 } else { lambda };
            self.add_nodal_point(k, lambda, curvature, &grad, grad_s, hess.as_ref(), &dn, force, &mut add_tangent);
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
            if let Some(f) = &self.friction {
                let count = |w: u8| f.status.iter().enumerate().filter(|&(k, &s)| own(k) && s == w).count();
                eprintln!("  {} friction: {} sticking, {} slipping", self.name, count(super::STICK), count(super::SLIP));
            }
        }
        if let Some(f) = &drive {
            // the load once over the processes
            if share.is_none_or(|s| s.leader) {
                force[f.dof] -= t * f.force;
            }
            if !any_tangent {
                self.hold_floating_punch(u, t, &d, &dn, force, &mut add_tangent, share)?;
            }
        }
        if integrated {
            if with_tangent {
                self.needs_coupling = self.tangent_points.iter().zip(&self.coupled).any(|(t, c)| *t && !*c);
            }
            self.add_integrated(&sites, &dn, force, add_tangent, share);
            if self.friction.is_some() {
                self.add_integrated_friction(&sites, &dn, force, with_tangent, share);
            }
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

    /// A force-driven punch with no point in contact: its equation has no stiffness (it floats)
    /// and no state is an equilibrium unless t F = 0. Keep the point closest to the punch on its
    /// active branch, lambda = lambda_bar + eps Psi even where that pulls: Newton then brings the
    /// punch onto the plate in one step instead of creeping towards it. Once a point touches, this
    /// stops; at t F = 0 the punch rests touching the plate with no force.
    #[allow(clippy::too_many_arguments)]
    fn hold_floating_punch(&mut self, u: &[f64], t: f64, d: &Vector3<f64>, dn: &Vector3<f64>, force: &mut [f64], add_tangent: &mut Option<&mut dyn FnMut(usize, usize, f64)>, share: Option<&PointShare>) -> crate::Result<()> {
        let own = |k: usize| share.is_none_or(|s| s.own[k]);
        let evaluated = |k: usize| share.is_none_or(|s| s.evaluated[k]);
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
        if let (Some(k), true) = (closest, self.face.is_some()) {
            // on every process that evaluates it (its cells' forces are theirs)
            if evaluated(k) {
                self.state[k].lambda = self.trial(k, self.state[k].psi);
                self.tangent_points[k] = true;
            }
        } else if let Some(k) = closest.filter(|&k| own(k)) {
            let p = &self.points[k];
            let g = Vector3::from(self.state[k].grad);
            let lambda = self.trial(k, self.state[k].psi);
            let (grad_s, hess_at) = match self.kinematics {
                ContactKinematics::Exact => (-g.dot(dn), Some(Vector3::from(p.x_ref) + point_displacement(u, p) - d)),
                ContactKinematics::Shallow { .. } => {
                    let x0 = Vector3::from(p.x_ref) - Vector3::from(self.motion.displacement(t));
                    (-self.placed().gradient(&x0).dot(dn), None)
                }
            };
            self.state[k].lambda = lambda;
            self.add_nodal_point(k, lambda, lambda, &g, grad_s, hess_at.as_ref(), dn, force, add_tangent);
        }
        Ok(())
    }
}

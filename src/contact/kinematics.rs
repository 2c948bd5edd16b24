//! Where a point of the body stands against the punch: Psi and its gradient at the point's
//! current position (exact kinematics, eq. 3.5) or linearised about its reference position (the
//! shallow constraint, eq. 3.9), with the derivative along a force-driven punch's travel.

use super::rotation::Turn;
use super::{ContactKinematics, ContactPoint};
use crate::surface::ContactSurface;
use nalgebra::Vector3;

/// Psi and its gradient at a point's last position in the punch's body frame (see
/// `ContactPair::surface_at_points`), both of the unturned surface.
#[derive(Debug, Clone, Copy)]
pub(super) struct SurfaceAtPoint {
    pub(super) x: Vector3<f64>,
    pub(super) psi: f64,
    pub(super) grad: Vector3<f64>,
}

impl SurfaceAtPoint {
    /// `n` points where the surface was not queried yet (at NaN, never equal to a position).
    pub(super) fn none(n: usize) -> Vec<SurfaceAtPoint> {
        vec![SurfaceAtPoint { x: Vector3::repeat(f64::NAN), psi: 0.0, grad: Vector3::zeros() }; n]
    }
}

/// Psi, its gradient with respect to the displacement of the point (or quadrature point), its
/// derivative with respect to a force-driven punch's unknown s, and where the Hessian is taken
/// (None: no curvature term, the shallow constraint).
pub(super) type Kinematics = (f64, Vector3<f64>, f64, Option<Vector3<f64>>);

/// What the kinematics of a point of the face needs at one evaluation.
pub(super) struct SiteContext<'a> {
    pub(super) surface: &'a dyn ContactSurface,
    /// The punch's rotation (None: it has not turned).
    pub(super) turn: Option<Turn>,
    pub(super) kinematics: ContactKinematics,
    /// The punch displacement (prescribed plus s n).
    pub(super) d: Vector3<f64>,
    /// The prescribed part of it.
    pub(super) prescribed: Vector3<f64>,
    /// A force-driven punch's direction n (zero otherwise) and its unknown s.
    pub(super) dn: Vector3<f64>,
    pub(super) s: f64,
}

impl SiteContext<'_> {
    /// The kinematics of the point at reference position `x_ref` displaced by `disp`: the surface
    /// is queried at x (exact kinematics) or at the reference position moved back by the
    /// prescribed motion (shallow: linearised about it), taken to the punch's body frame when it
    /// has turned, and not again while the point stays where it was in that frame (`at`). The
    /// gradient is in global axes (R grad Psi0); where the Hessian is taken is the translated
    /// position (the pair's [`Turned`](super::Turned) surface turns it).
    pub(super) fn kinematics(&self, x_ref: Vector3<f64>, disp: Vector3<f64>, at: &mut SurfaceAtPoint) -> Kinematics {
        // (a worker thread may come from faer's kernels: see crate::linalg::vector_state)
        crate::linalg::vector_state::clean_upper_vector_state();
        let x = match self.kinematics {
            ContactKinematics::Exact => x_ref + disp - self.d,
            ContactKinematics::Shallow { .. } => x_ref - self.prescribed,
        };
        let body = match &self.turn {
            None => x,
            Some(t) => t.to_body(&x),
        };
        // (NaN at the start: never equal)
        if body != at.x {
            let (psi, grad) = self.surface.psi_and_gradient(&body);
            *at = SurfaceAtPoint { x: body, psi, grad };
        }
        let SurfaceAtPoint { psi, grad: g, .. } = *at;
        let g = match &self.turn {
            None => g,
            Some(t) => t.r * g,
        };
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

/// The displacement of point `p` in the unknowns `u`.
pub(super) fn point_displacement(u: &[f64], p: &ContactPoint) -> Vector3<f64> {
    Vector3::new(u[p.dofs[0]], u[p.dofs[1]], u[p.dofs[2]])
}

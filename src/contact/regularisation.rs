//! The default regularisation parameter eps_reg (docs/design.md, "Contact regularisation"): a
//! contact spring per node that is a fixed multiple of the plate's membrane stiffness around it.

use super::ContactPair;
use nalgebra::Vector3;

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

impl ContactPair {
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
}

//! A punch's surface as its rotation places it ([`Turned`]): Psi(y) = Psi0(R^T (y - pivot) +
//! pivot) in the translated frame y = x - d, its gradient R grad Psi0 and its Hessian
//! R H0 R^T, for any [`ContactSurface`] (once here, not per shape).

use super::rotation::Turn;
use crate::surface::ContactSurface;
use nalgebra::{Matrix3, Vector3};

/// A surface seen through a punch's rotation at one load factor; with no rotation (`turn` None)
/// every query goes to the surface unchanged, to the bit.
#[derive(Clone, Copy)]
pub struct Turned<'a> {
    pub surface: &'a dyn ContactSurface,
    pub turn: Option<Turn>,
}

impl ContactSurface for Turned<'_> {
    fn psi(&self, y: &Vector3<f64>) -> f64 {
        match &self.turn {
            None => self.surface.psi(y),
            Some(t) => self.surface.psi(&t.to_body(y)),
        }
    }

    fn gradient(&self, y: &Vector3<f64>) -> Vector3<f64> {
        match &self.turn {
            None => self.surface.gradient(y),
            Some(t) => t.r * self.surface.gradient(&t.to_body(y)),
        }
    }

    fn psi_and_gradient(&self, y: &Vector3<f64>) -> (f64, Vector3<f64>) {
        match &self.turn {
            None => self.surface.psi_and_gradient(y),
            Some(t) => {
                let (psi, g) = self.surface.psi_and_gradient(&t.to_body(y));
                (psi, t.r * g)
            }
        }
    }

    fn hessian(&self, y: &Vector3<f64>) -> Matrix3<f64> {
        match &self.turn {
            None => self.surface.hessian(y),
            Some(t) => t.r * self.surface.hessian(&t.to_body(y)) * t.r.transpose(),
        }
    }

    fn length_scale(&self) -> f64 {
        self.surface.length_scale()
    }

    fn describe(&self) -> String {
        self.surface.describe()
    }

    fn evaluation_error(&self) -> Option<String> {
        self.surface.evaluation_error()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::rotation::Turn;

    /// An ellipsoid-like quartic with no symmetry, so that every term of the rotation shows.
    struct Lumpy;
    impl ContactSurface for Lumpy {
        fn psi(&self, x: &Vector3<f64>) -> f64 {
            (x[0] / 3.0).powi(2) + (x[1] / 2.0).powi(2) + x[2] * x[2] + 0.1 * x[0] * x[1] * x[2] + 0.05 * x[0].powi(3) - 1.0
        }
        fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64> {
            Vector3::new(
                2.0 * x[0] / 9.0 + 0.1 * x[1] * x[2] + 0.15 * x[0] * x[0],
                x[1] / 2.0 + 0.1 * x[0] * x[2],
                2.0 * x[2] + 0.1 * x[0] * x[1],
            )
        }
        fn hessian(&self, x: &Vector3<f64>) -> Matrix3<f64> {
            Matrix3::new(2.0 / 9.0 + 0.3 * x[0], 0.1 * x[2], 0.1 * x[1], 0.1 * x[2], 0.5, 0.1 * x[0], 0.1 * x[1], 0.1 * x[0], 2.0)
        }
    }

    /// Psi, its gradient and its Hessian of a turned surface against central differences of the
    /// turned Psi and gradient, and Psi at a turned point equal to Psi0 at the body point.
    #[test]
    fn a_turned_surface_has_the_derivatives_of_its_psi() {
        let turn = Turn::new([0.3, -1.0, 0.5], [0.4, 0.2, -0.7], 37.0);
        let s = Turned { surface: &Lumpy, turn: Some(turn) };
        let body = Vector3::new(0.6, -0.4, 0.9);
        let y = turn.to_translated(&body);
        assert!((s.psi(&y) - Lumpy.psi(&body)).abs() < 1e-14, "Psi follows the punch");
        let (psi, g) = s.psi_and_gradient(&y);
        assert_eq!((psi, g), (s.psi(&y), s.gradient(&y)));
        let h = s.hessian(&y);
        let step = 1e-6;
        for j in 0..3 {
            let mut e = Vector3::zeros();
            e[j] = step;
            let dpsi = (s.psi(&(y + e)) - s.psi(&(y - e))) / (2.0 * step);
            assert!((dpsi - g[j]).abs() < 1e-8, "dPsi/dy{j}: {dpsi} against {}", g[j]);
            let dg = (s.gradient(&(y + e)) - s.gradient(&(y - e))) / (2.0 * step);
            for i in 0..3 {
                assert!((dg[i] - h[(i, j)]).abs() < 1e-8, "H[{i}][{j}]: {} against {}", dg[i], h[(i, j)]);
            }
        }
        // the turn matters: the unturned surface's gradient differs by far more than round-off
        assert!((Lumpy.gradient(&y) - g).norm() > 0.1);
        // without a turn every query is the surface's own, to the bit
        let none = Turned { surface: &Lumpy, turn: None };
        assert_eq!((none.psi(&y), none.gradient(&y), none.hessian(&y)), (Lumpy.psi(&y), Lumpy.gradient(&y), Lumpy.hessian(&y)));
    }
}

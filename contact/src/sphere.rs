//! A spherical punch.

use crate::{check_finite_scalar, check_finite_vector, check_radius, fmt_vec};
use nalgebra::{Matrix3, Vector3};
use stamp::surface::ContactSurface;
use stamp::Result;

/// A rigid sphere: Psi(x) = |x - c|^2 - R^2, gradient 2 (x - c), Hessian 2 I.
///
/// Fields are private so that the radius stays positive; build one with [`Sphere::new`] or
/// [`Sphere::touching_from_above`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    center: Vector3<f64>,
    radius: f64,
}

impl Sphere {
    /// A sphere of the given `radius` centred at `center`.
    ///
    /// Errors with [`stamp::StampError::Problem`] if the centre is non-finite or the radius is not
    /// finite and strictly positive.
    pub fn new(center: Vector3<f64>, radius: f64) -> Result<Self> {
        check_finite_vector("sphere", "centre", &center)?;
        let radius = check_radius("sphere", radius)?;
        Ok(Self { center, radius })
    }

    /// A sphere touching the plane x3 = `top_z` from above at (`x1`, `x2`, `top_z`): its centre is
    /// (`x1`, `x2`, `top_z` + R).
    pub fn touching_from_above(x1: f64, x2: f64, top_z: f64, radius: f64) -> Result<Self> {
        let top_z = check_finite_scalar("sphere", "height of the touched plane", top_z)?;
        let radius = check_radius("sphere", radius)?;
        Self::new(Vector3::new(x1, x2, top_z + radius), radius)
    }

    /// The centre c.
    pub fn center(&self) -> Vector3<f64> {
        self.center
    }

    /// The radius R.
    pub fn radius(&self) -> f64 {
        self.radius
    }
}

impl ContactSurface for Sphere {
    fn psi(&self, x: &Vector3<f64>) -> f64 {
        (x - self.center).norm_squared() - self.radius * self.radius
    }

    fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64> {
        2.0 * (x - self.center)
    }

    fn hessian(&self, _x: &Vector3<f64>) -> Matrix3<f64> {
        2.0 * Matrix3::identity()
    }

    fn length_scale(&self) -> f64 {
        self.radius
    }

    fn describe(&self) -> String {
        format!("sphere R = {} at {}", self.radius, fmt_vec(&self.center))
    }
}

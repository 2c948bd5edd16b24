//! A spherical punch.

use crate::{check_finite_scalar, check_finite_vector, check_radius, fmt_vec};
use nalgebra::{Matrix3, Vector3};
use stamp::surface::ContactSurface;
use stamp::Result;

/// A rigid sphere: Psi(x) = |x - c|^2 - R^2, gradient 2 (x - c), Hessian 2 I.
///
/// Psi is evaluated as |y|^2 + 2 R y . e with y = x - p, p = c + R e the pole of the sphere
/// facing the plate's midplane x3 = 0 (e = -sign(c3) e3): the same function, without the
/// cancellation of |x - c|^2 against R^2 (both ~R^2, their round-off ~R^2 eps) near the pole,
/// where the plate touches. On a sphere of radius 200 that round-off, 9e-12 in Psi, times the
/// penalty, held Newton's residual at 1e-9 of the force scale; the pole form's is ~|y|^2 eps.
///
/// Fields are private so that the radius stays positive; build one with [`Sphere::new`] or
/// [`Sphere::touching_from_above`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    center: Vector3<f64>,
    radius: f64,
    /// The pole p = c + R e facing the midplane, and e.
    pole: Vector3<f64>,
    normal: Vector3<f64>,
}

impl Sphere {
    /// A sphere of the given `radius` centred at `center`.
    ///
    /// Errors with [`stamp::StampError::Problem`] if the centre is non-finite or the radius is not
    /// finite and strictly positive.
    pub fn new(center: Vector3<f64>, radius: f64) -> Result<Self> {
        // (the centre is checked there)
        let normal = Vector3::new(0.0, 0.0, if center.z > 0.0 { -1.0 } else { 1.0 });
        Self::with_pole(center, radius, normal)
    }

    /// A sphere whose Psi is evaluated about the pole c + R e in direction `toward` (any
    /// non-zero length): exact to the round-off of |x - p|^2 near that pole. [`Sphere::new`]
    /// takes the pole facing the midplane x3 = 0; give another where the plate touches
    /// elsewhere (a plate turned out of the x1-x2 plane).
    pub fn with_pole(center: Vector3<f64>, radius: f64, toward: Vector3<f64>) -> Result<Self> {
        check_finite_vector("sphere", "centre", &center)?;
        let radius = check_radius("sphere", radius)?;
        let normal = crate::unit_direction("sphere", "pole direction", &toward)?;
        Ok(Self { center, radius, pole: center + radius * normal, normal })
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
        // |x - c|^2 - R^2 = |y + R e|^2 - R^2 = |y|^2 + 2 R y . e
        let y = x - self.pole;
        y.norm_squared() + 2.0 * self.radius * y.dot(&self.normal)
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

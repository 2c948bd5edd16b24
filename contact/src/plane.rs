//! A rigid half-space bounded by a plane.

use crate::{check_finite_scalar, check_finite_vector, fmt_vec, unit_direction};
use nalgebra::{Matrix3, Vector3};
use stamp::surface::ContactSurface;
use stamp::Result;

/// A rigid half-space bounded by the plane through `point` with unit normal n:
/// Psi(x) = n·(x - point), gradient n, Hessian 0.
///
/// The normal points OUT of the rigid half-space, towards where the plate is allowed to be.
/// Fields are private so that the normal stays a unit vector; build one with [`Plane::new`],
/// [`Plane::below`] or [`Plane::above`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    point: Vector3<f64>,
    normal: Vector3<f64>,
}

impl Plane {
    /// The plane through `point` with normal `normal` (any non-zero length; it is normalised
    /// here), pointing out of the rigid half-space.
    ///
    /// Errors with [`stamp::StampError::Problem`] if any input is non-finite or the normal is zero.
    pub fn new(point: Vector3<f64>, normal: Vector3<f64>) -> Result<Self> {
        check_finite_vector("plane", "point", &point)?;
        let normal = unit_direction("plane", "normal", &normal)?;
        Ok(Self { point, normal })
    }

    /// The rigid half-space x3 < `z` (a floor): Psi(x) = x3 - z.
    pub fn below(z: f64) -> Result<Self> {
        let z = check_finite_scalar("plane", "height", z)?;
        Self::new(Vector3::new(0.0, 0.0, z), Vector3::z())
    }

    /// The rigid half-space x3 > `z` (a ceiling): Psi(x) = z - x3.
    pub fn above(z: f64) -> Result<Self> {
        let z = check_finite_scalar("plane", "height", z)?;
        Self::new(Vector3::new(0.0, 0.0, z), -Vector3::z())
    }

    /// A point on the plane.
    pub fn point(&self) -> Vector3<f64> {
        self.point
    }

    /// The unit normal, pointing out of the rigid half-space.
    pub fn normal(&self) -> Vector3<f64> {
        self.normal
    }
}

impl ContactSurface for Plane {
    fn psi(&self, x: &Vector3<f64>) -> f64 {
        self.normal.dot(&(x - self.point))
    }

    fn gradient(&self, _x: &Vector3<f64>) -> Vector3<f64> {
        self.normal
    }

    fn hessian(&self, _x: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::zeros()
    }

    fn length_scale(&self) -> f64 {
        1.0
    }

    fn describe(&self) -> String {
        format!(
            "rigid half-space behind the plane through {} with outward normal {}",
            fmt_vec(&self.point),
            fmt_vec(&self.normal)
        )
    }
}

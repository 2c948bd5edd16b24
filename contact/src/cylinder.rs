//! An infinitely long circular cylinder, the punch of the paper (eq. 3.6).

use crate::{check_finite_scalar, check_finite_vector, check_radius, fmt_vec, unit_direction};
use nalgebra::{Matrix3, Vector3};
use stamp::surface::ContactSurface;
use stamp::Result;

/// A rigid circular cylinder of radius R whose axis passes through `point` with unit direction `a`.
///
/// Psi(x) = |r_perp|^2 - R^2 with r = x - point and r_perp = r - (r·a) a, the squared distance to
/// the axis minus R^2. For the axis along x1 through (0, 0, R) this is the paper's eq. 3.6,
/// Psi = x2^2 + (x3 - R)^2 - R^2. The gradient is 2 r_perp and the Hessian 2 (I - a a^T).
///
/// Psi is evaluated as |y_perp|^2 + 2 R y . e with y = x - q, q = point + R e on the line of
/// the cylinder facing the plate's midplane x3 = 0 (e perpendicular to the axis, towards x3 = 0):
/// the same function without the cancellation of |r_perp|^2 against R^2 near that line, where
/// the plate touches (as [`crate::Sphere`]'s pole). An axis within 60 degrees of x3 has no such
/// line and keeps the plain form.
///
/// Fields are private so that the axis stays normalised and the radius positive; build one with
/// [`Cylinder::new`] or [`Cylinder::along_x1_touching`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cylinder {
    point: Vector3<f64>,
    axis: Vector3<f64>,
    radius: f64,
    /// The line facing the midplane, q = point + R e, and e (zero: the plain form).
    near: Vector3<f64>,
    normal: Vector3<f64>,
}

impl Cylinder {
    /// A cylinder of the given `radius` whose axis passes through `point` along `axis` (any
    /// non-zero length; it is normalised here).
    ///
    /// Errors with [`stamp::StampError::Problem`] if any input is non-finite, the axis is zero or
    /// the radius is not strictly positive.
    pub fn new(point: Vector3<f64>, axis: Vector3<f64>, radius: f64) -> Result<Self> {
        check_finite_vector("cylinder", "axis point", &point)?;
        let axis = unit_direction("cylinder", "axis direction", &axis)?;
        let radius = check_radius("cylinder", radius)?;
        let down = Vector3::new(0.0, 0.0, if point.z > 0.0 { -1.0 } else { 1.0 });
        let across = down - down.dot(&axis) * axis;
        let normal = if across.norm() >= 0.5 { across.normalize() } else { Vector3::zeros() };
        Ok(Self { point, axis, radius, near: point + radius * normal, normal })
    }

    /// A cylinder with its axis along x1 that touches the plane x3 = `top_z` from above along the
    /// line x2 = `x2_center`: its axis passes through (0, `x2_center`, `top_z` + R). With
    /// `x2_center` = `top_z` = 0 this is exactly the paper's eq. 3.6.
    pub fn along_x1_touching(x2_center: f64, top_z: f64, radius: f64) -> Result<Self> {
        let x2_center = check_finite_scalar("cylinder", "x2 of the contact line", x2_center)?;
        let top_z = check_finite_scalar("cylinder", "height of the touched plane", top_z)?;
        let radius = check_radius("cylinder", radius)?;
        Self::new(Vector3::new(0.0, x2_center, top_z + radius), Vector3::x(), radius)
    }

    /// A point on the axis.
    pub fn point(&self) -> Vector3<f64> {
        self.point
    }

    /// The unit axis direction.
    pub fn axis(&self) -> Vector3<f64> {
        self.axis
    }

    /// The radius R.
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The component of x - point perpendicular to the axis.
    fn r_perp(&self, x: &Vector3<f64>) -> Vector3<f64> {
        let r = x - self.point;
        r - r.dot(&self.axis) * self.axis
    }
}

impl ContactSurface for Cylinder {
    fn psi(&self, x: &Vector3<f64>) -> f64 {
        if self.normal == Vector3::zeros() {
            return self.r_perp(x).norm_squared() - self.radius * self.radius;
        }
        // |r_perp|^2 - R^2 = |y_perp + R e|^2 - R^2 = |y_perp|^2 + 2 R y . e (e normal to a)
        let y = x - self.near;
        let y_perp = y - y.dot(&self.axis) * self.axis;
        y_perp.norm_squared() + 2.0 * self.radius * y.dot(&self.normal)
    }

    fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64> {
        2.0 * self.r_perp(x)
    }

    fn hessian(&self, _x: &Vector3<f64>) -> Matrix3<f64> {
        2.0 * (Matrix3::identity() - self.axis * self.axis.transpose())
    }

    fn length_scale(&self) -> f64 {
        self.radius
    }

    fn describe(&self) -> String {
        format!(
            "cylinder R = {}, axis {} through {}",
            self.radius,
            fmt_vec(&self.axis),
            fmt_vec(&self.point)
        )
    }
}

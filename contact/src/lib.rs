//! # stamp-contact — rigid punch shapes
//!
//! Implementations of [`stamp::surface::ContactSurface`] for the punches of the paper: a
//! [`Cylinder`] (eq. 3.6), a [`Sphere`], a [`Plane`], an [`Expression`] (Psi written by the user
//! in x1, x2, x3, differentiated exactly by forward-mode automatic differentiation) and a die of any
//! shape given as a triangulated surface ([`StlSurface`], read from an STL file). Each surface is an implicit function
//! Psi(x) that is negative inside the punch, zero on its surface and positive outside, with its
//! analytic gradient and Hessian.
//!
//! Every surface is defined at its own fixed position: the framework applies the prescribed punch
//! motion d by evaluating Psi(x - d). Constructors validate their input and return
//! [`StampError::Problem`] instead of panicking.

mod cylinder;
mod expression;
pub mod expression_parser;
pub mod jet;
mod plane;
mod sphere;
pub mod stl;
#[cfg(test)]
mod test_rng;

pub use cylinder::Cylinder;
pub use expression::Expression;
pub use plane::Plane;
pub use sphere::Sphere;
pub use stl::StlSurface;

use nalgebra::Vector3;
use stamp::{Result, StampError};

/// Checks that every component of `v` is finite; `what` names the argument in the error.
fn check_finite_vector(shape: &str, what: &str, v: &Vector3<f64>) -> Result<()> {
    if v.iter().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(StampError::Problem(format!(
            "{shape}: the {what} must be finite, got ({}, {}, {})",
            v.x, v.y, v.z
        )))
    }
}

/// Checks that a radius is finite and strictly positive.
fn check_radius(shape: &str, radius: f64) -> Result<f64> {
    if radius.is_finite() && radius > 0.0 {
        Ok(radius)
    } else {
        Err(StampError::Problem(format!(
            "{shape}: the radius must be finite and positive, got {radius}"
        )))
    }
}

/// Checks that a scalar is finite.
fn check_finite_scalar(shape: &str, what: &str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(StampError::Problem(format!(
            "{shape}: the {what} must be finite, got {value}"
        )))
    }
}

/// Returns `v` normalised to unit length; rejects non-finite and zero vectors. The vector is first
/// scaled by its largest component so that tiny or huge (but finite) inputs normalise without
/// underflow or overflow.
fn unit_direction(shape: &str, what: &str, v: &Vector3<f64>) -> Result<Vector3<f64>> {
    check_finite_vector(shape, what, v)?;
    let m = v.amax();
    if m == 0.0 {
        return Err(StampError::Problem(format!(
            "{shape}: the {what} must not be the zero vector"
        )));
    }
    Ok((v / m).normalize())
}

/// Formats a point as "(x, y, z)" for [`describe`](stamp::surface::ContactSurface::describe).
fn fmt_vec(v: &Vector3<f64>) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

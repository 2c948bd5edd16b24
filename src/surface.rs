//! The rigid punch as an implicit surface (paper eqs. 3.2-3.3): Psi(x) = 0 on the surface,
//! Psi < 0 inside the punch, Psi > 0 outside. A new punch shape is one implementation of
//! [`ContactSurface`]; the contact constraint (module `contact`) needs nothing else.

use nalgebra::{Matrix3, Vector3};

/// An implicitly defined rigid surface Psi(x) >= 0 with its gradient and Hessian, in the punch's
/// own position (the contact constraint applies the prescribed punch motion).
///
/// Only [`psi`](ContactSurface::psi) and [`gradient`](ContactSurface::gradient) are required. The
/// Hessian enters the contact tangent through lambda * d(grad Psi)/dv (paper eq. 4.13); its default
/// is a central difference of the analytic gradient, accurate to about 1e-9 relative for smooth
/// surfaces, which keeps Newton's convergence quadratic in practice. Override it when an analytic
/// Hessian is available.
pub trait ContactSurface: Send + Sync {
    /// Psi(x): negative inside the punch, zero on its surface, positive outside.
    fn psi(&self, x: &Vector3<f64>) -> f64;

    /// The gradient of Psi at x.
    fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64>;

    /// Psi and its gradient at x together, as the contact constraint asks for them at every
    /// point. Default: [`psi`](Self::psi) and [`gradient`](Self::gradient); override it when the
    /// two share their work (an expression's one evaluation, a die's one closest-facet search).
    fn psi_and_gradient(&self, x: &Vector3<f64>) -> (f64, Vector3<f64>) {
        (self.psi(x), self.gradient(x))
    }

    /// The Hessian of Psi at x. Default: central differences of [`gradient`](Self::gradient) with a
    /// step of 1e-5 of [`length_scale`](Self::length_scale), symmetrised.
    fn hessian(&self, x: &Vector3<f64>) -> Matrix3<f64> {
        finite_difference_hessian(self, x)
    }

    /// A length typical of the surface (its radius, say): sets the finite-difference step of the
    /// default Hessian and the scale of geometric tolerances.
    fn length_scale(&self) -> f64 {
        1.0
    }

    /// A short human-readable description ("sphere R = 50 at (0, 0, 51)").
    fn describe(&self) -> String {
        "user-defined surface".to_string()
    }

    /// Why an evaluation of Psi, its gradient or Hessian was not finite, if one was: a surface
    /// that can fail (an expression's sqrt of a negative number) returns NaN, which the contact
    /// code would treat as "no contact", and keeps the first failure here. The caller checks it
    /// after a solve (or a step) and stops with this message. Default: None (never fails).
    fn evaluation_error(&self) -> Option<String> {
        None
    }
}

/// Central-difference Hessian of a surface's analytic gradient, symmetrised. This is the default of
/// [`ContactSurface::hessian`], public so that tests can compare an analytic Hessian with it.
pub fn finite_difference_hessian<S: ContactSurface + ?Sized>(s: &S, x: &Vector3<f64>) -> Matrix3<f64> {
    let h = 1e-5 * s.length_scale().abs().max(x.amax() * 1e-3).max(f64::MIN_POSITIVE.sqrt());
    let mut m = Matrix3::zeros();
    for j in 0..3 {
        let mut xp = *x;
        let mut xm = *x;
        xp[j] += h;
        xm[j] -= h;
        let d = (s.gradient(&xp) - s.gradient(&xm)) / (2.0 * h);
        m.set_column(j, &d);
    }
    0.5 * (m + m.transpose())
}

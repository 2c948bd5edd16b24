//! Tests of the punch surfaces: analytic derivatives against finite differences, the default
//! (finite-difference) Hessian of a user surface, the sign convention and input validation.

use nalgebra::{Matrix3, Vector3};
use stamp::surface::{finite_difference_hessian, ContactSurface};
use stamp::StampError;
use stamp_contact::{Cylinder, Plane, Sphere};

/// A tiny deterministic linear congruential generator (Knuth's MMIX constants).
struct Lcg(u64);

impl Lcg {
    /// A uniform number in [0, 1).
    fn next_f64(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A uniform number in [lo, hi).
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }

    /// A point uniform in the cube centre ± half.
    fn point(&mut self, centre: &Vector3<f64>, half: f64) -> Vector3<f64> {
        centre
            + Vector3::new(
                self.uniform(-half, half),
                self.uniform(-half, half),
                self.uniform(-half, half),
            )
    }
}

/// Central finite differences of psi, with a step relative to the surface and the point.
fn fd_gradient(s: &dyn ContactSurface, x: &Vector3<f64>) -> Vector3<f64> {
    let h = 1e-5 * s.length_scale().max(x.amax());
    Vector3::from_fn(|j, _| {
        let mut xp = *x;
        let mut xm = *x;
        xp[j] += h;
        xm[j] -= h;
        (s.psi(&xp) - s.psi(&xm)) / (2.0 * h)
    })
}

/// |a - b| <= rel * max(|b|, floor) in the Frobenius norm, with a message naming what is compared.
fn assert_rel_vec(a: &Vector3<f64>, b: &Vector3<f64>, rel: f64, floor: f64, what: &str) {
    let err = (a - b).norm();
    let tol = rel * b.norm().max(floor);
    assert!(err <= tol, "{what}: |{a:?} - {b:?}| = {err:e} > {tol:e}");
}

/// Same as [`assert_rel_vec`] for matrices.
fn assert_rel_mat(a: &Matrix3<f64>, b: &Matrix3<f64>, rel: f64, floor: f64, what: &str) {
    let err = (a - b).norm();
    let tol = rel * b.norm().max(floor);
    assert!(err <= tol, "{what}: |{a} - {b}| = {err:e} > {tol:e}");
}

/// Checks the analytic gradient against central differences of psi (1e-7 relative) and the
/// analytic Hessian against `finite_difference_hessian` (1e-6 relative) at `n` random points in
/// the cube centre ± half.
fn check_derivatives(s: &dyn ContactSurface, centre: Vector3<f64>, half: f64, seed: u64, n: usize) {
    let mut rng = Lcg(seed);
    // The floor only matters where the exact value vanishes (the plane's Hessian, the gradient on
    // the axis): there the comparison becomes absolute at the scale of a typical value.
    let grad_floor = s.length_scale();
    for _ in 0..n {
        let x = rng.point(&centre, half);
        let what = format!("{} at {x:?}", s.describe());
        assert_rel_vec(
            &s.gradient(&x),
            &fd_gradient(s, &x),
            1e-7,
            grad_floor,
            &format!("gradient of {what}"),
        );
        assert_rel_mat(
            &s.hessian(&x),
            &finite_difference_hessian(s, &x),
            1e-6,
            1.0,
            &format!("Hessian of {what}"),
        );
    }
}

#[test]
fn cylinder_derivatives_match_finite_differences() {
    let tilted = Cylinder::new(Vector3::new(1.0, -2.0, 3.0), Vector3::new(0.3, -1.2, 0.7), 2.5).unwrap();
    check_derivatives(&tilted, Vector3::new(1.0, -2.0, 3.0), 5.0, 1, 20);
    let paper = Cylinder::along_x1_touching(0.0, 0.0, 50.0).unwrap();
    check_derivatives(&paper, Vector3::new(0.0, 0.0, 0.0), 20.0, 2, 20);
}

#[test]
fn sphere_derivatives_match_finite_differences() {
    let s = Sphere::new(Vector3::new(-0.5, 2.0, 1.5), 3.0).unwrap();
    check_derivatives(&s, Vector3::new(0.0, 0.0, 0.0), 6.0, 3, 20);
    let s = Sphere::touching_from_above(10.0, 5.0, 0.1, 50.0).unwrap();
    check_derivatives(&s, Vector3::new(10.0, 5.0, 0.0), 20.0, 4, 20);
}

#[test]
fn plane_derivatives_match_finite_differences() {
    let p = Plane::new(Vector3::new(1.0, 2.0, -1.0), Vector3::new(-0.4, 0.8, 2.0)).unwrap();
    check_derivatives(&p, Vector3::new(0.0, 0.0, 0.0), 5.0, 5, 20);
    check_derivatives(&Plane::below(-0.3).unwrap(), Vector3::zeros(), 2.0, 6, 10);
    check_derivatives(&Plane::above(0.7).unwrap(), Vector3::zeros(), 2.0, 7, 10);
}

/// The cylinder reproduces the paper's eq. 3.6, Psi = x2^2 + (x3 - R)^2 - R^2, for the axis along
/// x1 through (0, 0, R), and a non-unit axis is normalised.
#[test]
fn cylinder_matches_paper_eq_3_6() {
    let r = 7.0;
    let c = Cylinder::along_x1_touching(0.0, 0.0, r).unwrap();
    let c_scaled_axis = Cylinder::new(Vector3::new(3.0, 0.0, r), Vector3::new(-4.0, 0.0, 0.0), r).unwrap();
    assert!((c.axis().norm() - 1.0).abs() < 1e-15);
    assert!((c_scaled_axis.axis().norm() - 1.0).abs() < 1e-15);
    let mut rng = Lcg(11);
    for _ in 0..20 {
        let x = rng.point(&Vector3::zeros(), 10.0);
        let expected = x[1] * x[1] + (x[2] - r) * (x[2] - r) - r * r;
        for s in [&c, &c_scaled_axis] {
            assert!(
                (s.psi(&x) - expected).abs() <= 1e-12 * r * r,
                "{} at {x:?}",
                s.describe()
            );
        }
    }
}

/// A user surface implementing only psi and gradient: the ellipsoid
/// Psi = (x1/a)^2 + (x2/b)^2 + (x3/c)^2 - 1, Hessian diag(2/a^2, 2/b^2, 2/c^2).
struct Ellipsoid {
    semi_axes: Vector3<f64>,
}

impl ContactSurface for Ellipsoid {
    fn psi(&self, x: &Vector3<f64>) -> f64 {
        x.component_div(&self.semi_axes).norm_squared() - 1.0
    }
    fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64> {
        2.0 * x.component_div(&self.semi_axes.component_mul(&self.semi_axes))
    }
}

/// A user surface whose gradient is not linear, so the default Hessian has a truncation error:
/// the torus Psi = (|x|^2 + R^2 - r^2)^2 - 4 R^2 (x1^2 + x2^2).
struct Torus {
    big: f64,
    small: f64,
}

impl Torus {
    fn s(&self, x: &Vector3<f64>) -> f64 {
        x.norm_squared() + self.big * self.big - self.small * self.small
    }
    fn analytic_hessian(&self, x: &Vector3<f64>) -> Matrix3<f64> {
        8.0 * x * x.transpose() + 4.0 * self.s(x) * Matrix3::identity()
            - Matrix3::from_diagonal(&Vector3::new(8.0, 8.0, 0.0)) * self.big * self.big
    }
}

impl ContactSurface for Torus {
    fn psi(&self, x: &Vector3<f64>) -> f64 {
        let s = self.s(x);
        s * s - 4.0 * self.big * self.big * (x[0] * x[0] + x[1] * x[1])
    }
    fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64> {
        4.0 * self.s(x) * x - 8.0 * self.big * self.big * Vector3::new(x[0], x[1], 0.0)
    }
    fn length_scale(&self) -> f64 {
        self.big
    }
}

#[test]
fn default_hessian_of_user_surface_matches_analytic() {
    let e = Ellipsoid {
        semi_axes: Vector3::new(3.0, 2.0, 0.5),
    };
    let expected = Matrix3::from_diagonal(&Vector3::new(2.0 / 9.0, 2.0 / 4.0, 2.0 / 0.25));
    let t = Torus { big: 4.0, small: 1.5 };
    let mut rng = Lcg(21);
    for _ in 0..20 {
        let x = rng.point(&Vector3::zeros(), 4.0);
        assert_rel_mat(
            &e.hessian(&x),
            &expected,
            1e-6,
            0.0,
            &format!("default Hessian of the ellipsoid at {x:?}"),
        );
        assert_rel_mat(
            &t.hessian(&x),
            &t.analytic_hessian(&x),
            1e-6,
            0.0,
            &format!("default Hessian of the torus at {x:?}"),
        );
    }
    // The gradients themselves, so that a wrong analytic formula above cannot hide a wrong test.
    for _ in 0..10 {
        let x = rng.point(&Vector3::zeros(), 4.0);
        assert_rel_vec(
            &e.gradient(&x),
            &fd_gradient(&e, &x),
            1e-7,
            1.0,
            "ellipsoid gradient",
        );
        assert_rel_vec(&t.gradient(&x), &fd_gradient(&t, &x), 1e-7, 1.0, "torus gradient");
    }
}

/// Inside < 0, outside > 0, on the surface ~ 0 (relative to R^2, the scale of psi).
fn check_signs(
    s: &dyn ContactSurface,
    inside: &[Vector3<f64>],
    outside: &[Vector3<f64>],
    on: &[Vector3<f64>],
) {
    let scale = s.length_scale() * s.length_scale();
    for x in inside {
        assert!(
            s.psi(x) < 0.0,
            "{} should be inside {}, psi = {}",
            x,
            s.describe(),
            s.psi(x)
        );
    }
    for x in outside {
        assert!(
            s.psi(x) > 0.0,
            "{} should be outside {}, psi = {}",
            x,
            s.describe(),
            s.psi(x)
        );
    }
    for x in on {
        assert!(
            s.psi(x).abs() <= 1e-12 * scale,
            "{} should be on {}, psi = {}",
            x,
            s.describe(),
            s.psi(x)
        );
    }
}

#[test]
fn cylinder_sign_convention() {
    let r = 2.0;
    let p = Vector3::new(1.0, 1.0, 1.0);
    let a = Vector3::new(1.0, 2.0, 2.0) / 3.0;
    let c = Cylinder::new(p, 3.0 * a, r).unwrap();
    // Two unit vectors perpendicular to the axis.
    let e1 = Vector3::new(2.0, -1.0, 0.0).normalize();
    let e2 = a.cross(&e1);
    let along = |t: f64, u: f64, v: f64| p + t * a + u * e1 + v * e2;
    check_signs(
        &c,
        &[
            p,
            along(10.0, 0.0, 0.0),
            along(-5.0, 1.9, 0.0),
            along(3.0, 1.0, -1.0),
        ],
        &[along(0.0, 2.1, 0.0), along(-7.0, 0.0, -3.0), along(2.0, 1.5, 1.5)],
        &[
            along(0.0, r, 0.0),
            along(4.0, 0.0, -r),
            along(-1.0, r * 0.6, r * 0.8),
        ],
    );
}

#[test]
fn cylinder_touching_plane_from_above() {
    let c = Cylinder::along_x1_touching(0.0, 0.0, 50.0).unwrap();
    assert_eq!(c.psi(&Vector3::new(0.0, 0.0, 0.0)), 0.0);
    assert_eq!(c.psi(&Vector3::new(123.0, 0.0, 0.0)), 0.0);
    for x2 in [-10.0, -0.1, 1e-3, 0.5, 30.0] {
        let x = Vector3::new(0.0, x2, 0.0);
        assert!(c.psi(&x) > 0.0, "psi{x:?} = {}", c.psi(&x));
        assert!((c.psi(&x) - x2 * x2).abs() <= 1e-12 * 2500.0);
    }
    // Below the contact line is outside, just above it is inside the punch.
    assert!(c.psi(&Vector3::new(0.0, 0.0, -0.01)) > 0.0);
    assert!(c.psi(&Vector3::new(0.0, 0.0, 0.01)) < 0.0);
    // Shifted contact line and plane.
    let c = Cylinder::along_x1_touching(3.0, -1.0, 5.0).unwrap();
    assert_eq!(c.psi(&Vector3::new(-2.0, 3.0, -1.0)), 0.0);
    assert!(c.psi(&Vector3::new(-2.0, 3.5, -1.0)) > 0.0);
    assert!(c.psi(&Vector3::new(-2.0, 3.0, -0.9)) < 0.0);
}

#[test]
fn sphere_sign_convention() {
    let s = Sphere::touching_from_above(1.0, -2.0, 0.5, 3.0).unwrap();
    let c = Vector3::new(1.0, -2.0, 3.5);
    assert_eq!(s.center(), c);
    check_signs(
        &s,
        &[c, c + Vector3::new(2.9, 0.0, 0.0), Vector3::new(1.0, -2.0, 0.6)],
        &[
            Vector3::new(1.0, -2.0, 0.4),
            Vector3::new(1.5, -2.0, 0.5),
            c + Vector3::new(2.0, 2.0, 2.0),
        ],
        &[
            Vector3::new(1.0, -2.0, 0.5),
            c + Vector3::new(0.0, -3.0, 0.0),
            c + Vector3::new(1.8, 0.0, 2.4),
        ],
    );
}

#[test]
fn plane_sign_convention() {
    let floor = Plane::below(0.25).unwrap();
    check_signs(
        &floor,
        &[Vector3::new(3.0, -4.0, 0.2), Vector3::new(0.0, 0.0, -10.0)],
        &[Vector3::new(3.0, -4.0, 0.3), Vector3::new(0.0, 0.0, 10.0)],
        &[Vector3::new(7.0, 8.0, 0.25)],
    );
    assert_eq!(floor.psi(&Vector3::new(1.0, 2.0, 3.0)), 3.0 - 0.25);
    let ceiling = Plane::above(0.25).unwrap();
    check_signs(
        &ceiling,
        &[Vector3::new(3.0, -4.0, 0.3), Vector3::new(0.0, 0.0, 10.0)],
        &[Vector3::new(3.0, -4.0, 0.2), Vector3::new(0.0, 0.0, -10.0)],
        &[Vector3::new(7.0, 8.0, 0.25)],
    );
    assert_eq!(ceiling.psi(&Vector3::new(1.0, 2.0, 3.0)), 0.25 - 3.0);
    // A tilted plane: the normal points out of the rigid side and is normalised.
    let p = Plane::new(Vector3::new(1.0, 0.0, 0.0), Vector3::new(3.0, 0.0, 4.0)).unwrap();
    assert!((p.normal() - Vector3::new(0.6, 0.0, 0.8)).norm() < 1e-15);
    check_signs(
        &p,
        &[Vector3::new(0.0, 5.0, 0.0)],
        &[Vector3::new(2.0, -5.0, 0.0)],
        &[Vector3::new(1.0 + 4.0, 9.0, -3.0)],
    );
    assert!((p.psi(&Vector3::new(1.0 + 0.6, 0.0, 0.8)) - 1.0).abs() < 1e-15);
}

/// The result is a `StampError::Problem` whose message mentions `needle`.
fn assert_problem<T: std::fmt::Debug>(r: stamp::Result<T>, needle: &str) {
    match r {
        Err(StampError::Problem(msg)) => assert!(msg.contains(needle), "message {msg:?} lacks {needle:?}"),
        other => panic!("expected StampError::Problem mentioning {needle:?}, got {other:?}"),
    }
}

#[test]
fn constructors_reject_bad_input() {
    let o = Vector3::zeros();
    let x = Vector3::x();
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    for r in [0.0, -1.0, nan, inf, -inf, -0.0] {
        assert_problem(Cylinder::new(o, x, r), "radius");
        assert_problem(Cylinder::along_x1_touching(0.0, 0.0, r), "radius");
        assert_problem(Sphere::new(o, r), "radius");
        assert_problem(Sphere::touching_from_above(0.0, 0.0, 0.0, r), "radius");
    }
    assert_problem(Cylinder::new(o, Vector3::zeros(), 1.0), "zero");
    assert_problem(Cylinder::new(o, Vector3::new(nan, 1.0, 0.0), 1.0), "finite");
    assert_problem(Cylinder::new(Vector3::new(0.0, inf, 0.0), x, 1.0), "finite");
    assert_problem(Cylinder::along_x1_touching(nan, 0.0, 1.0), "finite");
    assert_problem(Cylinder::along_x1_touching(0.0, inf, 1.0), "finite");
    assert_problem(Sphere::new(Vector3::new(nan, 0.0, 0.0), 1.0), "finite");
    assert_problem(Sphere::touching_from_above(0.0, inf, 0.0, 1.0), "finite");
    assert_problem(Sphere::touching_from_above(0.0, 0.0, nan, 1.0), "finite");
    assert_problem(Plane::new(o, Vector3::zeros()), "zero");
    assert_problem(Plane::new(o, Vector3::new(0.0, 0.0, nan)), "finite");
    assert_problem(Plane::new(Vector3::new(-inf, 0.0, 0.0), x), "finite");
    assert_problem(Plane::below(nan), "finite");
    assert_problem(Plane::above(inf), "finite");
    // Valid extremes are accepted: tiny and huge (finite) directions normalise cleanly.
    let c = Cylinder::new(o, Vector3::new(1e-200, 0.0, 1e-200), 1.0).unwrap();
    assert!((c.axis().norm() - 1.0).abs() < 1e-15);
    let p = Plane::new(o, Vector3::new(1e300, 1e300, 0.0)).unwrap();
    assert!((p.normal().norm() - 1.0).abs() < 1e-15);
}

#[test]
fn length_scale_and_describe() {
    let c = Cylinder::along_x1_touching(0.0, 0.0, 50.0).unwrap();
    let s = Sphere::touching_from_above(0.0, 0.0, 1.0, 50.0).unwrap();
    let p = Plane::below(0.0).unwrap();
    assert_eq!(c.length_scale(), 50.0);
    assert_eq!(s.length_scale(), 50.0);
    assert_eq!(p.length_scale(), 1.0);
    assert_eq!(c.describe(), "cylinder R = 50, axis (1, 0, 0) through (0, 0, 50)");
    assert_eq!(s.describe(), "sphere R = 50 at (0, 0, 51)");
    assert!(p.describe().contains("(0, 0, 1)"), "{}", p.describe());
    // The shapes are usable as trait objects, as the framework stores them.
    let all: Vec<Box<dyn ContactSurface>> = vec![Box::new(c), Box::new(s), Box::new(p)];
    assert_eq!(all.len(), 3);
}

/// Near the point that touches the plate, Psi is exact where |x - c|^2 - R^2 loses the low bits
/// of |x - c|^2 ~ R^2: at x = (0.25, 0.5, 0.5 - 2^-20) under a sphere of radius 200 touching
/// x3 = 0.5 (and a cylinder of radius 100 along x1), Psi = 0.3125 + 2 R 2^-20 + 2^-40 exactly
/// (every number here is a float); the plain form is off by 9e-13 there (its 2^-40 is lost in
/// |x - c|^2 = 40000.3...). Above and below the plate, far from the pole, the two forms agree.
#[test]
fn psi_is_exact_near_the_touching_point_of_a_large_sphere_or_cylinder() {
    let tiny = 2f64.powi(-20);
    let sphere = Sphere::new(Vector3::new(0.0, 0.0, 200.5), 200.0).unwrap();
    let x = Vector3::new(0.25, 0.5, 0.5 - tiny);
    let exact = 0.3125 + 400.0 * tiny + tiny * tiny;
    assert_eq!(sphere.psi(&x), exact, "sphere: Psi near the pole");
    let plain = (x - sphere.center()).norm_squared() - 200.0 * 200.0;
    assert!((plain - exact).abs() > 1e-13, "the plain form was exact here too ({plain} against {exact}): the test shows nothing");
    let cylinder = Cylinder::along_x1_touching(0.0, 0.5, 100.0).unwrap();
    let x = Vector3::new(3.0, 0.25, 0.5 - tiny);
    assert_eq!(cylinder.psi(&x), 0.0625 + 200.0 * tiny + tiny * tiny, "cylinder: Psi near its touching line");
    // the same function everywhere: a sphere below the plate, points far from the pole, an
    // oblique cylinder, and a vertical one (the plain form)
    let below = Sphere::new(Vector3::new(1.0, -2.0, -30.0), 29.0).unwrap();
    let oblique = Cylinder::new(Vector3::new(1.0, 2.0, 40.0), Vector3::new(1.0, 1.0, 0.3), 39.0).unwrap();
    let vertical = Cylinder::new(Vector3::new(1.0, 2.0, 40.0), Vector3::new(0.1, 0.0, 1.0), 3.0).unwrap();
    let mut rng = Lcg(7);
    for _ in 0..200 {
        let x = Vector3::new(rng.uniform(-60.0, 60.0), rng.uniform(-60.0, 60.0), rng.uniform(-60.0, 60.0));
        let d = x - below.center();
        let want = d.norm_squared() - 29.0 * 29.0;
        assert!((below.psi(&x) - want).abs() <= 1e-12 * d.norm_squared(), "sphere below at {x:?}");
        for (c, r) in [(&oblique, 39.0), (&vertical, 3.0)] {
            let rv = x - c.point();
            let perp = rv - rv.dot(&c.axis()) * c.axis();
            let want = perp.norm_squared() - r * r;
            assert!((c.psi(&x) - want).abs() <= 1e-11 * (rv.norm_squared() + r * r), "cylinder of radius {r} at {x:?}: {} against {want}", c.psi(&x));
        }
    }
}

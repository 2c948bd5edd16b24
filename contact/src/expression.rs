//! A punch whose Psi is written as an expression in x1, x2, x3 (`shape = "expression"` in a
//! problem file): parsed once by [`crate::expression_parser`], evaluated with second-order
//! forward-mode automatic differentiation ([`crate::jet::Jet`]), so the gradient and Hessian are
//! exact, never finite differences.
//!
//! [`ContactSurface`] cannot return an error, so a non-finite evaluation (the square root or
//! logarithm of a negative number, a division by zero) returns NaN and is recorded: the first one
//! is kept with its point and [`ContactSurface::evaluation_error`] reports it, so that the caller
//! stops with a clear message instead of computing on.

use crate::expression_parser::{self, BinOp, Func, Node, ParseError};
use crate::jet::Jet;
use nalgebra::{Matrix3, Vector3};
use stamp::surface::ContactSurface;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;

/// A rigid punch Psi(x) = the user's expression.
#[derive(Debug)]
pub struct Expression {
    text: String,
    root: Node,
    length_scale: f64,
    failed: AtomicBool,
    first_failure: Mutex<Option<String>>,
}

impl Expression {
    /// Parses `text`; `length_scale` is a length typical of the surface (the size of the model
    /// will do: it sets geometric tolerances, see [`ContactSurface::length_scale`]).
    pub fn new(text: &str, length_scale: f64) -> Result<Expression, ParseError> {
        let root = expression_parser::parse(text)?;
        let length_scale = if length_scale.is_finite() && length_scale > 0.0 { length_scale } else { 1.0 };
        Ok(Expression { text: text.to_string(), root, length_scale, failed: AtomicBool::new(false), first_failure: Mutex::new(None) })
    }

    /// The expression as written.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Psi with its exact gradient and Hessian at x. A non-finite result is recorded (see the
    /// module's documentation) and returned as is.
    pub fn jet(&self, x: &Vector3<f64>) -> Jet {
        let vars = [Jet::variable(0, x.x), Jet::variable(1, x.y), Jet::variable(2, x.z)];
        let j = eval(&self.root, &vars);
        if !(j.v.is_finite() && j.g.iter().all(|c| c.is_finite()) && j.h.iter().flatten().all(|c| c.is_finite())) {
            self.record_failure(x, &j);
        }
        j
    }

    /// Psi at x: the same evaluation as [`jet`](Self::jet), checked the same way.
    pub fn value(&self, x: &Vector3<f64>) -> f64 {
        self.jet(x).v
    }

    fn record_failure(&self, x: &Vector3<f64>, j: &Jet) {
        if self.failed.swap(true, Ordering::Relaxed) {
            return;
        }
        let what = if !j.v.is_finite() {
            format!("psi is {}", j.v)
        } else if !j.g.iter().all(|c| c.is_finite()) {
            "its gradient is not finite".to_string()
        } else {
            "its Hessian is not finite".to_string()
        };
        let message = format!(
            "{what} at x = ({}, {}, {}) (a square root or logarithm of a negative number, a division by zero, or a kink such as sqrt at 0?); psi must be finite and smooth where the plate may touch the punch",
            x.x, x.y, x.z
        );
        if let Ok(mut slot) = self.first_failure.lock() {
            slot.get_or_insert(message);
        }
    }
}

/// Evaluates a node on jets.
fn eval(node: &Node, vars: &[Jet; 3]) -> Jet {
    match node {
        Node::Const(v) => Jet::constant(*v),
        Node::Var(i) => vars[*i],
        Node::Neg(a) => eval(a, vars).neg(),
        Node::Bin(op, a, b) => {
            let (a, b) = (eval(a, vars), eval(b, vars));
            match op {
                BinOp::Add => a.add(&b),
                BinOp::Sub => a.sub(&b),
                BinOp::Mul => a.mul(&b),
                BinOp::Div => a.div(&b),
                BinOp::Pow => a.pow(&b),
            }
        }
        Node::Call(f, args) => {
            let a = eval(&args[0], vars);
            let b = || eval(&args[1], vars);
            match f {
                Func::Sqrt => a.sqrt(),
                Func::Sin => a.sin(),
                Func::Cos => a.cos(),
                Func::Tan => a.tan(),
                Func::Exp => a.exp(),
                Func::Ln => a.ln(),
                Func::Abs => a.abs(),
                Func::Min => a.min(&b()),
                Func::Max => a.max(&b()),
                Func::Pow => a.pow(&b()),
                Func::Atan2 => a.atan2(&b()),
                Func::Hypot => a.hypot(&b()),
            }
        }
    }
}

impl ContactSurface for Expression {
    fn psi(&self, x: &Vector3<f64>) -> f64 {
        self.value(x)
    }

    fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64> {
        Vector3::from(self.jet(x).g)
    }

    fn psi_and_gradient(&self, x: &Vector3<f64>) -> (f64, Vector3<f64>) {
        let j = self.jet(x);
        (j.v, Vector3::from(j.g))
    }

    fn hessian(&self, x: &Vector3<f64>) -> Matrix3<f64> {
        let h = self.jet(x).h;
        Matrix3::from_fn(|i, j| h[i][j])
    }

    fn length_scale(&self) -> f64 {
        self.length_scale
    }

    fn describe(&self) -> String {
        format!("expression psi = {}", stamp::quote(&self.text))
    }

    fn evaluation_error(&self) -> Option<String> {
        if !self.failed.load(Ordering::Relaxed) {
            return None;
        }
        self.first_failure.lock().ok().and_then(|s| s.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Sphere;

    /// A tiny deterministic generator (xorshift) for random expressions and points.
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            self.0
        }
        fn unit(&mut self) -> f64 {
            (self.next() >> 11) as f64 / (1u64 << 53) as f64
        }
        fn pick(&mut self, n: usize) -> usize {
            (self.next() % n as u64) as usize
        }
    }

    /// A random smooth expression, defined (finite, differentiable) for x in [-1, 1]^3.
    fn random_expression(r: &mut Rng, depth: usize) -> String {
        if depth == 0 || r.pick(4) == 0 {
            return match r.pick(4) {
                0 => format!("{:.3}", r.unit() * 2.0 - 1.0),
                k => format!("x{k}"),
            };
        }
        let a = random_expression(r, depth - 1);
        let b = random_expression(r, depth - 1);
        match r.pick(17) {
            0 => format!("({a} + {b})"),
            1 => format!("({a} - {b})"),
            2 => format!("({a} * {b})"),
            3 => format!("({a} / (2 + sin({b})))"),
            4 => format!("({a})^2"),
            5 => format!("({a})^3"),
            6 => format!("sqrt(1 + ({a})^2)"),
            7 => format!("sin({a})"),
            8 => format!("cos({a})"),
            9 => format!("tan(0.3 * sin({a}))"),
            10 => format!("exp(0.5 * sin({a}))"),
            11 => format!("ln(2 + cos({a}))"),
            12 => format!("pow(1.5 + sin({a}), {b} / (3 + abs({b})))"),
            13 => format!("atan2({a}, 3 + cos({b}))"),
            14 => format!("hypot(1 + ({a})^2, {b})"),
            15 => format!("-{a} * e / pi"),
            _ => format!("(1.5 + sin({a}))^(cos({b}))"),
        }
    }

    #[test]
    fn derivatives_of_random_expressions_match_central_differences() {
        let mut r = Rng(0x9e3779b97f4a7c15);
        let mut checked = 0;
        for _ in 0..300 {
            let text = random_expression(&mut r, 4);
            let e = Expression::new(&text, 1.0).unwrap_or_else(|err| panic!("{text}: {err}"));
            let x = Vector3::new(r.unit() * 2.0 - 1.0, r.unit() * 2.0 - 1.0, r.unit() * 2.0 - 1.0);
            let j = e.jet(&x);
            assert!(e.evaluation_error().is_none(), "{text} at {x:?}: {:?}", e.evaluation_error());
            let h = 1e-5;
            for k in 0..3 {
                let mut xp = x;
                let mut xm = x;
                xp[k] += h;
                xm[k] -= h;
                let (jp, jm) = (e.jet(&xp), e.jet(&xm));
                let fd = (jp.v - jm.v) / (2.0 * h);
                let scale = 1.0 + j.g[k].abs() + j.v.abs();
                assert!((fd - j.g[k]).abs() <= 1e-6 * scale, "{text}: d/dx{} = {} against {fd}", k + 1, j.g[k]);
                for i in 0..3 {
                    let fd = (jp.g[i] - jm.g[i]) / (2.0 * h);
                    let scale = 1.0 + j.h[i][k].abs() + j.g[i].abs();
                    assert!((fd - j.h[i][k]).abs() <= 1e-5 * scale, "{text}: H[{i}][{k}] = {} against {fd}", j.h[i][k]);
                }
            }
            // the Hessian is symmetric
            for i in 0..3 {
                for k in 0..3 {
                    assert!((j.h[i][k] - j.h[k][i]).abs() <= 1e-12 * (1.0 + j.h[i][k].abs()), "{text}: H not symmetric");
                }
            }
            checked += 1;
        }
        assert_eq!(checked, 300);
    }

    #[test]
    fn the_sphere_as_an_expression_is_the_built_in_sphere() {
        let e = Expression::new("(x1)^2 + (x2)^2 + (x3 - 200.5)^2 - 200^2", 200.0).unwrap();
        let s = Sphere::new(Vector3::new(0.0, 0.0, 200.5), 200.0).unwrap();
        for x in [Vector3::new(0.0, 0.0, 0.5), Vector3::new(3.0, -7.0, 0.2), Vector3::new(-150.0, 20.0, 400.0)] {
            let (a, b) = (e.psi(&x), s.psi(&x));
            assert!((a - b).abs() <= 1e-12 * b.abs().max(1.0), "{a} against {b}");
            assert!((e.gradient(&x) - s.gradient(&x)).norm() <= 1e-12 * s.gradient(&x).norm());
            assert_eq!(e.hessian(&x), s.hessian(&x));
            // psi and the gradient asked together are those asked one by one
            assert_eq!(e.psi_and_gradient(&x), (e.psi(&x), e.gradient(&x)));
        }
    }

    #[test]
    fn functions_and_constants_have_their_values() {
        let at = |t: &str| Expression::new(t, 1.0).unwrap().psi(&Vector3::new(0.5, -2.0, 3.0));
        assert_eq!(at("x1 + 10 * x2 + 100 * x3"), 0.5 - 20.0 + 300.0);
        assert_eq!(at("pi"), std::f64::consts::PI);
        assert_eq!(at("ln(e)"), 1.0);
        assert_eq!(at("log(x3)"), 3f64.ln());
        assert_eq!(at("min(x1, x2) + max(x1, x3)"), -2.0 + 3.0);
        assert_eq!(at("hypot(3, 4)"), 5.0);
        assert_eq!(at("atan2(x2, x1)"), (-2f64).atan2(0.5));
        assert_eq!(at("abs(x2)"), 2.0);
        assert_eq!(at("x2^2"), 4.0);
        assert_eq!(at("x2^3"), -8.0);
        assert_eq!(at("pow(x3, 0.5)"), 3f64.sqrt());
        assert_eq!(at("2^-1"), 0.5);
        assert_eq!(at("-x2^2"), -4.0);
    }

    #[test]
    fn a_non_finite_evaluation_is_recorded_with_its_point() {
        let e = Expression::new("sqrt(x1) - 1", 1.0).unwrap();
        assert!(e.psi(&Vector3::new(4.0, 0.0, 0.0)).is_finite());
        assert_eq!(e.evaluation_error(), None);
        assert!(e.psi(&Vector3::new(-1.0, 0.0, 0.0)).is_nan());
        let m = e.evaluation_error().expect("recorded");
        assert!(m.contains("psi is NaN at x = (-1, 0, 0)"), "{m}");
        // the first failure is kept
        let _ = e.psi(&Vector3::new(-2.0, 0.0, 0.0));
        assert!(e.evaluation_error().unwrap().contains("(-1, 0, 0)"));
        // a finite value whose derivative is not (sqrt at 0) is reported too
        let e = Expression::new("sqrt(x1) + x2", 1.0).unwrap();
        let _ = e.gradient(&Vector3::zeros());
        assert!(e.evaluation_error().unwrap().contains("gradient is not finite"));
    }
}

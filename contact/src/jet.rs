//! Second-order forward-mode automatic differentiation in three variables: a [`Jet`] carries a
//! value with its exact gradient and Hessian, and every operation applies the chain rule to second
//! order. Used by [`crate::Expression`] to differentiate a user's Psi without finite differences.

/// A value f(x) with its gradient df/dx_i and Hessian d2f/dx_i dx_j, x in R^3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jet {
    pub v: f64,
    pub g: [f64; 3],
    pub h: [[f64; 3]; 3],
}

impl Jet {
    /// A constant: zero gradient and Hessian.
    pub fn constant(v: f64) -> Jet {
        Jet { v, g: [0.0; 3], h: [[0.0; 3]; 3] }
    }

    /// The coordinate x_i (0-based) at value v: gradient e_i, Hessian 0.
    pub fn variable(i: usize, v: f64) -> Jet {
        let mut g = [0.0; 3];
        g[i] = 1.0;
        Jet { v, g, h: [[0.0; 3]; 3] }
    }

    /// True when the gradient and Hessian are zero (a constant subexpression).
    pub fn is_constant(&self) -> bool {
        self.g.iter().all(|&c| c == 0.0) && self.h.iter().flatten().all(|&c| c == 0.0)
    }

    /// f(self) for a scalar function with value `f`, first derivative `d1` and second `d2` at
    /// self.v: gradient d1 g, Hessian d1 H + d2 g g^T.
    pub fn chain(&self, f: f64, d1: f64, d2: f64) -> Jet {
        let mut out = Jet::constant(f);
        for i in 0..3 {
            out.g[i] = term(d1, self.g[i]);
            for j in 0..3 {
                out.h[i][j] = term(d1, self.h[i][j]) + term(d2, self.g[i] * self.g[j]);
            }
        }
        out
    }

    /// f(a, b) from its value `f`, first partials (fa, fb) and second partials (faa, fab, fbb).
    #[allow(clippy::too_many_arguments)]
    pub fn chain2(a: &Jet, b: &Jet, f: f64, fa: f64, fb: f64, faa: f64, fab: f64, fbb: f64) -> Jet {
        let mut out = Jet::constant(f);
        for i in 0..3 {
            out.g[i] = term(fa, a.g[i]) + term(fb, b.g[i]);
            for j in 0..3 {
                // zero partials times zero derivatives must stay zero even if a partial is infinite
                let mut h = term(fa, a.h[i][j]) + term(fb, b.h[i][j]);
                h += term(faa, a.g[i] * a.g[j]) + term(fbb, b.g[i] * b.g[j]);
                h += term(fab, a.g[i] * b.g[j] + b.g[i] * a.g[j]);
                out.h[i][j] = h;
            }
        }
        out
    }

    pub fn add(&self, b: &Jet) -> Jet {
        Jet::chain2(self, b, self.v + b.v, 1.0, 1.0, 0.0, 0.0, 0.0)
    }

    pub fn sub(&self, b: &Jet) -> Jet {
        Jet::chain2(self, b, self.v - b.v, 1.0, -1.0, 0.0, 0.0, 0.0)
    }

    pub fn neg(&self) -> Jet {
        self.chain(-self.v, -1.0, 0.0)
    }

    pub fn mul(&self, b: &Jet) -> Jet {
        Jet::chain2(self, b, self.v * b.v, b.v, self.v, 0.0, 1.0, 0.0)
    }

    pub fn div(&self, b: &Jet) -> Jet {
        let (a, c) = (self.v, b.v);
        Jet::chain2(self, b, a / c, 1.0 / c, -a / (c * c), 0.0, -1.0 / (c * c), 2.0 * a / (c * c * c))
    }

    /// self^b: a constant exponent uses the power rule (any sign of the base for integer powers);
    /// a variable one is exp(b ln self).
    pub fn pow(&self, b: &Jet) -> Jet {
        let (a, c) = (self.v, b.v);
        if b.is_constant() {
            if c == 0.0 {
                return Jet::constant(1.0);
            }
            if c == 1.0 {
                return *self;
            }
            let d2 = if c == 2.0 { 2.0 } else { c * (c - 1.0) * a.powf(c - 2.0) };
            return self.chain(a.powf(c), c * a.powf(c - 1.0), d2);
        }
        let f = a.powf(c);
        let l = a.ln();
        Jet::chain2(self, b, f, c * a.powf(c - 1.0), f * l, c * (c - 1.0) * a.powf(c - 2.0), a.powf(c - 1.0) * (1.0 + c * l), f * l * l)
    }

    pub fn sqrt(&self) -> Jet {
        let s = self.v.sqrt();
        self.chain(s, 0.5 / s, -0.25 / (s * self.v))
    }

    pub fn sin(&self) -> Jet {
        let (s, c) = self.v.sin_cos();
        self.chain(s, c, -s)
    }

    pub fn cos(&self) -> Jet {
        let (s, c) = self.v.sin_cos();
        self.chain(c, -s, -c)
    }

    pub fn tan(&self) -> Jet {
        let t = self.v.tan();
        let d1 = 1.0 + t * t;
        self.chain(t, d1, 2.0 * t * d1)
    }

    pub fn exp(&self) -> Jet {
        let e = self.v.exp();
        self.chain(e, e, e)
    }

    pub fn ln(&self) -> Jet {
        let a = self.v;
        self.chain(a.ln(), 1.0 / a, -1.0 / (a * a))
    }

    /// |self|: derivative sign(v) (1 at +0), second derivative 0.
    pub fn abs(&self) -> Jet {
        self.chain(self.v.abs(), self.v.signum(), 0.0)
    }

    /// The smaller of the two with its derivatives (the first on a tie).
    pub fn min(&self, b: &Jet) -> Jet {
        if b.v < self.v {
            *b
        } else {
            *self
        }
    }

    /// The larger of the two with its derivatives (the first on a tie).
    pub fn max(&self, b: &Jet) -> Jet {
        if b.v > self.v {
            *b
        } else {
            *self
        }
    }

    /// atan2(self, b): the angle of the point (b, self).
    pub fn atan2(&self, b: &Jet) -> Jet {
        let (y, x) = (self.v, b.v);
        let r2 = x * x + y * y;
        let q = r2 * r2;
        Jet::chain2(self, b, y.atan2(x), x / r2, -y / r2, -2.0 * x * y / q, (y * y - x * x) / q, 2.0 * x * y / q)
    }

    /// sqrt(self^2 + b^2) without overflow.
    pub fn hypot(&self, b: &Jet) -> Jet {
        let (a, c) = (self.v, b.v);
        let r = a.hypot(c);
        let r3 = r * r * r;
        Jet::chain2(self, b, r, a / r, c / r, c * c / r3, -a * c / r3, a * a / r3)
    }
}

/// p * d, zero when d is zero whatever p is (an infinite partial of a constant argument).
fn term(p: f64, d: f64) -> f64 {
    if d == 0.0 {
        0.0
    } else {
        p * d
    }
}

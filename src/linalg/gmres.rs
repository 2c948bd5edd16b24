//! Restarted GMRES with right preconditioning (Saad & Schultz 1986; Saad, "Iterative methods for
//! sparse linear systems", algorithm 9.5): solves A x = b given y -> A y and z -> M^-1 z. Modified
//! Gram-Schmidt, Givens rotations; convergence is judged on the true residual b - A x at the end
//! of every cycle, not only on the recursive estimate, as a normwise backward error
//! |b - A x| / (|A| |x| + |b|) (2-norms, |A| an estimate given by the caller; 0 gives the
//! relative residual |b - A x| / |b|): a backward-stable direct solver reaches round-off in that
//! measure, whereas |b - A x| / |b| cannot go below eps cond(A) |x| |A| / |b|.

/// Outcome of a GMRES solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GmresReport {
    /// Matrix-vector products (= preconditioner applications in the Krylov loop).
    pub iterations: usize,
    /// |b - A x| / (|A| |x| + |b|) of the returned x.
    pub backward_error: f64,
    pub converged: bool,
}

/// Workspace of restarted GMRES(m) for systems of size n: the Krylov basis, its preconditioned
/// images and the Hessenberg matrix, kept between solves so that a solve allocates nothing once
/// the bases have grown to the iterations a solve needs (vectors are added as needed, up to m).
pub struct Gmres {
    restart: usize,
    basis: Vec<Vec<f64>>,
    /// z_k = M^-1 v_k, kept so that the update x += M^-1 V y needs no further preconditioner
    /// application (as in flexible GMRES, Saad 1993).
    preconditioned: Vec<Vec<f64>>,
    hessenberg: Vec<f64>,
    cs: Vec<f64>,
    sn: Vec<f64>,
    g: Vec<f64>,
    y: Vec<f64>,
    w: Vec<f64>,
    r: Vec<f64>,
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

impl Gmres {
    /// GMRES restarted every `restart` iterations.
    pub fn new(restart: usize) -> Self {
        let m = restart.max(1);
        Gmres {
            restart: m,
            basis: Vec::new(),
            preconditioned: Vec::new(),
            hessenberg: vec![0.0; (m + 1) * m],
            cs: vec![0.0; m],
            sn: vec![0.0; m],
            g: vec![0.0; m + 1],
            y: vec![0.0; m],
            w: Vec::new(),
            r: Vec::new(),
        }
    }

    fn h(&mut self, i: usize, j: usize) -> &mut f64 {
        &mut self.hessenberg[j * (self.restart + 1) + i]
    }

    /// Solve A x = b, x holding the initial guess on entry, until
    /// |b - A x| <= tol (a_norm |x| + |b|), or |b - A x| <= rtol |b| (an inexact solve, say for an
    /// inexact Newton method: 0 for none), or `max_iterations` products. `apply(y, out)`: out = A y; `precondition(z)`: z = M^-1 z in place
    /// (errors propagate).
    pub fn solve<E>(
        &mut self,
        b: &[f64],
        x: &mut [f64],
        tol: f64,
        rtol: f64,
        a_norm: f64,
        max_iterations: usize,
        apply: &mut dyn FnMut(&[f64], &mut [f64]),
        precondition: &mut dyn FnMut(&mut [f64]) -> Result<(), E>,
    ) -> Result<GmresReport, E> {
        let n = b.len();
        let m = self.restart;
        if self.w.len() != n {
            self.basis.clear();
            self.preconditioned.clear();
            self.w = vec![0.0; n];
            self.r = vec![0.0; n];
        }
        if self.basis.is_empty() {
            self.basis.push(vec![0.0; n]);
        }
        let b_norm = dot(b, b).sqrt();
        let mut iterations = 0;
        if b_norm == 0.0 {
            x.iter_mut().for_each(|v| *v = 0.0);
            return Ok(GmresReport { iterations, backward_error: 0.0, converged: true });
        }
        let mut x_is_zero = x.iter().all(|v| *v == 0.0);
        loop {
            // true residual r = b - A x
            if x_is_zero {
                self.r.copy_from_slice(b);
            } else {
                apply(x, &mut self.r);
                for (r, bi) in self.r.iter_mut().zip(b) {
                    *r = bi - *r;
                }
            }
            x_is_zero = false;
            let beta = dot(&self.r, &self.r).sqrt();
            let scale = a_norm * dot(x, x).sqrt() + b_norm;
            let error = beta / scale;
            // the residual this solve must reach
            let target = (tol * scale).max(rtol * b_norm);
            let converged = beta <= target;
            if converged || iterations >= max_iterations || !error.is_finite() {
                return Ok(GmresReport { iterations, backward_error: error, converged });
            }
            for (v, r) in self.basis[0].iter_mut().zip(&self.r) {
                *v = r / beta;
            }
            self.g.iter_mut().for_each(|v| *v = 0.0);
            self.g[0] = beta;
            let mut k = 0;
            while k < m && iterations < max_iterations {
                // z_k = M^-1 v_k, w = A z_k
                if self.preconditioned.len() <= k {
                    self.preconditioned.push(vec![0.0; n]);
                }
                if self.basis.len() <= k + 1 {
                    self.basis.push(vec![0.0; n]);
                }
                let z = &mut self.preconditioned[k];
                z.copy_from_slice(&self.basis[k]);
                precondition(z)?;
                apply(z, &mut self.w);
                iterations += 1;
                for i in 0..=k {
                    let hik = dot(&self.w, &self.basis[i]);
                    *self.h(i, k) = hik;
                    for (w, v) in self.w.iter_mut().zip(&self.basis[i]) {
                        *w -= hik * v;
                    }
                }
                let norm = dot(&self.w, &self.w).sqrt();
                *self.h(k + 1, k) = norm;
                if norm > 0.0 {
                    let (next, w) = (&mut self.basis[k + 1], &self.w);
                    for (v, wi) in next.iter_mut().zip(w) {
                        *v = wi / norm;
                    }
                }
                for i in 0..k {
                    let (a, bb) = (*self.h(i, k), *self.h(i + 1, k));
                    *self.h(i, k) = self.cs[i] * a + self.sn[i] * bb;
                    *self.h(i + 1, k) = -self.sn[i] * a + self.cs[i] * bb;
                }
                let (a, bb) = (*self.h(k, k), *self.h(k + 1, k));
                let d = a.hypot(bb);
                let (c, s) = if d == 0.0 { (1.0, 0.0) } else { (a / d, bb / d) };
                self.cs[k] = c;
                self.sn[k] = s;
                *self.h(k, k) = d;
                *self.h(k + 1, k) = 0.0;
                self.g[k + 1] = -s * self.g[k];
                self.g[k] *= c;
                k += 1;
                if self.g[k].abs() <= 0.5 * target || norm == 0.0 {
                    break;
                }
            }
            // x += M^-1 V y = Z y, H y = g
            for i in (0..k).rev() {
                let mut s = self.g[i];
                for j in i + 1..k {
                    s -= self.hessenberg[j * (m + 1) + i] * self.y[j];
                }
                let hii = self.hessenberg[i * (m + 1) + i];
                self.y[i] = if hii != 0.0 { s / hii } else { 0.0 };
            }
            for j in 0..k {
                let yj = self.y[j];
                for (xi, z) in x.iter_mut().zip(&self.preconditioned[j]) {
                    *xi += yj * z;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = A x for the non-symmetric tridiagonal A = (-1.5, 4, -0.5).
    fn tridiagonal(x: &[f64], y: &mut [f64]) {
        let n = x.len();
        for i in 0..n {
            y[i] = 4.0 * x[i] + if i > 0 { -1.5 * x[i - 1] } else { 0.0 } + if i + 1 < n { -0.5 * x[i + 1] } else { 0.0 };
        }
    }

    /// A non-symmetric tridiagonal system with a known solution, preconditioned by its diagonal.
    #[test]
    fn solves_a_nonsymmetric_system() {
        let n = 200;
        let apply = tridiagonal;
        let exact: Vec<f64> = (0..n).map(|i| (i as f64 * 0.1).sin()).collect();
        let mut b = vec![0.0; n];
        apply(&exact, &mut b);
        let mut x = vec![0.0; n];
        let mut g = Gmres::new(10);
        let report = g
            .solve(&b, &mut x, 1e-13, 0.0, 0.0, 500, &mut |x, y| apply(x, y), &mut |z: &mut [f64]| -> Result<(), ()> {
                z.iter_mut().for_each(|v| *v /= 4.0);
                Ok(())
            })
            .unwrap();
        assert!(report.converged && report.backward_error <= 1e-13, "{report:?}");
        let err = x.iter().zip(&exact).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        assert!(err < 1e-11, "error {err}");
        // restarted: more than one cycle of 10 was needed
        assert!(report.iterations > 10, "{report:?}");
    }

    /// An inexact solve stops at the relative residual asked for, in fewer iterations.
    #[test]
    fn stops_at_a_relative_residual() {
        let n = 200;
        let apply = tridiagonal;
        let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        let solve = |rtol: f64| {
            let mut x = vec![0.0; n];
            let report = Gmres::new(50)
                .solve(&b, &mut x, 1e-14, rtol, 0.0, 500, &mut |x, y| apply(x, y), &mut |_: &mut [f64]| -> Result<(), ()> { Ok(()) })
                .unwrap();
            let mut r = vec![0.0; n];
            apply(&x, &mut r);
            let res = r.iter().zip(&b).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt() / b.iter().map(|v| v * v).sum::<f64>().sqrt();
            (report, res)
        };
        let (loose, res_loose) = solve(1e-3);
        let (tight, res_tight) = solve(0.0);
        assert!(loose.converged && res_loose <= 1e-3 && res_loose > 1e-12, "{loose:?} {res_loose}");
        assert!(tight.converged && res_tight <= 1e-13, "{tight:?} {res_tight}");
        assert!(loose.iterations < tight.iterations / 2, "{loose:?} {tight:?}");
    }

    #[test]
    fn reports_non_convergence() {
        // a rotation by 90 degrees in each plane: GMRES(1) stagnates
        let n = 4;
        let apply = |x: &[f64], y: &mut [f64]| {
            for i in (0..n).step_by(2) {
                y[i] = -x[i + 1];
                y[i + 1] = x[i];
            }
        };
        let b = vec![1.0, 0.0, 1.0, 0.0];
        let mut x = vec![0.0; n];
        let report = Gmres::new(1).solve(&b, &mut x, 1e-12, 0.0, 0.0, 20, &mut |x, y| apply(x, y), &mut |_: &mut [f64]| -> Result<(), ()> { Ok(()) }).unwrap();
        assert!(!report.converged && report.backward_error > 0.5, "{report:?}");
    }
}

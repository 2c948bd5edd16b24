//! A linear solver for a sparse matrix bordered by a few dense rows and columns,
//!
//! ```text
//! [ A11  A12 ] [x1]   [b1]
//! [ A21  A22 ] [x2] = [b2]      A11 sparse (n0 x n0), A12, A21 dense-ish, A22 small (m x m),
//! ```
//!
//! such as the tangent of a model with force-driven punches (one extra unknown per punch, coupled to
//! every candidate contact point: see [`crate::model::Model`]). A sparse LU of the whole matrix
//! would see a dense row, and its symbolic phase (which bounds the factors by the Cholesky
//! structure of A^T A) turns the block of every coupled column dense: several times slower than
//! the nodal system alone. Block elimination keeps the sparse solver on A11 only:
//! Y = A11^-1 A12 (m solves), S = A22 - A21 Y (m x m, dense), then for each right-hand side
//! z = A11^-1 b1, x2 = S^-1 (b2 - A21 z), x1 = z - Y x2. A11 must be non-singular: the plate is
//! held by its supports or by displacement-driven punches, not only by the force-driven ones.
//! With m = 0 it is exactly the inner solver: by default [`LdltGmres`] (the LDL^T of the symmetric
//! part, GMRES where A11 is not symmetric), or any [`LinearSolver`], e.g. [`crate::linalg::linear_solver::SparseLu`].

use crate::error::{Result, StampError};
use crate::linalg::ldlt_gmres::LdltGmres;
use crate::linalg::linear_solver::{LinearSolver, SolverTimings};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use nalgebra::DMatrix;

/// A sparse solver on the leading block and a dense Schur complement for the last `border`
/// unknowns.
pub struct BorderedSolver<S: LinearSolver = LdltGmres> {
    inner: S,
    border: usize,
    /// nnz of the full pattern the maps below were built for.
    pattern_nnz: usize,
    n0: usize,
    sym11: Option<SymbolicSparseColMat<usize>>,
    /// The values of the leading block A11 (see `copy11`).
    vals11: Vec<f64>,
    /// The leading block of the preconditioner matrix, in A11's order.
    pre11: Vec<f64>,
    /// (row, column k, position) of A12's entries (rows < n0, column n0 + k).
    a12: Vec<(usize, usize, usize)>,
    /// (row k, column, position) of A21's entries (row n0 + k, columns < n0).
    a21: Vec<(usize, usize, usize)>,
    /// (row k, column l, position) of A22's entries.
    a22: Vec<(usize, usize, usize)>,
    /// Y = A11^-1 A12, column-major n0 x m.
    y: Vec<f64>,
    /// A21 as a dense m x n0 matrix (row-major) of the last factorisation.
    a21_dense: Vec<f64>,
    schur: Option<nalgebra::LU<f64, nalgebra::Dyn, nalgebra::Dyn>>,
    /// For `forward_columns`, built at its first call after a factorisation: A11^-1 A21^T
    /// (column-major n0 x m, by the inner solver's estimate) and S^-1.
    z: Vec<f64>,
    schur_inverse: Option<std::sync::Arc<nalgebra::DMatrix<f64>>>,
}

impl BorderedSolver<LdltGmres> {
    /// A solver for matrices whose last `border` rows and columns are the border, with the
    /// default inner solver.
    pub fn new(border: usize) -> Self {
        Self::with_inner(border, LdltGmres::new())
    }
}

impl<S: LinearSolver> BorderedSolver<S> {
    /// S^-1 of the last factorisation's Schur complement, and z = A11^-1 A21^T (the inner
    /// solver's estimate), built at the first call after a factorisation.
    fn border_inverse(&mut self) -> Result<std::sync::Arc<DMatrix<f64>>> {
        let Some(schur) = self.schur.as_ref() else {
            return Err(StampError::LinearSolver("solve called without a successful factorisation".into()));
        };
        if self.schur_inverse.is_none() {
            let inverse = schur.clone().try_inverse().ok_or_else(|| StampError::LinearSolver("singular Schur complement".into()))?;
            self.schur_inverse = Some(std::sync::Arc::new(inverse));
            self.z = self.a21_dense.clone();
            self.inner.solve_many_approx(&mut self.z, self.border)?;
        }
        Ok(self.schur_inverse.clone().expect("built above"))
    }

    /// The vectors' leading parts (their entries in the leading block).
    fn leading(&self, v: &[Vec<(usize, f64)>]) -> Vec<Vec<(usize, f64)>> {
        v.iter().map(|g| g.iter().copied().filter(|&(e, _)| e < self.n0).collect()).collect()
    }

    /// The border's sides of a vector g = (g1, g2) in b^T K^-1 c: (g1 . Y - g2, z^T g1 - g2).
    fn border_sides(&self, g: &[(usize, f64)]) -> (Vec<f64>, Vec<f64>) {
        let (n0, m) = (self.n0, self.border);
        let mut left = vec![0.0; m];
        let mut right = vec![0.0; m];
        for &(e, x) in g {
            if e < n0 {
                for k in 0..m {
                    left[k] += x * self.y[k * n0 + e];
                    right[k] += x * self.z[k * n0 + e];
                }
            } else {
                left[e - n0] -= x;
                right[e - n0] -= x;
            }
        }
        (left, right)
    }

    /// The same with a given solver for the leading block.
    pub fn with_inner(border: usize, inner: S) -> Self {
        BorderedSolver {
            inner,
            border,
            pattern_nnz: usize::MAX,
            n0: 0,
            sym11: None,
            vals11: Vec::new(),
            pre11: Vec::new(),
            a12: Vec::new(),
            a21: Vec::new(),
            a22: Vec::new(),
            y: Vec::new(),
            a21_dense: Vec::new(),
            schur: None,
            z: Vec::new(),
            schur_inverse: None,
        }
    }

    /// The solver of the leading block.
    pub fn inner(&self) -> &S {
        &self.inner
    }

    /// The border's part of a solve, with z = A11^-1 b1 already in `b1`: x2 = S^-1 (b2 - A21 z)
    /// into `b2`, x1 = z - Y x2 into `b1`.
    fn finish_border(&self, b1: &mut [f64], b2: &mut [f64]) -> Result<()> {
        let (n0, m) = (self.n0, self.border);
        let Some(schur) = self.schur.as_ref() else {
            return Err(StampError::LinearSolver("solve called without a successful factorisation".into()));
        };
        let mut r = nalgebra::DVector::<f64>::zeros(m);
        for k in 0..m {
            let row = &self.a21_dense[k * n0..(k + 1) * n0];
            r[k] = b2[k] - row.iter().zip(b1.iter()).map(|(a, z)| a * z).sum::<f64>();
        }
        let x2 = schur.solve(&r).ok_or_else(|| StampError::LinearSolver("singular Schur complement".into()))?;
        for k in 0..m {
            b2[k] = x2[k];
            let col = &self.y[k * n0..(k + 1) * n0];
            for (x, yv) in b1.iter_mut().zip(col) {
                *x -= yv * x2[k];
            }
        }
        Ok(())
    }

    fn build_maps(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<()> {
        let n = a.ncols();
        let m = self.border;
        if m > n || a.nrows() != n {
            return Err(StampError::LinearSolver(format!("a {}x{n} matrix cannot have a border of {m}", a.nrows())));
        }
        let n0 = n - m;
        let sym = a.symbolic();
        let (cp, ri) = (sym.col_ptr(), sym.row_idx());
        let mut col_ptr = Vec::with_capacity(n0 + 1);
        let mut row_idx = Vec::new();
        self.a12.clear();
        self.a21.clear();
        self.a22.clear();
        col_ptr.push(0);
        for j in 0..n {
            for p in cp[j]..cp[j + 1] {
                let i = ri[p];
                match (i < n0, j < n0) {
                    (true, true) => {
                        // (rows ascend: a column's rows of A11 come first, see copy11)
                        if p - cp[j] != row_idx.len() - col_ptr[j] {
                            return Err(StampError::LinearSolver("the rows of a bordered matrix's columns must ascend".into()));
                        }
                        row_idx.push(i);
                    }
                    (true, false) => self.a12.push((i, j - n0, p)),
                    (false, true) => self.a21.push((i - n0, j, p)),
                    (false, false) => self.a22.push((i - n0, j - n0, p)),
                }
            }
            if j < n0 {
                col_ptr.push(row_idx.len());
            }
        }
        self.vals11 = vec![0.0; row_idx.len()];
        self.sym11 = Some(SymbolicSparseColMat::new_checked(n0, n0, col_ptr, None, row_idx));
        self.n0 = n0;
        self.pattern_nnz = ri.len();
        Ok(())
    }
}

/// The values of A11 (column pointers `cp11`) out of the whole matrix's (column pointers `cp`):
/// column j of A11 is the first cp11[j + 1] - cp11[j] entries of the whole column j (its rows
/// ascend, and A11's come first), so no map of positions is kept.
fn copy11(cp11: &[usize], cp: &[usize], whole: &[f64], out: &mut [f64]) {
    for j in 0..cp11.len() - 1 {
        let len = cp11[j + 1] - cp11[j];
        out[cp11[j]..cp11[j + 1]].copy_from_slice(&whole[cp[j]..cp[j] + len]);
    }
}

impl<S: LinearSolver> LinearSolver for BorderedSolver<S> {
    fn factorize(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<()> {
        self.factorize_preconditioned(a, None)
    }

    fn uses_preconditioner(&self) -> bool {
        self.inner.uses_preconditioner()
    }

    /// The leading block of `p` (A's pattern) preconditions the leading block of A.
    fn factorize_preconditioned(&mut self, a: SparseColMatRef<'_, usize, f64>, p: Option<SparseColMatRef<'_, usize, f64>>) -> Result<()> {
        if self.border == 0 {
            return self.inner.factorize_preconditioned(a, p);
        }
        if self.pattern_nnz != a.symbolic().row_idx().len() || self.sym11.is_none() {
            self.build_maps(a)?;
        }
        let (n0, m) = (self.n0, self.border);
        let vals = a.val();
        let sym11 = self.sym11.as_ref().unwrap().as_ref();
        copy11(sym11.col_ptr(), a.symbolic().col_ptr(), vals, &mut self.vals11);
        let a11 = SparseColMatRef::new(sym11, &self.vals11);
        match p {
            Some(p) if crate::linalg::sparse::same_pattern(p.symbolic(), a.symbolic()) => {
                let pv = p.val();
                self.pre11.resize(self.vals11.len(), 0.0);
                copy11(sym11.col_ptr(), a.symbolic().col_ptr(), pv, &mut self.pre11);
                self.inner.factorize_preconditioned(a11, Some(SparseColMatRef::new(sym11, &self.pre11)))?;
            }
            Some(_) => return Err(StampError::LinearSolver("the preconditioner's pattern is not the matrix's".into())),
            None => self.inner.factorize(a11)?,
        }
        self.z.clear();
        self.schur_inverse = None;
        // Y = A11^-1 A12
        self.y.clear();
        self.y.resize(n0 * m, 0.0);
        for &(i, k, p) in &self.a12 {
            self.y[k * n0 + i] += vals[p];
        }
        for k in 0..m {
            self.inner.solve_in_place(&mut self.y[k * n0..(k + 1) * n0])?;
        }
        // S = A22 - A21 Y
        self.a21_dense.clear();
        self.a21_dense.resize(m * n0, 0.0);
        for &(k, j, p) in &self.a21 {
            self.a21_dense[k * n0 + j] += vals[p];
        }
        let mut s = DMatrix::<f64>::zeros(m, m);
        for &(k, l, p) in &self.a22 {
            s[(k, l)] += vals[p];
        }
        for k in 0..m {
            let row = &self.a21_dense[k * n0..(k + 1) * n0];
            for l in 0..m {
                let col = &self.y[l * n0..(l + 1) * n0];
                s[(k, l)] -= row.iter().zip(col).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        let lu = s.lu();
        if !lu.is_invertible() {
            self.schur = None;
            return Err(StampError::LinearSolver("the Schur complement of the bordered system is singular (a force-driven punch touches nothing?)".into()));
        }
        self.schur = Some(lu);
        Ok(())
    }

    fn solve_in_place(&mut self, b: &mut [f64]) -> Result<()> {
        self.solve_in_place_to(b, 0.0)
    }

    /// The inner solve of the right-hand side may be inexact (`rtol`); the columns Y of the
    /// factorisation are always solved to full accuracy.
    fn solve_in_place_to(&mut self, b: &mut [f64], rtol: f64) -> Result<()> {
        if self.border == 0 {
            return self.inner.solve_in_place_to(b, rtol);
        }
        let (b1, b2) = b.split_at_mut(self.n0);
        self.inner.solve_in_place_to(b1, rtol)?;
        self.finish_border(b1, b2)?;
        if b.iter().any(|x| !x.is_finite()) {
            return Err(StampError::LinearSolver("the solution has non-finite entries: the matrix is singular".into()));
        }
        Ok(())
    }

    /// The leading block's columns by the inner solver's `solve_many_approx`, then the border
    /// as in `solve_in_place_to`.
    fn solve_many_approx(&mut self, b: &mut [f64], ncols: usize) -> Result<()> {
        if self.border == 0 {
            return self.inner.solve_many_approx(b, ncols);
        }
        if ncols == 0 {
            return Ok(());
        }
        let (n0, m) = (self.n0, self.border);
        let n = n0 + m;
        let mut lead = vec![0.0; n0 * ncols];
        for (l, c) in lead.chunks_mut(n0).zip(b.chunks(n)) {
            l.copy_from_slice(&c[..n0]);
        }
        self.inner.solve_many_approx(&mut lead, ncols)?;
        for (z, c) in lead.chunks(n0).zip(b.chunks_mut(n)) {
            let (b1, b2) = c.split_at_mut(n0);
            b1.copy_from_slice(z);
            self.finish_border(b1, b2)?;
        }
        Ok(())
    }

    /// With a border: the inner solver's forward columns of the vectors' leading parts, with the
    /// border's terms of b^T K^-1 c = b1^T A11^-1 c1 + (b1 . Y - b2)^T S^-1 (A21 A11^-1 c1 - c2)
    /// (the block inverse; A11^-1 the inner solver's symmetric estimate, Y = A11^-1 A12 as
    /// factorised).
    fn forward_columns(&mut self, b: &[Vec<(usize, f64)>]) -> Result<Option<Vec<crate::linalg::supernodal_solve::ForwardColumn>>> {
        if self.border == 0 {
            return self.inner.forward_columns(b);
        }
        let Some(columns) = self.inner.forward_columns(&self.leading(b))? else { return Ok(None) };
        let inverse = self.border_inverse()?;
        let out = columns
            .into_iter()
            .zip(b)
            .map(|(column, g)| {
                let (left, right) = self.border_sides(g);
                column.with_border(left, right, inverse.clone())
            })
            .collect();
        Ok(Some(out))
    }

    /// With a border: the inner solver's compliance of the vectors' leading parts, with the
    /// border's terms of the block inverse as in `forward_columns`.
    fn compliance(&mut self, a: &[Vec<(usize, f64)>], b: &[Vec<(usize, f64)>]) -> Result<Option<DMatrix<f64>>> {
        if self.border == 0 {
            return self.inner.compliance(a, b);
        }
        let (la, lb) = (self.leading(a), self.leading(b));
        let Some(mut c) = self.inner.compliance(&la, &lb)? else { return Ok(None) };
        let inverse = self.border_inverse()?;
        let right: Vec<nalgebra::DVector<f64>> = b.iter().map(|g| inverse.as_ref() * nalgebra::DVector::from_vec(self.border_sides(g).1)).collect();
        for (i, g) in a.iter().enumerate() {
            let left = nalgebra::DVector::from_vec(self.border_sides(g).0);
            for (j, r) in right.iter().enumerate() {
                c[(i, j)] += left.dot(r);
            }
        }
        Ok(Some(c))
    }

    fn timings(&self) -> SolverTimings {
        self.inner.timings()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    /// A k x k grid Laplacian (shifted, symmetric) bordered by one row and column that couple to
    /// a few unknowns: b^T K^-1 c from the forward columns (with the border's terms) equals the
    /// same from a whole solve, for vectors with and without a border entry.
    #[test]
    fn forward_columns_of_a_bordered_matrix_give_its_compliance() {
        let k = 150;
        let n0 = k * k;
        // the border: coupled to four unknowns, symmetric, and its own diagonal
        let a = grid_with_border(k, &[(10, 0.3, 0.3), (n0 / 2, -0.5, -0.5), (n0 / 2 + 7, 0.25, 0.25), (n0 - 5, 0.4, 0.4)]);
        let mut solver = BorderedSolver::new(1);
        solver.factorize(a.as_ref()).unwrap();
        let vectors: Vec<Vec<(usize, f64)>> = vec![vec![(n0 / 2, 1.0), (n0 / 2 + 1, -0.5), (n0, 0.7)], vec![(12, 2.0)], vec![(n0 - 3, 1.0), (n0 / 3, 0.25), (n0, -1.0)]];
        let columns = solver.forward_columns(&vectors).unwrap().expect("forward columns through the border");
        let got = DMatrix::from_fn(vectors.len(), vectors.len(), |i, j| columns[i].dot(&columns[j]));
        assert_whole_compliance(&mut solver, &vectors, &vectors, &got);
    }

    /// `got` against a_i^T K^-1 b_j from whole solves with `solver`, to 1e-10 relative.
    fn assert_whole_compliance<S: LinearSolver>(solver: &mut BorderedSolver<S>, a: &[Vec<(usize, f64)>], b: &[Vec<(usize, f64)>], got: &DMatrix<f64>) {
        let n = solver.n0 + solver.border;
        for (j, bj) in b.iter().enumerate() {
            let mut x = vec![0.0; n];
            bj.iter().for_each(|&(e, v)| x[e] += v);
            solver.solve_in_place(&mut x).unwrap();
            for (i, ai) in a.iter().enumerate() {
                let expected: f64 = ai.iter().map(|&(e, v)| v * x[e]).sum();
                assert!((got[(i, j)] - expected).abs() <= 1e-10 * expected.abs().max(1e-3), "a{i}^T K^-1 b{j}: {} against {expected}", got[(i, j)]);
            }
        }
    }

    /// The 5-point operator (diagonal 4.01) on a k x k grid bordered by one unknown: column
    /// entries (i, v) and row entries (i, w) of each triple (i, v, w), diagonal 2.
    fn grid_with_border(k: usize, border: &[(usize, f64, f64)]) -> SparseColMat<usize, f64> {
        let n0 = k * k;
        let mut t = Vec::new();
        for (x, y) in (0..k).flat_map(|x| (0..k).map(move |y| (x, y))) {
            let i = x * k + y;
            t.push(Triplet::new(i, i, 4.01));
            if x + 1 < k {
                t.extend([Triplet::new(i, i + k, -1.0), Triplet::new(i + k, i, -1.0)]);
            }
            if y + 1 < k {
                t.extend([Triplet::new(i, i + 1, -1.0), Triplet::new(i + 1, i, -1.0)]);
            }
        }
        for &(i, v, w) in border {
            t.extend([Triplet::new(i, n0, v), Triplet::new(n0, i, w)]);
        }
        t.push(Triplet::new(n0, n0, 2.0));
        SparseColMat::try_new_from_triplets(n0 + 1, n0 + 1, &t).unwrap()
    }

    /// An inner solver with the selected-entries compliance (as PETSc's MUMPS gives it), here
    /// by whole solves with faer's LU of the leading block.
    struct Entries(crate::linalg::linear_solver::SparseLu, usize);

    impl LinearSolver for Entries {
        fn factorize(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<()> {
            self.1 = a.nrows();
            self.0.factorize(a)
        }
        fn solve_in_place(&mut self, b: &mut [f64]) -> Result<()> {
            self.0.solve_in_place(b)
        }
        fn compliance(&mut self, a: &[Vec<(usize, f64)>], b: &[Vec<(usize, f64)>]) -> Result<Option<DMatrix<f64>>> {
            let n = self.1;
            let mut c = DMatrix::zeros(a.len(), b.len());
            for (j, g) in b.iter().enumerate() {
                let mut x = vec![0.0; n];
                g.iter().for_each(|&(e, v)| x[e] += v);
                self.0.solve_in_place(&mut x)?;
                for (i, f) in a.iter().enumerate() {
                    c[(i, j)] = f.iter().map(|&(e, v)| v * x[e]).sum();
                }
            }
            Ok(Some(c))
        }
        fn timings(&self) -> SolverTimings {
            self.0.timings()
        }
    }

    /// The compliance a_i^T K^-1 b_j of a bordered matrix (the border unsymmetric) from the inner
    /// solver's compliance of the leading parts and the block inverse's border terms, against
    /// whole solves; fails without the border terms.
    #[test]
    fn compliance_of_a_bordered_matrix_from_the_inner_compliance() {
        let k = 30;
        let n0 = k * k;
        // the border: its row and column differ (a force-driven punch's are not each other's transpose)
        let a = grid_with_border(k, &[(10, 0.3, 0.2), (n0 / 2, -0.5, -0.4), (n0 / 2 + 7, 0.25, 0.3), (n0 - 5, 0.4, 0.1)]);
        let mut solver = BorderedSolver::with_inner(1, Entries(crate::linalg::linear_solver::SparseLu::new(), 0));
        solver.factorize(a.as_ref()).unwrap();
        let va: Vec<Vec<(usize, f64)>> = vec![vec![(n0 / 2, 1.0), (n0 / 2 + 1, -0.5), (n0, 0.7)], vec![(12, 2.0)]];
        let vb: Vec<Vec<(usize, f64)>> = vec![vec![(n0 - 3, 1.0), (n0 / 3, 0.25), (n0, -1.0)], vec![(n0 / 2, 0.5)], vec![(n0, 1.0)]];
        let c = solver.compliance(&va, &vb).unwrap().expect("the inner solver's compliance through the border");
        assert_whole_compliance(&mut solver, &va, &vb, &c);
    }
}

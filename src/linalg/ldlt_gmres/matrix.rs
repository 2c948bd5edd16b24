//! The passes over A's values that the solver makes besides the factorisation: A by rows and its
//! symmetric part ([`split_values`]), the product A x by rows ([`multiply_rows`]), the backward
//! error of a solve ([`backward_error`]), the transposed positions of a symmetric pattern.

/// Rows per task of the parallel product.
pub(super) const ROWS_PER_TASK: usize = 4096;

/// From A's values `a` in its symmetric pattern (`transpose`: the position of a_ji for each
/// a_ij): A by rows (`row_values`, see [`multiply_rows`]), the row sums of |A| (`row_sums`) and,
/// if given, the symmetric part (`symmetric`); returns max |a_ij - a_ji| and max |a_ij|. Columns
/// in parallel when `parallel`.
pub(super) fn split_values(col_ptr: &[usize], transpose: &[usize], a: &[f64], row_values: &mut [f64], symmetric: Option<&mut [f64]>, row_sums: &mut [f64], parallel: bool) -> (f64, f64) {
    // the columns first..first + sums.len(), whose entries start at slot `base`
    let columns = |first: usize, base: usize, rows: &mut [f64], mut sym: Option<&mut [f64]>, sums: &mut [f64]| {
        crate::linalg::vector_state::clean_upper_vector_state();
        let (mut worst, mut size) = (0.0f64, 0.0f64);
        for (c, sum) in sums.iter_mut().enumerate() {
            let mut total = 0.0;
            for k in col_ptr[first + c]..col_ptr[first + c + 1] {
                let (v, t) = (a[k], a[transpose[k]]);
                rows[k - base] = t;
                total += t.abs();
                worst = worst.max((v - t).abs());
                size = size.max(v.abs());
                if let Some(s) = sym.as_deref_mut() {
                    s[k - base] = 0.5 * (v + t);
                }
            }
            *sum = total;
        }
        (worst, size)
    };
    let n = row_sums.len();
    if !parallel {
        return columns(0, 0, row_values, symmetric, row_sums);
    }
    // disjoint pieces of the output, ROWS_PER_TASK columns each
    let mut tasks = Vec::with_capacity(n.div_ceil(ROWS_PER_TASK));
    let (mut rows, mut sym, mut sums) = (row_values, symmetric, row_sums);
    let mut first = 0;
    while first < n {
        let last = (first + ROWS_PER_TASK).min(n);
        let len = col_ptr[last] - col_ptr[first];
        let (r_here, r_rest) = std::mem::take(&mut rows).split_at_mut(len);
        let (s_here, s_rest) = match sym.take() {
            Some(s) => {
                let (h, r) = s.split_at_mut(len);
                (Some(h), Some(r))
            }
            None => (None, None),
        };
        let (m_here, m_rest) = std::mem::take(&mut sums).split_at_mut(last - first);
        tasks.push((first, r_here, s_here, m_here));
        (rows, sym, sums) = (r_rest, s_rest, m_rest);
        first = last;
    }
    use rayon::prelude::*;
    tasks
        .into_par_iter()
        .map(|(first, rows, sym, sums)| columns(first, col_ptr[first], rows, sym, sums))
        .reduce(|| (0.0, 0.0), |x, y| (x.0.max(y.0), x.1.max(y.1)))
}

/// y = A x computed by rows, for a matrix of symmetric pattern: `row_values[k]` is
/// a_{c, row_idx[k]} for the k-th stored entry of column c (A^T stored in A's pattern), so that
/// y_c = sum_k row_values[k] x[row_idx[k]] over column c. Rows in parallel when `parallel`.
pub(super) fn multiply_rows(col_ptr: &[usize], row_idx: &[usize], row_values: &[f64], x: &[f64], y: &mut [f64], parallel: bool) {
    let rows = |first: usize, out: &mut [f64]| {
        // a worker thread may come from faer's kernels (see crate::linalg::vector_state)
        crate::linalg::vector_state::clean_upper_vector_state();
        for (i, yi) in out.iter_mut().enumerate() {
            let c = first + i;
            *yi = (col_ptr[c]..col_ptr[c + 1]).map(|k| row_values[k] * x[row_idx[k]]).sum();
        }
    };
    if parallel {
        use rayon::prelude::*;
        y.par_chunks_mut(ROWS_PER_TASK).enumerate().for_each(|(chunk, out)| rows(chunk * ROWS_PER_TASK, out));
    } else {
        rows(0, y);
    }
}

/// y = A x for A in compressed columns.
#[cfg(test)]
pub(super) fn multiply(col_ptr: &[usize], row_idx: &[usize], values: &[f64], x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    for (j, &xj) in x.iter().enumerate() {
        for k in col_ptr[j]..col_ptr[j + 1] {
            y[row_idx[k]] += values[k] * xj;
        }
    }
}

/// r = b - A x (A by rows, see [`multiply_rows`]); returns |r| / (|A| |x| + |b|) in infinity
/// norms.
#[allow(clippy::too_many_arguments)]
pub(super) fn backward_error(col_ptr: &[usize], row_idx: &[usize], row_values: &[f64], parallel: bool, norm_inf: f64, b: &[f64], x: &[f64], r: &mut [f64]) -> f64 {
    multiply_rows(col_ptr, row_idx, row_values, x, r, parallel);
    for (ri, bi) in r.iter_mut().zip(b) {
        *ri = bi - *ri;
    }
    let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, y| m.max(y.abs()));
    let denominator = norm_inf * inf(x) + inf(b);
    if denominator == 0.0 { 0.0 } else { inf(r) / denominator }
}

/// For every stored (i, j), the position of (j, i); None if the pattern is not symmetric. Row
/// indices must be sorted within each column (faer's invariant).
pub(super) fn transpose_positions(col_ptr: &[usize], row_idx: &[usize]) -> Option<Vec<usize>> {
    let mut out = vec![0usize; row_idx.len()];
    crate::linalg::sparse::pair_transposed(col_ptr, row_idx, |k, partner| out[k] = partner).then_some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::linalg::ldlt_gmres::tests::{matrix, tridiagonal};

    /// The row-wise (parallel) product equals the column-wise one on a non-symmetric matrix of
    /// symmetric pattern spanning several row chunks.
    #[test]
    fn row_wise_product_matches_column_wise() {
        let n = 3 * ROWS_PER_TASK + 17;
        let a = tridiagonal(n, 0.3, 0.5);
        let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        let tr = transpose_positions(cp, ri).unwrap();
        let rows: Vec<f64> = tr.iter().map(|&k| v[k]).collect();
        let x: Vec<f64> = (0..n).map(|i| (0.7 * i as f64).sin()).collect();
        let mut expected = vec![0.0; n];
        multiply(cp, ri, v, &x, &mut expected);
        for parallel in [false, true] {
            let mut y = vec![f64::NAN; n];
            multiply_rows(cp, ri, &rows, &x, &mut y, parallel);
            let err = y.iter().zip(&expected).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(err <= 1e-14, "parallel {parallel}: {err:e}");
        }
    }

    #[test]
    fn transpose_map_pairs_entries() {
        let a = tridiagonal(5, 0.3, 0.0);
        let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        let tr = transpose_positions(cp, ri).unwrap();
        let col = |k: usize| cp.partition_point(|&c| c <= k) - 1;
        for (k, &p) in tr.iter().enumerate() {
            assert_eq!((ri[k], col(k)), (col(p), ri[p]));
            // below the diagonal -1 - skew, its partner above -1 + skew
            if ri[k] == col(k) + 1 {
                assert_eq!((v[k], v[p]), (-1.3, -0.7));
            }
        }
        // (0, 1) without (1, 0): not symmetric
        let b = matrix(2, &[(0, 0, 1.0), (0, 1, 1.0), (1, 1, 1.0)]);
        assert!(transpose_positions(b.symbolic().col_ptr(), b.symbolic().row_idx()).is_none());
    }
}

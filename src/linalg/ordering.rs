//! Fill-reducing orderings for the sparse LDL^T: nested dissection by METIS on the compressed
//! (nodal) graph of a symmetric sparse pattern.
//!
//! A finite-element matrix has several unknowns per node whose columns have the same pattern
//! (on the plate, the 6 dofs of a node, fewer where some are prescribed). Those columns are
//! merged into one supervariable, METIS (`METIS_NodeND`, vendored and built from C source by the
//! `metis-sys` crate: a C compiler is all it needs) orders the quotient graph with the
//! supervariable sizes as vertex weights, and each supervariable is expanded back into its
//! unknowns, consecutively. The graph given to METIS is 6 times smaller in vertices and about 36
//! times smaller in edges than the matrix graph.
//!
//! The pattern may be any sparse square pattern (general meshes, any number of unknowns per
//! node): it is symmetrised (A + A^T) first where it is not symmetric, and the diagonal is
//! ignored.

use crate::error::{Result, StampError};
use std::borrow::Cow;
use std::sync::Mutex;

/// METIS keeps its random number generator in global (not thread-local) state, reseeded at each
/// call: calls are serialised, which also makes the orderings deterministic.
pub(crate) static METIS: Mutex<()> = Mutex::new(());

/// Supervariables of a symmetric pattern: unknowns with the same closed neighbourhood
/// adj(i) + {i}.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Supervariables {
    /// Supervariable of every unknown.
    pub of: Vec<usize>,
    /// Members of supervariable s: `members[ptr[s]..ptr[s + 1]]`, increasing.
    pub ptr: Vec<usize>,
    pub members: Vec<usize>,
}

impl Supervariables {
    pub fn len(&self) -> usize {
        self.ptr.len() - 1
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Closed neighbourhoods adj(j) + {j} of the symmetric pattern A + A^T plus the diagonal, as
/// compressed columns with sorted rows. A pattern that already is that (the usual finite-element
/// matrix: symmetric, rows sorted, diagonal stored) is borrowed, not copied.
pub fn closed_pattern<'a>(col_ptr: &'a [usize], row_idx: &'a [usize]) -> (Cow<'a, [usize]>, Cow<'a, [usize]>) {
    if is_closed_symmetric(col_ptr, row_idx) {
        return (Cow::Borrowed(col_ptr), Cow::Borrowed(row_idx));
    }
    let n = col_ptr.len() - 1;
    let mut count = vec![0usize; n + 1];
    for j in 0..n {
        count[j + 1] += 1;
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if i != j {
                count[i + 1] += 1;
                count[j + 1] += 1;
            }
        }
    }
    for j in 0..n {
        count[j + 1] += count[j];
    }
    let mut fill = count.clone();
    let mut adj = vec![0usize; count[n]];
    for j in 0..n {
        adj[fill[j]] = j;
        fill[j] += 1;
        for &i in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
            if i != j {
                adj[fill[j]] = i;
                fill[j] += 1;
                adj[fill[i]] = j;
                fill[i] += 1;
            }
        }
    }
    // sort and remove duplicates, compacting
    let mut ptr = vec![0usize; n + 1];
    let mut out = 0;
    for j in 0..n {
        let (start, end) = (count[j], count[j + 1]);
        adj[start..end].sort_unstable();
        let mut last = usize::MAX;
        for k in start..end {
            let i = adj[k];
            if i != last {
                adj[out] = i;
                out += 1;
                last = i;
            }
        }
        ptr[j + 1] = out;
    }
    adj.truncate(out);
    (Cow::Owned(ptr), Cow::Owned(adj))
}

/// The pattern is symmetric, its rows strictly increasing in each column, every diagonal entry
/// stored.
fn is_closed_symmetric(col_ptr: &[usize], row_idx: &[usize]) -> bool {
    let n = col_ptr.len() - 1;
    let sorted_with_diagonal = (0..n).all(|j| {
        let col = &row_idx[col_ptr[j]..col_ptr[j + 1]];
        col.windows(2).all(|w| w[0] < w[1]) && col.binary_search(&j).is_ok()
    });
    sorted_with_diagonal && crate::linalg::sparse::pair_transposed(col_ptr, row_idx, |_, _| {})
}

/// Group the vertices of a graph by closed neighbourhood; `ptr` / `adj`: the closed
/// neighbourhoods, sorted (as [`closed_pattern`] returns them).
pub fn supervariables(ptr: &[usize], adj: &[usize]) -> Supervariables {
    let n = ptr.len() - 1;
    let mix = |i: usize| (i as u64 ^ 0x5851_f42d_4c95_7f2d).wrapping_mul(0x9e37_79b9_7f4a_7c15).rotate_left(29);
    let hash: Vec<u64> = (0..n).map(|j| adj[ptr[j]..ptr[j + 1]].iter().fold(0u64, |h, &i| h.wrapping_add(mix(i)))).collect();
    let key = |j: usize| (hash[j], ptr[j + 1] - ptr[j]);
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_unstable_by_key(|&j| (key(j), j));
    const NONE: usize = usize::MAX;
    let mut of = vec![NONE; n];
    let mut count = 0;
    let mut start = 0;
    while start < n {
        let mut end = start + 1;
        while end < n && key(order[end]) == key(order[start]) {
            end += 1;
        }
        // within a group of equal keys (almost always one supervariable), split by comparison
        for a in start..end {
            let r = order[a];
            if of[r] != NONE {
                continue;
            }
            of[r] = count;
            for &c in &order[a + 1..end] {
                if of[c] == NONE && adj[ptr[r]..ptr[r + 1]] == adj[ptr[c]..ptr[c + 1]] {
                    of[c] = count;
                }
            }
            count += 1;
        }
        start = end;
    }
    // number supervariables by their smallest member, members increasing
    let mut renumber = vec![NONE; count];
    let mut next = 0;
    for j in 0..n {
        if renumber[of[j]] == NONE {
            renumber[of[j]] = next;
            next += 1;
        }
    }
    let of: Vec<usize> = of.iter().map(|&s| renumber[s]).collect();
    let mut sptr = vec![0usize; count + 1];
    for &s in &of {
        sptr[s + 1] += 1;
    }
    for s in 0..count {
        sptr[s + 1] += sptr[s];
    }
    let mut fill = sptr.clone();
    let mut members = vec![0usize; n];
    for (j, &s) in of.iter().enumerate() {
        members[fill[s]] = j;
        fill[s] += 1;
    }
    Supervariables { of, ptr: sptr, members }
}

/// Nested-dissection ordering of a square sparse pattern (compressed columns) by METIS on its
/// compressed graph. Returns the elimination order: `perm[k]` is the unknown eliminated k-th
/// (faer's forward permutation, METIS's `perm`).
pub fn nested_dissection(col_ptr: &[usize], row_idx: &[usize]) -> Result<Vec<usize>> {
    let n = col_ptr.len() - 1;
    let (ptr, adj) = closed_pattern(col_ptr, row_idx);
    let sv = supervariables(&ptr, &adj);
    let m = sv.len();
    // the quotient graph: supervariable s adjacent to t when some member of s is adjacent to one
    // of t (all members of s have the same neighbours: those of the first member will do)
    let too_big = || StampError::LinearSolver("graph too large for METIS's 32-bit indices".into());
    let mut xadj: Vec<i32> = Vec::with_capacity(m + 1);
    let mut adjncy: Vec<i32> = Vec::new();
    let mut mark = vec![usize::MAX; m];
    xadj.push(0);
    for s in 0..m {
        let r = sv.members[sv.ptr[s]];
        mark[s] = s;
        for &i in &adj[ptr[r]..ptr[r + 1]] {
            let t = sv.of[i];
            if mark[t] != s {
                mark[t] = s;
                adjncy.push(i32::try_from(t).map_err(|_| too_big())?);
            }
        }
        xadj.push(i32::try_from(adjncy.len()).map_err(|_| too_big())?);
    }
    drop(adj);
    let order = if adjncy.is_empty() {
        // no edges: any order is as good
        (0..m).collect::<Vec<_>>()
    } else {
        let mut vwgt: Vec<i32> = (0..m).map(|s| i32::try_from(sv.ptr[s + 1] - sv.ptr[s]).map_err(|_| too_big())).collect::<Result<_>>()?;
        let mut nvtxs = i32::try_from(m).map_err(|_| too_big())?;
        let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
        let mut perm = vec![0i32; m];
        let mut iperm = vec![0i32; m];
        let status = {
            let _guard = METIS.lock().unwrap_or_else(|e| e.into_inner());
            // SAFETY: the arrays have the lengths METIS_NodeND requires (n + 1, xadj[n], n, n, n,
            // NOPTIONS), outlive the call, and the graph is valid: symmetric, no self loops, all
            // indices in 0..n.
            unsafe {
                metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
                options[metis_sys::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
                metis_sys::METIS_NodeND(&mut nvtxs, xadj.as_mut_ptr(), adjncy.as_mut_ptr(), vwgt.as_mut_ptr(), options.as_mut_ptr(), perm.as_mut_ptr(), iperm.as_mut_ptr())
            }
        };
        if status != metis_sys::rstatus_et_METIS_OK {
            return Err(StampError::LinearSolver(format!("METIS_NodeND failed (status {status})")));
        }
        let order: Vec<usize> = perm.into_iter().map(|p| usize::try_from(p).unwrap_or(usize::MAX)).collect();
        if !is_permutation(&order, m) {
            return Err(StampError::LinearSolver("METIS_NodeND returned no permutation".into()));
        }
        order
    };
    let mut out = Vec::with_capacity(n);
    for s in order {
        out.extend_from_slice(&sv.members[sv.ptr[s]..sv.ptr[s + 1]]);
    }
    debug_assert!(is_permutation(&out, n));
    Ok(out)
}

/// `perm` holds every index of 0..n exactly once.
pub fn is_permutation(perm: &[usize], n: usize) -> bool {
    let mut seen = vec![false; n];
    perm.len() == n && perm.iter().all(|&p| p < n && !std::mem::replace(&mut seen[p], true))
}

/// The inverse permutation: `inverse(perm)[perm[k]] == k`.
pub fn inverse(perm: &[usize]) -> Vec<usize> {
    let mut inv = vec![0; perm.len()];
    for (k, &p) in perm.iter().enumerate() {
        inv[p] = k;
    }
    inv
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::perm::PermRef;
    use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, SymmetricOrdering};
    use faer::sparse::SymbolicSparseColMatRef;
    use faer::Side;

    /// Compressed columns (sorted, no duplicates) from a list of (row, column) entries.
    fn pattern(n: usize, entries: &[(usize, usize)]) -> (Vec<usize>, Vec<usize>) {
        let mut cols = vec![Vec::new(); n];
        for &(i, j) in entries {
            cols[j].push(i);
        }
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        for mut c in cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend(c);
            col_ptr.push(row_idx.len());
        }
        (col_ptr, row_idx)
    }

    /// The pattern of a k x k grid of nodes meshed by quadrilaterals (each node coupled to its 8
    /// neighbours), `dofs(node)` unknowns per node, every coupling a full block.
    fn grid(k: usize, dofs: impl Fn(usize) -> usize) -> (Vec<usize>, Vec<usize>) {
        let mut first = vec![0];
        for node in 0..k * k {
            first.push(first[node] + dofs(node));
        }
        let mut e = Vec::new();
        for (x, y) in (0..k).flat_map(|x| (0..k).map(move |y| (x, y))) {
            for (u, v) in (x.saturating_sub(1)..(x + 2).min(k)).flat_map(|u| (y.saturating_sub(1)..(y + 2).min(k)).map(move |v| (u, v))) {
                let (a, b) = (x * k + y, u * k + v);
                for i in first[a]..first[a + 1] {
                    for j in first[b]..first[b + 1] {
                        e.push((i, j));
                    }
                }
            }
        }
        pattern(first[k * k], &e)
    }

    /// Stored entries of the LDL^T factor under an ordering (None: faer's AMD).
    fn factor_len(col_ptr: &[usize], row_idx: &[usize], perm: Option<&[usize]>) -> usize {
        let n = col_ptr.len() - 1;
        let a = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
        let inverse = perm.map(inverse);
        let order = match (perm, &inverse) {
            (Some(p), Some(i)) => SymmetricOrdering::Custom(PermRef::new_checked(p, i, n)),
            _ => SymmetricOrdering::Amd,
        };
        factorize_symbolic_cholesky(a, Side::Lower, order, Default::default()).unwrap().len_val()
    }

    #[test]
    fn supervariables_are_the_nodes() {
        // 3 unknowns per node, 2 on the nodes of the first row (one of them prescribed)
        let k = 12;
        let (cp, ri) = grid(k, |node| if node % k == 0 { 2 } else { 3 });
        assert!(is_closed_symmetric(&cp, &ri));
        let (ptr, adj) = closed_pattern(&cp, &ri);
        assert!(matches!(ptr, Cow::Borrowed(_)) && matches!(adj, Cow::Borrowed(_)));
        let sv = supervariables(&ptr, &adj);
        assert_eq!(sv.len(), k * k);
        assert_eq!((&sv.members[sv.ptr[0]..sv.ptr[1]], &sv.members[sv.ptr[1]..sv.ptr[2]]), (&[0, 1][..], &[2, 3, 4][..]));
        for s in 0..sv.len() {
            assert!(sv.members[sv.ptr[s]..sv.ptr[s + 1]].iter().all(|&j| sv.of[j] == s));
        }
        // two unknowns coupled to each other only are one supervariable; two uncoupled are not
        let (cp, ri) = pattern(4, &[(0, 0), (1, 1), (0, 1), (1, 0), (2, 2), (3, 3)]);
        let (ptr, adj) = closed_pattern(&cp, &ri);
        assert_eq!(supervariables(&ptr, &adj).of, vec![0, 0, 1, 2]);
    }

    #[test]
    fn closed_pattern_symmetrises_and_adds_the_diagonal() {
        // (1, 0) without (0, 1), (2, 1) without (1, 2), no diagonal entry in column 2
        let (cp, ri) = pattern(3, &[(0, 0), (1, 0), (1, 1), (2, 1)]);
        assert!(!is_closed_symmetric(&cp, &ri));
        let (ptr, adj) = closed_pattern(&cp, &ri);
        assert!(matches!(ptr, Cow::Owned(_)));
        assert_eq!((&ptr[..], &adj[..]), (&[0, 2, 5, 7][..], &[0, 1, 0, 1, 2, 1, 2][..]));
    }

    #[test]
    fn nested_dissection_is_a_permutation() {
        let check = |cp: &[usize], ri: &[usize]| {
            let p = nested_dissection(cp, ri).unwrap();
            assert!(is_permutation(&p, cp.len() - 1), "{p:?}");
            // deterministic
            assert_eq!(p, nested_dissection(cp, ri).unwrap());
            p
        };
        // a plate-like grid with some prescribed unknowns; the members of a node stay together
        let (cp, ri) = grid(30, |node| if node % 7 == 0 { 4 } else { 6 });
        let p = check(&cp, &ri);
        let (ptr, adj) = closed_pattern(&cp, &ri);
        let sv = supervariables(&ptr, &adj);
        assert!(p.windows(2).filter(|w| sv.of[w[0]] != sv.of[w[1]]).count() == sv.len() - 1);
        // a structurally non-symmetric pattern with missing diagonal entries
        let mut e = Vec::new();
        let mut state = 12345u64;
        for _ in 0..3000 {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            e.push(((state >> 33) as usize % 500, (state >> 13) as usize % 500));
        }
        let (cp, ri) = pattern(500, &e);
        check(&cp, &ri);
        // two disconnected grids, a diagonal matrix, one unknown, none
        let (cp1, ri1) = grid(10, |_| 2);
        let m = cp1.len() - 1;
        let entries: Vec<(usize, usize)> = (0..m).flat_map(|j| ri1[cp1[j]..cp1[j + 1]].iter().flat_map(move |&i| [(i, j), (i + m, j + m)])).collect();
        let (cp, ri) = pattern(2 * m, &entries);
        check(&cp, &ri);
        let (cp, ri) = pattern(50, &(0..50).map(|i| (i, i)).collect::<Vec<_>>());
        check(&cp, &ri);
        check(&[0, 1], &[0]);
        assert!(nested_dissection(&[0], &[]).unwrap().is_empty());
    }

    #[test]
    fn nested_dissection_reduces_the_fill_of_a_grid() {
        // 80 x 80 nodes, 2 unknowns each
        let (cp, ri) = grid(80, |_| 2);
        let n = cp.len() - 1;
        let natural: Vec<usize> = (0..n).collect();
        let nd = nested_dissection(&cp, &ri).unwrap();
        let (l_natural, l_amd, l_nd) = (factor_len(&cp, &ri, Some(&natural)), factor_len(&cp, &ri, None), factor_len(&cp, &ri, Some(&nd)));
        println!("entries of L on an 80 x 80 grid, 2 unknowns per node: natural {l_natural}, AMD {l_amd}, ND {l_nd}");
        assert!(l_nd * 3 < l_natural, "{l_nd} vs {l_natural}");
        assert!(l_nd < l_amd, "{l_nd} vs {l_amd}");
        // the inverse permutation is not the ordering: faer's forward permutation is METIS's perm
        assert!(factor_len(&cp, &ri, Some(&inverse(&nd))) > l_nd);
    }

    #[test]
    fn faer_custom_ordering_takes_the_elimination_order() {
        // AMD's own permutation handed back as a custom ordering gives AMD's factor
        let (cp, ri) = grid(25, |_| 3);
        let n = cp.len() - 1;
        let a = SymbolicSparseColMatRef::new_checked(n, n, &cp, None, &ri);
        let amd = factorize_symbolic_cholesky(a, Side::Lower, SymmetricOrdering::Amd, Default::default()).unwrap();
        let fwd = amd.perm().unwrap().arrays().0.to_vec();
        assert_eq!(factor_len(&cp, &ri, Some(&fwd)), amd.len_val());
    }
}

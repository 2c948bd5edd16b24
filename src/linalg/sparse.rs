//! The sparsity pattern of the global tangent, built once from the element connectivity, and the
//! map from an element's local (row, column) dof pair to its slot in the compressed-column value
//! array, so that every assembly refills values in place.
//!
//! Columns and rows are equations (free dofs). Equations are numbered node-major, so the rows of a
//! column are the free dofs of the neighbouring nodes in node order: the slot of a local entry is
//! `col_ptr[column] + block_start[(a, b)] + rank(dof of a)`, with no search.

use crate::dofs::{DofMap, PRESCRIBED};
use crate::error::{Result, StampError};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};

/// The compressed-column pattern of the global matrix and the element-to-slot maps.
#[derive(Clone)]
pub struct SparsePattern {
    symbolic: SymbolicSparseColMat<usize>,
    /// For element e, `nodes_per_element^2` entries: offset of node a's rows inside the columns of
    /// node b, at index e * npe^2 + b * npe + a.
    block_start: Vec<u32>,
    /// For every dof, the number of free components of its node that precede it (u16: a plate of
    /// 257 surfaces has 771 dofs per node; a u8 wrapped past 255 and slotted entries of two dofs
    /// into one, which made plates of more than 85 surfaces "singular").
    rank: Vec<u16>,
    nodes_per_element: usize,
}

impl SparsePattern {
    /// The pattern of no equation (a model's before its first evaluation).
    pub fn empty() -> Self {
        SparsePattern { symbolic: SymbolicSparseColMat::new_checked(0, 0, vec![0], None, Vec::new()), block_start: Vec::new(), rank: Vec::new(), nodes_per_element: 0 }
    }

    /// Check the connectivity a pattern is built from: every element has `nodes_per_element`
    /// nodes below `num_nodes`, and every node belongs to some element (a stray point in a mesh
    /// file would be held by nothing).
    pub fn check_elements(num_nodes: usize, num_elements: usize, nodes_per_element: usize, element_nodes: impl Fn(usize) -> Vec<usize>) -> Result<()> {
        let mut used = vec![false; num_nodes];
        for e in 0..num_elements {
            let nodes = element_nodes(e);
            if nodes.len() != nodes_per_element {
                return Err(StampError::Mesh(format!("element {e} has {} nodes, expected {nodes_per_element}", nodes.len())));
            }
            for &a in &nodes {
                if a >= num_nodes {
                    return Err(StampError::Mesh(format!("element {e} refers to node {a}, the model has {num_nodes}")));
                }
                used[a] = true;
            }
        }
        match used.iter().position(|u| !u) {
            Some(orphan) => Err(StampError::Mesh(format!("node {orphan} belongs to no element, so nothing holds it (a stray point in the mesh file?)"))),
            None => Ok(()),
        }
    }

    /// Build the pattern of the matrix coupling all dofs of nodes that share an element.
    pub fn new(dofs: &DofMap, num_elements: usize, nodes_per_element: usize, element_nodes: impl Fn(usize) -> Vec<usize>) -> Result<Self> {
        Self::coupled(dofs, num_elements, nodes_per_element, element_nodes, &[])
    }

    /// The same, also coupling all dofs of the nodes of each group of `couplings` (an integrated
    /// contact's tangent couples the nodes of two cells that share a node: see
    /// [`crate::contact::ContactFace`]). Element slots are those of the larger pattern.
    pub fn coupled(dofs: &DofMap, num_elements: usize, nodes_per_element: usize, element_nodes: impl Fn(usize) -> Vec<usize>, couplings: &[Vec<usize>]) -> Result<Self> {
        Self::build(dofs, num_elements, nodes_per_element, element_nodes, couplings, None)
    }

    /// The pattern of some of the elements only (`subset[e]`, one flag per element) and of the
    /// groups of `couplings` that hold a node of theirs: the entries a process of a shared model
    /// needs (its elements' and the whole rows of its nodes, see [`crate::share`]). The nodes of
    /// no such element or group have no entries, not even on the diagonal; the other elements'
    /// slots are left out ([`slot`](Self::slot) is for the subset's elements only). Columns and
    /// rows are still all the equations.
    pub fn coupled_subset(dofs: &DofMap, num_elements: usize, nodes_per_element: usize, element_nodes: impl Fn(usize) -> Vec<usize>, couplings: &[Vec<usize>], subset: &[bool]) -> Result<Self> {
        if subset.len() != num_elements {
            return Err(StampError::Problem(format!("a subset of {} flags for {num_elements} elements", subset.len())));
        }
        Self::build(dofs, num_elements, nodes_per_element, element_nodes, couplings, Some(subset))
    }

    fn build(dofs: &DofMap, num_elements: usize, nodes_per_element: usize, element_nodes: impl Fn(usize) -> Vec<usize>, couplings: &[Vec<usize>], subset: Option<&[bool]>) -> Result<Self> {
        let nn = dofs.num_nodes();
        let dpn = dofs.dofs_per_node();
        let npe = nodes_per_element;
        Self::check_elements(nn, num_elements, npe, &element_nodes)?;
        let taken = |e: usize| subset.is_none_or(|s| s[e]);
        // node adjacency (each node of the pattern is its own neighbour; without a subset, every
        // node is of the pattern)
        let mut count = vec![usize::from(subset.is_none()); nn];
        let mut conn = Vec::with_capacity(num_elements * npe);
        for e in 0..num_elements {
            let nodes = element_nodes(e);
            if taken(e) {
                for &a in &nodes {
                    count[a] = count[a].max(1) + npe - 1;
                }
            }
            conn.extend_from_slice(&nodes);
        }
        for g in couplings {
            if let Some(&a) = g.iter().find(|&&a| a >= nn) {
                return Err(StampError::Mesh(format!("a coupling refers to node {a}, the model has {nn}")));
            }
        }
        // the groups of the pattern: all of them, or those that hold a node of the subset's
        // elements (their other nodes join the pattern)
        let groups: Vec<&Vec<usize>> = couplings.iter().filter(|g| subset.is_none() || g.iter().any(|&a| count[a] > 0)).collect();
        for g in &groups {
            for &a in g.iter() {
                count[a] = count[a].max(1) + g.len() - 1;
            }
        }
        let mut start = vec![0usize; nn + 1];
        for i in 0..nn {
            start[i + 1] = start[i] + count[i];
        }
        let mut adj = vec![0usize; start[nn]];
        let mut fill = start.clone();
        for i in (0..nn).filter(|&i| count[i] > 0) {
            adj[fill[i]] = i;
            fill[i] += 1;
        }
        for e in (0..num_elements).filter(|&e| taken(e)) {
            let nodes = &conn[e * npe..(e + 1) * npe];
            for &a in nodes {
                for &b in nodes {
                    if a != b {
                        adj[fill[a]] = b;
                        fill[a] += 1;
                    }
                }
            }
        }
        for g in &groups {
            for &a in g.iter() {
                for &b in g.iter() {
                    if a != b {
                        adj[fill[a]] = b;
                        fill[a] += 1;
                    }
                }
            }
        }
        // sort and deduplicate every node's neighbour list in place
        let mut nbr_start = vec![0usize; nn + 1];
        let mut nbr = Vec::with_capacity(adj.len() / 2);
        for i in 0..nn {
            let s = &mut adj[start[i]..start[i + 1]];
            s.sort_unstable();
            let mut last = usize::MAX;
            for &b in s.iter() {
                if b != last {
                    nbr.push(b);
                    last = b;
                }
            }
            nbr_start[i + 1] = nbr.len();
        }
        drop(adj);
        // free components per node and rank of each dof inside its node
        let eqs = dofs.equations();
        let mut free = vec![0u32; nn];
        if dpn > u16::MAX as usize {
            return Err(StampError::Problem(format!("{dpn} dofs per node is more than stamp can number (at most {})", u16::MAX)));
        }
        let mut rank = vec![0u16; nn * dpn];
        for n in 0..nn {
            let mut r = 0u16;
            for c in 0..dpn {
                rank[n * dpn + c] = r;
                if eqs[n * dpn + c] != PRESCRIBED {
                    r += 1;
                }
            }
            free[n] = r as u32;
        }
        // column pointers and row indices
        let neq = dofs.num_equations();
        let mut col_ptr = Vec::with_capacity(neq + 1);
        col_ptr.push(0usize);
        let mut col_len_of_node = vec![0usize; nn];
        for b in 0..nn {
            col_len_of_node[b] = nbr[nbr_start[b]..nbr_start[b + 1]].iter().map(|&a| free[a] as usize).sum();
        }
        let nnz: usize = (0..nn).map(|b| col_len_of_node[b] * free[b] as usize).sum();
        let mut row_idx = Vec::with_capacity(nnz);
        for b in 0..nn {
            for c in 0..dpn {
                if eqs[b * dpn + c] == PRESCRIBED {
                    continue;
                }
                for &a in &nbr[nbr_start[b]..nbr_start[b + 1]] {
                    for ca in 0..dpn {
                        let e = eqs[a * dpn + ca];
                        if e != PRESCRIBED {
                            row_idx.push(e as usize);
                        }
                    }
                }
                col_ptr.push(row_idx.len());
            }
        }
        debug_assert_eq!(col_ptr.len(), neq + 1);
        // element block offsets
        let mut block_start = vec![0u32; num_elements * npe * npe];
        for e in (0..num_elements).filter(|&e| taken(e)) {
            let nodes = &conn[e * npe..(e + 1) * npe];
            for (bl, &b) in nodes.iter().enumerate() {
                let list = &nbr[nbr_start[b]..nbr_start[b + 1]];
                for (al, &a) in nodes.iter().enumerate() {
                    let pos = list.binary_search(&a).expect("neighbour present by construction");
                    let off: usize = list[..pos].iter().map(|&x| free[x] as usize).sum();
                    block_start[e * npe * npe + bl * npe + al] = off as u32;
                }
            }
        }
        let symbolic = SymbolicSparseColMat::new_checked(neq, neq, col_ptr, None, row_idx);
        Ok(SparsePattern { symbolic, block_start, rank, nodes_per_element: npe })
    }

    /// The same pattern bordered by `border.len()` extra equations appended after the nodal ones:
    /// extra equation k couples with itself and with the equations of the dofs `border[k]`
    /// (prescribed dofs are skipped), in its row and in its column. The nodal columns keep their
    /// rows first, so element slots ([`slot`](Self::slot)) are unchanged.
    pub fn bordered(&self, dofs: &DofMap, border: &[Vec<usize>]) -> SparsePattern {
        let n0 = self.size();
        let nb = border.len();
        let mut coupled: Vec<Vec<usize>> = border.iter().map(|ds| {
            let mut v: Vec<usize> = ds.iter().filter_map(|&d| dofs.equation(d)).collect();
            v.sort_unstable();
            v.dedup();
            v
        }).collect();
        // extra rows of every nodal column
        let mut extra_rows: Vec<Vec<usize>> = vec![Vec::new(); n0];
        for (k, eqs) in coupled.iter().enumerate() {
            for &e in eqs {
                extra_rows[e].push(n0 + k);
            }
        }
        let (cp, ri) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        let mut col_ptr = Vec::with_capacity(n0 + nb + 1);
        let mut row_idx = Vec::with_capacity(ri.len() + 2 * coupled.iter().map(|c| c.len()).sum::<usize>() + nb);
        col_ptr.push(0);
        for j in 0..n0 {
            row_idx.extend_from_slice(&ri[cp[j]..cp[j + 1]]);
            row_idx.extend_from_slice(&extra_rows[j]);
            col_ptr.push(row_idx.len());
        }
        for (k, eqs) in coupled.iter_mut().enumerate() {
            eqs.push(n0 + k);
            row_idx.extend_from_slice(eqs);
            col_ptr.push(row_idx.len());
        }
        let symbolic = SymbolicSparseColMat::new_checked(n0 + nb, n0 + nb, col_ptr, None, row_idx);
        SparsePattern { symbolic, block_start: self.block_start.clone(), rank: self.rank.clone(), nodes_per_element: self.nodes_per_element }
    }

    /// The leading `n0` x `n0` block of this pattern: [`bordered`](Self::bordered)'s inverse (the
    /// rows of a column are sorted, so each column's first rows are the block's). Element slots
    /// are unchanged.
    pub fn unbordered(&self, n0: usize) -> SparsePattern {
        let n0 = n0.min(self.size());
        let (cp, ri) = (self.symbolic.col_ptr(), self.symbolic.row_idx());
        let mut col_ptr = Vec::with_capacity(n0 + 1);
        let mut row_idx = Vec::with_capacity(cp[n0]);
        col_ptr.push(0);
        for j in 0..n0 {
            let col = &ri[cp[j]..cp[j + 1]];
            row_idx.extend_from_slice(&col[..col.partition_point(|&i| i < n0)]);
            col_ptr.push(row_idx.len());
        }
        let symbolic = SymbolicSparseColMat::new_checked(n0, n0, col_ptr, None, row_idx);
        SparsePattern { symbolic, block_start: self.block_start.clone(), rank: self.rank.clone(), nodes_per_element: self.nodes_per_element }
    }

    /// Slot of the entry (row equation, column equation), if it is in the pattern (binary search).
    pub fn find(&self, row_eq: usize, col_eq: usize) -> Option<usize> {
        let cp = self.symbolic.col_ptr();
        if col_eq + 1 >= cp.len() {
            return None;
        }
        let col = cp[col_eq]..cp[col_eq + 1];
        self.symbolic.row_idx()[col.clone()].binary_search(&row_eq).ok().map(|p| col.start + p)
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.symbolic.row_idx().len()
    }

    /// Number of equations (rows = columns).
    pub fn size(&self) -> usize {
        self.symbolic.ncols()
    }

    /// The symbolic matrix.
    pub fn symbolic(&self) -> &SymbolicSparseColMat<usize> {
        &self.symbolic
    }

    /// A matrix view of `values` in this pattern.
    pub fn matrix<'a>(&'a self, values: &'a [f64]) -> SparseColMatRef<'a, usize, f64> {
        SparseColMatRef::new(self.symbolic.as_ref(), values)
    }

    /// Slot in the value array of the entry (row = dof `row_dof` at local node `a`, column = dof
    /// `col_dof` with equation `col_eq` at local node `b`) of element `e`.
    #[inline]
    pub fn slot(&self, e: usize, a: usize, b: usize, row_dof: usize, col_eq: usize) -> usize {
        let npe = self.nodes_per_element;
        self.symbolic.col_ptr()[col_eq] + self.block_start[e * npe * npe + b * npe + a] as usize + self.rank[row_dof] as usize
    }

    /// Slot of the first entry of the block (local node `a`, local node `b`) of element `e` in the
    /// column with equation `col_eq`: the row of dof d of node a sits at this + [`rank`](Self::rank)(d).
    #[inline]
    pub fn block_slot(&self, e: usize, a: usize, b: usize, col_eq: usize) -> usize {
        let npe = self.nodes_per_element;
        self.symbolic.col_ptr()[col_eq] + self.block_start[e * npe * npe + b * npe + a] as usize
    }

    /// Rank of a free dof among the free dofs of its node (its row offset inside a node block).
    #[inline]
    pub fn rank(&self, dof: usize) -> u32 {
        self.rank[dof] as u32
    }
}

/// Whether two compressed-column patterns are the same: the same arrays (a tangent and the
/// preconditioner a model builds in one pattern, found at once) or equal ones.
pub fn same_pattern(a: SymbolicSparseColMatRef<'_, usize>, b: SymbolicSparseColMatRef<'_, usize>) -> bool {
    let same = |x: &[usize], y: &[usize]| std::ptr::eq(x, y) || x == y;
    a.nrows() == b.nrows() && same(a.col_ptr(), b.col_ptr()) && same(a.row_idx(), b.row_idx())
}

/// Pair every stored entry (i, j) of a compressed-column pattern with the position of (j, i):
/// calls `pair(k, partner)` for each stored position k, in column order. Returns false (and stops)
/// as soon as an entry has no transposed partner or a row index is out of range: the pattern is
/// not symmetric. Row indices must be sorted within each column (faer's invariant).
pub fn pair_transposed(col_ptr: &[usize], row_idx: &[usize], mut pair: impl FnMut(usize, usize)) -> bool {
    let n = col_ptr.len() - 1;
    // walking the columns in order visits each row's entries by increasing column: the k-th entry
    // of row i met this way is (i, j_k), and its partner (j_k, i) is the k-th entry of column i
    let mut seen = vec![0usize; n];
    for j in 0..n {
        for k in col_ptr[j]..col_ptr[j + 1] {
            let i = row_idx[k];
            if i >= n {
                return false;
            }
            let partner = col_ptr[i] + seen[i];
            if partner >= col_ptr[i + 1] || row_idx[partner] != j {
                return false;
            }
            pair(k, partner);
            seen[i] += 1;
        }
    }
    (0..n).all(|i| seen[i] == col_ptr[i + 1] - col_ptr[i])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::QuadMesh;
    use std::collections::BTreeSet;

    /// A 4 x 3 mesh, 3 dofs per node, the left edge's first dof prescribed.
    fn setup() -> (QuadMesh, DofMap) {
        let mesh = QuadMesh::rectangle(0.0, 4.0, 0.0, 3.0, 4, 3).unwrap();
        let mut dofs = DofMap::new(mesh.num_nodes(), 3).unwrap();
        dofs.fix(mesh.group_nodes("left").unwrap(), &[0]).unwrap();
        (mesh, dofs)
    }

    fn entries(p: &SparsePattern) -> BTreeSet<(usize, usize)> {
        let (cp, ri) = (p.symbolic().col_ptr(), p.symbolic().row_idx());
        (0..p.size()).flat_map(|j| ri[cp[j]..cp[j + 1]].iter().map(move |&i| (i, j))).collect()
    }

    /// The equations of the free dofs of `nodes`.
    fn equations(dofs: &DofMap, nodes: &[usize]) -> Vec<usize> {
        nodes.iter().flat_map(|&n| (0..3).filter_map(move |c| dofs.equation(3 * n + c))).collect()
    }

    /// A subset's pattern holds exactly the pairs of its elements' equations (and a group's that
    /// touches them), and each of its elements' slots is its (row, column) entry there.
    #[test]
    fn a_subset_pattern_holds_its_elements_entries_and_their_slots() {
        let (mesh, dofs) = setup();
        let ne = mesh.num_cells();
        let nodes = |e: usize| mesh.cells[e].to_vec();
        let subset: Vec<bool> = (0..ne).map(|e| e % 4 == 1 || e == 6).collect();
        // a group that touches element 1's nodes, and one that does not
        let touching = vec![mesh.cells[1][0], mesh.cells[10][2]];
        let far = vec![mesh.cells[11][2], mesh.cells[8][0]];
        assert!(!subset[8] && !subset[10] && !subset[11] && !mesh.cells.iter().zip(&subset).any(|(c, s)| *s && (c.contains(&far[0]) || c.contains(&far[1]))));
        let p = SparsePattern::coupled_subset(&dofs, ne, 4, nodes, &[touching.clone(), far], &subset).unwrap();
        let mut want = BTreeSet::new();
        for group in (0..ne).filter(|&e| subset[e]).map(nodes).chain([touching]) {
            let eqs = equations(&dofs, &group);
            want.extend(eqs.iter().flat_map(|&i| eqs.iter().map(move |&j| (i, j))));
        }
        assert_eq!(entries(&p), want);
        assert_eq!(p.size(), dofs.num_equations());
        let (cp, ri) = (p.symbolic().col_ptr(), p.symbolic().row_idx());
        for e in (0..ne).filter(|&e| subset[e]) {
            let en = nodes(e);
            for (b, &nb) in en.iter().enumerate() {
                for cb in 0..3 {
                    let Some(col) = dofs.equation(3 * nb + cb) else { continue };
                    for (a, &na) in en.iter().enumerate() {
                        for ca in 0..3 {
                            let row_dof = 3 * na + ca;
                            let Some(row) = dofs.equation(row_dof) else { continue };
                            let slot = p.slot(e, a, b, row_dof, col);
                            assert!(slot >= cp[col] && slot < cp[col + 1] && ri[slot] == row, "element {e}: ({row}, {col})");
                        }
                    }
                }
            }
        }
        // every element: the whole pattern
        let all = SparsePattern::coupled_subset(&dofs, ne, 4, nodes, &[], &vec![true; ne]).unwrap();
        assert_eq!(entries(&all), entries(&SparsePattern::new(&dofs, ne, 4, nodes).unwrap()));
        assert!(SparsePattern::coupled_subset(&dofs, ne, 4, nodes, &[], &[true]).is_err());
    }

    /// Nodes of many dofs (a plate of 100 surfaces: 300 per node, some prescribed): every local
    /// entry has a slot of its own holding its (row, column) (a rank kept in a u8 wrapped at 256).
    #[test]
    fn nodes_of_hundreds_of_dofs_get_a_slot_for_every_entry() {
        let dpn = 300;
        let mesh = QuadMesh::rectangle(0.0, 2.0, 0.0, 1.0, 2, 1).unwrap();
        let mut dofs = DofMap::new(mesh.num_nodes(), dpn).unwrap();
        dofs.fix(mesh.group_nodes("left").unwrap(), &[0, 7, 299]).unwrap();
        let ne = mesh.num_cells();
        let p = SparsePattern::new(&dofs, ne, 4, |e| mesh.cells[e].to_vec()).unwrap();
        let (cp, ri) = (p.symbolic().col_ptr(), p.symbolic().row_idx());
        let mut seen = std::collections::HashSet::new();
        for e in 0..ne {
            let en = mesh.cells[e];
            for (b, &nb) in en.iter().enumerate() {
                for cb in 0..dpn {
                    let Some(col) = dofs.equation(dpn * nb + cb) else { continue };
                    for (a, &na) in en.iter().enumerate() {
                        for ca in 0..dpn {
                            let row_dof = dpn * na + ca;
                            let Some(row) = dofs.equation(row_dof) else { continue };
                            let slot = p.slot(e, a, b, row_dof, col);
                            assert!(slot >= cp[col] && slot < cp[col + 1] && ri[slot] == row, "element {e}: ({row}, {col}) at slot {slot}");
                            seen.insert(slot);
                        }
                    }
                }
            }
        }
        assert_eq!(seen.len(), p.nnz());
    }

    /// `unbordered` undoes `bordered`, element slots included.
    #[test]
    fn unbordered_undoes_bordered() {
        let (mesh, dofs) = setup();
        let ne = mesh.num_cells();
        let p = SparsePattern::new(&dofs, ne, 4, |e| mesh.cells[e].to_vec()).unwrap();
        let b = p.bordered(&dofs, &[vec![3, 4, 5, 30, 31], vec![12, 13]]);
        assert_eq!(b.size(), p.size() + 2);
        let u = b.unbordered(p.size());
        assert_eq!(entries(&u), entries(&p));
        assert_eq!(u.symbolic().col_ptr(), p.symbolic().col_ptr());
        assert_eq!(u.slot(5, 1, 2, 3 * mesh.cells[5][1], dofs.equation(3 * mesh.cells[5][2]).unwrap()), p.slot(5, 1, 2, 3 * mesh.cells[5][1], dofs.equation(3 * mesh.cells[5][2]).unwrap()));
    }
}

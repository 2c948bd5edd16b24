//! Uniform refinement of a quadrilateral mesh: every cell is cut into four at its edge midpoints
//! and its centre (the mean of its corners), so the refined mesh has the nodes of the mesh (same
//! indices, first), then one node per edge, then one per cell. The new nodes lie on the straight
//! edges: the refined mesh covers exactly the same polygon (a curved boundary is not followed).
//!
//! Groups carry over ([`Refinement`] maps them): a cell group gets the four children of each of
//! its cells; a line made of 2-node segments is cut at the midpoints of its segments
//! ([`Refinement::segments`]); a point group keeps its nodes. A node group of the mesh gets the
//! nodes of its cells when a cell group has the same name, else the midpoint of every edge whose
//! two ends are in the group and the centre of every cell whose four corners are (callers that
//! know their lines, like physical curves, should rebuild those groups from
//! [`Refinement::segments`]).

use crate::mesh::QuadMesh;
use std::collections::{BTreeSet, HashMap};

/// A refined mesh and how it was made from the coarse one.
#[derive(Debug, Clone)]
pub struct Refinement {
    /// The refined mesh (validated like any mesh), with the coarse mesh's groups carried over.
    pub mesh: QuadMesh,
    /// Nodes of the coarse mesh: they keep their indices in the refined mesh.
    pub coarse_nodes: usize,
    /// The new node at the midpoint of each coarse edge, by its sorted end nodes.
    midpoints: HashMap<(usize, usize), usize>,
    /// The new node at the centre of each coarse cell.
    pub centres: Vec<usize>,
    /// The four cells each coarse cell became (cell c's children are 4c .. 4c + 3).
    pub children: Vec<[usize; 4]>,
}

fn key(a: usize, b: usize) -> (usize, usize) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

impl Refinement {
    /// The node at the midpoint of the coarse edge from `a` to `b` (None: not an edge of a cell).
    pub fn midpoint(&self, a: usize, b: usize) -> Option<usize> {
        self.midpoints.get(&key(a, b)).copied()
    }

    /// Number of edges of the coarse mesh (one new node each).
    pub fn coarse_edges(&self) -> usize {
        self.midpoints.len()
    }

    /// A line of 2-node segments on the refined mesh: every segment that is a cell edge becomes
    /// its two halves, in the direction given; a segment that is no cell edge stays whole.
    pub fn segments(&self, segments: &[[usize; 2]]) -> Vec<[usize; 2]> {
        let mut out = Vec::with_capacity(2 * segments.len());
        for &[a, b] in segments {
            match self.midpoint(a, b) {
                Some(m) => out.extend([[a, m], [m, b]]),
                None => out.push([a, b]),
            }
        }
        out
    }

    /// The refined cells of a list of coarse cells (each becomes its four children, in order).
    pub fn cells(&self, cells: &[usize]) -> Vec<usize> {
        cells.iter().flat_map(|&c| self.children[c]).collect()
    }

    /// A value per coarse cell repeated on its four children (e.g. the element tag it came from).
    pub fn cell_values<T: Clone>(&self, values: &[T]) -> Vec<T> {
        values.iter().flat_map(|v| std::iter::repeat_n(v.clone(), 4)).collect()
    }
}

/// Cut every cell of `mesh` into four (see the module notes). The refined cells keep the
/// counter-clockwise order of their parent: child k holds corner k of the parent.
pub fn refine(mesh: &QuadMesh) -> Refinement {
    let n0 = mesh.num_nodes();
    let mut coords = mesh.coords.clone();
    let mut midpoints: HashMap<(usize, usize), usize> = HashMap::with_capacity(2 * mesh.num_cells() + 16);
    for cell in &mesh.cells {
        for i in 0..4 {
            let (a, b) = (cell[i], cell[(i + 1) % 4]);
            midpoints.entry(key(a, b)).or_insert_with(|| {
                let (x, y) = (mesh.coords[a], mesh.coords[b]);
                coords.push([0.5 * (x[0] + y[0]), 0.5 * (x[1] + y[1])]);
                coords.len() - 1
            });
        }
    }
    let mut centres = Vec::with_capacity(mesh.num_cells());
    let mut cells = Vec::with_capacity(4 * mesh.num_cells());
    let mut children = Vec::with_capacity(mesh.num_cells());
    for cell in &mesh.cells {
        let x = cell.map(|n| mesh.coords[n]);
        coords.push([0.25 * (x[0][0] + x[1][0] + x[2][0] + x[3][0]), 0.25 * (x[0][1] + x[1][1] + x[2][1] + x[3][1])]);
        let c = coords.len() - 1;
        centres.push(c);
        let m = [0, 1, 2, 3].map(|i| midpoints[&key(cell[i], cell[(i + 1) % 4])]);
        let first = cells.len();
        for k in 0..4 {
            // corner k, the midpoint after it, the centre, the midpoint before it
            cells.push([cell[k], m[k], c, m[(k + 3) % 4]]);
        }
        children.push([first, first + 1, first + 2, first + 3]);
    }
    let mut r = Refinement { mesh: QuadMesh { coords, cells, ..Default::default() }, coarse_nodes: n0, midpoints, centres, children };
    for (name, cs) in &mesh.cell_groups {
        r.mesh.cell_groups.insert(name.clone(), r.cells(cs));
    }
    for (name, nodes) in &mesh.node_groups {
        let refined = match r.mesh.cell_groups.get(name) {
            Some(cs) => cs.iter().flat_map(|&c| r.mesh.cells[c]).collect::<BTreeSet<usize>>(),
            None => {
                let set: BTreeSet<usize> = nodes.iter().copied().collect();
                let mut out = set.clone();
                for (&(a, b), &m) in &r.midpoints {
                    if set.contains(&a) && set.contains(&b) {
                        out.insert(m);
                    }
                }
                for (c, cell) in mesh.cells.iter().enumerate() {
                    if cell.iter().all(|n| set.contains(n)) {
                        out.insert(r.centres[c]);
                    }
                }
                out
            }
        };
        r.mesh.node_groups.insert(name.clone(), refined.into_iter().collect());
    }
    r
}

/// The (nodes, cells) of `mesh` refined 1, 2, ..., `levels` times, counted without refining:
/// a refinement adds a node per edge and per cell, cuts every edge in two and adds four edges per
/// cell (u64: no overflow for any level a caller could ask).
pub fn refined_sizes(mesh: &QuadMesh, levels: usize) -> Vec<(u64, u64)> {
    let edges: std::collections::HashSet<(usize, usize)> =
        mesh.cells.iter().flat_map(|c| (0..4).map(move |i| key(c[i], c[(i + 1) % 4]))).collect();
    let (mut n, mut e, mut c) = (mesh.num_nodes() as u64, edges.len() as u64, mesh.num_cells() as u64);
    let mut out = Vec::with_capacity(levels);
    for _ in 0..levels {
        n = n.saturating_add(e).saturating_add(c);
        e = e.saturating_mul(2).saturating_add(c.saturating_mul(4));
        c = c.saturating_mul(4);
        out.push((n, c));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(m: &QuadMesh) -> f64 {
        (0..m.num_cells()).map(|c| crate::mesh::quad_signed_area(&m.cell_coords(c))).sum()
    }

    /// A distorted 3 x 2 mesh (no cell a parallelogram) with groups.
    fn distorted() -> QuadMesh {
        let mut m = QuadMesh::rectangle(0.0, 3.0, 0.0, 2.0, 3, 2).unwrap();
        for (i, x) in m.coords.iter_mut().enumerate() {
            x[0] += 0.13 * ((i * 7 % 5) as f64 - 2.0) * x[1] * (2.0 - x[1]) / 2.0;
            x[1] += 0.11 * ((i * 3 % 4) as f64 - 1.5) * x[0] * (3.0 - x[0]) / 3.0;
        }
        m.validate().unwrap();
        m.cell_groups.insert("left_cells".into(), vec![0, 3]);
        m.node_groups.insert("left_cells".into(), vec![0, 1, 4, 5, 8, 9]);
        m
    }

    #[test]
    fn counts_follow_euler() {
        let m = distorted();
        let r = refine(&m);
        // a 3 x 2 grid: 12 nodes, 6 cells, 17 edges
        assert_eq!(r.coarse_edges(), 17);
        assert_eq!(r.mesh.num_nodes(), 12 + 17 + 6);
        assert_eq!(r.mesh.num_cells(), 24);
        assert_eq!(r.mesh.coords[..12], m.coords[..], "the coarse nodes keep their indices");
        r.mesh.validate().expect("every refined cell counter-clockwise and convex");
        let rr = refine(&r.mesh);
        assert_eq!((rr.mesh.num_nodes(), rr.mesh.num_cells()), (13 * 9, 96), "twice: the 12 x 8 grid");
        let counted = refined_sizes(&m, 3);
        assert_eq!(counted[..2], [(35, 24), (117, 96)]);
        assert_eq!(counted[2], (25 * 17, 384));
    }

    #[test]
    fn area_is_conserved_cell_by_cell() {
        let m = distorted();
        let r = refine(&m);
        for c in 0..m.num_cells() {
            let a = crate::mesh::quad_signed_area(&m.cell_coords(c));
            let children: f64 = r.children[c].iter().map(|&k| crate::mesh::quad_signed_area(&r.mesh.cell_coords(k))).sum();
            assert!((a - children).abs() < 1e-13 * a, "cell {c}: {a} against {children}");
        }
        assert!((area(&r.mesh) - area(&m)).abs() < 1e-12);
        // the nodal (tributary) areas add up to the area too
        let w: f64 = r.mesh.nodal_areas().iter().sum();
        assert!((w - area(&m)).abs() < 1e-12, "{w}");
    }

    #[test]
    fn a_structured_mesh_refined_is_the_structured_mesh_of_twice_the_cells() {
        let r = refine(&QuadMesh::rectangle(-1.0, 2.0, 0.5, 1.5, 3, 2).unwrap());
        let fine = QuadMesh::rectangle(-1.0, 2.0, 0.5, 1.5, 6, 4).unwrap();
        let pts = |m: &QuadMesh| m.coords.iter().map(|x| ((x[0] * 1e9).round() as i64, (x[1] * 1e9).round() as i64)).collect::<BTreeSet<_>>();
        assert_eq!(pts(&r.mesh), pts(&fine));
        let left: BTreeSet<(i64, i64)> = r.mesh.node_groups["left"].iter().map(|&n| ((r.mesh.coords[n][0] * 1e9).round() as i64, (r.mesh.coords[n][1] * 1e9).round() as i64)).collect();
        let want: BTreeSet<(i64, i64)> = fine.node_groups["left"].iter().map(|&n| ((fine.coords[n][0] * 1e9).round() as i64, (fine.coords[n][1] * 1e9).round() as i64)).collect();
        assert_eq!(left, want, "the node group of an edge gets the edge's midpoints");
        assert_eq!(r.mesh.cell_groups["all"].len(), 24);
    }

    #[test]
    fn groups_carry_over() {
        let m = distorted();
        let r = refine(&m);
        assert_eq!(r.mesh.cell_groups["left_cells"], vec![0, 1, 2, 3, 12, 13, 14, 15]);
        let nodes = &r.mesh.node_groups["left_cells"];
        let want: BTreeSet<usize> = r.mesh.cell_groups["left_cells"].iter().flat_map(|&c| r.mesh.cells[c]).collect();
        assert_eq!(nodes.iter().copied().collect::<BTreeSet<_>>(), want, "a node group named like a cell group: its cells' nodes");
        assert_eq!(nodes.len(), 15);
        // a line: the bottom edge 0-1-2-3 becomes 6 segments through the midpoints, in order
        let segs = r.segments(&[[0, 1], [1, 2], [2, 3]]);
        assert_eq!(segs.len(), 6);
        for w in segs.windows(2) {
            assert_eq!(w[0][1], w[1][0], "a connected chain: {segs:?}");
        }
        let mid = r.midpoint(1, 0).unwrap();
        assert_eq!(segs[0], [0, mid]);
        let (a, b, x) = (m.coords[0], m.coords[1], r.mesh.coords[mid]);
        assert_eq!(x, [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])]);
        assert_eq!(r.segments(&[[0, 5]]), vec![[0, 5]], "a diagonal is no edge: kept whole");
        assert_eq!(r.cell_values(&[7u64, 9]), vec![7, 7, 7, 7, 9, 9, 9, 9]);
    }

    #[test]
    fn refined_twice_is_consistent() {
        // refining twice equals cutting each coarse cell into 4 x 4: same node set, area, and the
        // coarse edge chain of the "bottom" group becomes four times as many segments
        let m = distorted();
        let r1 = refine(&m);
        let r2 = refine(&r1.mesh);
        assert_eq!(r2.coarse_nodes, r1.mesh.num_nodes());
        assert_eq!(r2.mesh.coords[..r1.mesh.num_nodes()], r1.mesh.coords[..]);
        assert!((area(&r2.mesh) - area(&m)).abs() < 1e-12);
        let bottom = [[0usize, 1], [1, 2], [2, 3]];
        let twice = r2.segments(&r1.segments(&bottom));
        assert_eq!(twice.len(), 12);
        let g = &r2.mesh.node_groups["bottom"];
        let on_chain: BTreeSet<usize> = twice.iter().flatten().copied().collect();
        assert_eq!(g.iter().copied().collect::<BTreeSet<_>>(), on_chain, "node group and line agree");
        // every cell of the twice-refined mesh lies in exactly one coarse cell: its centre is in it
        for c in 0..m.num_cells() {
            let grand: Vec<usize> = r1.children[c].iter().flat_map(|&k| r2.children[k]).collect();
            let a: f64 = grand.iter().map(|&k| crate::mesh::quad_signed_area(&r2.mesh.cell_coords(k))).sum();
            let a0 = crate::mesh::quad_signed_area(&m.cell_coords(c));
            assert!((a - a0).abs() < 1e-13 * a0);
        }
    }
}

//! gmsh element types: their names, node counts, and how the accepted surface types become 4-node
//! quadrilaterals.
//!
//! The plate element is the 4-node quadrilateral, so every accepted surface element is cut into
//! quadrilaterals:
//! * a 3-node triangle into three, at its centroid and edge midpoints;
//! * a 6-node triangle into three, at its own mid-edge nodes and a new centre node (the quadratic
//!   map's centre, -1/9 sum(corners) + 4/9 sum(mid-edge nodes));
//! * a 9-node quadrilateral into four on its own nodes;
//! * an 8-node quadrilateral into four with a new centre node (the serendipity map's centre,
//!   sum(mid-edge)/2 - sum(corners)/4);
//! * a 4-node quadrilateral stays whole, unless the mesh also has elements with edge midpoints
//!   (triangles or second-order elements): then it is cut into four at its edge midpoints and the
//!   mean of its corners, so that no edge of the mesh ends up with a node on one side only.
//!
//! New edge midpoints are keyed by the sorted pair of corner tags so the two cells on an edge share
//! them; a second-order element's own mid-edge node is registered under its edge first, so it is the
//! one shared.

/// The types stamp accepts, for messages.
pub(crate) const SUPPORTED: &str = "stamp accepts surface meshes of 3- or 6-node triangles (types 2, 9) and 4-, 8- or \
     9-node quadrilaterals (types 3, 16, 10) with 2- or 3-node lines (types 1, 8) and points (type 15)";

pub(crate) const LINE2: i32 = 1;
pub(crate) const TRI3: i32 = 2;
pub(crate) const QUAD4: i32 = 3;
pub(crate) const LINE3: i32 = 8;
pub(crate) const TRI6: i32 = 9;
pub(crate) const QUAD9: i32 = 10;
pub(crate) const POINT: i32 = 15;
pub(crate) const QUAD8: i32 = 16;

/// Nodes per element of the accepted types.
pub(crate) fn nodes_per_element(ty: i32) -> Option<usize> {
    match ty {
        LINE2 => Some(2),
        TRI3 => Some(3),
        QUAD4 => Some(4),
        LINE3 => Some(3),
        TRI6 => Some(6),
        QUAD9 => Some(9),
        POINT => Some(1),
        QUAD8 => Some(8),
        _ => None,
    }
}

/// The dimension of the entity an accepted type lies on.
pub(crate) fn dimension(ty: i32) -> i32 {
    match ty {
        POINT => 0,
        LINE2 | LINE3 => 1,
        _ => 2,
    }
}

/// A gmsh element type in words.
pub(crate) fn element_type_name(ty: i32) -> &'static str {
    match ty {
        1 => "2-node line",
        2 => "3-node triangle",
        3 => "4-node quadrilateral",
        4 => "4-node tetrahedron",
        5 => "8-node hexahedron",
        6 => "6-node prism",
        7 => "5-node pyramid",
        8 => "3-node line",
        9 => "6-node triangle",
        10 => "9-node quadrilateral",
        11 => "10-node tetrahedron",
        12 => "27-node hexahedron",
        13 => "18-node prism",
        14 => "14-node pyramid",
        15 => "point",
        16 => "8-node quadrilateral",
        17 => "20-node hexahedron",
        18 => "15-node prism",
        19 => "13-node pyramid",
        20 => "9-node triangle (third order, incomplete)",
        21 => "10-node triangle (third order)",
        22 => "12-node triangle (fourth order, incomplete)",
        23 => "15-node triangle (fourth order)",
        24 => "15-node triangle (fifth order, incomplete)",
        25 => "21-node triangle (fifth order)",
        26 => "4-node line (third order)",
        27 => "5-node line (fourth order)",
        28 => "6-node line (fifth order)",
        29 => "20-node tetrahedron",
        30 => "35-node tetrahedron",
        31 => "56-node tetrahedron",
        36 => "16-node quadrilateral (third order)",
        37 => "25-node quadrilateral (fourth order)",
        38 => "36-node quadrilateral (fifth order)",
        92 => "64-node hexahedron",
        93 => "125-node hexahedron",
        _ => "unknown type",
    }
}

/// A node of a sub-cell: a node of the file (index in file order) or a new one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum NodeRef {
    File(usize),
    New(usize),
}

/// Positions of new nodes as weights of file nodes.
#[derive(Debug, Default)]
pub(crate) struct NewNodes {
    /// Weighted file nodes of each new node.
    pub weights: Vec<Vec<(usize, f64)>>,
    /// Edge (sorted pair of file indices) -> its midpoint.
    pub midpoints: std::collections::HashMap<(usize, usize), NodeRef>,
}

impl NewNodes {
    fn add(&mut self, w: Vec<(usize, f64)>) -> NodeRef {
        self.weights.push(w);
        NodeRef::New(self.weights.len() - 1)
    }

    /// Registers a second-order element's own mid-edge node for edge (a, b).
    pub fn register_mid(&mut self, a: usize, b: usize, mid: usize) {
        self.midpoints.entry((a.min(b), a.max(b))).or_insert(NodeRef::File(mid));
    }

    /// The shared midpoint of edge (a, b), made if new.
    pub fn midpoint(&mut self, a: usize, b: usize) -> NodeRef {
        let key = (a.min(b), a.max(b));
        if let Some(&m) = self.midpoints.get(&key) {
            return m;
        }
        let m = self.add(vec![(a, 0.5), (b, 0.5)]);
        self.midpoints.insert(key, m);
        m
    }

    /// The midpoint of (a, b) if the edge has one.
    pub fn existing_midpoint(&self, a: usize, b: usize) -> Option<NodeRef> {
        self.midpoints.get(&(a.min(b), a.max(b))).copied()
    }
}

/// Cuts one surface element (node indices in the file's order, gmsh node order) into
/// quadrilaterals. `split_quads` cuts 4-node quadrilaterals too.
pub(crate) fn split_surface(ty: i32, n: &[usize], split_quads: bool, new: &mut NewNodes) -> Vec<[NodeRef; 4]> {
    use NodeRef::File as F;
    let fan = |corners: &[NodeRef], mids: &[NodeRef], centre: NodeRef| -> Vec<[NodeRef; 4]> {
        let k = corners.len();
        (0..k).map(|i| [corners[i], mids[i], centre, mids[(i + k - 1) % k]]).collect()
    };
    match ty {
        QUAD4 if !split_quads => vec![[F(n[0]), F(n[1]), F(n[2]), F(n[3])]],
        QUAD4 | TRI3 => {
            let k = if ty == QUAD4 { 4 } else { 3 };
            let corners: Vec<NodeRef> = n[..k].iter().map(|&i| F(i)).collect();
            let mids: Vec<NodeRef> = (0..k).map(|i| new.midpoint(n[i], n[(i + 1) % k])).collect();
            let centre = new.add(n[..k].iter().map(|&i| (i, 1.0 / k as f64)).collect());
            fan(&corners, &mids, centre)
        }
        TRI6 => {
            let mut w: Vec<(usize, f64)> = n[..3].iter().map(|&i| (i, -1.0 / 9.0)).collect();
            w.extend(n[3..6].iter().map(|&i| (i, 4.0 / 9.0)));
            let centre = new.add(w);
            let corners: Vec<NodeRef> = n[..3].iter().map(|&i| F(i)).collect();
            let mids: Vec<NodeRef> = n[3..6].iter().map(|&i| F(i)).collect();
            fan(&corners, &mids, centre)
        }
        QUAD8 | QUAD9 => {
            let centre = if ty == QUAD9 {
                F(n[8])
            } else {
                let mut w: Vec<(usize, f64)> = n[..4].iter().map(|&i| (i, -0.25)).collect();
                w.extend(n[4..8].iter().map(|&i| (i, 0.5)));
                new.add(w)
            };
            let corners: Vec<NodeRef> = n[..4].iter().map(|&i| F(i)).collect();
            let mids: Vec<NodeRef> = n[4..8].iter().map(|&i| F(i)).collect();
            fan(&corners, &mids, centre)
        }
        _ => Vec::new(),
    }
}

/// Registers the mid-edge nodes of a second-order surface element.
pub(crate) fn register_mids(ty: i32, n: &[usize], new: &mut NewNodes) {
    let k = match ty {
        TRI6 => 3,
        QUAD8 | QUAD9 => 4,
        _ => return,
    };
    for i in 0..k {
        new.register_mid(n[i], n[(i + 1) % k], n[k + i]);
    }
}

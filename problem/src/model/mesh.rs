//! The mesh of a problem with its groups by dimension: read from gmsh, or the built-in rectangle.
//!
//! The built-in `rectangle = {x = [a, b], y = [c, d], n = [nx, ny]}` has the curve groups `left`
//! (x = a), `right` (x = b), `bottom` (y = c), `top` (y = d) and `boundary` (all four), the surface
//! group `all`, and the point groups `corner_ll` (a, c), `corner_lr` (b, c), `corner_ur` (b, d),
//! `corner_ul` (a, d) and, when nx and ny are even, `center`.

use crate::checks::rigid_modes::num;
use crate::model::memory::check_model_fits;
use crate::schema::Problem;
use stamp::io::read_msh;
use stamp::mesh::QuadMesh;
use stamp::{Result, StampError};
use std::collections::BTreeMap;
use toml::Spanned;

/// A mesh and its named groups.
pub struct MeshData {
    pub mesh: QuadMesh,
    /// Physical points: name -> nodes.
    pub points: BTreeMap<String, Vec<usize>>,
    /// Physical curves: name -> 2-node segments.
    pub curves: BTreeMap<String, Vec<[usize; 2]>>,
    /// Physical surfaces: name -> cells (also in `mesh.cell_groups`).
    pub surfaces: BTreeMap<String, Vec<usize>>,
    /// gmsh node tags (for the CSV), if read from gmsh.
    pub node_tags: Option<Vec<u64>>,
    /// gmsh element tag of each cell (for error messages), if read from gmsh.
    pub cell_tags: Option<Vec<u64>>,
    /// What the reader cut into 4-node cells (triangles, second-order cells), e.g. "113 3-node
    /// triangles split into 339 quadrilaterals"; None when the file's cells were used as they are.
    pub split: Option<String>,
}

impl MeshData {
    /// The lowest and highest (x1, x2) of the nodes.
    pub fn bounding_box(&self) -> ([f64; 2], [f64; 2]) {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for c in &self.mesh.coords {
            for i in 0..2 {
                lo[i] = lo[i].min(c[i]);
                hi[i] = hi[i].max(c[i]);
            }
        }
        (lo, hi)
    }

    /// Load the mesh the problem names.
    pub fn load(p: &Problem) -> Result<MeshData> {
        let spec = p.spec.mesh.get_ref();
        if let Some(g) = &p.given_mesh {
            // gmsh tags are no help with arrays: nodes are named by their coordinates
            Ok(MeshData { node_tags: None, cell_tags: None, ..Self::of_gmsh(g.as_ref().clone()) })
        } else if let Some(file) = &spec.file {
            Self::read(p, file, "mesh.file")
        } else {
            let r = spec.rectangle.as_ref().expect("checked: file or rectangle");
            // refused before its nodes are allocated when its model cannot fit
            let nodes = (r.n[0] as u64 + 1) * (r.n[1] as u64 + 1);
            check_model_fits(nodes, p.spec.plate.get_ref().dofs_per_node()).map_err(|e| {
                // the `rectangle` key after the [mesh] header (its span is the header's)
                let at = p.spec.mesh.span().start;
                let at = p.source.get(at..).and_then(|t| t.find("rectangle")).map_or(at, |k| at + k);
                p.error_at(at..at, "mesh.rectangle.n", format!("[{}, {}]: {e}", r.n[0], r.n[1]))
            })?;
            Self::rectangle(r, r.n[0], r.n[1])
        }
    }

    /// The coarse mesh of `[solver] predictor = "coarse"`: the rectangle with half its n (checked
    /// even), or `mesh.coarse_file`. Errors name the coarse file.
    pub fn load_coarse(p: &Problem) -> Result<MeshData> {
        let spec = p.spec.mesh.get_ref();
        match (&spec.rectangle, &spec.coarse_file) {
            (Some(r), _) => Self::rectangle(r, r.n[0] / 2, r.n[1] / 2),
            (None, Some(file)) => Self::read(p, file, "mesh.coarse_file"),
            (None, None) => Err(p.error_at(p.spec.mesh.span(), "mesh.coarse_file", "is needed for predictor = \"coarse\" with a gmsh mesh")),
        }
    }

    /// The gmsh file `file` (given at `key`), relative to the problem file.
    fn read(p: &Problem, file: &Spanned<String>, key: &str) -> Result<MeshData> {
        let path = p.dir().join(file.get_ref());
        if !path.exists() {
            return Err(p.error_at(file.span(), key, format!("{} does not exist", stamp::show_path(&path))));
        }
        // the reader names the .msh file; the problem file and its key say where it was asked for
        let g = read_msh(&path).map_err(|e| match e {
            StampError::Input { file, message } => StampError::Input { file, message: format!("{message} (read as {key} of {})", stamp::show_path(&p.path)) },
            e => e,
        })?;
        Ok(Self::of_gmsh(g))
    }

    /// A mesh read by the gmsh reader (or given as arrays) with its groups.
    fn of_gmsh(g: stamp::io::GmshMesh) -> MeshData {
        let surfaces = g.mesh.cell_groups.clone();
        let split = g.split_summary();
        MeshData { points: g.point_groups, curves: g.curve_groups, surfaces, node_tags: Some(g.node_tags), cell_tags: Some(g.cell_tags), mesh: g.mesh, split }
    }

    /// The built-in rectangle `r` with nx x ny cells and its named groups.
    fn rectangle(r: &crate::schema::RectangleSpec, nx: usize, ny: usize) -> Result<MeshData> {
        let mut mesh = QuadMesh::rectangle(r.x[0], r.x[1], r.y[0], r.y[1], nx, ny)?;
        let id = |i: usize, j: usize| j * (nx + 1) + i;
        let mut curves = BTreeMap::new();
        let chain = |nodes: Vec<usize>| nodes.windows(2).map(|w| [w[0], w[1]]).collect::<Vec<_>>();
        curves.insert("bottom".to_string(), chain((0..=nx).map(|i| id(i, 0)).collect()));
        curves.insert("right".to_string(), chain((0..=ny).map(|j| id(nx, j)).collect()));
        curves.insert("top".to_string(), chain((0..=nx).rev().map(|i| id(i, ny)).collect()));
        curves.insert("left".to_string(), chain((0..=ny).rev().map(|j| id(0, j)).collect()));
        let boundary: Vec<[usize; 2]> = ["bottom", "right", "top", "left"].iter().flat_map(|k| curves[*k].clone()).collect();
        curves.insert("boundary".to_string(), boundary);
        let mut points = BTreeMap::new();
        points.insert("corner_ll".to_string(), vec![id(0, 0)]);
        points.insert("corner_lr".to_string(), vec![id(nx, 0)]);
        points.insert("corner_ur".to_string(), vec![id(nx, ny)]);
        points.insert("corner_ul".to_string(), vec![id(0, ny)]);
        if nx % 2 == 0 && ny % 2 == 0 {
            points.insert("center".to_string(), vec![id(nx / 2, ny / 2)]);
        }
        let mut bnodes: Vec<usize> = curves["boundary"].iter().flatten().copied().collect();
        bnodes.sort_unstable();
        bnodes.dedup();
        mesh.node_groups.insert("boundary".into(), bnodes);
        mesh.node_groups.insert("all".into(), (0..mesh.num_nodes()).collect());
        for (k, v) in &points {
            mesh.node_groups.insert(k.clone(), v.clone());
        }
        let surfaces = mesh.cell_groups.clone();
        Ok(MeshData { mesh, points, curves, surfaces, node_tags: None, cell_tags: None, split: None })
    }

    /// The uniform refinement of this mesh ([`stamp::mesh::refine`]: every cell into four at its edge
    /// midpoints and centre). Point groups keep their nodes, curves are cut at the midpoints of
    /// their segments, surfaces get the four children of each cell; the node groups of curves and
    /// points are rebuilt from those. New nodes have gmsh tag 0; a cell keeps the tag of the
    /// element it was cut from.
    pub fn refined(&self) -> MeshData {
        let r = stamp::mesh::refine::refine(&self.mesh);
        let curves: BTreeMap<String, Vec<[usize; 2]>> = self.curves.iter().map(|(k, s)| (k.clone(), r.segments(s))).collect();
        let surfaces = self.surfaces.iter().map(|(k, c)| (k.clone(), r.cells(c))).collect();
        let mut mesh = r.mesh.clone();
        for (k, segs) in &curves {
            if mesh.node_groups.contains_key(k) && !self.surfaces.contains_key(k) {
                let mut v: Vec<usize> = segs.iter().flatten().copied().collect();
                // a name used by a point group as well holds both (as the gmsh reader does)
                v.extend(self.points.get(k).into_iter().flatten());
                v.sort_unstable();
                v.dedup();
                mesh.node_groups.insert(k.clone(), v);
            }
        }
        for (k, nodes) in &self.points {
            if !curves.contains_key(k) && !self.surfaces.contains_key(k) && mesh.node_groups.contains_key(k) {
                mesh.node_groups.insert(k.clone(), nodes.clone());
            }
        }
        let node_tags = self.node_tags.as_ref().map(|t| {
            let mut v = t.clone();
            v.resize(mesh.num_nodes(), 0);
            v
        });
        let cell_tags = self.cell_tags.as_ref().map(|t| r.cell_values(t));
        MeshData { mesh, points: self.points.clone(), curves, surfaces, node_tags, cell_tags, split: self.split.clone() }
    }

    /// Every group name, for error messages.
    pub fn all_names(&self) -> String {
        let mut v: Vec<String> = Vec::new();
        v.extend(self.points.keys().filter(|k| !k.starts_with('#')).map(|k| format!("{k} (point)")));
        v.extend(self.curves.keys().filter(|k| !k.starts_with('#')).map(|k| format!("{k} (curve)")));
        v.extend(self.surfaces.keys().filter(|k| !k.starts_with('#')).map(|k| format!("{k} (surface)")));
        if v.is_empty() {
            "none".into()
        } else {
            v.join(", ")
        }
    }

    /// Nodes of a group of any dimension.
    pub fn nodes(&self, name: &str) -> Option<Vec<usize>> {
        if let Some(cells) = self.surfaces.get(name) {
            let mut v: Vec<usize> = cells.iter().flat_map(|&c| self.mesh.cells[c]).collect();
            v.sort_unstable();
            v.dedup();
            return Some(v);
        }
        if let Some(seg) = self.curves.get(name) {
            let mut v: Vec<usize> = seg.iter().flatten().copied().collect();
            v.sort_unstable();
            v.dedup();
            return Some(v);
        }
        if let Some(p) = self.points.get(name) {
            return Some(p.clone());
        }
        self.mesh.node_groups.get(name).cloned()
    }

    /// Integral of every node's bilinear shape function over the given cells (tributary areas; for a
    /// constant load per unit area these are the consistent nodal weights).
    pub fn nodal_areas_of(&self, cells: &[usize]) -> Vec<f64> {
        let sub = QuadMesh {
            coords: self.mesh.coords.clone(),
            cells: cells.iter().map(|&c| self.mesh.cells[c]).collect(),
            ..Default::default()
        };
        sub.nodal_areas()
    }

    /// Characteristic element size: the square root of the mean cell area.
    pub fn element_size(&self) -> f64 {
        self.mesh.element_size()
    }

    /// The nodes of a curve group in chain order with their arc length from the chain's start (for
    /// plots). A curve made of several pieces is walked piece after piece.
    pub fn curve_chain(&self, name: &str) -> Option<Vec<(usize, f64)>> {
        let segs = self.curves.get(name)?;
        let mut next: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
        let mut indeg: BTreeMap<usize, usize> = BTreeMap::new();
        for s in segs {
            next.entry(s[0]).or_default().push(s[1]);
            *indeg.entry(s[1]).or_default() += 1;
            indeg.entry(s[0]).or_default();
        }
        let mut used = vec![false; segs.len()];
        let mut out: Vec<(usize, f64)> = Vec::new();
        let mut s_acc = 0.0;
        let dist = |a: usize, b: usize| {
            let (x, y) = (self.mesh.coords[a], self.mesh.coords[b]);
            ((x[0] - y[0]).powi(2) + (x[1] - y[1]).powi(2)).sqrt()
        };
        let mut seen = std::collections::BTreeSet::new();
        // start at nodes with no incoming segment, then anywhere (closed loops)
        let mut starts: Vec<usize> = indeg.iter().filter(|(_, &d)| d == 0).map(|(&n, _)| n).collect();
        starts.extend(segs.iter().map(|s| s[0]));
        for start in starts {
            if !segs.iter().enumerate().any(|(k, s)| !used[k] && s[0] == start) {
                continue;
            }
            let mut cur = start;
            if let Some(&(last, _)) = out.last() {
                s_acc += dist(last, cur);
            }
            if seen.insert(cur) {
                out.push((cur, s_acc));
            }
            while let Some(k) = segs.iter().enumerate().position(|(k, s)| !used[k] && s[0] == cur) {
                used[k] = true;
                let nxt = segs[k][1];
                s_acc += dist(cur, nxt);
                cur = nxt;
                if seen.insert(cur) {
                    out.push((cur, s_acc));
                }
            }
        }
        Some(out)
    }
}

/// An error for a group that does not exist or has the wrong dimension.
pub fn group_error(p: &Problem, span: std::ops::Range<usize>, key: &str, name: &str, want: &str, mesh: &MeshData) -> StampError {
    let want = if want.is_empty() { String::new() } else { format!("{want} ") };
    let mut names = mesh.all_names();
    if names.chars().count() > 200 {
        names = names.chars().take(200).collect::<String>() + ", ...";
    }
    p.error_at(span, key, format!("no {want}group named '{}'; the mesh has: {names}", stamp::quote(name)))
}

/// "node at (x1, x2) = (1, 2) (gmsh node 17)"; a node the reader or a refinement added (tag 0)
/// has no gmsh tag to name.
pub fn where_node(mesh: &MeshData, node: usize) -> String {
    let x = mesh.mesh.coords[node];
    let tag = match mesh.node_tags.as_ref().and_then(|t| t.get(node)) {
        Some(0) => " (not a gmsh node: added where a cell was cut)".to_string(),
        Some(t) => format!(" (gmsh node {t})"),
        None => String::new(),
    };
    format!("the node at (x1, x2) = ({}, {}){tag}", num(x[0]), num(x[1]))
}

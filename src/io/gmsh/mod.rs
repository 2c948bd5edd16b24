//! Reading gmsh meshes (MSH 4.1, ASCII or binary) into a [`QuadMesh`] with its physical groups.
//!
//! * `sections`: the file's sections read by us (no count from the file sizes an allocation before
//!   it is checked against the bytes left; header counts and tag ranges are checked);
//! * `elements`: the accepted element types (3- and 6-node triangles, 4-, 8- and 9-node
//!   quadrilaterals, 2- and 3-node lines, points) and how surface elements are cut into 4-node
//!   quadrilaterals;
//! * this file: nodes, cells and physical groups put together, orientation, and the mesh checked as
//!   a whole ([`crate::mesh::check`]) with messages that name gmsh tags.
//!
//! The plate lies in the x1-x2 plane (every z must be 0). A mesh whose cells are all clockwise
//! (surface normal along -z) is reoriented; a mixture of orientations is an error.

mod arrays;
mod elements;
mod sections;

pub use arrays::{mesh_from_arrays, ArrayGroup, GroupItems};

use crate::error::{Result, StampError};
use crate::mesh::{quad_signed_area, QuadMesh};
use crate::mesh::check::{self as mesh_check, Defect};
use elements::{NewNodes, NodeRef};
use sections::{input_err, RawMsh};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// The elements of one gmsh type in the file and the cells they became.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SourceCells {
    /// The gmsh element type (2 triangle, 3 quadrilateral, 9, 10, 16 second order).
    pub gmsh_type: i32,
    /// The type in words, e.g. "3-node triangle".
    pub kind: &'static str,
    /// Elements of this type in the file.
    pub elements: usize,
    /// Cells (4-node quadrilaterals) made from them.
    pub cells: usize,
}

/// One entry of the `$PhysicalNames` section.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhysicalName {
    /// Dimension of the group: 0 point, 1 curve, 2 surface (3 volume).
    pub dim: usize,
    /// The physical tag (group number) in the file.
    pub tag: i32,
    /// The name.
    pub name: String,
}

/// A physical group present in the file (named or not).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PhysicalGroup {
    /// Dimension: 0 point, 1 curve, 2 surface.
    pub dim: usize,
    /// The physical tag (group number).
    pub tag: i32,
    /// The name from `$PhysicalNames`, if it has one.
    pub name: Option<String>,
}

impl PhysicalGroup {
    /// The key `"#<tag>"` under which the group is always stored.
    pub fn number_key(&self) -> String {
        format!("#{}", self.tag)
    }
}

/// A mesh read from a gmsh file, with its physical groups.
///
/// Groups are keyed by name and by number as `"#<tag>"` (a named group has both keys). In
/// `mesh.node_groups`, which mixes dimensions, a name used by groups of several dimensions holds the
/// union of their nodes, and a number used by groups of several dimensions is left out (ambiguous:
/// look it up with [`GmshMesh::point_group`], [`GmshMesh::curve_group`] or
/// [`GmshMesh::cell_group`], or by name).
#[derive(Debug, Clone)]
pub struct GmshMesh {
    /// The file the mesh was read from.
    pub path: PathBuf,
    /// The mesh. `node_groups` holds the nodes of every physical group (points, curves, surfaces);
    /// `cell_groups` the cells of every physical surface.
    pub mesh: QuadMesh,
    /// The `$PhysicalNames` section as written in the file.
    pub physical_names: Vec<PhysicalName>,
    /// Every physical group of dimension 0, 1 or 2 that the file uses or names, sorted by
    /// (dim, tag).
    pub physical_groups: Vec<PhysicalGroup>,
    /// gmsh node tag of each of our nodes; 0 for a node made by cutting an element into
    /// quadrilaterals (an edge midpoint or an element centre: gmsh tags are never 0).
    pub node_tags: Vec<u64>,
    /// gmsh element tag of each of our cells: the tag of the element the cell was cut from (a
    /// triangle gives three cells with its tag).
    pub cell_tags: Vec<u64>,
    /// How many elements of each type the file had and how many cells they became, by gmsh type.
    pub source_cells: Vec<SourceCells>,
    /// Nodes of each physical point group.
    pub point_groups: BTreeMap<String, Vec<usize>>,
    /// 2-node line segments (in the direction the file gives them) of each physical curve group.
    pub curve_groups: BTreeMap<String, Vec<[usize; 2]>>,
    /// True if every quadrilateral was clockwise in the file and the node order was reversed.
    pub reoriented: bool,
}

fn dim_word(dim: usize) -> &'static str {
    match dim {
        0 => "point",
        1 => "curve",
        2 => "surface",
        3 => "volume",
        _ => "entity",
    }
}

impl GmshMesh {
    /// What the conversion did, for a summary line, e.g. "1204 3-node triangles split into 3612
    /// quadrilaterals; 20 4-node quadrilaterals kept"; `None` if the file had only 4-node
    /// quadrilaterals, kept whole.
    pub fn split_summary(&self) -> Option<String> {
        if self.source_cells.iter().all(|s| s.gmsh_type == elements::QUAD4 && s.cells == s.elements) {
            return None;
        }
        let parts: Vec<String> = self
            .source_cells
            .iter()
            .map(|s| {
                let plural = if s.elements == 1 { "" } else { "s" };
                if s.cells == s.elements {
                    format!("{} {}{plural} kept", s.elements, s.kind)
                } else {
                    format!("{} {}{plural} split into {} quadrilaterals", s.elements, s.kind, s.cells)
                }
            })
            .collect();
        Some(parts.join("; "))
    }

    fn file(&self) -> String {
        self.path.display().to_string()
    }

    fn unknown(&self, what: &str, name: &str, keys: Vec<&String>) -> StampError {
        let mut message = format!("no physical {what} named '{name}'; ");
        if keys.is_empty() {
            message.push_str(&format!("the file has no physical {what}s"));
        } else {
            message
                .push_str(&format!("the file has: {}", keys.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", ")));
        }
        let elsewhere: Vec<String> = self
            .physical_groups
            .iter()
            .filter(|g| g.name.as_deref() == Some(name) || g.number_key() == name)
            .map(|g| format!("a physical {} ({}D, tag {})", dim_word(g.dim), g.dim, g.tag))
            .collect();
        if !elsewhere.is_empty() {
            message.push_str(&format!("; '{name}' is {}", elsewhere.join(" and ")));
        }
        StampError::Input { file: self.file(), message }
    }

    /// Nodes of a physical group of any dimension (see the type's note on names and numbers used by
    /// several dimensions).
    pub fn node_group(&self, name: &str) -> Result<&[usize]> {
        if let Some(v) = self.mesh.node_groups.get(name) {
            return Ok(v);
        }
        let dims: Vec<&PhysicalGroup> = self.physical_groups.iter().filter(|g| g.number_key() == name).collect();
        if dims.len() > 1 {
            return Err(StampError::Input {
                file: self.file(),
                message: format!(
                    "group number '{name}' is ambiguous: it is used by {}; use the group's name or \
                     ask for the point, curve or surface group",
                    dims.iter().map(|g| format!("a physical {}", dim_word(g.dim))).collect::<Vec<_>>().join(" and ")
                ),
            });
        }
        Err(self.unknown("group", name, self.mesh.node_groups.keys().collect()))
    }

    /// Same as [`GmshMesh::node_group`].
    pub fn group(&self, name: &str) -> Result<&[usize]> {
        self.node_group(name)
    }

    /// Nodes of a physical point group.
    pub fn point_group(&self, name: &str) -> Result<&[usize]> {
        self.point_groups
            .get(name)
            .map(|v| v.as_slice())
            .ok_or_else(|| self.unknown("point group", name, self.point_groups.keys().collect()))
    }

    /// Line segments of a physical curve group.
    pub fn curve_group(&self, name: &str) -> Result<&[[usize; 2]]> {
        self.curve_groups
            .get(name)
            .map(|v| v.as_slice())
            .ok_or_else(|| self.unknown("curve group", name, self.curve_groups.keys().collect()))
    }

    /// Cells of a physical surface group.
    pub fn cell_group(&self, name: &str) -> Result<&[usize]> {
        self.mesh
            .cell_groups
            .get(name)
            .map(|v| v.as_slice())
            .ok_or_else(|| self.unknown("surface group", name, self.mesh.cell_groups.keys().collect()))
    }

    /// All group keys (names and `"#<tag>"` numbers) of `mesh.node_groups`.
    pub fn group_names(&self) -> Vec<String> {
        self.mesh.node_groups.keys().cloned().collect()
    }
}

/// Reads a gmsh MSH 4.1 file (ASCII or binary) of a plane surface mesh: see [`parse_msh_bytes`].
/// Only regular files are read (a directory, FIFO or device is refused before it is opened).
pub fn read_msh(path: &Path) -> Result<GmshMesh> {
    let meta = std::fs::metadata(path).map_err(|e| input_err(path, format!("cannot read the mesh file: {e}")))?;
    if !meta.is_file() {
        let kind = if meta.is_dir() { "a directory" } else { "not a regular file (a FIFO, socket or device)" };
        return Err(input_err(path, format!("cannot read the mesh file: it is {kind}")));
    }
    let bytes = std::fs::read(path).map_err(|e| input_err(path, format!("cannot read the mesh file: {e}")))?;
    parse_msh_bytes(path, &bytes)
}

/// A surface element of the file: its type, node indices (file order), tag, entity and physical
/// surfaces.
struct SurfaceElement {
    ty: i32,
    nodes: Vec<usize>,
    tag: u64,
    entity: i32,
    phys: Vec<i32>,
}

/// Parses the bytes of a gmsh MSH 4.1 file (ASCII or binary); `path` names the file in messages.
///
/// Surface elements of the accepted types (3- and 6-node triangles, 4-, 8- and 9-node
/// quadrilaterals) are cut into 4-node quadrilaterals (see the `elements` module); 2- and 3-node
/// lines give 2-node segments of curve groups (a line whose edge got a midpoint is cut in two), and
/// points give point groups. The mesh is then checked as a whole ([`crate::mesh::check`]). Every
/// failure is a [`StampError::Input`] naming the file and the gmsh tags concerned; nothing in the
/// bytes can make it panic or allocate beyond what the bytes can hold.
pub fn parse_msh_bytes(path: &Path, bytes: &[u8]) -> Result<GmshMesh> {
    let raw = sections::read_sections(path, bytes)?;
    convert(path, raw)
}

fn convert(path: &Path, raw: RawMsh) -> Result<GmshMesh> {
    let err = |m: String| input_err(path, m);
    if !raw.has_nodes {
        return Err(err("the file has no $Nodes section".into()));
    }
    if !raw.has_elements {
        return Err(err("the file has no $Elements section".into()));
    }
    let mut index_of_tag: HashMap<u64, usize> = HashMap::with_capacity(raw.node_tags.len());
    for (i, &t) in raw.node_tags.iter().enumerate() {
        index_of_tag.insert(t, i);
    }

    // Elements by kind, with nodes as indices into the file's node list.
    let mut surface: Vec<SurfaceElement> = Vec::new();
    let mut lines: Vec<(Vec<usize>, Vec<i32>)> = Vec::new(); // nodes (2 or 3), physical curves
    let mut points: Vec<(usize, Vec<i32>)> = Vec::new();
    let mut used_groups: BTreeSet<(usize, i32)> = BTreeSet::new();
    for block in &raw.element_blocks {
        let ty = block.element_type;
        let first_tag = block.tags.first().copied().unwrap_or(0);
        let want = elements::dimension(ty);
        let dim = block.entity_dim;
        if dim != want {
            return Err(err(format!(
                "element {first_tag} ({}) lies on a {dim}-dimensional entity (expected {want})",
                elements::element_type_name(ty)
            )));
        }
        let dim = dim as usize;
        let phys: Vec<i32> = match &raw.entities {
            None => Vec::new(),
            Some(ent) => ent.get(&(dim, block.entity_tag)).cloned().ok_or_else(|| {
                err(format!("element {first_tag} lies on {} {} which is not in $Entities", dim_word(dim), block.entity_tag))
            })?,
        };
        for &p in &phys {
            used_groups.insert((dim, p));
        }
        for (k, &tag) in block.tags.iter().enumerate() {
            let node_tags = &block.nodes[k * block.nodes_per_element..(k + 1) * block.nodes_per_element];
            let mut idx = Vec::with_capacity(node_tags.len());
            for t in node_tags {
                let i = *index_of_tag
                    .get(t)
                    .ok_or_else(|| err(format!("element {tag} refers to node tag {t}, which is not in $Nodes")))?;
                if idx.contains(&i) {
                    return Err(err(format!(
                        "element {tag} ({}) lists node {t} twice",
                        elements::element_type_name(ty)
                    )));
                }
                idx.push(i);
            }
            match dim {
                2 => surface.push(SurfaceElement { ty, nodes: idx, tag, entity: block.entity_tag, phys: phys.clone() }),
                1 => lines.push((idx, phys.clone())),
                _ => points.push((idx[0], phys.clone())),
            }
        }
    }
    if surface.is_empty() {
        return Err(err(format!("the file has no surface elements: mesh the surface in 2D (gmsh -2); {}", elements::SUPPORTED)));
    }

    // Cut the surface elements into quadrilaterals.
    let needs_mids = surface.iter().any(|e| e.ty != elements::QUAD4);
    let split_quads = needs_mids && surface.iter().any(|e| e.ty == elements::QUAD4);
    let mut new = NewNodes::default();
    for e in &surface {
        elements::register_mids(e.ty, &e.nodes, &mut new);
    }
    for (l, _) in &lines {
        if l.len() == 3 {
            new.register_mid(l[0], l[1], l[2]);
        }
    }
    let mut sub: Vec<[NodeRef; 4]> = Vec::new();
    let mut parent: Vec<usize> = Vec::new(); // surface element of each sub-cell
    let mut new_owner: Vec<u64> = Vec::new(); // element tag that made each new node
    let mut sources: BTreeMap<i32, (usize, usize)> = BTreeMap::new();
    for (k, e) in surface.iter().enumerate() {
        let cells = elements::split_surface(e.ty, &e.nodes, split_quads, &mut new);
        new_owner.resize(new.weights.len(), e.tag);
        let s = sources.entry(e.ty).or_default();
        s.0 += 1;
        s.1 += cells.len();
        parent.extend(std::iter::repeat_n(k, cells.len()));
        sub.extend(cells);
    }
    // Boundary lines: cut where their edge got a midpoint.
    let mut segments: Vec<([NodeRef; 2], &[i32])> = Vec::new();
    for (l, phys) in &lines {
        let (a, b) = (NodeRef::File(l[0]), NodeRef::File(l[1]));
        let mid = if l.len() == 3 { Some(NodeRef::File(l[2])) } else { new.existing_midpoint(l[0], l[1]) };
        match mid {
            Some(m) => {
                segments.push(([a, m], phys));
                segments.push(([m, b], phys));
            }
            None => segments.push(([a, b], phys)),
        }
    }

    // Compact numbering: used file nodes in file order, then the new nodes.
    let nfile = raw.node_tags.len();
    let mut used = vec![false; nfile];
    let mark = |r: &NodeRef, used: &mut Vec<bool>| {
        if let NodeRef::File(i) = *r {
            used[i] = true;
        }
    };
    for c in &sub {
        c.iter().for_each(|r| mark(r, &mut used));
    }
    for (s, _) in &segments {
        s.iter().for_each(|r| mark(r, &mut used));
    }
    for (p, _) in &points {
        used[*p] = true;
    }
    let mut extent = 0.0f64;
    for (i, c) in raw.node_coords.iter().enumerate() {
        if used[i] && c[0].is_finite() && c[1].is_finite() {
            extent = extent.max(c[0].abs()).max(c[1].abs());
        }
    }
    let mut file_index = vec![usize::MAX; nfile];
    let mut coords = Vec::new();
    let mut node_tags = Vec::new();
    for i in 0..nfile {
        if !used[i] {
            continue;
        }
        let [x, y, z] = raw.node_coords[i];
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err(err(format!(
                "node {} has a non-finite coordinate ({}, {}, {})",
                raw.node_tags[i],
                short(x),
                short(y),
                short(z)
            )));
        }
        if z.abs() > 1e-12 * extent.max(1e-300) {
            return Err(err(format!(
                "node {} has z = {}: the plate must lie in the x1-x2 plane (z = 0 everywhere)",
                raw.node_tags[i],
                short(z)
            )));
        }
        file_index[i] = coords.len();
        coords.push([x, y]);
        node_tags.push(raw.node_tags[i]);
    }
    let first_new = coords.len();
    for w in &new.weights {
        let mut x = [0.0; 2];
        for &(i, a) in w {
            x[0] += a * raw.node_coords[i][0];
            x[1] += a * raw.node_coords[i][1];
        }
        coords.push(x);
        node_tags.push(0);
    }
    let index = |r: NodeRef| match r {
        NodeRef::File(i) => file_index[i],
        NodeRef::New(k) => first_new + k,
    };

    // Cells and orientation.
    let mut cells: Vec<[usize; 4]> = sub.iter().map(|c| c.map(index)).collect();
    let cell_tags: Vec<u64> = parent.iter().map(|&k| surface[k].tag).collect();
    let areas: Vec<f64> = cells.iter().map(|c| quad_signed_area(&c.map(|n| coords[n]))).collect();
    let n_neg = areas.iter().filter(|&&a| a < 0.0).count();
    let n_pos = areas.iter().filter(|&&a| a > 0.0).count();
    let reoriented = n_neg > 0 && n_pos == 0;
    if reoriented {
        for c in &mut cells {
            *c = [c[0], c[3], c[2], c[1]];
        }
    } else if n_neg > 0 {
        // Mixed orientations: the minority is inverted (ties: clockwise cells are the inverted ones).
        let bad_is_neg = n_neg <= n_pos;
        let first = (0..cells.len()).find(|&c| (areas[c] < 0.0) == bad_is_neg && areas[c] != 0.0).unwrap_or(0);
        let (sense, other) =
            if bad_is_neg { ("clockwise", "counter-clockwise") } else { ("counter-clockwise", "clockwise") };
        return Err(err(format!(
            "element {} (on surface {}) is inverted: it is {sense} while {} of the {} cells are {other} ({} \
             inverted in all); if a whole surface was meshed with the opposite normal, reverse its curve loop \
             or add `ReverseMesh Surface{{...}};` to the .geo file",
            cell_tags[first],
            surface[parent[first]].entity,
            if bad_is_neg { n_pos } else { n_neg },
            cells.len(),
            if bad_is_neg { n_neg } else { n_pos },
        )));
    }
    let mut mesh = QuadMesh { coords, cells, ..Default::default() };

    // The mesh as a whole, with messages in gmsh tags.
    let namer = Namer { tags: &node_tags, first_new, new_owner: &new_owner, coords: &mesh.coords };
    let cell_name = |c: usize| format!("element {} (on surface {})", cell_tags[c], surface[parent[c]].entity);
    let check = mesh_check::check_cells(&mesh).and_then(|_| mesh_check::check_topology(&mesh));
    if let Err(d) = check {
        let message = match d {
            Defect::Empty => "the mesh is empty".to_string(),
            Defect::NonFiniteNode { node } => format!("{} has a non-finite coordinate", namer.name(node)),
            Defect::MissingNode { cell, .. } => format!("{} refers to a missing node", cell_name(cell)),
            Defect::RepeatedNode { cell, node } => format!("{} uses {} twice", cell_name(cell), namer.name(node)),
            Defect::BadCell { cell, inverted, area, .. } => {
                let kind = if inverted { "inverted (clockwise)" } else { "degenerate or non-convex" };
                let what = if cell_tags.iter().filter(|&&t| t == cell_tags[cell]).count() > 1 {
                    "a quadrilateral cut from it"
                } else {
                    "it"
                };
                format!("{} is unusable: {what} is {kind} (signed area {area:.3e}, a corner angle of 180 degrees or more)", cell_name(cell))
            }
            Defect::DuplicateCells { first, second } => format!(
                "elements {} and {} are duplicates (the same nodes): remove one",
                cell_tags[first], cell_tags[second]
            ),
            Defect::EdgeSharedByMore { edge, cells } => {
                let mut tags: Vec<u64> = cells.iter().map(|&c| cell_tags[c]).collect();
                tags.dedup();
                format!(
                    "the edge from {} to {} is shared by {} cells (of elements {}); a surface edge has at most two",
                    namer.name(edge[0]),
                    namer.name(edge[1]),
                    cells.len(),
                    join_tags(&tags)
                )
            }
            Defect::Folded { first, second, edge } => format!(
                "elements {} and {} lie on the same side of their shared edge from {} to {}: they overlap (the mesh folds over)",
                cell_tags[first],
                cell_tags[second],
                namer.name(edge[0]),
                namer.name(edge[1])
            ),
            Defect::Overlap { first, second } => format!(
                "elements {} and {} overlap or cross each other",
                cell_tags[first], cell_tags[second]
            ),
            Defect::HangingNode { node, cell, edge } => format!(
                "{} lies on the edge from {} to {} of {} without being one of its nodes: the mesh is not conforming there (a hanging node)",
                namer.name(node),
                namer.name(edge[0]),
                namer.name(edge[1]),
                cell_name(cell)
            ),
            Defect::CoincidentNodes { first, second } => format!(
                "{} and {} are at the same point: the mesh is cut there (merge duplicate nodes, e.g. Coherence Mesh)",
                namer.name(first),
                namer.name(second)
            ),
        };
        return Err(err(message));
    }

    // Groups.
    let physical_names = raw.physical_names;
    let name_of: HashMap<(usize, i32), &str> =
        physical_names.iter().map(|p| ((p.dim, p.tag), p.name.as_str())).collect();
    let mut all_groups: BTreeSet<(usize, i32)> = used_groups;
    for p in &physical_names {
        if p.dim <= 2 {
            all_groups.insert((p.dim, p.tag));
        }
    }
    let physical_groups: Vec<PhysicalGroup> = all_groups
        .iter()
        .map(|&(dim, tag)| PhysicalGroup { dim, tag, name: name_of.get(&(dim, tag)).map(|s| s.to_string()) })
        .collect();
    let mut number_uses: HashMap<i32, usize> = HashMap::new();
    for g in &physical_groups {
        *number_uses.entry(g.tag).or_default() += 1;
    }
    let mut points_by_group: BTreeMap<i32, Vec<usize>> = BTreeMap::new();
    for (p, phys) in &points {
        for &g in phys {
            points_by_group.entry(g).or_default().push(file_index[*p]);
        }
    }
    let mut segs_by_group: BTreeMap<i32, Vec<[usize; 2]>> = BTreeMap::new();
    for (s, phys) in &segments {
        for &g in phys.iter() {
            segs_by_group.entry(g).or_default().push(s.map(index));
        }
    }
    let mut cells_by_group: BTreeMap<i32, Vec<usize>> = BTreeMap::new();
    for (c, &k) in parent.iter().enumerate() {
        for &g in &surface[k].phys {
            cells_by_group.entry(g).or_default().push(c);
        }
    }
    let mut point_groups = BTreeMap::new();
    let mut curve_groups = BTreeMap::new();
    for g in &physical_groups {
        let mut keys = vec![g.number_key()];
        if let Some(n) = &g.name {
            keys.push(n.clone());
        }
        let nodes: BTreeSet<usize> = match g.dim {
            0 => points_by_group.get(&g.tag).into_iter().flatten().copied().collect(),
            1 => segs_by_group.get(&g.tag).into_iter().flatten().flatten().copied().collect(),
            _ => cells_by_group.get(&g.tag).into_iter().flatten().flat_map(|&c| mesh.cells[c]).collect(),
        };
        for (i, k) in keys.iter().enumerate() {
            match g.dim {
                0 => {
                    point_groups.insert(k.clone(), nodes.iter().copied().collect::<Vec<_>>());
                }
                1 => {
                    curve_groups.insert(k.clone(), segs_by_group.get(&g.tag).cloned().unwrap_or_default());
                }
                _ => {
                    mesh.cell_groups.insert(k.clone(), cells_by_group.get(&g.tag).cloned().unwrap_or_default());
                }
            }
            if i == 0 && number_uses[&g.tag] > 1 {
                continue; // ambiguous across dimensions
            }
            let entry = mesh.node_groups.entry(k.clone()).or_default();
            let merged: BTreeSet<usize> = entry.iter().copied().chain(nodes.iter().copied()).collect();
            *entry = merged.into_iter().collect();
        }
    }
    let source_cells = sources
        .into_iter()
        .map(|(ty, (elements, cells))| SourceCells { gmsh_type: ty, kind: elements::element_type_name(ty), elements, cells })
        .collect();

    Ok(GmshMesh {
        path: path.to_path_buf(),
        mesh,
        physical_names,
        physical_groups,
        node_tags,
        cell_tags,
        source_cells,
        point_groups,
        curve_groups,
        reoriented,
    })
}

/// A number for a message: plain when of moderate size, else in exponent form (never 300 digits).
fn short(x: f64) -> String {
    if x == 0.0 || (x.abs() >= 1e-4 && x.abs() < 1e9) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

fn join_tags(tags: &[u64]) -> String {
    tags.iter().map(|t| t.to_string()).collect::<Vec<_>>().join(", ")
}

/// Names our nodes in messages by their gmsh tag, or for a node we made, by the element it was
/// made for and its position.
struct Namer<'a> {
    tags: &'a [u64],
    first_new: usize,
    new_owner: &'a [u64],
    coords: &'a [[f64; 2]],
}

impl Namer<'_> {
    fn name(&self, node: usize) -> String {
        match self.tags.get(node) {
            Some(&t) if t != 0 => format!("node {t}"),
            _ => {
                let owner = node.checked_sub(self.first_new).and_then(|k| self.new_owner.get(k));
                let at = self.coords.get(node).map(|x| format!(" at ({:.6e}, {:.6e})", x[0], x[1])).unwrap_or_default();
                match owner {
                    Some(e) => format!("the node added when cutting element {e}{at}"),
                    None => format!("a node made by the reader{at}"),
                }
            }
        }
    }
}

//! Reading gmsh meshes (MSH 4.1, ASCII or binary) into a [`QuadMesh`] with its physical groups.
//!
//! The file is parsed by `mshio`, with three things done here because `mshio` does not do them or
//! does them wrongly:
//! * the `$MeshFormat` header is checked first, so that MSH 2.2 or 4.0 files get an error that says
//!   how to convert them;
//! * `$PhysicalNames` is parsed here (it is ASCII even in binary files);
//! * the node tags are read here from the `$Nodes` section: when the tags are dense, `mshio` drops
//!   them and assumes they run in file order, which gives wrong connectivity for a file whose dense
//!   tags are permuted.
//!
//! Only 4-node quadrilaterals (gmsh type 3), 2-node lines (type 1) and points (type 15) are
//! accepted; the plate lies in the x1-x2 plane (every z must be 0). A mesh whose quadrilaterals are
//! all clockwise (surface normal along -z) is reoriented; a mixture of orientations is an error.

use crate::error::{Result, StampError};
use crate::mesh::{quad_signed_area, QuadMesh};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// gmsh element types accepted by [`read_msh`].
const TYPE_LINE2: i32 = 1;
const TYPE_QUAD4: i32 = 3;
const TYPE_POINT: i32 = 15;

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
    /// gmsh node tag of each of our nodes.
    pub node_tags: Vec<u64>,
    /// gmsh element tag of each of our cells.
    pub cell_tags: Vec<u64>,
    /// Nodes of each physical point group.
    pub point_groups: BTreeMap<String, Vec<usize>>,
    /// 2-node line segments (in the direction the file gives them) of each physical curve group.
    pub curve_groups: BTreeMap<String, Vec<[usize; 2]>>,
    /// True if every quadrilateral was clockwise in the file and the node order was reversed.
    pub reoriented: bool,
}

fn input_err(path: &Path, message: impl Into<String>) -> StampError {
    StampError::Input { file: path.display().to_string(), message: message.into() }
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

/// Where a line starts and ends in `bytes`; yields (line without "\r\n", offset after the line).
fn next_line(bytes: &[u8], start: usize) -> Option<(&[u8], usize)> {
    if start >= bytes.len() {
        return None;
    }
    let end = bytes[start..].iter().position(|&b| b == b'\n').map(|p| start + p).unwrap_or(bytes.len());
    let mut line = &bytes[start..end];
    while let Some((&last, rest)) = line.split_last() {
        if last == b'\r' || last == b' ' || last == b'\t' {
            line = rest;
        } else {
            break;
        }
    }
    Some((line, (end + 1).min(bytes.len())))
}

/// Offset just after the line "$<name>" (at the start of a line), searching from `from`.
fn find_section(bytes: &[u8], name: &str, from: usize) -> Option<usize> {
    let pat = name.as_bytes();
    let mut i = from;
    while i + pat.len() <= bytes.len() {
        let p = bytes[i..].windows(pat.len()).position(|w| w == pat)? + i;
        let at_line_start = p == 0 || bytes[p - 1] == b'\n';
        let after = p + pat.len();
        let line_ends = after == bytes.len() || bytes[after] == b'\n' || bytes[after] == b'\r';
        if at_line_start && line_ends {
            return next_line(bytes, p).map(|(_, next)| next);
        }
        i = p + 1;
    }
    None
}

struct Header {
    binary: bool,
    big_endian: bool,
    size_t: usize,
}

fn check_header(path: &Path, bytes: &[u8]) -> Result<Header> {
    let convert = format!(
        "stamp reads MSH 4.1 only: convert with `gmsh {} -save -format msh41` (add `-bin` for binary), \
         or export with `-format msh41` / Mesh.MshFileVersion = 4.1",
        path.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
    );
    let mut start = 0;
    while start < bytes.len() && bytes[start].is_ascii_whitespace() {
        start += 1;
    }
    let first = next_line(bytes, start);
    if first.map(|(l, _)| l) != Some(b"$MeshFormat".as_slice()) {
        return Err(input_err(
            path,
            if bytes.is_empty() {
                "the file is empty (expected a gmsh MSH 4.1 mesh)".to_string()
            } else {
                "not a gmsh mesh: the file does not start with $MeshFormat".to_string()
            },
        ));
    }
    let (_, next) = first.unwrap();
    let (line, after) =
        next_line(bytes, next).ok_or_else(|| input_err(path, "the file is truncated in the $MeshFormat section"))?;
    let line = String::from_utf8_lossy(line).into_owned();
    let fields: Vec<&str> = line.split_whitespace().collect();
    if fields.len() != 3 {
        return Err(input_err(
            path,
            format!("malformed $MeshFormat line '{line}' (expected 'version file-type data-size')"),
        ));
    }
    if fields[0] != "4.1" {
        return Err(input_err(path, format!("MSH format version {} is not supported; {convert}", fields[0])));
    }
    let binary = match fields[1] {
        "0" => false,
        "1" => true,
        other => {
            return Err(input_err(path, format!("unknown MSH file type '{other}' in $MeshFormat (expected 0 or 1)")))
        }
    };
    let size_t: usize = match fields[2] {
        "8" => 8,
        "4" => 4,
        other => {
            return Err(input_err(path, format!("unsupported MSH data size '{other}' in $MeshFormat (expected 8)")))
        }
    };
    let mut big_endian = false;
    if binary {
        let one = bytes
            .get(after..after + 4)
            .ok_or_else(|| input_err(path, "the file is truncated in the $MeshFormat section"))?;
        big_endian = match one {
            [1, 0, 0, 0] => false,
            [0, 0, 0, 1] => true,
            _ => {
                return Err(input_err(
                    path,
                    "binary $MeshFormat: cannot detect the byte order (the integer 1 is missing)",
                ))
            }
        };
    }
    Ok(Header { binary, big_endian, size_t })
}

fn parse_physical_names(path: &Path, bytes: &[u8]) -> Result<Vec<PhysicalName>> {
    let Some(mut pos) = find_section(bytes, "$PhysicalNames", 0) else {
        return Ok(Vec::new());
    };
    let trunc = || input_err(path, "the file is truncated in the $PhysicalNames section");
    let (line, next) = next_line(bytes, pos).ok_or_else(trunc)?;
    pos = next;
    let count_text = String::from_utf8_lossy(line).trim().to_string();
    let count: usize = count_text
        .parse()
        .map_err(|_| input_err(path, format!("$PhysicalNames: expected the number of names, found '{count_text}'")))?;
    let mut names = Vec::with_capacity(count);
    for k in 0..count {
        let (line, next) = next_line(bytes, pos).ok_or_else(trunc)?;
        pos = next;
        let text = String::from_utf8_lossy(line).trim().to_string();
        let bad = || {
            input_err(
                path,
                format!("$PhysicalNames entry {} is malformed: '{text}' (expected: dim tag \"name\")", k + 1),
            )
        };
        if text == "$EndPhysicalNames" {
            return Err(input_err(path, format!("$PhysicalNames announces {count} names but has {k}")));
        }
        let mut it = text.splitn(3, char::is_whitespace);
        let dim: usize = it.next().and_then(|s| s.parse().ok()).ok_or_else(bad)?;
        let tag: i32 = it.next().and_then(|s| s.parse().ok()).ok_or_else(bad)?;
        let rest = it.next().ok_or_else(bad)?.trim();
        if rest.len() < 2 || !rest.starts_with('"') || !rest.ends_with('"') {
            return Err(bad());
        }
        names.push(PhysicalName { dim, tag, name: rest[1..rest.len() - 1].to_string() });
    }
    match next_line(bytes, pos) {
        Some((l, _)) if l == b"$EndPhysicalNames" => Ok(names),
        Some(_) => Err(input_err(path, format!("$PhysicalNames has more entries than the {count} it announces"))),
        None => Err(trunc()),
    }
}

/// Reads the node tags of every block of the `$Nodes` section (what mshio drops for dense tags).
fn scan_node_tags(path: &Path, bytes: &[u8], h: &Header) -> Result<Vec<Vec<u64>>> {
    let start = find_section(bytes, "$Nodes", 0).ok_or_else(|| input_err(path, "the file has no $Nodes section"))?;
    let trunc = || input_err(path, "the file is truncated in the $Nodes section");
    let mut blocks = Vec::new();
    if h.binary {
        let mut pos = start;
        let mut take = |n: usize| -> Result<&[u8]> {
            let s = bytes.get(pos..pos + n).ok_or_else(trunc)?;
            pos += n;
            Ok(s)
        };
        let rd = |s: &[u8]| -> u64 {
            let mut v = 0u64;
            if h.big_endian {
                for &b in s {
                    v = (v << 8) | b as u64;
                }
            } else {
                for &b in s.iter().rev() {
                    v = (v << 8) | b as u64;
                }
            }
            v
        };
        let st = h.size_t;
        let num_blocks = rd(take(st)?);
        let _num_nodes = rd(take(st)?);
        take(2 * st)?;
        for _ in 0..num_blocks {
            take(8)?; // entity dim, entity tag
            let parametric = rd(take(4)?);
            if parametric != 0 {
                return Err(input_err(
                    path,
                    "parametric nodes are not supported: save the mesh without Mesh.SaveParametric",
                ));
            }
            let n = rd(take(st)?) as usize;
            let raw = take(n.checked_mul(st).ok_or_else(trunc)?)?;
            blocks.push(raw.chunks(st).map(rd).collect());
            take(n.checked_mul(24).ok_or_else(trunc)?)?;
        }
    } else {
        let end = find_section(bytes, "$EndNodes", start).unwrap_or(bytes.len());
        let text = std::str::from_utf8(&bytes[start..end])
            .map_err(|_| input_err(path, "the $Nodes section of an ASCII file is not valid text"))?;
        let mut tok = text.split_ascii_whitespace();
        let mut num = |what: &str| -> Result<u64> {
            let t = tok.next().ok_or_else(trunc)?;
            if what.is_empty() {
                return Ok(0); // skipping a coordinate
            }
            t.parse::<u64>().map_err(|_| input_err(path, format!("$Nodes: expected {what}, found '{t}'")))
        };
        let num_blocks = num("the number of blocks")?;
        num("the number of nodes")?;
        num("the minimum node tag")?;
        num("the maximum node tag")?;
        for _ in 0..num_blocks {
            num("an entity dimension")?;
            num("an entity tag")?;
            if num("the parametric flag")? != 0 {
                return Err(input_err(
                    path,
                    "parametric nodes are not supported: save the mesh without Mesh.SaveParametric",
                ));
            }
            let n = num("the number of nodes in a block")? as usize;
            let mut tags = Vec::with_capacity(n.min(1 << 24));
            for _ in 0..n {
                tags.push(num("a node tag")?);
            }
            for _ in 0..3 * n {
                num("")?;
            }
            blocks.push(tags);
        }
    }
    Ok(blocks)
}

fn mshio_message(e: String) -> String {
    let e = e.split("Hex dump").next().unwrap_or("").to_string();
    e.lines().map(str::trim).filter(|l| !l.is_empty()).collect::<Vec<_>>().join(" ")
}

/// Reads a gmsh MSH 4.1 file (ASCII or binary) of 4-node quadrilaterals in the x1-x2 plane.
///
/// Errors (all [`StampError::Input`] naming the file) for: a missing or unreadable file, other MSH
/// versions, element types other than 4-node quadrilaterals, 2-node lines and points, a non-zero z,
/// truncated or corrupt files, elements that refer to missing nodes, and inverted, degenerate or
/// non-convex quadrilaterals (naming the gmsh element tag).
pub fn read_msh(path: &Path) -> Result<GmshMesh> {
    let bytes = std::fs::read(path).map_err(|e| input_err(path, format!("cannot read the mesh file: {e}")))?;
    let header = check_header(path, &bytes)?;
    let physical_names = parse_physical_names(path, &bytes)?;

    // mshio has a few `expect`s left: a panic is turned into an error, never passed on.
    let parsed = std::panic::catch_unwind(|| mshio::parse_msh_bytes(&bytes).map_err(|e| mshio_message(e.to_string())))
        .unwrap_or_else(|_| Err("the mshio parser panicked".to_string()));
    let msh = match parsed {
        Ok(m) => m,
        Err(detail) => {
            let message = if find_section(&bytes, "$EndElements", 0).is_none() {
                format!("the file is truncated or corrupt (no complete $Elements section): {detail}")
            } else {
                format!("cannot parse the MSH 4.1 file: {detail}")
            };
            return Err(input_err(path, message));
        }
    };
    let nodes = msh.data.nodes.as_ref().ok_or_else(|| input_err(path, "the file has no $Nodes section"))?;
    let elements = msh.data.elements.as_ref().ok_or_else(|| input_err(path, "the file has no $Elements section"))?;

    // Node tags, read by us; cross-checked with what mshio kept.
    let tag_blocks = scan_node_tags(path, &bytes, &header)?;
    if tag_blocks.len() != nodes.node_blocks.len() {
        return Err(input_err(path, "the $Nodes section is inconsistent (block count)"));
    }
    let mut file_coords: Vec<[f64; 3]> = Vec::new();
    let mut file_tags: Vec<u64> = Vec::new();
    let mut index_of_tag: HashMap<u64, usize> = HashMap::new();
    for (b, (block, tags)) in nodes.node_blocks.iter().zip(&tag_blocks).enumerate() {
        if block.nodes.len() != tags.len() {
            return Err(input_err(path, format!("the $Nodes section is inconsistent (node block {})", b + 1)));
        }
        if let Some(map) = &block.node_tags {
            for (tag, &i) in map {
                if tags.get(i) != Some(tag) {
                    return Err(input_err(path, format!("the $Nodes section is inconsistent (node tag {tag})")));
                }
            }
        }
        for (node, &tag) in block.nodes.iter().zip(tags) {
            if index_of_tag.insert(tag, file_tags.len()).is_some() {
                return Err(input_err(path, format!("node tag {tag} appears more than once in $Nodes")));
            }
            file_tags.push(tag);
            file_coords.push([node.x, node.y, node.z]);
        }
    }

    // Physical tags of every entity.
    let mut entity_phys: HashMap<(usize, i32), Vec<i32>> = HashMap::new();
    if let Some(ent) = &msh.data.entities {
        for p in &ent.points {
            entity_phys.insert((0, p.tag), p.physical_tags.iter().map(|t| t.abs()).collect());
        }
        for c in &ent.curves {
            entity_phys.insert((1, c.tag), c.physical_tags.iter().map(|t| t.abs()).collect());
        }
        for s in &ent.surfaces {
            entity_phys.insert((2, s.tag), s.physical_tags.iter().map(|t| t.abs()).collect());
        }
    }

    // Elements, with nodes as indices into the file's node list.
    let mut quads: Vec<([usize; 4], u64, i32)> = Vec::new(); // nodes, element tag, surface tag
    let mut lines_by_group: BTreeMap<(usize, i32), Vec<[usize; 2]>> = BTreeMap::new();
    let mut points_by_group: BTreeMap<(usize, i32), Vec<usize>> = BTreeMap::new();
    let mut cells_by_group: BTreeMap<(usize, i32), Vec<usize>> = BTreeMap::new();
    let mut used_groups: BTreeSet<(usize, i32)> = BTreeSet::new();
    let mut used_lines: Vec<[usize; 2]> = Vec::new();
    let mut used_points: Vec<usize> = Vec::new();
    for block in &elements.element_blocks {
        let ty = block.element_type as i32;
        let first_tag = block.elements.first().map(|e| e.element_tag).unwrap_or(0);
        let (want_dim, nn) = match ty {
            TYPE_QUAD4 => (2, 4),
            TYPE_LINE2 => (1, 2),
            TYPE_POINT => (0, 1),
            _ => {
                return Err(input_err(
                    path,
                    format!(
                        "element {first_tag} has gmsh element type {ty} ({:?}, {} elements in the block on {} {}); \
                         only 4-node quadrilaterals (type 3), 2-node lines (type 1) and points (type 15) are \
                         supported: recombine the mesh into first-order quadrilaterals (Recombine Surface, \
                         Mesh.RecombineAll = 1, Mesh.ElementOrder = 1)",
                        block.element_type,
                        block.elements.len(),
                        dim_word(block.entity_dim.max(0) as usize),
                        block.entity_tag
                    ),
                ))
            }
        };
        let dim = block.entity_dim;
        if dim != want_dim {
            return Err(input_err(
                path,
                format!("element {first_tag} of type {ty} lies on a {dim}-dimensional entity (expected {want_dim})"),
            ));
        }
        let dim = dim as usize;
        let phys: Vec<i32> = match (&msh.data.entities, entity_phys.get(&(dim, block.entity_tag))) {
            (_, Some(p)) => p.clone(),
            (None, None) => Vec::new(),
            (Some(_), None) => {
                return Err(input_err(
                    path,
                    format!(
                        "element {first_tag} lies on {} {} which is not in $Entities",
                        dim_word(dim),
                        block.entity_tag
                    ),
                ))
            }
        };
        for &p in &phys {
            used_groups.insert((dim, p));
        }
        for el in &block.elements {
            if el.nodes.len() != nn {
                return Err(input_err(
                    path,
                    format!("element {} has {} nodes, expected {nn}", el.element_tag, el.nodes.len()),
                ));
            }
            let mut idx = [0usize; 4];
            for (k, t) in el.nodes.iter().enumerate() {
                idx[k] = *index_of_tag.get(t).ok_or_else(|| {
                    input_err(
                        path,
                        format!("element {} refers to node tag {t}, which is not in $Nodes", el.element_tag),
                    )
                })?;
            }
            match ty {
                TYPE_QUAD4 => {
                    for &p in &phys {
                        cells_by_group.entry((2, p)).or_default().push(quads.len());
                    }
                    quads.push((idx, el.element_tag, block.entity_tag));
                }
                TYPE_LINE2 => {
                    used_lines.push([idx[0], idx[1]]);
                    for &p in &phys {
                        lines_by_group.entry((1, p)).or_default().push([idx[0], idx[1]]);
                    }
                }
                _ => {
                    used_points.push(idx[0]);
                    for &p in &phys {
                        points_by_group.entry((0, p)).or_default().push(idx[0]);
                    }
                }
            }
        }
    }
    if quads.is_empty() {
        return Err(input_err(
            path,
            "the file has no 4-node quadrilaterals (gmsh type 3): mesh the surface and recombine it \
             (Recombine Surface, Mesh.RecombineAll = 1)",
        ));
    }

    // Compact numbering: used nodes, in file order.
    let mut used = vec![false; file_tags.len()];
    for (q, _, _) in &quads {
        for &n in q {
            used[n] = true;
        }
    }
    for l in &used_lines {
        used[l[0]] = true;
        used[l[1]] = true;
    }
    for &p in &used_points {
        used[p] = true;
    }
    let mut new_index = vec![usize::MAX; file_tags.len()];
    let mut coords = Vec::new();
    let mut node_tags = Vec::new();
    let mut extent = 0.0f64;
    for (i, c) in file_coords.iter().enumerate() {
        if used[i] {
            extent = extent.max(c[0].abs()).max(c[1].abs());
        }
    }
    for i in 0..file_tags.len() {
        if !used[i] {
            continue;
        }
        let [x, y, z] = file_coords[i];
        if !(x.is_finite() && y.is_finite() && z.is_finite()) {
            return Err(input_err(path, format!("node {} has a non-finite coordinate ({x}, {y}, {z})", file_tags[i])));
        }
        if z.abs() > 1e-12 * extent.max(1e-300) {
            return Err(input_err(
                path,
                format!("node {} has z = {z}: the plate must lie in the x1-x2 plane (z = 0 everywhere)", file_tags[i]),
            ));
        }
        new_index[i] = coords.len();
        coords.push([x, y]);
        node_tags.push(file_tags[i]);
    }

    // Cells and orientation.
    let mut cells: Vec<[usize; 4]> = quads.iter().map(|(q, _, _)| q.map(|n| new_index[n])).collect();
    let cell_tags: Vec<u64> = quads.iter().map(|(_, t, _)| *t).collect();
    let areas: Vec<f64> = (0..cells.len()).map(|c| quad_signed_area(&cells[c].map(|n| coords[n]))).collect();
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
        let first = (0..cells.len()).find(|&c| (areas[c] < 0.0) == bad_is_neg && areas[c] != 0.0).unwrap();
        let (sense, other) =
            if bad_is_neg { ("clockwise", "counter-clockwise") } else { ("counter-clockwise", "clockwise") };
        return Err(input_err(
            path,
            format!(
                "element {} (on surface {}) is inverted: it is {sense} while {} of the {} quadrilaterals are \
                 {other} ({} inverted in all); if a whole surface was meshed with the opposite normal, \
                 reverse its curve loop or add `ReverseMesh Surface{{...}};` to the .geo file",
                cell_tags[first],
                quads[first].2,
                if bad_is_neg { n_pos } else { n_neg },
                cells.len(),
                if bad_is_neg { n_neg } else { n_pos },
            ),
        ));
    }

    let mut mesh = QuadMesh { coords, cells, ..Default::default() };
    if let Err(e) = mesh.validate() {
        let msg = match e {
            StampError::Mesh(m) => m,
            other => other.to_string(),
        };
        let cell = msg
            .strip_prefix("cell ")
            .and_then(|r| r.split(' ').next())
            .and_then(|s| s.parse::<usize>().ok())
            .filter(|&c| c < cell_tags.len());
        return Err(input_err(
            path,
            match cell {
                Some(c) => format!("element {} (on surface {}) is unusable: {msg}", cell_tags[c], quads[c].2),
                None => format!("invalid mesh: {msg}"),
            },
        ));
    }

    // Groups.
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
    let mut point_groups = BTreeMap::new();
    let mut curve_groups = BTreeMap::new();
    for g in &physical_groups {
        let key = (g.dim, g.tag);
        let mut keys = vec![g.number_key()];
        if let Some(n) = &g.name {
            keys.push(n.clone());
        }
        let nodes: BTreeSet<usize> = match g.dim {
            0 => points_by_group.get(&key).into_iter().flatten().map(|&n| new_index[n]).collect(),
            1 => lines_by_group.get(&key).into_iter().flatten().flat_map(|l| l.iter().map(|&n| new_index[n])).collect(),
            _ => cells_by_group.get(&key).into_iter().flatten().flat_map(|&c| mesh.cells[c].iter().copied()).collect(),
        };
        for (i, k) in keys.iter().enumerate() {
            match g.dim {
                0 => {
                    point_groups.insert(k.clone(), nodes.iter().copied().collect::<Vec<_>>());
                }
                1 => {
                    let segs: Vec<[usize; 2]> = lines_by_group
                        .get(&key)
                        .into_iter()
                        .flatten()
                        .map(|l| [new_index[l[0]], new_index[l[1]]])
                        .collect();
                    curve_groups.insert(k.clone(), segs);
                }
                _ => {
                    mesh.cell_groups.insert(k.clone(), cells_by_group.get(&key).cloned().unwrap_or_default());
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

    Ok(GmshMesh {
        path: path.to_path_buf(),
        mesh,
        physical_names,
        physical_groups,
        node_tags,
        cell_tags,
        point_groups,
        curve_groups,
        reoriented,
    })
}

//! The raw sections of a gmsh MSH 4.1 file (ASCII or binary): `$MeshFormat`, `$PhysicalNames`,
//! `$Entities`, `$Nodes` and `$Elements`, read into plain vectors. Other sections are skipped.
//!
//! Every count read from the file is checked against the bytes left before anything is sized by
//! it (an entry takes at least 2 bytes in ASCII, its exact size in binary), so a corrupt count gives
//! an error, never an allocation failure. Header counts and tag ranges of `$Nodes` and `$Elements`
//! must match their blocks; tag 0 and repeated tags are refused.

use super::elements::element_type_name;
use super::PhysicalName;
use crate::error::{quote_bytes, Result, StampError};
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// One block of `$Elements`: its entity, gmsh element type, element tags, and node tags
/// (`nodes_per_element` per element, flattened).
#[derive(Debug, Clone)]
pub(crate) struct ElementBlock {
    pub entity_dim: i32,
    pub entity_tag: i32,
    pub element_type: i32,
    pub nodes_per_element: usize,
    pub tags: Vec<u64>,
    pub nodes: Vec<u64>,
}

/// The sections of a file that stamp uses.
#[derive(Debug, Clone, Default)]
pub(crate) struct RawMsh {
    pub physical_names: Vec<PhysicalName>,
    /// Physical tags of every entity (dim, tag), if the file has `$Entities`.
    pub entities: Option<HashMap<(usize, i32), Vec<i32>>>,
    /// Node tags and coordinates, in file order.
    pub node_tags: Vec<u64>,
    pub node_coords: Vec<[f64; 3]>,
    pub element_blocks: Vec<ElementBlock>,
    pub has_nodes: bool,
    pub has_elements: bool,
}

pub(crate) fn input_err(path: &Path, message: impl Into<String>) -> StampError {
    StampError::Input { file: path.display().to_string(), message: message.into() }
}

/// A reader over the bytes of one file, ASCII or binary.
struct Cursor<'a> {
    path: &'a Path,
    bytes: &'a [u8],
    pos: usize,
    binary: bool,
    big_endian: bool,
    size_t: usize,
    /// The section being read (for messages).
    section: &'static str,
}

fn is_space(b: u8) -> bool {
    b == b' ' || b == b'\t' || b == b'\n' || b == b'\r'
}

impl<'a> Cursor<'a> {
    fn err(&self, message: impl Into<String>) -> StampError {
        input_err(self.path, message)
    }

    /// The error for data that ends before the section says it should.
    fn truncated(&self, what: &str) -> StampError {
        let end = format!("$End{}", &self.section[1..]);
        if find_line(self.bytes, &end, self.pos).is_none() {
            self.err(format!("the file is truncated: the {} section has no {end} line (reading {what})", self.section))
        } else {
            self.err(format!("the {} section ends early or is corrupt: expected {what}", self.section))
        }
    }

    fn skip_space(&mut self) {
        while self.pos < self.bytes.len() && is_space(self.bytes[self.pos]) {
            self.pos += 1;
        }
    }

    /// The next whitespace-separated token (ASCII files).
    fn token(&mut self, what: &str) -> Result<&'a [u8]> {
        self.skip_space();
        let start = self.pos;
        while self.pos < self.bytes.len() && !is_space(self.bytes[self.pos]) {
            self.pos += 1;
        }
        let t = &self.bytes[start..self.pos];
        if t.is_empty() || t[0] == b'$' {
            self.pos = start;
            return Err(self.truncated(what));
        }
        Ok(t)
    }

    fn parse_token<T: std::str::FromStr>(&mut self, what: &str) -> Result<T> {
        let t = self.token(what)?;
        std::str::from_utf8(t).ok().and_then(|s| s.parse().ok()).ok_or_else(|| {
            self.err(format!("{} section: expected {what}, found '{}'", self.section, quote_bytes(t)))
        })
    }

    fn take(&mut self, n: usize, what: &str) -> Result<&'a [u8]> {
        match self.bytes.get(self.pos..self.pos.saturating_add(n)) {
            Some(s) => {
                self.pos += n;
                Ok(s)
            }
            None => Err(self.truncated(what)),
        }
    }

    fn uint(&self, s: &[u8]) -> u64 {
        let mut v = 0u64;
        if self.big_endian {
            for &b in s {
                v = (v << 8) | b as u64;
            }
        } else {
            for &b in s.iter().rev() {
                v = (v << 8) | b as u64;
            }
        }
        v
    }

    /// An unsigned size (size_t in binary files).
    fn size(&mut self, what: &str) -> Result<u64> {
        if self.binary {
            let s = self.take(self.size_t, what)?;
            Ok(self.uint(s))
        } else {
            self.parse_token(what)
        }
    }

    /// A signed 32-bit integer.
    fn int(&mut self, what: &str) -> Result<i32> {
        if self.binary {
            let s = self.take(4, what)?;
            Ok(self.uint(s) as u32 as i32)
        } else {
            self.parse_token(what)
        }
    }

    fn double(&mut self, what: &str) -> Result<f64> {
        if self.binary {
            let s = self.take(8, what)?;
            Ok(f64::from_bits(self.uint(s)))
        } else {
            self.parse_token(what)
        }
    }

    /// Checks that `count` entries of at least `ascii_tokens` tokens (ASCII, 2 bytes each at
    /// least) or `binary_bytes` bytes (binary) fit in what is left of the file, and returns the
    /// count as a usize that may size an allocation.
    fn count(&self, count: u64, ascii_tokens: usize, binary_bytes: usize, what: &str) -> Result<usize> {
        let per = if self.binary { binary_bytes } else { 2 * ascii_tokens }.max(1) as u64;
        let left = (self.bytes.len() - self.pos.min(self.bytes.len())) as u64;
        if count > left / per {
            return Err(self.err(format!(
                "{} section: {what} is {count}, more than the {left} bytes left in the file can hold",
                self.section
            )));
        }
        Ok(count as usize)
    }

    /// Expects the line `$End<section>` next.
    fn end_section(&mut self) -> Result<()> {
        self.skip_space();
        let end = format!("$End{}", &self.section[1..]);
        let rest = &self.bytes[self.pos..];
        let line_end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        let line = trim_end(&rest[..line_end]);
        if line == end.as_bytes() {
            self.pos += line_end;
            return Ok(());
        }
        if line.is_empty() {
            return Err(self.err(format!("the file is truncated: the {} section has no {end} line", self.section)));
        }
        Err(self.err(format!(
            "the {} section is not closed by {end} where its counts say it ends (found '{}'): the counts or the data are wrong",
            self.section,
            quote_bytes(&line[..line.len().min(40)])
        )))
    }
}

fn trim_end(mut line: &[u8]) -> &[u8] {
    while let Some((&last, rest)) = line.split_last() {
        if is_space(last) {
            line = rest;
        } else {
            break;
        }
    }
    line
}

/// Offset of the start of the line that is exactly `name` (ignoring trailing spaces), from `from`.
pub(crate) fn find_line(bytes: &[u8], name: &str, from: usize) -> Option<usize> {
    let pat = name.as_bytes();
    let mut i = from;
    while i + pat.len() <= bytes.len() {
        let p = bytes[i..].windows(pat.len()).position(|w| w == pat)? + i;
        let at_line_start = p == 0 || bytes[p - 1] == b'\n';
        let after = p + pat.len();
        let rest = &bytes[after..];
        let line_end = rest.iter().position(|&b| b == b'\n').unwrap_or(rest.len());
        if at_line_start && rest[..line_end].iter().all(|&b| is_space(b)) {
            return Some(p);
        }
        i = p + 1;
    }
    None
}

/// The file format: binary or not, byte order, size of size_t.
struct Format {
    binary: bool,
    big_endian: bool,
    size_t: usize,
}

fn next_line(bytes: &[u8], start: usize) -> Option<(&[u8], usize)> {
    if start >= bytes.len() {
        return None;
    }
    let end = bytes[start..].iter().position(|&b| b == b'\n').map(|p| start + p).unwrap_or(bytes.len());
    Some((trim_end(&bytes[start..end]), (end + 1).min(bytes.len())))
}

/// Reads `$MeshFormat`; returns the format and the offset after `$EndMeshFormat`.
fn read_header(path: &Path, bytes: &[u8]) -> Result<(Format, usize)> {
    let convert = format!(
        "stamp reads MSH 4.1 only: convert with `gmsh {} -save -format msh41` (add `-bin` for binary), \
         or export with `-format msh41` / Mesh.MshFileVersion = 4.1",
        crate::error::quote(&path.file_name().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default())
    );
    let mut start = 0;
    while start < bytes.len() && is_space(bytes[start]) {
        start += 1;
    }
    let first = next_line(bytes, start);
    let Some((b"$MeshFormat", next)) = first else {
        return Err(input_err(
            path,
            if bytes.is_empty() {
                "the file is empty (expected a gmsh MSH 4.1 mesh)"
            } else {
                "not a gmsh mesh: the file does not start with $MeshFormat"
            },
        ));
    };
    let trunc = || input_err(path, "the file is truncated in the $MeshFormat section");
    let (line, mut after) = next_line(bytes, next).ok_or_else(trunc)?;
    let fields: Vec<&[u8]> = line.split(|&b| b == b' ' || b == b'\t').filter(|f| !f.is_empty()).collect();
    if fields.len() != 3 {
        return Err(input_err(
            path,
            format!("malformed $MeshFormat line '{}' (expected 'version file-type data-size')", quote_bytes(line)),
        ));
    }
    if fields[0] != b"4.1" {
        return Err(input_err(path, format!("MSH format version {} is not supported; {convert}", quote_bytes(fields[0]))));
    }
    let binary = match fields[1] {
        b"0" => false,
        b"1" => true,
        other => {
            return Err(input_err(
                path,
                format!("unknown MSH file type '{}' in $MeshFormat (expected 0 or 1)", quote_bytes(other)),
            ))
        }
    };
    let size_t = match fields[2] {
        b"8" => 8,
        b"4" => 4,
        other => {
            return Err(input_err(
                path,
                format!("unsupported MSH data size '{}' in $MeshFormat (expected 8)", quote_bytes(other)),
            ))
        }
    };
    let mut big_endian = false;
    if binary {
        let one = bytes.get(after..after + 4).ok_or_else(trunc)?;
        big_endian = match one {
            [1, 0, 0, 0] => false,
            [0, 0, 0, 1] => true,
            _ => {
                return Err(input_err(path, "binary $MeshFormat: cannot detect the byte order (the integer 1 is missing)"))
            }
        };
        after += 4;
    }
    let mut c = Cursor { path, bytes, pos: after, binary: false, big_endian, size_t, section: "$MeshFormat" };
    c.end_section()?;
    Ok((Format { binary, big_endian, size_t }, c.pos))
}

/// Reads the whole file.
pub(crate) fn read_sections(path: &Path, bytes: &[u8]) -> Result<RawMsh> {
    let (fmt, mut pos) = read_header(path, bytes)?;
    let mut raw = RawMsh::default();
    let mut seen: HashSet<Vec<u8>> = HashSet::new();
    loop {
        while pos < bytes.len() && is_space(bytes[pos]) {
            pos += 1;
        }
        let Some((line, next)) = next_line(bytes, pos) else { break };
        if line.first() != Some(&b'$') || line.len() < 2 || line.starts_with(b"$End") {
            return Err(input_err(
                path,
                format!("expected a section header ($Name) but found '{}'", quote_bytes(&line[..line.len().min(40)])),
            ));
        }
        let name = &line[1..];
        let section: Option<&'static str> = match name {
            b"PhysicalNames" => Some("$PhysicalNames"),
            b"Entities" => Some("$Entities"),
            b"Nodes" => Some("$Nodes"),
            b"Elements" => Some("$Elements"),
            b"MeshFormat" => Some("$MeshFormat"),
            _ => None,
        };
        let Some(section) = section else {
            // Another section (periodic links, data, comments, ...): skipped to its end line.
            let end = format!("$End{}", String::from_utf8_lossy(name));
            let Some(p) = find_line(bytes, &end, next) else {
                return Err(input_err(
                    path,
                    format!("the file is truncated: the ${} section has no {} line", quote_bytes(name), quote_bytes(end.as_bytes())),
                ));
            };
            pos = p + end.len();
            continue;
        };
        if !seen.insert(name.to_vec()) {
            return Err(input_err(path, format!("the file has more than one {section} section")));
        }
        let binary = fmt.binary && section != "$PhysicalNames" && section != "$MeshFormat";
        let mut c = Cursor {
            path,
            bytes,
            pos: next,
            binary,
            big_endian: fmt.big_endian,
            size_t: fmt.size_t,
            section,
        };
        match section {
            "$PhysicalNames" => raw.physical_names = read_physical_names(&mut c)?,
            "$Entities" => raw.entities = Some(read_entities(&mut c)?),
            "$Nodes" => {
                read_nodes(&mut c, &mut raw)?;
                raw.has_nodes = true;
            }
            "$Elements" => {
                raw.element_blocks = read_elements(&mut c)?;
                raw.has_elements = true;
            }
            _ => return Err(input_err(path, "the file has more than one $MeshFormat section")),
        }
        c.end_section()?;
        pos = c.pos;
    }
    Ok(raw)
}

fn read_physical_names(c: &mut Cursor) -> Result<Vec<PhysicalName>> {
    let n = c.size("the number of physical names")?;
    let count = c.count(n, 3, 0, "the number of physical names")?;
    let mut names = Vec::with_capacity(count);
    for k in 0..count {
        c.skip_space();
        let Some((line, next)) = next_line(c.bytes, c.pos) else {
            return Err(c.truncated("a physical name"));
        };
        if line.starts_with(b"$End") {
            return Err(c.err(format!("$PhysicalNames announces {count} names but has {k}")));
        }
        let text = String::from_utf8_lossy(line);
        let bad = || {
            c.err(format!(
                "$PhysicalNames entry {} is malformed: '{}' (expected: dim tag \"name\")",
                k + 1,
                crate::error::quote(&text)
            ))
        };
        let mut it = text.splitn(3, char::is_whitespace);
        let dim: usize = it.next().and_then(|s| s.parse().ok()).filter(|&d| d <= 3).ok_or_else(bad)?;
        let tag: i32 = it.next().and_then(|s| s.parse().ok()).ok_or_else(bad)?;
        let rest = it.next().ok_or_else(bad)?.trim();
        if rest.len() < 2 || !rest.starts_with('"') || !rest.ends_with('"') {
            return Err(bad());
        }
        names.push(PhysicalName { dim, tag, name: rest[1..rest.len() - 1].to_string() });
        c.pos = next;
    }
    c.skip_space();
    if let Some((line, _)) = next_line(c.bytes, c.pos) {
        if !line.starts_with(b"$") {
            return Err(c.err(format!("$PhysicalNames has more entries than the {count} it announces")));
        }
    }
    Ok(names)
}

fn read_entities(c: &mut Cursor) -> Result<HashMap<(usize, i32), Vec<i32>>> {
    let st = c.size_t;
    let mut counts = [0u64; 4];
    for (d, what) in ["points", "curves", "surfaces", "volumes"].iter().enumerate() {
        counts[d] = c.size(&format!("the number of {what}"))?;
    }
    let mut map = HashMap::new();
    for (dim, &n) in counts.iter().enumerate() {
        let word = ["point", "curve", "surface", "volume"][dim];
        let (tokens, bytes) = if dim == 0 { (5, 4 + 24 + st) } else { (9, 4 + 48 + 2 * st) };
        let n = c.count(n, tokens, bytes, &format!("the number of {word} entities"))?;
        for _ in 0..n {
            let tag = c.int(&format!("a {word} entity tag"))?;
            for _ in 0..if dim == 0 { 3 } else { 6 } {
                c.double(&format!("the bounding box of {word} entity {tag}"))?;
            }
            let np = c.size(&format!("the number of physical tags of {word} entity {tag}"))?;
            let np = c.count(np, 1, 4, &format!("the number of physical tags of {word} entity {tag}"))?;
            let mut phys = Vec::with_capacity(np);
            for _ in 0..np {
                phys.push(c.int(&format!("a physical tag of {word} entity {tag}"))?.wrapping_abs());
            }
            if dim > 0 {
                let nb = c.size(&format!("the number of bounding entities of {word} entity {tag}"))?;
                let nb = c.count(nb, 1, 4, &format!("the number of bounding entities of {word} entity {tag}"))?;
                for _ in 0..nb {
                    c.int(&format!("a bounding entity of {word} entity {tag}"))?;
                }
            }
            if map.insert((dim, tag), phys).is_some() {
                return Err(c.err(format!("$Entities lists {word} entity {tag} twice")));
            }
        }
    }
    Ok(map)
}

fn read_nodes(c: &mut Cursor, raw: &mut RawMsh) -> Result<()> {
    let st = c.size_t;
    let blocks = c.size("the number of node blocks")?;
    let num_nodes = c.size("the number of nodes")?;
    let min_tag = c.size("the smallest node tag")?;
    let max_tag = c.size("the largest node tag")?;
    let blocks = c.count(blocks, 4, 12 + st, "the number of node blocks")?;
    let total = c.count(num_nodes, 4, st + 24, "the number of nodes")?;
    raw.node_tags.reserve(total);
    raw.node_coords.reserve(total);
    for b in 0..blocks {
        let dim = c.int("the entity dimension of a node block")?;
        let entity = c.int("the entity tag of a node block")?;
        let parametric = c.int("the parametric flag of a node block")?;
        if parametric != 0 {
            return Err(c.err(format!(
                "node block {} (on entity {dim}D {entity}) has parametric coordinates, which are not supported: save the mesh without Mesh.SaveParametric",
                b + 1
            )));
        }
        let n = c.size("the number of nodes in a block")?;
        let n = c.count(n, 4, st + 24, &format!("the number of nodes in block {} (entity {dim}D {entity})", b + 1))?;
        let first = raw.node_tags.len();
        if first + n > total {
            return Err(c.err(format!("$Nodes: the blocks hold more nodes than the {total} the header announces")));
        }
        for _ in 0..n {
            let tag = c.size("a node tag")?;
            if tag == 0 {
                return Err(c.err(format!("$Nodes: node tag 0 is invalid (block {}, entity {dim}D {entity})", b + 1)));
            }
            raw.node_tags.push(tag);
        }
        for _ in 0..n {
            let what = "node coordinates";
            raw.node_coords.push([c.double(what)?, c.double(what)?, c.double(what)?]);
        }
    }
    if raw.node_tags.len() != total {
        return Err(c.err(format!(
            "$Nodes: the header announces {total} nodes but the blocks hold {}",
            raw.node_tags.len()
        )));
    }
    check_tag_range(c, "node", &raw.node_tags, min_tag, max_tag)
}

/// The header's tag range must be the range of the tags, and no tag may repeat.
fn check_tag_range(c: &Cursor, what: &str, tags: &[u64], min_tag: u64, max_tag: u64) -> Result<()> {
    if let (Some(&lo), Some(&hi)) = (tags.iter().min(), tags.iter().max()) {
        if lo != min_tag || hi != max_tag {
            return Err(c.err(format!(
                "{}: the header gives {what} tags {min_tag} to {max_tag} but the tags run from {lo} to {hi}",
                c.section
            )));
        }
    }
    let mut sorted = tags.to_vec();
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(c.err(format!("{what} tag {} appears more than once in {}", w[0], c.section)));
    }
    Ok(())
}

fn read_elements(c: &mut Cursor) -> Result<Vec<ElementBlock>> {
    let st = c.size_t;
    let blocks = c.size("the number of element blocks")?;
    let num = c.size("the number of elements")?;
    let min_tag = c.size("the smallest element tag")?;
    let max_tag = c.size("the largest element tag")?;
    let blocks = c.count(blocks, 4, 12 + st, "the number of element blocks")?;
    let total = c.count(num, 2, 2 * st, "the number of elements")?;
    let mut out = Vec::with_capacity(blocks);
    let mut all_tags = Vec::with_capacity(total);
    for b in 0..blocks {
        let dim = c.int("the entity dimension of an element block")?;
        let entity = c.int("the entity tag of an element block")?;
        let ty = c.int("the element type of an element block")?;
        let n = c.size("the number of elements in a block")?;
        let Some(nn) = super::elements::nodes_per_element(ty) else {
            let first = if n > 0 { c.size("an element tag").ok() } else { None };
            return Err(c.err(format!(
                "{}gmsh element type {ty} ({}, in block {} on entity {dim}D {entity}) is not supported; {}",
                first.map(|t| format!("element {t}: ")).unwrap_or_default(),
                element_type_name(ty),
                b + 1,
                super::elements::SUPPORTED
            )));
        };
        let n = c.count(n, 1 + nn, (1 + nn) * st, &format!("the number of elements in block {}", b + 1))?;
        if all_tags.len() + n > total {
            return Err(c.err(format!("$Elements: the blocks hold more elements than the {total} the header announces")));
        }
        let mut tags = Vec::with_capacity(n);
        let mut nodes = Vec::with_capacity(n * nn);
        for _ in 0..n {
            let tag = c.size("an element tag")?;
            if tag == 0 {
                return Err(c.err(format!("$Elements: element tag 0 is invalid (block {}, entity {dim}D {entity})", b + 1)));
            }
            tags.push(tag);
            for _ in 0..nn {
                nodes.push(c.size("the node tags of an element")?);
            }
        }
        all_tags.extend_from_slice(&tags);
        out.push(ElementBlock { entity_dim: dim, entity_tag: entity, element_type: ty, nodes_per_element: nn, tags, nodes });
    }
    if all_tags.len() != total {
        return Err(c.err(format!(
            "$Elements: the header announces {total} elements but the blocks hold {}",
            all_tags.len()
        )));
    }
    check_tag_range(c, "element", &all_tags, min_tag, max_tag)?;
    Ok(out)
}

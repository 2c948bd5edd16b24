//! The STL reader: ASCII and binary STL files into an indexed triangle mesh (vertices welded by
//! exact coordinates), checked for what the signed distance of [`super::StlSurface`] needs:
//! finite coordinates, facets of non-zero area and a consistent orientation (no two facets
//! traverse a shared edge in the same direction).
//!
//! The facet normal stored in the file is ignored: the orientation is the vertex order
//! (counter-clockwise seen from the side the normal points to, the STL convention).
//!
//! An ASCII file may hold several solids one after the other (`solid` ... `endsolid`, as CAD
//! programs write a body of several parts): the die is all their facets together. Anything else
//! after the last `endsolid`, or between `solid` and the first `facet`, is refused with its line.
//!
//! Binary or ASCII: a file whose size is exactly 84 + 50 N bytes, N the count in its header, is
//! binary; otherwise a file starting with `solid` is ASCII; anything else is a binary file whose
//! size does not match its header (truncated or padded). The header's count is checked against the
//! file size and against the facet limit before anything is allocated from it.

use stamp::error::quote_bytes;
use stamp::{quote, Result, StampError};
use std::collections::HashMap;
use std::path::Path;

/// The largest die accepted by default: 20 million facets (about 4 GiB with the search tree).
pub const DEFAULT_MAX_FACETS: usize = 20_000_000;

/// Approximate bytes needed per facet once read and indexed (vertices, facets, normals, tree).
pub const BYTES_PER_FACET: usize = 200;

/// An indexed triangle mesh read from an STL file.
#[derive(Debug, Clone)]
pub struct TriangleMesh {
    /// Distinct vertices (welded by exact coordinates).
    pub vertices: Vec<[f64; 3]>,
    /// Facets as vertex indices, in the file's order and orientation.
    pub facets: Vec<[u32; 3]>,
}

fn input_error(path: &Path, message: impl Into<String>) -> StampError {
    StampError::Input { file: path.display().to_string(), message: message.into() }
}

/// Reads and checks an STL file with at most `max_facets` facets.
pub fn read_stl(path: &Path, max_facets: usize) -> Result<TriangleMesh> {
    let meta = std::fs::metadata(path).map_err(|e| input_error(path, format!("cannot read the STL file: {e}")))?;
    if !meta.is_file() {
        return Err(input_error(path, "is not a regular file (an STL file is expected)"));
    }
    let size = meta.len();
    // the largest file that can hold max_facets facets: binary 84 + 50 N, ASCII ~ 1 KiB a facet
    let max_bytes = (max_facets as u64).saturating_mul(1024).saturating_add(4096);
    if size > max_bytes {
        return Err(too_many(path, format!("the file has {size} bytes"), max_facets));
    }
    let bytes = std::fs::read(path).map_err(|e| input_error(path, format!("cannot read the STL file: {e}")))?;
    parse_stl_bytes(path, &bytes, max_facets)
}

/// Parses and checks the bytes of an STL file (`path` names it in errors) with at most
/// `max_facets` facets: [`read_stl`] without the file system.
pub fn parse_stl_bytes(path: &Path, bytes: &[u8], max_facets: usize) -> Result<TriangleMesh> {
    let soup = if let Some(n) = binary_count(&bytes) {
        if 84 + 50 * n as u64 == bytes.len() as u64 {
            if n as usize > max_facets {
                return Err(too_many(path, format!("the header announces {n} facets"), max_facets));
            }
            read_binary(path, bytes, n as usize)?
        } else if bytes.starts_with(b"solid") {
            read_ascii(path, bytes, max_facets)?
        } else {
            return Err(input_error(
                path,
                format!(
                    "binary STL: the header announces {n} facets (84 + 50 x {n} = {} bytes) but the file has {} bytes (truncated or not an STL file)",
                    84 + 50 * n as u64,
                    bytes.len()
                ),
            ));
        }
    } else if bytes.starts_with(b"solid") {
        read_ascii(path, bytes, max_facets)?
    } else {
        return Err(input_error(
            path,
            format!("not an STL file: {} bytes, too short for a binary STL (84-byte header) and not starting with `solid`", bytes.len()),
        ));
    };
    if soup.is_empty() {
        return Err(input_error(path, "the STL file has no facets"));
    }
    let mesh = weld(&soup);
    check_facets(path, &mesh)?;
    Ok(mesh)
}

fn too_many(path: &Path, what: String, max_facets: usize) -> StampError {
    input_error(
        path,
        format!(
            "too many facets for memory: {what}; at most {max_facets} facets (about {} bytes each once indexed) are accepted",
            BYTES_PER_FACET
        ),
    )
}

/// The facet count of a binary header, if the file is long enough to have one.
fn binary_count(bytes: &[u8]) -> Option<u32> {
    (bytes.len() >= 84).then(|| u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]))
}

/// Facets as three vertices each, coordinates checked finite.
type Soup = Vec<[[f64; 3]; 3]>;

fn check_finite(path: &Path, facet: usize, v: &[[f64; 3]; 3]) -> Result<()> {
    if v.iter().flatten().all(|c| c.is_finite()) {
        Ok(())
    } else {
        Err(input_error(path, format!("facet {facet}: a vertex coordinate is not finite ({:?})", v)))
    }
}

fn read_binary(path: &Path, bytes: &[u8], n: usize) -> Result<Soup> {
    let mut soup = Vec::with_capacity(n);
    for k in 0..n {
        let rec = &bytes[84 + 50 * k..84 + 50 * (k + 1)];
        let f = |i: usize| f32::from_le_bytes([rec[4 * i], rec[4 * i + 1], rec[4 * i + 2], rec[4 * i + 3]]) as f64;
        // record: normal (3 floats), three vertices (9 floats), attribute (2 bytes)
        let v = [[f(3), f(4), f(5)], [f(6), f(7), f(8)], [f(9), f(10), f(11)]];
        check_finite(path, k + 1, &v)?;
        soup.push(v);
    }
    Ok(soup)
}

fn read_ascii(path: &Path, bytes: &[u8], max_facets: usize) -> Result<Soup> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        input_error(path, format!("ASCII STL: not valid text at byte {} (nor a binary STL of matching size)", e.valid_up_to()))
    })?;
    let tokens = text
        .lines()
        .enumerate()
        .flat_map(|(l, line)| line.split_whitespace().map(move |t| (l + 1, t)));
    let mut soup = Vec::new();
    let err = |line: usize, m: String| input_error(path, format!("line {line}: {m}"));
    let expect = |tok: Option<(usize, &str)>, want: &str, facet: usize| -> Result<usize> {
        match tok {
            Some((l, t)) if t == want => Ok(l),
            Some((l, t)) => Err(err(l, format!("facet {facet}: expected `{want}`, found '{}'", quote(t)))),
            None => Err(input_error(path, format!("facet {facet}: the file ends where `{want}` is expected"))),
        }
    };
    // one or more solids, each `solid [name]` ... `endsolid [name]` (the names on the keyword's own
    // line); after the last, nothing but blanks: a word anywhere else is refused with its line
    let mut tokens = tokens.peekable();
    let mut solids = 0usize;
    loop {
        match tokens.next() {
            // the file starts with `solid` (checked): its first word may run into the name
            Some((l, t)) if t == "solid" || (solids == 0 && t.starts_with("solid")) => {
                while tokens.peek().is_some_and(|&(l2, _)| l2 == l) {
                    tokens.next();
                }
            }
            Some((l, t)) => {
                return Err(err(l, format!("after `endsolid` of solid {solids}: expected `solid` (another solid) or the end of the file, found '{}'", quote(t))));
            }
            None => break,
        }
        solids += 1;
        loop {
            let facet = soup.len() + 1;
            match tokens.next() {
                Some((_, "facet")) => {}
                Some((l, "endsolid")) => {
                    while tokens.peek().is_some_and(|&(l2, _)| l2 == l) {
                        tokens.next();
                    }
                    break;
                }
                Some((l, t)) => return Err(err(l, format!("expected `facet` or `endsolid`, found '{}'", quote(t)))),
                None => return Err(input_error(path, format!("ASCII STL: the file ends after {} facets without `endsolid`", soup.len()))),
            }
            if soup.len() >= max_facets {
                return Err(too_many(path, format!("more than {max_facets} facets"), max_facets));
            }
            expect(tokens.next(), "normal", facet)?;
            for _ in 0..3 {
                number(path, tokens.next(), facet)?;
            }
            expect(tokens.next(), "outer", facet)?;
            expect(tokens.next(), "loop", facet)?;
            let mut v = [[0.0; 3]; 3];
            for vertex in v.iter_mut() {
                expect(tokens.next(), "vertex", facet)?;
                for c in vertex.iter_mut() {
                    *c = number(path, tokens.next(), facet)?;
                }
            }
            expect(tokens.next(), "endloop", facet)?;
            expect(tokens.next(), "endfacet", facet)?;
            check_finite(path, facet, &v)?;
            soup.push(v);
        }
    }
    Ok(soup)
}

fn number(path: &Path, tok: Option<(usize, &str)>, facet: usize) -> Result<f64> {
    match tok {
        Some((l, t)) => t.parse::<f64>().map_err(|_| {
            input_error(path, format!("line {l}: facet {facet}: '{}' is not a number", quote_bytes(t.as_bytes())))
        }),
        None => Err(input_error(path, format!("facet {facet}: the file ends where a number is expected"))),
    }
}

/// Merges vertices with identical coordinates (STL repeats them in every facet).
fn weld(soup: &Soup) -> TriangleMesh {
    let mut index: HashMap<[u64; 3], u32> = HashMap::with_capacity(soup.len() / 2 + 3);
    let mut vertices = Vec::with_capacity(soup.len() / 2 + 3);
    let mut facets = Vec::with_capacity(soup.len());
    for f in soup {
        let mut t = [0u32; 3];
        for (k, v) in f.iter().enumerate() {
            // +0.0 and -0.0 are the same point
            let key = v.map(|c| (c + 0.0).to_bits());
            t[k] = *index.entry(key).or_insert_with(|| {
                vertices.push(*v);
                (vertices.len() - 1) as u32
            });
        }
        facets.push(t);
    }
    TriangleMesh { vertices, facets }
}

/// Zero-area facets and inconsistent orientation.
fn check_facets(path: &Path, mesh: &TriangleMesh) -> Result<()> {
    let v = &mesh.vertices;
    for (k, t) in mesh.facets.iter().enumerate() {
        let [a, b, c] = t.map(|i| v[i as usize]);
        let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
        let n = [u[1] * w[2] - u[2] * w[1], u[2] * w[0] - u[0] * w[2], u[0] * w[1] - u[1] * w[0]];
        let n2 = n.iter().map(|x| x * x).sum::<f64>();
        let e2 = u.iter().chain(w.iter()).map(|x| x * x).sum::<f64>();
        // relative to the edges: a facet whose vertices are (numerically) on one line has no normal
        if !(n2 > 1e-24 * e2 * e2) {
            return Err(input_error(
                path,
                format!("facet {}: degenerate (zero area): vertices {:?}, {:?}, {:?}", k + 1, a, b, c),
            ));
        }
    }
    let mut edges: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.facets.len() * 3);
    for (k, t) in mesh.facets.iter().enumerate() {
        for e in 0..3 {
            let key = (t[e], t[(e + 1) % 3]);
            if let Some(other) = edges.insert(key, k as u32) {
                let p = v[key.0 as usize];
                let q = v[key.1 as usize];
                return Err(input_error(
                    path,
                    format!(
                        "facets {} and {} traverse their shared edge {:?} -> {:?} in the same direction: inconsistent orientation (flip one of them so that every normal points to the plate's side)",
                        other + 1,
                        k + 1,
                        p,
                        q
                    ),
                ));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::test_rng::Rng;

    const TETRAHEDRON: &str = "solid t\n facet normal 0 0 -1\n  outer loop\n   vertex 0 0 0\n   vertex 0 1 0\n   vertex 1 0 0\n  endloop\n endfacet\n \
facet normal 0 -1 0\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 0 1\n  endloop\n endfacet\n \
facet normal -1 0 0\n  outer loop\n   vertex 0 0 0\n   vertex 0 0 1\n   vertex 0 1 0\n  endloop\n endfacet\n \
facet normal 1 1 1\n  outer loop\n   vertex 1 0 0\n   vertex 0 1 0\n   vertex 0 0 1\n  endloop\n endfacet\nendsolid t\n";

    /// The binary form of the tetrahedron above.
    fn binary() -> Vec<u8> {
        let mesh = parse_stl_bytes(Path::new("t.stl"), TETRAHEDRON.as_bytes(), 100).unwrap();
        let mut b = vec![0u8; 80];
        b.extend((mesh.facets.len() as u32).to_le_bytes());
        for f in &mesh.facets {
            b.extend([0u8; 12]);
            for &v in f {
                for c in mesh.vertices[v as usize] {
                    b.extend((c as f32).to_le_bytes());
                }
            }
            b.extend([0u8; 2]);
        }
        b
    }

    /// `bytes` with a few random edits: bytes flipped, cut, repeated, inserted words.
    fn mutate(rng: &mut Rng, bytes: &[u8]) -> Vec<u8> {
        let mut b = bytes.to_vec();
        for _ in 0..1 + rng.below(4) {
            let at = rng.below(b.len() + 1);
            match rng.below(6) {
                0 if at < b.len() => b[at] = rng.next() as u8,
                1 => b.truncate(at),
                2 => {
                    let words: [&[u8]; 8] = [b"solid", b"endsolid", b"facet", b" nan ", b" 1e308 ", b"\n", b"vertex", b"-0"];
                    let w = words[rng.below(words.len())];
                    b.splice(at.min(b.len())..at.min(b.len()), w.iter().copied());
                }
                3 if at + 50 <= b.len() => {
                    let piece = b[at..at + 50].to_vec();
                    b.splice(at..at, piece);
                }
                4 if b.len() >= 84 => b[80..84].copy_from_slice(&(rng.next() as u32).to_le_bytes()),
                _ => b.extend((0..rng.below(8)).map(|_| rng.next() as u8)),
            }
        }
        b
    }

    #[test]
    fn hundreds_of_mutated_files_give_a_mesh_or_an_error_never_a_panic() {
        let mut rng = Rng(0x5eed_2026);
        let seeds = [TETRAHEDRON.as_bytes().to_vec(), binary()];
        let (mut ok, mut err) = (0, 0);
        for k in 0..600 {
            let input = if k % 10 == 9 { (0..rng.below(300)).map(|_| rng.next() as u8).collect() } else { mutate(&mut rng, &seeds[k % 2]) };
            match parse_stl_bytes(Path::new("fuzz.stl"), &input, 1000) {
                Ok(m) => {
                    ok += 1;
                    assert!(!m.facets.is_empty());
                    assert!(m.facets.iter().flatten().all(|&v| (v as usize) < m.vertices.len()));
                    assert!(m.vertices.iter().flatten().all(|c| c.is_finite()));
                }
                Err(e) => {
                    err += 1;
                    let msg = e.to_string();
                    assert!(msg.starts_with("fuzz.stl: ") && msg.len() < 1000, "{msg}");
                }
            }
        }
        // both outcomes are exercised
        assert!(ok > 10 && err > 100, "{ok} read, {err} refused");
    }
}

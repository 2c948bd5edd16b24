//! How much memory a model will need, checked before it is built: a problem that cannot fit is
//! refused with the estimate instead of dying of an allocation failure (or swapping for minutes).
//!
//! The estimate covers the mesh, the sparse tangent and its pattern, the preconditioner and the
//! LDL^T factor, whose fill grows like N log2 N for a nested-dissection ordering of a 2D mesh
//! (N unknowns: 6 per node in the paper's plate, 3 per surface in the others). Calibrated on
//! `stamp bench` (quarter plate, n x n cells): peak RSS 1.36 GiB at n = 200 (241 200 unknowns) and 5.85 GiB at n = 400 (961 600 unknowns); the formula
//! gives 1.44 and 6.14 GiB, a little on the safe side. Measured again with /usr/bin/time -v
//! (`stamp bench --one n`, 2026-11-24): n = 50 peaks at 0.077 GiB (estimate 0.13), n = 100 at
//! 0.32 GiB (estimate 0.37).

use stamp::memory::{MemoryLimit, ADDRESS_SPACE_OVERHEAD};

/// Unknowns per node of a plate of `surfaces` surfaces (the problem file's `[plate] surfaces`):
/// three per surface.
pub fn dofs_per_node(surfaces: impl Into<usize>) -> u64 {
    3 * surfaces.into() as u64
}

/// Bytes per unknown and per factor of log2(unknowns) (see the calibration above).
const BYTES_PER_UNKNOWN_LOG: f64 = 340.0;
/// What any run needs besides (program, buffers).
const BASE_BYTES: f64 = 64.0 * 1024.0 * 1024.0;

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// Estimated peak memory in bytes of a model with `nodes` nodes of `dofs_per_node` unknowns each
/// (f64: no overflow). The calibration above is of 6 unknowns a node; the tangent's and the
/// factor's blocks grow with the square of the unknowns a node, so that a laminate of 40 plies
/// (243 unknowns a node) is no longer estimated as if its unknowns were so many nodes of 6 (0.63
/// GiB for 20 x 20 cells, where the run needed several times that):
/// * the fill of the factor, the calibrated N log2 N, times dofs_per_node / 6 beyond 6 (the
///   separators' dense blocks are (dofs_per_node)^2 a node pair), but at most dense: N^2 / 2
///   numbers;
/// * the tangent, its preconditioner and their indices: 9 neighbouring nodes a node, a block of
///   (dofs_per_node)^2 each, `BLOCK_BYTES` (24 bytes) an entry.
///
/// Measured (peak RSS, `stamp run`, 4 x 4 cells, 2026-11-28): 40 plies x 3 surfaces (243 unknowns
/// a node) 0.43 GB, estimate 0.53 GB; 44 plies (267) 0.54 GB, estimate 0.63 GB; 20 plies (123)
/// 0.12 GB, estimate 0.18 GB. Models of 6 unknowns a node: the calibration above, unchanged.
pub fn estimate_bytes(nodes: u64, dofs_per_node: u64) -> f64 {
    let unknowns = (nodes as f64) * dofs_per_node as f64;
    let per_node = dofs_per_node as f64;
    let fill = BYTES_PER_UNKNOWN_LOG * unknowns * unknowns.max(2.0).log2() * (per_node / 6.0).max(1.0);
    let blocks = BLOCK_BYTES * 9.0 * nodes as f64 * per_node * per_node;
    let dense = 4.0 * unknowns * unknowns;
    BASE_BYTES + fill.min(dense + blocks).max(blocks)
}

/// Bytes a matrix entry of the tangent costs: its value, the preconditioner's and the row index.
const BLOCK_BYTES: f64 = 24.0;

/// Bytes of memory per facet of an STL die, besides the file's own bytes (read whole): the facet
/// soup, the welded vertices and their normals, the R-tree. Measured: a binary STL of 1 598 000
/// facets (80 MB) peaks at 610 MB in `stamp check` (2026-11-25), 330 bytes a facet beyond the file.
pub const BYTES_PER_STL_FACET: f64 = 360.0;
/// The fewest bytes an ASCII STL spends on a facet (`facet normal`, `outer loop`, three
/// `vertex` lines, `endloop`, `endfacet`, with the shortest numbers).
const MIN_ASCII_FACET_BYTES: f64 = 90.0;

/// The memory this process may use, in bytes ([`stamp::memory::available_bytes`]); None when it
/// is not known (no check).
pub fn available_bytes() -> Option<f64> {
    stamp::memory::available_bytes()
}

/// [`available_bytes`] with the words for what limits it.
fn limit() -> Option<(f64, String)> {
    let (bytes, why) = stamp::memory::memory_limit()?;
    let words = match why {
        MemoryLimit::Available => "available".to_string(),
        MemoryLimit::AddressSpace { limit } => format!("usable under ulimit -v ({:.2} GiB less {:.2} GiB for stacks and heaps)", limit / GIB, ADDRESS_SPACE_OVERHEAD / GIB),
    };
    Some((bytes, words))
}

/// Estimated memory of an STL die read from `path`: the file's bytes and [`BYTES_PER_STL_FACET`]
/// for each facet (a binary file's header count when its size matches, else as many facets as
/// the shortest ASCII text could hold); 0 for a file that cannot be looked at (reading it will say).
pub fn stl_bytes(path: &std::path::Path) -> f64 {
    use std::io::Read;
    let Ok(meta) = std::fs::metadata(path) else { return 0.0 };
    let size = meta.len() as f64;
    let mut head = [0u8; 84];
    let binary_count = std::fs::File::open(path)
        .ok()
        .filter(|_| meta.is_file())
        .and_then(|mut f| f.read_exact(&mut head).ok())
        .map(|()| u32::from_le_bytes([head[80], head[81], head[82], head[83]]) as f64)
        .filter(|&n| 84.0 + 50.0 * n == size);
    let facets = binary_count.unwrap_or(size / MIN_ASCII_FACET_BYTES);
    size + BYTES_PER_STL_FACET * facets
}

/// Ok if a model of `nodes` nodes with `dofs_per_node` unknowns each fits in the available
/// memory; else what it needs and what to do, as a message (the caller names the file and key).
pub fn check_model_fits(nodes: u64, dofs_per_node: u64) -> Result<(), String> {
    check_with(nodes, dofs_per_node, &[], limit())
}

/// [`check_model_fits`] with the STL dies (name as written, path) taking their share too.
pub fn check_problem_fits(stl_dies: &[(String, std::path::PathBuf)], nodes: u64, dofs_per_node: u64) -> Result<(), String> {
    let dies: Vec<(String, f64)> = stl_dies.iter().map(|(name, path)| (name.clone(), stl_bytes(path))).collect();
    check_with(nodes, dofs_per_node, &dies, limit())
}

/// [`check_model_fits`] against a given amount of memory (None: unknown, accepted).
pub fn check_against(nodes: u64, dofs_per_node: u64, available: Option<f64>) -> Result<(), String> {
    check_with(nodes, dofs_per_node, &[], available.map(|a| (a, "available".to_string())))
}

/// The check: the model's estimate and the STL dies' (file, bytes) against the memory `limit`
/// (bytes, and the words for where it comes from).
fn check_with(nodes: u64, dofs_per_node: u64, dies: &[(String, f64)], limit: Option<(f64, String)>) -> Result<(), String> {
    let need = estimate_bytes(nodes, dofs_per_node) + dies.iter().map(|d| d.1).sum::<f64>();
    let die_words: String = dies.iter().map(|(f, b)| format!(", STL die {f} {:.2} GiB", b / GIB)).collect();
    let coarser = if dies.is_empty() { "a coarser mesh" } else { "a coarser mesh or STL die" };
    match limit {
        Some((avail, what)) if need > avail => Err(format!(
            "the model has {nodes} nodes ({} unknowns) and needs about {:.2} GiB of memory (mesh, sparse matrix, LDL^T factor{die_words}), \
             but only {:.2} GiB is {what}: use {coarser}, or a machine with more memory",
            nodes.saturating_mul(dofs_per_node),
            need / GIB,
            avail / GIB
        )),
        _ => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's plate: three displacements on each of its two faces.
    const DOFS_PER_NODE: u64 = 6;

    #[test]
    fn the_estimate_matches_the_bench_calibration() {
        // quarter plate n x n: (n + 1)^2 nodes; measured 1.36 GiB (n = 200) and 5.85 GiB (n = 400)
        for (n, measured) in [(200u64, 1.36), (400, 5.85)] {
            let est = estimate_bytes((n + 1) * (n + 1), DOFS_PER_NODE) / GIB;
            assert!(est >= measured && est < 1.15 * measured, "n = {n}: {est} GiB against {measured}");
        }
    }

    #[test]
    fn the_estimate_grows_with_the_square_of_the_unknowns_a_node() {
        // measured peak RSS of laminates on 4 x 4 cells (25 nodes): the estimate above, within 1.6x
        for (dpn, measured_gb) in [(123u64, 0.119), (243, 0.436), (267, 0.536)] {
            let est = estimate_bytes(25, dpn) / 1e9;
            assert!(est >= measured_gb && est < 1.6 * measured_gb, "{dpn} unknowns a node: {est} GB against {measured_gb}");
        }
        // 40 plies on 20 x 20 cells: far beyond the 0.63 GiB it was estimated at
        assert!(estimate_bytes(441, 243) > 5.0 * GIB);
    }

    #[test]
    fn three_unknowns_per_surface() {
        assert_eq!(dofs_per_node(2usize), DOFS_PER_NODE);
        assert_eq!(dofs_per_node(5usize), 15);
    }

    #[test]
    fn an_stl_die_counts_by_its_facets() {
        let dir = std::env::temp_dir().join(format!("stamp-memory-stl-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // binary: 84 + 50 n bytes with n in the header
        let mut bytes = vec![0u8; 84 + 50 * 1000];
        bytes[80..84].copy_from_slice(&1000u32.to_le_bytes());
        std::fs::write(dir.join("b.stl"), &bytes).unwrap();
        assert_eq!(stl_bytes(&dir.join("b.stl")), bytes.len() as f64 + 1000.0 * BYTES_PER_STL_FACET);
        // ASCII: as many facets as the shortest text could hold
        std::fs::write(dir.join("a.stl"), "solid x\n".repeat(900)).unwrap();
        assert_eq!(stl_bytes(&dir.join("a.stl")), 7200.0 + 80.0 * BYTES_PER_STL_FACET);
        assert_eq!(stl_bytes(&dir.join("none.stl")), 0.0);
        let e = check_with(441, DOFS_PER_NODE, &[("die.stl".into(), 2.0 * GIB)], Some((1.0 * GIB, "available".into()))).unwrap_err();
        assert!(e.contains("STL die die.stl 2.00 GiB") && e.contains("coarser mesh or STL die"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_model_too_large_is_refused_with_the_estimate() {
        let e = check_against(25_010_001, DOFS_PER_NODE, Some(8.0 * GIB)).unwrap_err();
        assert!(e.contains("25010001 nodes") && e.contains("GiB") && e.contains("8.00 GiB is available") && e.contains("coarser mesh"), "{e}");
        assert!(check_against(441, DOFS_PER_NODE, Some(8.0 * GIB)).is_ok());
        assert!(check_against(u64::MAX, DOFS_PER_NODE, None).is_ok());
        assert!(check_against(u64::MAX, DOFS_PER_NODE, Some(1e12)).is_err());
    }
}

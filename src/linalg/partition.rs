//! Partitioning a mesh's elements into parts of about equal size with few shared nodes (METIS's
//! multilevel k-way partitioning of the element dual graph, `METIS_PartMeshDual`), for processes
//! that each evaluate one part (see [`crate::share`]).

use super::ordering::METIS;
use crate::error::{Result, StampError};

/// The part (0..parts) of each of `num_elements` elements whose nodes (indices below `num_nodes`)
/// `element_nodes(e)` lists: METIS's k-way partition of the graph of elements that share an edge
/// (two nodes), or one part for all when `parts` is 1. Deterministic: the same mesh gives the same
/// parts in every process. Fewer elements than parts, or a graph METIS refuses, is an error.
pub fn partition_elements(num_nodes: usize, num_elements: usize, element_nodes: impl Fn(usize) -> Vec<usize>, parts: usize) -> Result<Vec<u32>> {
    if parts <= 1 {
        return Ok(vec![0; num_elements]);
    }
    if num_elements < parts {
        return Err(StampError::Problem(format!("{num_elements} elements cannot be shared by {parts} processes")));
    }
    let too_big = || StampError::Problem("mesh too large for METIS's 32-bit indices".into());
    let idx = |n: usize| i32::try_from(n).map_err(|_| too_big());
    let mut eptr: Vec<i32> = Vec::with_capacity(num_elements + 1);
    let mut eind: Vec<i32> = Vec::new();
    eptr.push(0);
    for e in 0..num_elements {
        for n in element_nodes(e) {
            if n >= num_nodes {
                return Err(StampError::Problem(format!("element {e} has node {n}, the mesh {num_nodes} nodes")));
            }
            eind.push(idx(n)?);
        }
        eptr.push(idx(eind.len())?);
    }
    let (mut ne, mut nn, mut ncommon, mut nparts) = (idx(num_elements)?, idx(num_nodes)?, 2i32, idx(parts)?);
    let mut options = [0i32; metis_sys::METIS_NOPTIONS as usize];
    let mut objval = 0i32;
    let mut epart = vec![0i32; num_elements];
    let mut npart = vec![0i32; num_nodes];
    let status = {
        let _guard = METIS.lock().unwrap_or_else(|e| e.into_inner());
        // SAFETY: the arrays have the lengths METIS_PartMeshDual requires (ne + 1, eptr[ne],
        // NOPTIONS, ne, nn), outlive the call, and every node index is below nn; null weights and
        // target fractions mean equal ones.
        unsafe {
            metis_sys::METIS_SetDefaultOptions(options.as_mut_ptr());
            options[metis_sys::moptions_et_METIS_OPTION_NUMBERING as usize] = 0;
            metis_sys::METIS_PartMeshDual(
                &mut ne,
                &mut nn,
                eptr.as_mut_ptr(),
                eind.as_mut_ptr(),
                std::ptr::null_mut(),
                std::ptr::null_mut(),
                &mut ncommon,
                &mut nparts,
                std::ptr::null_mut(),
                options.as_mut_ptr(),
                &mut objval,
                epart.as_mut_ptr(),
                npart.as_mut_ptr(),
            )
        }
    };
    if status != metis_sys::rstatus_et_METIS_OK {
        return Err(StampError::Problem(format!("METIS_PartMeshDual failed (status {status})")));
    }
    epart.into_iter().map(|p| u32::try_from(p).ok().filter(|&p| (p as usize) < parts).ok_or_else(|| StampError::Problem(format!("METIS gave part {p} of {parts}")))).collect()
}

/// The owner of each node: the part of the lowest-numbered element around it (part 0 for a node
/// of no element), so that a node's owner evaluates an element of it.
pub fn node_owners(num_nodes: usize, num_elements: usize, element_nodes: impl Fn(usize) -> Vec<usize>, element_part: &[u32]) -> Vec<u32> {
    let mut owner = vec![u32::MAX; num_nodes];
    for e in 0..num_elements {
        for n in element_nodes(e) {
            if owner[n] == u32::MAX {
                owner[n] = element_part[e];
            }
        }
    }
    owner.iter_mut().filter(|o| **o == u32::MAX).for_each(|o| *o = 0);
    owner
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nodes of element e of a grid nx cells wide (numbered row by row, like its nodes).
    fn grid(nx: usize) -> impl Fn(usize) -> Vec<usize> {
        move |e| {
            let (i, j) = (e % nx, e / nx);
            let n = j * (nx + 1) + i;
            vec![n, n + 1, n + nx + 2, n + nx + 1]
        }
    }

    /// A 40 x 40 grid in 1, 2, 3 and 4 parts: every part nonempty and within 5 % of an equal
    /// share (METIS's default imbalance is 3 %), the cut a small multiple of the grid's side (a
    /// part of compact shape, not a scatter of elements), the same parts on a second call, and
    /// every node owned by the part of an element around it.
    #[test]
    fn grid_parts_are_balanced_compact_and_repeatable() {
        let (nx, ny) = (40, 40);
        let ne = nx * ny;
        let nn = (nx + 1) * (ny + 1);
        for parts in 1..=4 {
            let p = partition_elements(nn, ne, grid(nx), parts).unwrap();
            assert_eq!(p, partition_elements(nn, ne, grid(nx), parts).unwrap(), "{parts} parts: repeatable");
            let mut size = vec![0usize; parts];
            p.iter().for_each(|&k| size[k as usize] += 1);
            for s in &size {
                assert!((*s as f64) > 0.95 * ne as f64 / parts as f64 && (*s as f64) < 1.05 * ne as f64 / parts as f64, "{parts} parts: sizes {size:?}");
            }
            // edges between elements of different parts
            let mut cut = 0;
            for j in 0..ny {
                for i in 0..nx {
                    let e = j * nx + i;
                    if i + 1 < nx && p[e] != p[e + 1] {
                        cut += 1;
                    }
                    if j + 1 < ny && p[e] != p[e + nx] {
                        cut += 1;
                    }
                }
            }
            assert!(cut <= 3 * nx * (parts - 1), "{parts} parts: {cut} cut edges");
            let owners = node_owners(nn, ne, grid(nx), &p);
            for (n, &o) in owners.iter().enumerate() {
                assert!((0..ne).any(|e| p[e] == o && grid(nx)(e).contains(&n)), "node {n} owned by part {o}, which has no element of it");
            }
        }
        assert!(partition_elements(nn, 3, grid(nx), 4).is_err());
    }
}

//! The generic assembler: evaluates any [`Element`] set in parallel (rayon) and adds the local
//! residuals and tangents into a full-length force vector and the value array of a
//! [`SparsePattern`]. Elements are split into colours such that no two elements of one colour share a
//! node; the elements of a colour then write disjoint entries and run in parallel without locks.
//! Each thread keeps one workspace and one local system: nothing is allocated per element.

use crate::dofs::DofMap;
use crate::element::{Element, LocalSystem};
use crate::error::{Result, StampError};
use crate::sparse::SparsePattern;
use rayon::prelude::*;

/// Greedy colouring of the elements so that elements of one colour share no node.
pub fn color_elements(num_nodes: usize, num_elements: usize, element_nodes: impl Fn(usize) -> Vec<usize>) -> Vec<Vec<usize>> {
    // node -> bitmask of colours already used by its elements (up to 64 colours, then fall back)
    let mut used: Vec<u64> = vec![0; num_nodes];
    let mut colors: Vec<Vec<usize>> = Vec::new();
    for e in 0..num_elements {
        let nodes = element_nodes(e);
        let mask = nodes.iter().fold(0u64, |m, &n| m | used[n]);
        let c = (!mask).trailing_zeros() as usize;
        let c = c.min(63);
        if c >= colors.len() {
            colors.resize(c + 1, Vec::new());
        }
        colors[c].push(e);
        for &n in &nodes {
            used[n] |= 1u64 << c;
        }
    }
    // colour 63 may hold conflicting elements if more than 63 colours were needed: split it serially
    if colors.len() == 64 {
        let overflow = std::mem::take(&mut colors[63]);
        colors.pop();
        for e in overflow {
            colors.push(vec![e]);
        }
    }
    colors
}

/// Pointer wrapper used to write disjoint entries from several threads.
#[derive(Clone, Copy)]
struct SharedMut(*mut f64);
unsafe impl Send for SharedMut {}
unsafe impl Sync for SharedMut {}

/// Assembles one element set into a pattern. Built once per model; reused for every assembly.
/// Element count below which the assembly runs on the calling thread.
pub const PARALLEL_MIN_ELEMENTS: usize = 2048;

pub struct Assembler {
    colors: Vec<Vec<usize>>,
}

impl Assembler {
    /// Colour the elements of `element`.
    pub fn new<E: Element>(element: &E, num_nodes: usize) -> Self {
        let colors = color_elements(num_nodes, element.num_elements(), |e| element.element_nodes(e).to_vec());
        Assembler { colors }
    }

    /// Number of colours (for diagnostics).
    pub fn num_colors(&self) -> usize {
        self.colors.len()
    }

    /// Evaluate all elements at the full dof vector `u`, add their internal forces into `force`
    /// (length = number of dofs, prescribed dofs included: those entries are reactions) and, if
    /// `values` is given, their tangents into it (in `pattern`), and their preconditioner matrices
    /// into `preconditioner` when that is given too (for elements with
    /// [`Element::has_preconditioner`]). Returns the total strain energy, or
    /// [`StampError::Inadmissible`] naming the lowest-numbered element that refused the state
    /// ([`LocalSystem::inadmissible`]; the arrays are then not meaningful). `force`, `values` and
    /// `preconditioner` are overwritten, not accumulated.
    #[allow(clippy::too_many_arguments)]
    pub fn assemble<E: Element>(
        &self,
        element: &E,
        dofs: &DofMap,
        pattern: &SparsePattern,
        u: &[f64],
        force: &mut [f64],
        values: Option<&mut [f64]>,
        preconditioner: Option<&mut [f64]>,
    ) -> Result<f64> {
        let dpn = dofs.dofs_per_node();
        let npe = element.nodes_per_element();
        let nloc = dpn * npe;
        // below this many elements a fork-join costs more than it saves
        let parallel = element.num_elements() >= PARALLEL_MIN_ELEMENTS && rayon::current_num_threads() > 1;
        force.fill(0.0);
        let with_tangent = values.is_some();
        let zeroed = |values: Option<&mut [f64]>| match values {
            Some(v) => {
                if parallel {
                    v.par_iter_mut().for_each(|x| *x = 0.0);
                } else {
                    v.fill(0.0);
                }
                SharedMut(v.as_mut_ptr())
            }
            None => SharedMut(std::ptr::null_mut()),
        };
        let vals_ptr = zeroed(values);
        let with_preconditioner = with_tangent && preconditioner.is_some() && element.has_preconditioner();
        let pre_ptr = zeroed(if with_preconditioner { preconditioner } else { None });
        let force_ptr = SharedMut(force.as_mut_ptr());
        let eqs = dofs.equations();
        let mut energy = 0.0;
        let local_system = || if with_preconditioner { LocalSystem::with_preconditioner(nloc) } else { LocalSystem::new(nloc) };
        let init = || (element.new_workspace(), local_system(), vec![0.0; nloc], vec![0usize; nloc], vec![0u32; nloc]);
        // per-thread scratch: workspace, local system, local values, global dofs, row ranks
        // per element: its energy, and its number if it refused the state (usize::MAX if not)
        let kernel = |st: &mut (E::Workspace, LocalSystem, Vec<f64>, Vec<usize>, Vec<u32>), e: usize| -> (f64, usize) {
                let (ws, local, ue, gdof, rank) = st;
                let nodes = element.element_nodes(e);
                for (a, &n) in nodes.iter().enumerate() {
                    for c in 0..dpn {
                        gdof[a * dpn + c] = n * dpn + c;
                        ue[a * dpn + c] = u[n * dpn + c];
                    }
                }
                local.clear();
                element.evaluate(e, ue, ws, local, with_tangent);
                if local.inadmissible.is_some() {
                    return (0.0, e);
                }
                // SAFETY: elements of one colour share no node, so they write disjoint
                // entries of `force` and of the value array.
                unsafe {
                    let fp = force_ptr;
                    for i in 0..nloc {
                        *fp.0.add(gdof[i]) += local.residual[i];
                    }
                    if with_tangent {
                        let (vp, pp) = (vals_ptr, pre_ptr);
                        // slot of (row dof i, column j) = column start + block offset of
                        // (node of i, node of j) + rank of i among its node's free dofs
                        for (a, r) in rank.iter_mut().enumerate() {
                            *r = if eqs[gdof[a]] == crate::dofs::PRESCRIBED { u32::MAX } else { pattern.rank(gdof[a]) };
                        }
                        for j in 0..nloc {
                            let ce = eqs[gdof[j]];
                            if ce == crate::dofs::PRESCRIBED {
                                continue;
                            }
                            let b = j / dpn;
                            for a in 0..npe {
                                let base = pattern.block_slot(e, a, b, ce as usize);
                                for i in a * dpn..(a + 1) * dpn {
                                    if rank[i] != u32::MAX {
                                        let slot = base + rank[i] as usize;
                                        *vp.0.add(slot) += local.tangent[i * nloc + j];
                                        if with_preconditioner {
                                            *pp.0.add(slot) += local.preconditioner[i * nloc + j];
                                        }
                                    }
                                }
                            }
                        }
                    }
                }
                (local.energy, usize::MAX)
            };
        let mut refused = usize::MAX;
        if !parallel {
            let mut state = init();
            for color in &self.colors {
                for &e in color {
                    let (w, bad) = kernel(&mut state, e);
                    energy += w;
                    refused = refused.min(bad);
                }
            }
        } else {
            for color in &self.colors {
                let (w, bad) = color
                    .par_iter()
                    .with_min_len(256)
                    .map_init(init, |st, &e| kernel(st, e))
                    .reduce(|| (0.0, usize::MAX), |a, b| (a.0 + b.0, a.1.min(b.1)));
                energy += w;
                refused = refused.min(bad);
            }
        }
        if refused == usize::MAX {
            return Ok(energy);
        }
        // the reason, from the element itself
        let mut local = LocalSystem::new(nloc);
        let ue: Vec<f64> = element.element_nodes(refused).iter().flat_map(|&n| (0..dpn).map(move |c| u[n * dpn + c])).collect();
        element.evaluate(refused, &ue, &mut element.new_workspace(), &mut local, false);
        let reason = local.inadmissible.unwrap_or_else(|| "refused (no reason given)".into());
        Err(StampError::Inadmissible { element: refused, reason })
    }
}

//! A model evaluated by several processes together, each its own share: the framework's side of a
//! distributed run, with no knowledge of how the processes talk (MPI lives in the caller, behind
//! [`Reduce`]).
//!
//! Every process holds the whole model (less, if it likes, the data of the elements it does not
//! evaluate: [`crate::element::Element::retain_elements`]) and the same iterate. With a [`Share`] set
//! ([`crate::model::Model::set_share`]) a process evaluates only its own elements; their internal
//! forces and energy are summed over the processes ([`Reduce::sum`]) before anything reads them, so
//! the residual, the reactions, the energy and every test on them are the whole model's on every
//! process. The contact points and the displacement-dependent loads are evaluated on every
//! process (their state -- active sets, multipliers, pressures -- is the same everywhere by
//! construction); each process adds only the tangent rows of the nodes it owns. So the sparse
//! tangent and preconditioner values a process holds are its share of the nodal block (the sum
//! over the processes is the whole matrix: a distributed solver adds them), while the rows and
//! columns of the force-driven punches' unknowns are whole on every process. The pattern a
//! process holds is its own (its value arrays are sized to it): the entries of its elements and
//! of every element around a node it owns (so the rows of its nodes are whole: a distributed
//! solver preallocates them from it), with the force-driven punches' rows and columns.

use crate::error::Result;
use std::sync::Arc;

/// Reductions over the processes sharing a model (collective: every process calls them in the
/// same order).
pub trait Reduce: Send + Sync {
    /// Sum `v` over the processes, in place; every process gets the same sums to the bit.
    fn sum(&self, v: &mut [f64]) -> Result<()>;
    /// The smallest of each entry of `v` over the processes, in place.
    fn min(&self, v: &mut [u64]) -> Result<()>;
    /// The text of the one process that passes some (the others pass None), on every process:
    /// the reason an element refused the state, which only its own process can say (the others
    /// may not hold its data). Built on [`min`](Self::min): its bytes in words, the others' all
    /// ones.
    fn text(&self, mine: Option<&str>) -> Result<String> {
        let mut len = [u64::MAX - mine.map_or(0, |t| t.len() as u64)];
        self.min(&mut len)?;
        let n = usize::try_from(u64::MAX - len[0]).unwrap_or(0);
        let mut words = vec![u64::MAX; n.div_ceil(8)];
        if let Some(t) = mine {
            for (w, chunk) in words.iter_mut().zip(t.as_bytes().chunks(8)) {
                let mut b = [0u8; 8];
                b[..chunk.len()].copy_from_slice(chunk);
                *w = u64::from_le_bytes(b);
            }
        }
        self.min(&mut words)?;
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).take(n).collect();
        Ok(String::from_utf8_lossy(&bytes).into_owned())
    }
}

/// What one process evaluates.
#[derive(Clone)]
pub struct Share {
    /// The elements this process evaluates (each element by exactly one process).
    pub elements: Vec<usize>,
    /// Per node: this process adds the contact and displacement-dependent-load tangent rows of
    /// the node's dofs (each node owned by exactly one process).
    pub owned_nodes: Vec<bool>,
    pub reduce: Arc<dyn Reduce>,
}

//! A model evaluated by several processes together, each its own share: the framework's side of a
//! distributed run, with no knowledge of how the processes talk (MPI lives in the caller, behind
//! [`Reduce`]).
//!
//! Every process holds the whole model and the same iterate. With a [`Share`] set
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

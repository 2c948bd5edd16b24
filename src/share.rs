//! A model evaluated by several processes together, each its own share: the framework's side of a
//! distributed run, with no knowledge of how the processes talk (MPI lives in the caller, behind
//! [`Reduce`]).
//!
//! Every process holds the whole model (less, if it likes, the data of the elements it does not
//! evaluate: [`crate::element::Element::retain_elements`]) and the same iterate. With a [`Share`] set
//! ([`crate::model::Model::set_share`]) a process evaluates only its own elements; their internal
//! forces and energy are summed over the processes ([`Reduce::sum`]) before anything reads them, so
//! the residual, the reactions, the energy and every test on them are the whole model's on every
//! process. A process evaluates the contact points of the nodes it owns
//! ([`crate::contact::PointShare`]: with a halo for the integrated discretisation) and the pieces
//! of the displacement-dependent loads at its nodes
//! ([`crate::follower::DeformationDependentLoad::share_nodes`]); what the active-set rules and
//! Newton read of a whole punch is reduced over the processes, the contact forces are summed with
//! the internal ones, and each process adds only the tangent rows of the nodes it owns. So the
//! sparse tangent and preconditioner values a process holds are its share of the nodal block (the
//! sum over the processes is the whole matrix: a distributed solver adds them), while the rows and
//! columns of the force-driven punches' unknowns are summed to the whole on every process. After
//! each converged step ([`crate::nonlinear::NonlinearProblem::checkpoint`]) every contact point's
//! state is whole on every process. The pattern a
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
    /// The largest of each entry of `v` over the processes, in place (no NaN): minus the smallest
    /// of their negatives.
    fn max_f64(&self, v: &mut [f64]) -> Result<()> {
        v.iter_mut().for_each(|x| *x = -*x);
        self.min_f64(v)?;
        v.iter_mut().for_each(|x| *x = -*x);
        Ok(())
    }
    /// The smallest of each entry of `v` over the processes, in place (no NaN). Built on
    /// [`min`](Self::min) through an order-preserving map of the f64 onto u64.
    fn min_f64(&self, v: &mut [f64]) -> Result<()> {
        let mut keys: Vec<u64> = v.iter().map(|&x| order_key(x)).collect();
        self.min(&mut keys)?;
        for (x, k) in v.iter_mut().zip(&keys) {
            *x = from_order_key(*k);
        }
        Ok(())
    }
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

/// A u64 that orders as the f64 does (for any f64 but NaN): the sign bit flipped on a positive
/// number, every bit on a negative one.
fn order_key(x: f64) -> u64 {
    let b = x.to_bits();
    if b >> 63 == 1 { !b } else { b | 1 << 63 }
}

fn from_order_key(k: u64) -> f64 {
    f64::from_bits(if k >> 63 == 1 { k & !(1 << 63) } else { !k })
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
    /// This process adds what is applied once whatever the share (a force-driven punch's load)
    /// and prints the debug lines: exactly one process does.
    pub leader: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One process: every reduction is the identity.
    struct Alone;
    impl Reduce for Alone {
        fn sum(&self, _: &mut [f64]) -> Result<()> {
            Ok(())
        }
        fn min(&self, _: &mut [u64]) -> Result<()> {
            Ok(())
        }
    }

    #[test]
    fn the_order_key_orders_as_the_numbers_and_comes_back() {
        let xs = [f64::NEG_INFINITY, -1e300, -2.5, -1e-300, -0.0, 0.0, 1e-300, 3.0, 1e300, f64::INFINITY];
        for w in xs.windows(2) {
            assert!(order_key(w[0]) <= order_key(w[1]), "{} {}", w[0], w[1]);
        }
        for &x in &xs {
            assert_eq!(from_order_key(order_key(x)).to_bits(), x.to_bits());
        }
        let mut v = xs.to_vec();
        Alone.max_f64(&mut v).unwrap();
        Alone.min_f64(&mut v).unwrap();
        assert_eq!(v, xs);
    }
}

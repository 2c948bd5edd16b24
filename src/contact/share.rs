//! A punch's contact points shared over the processes of a distributed run (see
//! [`crate::share`]): each process evaluates the points of the nodes it owns, and the punch's
//! totals -- the deepest penetration and the most tensile point that the active-set rules read,
//! the number of changes, the forces and the punch's equation -- are reduced over the processes.
//!
//! The nodal scheme evaluates a process's own points only: a point's force and tangent are its own
//! node's rows (and the force-driven punch's row and column, which the model sums over the
//! processes). The integrated scheme's point i is made of every cell around it (its weighted
//! gap) and its traction reaches the nodes of those cells, so a process evaluates a halo: every
//! point of a cell around one of its own (`evaluated`), from the quadrature points of every cell
//! around those (`sites`). A halo point's state is computed from the same numbers by the same
//! rules as on its owner's process (the rules' thresholds are reduced over the processes), so it
//! is the same; only the owner counts it in the totals.
//!
//! Between evaluations the state of a point a process does not evaluate is stale; after each
//! converged step [`super::ContactPair::gather_state`] makes it whole on every process for the
//! outputs (its pressures, its reaction, its active set) and, with friction, for the step's
//! commit ([`PointShare::gather_friction`]).
//!
//! Friction needs nothing more: a point's return map reads only its own numbers (its position,
//! normal multiplier, anchor and tangential multiplier), so its owner decides its stick or slip
//! alone and every process agrees with it; its force and tangent rows are its node's (the
//! force-driven punch's row and column summed as the normal ones are); the augmented update of a
//! point is made by the processes that evaluate it, and the tangential violation that decides
//! whether to update is the largest over the processes (`Model`'s reduction of
//! [`super::ContactPair::constraint_violation`]).

use super::friction_law::Friction;
use super::ContactFace;
use crate::share::Reduce;
use std::sync::Arc;

/// What one process evaluates of a punch.
pub struct PointShare {
    /// Per point: this process owns it (the point of a node it owns). It counts it in the punch's
    /// totals and adds its forces and tangent rows.
    pub own: Vec<bool>,
    /// Per point: this process evaluates it (its own points and, integrated, every point of a cell
    /// around one of them).
    pub evaluated: Vec<bool>,
    /// Integrated only, per quadrature point of the face: evaluated (the cells around an
    /// evaluated point).
    pub sites: Vec<bool>,
    /// Integrated only, per quadrature point: its cell has an own point (its forces on the own
    /// points are added here).
    pub force_sites: Vec<bool>,
    /// Integrated only, per quadrature point: the process that gathers its kinematics (the owner
    /// of its cell's first point).
    pub gathers_site: Vec<bool>,
    pub reduce: Arc<dyn Reduce>,
    /// This process adds the force-driven punch's load and prints the punch's STAMP_DEBUG lines
    /// (exactly one process does).
    pub leader: bool,
}

impl PointShare {
    /// The share of a punch whose point k is owned here when `own[k]`; `face`: its integrated
    /// discretisation's face, if any.
    pub fn new(own: Vec<bool>, face: Option<&ContactFace>, reduce: Arc<dyn Reduce>, leader: bool) -> PointShare {
        let Some(face) = face else {
            return PointShare { evaluated: own.clone(), own, sites: Vec::new(), force_sites: Vec::new(), gathers_site: Vec::new(), reduce, leader };
        };
        // the face's quadrature points come four to a cell
        let cells: Vec<[u32; 4]> = face.quadrature.chunks(4).map(|c| c[0].points).collect();
        let touches = |cell: &[u32; 4], set: &[bool]| cell.iter().any(|&p| set[p as usize]);
        let mut evaluated = own.clone();
        for cell in cells.iter().filter(|c| touches(c, &own)) {
            for &p in cell {
                evaluated[p as usize] = true;
            }
        }
        let per_site = |f: &dyn Fn(&[u32; 4]) -> bool| cells.iter().flat_map(|c| [f(c); 4]).collect::<Vec<bool>>();
        let sites = per_site(&|c| touches(c, &evaluated));
        let force_sites = per_site(&|c| touches(c, &own));
        let gathers_site = per_site(&|c| own[c[0] as usize]);
        PointShare { own, evaluated, sites, force_sites, gathers_site, reduce, leader }
    }
}

/// What an evaluation changes of a point's friction state, per point: its position in the
/// punch's frame (3), its tangential traction (3), its tangential multiplier (3), its status.
const FRICTION_WORDS: usize = 10;

impl PointShare {
    /// Make the friction state of every site (a point, or the integrated face's quadrature point)
    /// whole on every process from the one process that gives it (`gives[k]`: this process's own
    /// points, its `gathers_site`) (collective): the position, traction, tangential multiplier
    /// and status of the last evaluation (each process evaluated its own sites, those of other
    /// processes are stale).
    /// Summed over the processes, the others adding zeros, so every process gets the owner's
    /// numbers to the bit. The anchors, slip lengths and dissipations change only in
    /// [`Friction::commit`], which every process then makes on the same whole state: they stay
    /// the same on every process without being sent.
    pub(super) fn gather_friction(&self, f: &mut Friction, gives: &[bool]) -> crate::Result<()> {
        const W: usize = FRICTION_WORDS;
        let n = f.status.len();
        let mut buf = vec![0.0; W * n];
        for (k, b) in buf.chunks_exact_mut(W).enumerate().filter(|(k, _)| gives[*k]) {
            b[0..3].copy_from_slice(&f.position[k]);
            b[3..6].copy_from_slice(&f.traction[k]);
            b[6..9].copy_from_slice(&f.lambda_t_bar[k]);
            b[9] = f64::from(f.status[k]);
        }
        self.reduce.sum(&mut buf)?;
        for (k, b) in buf.chunks_exact(W).enumerate() {
            f.position[k] = [b[0], b[1], b[2]];
            f.traction[k] = [b[3], b[4], b[5]];
            f.lambda_t_bar[k] = [b[6], b[7], b[8]];
            // 0, 1 or 2 exactly (one process adds it, the others zero)
            f.status[k] = b[9] as u8;
        }
        Ok(())
    }
}

//! The stick/slip criterion of friction (docs/design.md, "Friction"): the branch of the return
//! map (stick or slip) each contact point is held on while Newton converges, changed only when
//! Newton has converged on the branches it held, like the normal active set (Kratos' contact
//! application treats stick/slip convergence as a criterion of its own the same way).
//!
//! Why: a point at the edge of a stick zone moves against the punch by amounts far below what a
//! Newton step moves it. Left to the cone at every iteration its slip direction turns round from
//! one iteration to the next (the stick zone of the penalty, |x - a| <= mu q / eps_T, is crossed
//! in one step) and its traction flips with it: Newton cycles, the load step is cut back. Held
//! on one branch, the equations are smooth and Newton converges on them; the points whose return
//! map then disagrees are moved to the other branch and Newton goes on, until every point is on
//! the cone's own branch, where the held residual is the Coulomb law's exactly.
//!
//! The rules:
//! - a point coming into contact takes the cone's branch of its first evaluation;
//! - a slipping point whose trial traction turns against the direction it slipped in, or falls
//!   below the bound divided by [`CLEAR_SLIP`], sticks at once (counted as a change); a sticking
//!   point whose trial traction is [`CLEAR_SLIP`] times the bound slips at once;
//! - after Newton converged on the held branches, each point whose return map disagrees takes
//!   the cone's branch;
//! - a point that changed [`MAX_SWITCHES`] times in a load step is not held any more: it follows
//!   the cone at every iteration (as without the criterion) until the step ends.

use super::friction_law::{PointFriction, OPEN, SLIP, STICK};
use nalgebra::Vector3;

/// Changes of branch of one point in one load step after which it follows the cone.
pub const MAX_SWITCHES: u8 = 4;
/// A sticking point whose trial traction is this many times the bound slips at once, a slipping
/// one whose trial traction is below the bound over this sticks at once: they are nowhere near
/// the edge of the stick zone, where the branches chatter (a punch that starts to slide drags
/// its points along; one that stops holds them).
pub const CLEAR_SLIP: f64 = 2.0;
/// Held on no branch: the cone decides at every evaluation.
const FREE: u8 = 3;

/// The branch each point of a punch is held on.
#[derive(Debug, Clone)]
pub struct StickSlip {
    /// Per point: OPEN (out of contact: no branch yet), STICK, SLIP or FREE.
    law: Vec<u8>,
    /// The direction of the trial traction when the point was put on the slip branch.
    direction: Vec<[f64; 3]>,
    /// Changes of branch in this load step.
    switches: Vec<u8>,
    /// The cone's branch and trial direction at the last evaluation with a tangent.
    natural: Vec<u8>,
    natural_direction: Vec<[f64; 3]>,
}

impl StickSlip {
    /// n points, none in contact.
    pub fn new(n: usize) -> Self {
        StickSlip { law: vec![OPEN; n], direction: vec![[0.0; 3]; n], switches: vec![0; n], natural: vec![OPEN; n], natural_direction: vec![[0.0; 3]; n] }
    }

    /// Point k is out of contact.
    pub fn open(&mut self, k: usize, with_tangent: bool) {
        if with_tangent {
            self.law[k] = OPEN;
            self.natural[k] = OPEN;
        }
    }

    /// The branch point k is held on at this evaluation, `natural` its return map on the cone's
    /// own branch. An evaluation with a tangent (a Newton iterate) applies the rules and records
    /// the branch; one without (a line search's trial, a finite difference) evaluates the branch
    /// recorded, so that the tangent is the derivative of the residual it is used with.
    pub fn branch(&mut self, k: usize, natural: &PointFriction, with_tangent: bool) -> u8 {
        if !with_tangent {
            return match self.law[k] {
                OPEN | FREE => natural.status,
                law => law,
            };
        }
        let direction = natural.trial.try_normalize(0.0).unwrap_or_else(Vector3::zeros);
        let law = self.law[k];
        if law == OPEN {
            self.law[k] = natural.status;
            self.direction[k] = direction.into();
        } else if law == STICK && natural.status == SLIP && natural.cone_ratio > CLEAR_SLIP {
            self.switch(k, SLIP, direction);
        } else if law == SLIP && (natural.trial.dot(&Vector3::from(self.direction[k])) < 0.0 || natural.cone_ratio < 1.0 / CLEAR_SLIP) {
            self.switch(k, STICK, Vector3::zeros());
        }
        self.natural[k] = natural.status;
        self.natural_direction[k] = direction.into();
        if self.law[k] == FREE { natural.status } else { self.law[k] }
    }

    /// Point k is held on a branch that is not the cone's (`natural`).
    pub fn inconsistent(&self, k: usize, natural: &PointFriction) -> bool {
        matches!(self.law[k], STICK | SLIP) && self.law[k] != natural.status
    }

    /// Newton converged on the held branches: every point of `evaluated` whose cone disagreed at
    /// the last evaluation takes the cone's branch. Returns how many of `own` changed.
    pub fn update(&mut self, own: impl Fn(usize) -> bool, evaluated: impl Fn(usize) -> bool) -> usize {
        let mut changes = 0;
        for k in 0..self.law.len() {
            let (law, natural) = (self.law[k], self.natural[k]);
            if evaluated(k) && matches!(law, STICK | SLIP) && matches!(natural, STICK | SLIP) && natural != law {
                self.switch(k, natural, Vector3::from(self.natural_direction[k]));
                changes += usize::from(own(k));
            }
        }
        changes
    }

    /// A new load step: every point may change branch again; a point that followed the cone
    /// is held on the branch it ended the last step on.
    pub fn start_step(&mut self) {
        self.switches.fill(0);
        for k in 0..self.law.len() {
            if self.law[k] == FREE {
                self.law[k] = self.natural[k];
                self.direction[k] = self.natural_direction[k];
            }
        }
    }

    fn switch(&mut self, k: usize, to: u8, direction: Vector3<f64>) {
        self.switches[k] = self.switches[k].saturating_add(1);
        self.law[k] = if self.switches[k] >= MAX_SWITCHES { FREE } else { to };
        self.direction[k] = direction.into();
    }
}

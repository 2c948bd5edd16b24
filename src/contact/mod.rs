//! Frictionless contact of a set of points with a rigid punch, by the perturbed Lagrangian method
//! (paper eqs. 3.8, 3.15-3.16, 4.6, 4.9-4.10, 4.13-4.15), written against [`ContactSurface`](crate::surface::ContactSurface) only.
//!
//! Every contact point carries a multiplier lambda (a force per unit reference area: the nodal
//! weights are tributary areas). On the active set the regularised constraint
//! Psi - (lambda - lambda_bar) / eps_reg = 0 holds, off it lambda = 0; lambda <= 0 in contact. The
//! multiplier is condensed point by point, lambda = min(0, lambda_bar + eps_reg * Psi), so the
//! global system keeps only displacement unknowns and its pattern never changes; the solution is
//! that of the paper's (V, Lambda) system. lambda_bar = 0 is the paper's perturbed Lagrangian;
//! updating lambda_bar to the converged lambda (augmented Lagrangian, Uzawa) drives the
//! penetration to zero whatever eps_reg is.
//!
//! The contact force on the body is -lambda grad Psi per unit area (eq. 3.13), the contact pressure
//! q_n = -lambda |grad Psi| >= 0 (eq. 3.14 with compression counted positive).
//!
//! A punch is moved either by a prescribed displacement ([`PunchMotion`]: a vector times the load
//! factor, or a piecewise-linear path in the load factor) or by a
//! prescribed force ([`ForceDrive`]): then its rigid displacement s along a fixed direction n is one
//! more unknown, with the punch's equilibrium as its equation,
//! R_s = sum_k w_k lambda_k dPsi_k/ds - t F = -n . sum_k w_k lambda_k grad Psi_k - t F = 0
//! (dPsi/ds = -grad Psi . n since the punch sits at x - d, d = motion(t) + s n). This is the
//! derivative of the penalty energy sum w eps Psi^2 / 2 minus the work t F s, so the bordered
//! tangent stays symmetric wherever the plate's is. The model appends these unknowns after the
//! nodal dofs (see [`crate::model::Model`]).
//!
//! The default eps_reg is [`automatic_eps_reg`]: a contact spring per node that is a fixed multiple
//! of the plate's membrane stiffness around it.
//!
//! The files: `constraint.rs` the pair, its points and their state, and what is read off it
//! (penetration, reaction, pressures; the augmented-Lagrangian update); `kinematics.rs` Psi and
//! its gradient at a point; `normal_law.rs` the frictionless law of one point (its multiplier and
//! its tangent); `evaluate.rs` one evaluation of every point; `nodal.rs` the paper's collocation
//! at the nodes; `integrated.rs` the integrated discretisation on a [`ContactFace`];
//! `recover.rs` the recovered pressure field written beside the nodal one; `friction_law.rs`
//! Coulomb friction of a nodal point (its return map, its tangent, its history; docs/design.md,
//! "Friction"); `stick_slip.rs` the stick/slip criterion (the branch of the cone each point is
//! held on while Newton converges); `integrated_friction.rs` the same law at the integrated face's
//! quadrature points; `first_touch.rs` the active-set rules (damped entry and release, holds,
//! flips and freezing); `regularisation.rs` the default eps_reg; `motion.rs` how the punch moves;
//! `rotation.rs` how it turns, and `turned.rs` its surface as the rotation places it (Psi,
//! gradient and Hessian, for every shape); `share.rs` the points
//! of one process.

mod constraint;
mod evaluate;
mod face;
mod first_touch;
mod friction_law;
pub mod stick_slip;
mod integrated;
mod integrated_friction;
mod kinematics;
mod motion;
mod nodal;
mod normal_law;
mod recover;
mod regularisation;
mod rotation;
mod share;
mod turned;
pub use constraint::{ContactKinematics, ContactPair, ContactPoint, PointState};
pub use face::ContactFace;
pub use friction_law::{return_map, return_map_on, Friction, PointFriction, OPEN, SLIP, STICK};
pub use integrated_friction::FrictionAtPoints;
pub use first_touch::{CONVERGING_TENSION, DEEP_ENTRY_RATIO, ENTRY_FRACTION, FIRST_TOUCH_FRACTION, LONE_MAX_FLIPS, RELEASE_FRACTION, STEP_START_ENTRY_FRACTION};
pub use motion::{ForceDrive, PunchMotion};
pub use recover::{recovered_pressure, RecoveredPressure, Recovery, RECOVERY};
pub use rotation::{PunchRotation, Turn};
pub use turned::Turned;
pub use regularisation::{automatic_eps_reg, AUTO_EPS_FACTOR};
pub use share::PointShare;

#[cfg(test)]
mod entry_tests;

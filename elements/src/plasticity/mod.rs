//! Elastic-plastic materials for the plates of three to five surfaces: von Mises or Hill (1948)
//! yield functions with isotropic hardening, at finite strain by the additive plasticity in the
//! logarithmic strain space of Miehe, Apel & Lambrecht (2002). See docs/design.md "Plasticity".
//!
//! - [`hardening`]: sigma_y(ep), linear, Swift or a table;
//! - [`yield_function`]: phi(T) = sqrt(T . M T), von Mises or Hill from the r-values;
//! - [`return_map`]: the small-strain return map and its consistent tangent in H space;
//! - [`hencky`]: H = 1/2 ln(I + 2E), S = P^T T and dS/dE;
//! - [`law`]: the three together, the law of a material point of the plate;
//! - [`points`]: the history of a plate's integration points.

pub mod hardening;
pub mod hencky;
pub mod law;
pub mod points;
pub mod return_map;
pub mod yield_function;

pub use hardening::Hardening;
pub use law::{Plasticity, PlasticLaw};
pub use return_map::PlasticState;
pub use points::{ElementPlasticity, PlasticPoints};

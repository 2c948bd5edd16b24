//! The check report: what is wrong with a built problem, said before the solve (`stamp check`,
//! and first in `stamp run`) by [`mod@check`], with [`rigid_modes`] (rigid motions held by nothing),
//! [`travel_modes`] (force-driven punches' travels held by nothing), [`punch_start`] (gaps at the
//! start), [`psi_checks`] (a punch's Psi) and [`cell_shape`] (cells of extreme aspect ratio).

pub mod cell_shape;
pub mod check;
pub mod psi_checks;
pub mod punch_start;
pub mod rigid_modes;
pub mod travel_modes;

pub use check::{after_the_run, check};

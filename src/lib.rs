//! # stamp — the framework crate
//!
//! A generic finite-element framework for structures in frictionless contact with rigid punches.
//! Data flows one way: mesh -> degrees of freedom -> assembly -> nonlinear solver -> output. This crate
//! knows nothing about plates or cylinders: elements plug in through [`element::Element`], punch
//! shapes through [`surface::ContactSurface`], solution strategies through
//! [`nonlinear::NonlinearSolver`], linear solvers through
//! [`linalg::linear_solver::LinearSolver`] (the sparse linear algebra lives in [`linalg`]).

pub mod error;
pub mod io;
pub mod mesh;
pub mod surface;

pub use error::{quote, show_path, short_path, Result, StampError};
pub mod dofs;
pub mod factor_path;
pub mod element;
pub mod linalg;
pub mod memory;
pub mod assembly;
pub mod contact;
pub mod follower;
pub mod model;
pub mod linearised_contact;
pub mod nonlinear;
pub mod share;

//! # stamp — the framework crate
//!
//! A generic finite-element framework for structures in frictionless contact with rigid punches.
//! Data flows one way: mesh -> degrees of freedom -> assembly -> nonlinear solver -> output. This crate
//! knows nothing about plates or cylinders: elements plug in through [`element::Element`], punch
//! shapes through [`surface::ContactSurface`], solution strategies through
//! [`nonlinear::NonlinearSolver`].

pub mod error;
pub mod io;
pub mod mesh;
pub mod mesh_check;
pub mod surface;

pub use error::{quote, Result, StampError};
pub mod dofs;
pub mod element;
pub mod linear_solver;
pub mod gmres;
pub mod ldlt_gmres;
pub mod supernodal_solve;
pub mod ordering;
pub mod bordered;
pub mod sparse;
pub mod assembly;
pub mod vector_state;
pub mod contact;
pub mod model;
pub mod nonlinear;

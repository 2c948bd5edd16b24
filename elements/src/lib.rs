//! # stamp-elements
//!
//! The plate of G. M. Kulikov and S. V. Plotnikova, "Contact interaction of an elastic plate with a
//! rigid body. 2. Geometrically nonlinear formulation": a Timoshenko-type plate whose unknowns are
//! the six displacements of its two face planes, with Green-Lagrange strains that represent any
//! rigid-body motion exactly, discretised by the mixed (Hu-Washizu) four-node element of the paper.
//! It plugs into the stamp framework as an [`stamp::element::Element`].

pub mod follower;
pub mod geometries;
pub mod geometry;
pub mod material;
pub mod plate;
pub mod strain;
pub mod multi_surface;
pub mod orthotropic;
pub mod plasticity;
pub mod laminate;

pub use follower::{fixed_couple_force, FollowerCouple, FollowerPressure};
pub use material::{Isotropic, Layer, NormalStress, Section};
pub use plate::{Face, Kinematics, PlateElements, DOFS_PER_NODE};
pub use laminate::{FiveSurfaceLaminate, FourSurfaceLaminate, Laminate, LaminatePlate, Ply, ThreeSurfaceLaminate};
pub use orthotropic::{Orthotropic, PlyMaterial};
pub use multi_surface::{FiveSurfacePlate, FourSurfacePlate, MultiSurfacePlate, ThreeSurfacePlate};

//! The model a problem describes, built from the schema: the mesh ([`mesh`], gmsh or the built-in
//! rectangle, refused before it is built when it cannot fit in memory: [`memory`]), the plate
//! ([`plate_model`], with the laminate of [`laminate_spec`] or the one material of
//! [`plasticity_spec`]), and [`mod@build`]: section, plate
//! elements, constraints, loads (the pressures of [`pressure`]), punches and solver settings, one
//! builder per table of the problem file; [`coarse`] the coarse-mesh predictor.

pub mod build;
pub mod coarse;
pub mod laminate_spec;
pub mod memory;
pub mod mesh;
pub mod plasticity_spec;
pub mod plate_model;
pub mod pressure;

pub use build::{build, Setup};

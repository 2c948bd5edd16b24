//! Input and output: gmsh meshes in, ParaView files out.
//!
//! * [`gmsh::read_msh`] reads a gmsh MSH 4.1 file (ASCII or binary) of triangles and
//!   quadrilaterals (first or second order, cut into 4-node quadrilaterals) into a
//!   [`crate::mesh::QuadMesh`] with its physical groups, checked as a whole
//!   ([`crate::mesh::check`]); [`gmsh::parse_msh_bytes`] does the same from bytes, and
//!   [`gmsh::mesh_from_arrays`] from arrays of nodes, cells and groups;
//! * [`vtk::write_vtu`] writes a mesh with point and cell fields as a `.vtu` file, and
//!   [`vtk::write_pvd`] the `.pvd` collection that lists them by load factor;
//! * [`atomic::write_atomically`] makes every written file appear whole or not at all.

pub mod atomic;
pub mod gmsh;
pub mod vtk;

pub use atomic::{write_atomically, write_string_atomically};
pub use gmsh::{mesh_from_arrays, parse_msh_bytes, read_msh, GmshMesh, PhysicalGroup, PhysicalName, SourceCells};
pub use vtk::{write_pvd, write_vtu, Field};

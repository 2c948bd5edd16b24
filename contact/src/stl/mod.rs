//! A rigid die given as a triangulated surface in an STL file: the reader ([`read_stl`]) and the
//! surface with its smooth signed distance ([`StlSurface`]).

mod reader;
mod surface;

pub use reader::{parse_stl_bytes, read_stl, TriangleMesh, BYTES_PER_FACET, DEFAULT_MAX_FACETS};
pub use surface::StlSurface;

//! Any bytes given to the gmsh reader: a mesh that passes the whole-mesh checks, or an error of a
//! few hundred printable characters; never a panic, abort or unbounded allocation.
#![no_main]
use libfuzzer_sys::fuzz_target;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    match stamp::io::parse_msh_bytes(Path::new("fuzz.msh"), data) {
        Ok(m) => {
            if let Err(d) = stamp::mesh_check::check_mesh(&m.mesh) {
                panic!("accepted a mesh that fails the checks: {d:?}");
            }
            assert_eq!(m.node_tags.len(), m.mesh.num_nodes());
            assert_eq!(m.cell_tags.len(), m.mesh.num_cells());
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.len() <= 400, "message of {} bytes: {msg}", msg.len());
            assert!(!msg.chars().any(|c| c.is_control()), "control characters in: {msg}");
        }
    }
});

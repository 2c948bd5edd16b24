//! Any bytes given to the STL reader (ASCII or binary): a welded, checked triangle mesh whose
//! signed distance evaluates without a panic, or an error naming the file in a bounded message;
//! never a panic, abort or an allocation the header's count asks for unchecked.
#![no_main]
use libfuzzer_sys::fuzz_target;
use stamp::surface::ContactSurface;
use std::path::Path;

fuzz_target!(|data: &[u8]| {
    match stamp_contact::stl::parse_stl_bytes(Path::new("fuzz.stl"), data, 10_000) {
        Ok(mesh) => {
            assert!(!mesh.facets.is_empty());
            assert!(mesh.facets.iter().flatten().all(|&v| (v as usize) < mesh.vertices.len()));
            if let Ok(s) = stamp_contact::StlSurface::from_mesh("fuzz.stl", mesh) {
                let x = nalgebra::Vector3::new(0.25, -0.5, 2.0);
                let _ = (s.psi(&x), s.gradient(&x), s.hessian(&x));
            }
        }
        Err(e) => {
            let msg = e.to_string();
            assert!(msg.starts_with("fuzz.stl: "), "{msg}");
            assert!(msg.len() <= 1000, "message of {} bytes: {msg}", msg.len());
        }
    }
});

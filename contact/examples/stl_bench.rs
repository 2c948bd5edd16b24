//! The cost of an STL die: reading, building the search tree, and queries (Psi, gradient,
//! Hessian) on a triangulated sphere of about a million facets.
//!
//!     cargo run --release -p stamp-contact --example stl_bench [LEVELS]
//!
//! LEVELS (default 8): subdivisions of the icosahedron, 20 * 4^LEVELS facets (8: 1 310 720).
//!
//!     cargo run --release -p stamp-contact --example stl_bench cap LEVELS ANGLE FILE
//!
//! writes instead the cap of ANGLE degrees about the lowest point of the icosphere R = 200 about
//! (0, 0, 200.5) as a binary STL (the die of docs/performance.md's STL table: it stands in for
//! the sphere of meshes/sphere-ss-displacement.toml).

#[path = "../tests/common/mod.rs"]
mod common;

use nalgebra::Vector3;
use stamp::surface::ContactSurface;
use stamp_contact::stl::{read_stl, StlSurface};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("cap") {
        let levels: u32 = args[2].parse().expect("LEVELS");
        let angle: f64 = args[3].parse().expect("ANGLE");
        let f = common::icosphere_cap(levels, 200.0, [0.0, 0.0, 200.5], angle.to_radians());
        common::write(std::path::Path::new(&args[4]), &common::binary_stl(&f));
        println!("{}: {} facets", args[4], f.len());
        return;
    }
    let levels: u32 = std::env::args().nth(1).map(|a| a.parse().expect("LEVELS: a number")).unwrap_or(8);
    let r = 200.0;
    let facets = common::icosphere(levels, r, [0.0, 0.0, 0.0]);
    let dir = common::temp_dir("bench");
    let path = dir.join("sphere.stl");
    common::write(&path, &common::binary_stl(&facets));
    println!("{} facets, binary STL {} bytes", facets.len(), std::fs::metadata(&path).unwrap().len());
    drop(facets);
    let t = Instant::now();
    let mesh = read_stl(&path, usize::MAX).unwrap();
    let t_read = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let s = StlSurface::from_mesh("sphere.stl", mesh).unwrap();
    let t_build = t.elapsed().as_secs_f64();
    println!("read and checked: {t_read:.3} s; normals and R*-tree: {t_build:.3} s");
    // 10 000 points within 2 of the surface, spread over a cap (as a plate's nodes would be)
    let pts: Vec<Vector3<f64>> = (0..10_000)
        .map(|k| {
            let k = k as f64;
            let (theta, phi) = (3.0 - 0.2 * (k * 0.6180339).fract(), 6.283 * (k * 0.4142135).fract());
            (r + 2.0 * (k * 0.7320508).fract() - 1.0) * Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
        })
        .collect();
    let mut sum = 0.0;
    let t = Instant::now();
    for p in &pts {
        sum += s.psi(p);
    }
    let t_psi = t.elapsed().as_secs_f64();
    let t = Instant::now();
    for p in &pts {
        sum += s.gradient(p).x;
    }
    let t_grad = t.elapsed().as_secs_f64();
    let t = Instant::now();
    for p in &pts {
        sum += s.hessian(p)[(0, 0)];
    }
    let t_hess = t.elapsed().as_secs_f64();
    println!("10 000 queries: psi {:.1} ms, gradient {:.1} ms, hessian {:.1} ms (checksum {sum:.3})", t_psi * 1e3, t_grad * 1e3, t_hess * 1e3);
    let _ = std::fs::remove_dir_all(&dir);
}

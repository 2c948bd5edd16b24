//! The cost of evaluating a punch surface for one Newton iteration: Psi, its gradient and its
//! Hessian at every candidate point of the n = 100 quarter plate of
//! meshes/sphere-ss-displacement.toml (101 x 101 nodes of the top face, pushed down under the
//! punch as at the end of the run), for the built-in sphere, the same sphere written as an
//! expression, and the same sphere as STL caps of growing size.
//!
//!     cargo run --release -p stamp-contact --example shape_cost [CAP.stl ...]
//!
//! Each CAP.stl is an STL die standing in for the sphere (made by the `stl_bench` example's `cap`
//! mode: `cargo run --release -p stamp-contact --example stl_bench cap 11 12 cap11.stl`). Prints,
//! per shape, the best of five passes over the points (ms) and the time per point (us).

use nalgebra::Vector3;
use stamp::surface::ContactSurface;
use stamp_contact::{Expression, Sphere, StlSurface};
use std::time::Instant;

fn main() {
    let n = 100;
    let points: Vec<Vector3<f64>> = (0..=n)
        .flat_map(|i| (0..=n).map(move |j| (i, j)))
        .map(|(i, j)| {
            let (x1, x2) = (20.0 * i as f64 / n as f64, 20.0 * j as f64 / n as f64);
            // the deflection of the run's last step, roughly: 0.9 at the centre, fading outwards
            let w = 0.9 * (1.0 - (x1 * x1 + x2 * x2) / 800.0).max(0.0);
            Vector3::new(x1, x2, 0.5 - w)
        })
        .collect();
    let mut shapes: Vec<(String, Box<dyn ContactSurface>)> = vec![
        ("sphere (built in)".into(), Box::new(Sphere::new(Vector3::new(0.0, 0.0, 200.5), 200.0).unwrap())),
        ("expression".into(), Box::new(Expression::new("x1^2 + x2^2 + (x3 - 200.5)^2 - 200^2", 200.0).unwrap())),
    ];
    for path in std::env::args().skip(1) {
        let t = Instant::now();
        let s = StlSurface::from_file(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{path}: {e}"));
        let label = format!("STL, {} facets (read and indexed in {:.2} s)", s.num_facets(), t.elapsed().as_secs_f64());
        shapes.push((label, Box::new(s)));
    }
    println!("{} points, Psi + gradient + Hessian at each:", points.len());
    for (label, s) in &shapes {
        let mut best = f64::INFINITY;
        let mut checksum = 0.0;
        for _ in 0..5 {
            let t = Instant::now();
            for p in &points {
                checksum += s.psi(p) + s.gradient(p).x + s.hessian(p)[(2, 2)];
            }
            best = best.min(t.elapsed().as_secs_f64());
        }
        println!("  {label}: {:.2} ms, {:.3} us per point (checksum {checksum:.6e})", best * 1e3, best * 1e6 / points.len() as f64);
    }
}

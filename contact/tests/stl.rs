//! The STL die: the reader (ASCII, binary, every error) and the signed distance against the
//! analytic sphere on a triangulated sphere, its continuity across facet edges and its Hessian.

mod common;

use common::{ascii_stl, binary_stl, icosphere, temp_dir, write};
use nalgebra::Vector3;
use stamp::surface::{finite_difference_hessian, ContactSurface};
use stamp_contact::stl::{read_stl, StlSurface};
use std::path::Path;

fn tetrahedron() -> Vec<[[f64; 3]; 3]> {
    let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    // outward normals
    [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]].iter().map(|t: &[usize; 3]| t.map(|i| p[i])).collect()
}

fn error_of(path: &Path) -> String {
    match read_stl(path, 1000) {
        Ok(_) => panic!("{} was accepted", path.display()),
        Err(e) => e.to_string(),
    }
}

#[test]
fn ascii_and_binary_read_the_same_welded_mesh() {
    let d = temp_dir("read");
    let t = tetrahedron();
    write(&d.join("a.stl"), ascii_stl(&t).as_bytes());
    write(&d.join("b.stl"), &binary_stl(&t));
    let a = read_stl(&d.join("a.stl"), 1000).unwrap();
    let b = read_stl(&d.join("b.stl"), 1000).unwrap();
    assert_eq!((a.vertices.len(), a.facets.len()), (4, 4));
    assert_eq!(a.facets, b.facets);
    assert_eq!(a.vertices, b.vertices);
    // a binary file whose 80-byte header starts with "solid" is still binary (its size matches)
    let mut bytes = binary_stl(&t);
    bytes[..5].copy_from_slice(b"solid");
    write(&d.join("c.stl"), &bytes);
    assert_eq!(read_stl(&d.join("c.stl"), 1000).unwrap().facets.len(), 4);
}

#[test]
fn every_solid_of_an_ascii_file_is_read() {
    let d = temp_dir("solids");
    let t = tetrahedron();
    let moved: Vec<_> = t.iter().map(|f| f.map(|v| [v[0] + 5.0, v[1], v[2]])).collect();
    // two solids, the second named on its lines, blank lines between and after
    let text = format!("{}\n{}\n\n", ascii_stl(&t), ascii_stl(&moved).replace("solid test", "solid part two"));
    write(&d.join("two.stl"), text.as_bytes());
    let m = read_stl(&d.join("two.stl"), 1000).unwrap();
    assert_eq!((m.vertices.len(), m.facets.len()), (8, 8));
    assert!(m.vertices.iter().any(|v| v[0] == 6.0), "the second solid's vertices are there");
    // the facet limit counts both
    let e = read_stl(&d.join("two.stl"), 6).unwrap_err().to_string();
    assert!(e.contains("too many facets"), "{e}");
}

#[test]
fn every_bad_file_is_refused_naming_the_file_and_the_facet() {
    let d = temp_dir("errors");
    let t = tetrahedron();
    let missing = d.join("missing.stl");
    let e = error_of(&missing);
    assert!(e.contains("missing.stl") && e.contains("cannot read"), "{e}");
    let e = error_of(&d);
    assert!(e.contains("not a regular file"), "{e}");
    // truncated binary: the header announces 4 facets, 3.5 are there; and a huge count
    let mut bytes = binary_stl(&t);
    bytes.truncate(84 + 175);
    write(&d.join("trunc.stl"), &bytes);
    let e = error_of(&d.join("trunc.stl"));
    assert!(e.contains("trunc.stl") && e.contains("announces 4 facets") && e.contains("259 bytes"), "{e}");
    bytes[80..84].copy_from_slice(&u32::MAX.to_le_bytes());
    write(&d.join("huge.stl"), &bytes);
    let e = error_of(&d.join("huge.stl"));
    assert!(e.contains("announces 4294967295 facets"), "{e}");
    // too many facets for the limit
    let many = icosphere(2, 1.0, [0.0; 3]);
    write(&d.join("many.stl"), &binary_stl(&many));
    let e = read_stl(&d.join("many.stl"), 100).unwrap_err().to_string();
    assert!(e.contains("too many facets") && e.contains("320"), "{e}");
    write(&d.join("many.txt"), ascii_stl(&many).as_bytes());
    let e = read_stl(&d.join("many.txt"), 100).unwrap_err().to_string();
    assert!(e.contains("too many facets"), "{e}");
    // non-finite coordinate in facet 3
    let mut bad = t.clone();
    bad[2][1][0] = f64::NAN;
    write(&d.join("nan.stl"), &binary_stl(&bad));
    let e = error_of(&d.join("nan.stl"));
    assert!(e.contains("facet 3") && e.contains("not finite"), "{e}");
    write(&d.join("inf.stl"), ascii_stl(&bad).replace("NaN", "inf").as_bytes());
    let e = error_of(&d.join("inf.stl"));
    assert!(e.contains("facet 3") && e.contains("not finite"), "{e}");
    // zero area: facet 2 has two equal corners
    let mut bad = t.clone();
    bad[1][2] = bad[1][1];
    write(&d.join("flat.stl"), ascii_stl(&bad).as_bytes());
    let e = error_of(&d.join("flat.stl"));
    assert!(e.contains("facet 2") && e.contains("degenerate"), "{e}");
    // facet 4 flipped: it traverses an edge in the same direction as a neighbour
    let mut bad = t.clone();
    bad[3].swap(0, 1);
    write(&d.join("flip.stl"), &binary_stl(&bad));
    let e = error_of(&d.join("flip.stl"));
    assert!(e.contains("flip.stl") && e.contains("inconsistent orientation") && e.contains(" and 4 "), "{e}");
    // ASCII syntax: a word instead of a number, with its line
    write(&d.join("word.stl"), ascii_stl(&t).replacen("vertex 1e0", "vertex one", 1).as_bytes());
    let e = error_of(&d.join("word.stl"));
    assert!(e.contains("line ") && e.contains("'one' is not a number"), "{e}");
    let text = ascii_stl(&t);
    let cut = text.match_indices("vertex").nth(4).unwrap().0;
    write(&d.join("cut.stl"), text[..cut].as_bytes());
    let e = error_of(&d.join("cut.stl"));
    assert!(e.contains("cut.stl") && e.contains("facet 2: the file ends where `vertex` is expected"), "{e}");
    write(&d.join("nend.stl"), text.replace("endsolid test\n", "").as_bytes());
    let e = error_of(&d.join("nend.stl"));
    assert!(e.contains("after 4 facets without `endsolid`"), "{e}");
    // after `endsolid`: a garbage line is refused with its line, not ignored
    write(&d.join("tail.stl"), format!("{text}garbage here\n").as_bytes());
    let e = error_of(&d.join("tail.stl"));
    let line = text.lines().count() + 1;
    assert!(e.contains("tail.stl") && e.contains(&format!("line {line}:")) && e.contains("after `endsolid`") && e.contains("'garbage'"), "{e}");
    // ... and so is a word between `solid` and the first facet
    write(&d.join("head.stl"), text.replacen("solid test\n", "solid test\njunk\n", 1).as_bytes());
    let e = error_of(&d.join("head.stl"));
    assert!(e.contains("line 2:") && e.contains("'junk'"), "{e}");
    // a second solid with garbage after it: refused at the garbage's line
    let moved: Vec<_> = t.iter().map(|f| f.map(|v| [v[0] + 5.0, v[1], v[2]])).collect();
    let two = format!("{text}{}", ascii_stl(&moved));
    write(&d.join("two-tail.stl"), format!("{two}\n  endsolid\n").as_bytes());
    let e = error_of(&d.join("two-tail.stl"));
    assert!(e.contains(&format!("line {}:", two.lines().count() + 2)) && e.contains("after `endsolid` of solid 2"), "{e}");
    write(&d.join("empty.stl"), b"solid x\nendsolid x\n");
    assert!(error_of(&d.join("empty.stl")).contains("no facets"));
    write(&d.join("short.stl"), b"hello");
    assert!(error_of(&d.join("short.stl")).contains("not an STL file"));
}

/// A point at distance `dist` from the sphere of radius r about c, in direction (theta, phi).
fn at(c: Vector3<f64>, r: f64, theta: f64, phi: f64, dist: f64) -> Vector3<f64> {
    c + (r + dist) * Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

#[test]
fn psi_and_its_gradient_tend_to_the_sphere_distance() {
    let c = Vector3::new(1.0, -2.0, 60.0);
    let r = 50.0;
    let d = temp_dir("sphere");
    let mut errors = Vec::new();
    for levels in [3, 4, 5] {
        let facets = icosphere(levels, r, c.into());
        write(&d.join("s.stl"), ascii_stl(&facets).as_bytes());
        let s = StlSurface::from_file(&d.join("s.stl")).unwrap();
        assert_eq!(s.num_facets(), 20 * 4usize.pow(levels));
        let (mut e_psi, mut e_grad) = (0.0f64, 0.0f64);
        for k in 0..400 {
            let (theta, phi) = (0.1 + 2.9 * ((k as f64) * 0.6180339).fract(), 6.28 * ((k as f64) * 0.4142135).fract());
            let dist = -5.0 + 25.0 * ((k as f64) * 0.7320508).fract();
            let x = at(c, r, theta, phi, dist);
            e_psi = e_psi.max((s.psi(&x) - dist).abs());
            e_grad = e_grad.max((s.gradient(&x) - (x - c).normalize()).norm());
        }
        errors.push((levels, e_psi, e_grad));
    }
    eprintln!("levels, max |Psi - distance|, max |grad Psi - n|: {errors:?}");
    // facet size halves per level: the distance error falls by ~4, the normal's by ~2 or more
    for w in errors.windows(2) {
        assert!(w[1].1 < w[0].1 / 3.0, "{errors:?}");
        assert!(w[1].2 < w[0].2 / 1.8, "{errors:?}");
    }
    // Psi's error is the facets' sagitta, ~ h_f^2 / (8 R); the normal at a distance d from the
    // surface is that of the closest point, off the radial direction by O(h_f d / R^2)
    let (_, e_psi, e_grad) = errors[2];
    assert!(e_psi < 5e-4 * r && e_grad < 1e-2, "{errors:?}");
}

#[test]
fn psi_and_gradient_are_continuous_across_a_facet_edge_and_the_hessian_is_their_derivative() {
    let c = Vector3::new(0.0, 0.0, 0.0);
    let facets = icosphere(3, 10.0, c.into());
    let d = temp_dir("edge");
    write(&d.join("s.stl"), &binary_stl(&facets));
    let s = StlSurface::from_file(&d.join("s.stl")).unwrap();
    // the midpoint of the first facet's first edge, pushed out by 0.3, crossed along the other
    // facet's direction
    let f = facets[0].map(Vector3::from);
    let mid = (f[0] + f[1]) / 2.0;
    let out = mid.normalize();
    let across = (f[2] - mid).normalize();
    let x0 = mid + 0.3 * out;
    for eps in [1e-4, 1e-6, 1e-8] {
        let a = x0 + eps * across;
        let b = x0 - eps * across;
        let dpsi = (s.psi(&a) - s.psi(&b)).abs();
        let dgrad = (s.gradient(&a) - s.gradient(&b)).norm();
        assert!(dpsi < 10.0 * eps && dgrad < 10.0 * eps, "eps {eps}: jump of Psi {dpsi:e}, of grad {dgrad:e}");
    }
    // the Hessian against central differences of the gradient inside a facet and near an edge
    for x in [(f[0] + f[1] + f[2]) / 3.0 * 1.02, x0 + 0.05 * across] {
        let h = s.hessian(&x);
        let fd = finite_difference_hessian(&s, &x);
        assert!((h - fd).norm() < 1e-6 * fd.norm().max(1e-3), "{h} vs {fd}");
        // and near (I - n n^T)/R for the sphere's curvature
        let n = x.normalize();
        let want = (nalgebra::Matrix3::identity() - n * n.transpose()) / 10.0;
        assert!((h - want).norm() < 0.3 * want.norm(), "{h} vs {want}");
    }
    assert!(s.describe().contains("1280 facets"), "{}", s.describe());
    assert!((s.length_scale() - 20.0 * 3f64.sqrt()).abs() < 2.0);
}

//! Triangulated spheres and STL writers for the STL tests.

#![allow(dead_code)]

use std::io::Write;
use std::path::Path;

/// An icosphere: the icosahedron with each facet split into 4, `levels` times, vertices pushed
/// onto the sphere of radius `r` about `c`; facets counter-clockwise seen from outside (outward
/// normals). 20 * 4^levels facets.
pub fn icosphere(levels: u32, r: f64, c: [f64; 3]) -> Vec<[[f64; 3]; 3]> {
    icosphere_cap(levels, r, c, std::f64::consts::PI)
}

/// The facets of [`icosphere`] within `angle` (radians) of its lowest point (0, 0, -r) from the
/// centre: facets farther than that are dropped at every level, so that a fine cap costs only its
/// own facets. The icosahedron is symmetric about x1 = 0 and x2 = 0, and (0, 0, -r) is a vertex
/// from one subdivision on.
pub fn icosphere_cap(levels: u32, r: f64, c: [f64; 3], angle: f64) -> Vec<[[f64; 3]; 3]> {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<[f64; 3]> = vec![
        [-1.0, t, 0.0], [1.0, t, 0.0], [-1.0, -t, 0.0], [1.0, -t, 0.0],
        [0.0, -1.0, t], [0.0, 1.0, t], [0.0, -1.0, -t], [0.0, 1.0, -t],
        [t, 0.0, -1.0], [t, 0.0, 1.0], [-t, 0.0, -1.0], [-t, 0.0, 1.0],
    ];
    let mut f: Vec<[usize; 3]> = vec![
        [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
        [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
        [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
        [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
    ];
    let unit = |p: [f64; 3]| {
        let n = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        [p[0] / n, p[1] / n, p[2] / n]
    };
    for p in v.iter_mut() {
        *p = unit(*p);
    }
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut nf = Vec::with_capacity(f.len() * 4);
        let mut m = |a: usize, b: usize, v: &mut Vec<[f64; 3]>| -> usize {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let p = unit([(v[a][0] + v[b][0]) / 2.0, (v[a][1] + v[b][1]) / 2.0, (v[a][2] + v[b][2]) / 2.0]);
                v.push(p);
                v.len() - 1
            })
        };
        for &[a, b, c] in &f {
            let ab = m(a, b, &mut v);
            let bc = m(b, c, &mut v);
            let ca = m(c, a, &mut v);
            nf.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        f = nf;
        // keep the facets with a corner within the cap (a facet's angular size shrinks by 2 a level)
        let keep = |p: &[f64; 3]| -p[2] >= (angle.min(std::f64::consts::PI)).cos();
        if angle < std::f64::consts::PI {
            f.retain(|t| t.iter().any(|&i| keep(&v[i])));
        }
    }
    f.iter()
        .map(|t| t.map(|i| [c[0] + r * v[i][0], c[1] + r * v[i][1], c[2] + r * v[i][2]]))
        .collect()
}

/// The ASCII STL text of facets.
pub fn ascii_stl(facets: &[[[f64; 3]; 3]]) -> String {
    let mut s = String::from("solid test\n");
    for f in facets {
        s += "  facet normal 0 0 0\n    outer loop\n";
        for v in f {
            s += &format!("      vertex {:e} {:e} {:e}\n", v[0], v[1], v[2]);
        }
        s += "    endloop\n  endfacet\n";
    }
    s + "endsolid test\n"
}

/// The binary STL bytes of facets (f32 coordinates).
pub fn binary_stl(facets: &[[[f64; 3]; 3]]) -> Vec<u8> {
    let mut b = vec![0u8; 80];
    b.extend((facets.len() as u32).to_le_bytes());
    for f in facets {
        for _ in 0..3 {
            b.extend(0f32.to_le_bytes());
        }
        for v in f {
            for c in v {
                b.extend((*c as f32).to_le_bytes());
            }
        }
        b.extend([0u8, 0u8]);
    }
    b
}

pub fn write(path: &Path, bytes: &[u8]) {
    std::fs::File::create(path).unwrap().write_all(bytes).unwrap();
}

/// A fresh empty directory under the target directory.
pub fn temp_dir(name: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("stamp-stl-tests-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

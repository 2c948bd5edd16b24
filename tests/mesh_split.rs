//! Triangle, mixed and second-order gmsh meshes cut into 4-node quadrilaterals (tests/data, made by
//! make_split_meshes.py): the cut mesh is conforming, keeps the area and the physical groups, and
//! the plate element on it passes the rigid-body and patch tests.

mod common;
use common::*;
use stamp::element::{Element, LocalSystem};
use stamp::io::gmsh::{read_msh, GmshMesh};
use stamp::mesh::{quad_signed_area, QuadMesh};
use stamp_elements::Kinematics;
use std::collections::BTreeMap;
use std::path::Path;

fn read(name: &str) -> GmshMesh {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name);
    read_msh(&p).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Edges (sorted node pairs) with the number of cells using each.
fn edge_uses(mesh: &QuadMesh) -> BTreeMap<[usize; 2], usize> {
    let mut m = BTreeMap::new();
    for c in &mesh.cells {
        for i in 0..4 {
            let (a, b) = (c[i], c[(i + 1) % 4]);
            *m.entry([a.min(b), a.max(b)]).or_insert(0) += 1;
        }
    }
    m
}

fn boundary_nodes(mesh: &QuadMesh) -> Vec<usize> {
    let mut v: Vec<usize> = edge_uses(mesh).iter().filter(|(_, &k)| k == 1).flat_map(|(e, _)| *e).collect();
    v.sort_unstable();
    v.dedup();
    v
}

fn total_area(mesh: &QuadMesh) -> f64 {
    (0..mesh.num_cells()).map(|c| quad_signed_area(&mesh.cell_coords(c))).sum()
}

/// Area of the polygon the hole's segments make with the hole centre (2, 1.5).
fn hole_polygon(m: &GmshMesh) -> f64 {
    m.curve_group("hole")
        .unwrap()
        .iter()
        .map(|s| {
            let (a, b) = (m.mesh.coords[s[0]], m.mesh.coords[s[1]]);
            0.5 * ((a[0] - 2.0) * (b[1] - 1.5) - (a[1] - 1.5) * (b[0] - 2.0)).abs()
        })
        .sum()
}

/// Conforming: every edge in one or two cells, the edges in one cell are exactly the segments of
/// the boundary curve groups, and the area is the plate's minus the hole polygon.
fn assert_conforming_holed(m: &GmshMesh) {
    let uses = edge_uses(&m.mesh);
    assert!(uses.values().all(|&k| k == 1 || k == 2), "an edge in more than two cells");
    let mut boundary: Vec<[usize; 2]> = uses.iter().filter(|(_, &k)| k == 1).map(|(e, _)| *e).collect();
    let mut segs: Vec<[usize; 2]> = ["hole", "outer"]
        .iter()
        .flat_map(|g| m.curve_group(g).unwrap().iter().map(|s| [s[0].min(s[1]), s[0].max(s[1])]))
        .collect();
    boundary.sort_unstable();
    segs.sort_unstable();
    assert_eq!(boundary, segs, "{}: the one-cell edges are not the boundary segments", m.path.display());
    let area = total_area(&m.mesh);
    let expected = 12.0 - hole_polygon(m);
    assert!((area - expected).abs() < 1e-10, "{}: area {area}, expected {expected}", m.path.display());
    assert!(hole_polygon(m) > 0.75 * std::f64::consts::PI * 0.49 && hole_polygon(m) <= std::f64::consts::PI * 0.49 + 1e-12);
}

#[test]
fn triangles_are_cut_into_three_quadrilaterals_sharing_edge_midpoints() {
    let m = read("holed_tri.msh");
    assert_eq!(m.source_cells.len(), 1);
    let s = &m.source_cells[0];
    assert_eq!((s.gmsh_type, s.kind), (2, "3-node triangle"));
    assert_eq!(s.cells, 3 * s.elements);
    assert_eq!(m.mesh.num_cells(), s.cells);
    assert_eq!(m.split_summary().unwrap(), format!("{} 3-node triangles split into {} quadrilaterals", s.elements, s.cells));
    // Each triangle's tag on its three cells, in order.
    for (k, chunk) in m.cell_tags.chunks(3).enumerate() {
        assert!(chunk.iter().all(|&t| t == chunk[0]), "cells {}..: {chunk:?}", 3 * k);
    }
    // New nodes (tag 0): one per edge and one per triangle; Euler: V - E + F = 1 - holes = 0.
    let file_nodes = m.node_tags.iter().filter(|&&t| t != 0).count();
    let new_nodes = m.node_tags.len() - file_nodes;
    let tri_edges = new_nodes - s.elements;
    assert_eq!(file_nodes as i64 - tri_edges as i64 + s.elements as i64, 0);
    assert_conforming_holed(&m);
    // Binary gives the same.
    let b = read("holed_tri_bin.msh");
    assert_eq!(b.mesh.cells, m.mesh.cells);
    assert_eq!(b.node_tags, m.node_tags);
    assert_eq!(b.curve_groups, m.curve_groups);
}

#[test]
fn physical_groups_carry_over_to_the_new_nodes() {
    let m = read("holed_tri.msh");
    let hole = m.curve_group("hole").unwrap();
    // Every boundary line was cut in two at a new node (tag 0) at its middle.
    assert_eq!(hole.len() % 2, 0);
    for pair in hole.chunks(2) {
        assert_eq!(pair[0][1], pair[1][0]);
        let mid = pair[0][1];
        assert_eq!(m.node_tags[mid], 0);
        let (a, b) = (m.mesh.coords[pair[0][0]], m.mesh.coords[pair[1][1]]);
        let x = m.mesh.coords[mid];
        assert!((x[0] - 0.5 * (a[0] + b[0])).abs() < 1e-14 && (x[1] - 0.5 * (a[1] + b[1])).abs() < 1e-14);
        for n in [pair[0][0], pair[1][1]] {
            let [x, y] = m.mesh.coords[n];
            assert!((((x - 2.0).powi(2) + (y - 1.5).powi(2)).sqrt() - 0.7).abs() < 1e-9);
        }
    }
    // The node group holds old and new nodes: each node of the closed loop ends two segments.
    assert_eq!(m.node_group("hole").unwrap().len(), hole.len());
    let outer = m.node_group("outer").unwrap();
    for &n in outer {
        let [x, y] = m.mesh.coords[n];
        assert!(x.abs() < 1e-12 || y.abs() < 1e-12 || (x - 4.0).abs() < 1e-12 || (y - 3.0).abs() < 1e-12);
    }
    assert!(outer.iter().any(|&n| m.node_tags[n] == 0));
    assert_eq!(m.point_group("origin").unwrap().len(), 1);
    assert_eq!(m.mesh.coords[m.point_group("origin").unwrap()[0]], [0.0, 0.0]);
    // The surface holds every cell and every node.
    assert_eq!(m.cell_group("plate").unwrap().len(), m.mesh.num_cells());
    assert_eq!(m.node_group("plate").unwrap().len(), m.mesh.num_nodes());
}

#[test]
fn second_order_elements_are_cut_on_their_own_nodes() {
    for (name, ty, per, new_per_element) in
        [("holed_tri6.msh", 9, 3, 1), ("holed_quad9.msh", 10, 4, 0), ("holed_quad8.msh", 16, 4, 1)]
    {
        let m = read(name);
        let surf: Vec<_> = m.source_cells.iter().filter(|s| s.gmsh_type == ty).collect();
        assert_eq!(surf.len(), 1, "{name}: {:?}", m.source_cells);
        let s = surf[0];
        assert_eq!(s.cells, per * s.elements, "{name}");
        // Second-order meshes may hold a few other surface types (e.g. 6-node triangles left over
        // by recombination): everything is cut.
        let new_nodes = m.node_tags.iter().filter(|&&t| t == 0).count();
        let others: usize = m.source_cells.iter().filter(|s| s.gmsh_type != ty).map(|s| s.elements).sum();
        if others == 0 {
            assert_eq!(new_nodes, new_per_element * s.elements, "{name}");
        }
        assert_conforming_holed(&m);
        // The mid-side nodes of the hole lie on the circle (gmsh puts them on the curve): the
        // hole's segments come from 3-node lines cut in two, all ends on the circle.
        for seg in m.curve_group("hole").unwrap() {
            for &n in seg {
                let [x, y] = m.mesh.coords[n];
                assert!((((x - 2.0).powi(2) + (y - 1.5).powi(2)).sqrt() - 0.7).abs() < 1e-9, "{name}");
                assert_ne!(m.node_tags[n], 0, "{name}");
            }
        }
    }
}

#[test]
fn a_mixed_triangle_and_quadrilateral_mesh_is_conforming() {
    let m = read("mixed.msh");
    let by_type: BTreeMap<i32, (usize, usize)> = m.source_cells.iter().map(|s| (s.gmsh_type, (s.elements, s.cells))).collect();
    let (tri, tri_cells) = by_type[&2];
    let (quad, quad_cells) = by_type[&3];
    assert_eq!((tri_cells, quad_cells), (3 * tri, 4 * quad));
    let summary = m.split_summary().unwrap();
    assert!(summary.contains("3-node triangles split into") && summary.contains("4-node quadrilaterals split into"), "{summary}");
    let uses = edge_uses(&m.mesh);
    assert!(uses.values().all(|&k| k == 1 || k == 2));
    // the boundary edges all lie on the outline of [0, 2] x [0, 1]
    for (e, &k) in &uses {
        if k == 1 {
            let on = |x: [f64; 2]| x[0].abs() < 1e-12 || x[1].abs() < 1e-12 || (x[0] - 2.0).abs() < 1e-12 || (x[1] - 1.0).abs() < 1e-12;
            assert!(on(m.mesh.coords[e[0]]) && on(m.mesh.coords[e[1]]));
        }
    }
    assert!((total_area(&m.mesh) - 2.0).abs() < 1e-12);
    let bottom: f64 = m
        .curve_group("bottom")
        .unwrap()
        .iter()
        .map(|s| (m.mesh.coords[s[1]][0] - m.mesh.coords[s[0]][0]).abs())
        .sum();
    assert!((bottom - 2.0).abs() < 1e-12);
}

/// Local dofs of cell `e` for a displacement field `f(x, z)`.
fn local_dofs(mesh: &QuadMesh, e: usize, h: f64, f: &dyn Fn([f64; 2], f64) -> [f64; 3]) -> Vec<f64> {
    let mut v = vec![0.0; 24];
    for a in 0..4 {
        let x = mesh.coords[mesh.cells[e][a]];
        for (face, z) in [(0usize, -0.5 * h), (1, 0.5 * h)] {
            let u = f(x, z);
            for i in 0..3 {
                v[a * 6 + face * 3 + i] = u[i];
            }
        }
    }
    v
}

#[test]
fn rigid_body_motions_are_exact_on_a_cut_triangle_mesh() {
    let m = read("holed_tri.msh");
    let h = 0.1;
    let plate = plate(&m.mesh, h, Kinematics::Nonlinear);
    let mut ws = plate.new_workspace();
    let mut out = LocalSystem::with_preconditioner(24);
    let pi = std::f64::consts::PI;
    let mut rng = Lcg(3);
    for _ in 0..5 {
        let rot = euler_krylov(rng.range(-pi, pi), rng.range(-pi, pi), rng.range(-pi, pi));
        let shift = [rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), rng.range(-5.0, 5.0)];
        let motion = |x: [f64; 2], z: f64| {
            let r = [x[0], x[1], z];
            [0, 1, 2].map(|i| shift[i] + (0..3).map(|j| rot[i][j] * r[j]).sum::<f64>() - r[i])
        };
        for e in 0..m.mesh.num_cells() {
            plate.evaluate(e, &vec![0.0; 24], &mut ws, &mut out, true);
            let k_scale = max_abs(&out.tangent);
            let v = local_dofs(&m.mesh, e, h, &motion);
            plate.evaluate(e, &v, &mut ws, &mut out, false);
            let force = max_abs(&out.residual);
            assert!(force <= 1e-11 * k_scale * max_abs(&v), "cell {e}: internal force {force:e}");
        }
    }
    // The test can fail: a stretch is not strain-free.
    let v = local_dofs(&m.mesh, 0, h, &|x, _| [0.01 * x[0], 0.0, 0.0]);
    plate.evaluate(0, &v, &mut ws, &mut out, false);
    assert!(max_abs(&out.residual) > 1.0);
}

/// Solves with the boundary nodes prescribed to `exact`; the largest error at the interior nodes
/// relative to the largest exact value.
fn patch(m: &QuadMesh, kin: Kinematics, h: f64, exact: &dyn Fn([f64; 2], f64) -> [f64; 3]) -> f64 {
    let boundary = boundary_nodes(m);
    assert!(m.num_nodes() - boundary.len() > 10);
    patch_error(m, &boundary, kin, h, exact)
}

#[test]
fn membrane_and_bending_patch_tests_pass_on_cut_triangle_meshes() {
    let m = read("mixed.msh");
    // constant membrane strain, with the through-thickness stretch that makes T33 vanish
    let mat = stamp_elements::Isotropic::new(2.0e5, 0.3).unwrap();
    let (lam, mu) = (mat.lame_lambda(), mat.shear_modulus());
    let a = [[0.02, -0.013], [0.007, -0.011]];
    let g = -lam * (a[0][0] + a[1][1]) / (lam + 2.0 * mu);
    let membrane = move |x: [f64; 2], z: f64| {
        [a[0][0] * x[0] + a[0][1] * x[1], a[1][0] * x[0] + a[1][1] * x[1], g * z]
    };
    let e = patch(&m.mesh, Kinematics::Linear, 0.05, &membrane);
    assert!(e < 1e-10, "membrane patch error {e:e}");
    // constant curvature
    let (k11, k12, k22) = (0.3, -0.12, 0.2);
    let bending = move |x: [f64; 2], z: f64| {
        let w = -(k11 * x[0] * x[0] + 2.0 * k12 * x[0] * x[1] + k22 * x[1] * x[1]) / 2.0;
        [z * (k11 * x[0] + k12 * x[1]), z * (k12 * x[0] + k22 * x[1]), w]
    };
    let e = patch(&m.mesh, Kinematics::Linear, 0.01, &bending);
    assert!(e < 1e-8, "bending patch error {e:e}");
    // the test can fail: without the thickness stretch the membrane state is no equilibrium
    let wrong = move |x: [f64; 2], _z: f64| [a[0][0] * x[0] + a[0][1] * x[1], a[1][0] * x[0] + a[1][1] * x[1], 0.0];
    assert!(patch(&m.mesh, Kinematics::Linear, 0.05, &wrong) > 1e-4);
    // and on the holed triangle mesh (curved hole, unstructured)
    let t = read("holed_tri.msh");
    let e = patch(&t.mesh, Kinematics::Linear, 0.05, &membrane);
    assert!(e < 1e-10, "holed membrane patch error {e:e}");
    let e = patch(&t.mesh, Kinematics::Linear, 0.01, &bending);
    assert!(e < 1e-8, "holed bending patch error {e:e}");
}

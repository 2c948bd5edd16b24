//! The contact patch test: a plate resting on a rigid plane (a punch under its bottom face) and
//! loaded by a uniform pressure on its top face must pass the pressure through the contact
//! unchanged: the contact pressure equals the applied pressure at every node, on a mesh of gmsh
//! triangles cut into quadrilaterals (irregular valence, distorted cells) and on a randomly
//! distorted quadrilateral mesh, with the nodal and with the integrated discretisation; and the
//! written pressure integrates to the punch's force (sum_i A_i q_i, A_i = int N_i dA).

mod common;
use common::*;
use stamp::contact::{ContactFace, ContactKinematics, ContactPair, ContactPoint};
use stamp::dofs::DofMap;
use stamp::linalg::linear_solver::SparseLu;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearSolver};
use stamp_contact::Plane;
use stamp_elements::{Face, Kinematics, PlateElements};
use std::sync::Arc;

const PRESSURE: f64 = 25.0;

/// Solve the plate on `mesh` resting on the plane and return (contact pressures, nodal areas,
/// the punch's force along x3).
fn patch(mesh: &QuadMesh, integrated: bool) -> (Vec<f64>, Vec<f64>, f64) {
    let h = 0.5;
    let section = steel_section(h);
    let dm = section.delta_minus;
    let plate = PlateElements::new(mesh, section, Kinematics::Nonlinear).unwrap();
    let mut dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    // the in-plane rigid motions: u1, u2 at the leftmost node, u2 at the rightmost, both faces
    // (the plate is free to expand in its plane as the pressure squeezes it)
    let by_x = |a: &usize, b: &usize| mesh.coords[*a][0].total_cmp(&mesh.coords[*b][0]);
    let left = (0..mesh.num_nodes()).min_by(by_x).unwrap();
    let right = (0..mesh.num_nodes()).max_by(by_x).unwrap();
    dofs.fix(&[left], &[0, 1, 3, 4]).unwrap();
    dofs.fix(&[right], &[1, 4]).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    let areas = mesh.nodal_areas();
    for n in 0..mesh.num_nodes() {
        model.add_load(Face::Top.dof(n, 2), -PRESSURE * areas[n]).unwrap();
    }
    // the plane x3 = delta-, its normal up (towards the plate): the bottom face touches it
    let plane = Plane::new(nalgebra::Vector3::new(0.0, 0.0, dm), nalgebra::Vector3::new(0.0, 0.0, 1.0)).unwrap();
    let points = (0..mesh.num_nodes())
        .map(|n| ContactPoint { node: n, x_ref: [mesh.coords[n][0], mesh.coords[n][1], dm], dofs: [0, 1, 2].map(|c| Face::Bottom.dof(n, c)), weight: areas[n] })
        .collect();
    let mut pair = ContactPair::new("plane", Arc::new(plane), points, 1.0e6, ContactKinematics::Exact);
    if integrated {
        let all: Vec<Option<usize>> = (0..mesh.num_nodes()).map(Some).collect();
        pair = pair.with_face(ContactFace::new(&mesh.coords, &mesh.cells, &all, mesh.num_nodes()).unwrap()).unwrap();
    }
    model.add_contact(pair);
    let mut newton = NewtonRaphson::new(SparseLu::new(), NewtonSettings { rel_tol: 1e-12, ..NewtonSettings::default() });
    let mut u = vec![0.0; model.dofs.num_dofs()];
    newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
    let pair = &model.contacts[0];
    (pair.pressures(), areas, pair.reaction()[2])
}

fn check(mesh: &QuadMesh, what: &str) {
    let total: f64 = mesh.nodal_areas().iter().sum();
    for integrated in [false, true] {
        let (q, areas, force) = patch(mesh, integrated);
        let worst = q.iter().map(|q| (q - PRESSURE).abs()).fold(0.0, f64::max);
        println!("{what}, integrated {integrated}: {} nodes, largest deviation from the applied pressure {worst:.2e}", q.len());
        assert!(worst < 1e-8 * PRESSURE, "{what} (integrated {integrated}): the contact pressure deviates from the uniform {PRESSURE} by {worst:e}");
        let integral: f64 = q.iter().zip(&areas).map(|(q, a)| q * a).sum();
        assert!((integral - force).abs() < 1e-9 * force, "{what}: the pressure integrates to {integral}, the punch's force is {force}");
        assert!((force - PRESSURE * total).abs() < 1e-9 * force, "{what}: the punch carries {force}, the load is {}", PRESSURE * total);
    }
}

#[test]
fn a_uniform_pressure_passes_through_the_contact_unchanged_on_cut_triangles() {
    let gmsh = stamp::io::gmsh::read_msh(std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/holed_tri.msh"))).unwrap();
    check(&gmsh.mesh, "gmsh triangles cut into quadrilaterals");
}

#[test]
fn a_uniform_pressure_passes_through_the_contact_unchanged_on_a_distorted_mesh() {
    let mut mesh = QuadMesh::rectangle(0.0, 6.0, 0.0, 4.0, 6, 4).unwrap();
    let mut rng = Lcg(7);
    for n in 0..mesh.num_nodes() {
        let x = mesh.coords[n];
        if x[0] > 0.0 && x[0] < 6.0 && x[1] > 0.0 && x[1] < 4.0 {
            mesh.coords[n] = [x[0] + rng.range(-0.3, 0.3), x[1] + rng.range(-0.3, 0.3)];
        }
    }
    check(&mesh, "distorted quadrilaterals");
}

//! The assembled tangent of a whole model (plate elements plus contact with a curved punch) is the
//! derivative of its residual: compared with central finite differences at a random
//! large-displacement state with many points in contact.

mod common;
use common::*;
use stamp::contact::{ContactKinematics, ContactPair, ContactPoint};
use stamp::dofs::DofMap;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::NonlinearProblem;
use stamp_contact::{Cylinder, Sphere};
use stamp_elements::{Face, Kinematics, PlateElements};
use std::sync::Arc;

fn dense(m: faer::sparse::SparseColMatRef<'_, usize, f64>) -> Vec<Vec<f64>> {
    let n = m.nrows();
    let mut d = vec![vec![0.0; n]; n];
    let (sym, vals) = m.parts();
    for j in 0..n {
        for (k, &i) in sym.row_idx()[sym.col_ptr()[j]..sym.col_ptr()[j + 1]].iter().enumerate() {
            d[i][j] += vals[sym.col_ptr()[j] + k];
        }
    }
    d
}

fn check(surface: Arc<dyn stamp::surface::ContactSurface>, kin: Kinematics, seed: u64) {
    let mut mesh = QuadMesh::rectangle(0.0, 2.0, 0.0, 2.0, 3, 3).unwrap();
    // distort the interior nodes
    let mut rng = Lcg(seed);
    for n in 0..mesh.num_nodes() {
        let x = mesh.coords[n];
        if x[0] > 0.0 && x[0] < 2.0 && x[1] > 0.0 && x[1] < 2.0 {
            mesh.coords[n] = [x[0] + rng.range(-0.15, 0.15), x[1] + rng.range(-0.15, 0.15)];
        }
    }
    let section = steel_section(0.2);
    let dp = section.delta_plus;
    let plate = PlateElements::new(&mesh, section, kin).unwrap();
    let mut dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    dofs.fix(mesh.group_nodes("left").unwrap(), &[0, 1, 2, 3, 4, 5]).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    let areas = mesh.nodal_areas();
    let points = (0..mesh.num_nodes())
        .map(|n| ContactPoint { node: n, x_ref: [mesh.coords[n][0], mesh.coords[n][1], dp], dofs: [0, 1, 2].map(|c| Face::Top.dof(n, c)), weight: areas[n] })
        .collect();
    model.contacts.push(ContactPair::new("punch", surface, points, 3.0e3, ContactKinematics::Exact));
    let mut u: Vec<f64> = (0..model.num_dofs()).map(|_| rng.range(-0.3, 0.3)).collect();
    model.apply_prescribed(&mut u, 1.0);
    model.evaluate(&u, 1.0, true).unwrap();
    let active = model.contacts[0].state.iter().filter(|s| s.active).count();
    assert!(active >= 3, "the test state should have points in contact, has {active}");
    let k = dense(model.matrix());
    let scale = k.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let neq = model.num_equations();
    let step = 1e-7;
    let mut worst = 0.0f64;
    for j in 0..neq {
        let mut du = vec![0.0; neq];
        du[j] = step;
        let mut up = u.clone();
        model.add_increment(&mut up, &du);
        du[j] = -step;
        let mut um = u.clone();
        model.add_increment(&mut um, &du);
        model.evaluate(&up, 1.0, false).unwrap();
        let rp = model.residual().to_vec();
        let ap: Vec<bool> = model.contacts[0].state.iter().map(|s| s.active).collect();
        model.evaluate(&um, 1.0, false).unwrap();
        let am: Vec<bool> = model.contacts[0].state.iter().map(|s| s.active).collect();
        if ap != am {
            continue; // a point crossed the kink: the derivative does not exist there
        }
        let rm = model.residual();
        for i in 0..neq {
            let fd = (rp[i] - rm[i]) / (2.0 * step);
            worst = worst.max((fd - k[i][j]).abs() / scale);
        }
    }
    assert!(worst < 1e-6, "model tangent differs from finite differences by {worst:e}");
}

#[test]
fn model_tangent_with_sphere_contact_matches_finite_differences() {
    let s = Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    check(Arc::new(s), Kinematics::Nonlinear, 11);
}

#[test]
fn model_tangent_with_cylinder_contact_matches_finite_differences() {
    let c = Cylinder::new(nalgebra::Vector3::new(0.0, 1.0, 1.0), nalgebra::Vector3::new(1.0, 0.3, 0.0), 1.3).unwrap();
    check(Arc::new(c), Kinematics::Nonlinear, 12);
    check(Arc::new(Cylinder::new(nalgebra::Vector3::new(0.0, 1.0, 1.0), nalgebra::Vector3::new(1.0, 0.3, 0.0), 1.3).unwrap()), Kinematics::Linear, 13);
}

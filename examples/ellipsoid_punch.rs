//! A punch shape of your own: an ellipsoid, in one implementation of `ContactSurface`, pressed with
//! a force onto a clamped square plate. Nothing else in stamp needs to know about it.
//!
//!     cargo run --release --example ellipsoid_punch

use nalgebra::{Matrix3, Vector3};
use stamp::linalg::bordered::BorderedSolver;
use stamp::contact::{automatic_eps_reg, ContactKinematics, ContactPair, ContactPoint, ForceDrive};
use stamp::dofs::DofMap;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearProblem, NonlinearSolver};
use stamp::surface::ContactSurface;
use stamp_elements::{Face, Isotropic, Kinematics, PlateElements, Section};
use std::sync::Arc;

/// The ellipsoid sum_i ((x_i - c_i) / a_i)^2 = 1: Psi < 0 inside, 0 on it, > 0 outside.
struct Ellipsoid {
    center: Vector3<f64>,
    semi_axes: Vector3<f64>,
}

impl ContactSurface for Ellipsoid {
    fn psi(&self, x: &Vector3<f64>) -> f64 {
        (x - self.center).component_div(&self.semi_axes).norm_squared() - 1.0
    }
    fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64> {
        2.0 * (x - self.center).component_div(&self.semi_axes.component_mul(&self.semi_axes))
    }
    // optional: the default is a finite difference of `gradient`
    fn hessian(&self, _x: &Vector3<f64>) -> Matrix3<f64> {
        Matrix3::from_diagonal(&self.semi_axes.map(|a| 2.0 / (a * a)))
    }
    fn length_scale(&self) -> f64 {
        self.semi_axes.max()
    }
    fn describe(&self) -> String {
        format!("ellipsoid with semi-axes {:?} at {:?}", self.semi_axes.as_slice(), self.center.as_slice())
    }
}

fn main() -> stamp::Result<()> {
    // a clamped steel plate 40 x 40, h = 1, 20 x 20 elements
    let (h, young) = (1.0, 2.1e5);
    let mesh = QuadMesh::rectangle(-20.0, 20.0, -20.0, 20.0, 20, 20)?;
    let section = Section::homogeneous(h, Isotropic::new(young, 0.3)?)?;
    let plate = PlateElements::new(&mesh, section, Kinematics::Nonlinear)?;
    let mut dofs = DofMap::new(mesh.num_nodes(), 6)?;
    for edge in ["left", "right", "bottom", "top"] {
        dofs.fix(mesh.group_nodes(edge)?, &[0, 1, 2, 3, 4, 5])?;
    }
    let mut model = Model::new(plate, dofs)?;

    // the ellipsoid, long along x1, touching the top face (x3 = h/2) at the centre
    let (a1, a2, a3) = (120.0, 80.0, 40.0);
    let punch = Arc::new(Ellipsoid { center: Vector3::new(0.0, 0.0, 0.5 * h + a3), semi_axes: Vector3::new(a1, a2, a3) });
    // every node of the top face may touch it, weighted by its tributary area
    let areas = mesh.nodal_areas();
    let points = (0..mesh.num_nodes())
        .map(|n| ContactPoint { node: n, x_ref: [mesh.coords[n][0], mesh.coords[n][1], 0.5 * h], dofs: [0, 1, 2].map(|c| Face::Top.dof(n, c)), weight: areas[n] })
        .collect();
    let mut pair = ContactPair::new("ellipsoid", punch, points, 1.0, ContactKinematics::Exact);
    pair.eps_reg = automatic_eps_reg(young * h, 2.0, pair.contact_gradient_norm());
    // pressed down by a force of 4000 at load factor 1; its travel is an unknown
    pair.drive = Some(ForceDrive::new([0.0, 0.0, -1.0], 4000.0)?);
    model.add_contact(pair);
    model.augmented_tolerance = Some(1e-6);

    let settings = NewtonSettings { max_increment: 0.25, ..NewtonSettings::default() };
    let mut newton = NewtonRaphson::new(BorderedSolver::new(model.num_drives()), settings);
    let mut u = vec![0.0; model.num_dofs()];
    let mut zones = Vec::new();
    println!("  load   travel  active  zone along x1  along x2  reaction");
    newton.solve_path(&mut model, &mut u, 0.0, &[0.25, 0.5, 0.75, 1.0], &mut |rep, u, m| {
        let c = &m.contacts[0];
        let loaded: Vec<[f64; 3]> = c.points.iter().zip(&c.state).filter(|(_, s)| s.lambda < 0.0).map(|(p, _)| p.x_ref).collect();
        let extent = |i: usize| loaded.iter().map(|x| x[i].abs()).fold(0.0, f64::max);
        println!("{:6.2} {:8.4} {:7} {:14.1} {:9.1} {:9.1}", rep.load_factor, c.drive_displacement(u).unwrap(), loaded.len(), extent(0), extent(1), -c.reaction()[2]);
        zones.push((extent(0), extent(1)));
    })?;
    // the contact zone follows the punch's shape: longer along its long axis
    let (l1, l2) = *zones.last().unwrap();
    assert!(l1 > l2, "the contact zone should be longer along x1: {l1} vs {l2}");
    Ok(())
}

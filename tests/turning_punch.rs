//! A punch that turns (`ContactPair::rotation`): objectivity of the contact and of friction's
//! body frame. A rigid rotation of plate and punch together about the same pivot changes no
//! normal answer and makes no friction; a sphere turning about its centre presses as one that
//! does not turn, and drags a sticking plate with a traction against its surface velocity.

mod common;
use common::*;
use nalgebra::Vector3;
use stamp::contact::{ContactKinematics, ContactPair, ContactPoint, PunchMotion, PunchRotation, Turn, STICK};
use stamp::dofs::DofMap;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::NonlinearProblem;
use stamp_contact::Sphere;
use stamp_elements::{Face, Kinematics, PlateElements};
use std::sync::Arc;

const D0: [f64; 3] = [0.0, 0.0, -0.05];

/// A free 4 x 4 plate (2 x 2, thickness 0.2) under a sphere of radius 1.5 pressed by D0, friction
/// `mu`, evaluated once at load factor 1 with every point's anchor where it stands (the punch
/// touched there) and evaluated again: the plate's displacement zero.
fn pressed(mu: f64, rotation: Option<PunchRotation>) -> (Model<PlateElements>, QuadMesh, [f64; 2]) {
    let mesh = QuadMesh::rectangle(0.0, 2.0, 0.0, 2.0, 4, 4).unwrap();
    let section = steel_section(0.2);
    let faces = [section.delta_minus, section.delta_plus];
    let plate = PlateElements::new(&mesh, section, Kinematics::Nonlinear).unwrap();
    let dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    let areas = mesh.nodal_areas();
    let points = (0..mesh.num_nodes())
        .map(|n| ContactPoint { node: n, x_ref: [mesh.coords[n][0], mesh.coords[n][1], faces[1]], dofs: [0, 1, 2].map(|c| Face::Top.dof(n, c)), weight: areas[n] })
        .collect();
    let s = Sphere::new(Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    let mut pair = ContactPair::new("punch", Arc::new(s), points, 3.0e3, ContactKinematics::Exact);
    pair.entry_fraction = 0.0;
    // (held at D0 beyond t = 1, where the tests turn the punch further)
    pair.motion = PunchMotion::path(&[(1.0, D0)]).unwrap();
    pair.rotation = rotation;
    if mu > 0.0 {
        pair.set_friction(mu).unwrap();
    }
    model.add_contact(pair);
    let u0 = vec![0.0; model.num_dofs()];
    model.evaluate(&u0, 0.0, true).unwrap();
    model.evaluate(&u0, 1.0, true).unwrap();
    if let Some(f) = model.contacts[0].friction.as_mut() {
        f.anchor.clone_from(&f.position);
    }
    model.evaluate(&u0, 1.0, true).unwrap();
    (model, mesh, faces)
}

/// The plate's displacement that turns it by `turn` about the pivot as carried by D0 (both faces).
fn turned_plate(model: &Model<PlateElements>, mesh: &QuadMesh, faces: [f64; 2], turn: &Turn) -> Vec<f64> {
    let mut u = vec![0.0; model.num_dofs()];
    let d0 = Vector3::from(D0);
    for n in 0..mesh.num_nodes() {
        for (face, z) in [(Face::Bottom, faces[0]), (Face::Top, faces[1])] {
            let x = Vector3::new(mesh.coords[n][0], mesh.coords[n][1], z);
            let moved = turn.to_translated(&(x - d0)) + d0;
            for i in 0..3 {
                u[face.dof(n, i)] = moved[i] - x[i];
            }
        }
    }
    u
}

#[test]
fn a_rigid_rotation_of_plate_and_punch_gives_the_same_contact_and_no_friction() {
    let axis = [0.3, -0.5, 1.0];
    let pivot = [0.7, 1.4, 0.9];
    let degrees = 30.0;
    let rotation = PunchRotation::new(axis, pivot, &[(1.0, degrees)]).unwrap();
    let turn = Turn::new(rotation.axis(), pivot, degrees);
    for mu in [0.0, 0.3] {
        // the punch pressed without turning (rows beyond t = 1 never reached)
        let late = PunchRotation::new(axis, pivot, &[(1.0, 0.0), (2.0, degrees)]).unwrap();
        let (mut still, mesh, faces) = pressed(mu, Some(late));
        still.checkpoint();
        let normal = still.contacts[0].reaction();
        let active = still.contacts[0].state.iter().filter(|s| s.active).count();
        assert!(active >= 3, "{active} points in contact");
        // plate and punch turned together (the same anchors: the state of `still`)
        let u = turned_plate(&still, &mesh, faces, &turn);
        still.contacts[0].rotation = Some(rotation.clone());
        still.evaluate(&u, 1.0, true).unwrap();
        let c = &still.contacts[0];
        let r = c.reaction();
        let want = turn.r * Vector3::from(normal);
        let size = Vector3::from(normal).norm();
        let err = (Vector3::from(r) - want).norm() / size;
        println!("mu = {mu}: reaction {r:?} against R times {normal:?}: {err:e}");
        assert!(err < 1e-9, "the reaction turned with the pair: error {err:e}");
        assert_eq!(c.state.iter().filter(|s| s.active).count(), active);
        if let Some(f) = &c.friction {
            assert_eq!(f.status.iter().filter(|&&s| s == STICK).count(), active, "every point in contact sticks");
            let largest = f.traction.iter().map(|t| Vector3::from(*t).norm()).fold(0.0, f64::max);
            assert!(largest < 1e-9 * size, "traction {largest:e} after a rigid rotation (normal force {size:e})");
            still.checkpoint();
            let f = still.contacts[0].friction.as_ref().unwrap();
            assert!(f.slip.iter().all(|&s| s < 1e-12) && f.dissipation.iter().all(|&d| d.abs() < 1e-12 * size), "slip {:?}", f.slip);
        }
        // the plate's residual too is that of the unturned state, turned (the whole model is objective)
        let mut model_still = pressed(mu, None).0;
        let u0 = vec![0.0; model_still.num_dofs()];
        model_still.evaluate(&u0, 1.0, false).unwrap();
        let r0 = model_still.residual().to_vec();
        let r1 = still.residual().to_vec();
        let scale = r0.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut worst = 0.0f64;
        for n in 0..mesh.num_nodes() {
            for face in [Face::Bottom, Face::Top] {
                let eq = |i: usize| still.dofs.equation(face.dof(n, i));
                let (Some(a), Some(b), Some(c)) = (eq(0), eq(1), eq(2)) else { continue };
                let turned = turn.r * Vector3::new(r0[a], r0[b], r0[c]);
                worst = worst.max((turned - Vector3::new(r1[a], r1[b], r1[c])).amax());
            }
        }
        println!("mu = {mu}: residual against the turned residual {:e}", worst / scale);
        assert!(worst < 1e-8 * scale, "residuals differ by {worst:e} of {scale:e}");
    }
}

/// A sphere turning about its own centre has the same Psi: the same multipliers and forces as
/// one that does not turn. With friction, a plate sticking to it is dragged along its surface:
/// the traction (of the plate on the punch) is -eps_T (angle) (k x (x - c)) to first order in
/// the angle, against the surface's velocity.
#[test]
fn a_sphere_turning_about_its_centre_presses_the_same_and_drags_along_its_surface() {
    let centre = [1.0, 1.0, 1.2 + D0[2]];
    // (the pivot is a point of the punch at t = 0: its centre before the motion D0 carried it)
    let pivot = [1.0, 1.0, 1.2];
    let axis = Vector3::new(0.4, 1.0, 0.2).normalize();
    let turning = |deg: f64| PunchRotation::new(axis.into(), pivot, &[(1.0, deg)]).unwrap();
    let (plain, ..) = pressed(0.0, None);
    let (turned, ..) = pressed(0.0, Some(turning(70.0)));
    let (a, b) = (&plain.contacts[0], &turned.contacts[0]);
    let scale = a.state.iter().fold(0.0f64, |m, s| m.max(s.lambda.abs()));
    let worst = a.state.iter().zip(&b.state).fold(0.0f64, |m, (s, t)| m.max((s.lambda - t.lambda).abs()));
    println!("multipliers of a sphere turned 70 degrees about its centre: {:e} of {scale:e}", worst / scale);
    assert!(scale > 0.0 && worst < 1e-9 * scale && a.state.iter().zip(&b.state).all(|(s, t)| s.active == t.active));
    // friction: the anchors where the points stood at t = 1 without turning, then the sphere turned
    let degrees = 1e-3;
    let (mut model, ..) = pressed(0.3, None);
    model.contacts[0].rotation = Some(PunchRotation::new(axis.into(), pivot, &[(1.0, 0.0), (2.0, degrees)]).unwrap());
    let u0 = vec![0.0; model.num_dofs()];
    model.evaluate(&u0, 2.0, true).unwrap();
    let c = &model.contacts[0];
    let f = c.friction.as_ref().unwrap();
    let angle = degrees.to_radians();
    let mut checked = 0;
    for (k, p) in c.points.iter().enumerate().filter(|(k, _)| f.status[*k] == STICK) {
        let x = Vector3::from(p.x_ref) - Vector3::from(centre);
        let t = Vector3::from(f.traction[k]);
        let want = -axis.cross(&x) * (f.eps_t * angle);
        let n = x.normalize();
        let want = want - n * n.dot(&want);
        assert!((t - want).norm() < 1e-3 * want.norm(), "point {k}: traction {t:?} against {want:?}");
        checked += 1;
    }
    println!("{checked} sticking points dragged along the surface of a sphere turned by {degrees:e} degrees");
    assert!(checked >= 3, "{checked} sticking points");
}

//! With Coulomb friction the assembled tangent of a model (plate plus a curved punch) is still the
//! derivative of its residual: compared with central finite differences at a random
//! large-displacement state where some points stick and some slip, with the punch moved by a
//! prescribed displacement or pressed by a force (its travel an unknown), turned by a prescribed
//! rotation (friction then works in the punch's body frame); with the nodal and the integrated
//! contact discretisation (friction at the face's quadrature points).

mod common;
use common::*;
use stamp::contact::{ContactFace, ContactKinematics, ContactPair, ContactPoint, ForceDrive, PunchRotation, SLIP, STICK};
use stamp::dofs::DofMap;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::NonlinearProblem;
use stamp_contact::{Cylinder, Sphere};
use stamp_elements::{Face, Kinematics, PlateElements};
use std::sync::Arc;

/// A distorted 3 x 3 plate pressed by `surface` at a random large-displacement state, friction
/// `mu`, each point's anchor moved from where it stands by a random offset of 1e-5 to 1 (some
/// stick, some slip) and a random tangential multiplier. Returns the model, evaluated once with
/// the tangent there, and the state.
fn model_at(surface: Arc<dyn stamp::surface::ContactSurface>, seed: u64, mu: f64, drive: Option<[f64; 3]>) -> (Model<PlateElements>, Vec<f64>) {
    model_turned_at(surface, seed, mu, drive, None, false)
}

/// [`model_at`] with the punch turned by `rotation` too, and with the nodal contact or the
/// `integrated` one (every point's patch coupled in the pattern: the friction's anchors and
/// multipliers are then at the face's quadrature points).
fn model_turned_at(surface: Arc<dyn stamp::surface::ContactSurface>, seed: u64, mu: f64, drive: Option<[f64; 3]>, rotation: Option<PunchRotation>, integrated: bool) -> (Model<PlateElements>, Vec<f64>) {
    let mut mesh = QuadMesh::rectangle(0.0, 2.0, 0.0, 2.0, 3, 3).unwrap();
    let mut rng = Lcg(seed);
    for n in 0..mesh.num_nodes() {
        let x = mesh.coords[n];
        if x[0] > 0.0 && x[0] < 2.0 && x[1] > 0.0 && x[1] < 2.0 {
            mesh.coords[n] = [x[0] + rng.range(-0.15, 0.15), x[1] + rng.range(-0.15, 0.15)];
        }
    }
    let section = steel_section(0.2);
    let dp = section.delta_plus;
    let plate = PlateElements::new(&mesh, section, Kinematics::Nonlinear).unwrap();
    let mut dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    dofs.fix(mesh.group_nodes("left").unwrap(), &[0, 1, 2, 3, 4, 5]).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    let areas = mesh.nodal_areas();
    let points = (0..mesh.num_nodes())
        .map(|n| ContactPoint { node: n, x_ref: [mesh.coords[n][0], mesh.coords[n][1], dp], dofs: [0, 1, 2].map(|c| Face::Top.dof(n, c)), weight: areas[n] })
        .collect();
    let mut pair = ContactPair::new("punch", surface, points, 3.0e3, ContactKinematics::Exact);
    if integrated {
        let all: Vec<Option<usize>> = (0..mesh.num_nodes()).map(Some).collect();
        pair = pair.with_face(ContactFace::new(&mesh.coords, &mesh.cells, &all, mesh.num_nodes()).unwrap()).unwrap();
        pair.coupling_reach = 10.0;
    }
    pair.entry_fraction = 0.0;
    pair.gauss_newton_entry = false;
    pair.motion = [0.01, -0.02, -0.05].into();
    if let Some(n) = drive {
        pair.drive = Some(ForceDrive::new(n, 7.0).unwrap());
    }
    pair.rotation = rotation;
    pair.set_friction(mu).unwrap();
    model.add_contact(pair);
    let mut u: Vec<f64> = (0..model.num_dofs()).map(|_| rng.range(-0.3, 0.3)).collect();
    for n in 0..mesh.num_nodes() {
        for c in 0..3 {
            let amplitude = if c == 2 { 1.0 } else { 1.0 / 3.0 };
            u[Face::Top.dof(n, c)] *= amplitude;
            u[Face::Bottom.dof(n, c)] = u[Face::Top.dof(n, c)] + 0.1 * u[Face::Bottom.dof(n, c)];
        }
    }
    model.apply_prescribed(&mut u, 1.0);
    model.evaluate(&u, 1.0, true).unwrap();
    let f = model.contacts[0].friction.as_mut().unwrap();
    for k in 0..f.anchor.len() {
        let size = 10f64.powf(rng.range(-5.0, 0.0));
        for i in 0..3 {
            f.anchor[k][i] = f.position[k][i] + size * rng.range(-1.0, 1.0);
            f.lambda_t_bar[k][i] = rng.range(-20.0, 20.0);
        }
    }
    model.evaluate(&u, 1.0, true).unwrap();
    (model, u)
}

/// Each point's active state and its stick or slip: the finite differences skip a column across
/// which they change.
fn states(m: &Model<PlateElements>) -> (Vec<bool>, Vec<u8>) {
    let c = &m.contacts[0];
    (c.state.iter().map(|s| s.active).collect(), c.friction.as_ref().unwrap().status.clone())
}

fn check(surface: Arc<dyn stamp::surface::ContactSurface>, seed: u64, drive: Option<[f64; 3]>) -> f64 {
    check_turned(surface, seed, drive, None)
}

fn check_turned(surface: Arc<dyn stamp::surface::ContactSurface>, seed: u64, drive: Option<[f64; 3]>, rotation: Option<PunchRotation>) -> f64 {
    check_scheme(surface, seed, drive, rotation, false)
}

fn check_scheme(surface: Arc<dyn stamp::surface::ContactSurface>, seed: u64, drive: Option<[f64; 3]>, rotation: Option<PunchRotation>, integrated: bool) -> f64 {
    let (mut model, u) = model_turned_at(surface, seed, 0.3, drive, rotation, integrated);
    check_model(&mut model, &u, seed)
}

/// The first seed from `seed` on (of 40) whose state has two points or more in stick and in slip.
fn mixed_seed(surface: &Arc<dyn stamp::surface::ContactSurface>, seed: u64, drive: Option<[f64; 3]>, rotation: &PunchRotation) -> u64 {
    (seed..seed + 40)
        .find(|&s| {
            let (m, _) = model_turned_at(surface.clone(), s, 0.3, drive, Some(rotation.clone()), false);
            let f = m.contacts[0].friction.as_ref().unwrap();
            f.status.iter().filter(|&&x| x == STICK).count() >= 2 && f.status.iter().filter(|&&x| x == SLIP).count() >= 2
        })
        .expect("a state with points in stick and in slip")
}

fn check_model(model: &mut Model<PlateElements>, u: &[f64], seed: u64) -> f64 {
    let f = model.contacts[0].friction.as_ref().unwrap();
    let stick = f.status.iter().filter(|&&s| s == STICK).count();
    let slip = f.status.iter().filter(|&&s| s == SLIP).count();
    assert!(stick >= 2 && slip >= 2, "the state should have points in stick and in slip: {stick} stick, {slip} slip");
    // the friction's tangent is not symmetric
    let k = dense(model.matrix());
    let asym = (0..k.len()).flat_map(|i| (0..k.len()).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max((k[i][j] - k[j][i]).abs()));
    assert!(asym > 0.0);
    let (worst, skipped) = model_fd_error(model, u, &k, states);
    println!("seed {seed}: {stick} stick, {slip} slip, tangent vs differences {worst:e} ({skipped} columns skipped)");
    assert!(skipped < k.len() / 4, "{skipped} columns crossed a kink");
    assert!(worst < 1e-6, "model tangent with friction differs from finite differences by {worst:e}");
    worst
}

#[test]
fn friction_tangent_with_a_sphere_matches_finite_differences() {
    let s = Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    check(Arc::new(s), 11, None);
}

#[test]
fn friction_tangent_with_a_force_driven_punch_matches_finite_differences() {
    let s = Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    check(Arc::new(s), 21, Some([0.3, -0.2, -1.0]));
    let c = Cylinder::new(nalgebra::Vector3::new(0.0, 1.0, 1.0), nalgebra::Vector3::new(1.0, 0.3, 0.0), 1.3).unwrap();
    check(Arc::new(c), 22, Some([0.0, 0.0, -1.0]));
}

/// The integrated discretisation: friction at the face's quadrature points, whose bound follows
/// the normal multiplier field sum_a N_a lambda_a (so a slipping quadrature point's traction
/// depends on the weighted gaps of its cell's points, over their patches); prescribed and
/// force-driven, sphere and cylinder.
#[test]
fn integrated_friction_tangent_matches_finite_differences() {
    let s = || Arc::new(Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap());
    check_scheme(s(), 11, None, None, true);
    check_scheme(s(), 21, Some([0.3, -0.2, -1.0]), None, true);
    let c = Cylinder::new(nalgebra::Vector3::new(0.0, 1.0, 1.0), nalgebra::Vector3::new(1.0, 0.3, 0.0), 1.3).unwrap();
    check_scheme(Arc::new(c), 22, Some([0.0, 0.0, -1.0]), None, true);
}

/// A punch turned at the load factor of the state (25 degrees about a tilted axis through a
/// pivot off the sphere's centre; a cylinder about its own axis, force driven): the friction's
/// law in the body frame, turned back to global axes, is still the derivative of the residual.
#[test]
fn friction_tangent_with_a_turning_punch_matches_finite_differences() {
    let s: Arc<dyn stamp::surface::ContactSurface> = Arc::new(Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap());
    let r = PunchRotation::new([0.2, 1.0, 0.3], [1.2, 0.9, 1.0], &[(0.5, 10.0), (1.0, 25.0)]).unwrap();
    for (seed, drive) in [(11, None), (21, Some([0.3, -0.2, -1.0]))] {
        let seed = mixed_seed(&s, seed, drive, &r);
        check_turned(s.clone(), seed, drive, Some(r.clone()));
    }
    let axis = [1.0, 0.3, 0.0];
    let c: Arc<dyn stamp::surface::ContactSurface> = Arc::new(Cylinder::new(nalgebra::Vector3::new(0.0, 1.0, 1.0), nalgebra::Vector3::from(axis), 1.3).unwrap());
    let r = PunchRotation::new(axis, [0.0, 1.0, 1.0], &[(1.0, -40.0)]).unwrap();
    let seed = mixed_seed(&c, 22, Some([0.0, 0.0, -1.0]), &r);
    check_turned(c, seed, Some([0.0, 0.0, -1.0]), Some(r));
}

/// mu = 0 is no friction at all: no friction state (so no friction code runs; the bitwise
/// comparison of whole runs is in docs/design.md, "Friction"); bad coefficients are refused.
#[test]
fn zero_friction_changes_nothing() {
    let s = || Arc::new(Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap());
    let (a, _) = model_at(s(), 11, 0.3, None);
    assert!(a.contacts[0].friction.is_some());
    let mut pair = ContactPair::new("p", s(), Vec::new(), 1.0, ContactKinematics::Exact);
    pair.set_friction(0.0).unwrap();
    assert!(pair.friction.is_none());
    assert!(pair.set_friction(-0.1).is_err() && pair.set_friction(f64::NAN).is_err());
}

/// A rigid translation of plate and punch together moves no point against the punch: no
/// friction force, no slip, no dissipation; the same translation of the punch alone drags.
#[test]
fn a_rigid_translation_of_plate_and_punch_gives_no_friction() {
    let mesh = QuadMesh::rectangle(0.0, 2.0, 0.0, 2.0, 4, 4).unwrap();
    let section = steel_section(0.2);
    let dp = section.delta_plus;
    let plate = PlateElements::new(&mesh, section, Kinematics::Nonlinear).unwrap();
    let dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    let areas = mesh.nodal_areas();
    let points = (0..mesh.num_nodes())
        .map(|n| ContactPoint { node: n, x_ref: [mesh.coords[n][0], mesh.coords[n][1], dp], dofs: [0, 1, 2].map(|c| Face::Top.dof(n, c)), weight: areas[n] })
        .collect();
    let s = Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    let mut pair = ContactPair::new("punch", Arc::new(s), points, 3.0e3, ContactKinematics::Exact);
    pair.entry_fraction = 0.0;
    let d0 = [0.0, 0.0, -0.05];
    pair.motion = d0.into();
    pair.set_friction(0.3).unwrap();
    model.add_contact(pair);
    let u0 = vec![0.0; model.num_dofs()];
    model.evaluate(&u0, 1.0, true).unwrap();
    // the points touched where they stand: their anchors there, no traction
    let f = model.contacts[0].friction.as_mut().unwrap();
    f.anchor.clone_from(&f.position);
    model.evaluate(&u0, 1.0, true).unwrap();
    let active = model.contacts[0].state.iter().filter(|s| s.active).count();
    assert!(active >= 3, "{active} points in contact");
    model.checkpoint();
    let normal = model.contacts[0].reaction()[2].abs();
    let c = [0.3, -0.2, 0.1];
    let translated = |model: &mut Model<PlateElements>, plate_too: bool| {
        model.contacts[0].motion = [d0[0] + c[0], d0[1] + c[1], d0[2] + c[2]].into();
        let mut u1 = u0.clone();
        if plate_too {
            for n in 0..mesh.num_nodes() {
                for i in 0..3 {
                    u1[Face::Top.dof(n, i)] = c[i];
                    u1[Face::Bottom.dof(n, i)] = c[i];
                }
            }
        }
        model.evaluate(&u1, 1.0, true).unwrap();
        model.contacts[0].friction_force()
    };
    let drag = translated(&mut model, true);
    let fr = model.contacts[0].friction.as_ref().unwrap();
    assert_eq!(fr.status.iter().filter(|&&s| s == STICK).count(), active, "every point in contact sticks");
    let largest = fr.traction.iter().map(|t| nalgebra::Vector3::from(*t).norm()).fold(0.0, f64::max);
    assert!(largest < 1e-9 * normal, "traction {largest:e} after a rigid translation (normal force {normal:e})");
    assert!(drag.iter().all(|x| x.abs() < 1e-9 * normal), "friction force {drag:?}");
    model.checkpoint();
    let fr = model.contacts[0].friction.as_ref().unwrap();
    assert!(fr.slip.iter().all(|&s| s == 0.0) && fr.dissipation.iter().all(|&d| d == 0.0));
    // the punch alone moved: it drags the plate, every touching point slides
    let drag = translated(&mut model, false);
    let fr = model.contacts[0].friction.as_ref().unwrap();
    assert!(fr.status.iter().filter(|&&s| s == SLIP).count() >= 3);
    // (the force of the plate on the punch, against its motion)
    assert!(drag[0] < -1e-3 * normal && drag[1] > 1e-3 * normal, "drag {drag:?} against the normal force {normal:e}");
}

/// A cut-back restarts from the last converged friction state: `restore` brings back the
/// anchors, multipliers, slips and dissipations `checkpoint` saved, whatever the failed attempt
/// did to them.
#[test]
fn restore_brings_back_the_friction_state_of_the_checkpoint() {
    let s = Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    let (mut model, u) = model_at(Arc::new(s), 11, 0.3, None);
    model.checkpoint();
    let saved = model.contacts[0].friction.clone().unwrap();
    // an attempt: another state, a multiplier update, a converged-looking commit
    let mut v = u.clone();
    for x in v.iter_mut() {
        *x *= 1.01;
    }
    model.evaluate(&v, 1.0, true).unwrap();
    model.contacts[0].augment();
    model.contacts[0].commit_friction();
    let changed = model.contacts[0].friction.as_ref().unwrap();
    assert!(changed.anchor != saved.anchor && changed.lambda_t_bar != saved.lambda_t_bar && changed.slip != saved.slip);
    model.restore();
    let back = model.contacts[0].friction.as_ref().unwrap();
    assert_eq!((&back.anchor, &back.lambda_t_bar, &back.slip, &back.dissipation, &back.status), (&saved.anchor, &saved.lambda_t_bar, &saved.slip, &saved.dissipation, &saved.status));
}

/// GMRES on the LDL^T of the plate's symmetric preconditioner P, which holds a symmetric stand-in
/// of the friction's tangent, solves the unsymmetric system with points in stick and in slip:
/// the sparse LU's solution, in a few iterations, and not by falling back to the LU.
#[test]
fn gmres_on_the_symmetric_preconditioner_solves_the_friction_tangent() {
    use stamp::linalg::linear_solver::LinearSolver;
    let s = Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    let (mut model, u) = model_at(Arc::new(s), 11, 0.3, None);
    model.want_preconditioner(true);
    model.evaluate(&u, 1.0, true).unwrap();
    let r = model.residual().to_vec();
    let mut x_lu = r.clone();
    let mut lu = stamp::linalg::linear_solver::SparseLu::new();
    lu.factorize(model.matrix()).unwrap();
    lu.solve_in_place(&mut x_lu).unwrap();
    let p = model.preconditioner().expect("the plate gives P");
    let pd = p.to_dense();
    let n = pd.nrows();
    let asym = (0..n).flat_map(|i| (0..n).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max((pd[(i, j)] - pd[(j, i)]).abs()));
    assert!(asym == 0.0 || asym < 1e-12 * pd.norm_max(), "P is not symmetric: {asym:e}");
    let mut g = stamp::linalg::ldlt_gmres::LdltGmres::new().with_preconditioner(true);
    g.factorize_preconditioned(model.matrix(), Some(p)).unwrap();
    let mut x = r.clone();
    g.solve_in_place(&mut x).unwrap();
    let norm = x_lu.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let diff = x_lu.iter().zip(&x).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
    let st = g.stats();
    println!("GMRES on LDL^T(P): {} iterations, {} preconditioned, {} LU fallbacks; differs from LU by {:e}", st.gmres_iterations, st.preconditioned, st.lu_fallbacks, diff / norm);
    assert!(diff < 1e-8 * norm, "GMRES with P differs from the LU by {diff:e} (|x| = {norm:e})");
    assert_eq!(st.lu_fallbacks, 0);
    assert!(st.preconditioned == 1 && st.gmres_iterations <= 30, "{st:?}");
}

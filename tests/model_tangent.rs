//! The assembled tangent of a whole model (plate elements plus contact with a curved punch) is the
//! derivative of its residual: compared with central finite differences at a random (admissible)
//! large-displacement state with many points in contact, with the punch moved by a prescribed
//! displacement or pressed by a force (its displacement then an unknown with its own equation).

mod common;
use common::*;
use stamp::contact::{ContactFace, ContactKinematics, ContactPair, ContactPoint, ForceDrive};
use stamp::dofs::DofMap;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::NonlinearProblem;
use stamp_contact::{Cylinder, Sphere};
use stamp_elements::{Face, Kinematics, PlateElements};
use std::sync::Arc;

fn check(surface: Arc<dyn stamp::surface::ContactSurface>, kin: Kinematics, seed: u64, drive: Option<[f64; 3]>) {
    check_with(surface, kin, seed, drive, false)
}

fn check_with(surface: Arc<dyn stamp::surface::ContactSurface>, kin: Kinematics, seed: u64, drive: Option<[f64; 3]>, integrated: bool) {
    let (mut model, u) = model_at(surface, kin, seed, drive, integrated, false);
    check_model(&mut model, &u, drive.is_some());
}

/// A distorted 3 x 3 plate with a punch pressed into it at a random large-displacement state,
/// evaluated once with the tangent. `integrated`: the integrated discretisation (each node's
/// weighted gap over its cells), whose tangent couples the nodes of neighbouring cells;
/// `gauss_newton`: the Gauss-Newton tangent of the points that enter at this (first) contact.
fn model_at(surface: Arc<dyn stamp::surface::ContactSurface>, kin: Kinematics, seed: u64, drive: Option<[f64; 3]>, integrated: bool, gauss_newton: bool) -> (Model<PlateElements>, Vec<f64>) {
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
    let ck = match kin {
        Kinematics::Nonlinear => ContactKinematics::Exact,
        Kinematics::Linear => ContactKinematics::Shallow { direction: [0.0, 0.0, 1.0] },
    };
    let mut pair = ContactPair::new("punch", surface, points, 3.0e3, ck);
    if integrated {
        let all: Vec<Option<usize>> = (0..mesh.num_nodes()).map(Some).collect();
        pair = pair.with_face(ContactFace::new(&mesh.coords, &mesh.cells, &all, mesh.num_nodes()).unwrap()).unwrap();
    }
    // every penetrating point active in the one evaluation (no damped entry, which starts an
    // empty set at the deepest point only), each with its exact tangent (no Gauss-Newton tangent
    // for the points that enter: see the next test)
    pair.entry_fraction = 0.0;
    pair.gauss_newton_entry = gauss_newton;
    pair.motion = [0.01, -0.02, -0.05].into();
    if let Some(n) = drive {
        pair.drive = Some(ForceDrive::new(n, 7.0).unwrap());
    }
    model.add_contact(pair);
    assert_eq!(model.num_dofs(), model.dofs.num_dofs() + drive.is_some() as usize);
    assert_eq!(model.num_equations(), model.dofs.num_equations() + drive.is_some() as usize);
    // large deflections (+-0.3, the thickness 0.2), in-plane displacements of +-0.1 and the faces
    // close to each other (+-0.03): admissible (no element turned inside out)
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
    if integrated {
        // the first evaluation found the points in contact, which the pattern did not couple
        // yet: the model couples them from the next evaluation on
        model.evaluate(&u, 1.0, true).unwrap();
        assert!(!model.contacts[0].needs_coupling());
    }
    (model, u)
}

/// The tangent of the model's last evaluation against central differences of its residual at `u`.
fn check_model(model: &mut Model<PlateElements>, u: &[f64], drive: bool) {
    let u = u.to_vec();
    let active = model.contacts[0].state.iter().filter(|s| s.active).count();
    assert!(active >= 3, "the test state should have points in contact, has {active}");
    let k = dense(model.matrix());
    let scale = k.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let neq = model.num_equations();
    // a column across which a point enters or leaves contact is skipped: no derivative at the kink
    let (worst, _) = model_fd_error(model, &u, &k, |m| m.contacts[0].state.iter().map(|s| s.active).collect::<Vec<bool>>());
    assert!(worst < 1e-6, "model tangent differs from finite differences by {worst:e}");
    if drive {
        // the punch's row and column are really there (a tangent of zeros would pass above only if
        // the residual ignored s too)
        let s = neq - 1;
        let coupling = (0..neq - 1).map(|i| k[i][s].abs() + k[s][i].abs()).fold(0.0, f64::max);
        assert!(k[s][s].abs() > 1e-3 * scale && coupling > 1e-3 * scale, "K_ss = {}, largest coupling {coupling:e}", k[s][s]);
        // the bordered solver (block elimination) gives the sparse LU's solution of the whole system
        use stamp::linalg::linear_solver::LinearSolver;
        model.evaluate(&u, 1.0, true).unwrap();
        let r = model.residual().to_vec();
        let mut x_lu = r.clone();
        let mut lu = stamp::linalg::linear_solver::SparseLu::new();
        lu.factorize(model.matrix()).unwrap();
        lu.solve_in_place(&mut x_lu).unwrap();
        let mut x_b = r.clone();
        let mut b = stamp::linalg::bordered::BorderedSolver::new(1);
        b.factorize(model.matrix()).unwrap();
        b.solve_in_place(&mut x_b).unwrap();
        let norm = x_lu.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let diff = x_lu.iter().zip(&x_b).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(diff < 1e-8 * norm, "bordered solve differs from the full LU by {diff:e} (|x| = {norm:e})");
        // with the plate's preconditioner P (bordered like the tangent, symmetric, the contact and
        // punch terms whole): the same solution
        model.want_preconditioner(true);
        model.evaluate(&u, 1.0, true).unwrap();
        let p = model.preconditioner().expect("the plate gives P");
        let pd = p.to_dense();
        let asym = (0..neq).flat_map(|i| (0..neq).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max((pd[(i, j)] - pd[(j, i)]).abs()));
        assert!(asym < 1e-10 * scale, "P is not symmetric: {asym:e}");
        assert_eq!(pd[(s, s)], model.matrix().to_dense()[(s, s)], "the punch's own entry belongs to P whole");
        let mut x_p = r.clone();
        let mut b = stamp::linalg::bordered::BorderedSolver::with_inner(1, stamp::linalg::ldlt_gmres::LdltGmres::new().with_preconditioner(true));
        b.factorize_preconditioned(model.matrix(), Some(p)).unwrap();
        b.solve_in_place(&mut x_p).unwrap();
        let diff = x_lu.iter().zip(&x_p).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(diff < 1e-8 * norm, "bordered solve with P differs from the full LU by {diff:e} (|x| = {norm:e})");
    }
}

#[test]
fn model_tangent_with_sphere_contact_matches_finite_differences() {
    let s = Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    check(Arc::new(s), Kinematics::Nonlinear, 11, None);
}

#[test]
fn model_tangent_with_a_force_driven_punch_matches_finite_differences() {
    // the punch's displacement along its direction is an unknown; an oblique direction exercises
    // every coupling term (grad Psi . n, H n, n^T H n)
    let s = Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    check(Arc::new(s), Kinematics::Nonlinear, 21, Some([0.3, -0.2, -1.0]));
    let c = Cylinder::new(nalgebra::Vector3::new(0.0, 1.0, 1.0), nalgebra::Vector3::new(1.0, 0.3, 0.0), 1.3).unwrap();
    check(Arc::new(c), Kinematics::Nonlinear, 22, Some([0.0, 0.0, -1.0]));
    let s = Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    check(Arc::new(s), Kinematics::Linear, 23, Some([0.0, 0.0, -1.0]));
}

#[test]
fn model_tangent_with_cylinder_contact_matches_finite_differences() {
    let c = Cylinder::new(nalgebra::Vector3::new(0.0, 1.0, 1.0), nalgebra::Vector3::new(1.0, 0.3, 0.0), 1.3).unwrap();
    check(Arc::new(c), Kinematics::Nonlinear, 12, None);
    check(Arc::new(Cylinder::new(nalgebra::Vector3::new(0.0, 1.0, 1.0), nalgebra::Vector3::new(1.0, 0.3, 0.0), 1.3).unwrap()), Kinematics::Linear, 13, None);
}

#[test]
fn model_tangent_with_integrated_contact_matches_finite_differences() {
    // the weighted gaps couple the nodes of neighbouring cells: those entries must be in the
    // pattern and right, for a prescribed and a force-driven punch, exact and shallow kinematics
    let s = || Sphere::new(nalgebra::Vector3::new(1.0, 1.0, 1.2), 1.5).unwrap();
    check_with(Arc::new(s()), Kinematics::Nonlinear, 31, None, true);
    check_with(Arc::new(s()), Kinematics::Nonlinear, 32, Some([0.3, -0.2, -1.0]), true);
    check_with(Arc::new(s()), Kinematics::Linear, 33, Some([0.0, 0.0, -1.0]), true);
    let c = Cylinder::new(nalgebra::Vector3::new(0.0, 1.0, 1.0), nalgebra::Vector3::new(1.0, 0.3, 0.0), 1.3).unwrap();
    check_with(Arc::new(c), Kinematics::Nonlinear, 34, None, true);
}

/// At the first contact every point enters: with `gauss_newton_entry` (the default) their
/// tangent lacks the curvature term w lambda H (see stamp::contact::DEEP_ENTRY_RATIO), and
/// nothing else differs; once they are in, the next evaluation at the same state gives the
/// exact tangent again.
#[test]
fn points_entering_at_the_first_contact_get_the_gauss_newton_tangent() {
    let centre = nalgebra::Vector3::new(1.0, 1.0, 1.2);
    let sphere = || Arc::new(Sphere::new(centre, 1.5).unwrap());
    let (exact, u) = model_at(sphere(), Kinematics::Nonlinear, 11, None, false, false);
    let (mut gn, _) = model_at(sphere(), Kinematics::Nonlinear, 11, None, false, true);
    let (ke, kg) = (dense(exact.matrix()), dense(gn.matrix()));
    let scale = ke.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    // exact - Gauss-Newton = sum over the entering (here: all active) points of w lambda H, H = 2 I
    // for |x - c|^2 - R^2, on the point's three displacement dofs
    let mut expected = vec![vec![0.0; ke.len()]; ke.len()];
    let pair = &gn.contacts[0];
    let mut entering = 0;
    for (p, s) in pair.points.iter().zip(&pair.state) {
        if s.active {
            entering += 1;
            for &d in &p.dofs {
                if let Some(e) = gn.dofs.equation(d) {
                    expected[e][e] += p.weight * s.lambda * 2.0;
                }
            }
        }
    }
    assert!(entering >= 3, "{entering} points in contact");
    let worst = (0..ke.len()).flat_map(|i| (0..ke.len()).map(move |j| (i, j))).fold(0.0f64, |m, (i, j)| m.max((ke[i][j] - kg[i][j] - expected[i][j]).abs()));
    assert!(worst < 1e-12 * scale, "the tangents differ by more than the entering points' curvature terms: {worst:e}");
    let largest = expected.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(largest > 1e-6 * scale, "the curvature terms are there to be missed: {largest:e}");
    // evaluated again at the same state the points are no longer entering: the exact tangent
    gn.evaluate(&u, 1.0, true).unwrap();
    check_model(&mut gn, &u, false);
}

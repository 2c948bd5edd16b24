//! Follower loads (stamp_elements::follower): their tangents against central differences of
//! their forces, a cantilever strip rolled up by an end couple against the exact circle (follower
//! and fixed couples), and follower pressures (equilibrium of a free plate pressed from both
//! sides, a clamped strip against the dead pressure, the support reactions against the integral
//! of p n da over the deformed face).

mod common;

use common::Lcg;
use stamp::dofs::DofMap;
use stamp::follower::DeformationDependentLoad;
use stamp::linalg::linear_solver::SparseLu;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearProblem, NonlinearSolver, StepReport};
use stamp_elements::{fixed_couple_force, Face, FollowerCouple, FollowerPressure, Isotropic, Kinematics, PlateElements, Section};
use std::collections::HashMap;

/// The force F(u) and the dense tangent dF/du of a load over `n` dofs.
fn force_and_tangent(load: &dyn DeformationDependentLoad, u: &[f64]) -> (Vec<f64>, Vec<Vec<f64>>) {
    let n = u.len();
    let mut f = vec![0.0; n];
    let mut k = vec![vec![0.0; n]; n];
    let mut add = |r: usize, c: usize, v: f64| k[r][c] += v;
    load.add_force_and_stiffness(u, &mut f, Some(&mut add));
    (f, k)
}

/// Largest |K - central differences of F| over the largest |K| entry, at `u`.
fn tangent_error(load: &dyn DeformationDependentLoad, u: &[f64], step: f64) -> f64 {
    let (_, k) = force_and_tangent(load, u);
    let n = u.len();
    let kmax = k.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(kmax > 0.0, "the tangent is zero");
    let mut worst = 0.0f64;
    for c in 0..n {
        let (mut up, mut um) = (u.to_vec(), u.to_vec());
        up[c] += step;
        um[c] -= step;
        let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
        load.add_force_and_stiffness(&up, &mut fp, None);
        load.add_force_and_stiffness(&um, &mut fm, None);
        for r in 0..n {
            worst = worst.max((k[r][c] - (fp[r] - fm[r]) / (2.0 * step)).abs());
        }
    }
    worst / kmax
}

/// A distorted 2 x 2 mesh (interior node moved, cells of both orientations are avoided: all
/// counter-clockwise).
fn distorted_mesh() -> QuadMesh {
    let mut m = QuadMesh::rectangle(0.0, 2.0, 0.0, 1.6, 2, 2).unwrap();
    m.coords[4] = [1.23, 0.71];
    m.coords[2] = [2.2, -0.1];
    m
}

#[test]
fn follower_pressure_tangent_matches_central_differences() {
    let mesh = distorted_mesh();
    let mut rng = Lcg(7);
    for (face, z) in [(Face::Top, 0.05), (Face::Bottom, -0.05)] {
        let load = FollowerPressure::new("p", &mesh.coords, &mesh.cells, face, z, 3.7);
        for _ in 0..3 {
            // large displacements: of the order of the plate's size
            let u: Vec<f64> = (0..6 * mesh.num_nodes()).map(|_| rng.range(-0.6, 0.6)).collect();
            let e = tangent_error(&load, &u, 1e-6);
            assert!(e < 1e-8, "follower pressure on {face:?}: tangent differs from central differences by {e:e} (relative)");
        }
    }
}

#[test]
fn follower_couple_tangent_matches_central_differences() {
    let mut rng = Lcg(11);
    let nodes = vec![(0, [0.3, -1.2, 0.4]), (1, [-0.7, 0.2, 0.9]), (2, [0.0, 2.0, 0.0])];
    let load = FollowerCouple::new("m", nodes, 0.1);
    for _ in 0..5 {
        // the fibre turned and stretched: face displacements of the order of the thickness
        let u: Vec<f64> = (0..18).map(|_| rng.range(-0.08, 0.08)).collect();
        let e = tangent_error(&load, &u, 1e-7);
        assert!(e < 1e-7, "follower couple: tangent differs from central differences by {e:e} (relative)");
    }
}

#[test]
fn couple_force_pair_has_the_moment_perpendicular_to_the_fibre() {
    let mut rng = Lcg(3);
    let m = [0.3, -1.2, 0.4];
    let h = 0.1;
    let load = FollowerCouple::new("m", vec![(0, m)], h);
    for _ in 0..5 {
        let u: Vec<f64> = (0..6).map(|_| rng.range(-0.08, 0.08)).collect();
        let mut f = vec![0.0; 6];
        load.add_force_and_stiffness(&u, &mut f, None);
        let d: Vec<f64> = (0..3).map(|i| [0.0, 0.0, h][i] + u[3 + i] - u[i]).collect();
        let xp: Vec<f64> = (0..3).map(|i| [0.0, 0.0, 0.5 * h][i] + u[3 + i]).collect();
        let xm: Vec<f64> = (0..3).map(|i| [0.0, 0.0, -0.5 * h][i] + u[i]).collect();
        let cross = |a: &[f64], b: &[f64]| [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
        let (cp, cm) = (cross(&xp, &f[3..]), cross(&xm, &f[..3]));
        let q: f64 = d.iter().map(|x| x * x).sum();
        let md: f64 = (0..3).map(|i| m[i] * d[i]).sum();
        for i in 0..3 {
            assert!((f[i] + f[3 + i]).abs() < 1e-12, "the pair has a resultant {}", f[i] + f[3 + i]);
            let want = m[i] - md * d[i] / q;
            assert!((cp[i] + cm[i] - want).abs() < 1e-12, "moment component {i}: {} instead of {want}", cp[i] + cm[i]);
        }
    }
    // the fixed pair at the reference fibre carries M exactly (M3 = 0)
    let f = fixed_couple_force([0.3, -1.2, 0.0], h);
    let mom = [-0.5 * h * f[1] * 2.0, 0.5 * h * f[0] * 2.0];
    assert!((mom[0] - 0.3).abs() < 1e-14 && (mom[1] + 1.2).abs() < 1e-14, "fixed pair moment {mom:?}");
}

// ---------------------------------------------------------------------------------------------
// the cantilever rolled up by an end couple

/// Strip length, thickness, Young's modulus (nu = 0): EI = E h^3 / 12 = 1 per unit width.
const L: f64 = 100.0;
const H: f64 = 1.0;
const E: f64 = 12.0;
const EI: f64 = E * H * H * H / 12.0;
const CELLS: usize = 80;

fn settings(max_increment: f64) -> NewtonSettings {
    NewtonSettings { max_increment, chord_tol: 0.0, ..NewtonSettings::default() }
}

/// The strip along x1 (one cell across the unit width), clamped at x1 = 0, with the couple
/// -M e2 per unit width on its end x1 = L (M = 2 pi EI / L at load factor 1: the tip curls up).
fn roll_model(follower: bool) -> (QuadMesh, Model<PlateElements>) {
    let mesh = QuadMesh::rectangle(0.0, L, 0.0, 1.0, CELLS, 1).unwrap();
    let section = Section::homogeneous(H, Isotropic::new(E, 0.0).unwrap()).unwrap();
    let plate = PlateElements::new(&mesh, section, Kinematics::Nonlinear).unwrap();
    let mut dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    dofs.fix(mesh.group_nodes("left").unwrap(), &[0, 1, 2, 3, 4, 5]).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    let m = [0.0, -2.0 * std::f64::consts::PI * EI / L, 0.0];
    // each of the two end nodes carries half the unit width
    let couples: Vec<(usize, [f64; 3])> = mesh.group_nodes("right").unwrap().iter().map(|&n| (n, m.map(|x| 0.5 * x))).collect();
    if follower {
        model.add_follower_load(Box::new(FollowerCouple::new("end couple", couples, H)));
    } else {
        for (n, mn) in couples {
            let f = fixed_couple_force(mn, H);
            for c in 0..3 {
                if f[c] != 0.0 {
                    model.add_load(Face::Top.dof(n, c), f[c]).unwrap();
                    model.add_load(Face::Bottom.dof(n, c), -f[c]).unwrap();
                }
            }
        }
    }
    (mesh, model)
}

/// Per target load factor: the tip's mid-surface position (x1, x3), the end fibre's rotation
/// about -e2, and the step reports.
fn roll(follower: bool, targets: &[f64], max_increment: f64) -> (HashMap<usize, ([f64; 2], f64)>, Vec<StepReport>) {
    let (mesh, mut model) = roll_model(follower);
    let tip = mesh.group_nodes("right").unwrap().to_vec();
    let mut newton = NewtonRaphson::new(SparseLu::new(), settings(max_increment));
    let mut u = vec![0.0; model.num_dofs()];
    let mut at = HashMap::new();
    let mut reports = Vec::new();
    newton
        .solve_path(&mut model, &mut u, 0.0, targets, &mut |r, u, _| {
            reports.push(r.clone());
            if let Some(i) = r.target_index.filter(|_| r.is_target) {
                let mean = |f: &dyn Fn(usize) -> f64| tip.iter().map(|&n| f(n)).sum::<f64>() / tip.len() as f64;
                let mid = |c: usize| mean(&|n| 0.5 * (u[Face::Bottom.dof(n, c)] + u[Face::Top.dof(n, c)]));
                let fibre = |c: usize| mean(&|n| u[Face::Top.dof(n, c)] - u[Face::Bottom.dof(n, c)]) + if c == 2 { H } else { 0.0 };
                at.insert(i, ([L + mid(0), mid(2)], (-fibre(0)).atan2(fibre(2))));
            }
        })
        .unwrap();
    (at, reports)
}

/// The tip (x1, x3) of a strip of length L bent into a circular arc through the end angle theta.
fn arc_tip(theta: f64) -> [f64; 2] {
    if theta.abs() < 1e-12 {
        return [L, 0.0];
    }
    let r = L / theta;
    [r * theta.sin(), r * (1.0 - theta.cos())]
}

/// Plain Newton iterations (a new tangent every iteration, sparse LU) at load factor `t` from `u`:
/// the norms of the corrections |du| until |du| <= 1e-12 |u| (or 12 iterations).
fn newton_corrections<P: NonlinearProblem>(model: &mut P, u: &mut [f64], t: f64) -> Vec<f64> {
    use stamp::linalg::linear_solver::LinearSolver;
    let mut lu = SparseLu::new();
    let mut out = Vec::new();
    for _ in 0..12 {
        model.evaluate(u, t, true).unwrap();
        lu.factorize(model.matrix()).unwrap();
        let mut du: Vec<f64> = model.residual().iter().map(|r| -r).collect();
        lu.solve_in_place(&mut du).unwrap();
        model.add_increment(u, &du);
        let n = du.iter().map(|x| x * x).sum::<f64>().sqrt();
        out.push(n);
        if n <= 1e-12 * size(u) {
            break;
        }
    }
    out
}

/// Quadratic convergence: the order ln(e_k+1 / e_k) / ln(e_k / e_k-1) of the last three corrections
/// above the round-off of the linear solves (1e-12 |u|) is at least 1.6 (2 for Newton's method
/// with an exact tangent, 1 with a wrong one), and Newton converged.
fn assert_quadratic(what: &str, du: &[f64], size: f64) {
    assert!(du.last().is_some_and(|&x| x <= 1e-10 * size), "{what}: Newton did not converge: corrections {du:?}");
    let floor = 1e-12 * size;
    let k = du.iter().rposition(|&x| x > floor).expect("a correction above round-off");
    assert!(k >= 2, "{what}: too few corrections above round-off to see the order: {du:?}");
    let order = (du[k] / du[k - 1]).ln() / (du[k - 1] / du[k - 2]).ln();
    println!("{what}: order of convergence {order:.2} from |du| = {:.2e}, {:.2e}, {:.2e}", du[k - 2], du[k - 1], du[k]);
    assert!(du[k] < du[k - 1] && du[k - 1] < du[k - 2] && order >= 1.6, "{what}: order of convergence {order:.2} from |du| = {:e}, {:e}, {:e}: not quadratic; corrections {du:?}", du[k - 2], du[k - 1], du[k]);
}

/// The norm of `u`, at least 1.
fn size(u: &[f64]) -> f64 {
    u.iter().map(|x| x * x).sum::<f64>().sqrt().max(1.0)
}

/// The rolled strip converged at load factor `t` (steps of at most 0.05).
fn rolled_state(follower: bool, t: f64) -> Model<PlateElements> {
    let (_, mut model) = roll_model(follower);
    let mut newton = NewtonRaphson::new(SparseLu::new(), settings(0.05));
    let mut u = vec![0.0; model.num_dofs()];
    newton.solve_path(&mut model, &mut u, 0.0, &[t], &mut |_, _, _| {}).unwrap();
    model.evaluate(&u, t, false).unwrap();
    ROLLED.with(|r| *r.borrow_mut() = u);
    model
}

thread_local! {
    static ROLLED: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
}

#[test]
fn newton_converges_quadratically_with_the_follower_couple() {
    for (t, next) in [(0.25f64, 0.3), (0.5, 0.55), (0.95, 1.0)] {
        let mut model = rolled_state(true, t.max(1e-3));
        let mut u = ROLLED.with(|r| r.borrow().clone());
        let du = newton_corrections(&mut model, &mut u, next);
        println!("follower couple, Newton from t = {t} to {next}: |du| = {:?}", du.iter().map(|x| format!("{x:.2e}")).collect::<Vec<_>>());
        assert_quadratic(&format!("follower couple from t = {t} to {next}"), &du, size(&u));
    }
}

#[test]
fn newton_converges_quadratically_with_the_follower_pressure() {
    // the cantilever strip of the test below, from its converged state at t = 0.5 to t = 0.6
    let d = 1.0e4 * 1e-3 / (12.0 * (1.0 - 0.09));
    let p = 3.0 * d / 1000.0;
    let (mut model, mut u) = strip_model(true, p, false);
    let mut newton = NewtonRaphson::new(SparseLu::new(), settings(0.1));
    newton.solve_path(&mut model, &mut u, 0.0, &[0.5], &mut |_, _, _| {}).unwrap();
    let du = newton_corrections(&mut model, &mut u, 0.6);
    println!("follower pressure, Newton from t = 0.5 to 0.6: |du| = {:?}", du.iter().map(|x| format!("{x:.2e}")).collect::<Vec<_>>());
    assert_quadratic("follower pressure on the cantilever from t = 0.5 to 0.6", &du, size(&u));
}

#[test]
fn follower_couple_rolls_a_cantilever_onto_the_exact_circle() {
    let targets = [0.01, 0.25, 0.5, 1.0];
    let (at, reports) = roll(true, &targets, 0.05);
    // the bending stiffness at a small moment: theta = M L / EI
    let theta = at[&0].1;
    let linear = 0.01 * 2.0 * std::f64::consts::PI;
    assert!((theta / linear - 1.0).abs() < 2e-3, "end rotation {theta} at t = 0.01, M L / EI = {linear}: EI is not E h^3 / 12");
    for (i, &k) in targets.iter().enumerate() {
        let want = arc_tip(2.0 * std::f64::consts::PI * k);
        let got = at[&i].0;
        let err = ((got[0] - want[0]).powi(2) + (got[1] - want[1]).powi(2)).sqrt();
        println!("k = {k}: tip ({:.4}, {:.4}), exact ({:.4}, {:.4}), error {:.3e} L; end rotation {:.5} (exact {:.5})", got[0], got[1], want[0], want[1], err / L, at[&i].1, 2.0 * std::f64::consts::PI * k);
        assert!(err < 0.01 * L, "k = {k}: tip {got:?} is {err} from the exact circle's {want:?} (more than 1 % of L)");
    }
    for r in &reports {
        println!("step {} t = {:.3}: {} iterations, |R| {:?}", r.step, r.load_factor, r.iterations, r.residual_history.iter().map(|x| format!("{x:.1e}")).collect::<Vec<_>>());
    }
    // steps of 0.05 (pi / 10 of end rotation each) take 9 iterations, shorter ones 5-8
    assert!(reports.iter().all(|r| r.iterations <= 9), "Newton needed more than 9 iterations in a step: {:?}", reports.iter().map(|r| r.iterations).collect::<Vec<_>>());
}

#[test]
fn fixed_couple_agrees_at_small_load_and_does_not_close_the_circle() {
    let (follower, _) = roll(true, &[0.01], 0.05);
    let (fixed, reports) = roll(false, &[0.01, 1.0], 0.05);
    // first order: the same end rotation and tip (they differ by O(theta^2))
    let (a, b) = (follower[&0], fixed[&0]);
    let theta = a.1;
    assert!((a.1 - b.1).abs() < 0.01 * theta, "at t = 0.01 the fixed couple turns the end by {}, the follower by {}", b.1, a.1);
    assert!((a.0[1] - b.0[1]).abs() < 0.01 * a.0[1], "at t = 0.01 tip deflections {} (fixed) and {} (follower)", b.0[1], a.0[1]);
    // at M = 2 pi EI / L the dead pair's moment is M cos(theta): the end turns to the root of
    // theta = 2 pi cos(theta), far from a full circle
    let mut th = 1.0f64;
    for _ in 0..50 {
        th -= (th - 2.0 * std::f64::consts::PI * th.cos()) / (1.0 + 2.0 * std::f64::consts::PI * th.sin());
    }
    let (tip, rot) = fixed[&1];
    let want = arc_tip(th);
    println!("fixed couple at t = 1: end rotation {rot:.4} (theta = 2 pi cos theta: {th:.4}), tip ({:.3}, {:.3}), arc ({:.3}, {:.3})", tip[0], tip[1], want[0], want[1]);
    assert!((rot - th).abs() < 0.01 * th, "fixed couple at t = 1: end rotation {rot}, theta = 2 pi cos(theta) gives {th}");
    assert!(((tip[0] - want[0]).powi(2) + (tip[1] - want[1]).powi(2)).sqrt() < 0.01 * L, "fixed couple at t = 1: tip {tip:?}, arc {want:?}");
    assert!(tip[0] > 0.5 * L, "the fixed couple closed the circle: tip {tip:?}");
    // steps of 0.05 (pi / 10 of end rotation each) take 9 iterations, shorter ones 5-8
    assert!(reports.iter().all(|r| r.iterations <= 9), "Newton needed more than 9 iterations in a step: {:?}", reports.iter().map(|r| r.iterations).collect::<Vec<_>>());
}

// ---------------------------------------------------------------------------------------------
// follower pressures

#[test]
fn pressure_on_both_faces_has_no_resultant_and_turns_with_the_plate() {
    let mesh = QuadMesh::rectangle(0.0, 2.0, 0.0, 1.0, 4, 2).unwrap();
    let h = 0.1;
    let p = 50.0;
    let top = FollowerPressure::new("top", &mesh.coords, &mesh.cells, Face::Top, 0.5 * h, p);
    let bottom = FollowerPressure::new("bottom", &mesh.coords, &mesh.cells, Face::Bottom, -0.5 * h, p);
    let n = 6 * mesh.num_nodes();
    // positions of the face points after the rigid motion x -> rot x + shift
    let place = |rot: &[[f64; 3]; 3], shift: [f64; 3]| {
        let mut u = vec![0.0; n];
        let mut x = vec![[0.0; 3]; 2 * mesh.num_nodes()];
        for (k, c) in mesh.coords.iter().enumerate() {
            for (face, z) in [(Face::Bottom, -0.5 * h), (Face::Top, 0.5 * h)] {
                let x0 = [c[0], c[1], z];
                for i in 0..3 {
                    let y: f64 = (0..3).map(|j| rot[i][j] * x0[j]).sum::<f64>() + shift[i];
                    u[face.dof(k, i)] = y - x0[i];
                    x[2 * k + face.index()][i] = y;
                }
            }
        }
        let mut f = vec![0.0; n];
        top.add_force_and_stiffness(&u, &mut f, None);
        bottom.add_force_and_stiffness(&u, &mut f, None);
        (x, f)
    };
    let id = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let (_, f0) = place(&id, [0.0; 3]);
    // p A on each face, A = 2: the top face gets -p A e3, the bottom one +p A e3
    let top_sum: f64 = (0..mesh.num_nodes()).map(|k| f0[Face::Top.dof(k, 2)]).sum();
    assert!((top_sum + p * 2.0).abs() < 1e-12 * p, "the top face's pressure gives {top_sum}, not -p A = {}", -p * 2.0);
    let rot = common::euler_krylov(0.4, -0.9, 1.3);
    let (x, f) = place(&rot, [0.3, -2.0, 1.1]);
    let (mut force, mut moment) = ([0.0; 3], [0.0; 3]);
    for k in 0..mesh.num_nodes() {
        for face in [Face::Bottom, Face::Top] {
            let fk: Vec<f64> = (0..3).map(|i| f[face.dof(k, i)]).collect();
            let xk = x[2 * k + face.index()];
            for i in 0..3 {
                force[i] += fk[i];
                // the pressure turns with the plate: its nodal forces are the reference ones rotated
                let want: f64 = (0..3).map(|j| rot[i][j] * f0[face.dof(k, j)]).sum();
                assert!((fk[i] - want).abs() < 1e-12 * p, "node {k} {face:?}: force {} after the rotation, the rotated reference force is {want}", fk[i]);
            }
            let m = [xk[1] * fk[2] - xk[2] * fk[1], xk[2] * fk[0] - xk[0] * fk[2], xk[0] * fk[1] - xk[1] * fk[0]];
            for i in 0..3 {
                moment[i] += m[i];
            }
        }
    }
    for i in 0..3 {
        assert!(force[i].abs() < 1e-12 * p && moment[i].abs() < 1e-11 * p, "equal pressures on both faces give the resultant {force:?} and moment {moment:?}");
    }
}

/// A strip along x2 (plane strain, one cell across the unit width in x1, length 10, h = 0.1)
/// clamped at x2 = 0 and, when `both_ends`, at x2 = 10, under a pressure on its top face: the
/// deflection (downwards positive) at midspan (both ends) or at the tip, the support reactions
/// and the applied load's total force.
fn clamped_strip(follower: bool, p: f64, both_ends: bool) -> (f64, [f64; 3], [f64; 3], Vec<StepReport>) {
    let (mut model, mut u) = strip_model(follower, p, both_ends);
    let mesh = QuadMesh::rectangle(0.0, 1.0, 0.0, 10.0, 1, 40).unwrap();
    let l = 10.0;
    let mut newton = NewtonRaphson::new(SparseLu::new(), settings(0.1));
    let mut reports = Vec::new();
    newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |r, _, _| reports.push(r.clone())).unwrap();
    model.evaluate(&u, 1.0, false).unwrap();
    let probe = if both_ends { 0.5 * l } else { l };
    let mid = mesh.nodes_where(|x| (x[1] - probe).abs() < 1e-9);
    let w = -mid.iter().map(|&n| 0.5 * (u[Face::Top.dof(n, 2)] + u[Face::Bottom.dof(n, 2)])).sum::<f64>() / mid.len() as f64;
    // the reaction of the supports on the plate: f_int - f_ext at the held dofs
    let forces = model.nodal_forces();
    let ff = model.follower_forces();
    let mut reaction = [0.0; 3];
    let mut total = [0.0; 3];
    for n in 0..mesh.num_nodes() {
        for face in [Face::Bottom, Face::Top] {
            for c in 0..3 {
                let d = face.dof(n, c);
                let applied = if follower { ff[d] } else if face == Face::Top && c == 2 { -p * mesh.nodal_areas()[n] } else { 0.0 };
                total[c] += applied;
                if model.dofs.equation(d).is_none() {
                    reaction[c] += forces[d] - applied;
                }
            }
        }
    }
    (w, reaction, total, reports)
}

/// The model of [`clamped_strip`] and its zero state.
fn strip_model(follower: bool, p: f64, both_ends: bool) -> (Model<PlateElements>, Vec<f64>) {
    let (l, h, cells) = (10.0, 0.1, 40);
    let mesh = QuadMesh::rectangle(0.0, 1.0, 0.0, l, 1, cells).unwrap();
    let section = Section::homogeneous(h, Isotropic::new(1.0e4, 0.3).unwrap()).unwrap();
    let plate = PlateElements::new(&mesh, section, Kinematics::Nonlinear).unwrap();
    let mut dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    let all: Vec<usize> = (0..mesh.num_nodes()).collect();
    dofs.fix(&all, &[0, 3]).unwrap();
    let mut ends = mesh.group_nodes("bottom").unwrap().to_vec();
    if both_ends {
        ends.extend_from_slice(mesh.group_nodes("top").unwrap());
    }
    dofs.fix(&ends, &[0, 1, 2, 3, 4, 5]).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    if follower {
        model.add_follower_load(Box::new(FollowerPressure::new("p", &mesh.coords, &mesh.cells, Face::Top, 0.5 * h, p)));
    } else {
        for (n, a) in mesh.nodal_areas().iter().enumerate() {
            model.add_load(Face::Top.dof(n, 2), -p * a).unwrap();
        }
    }
    let u = vec![0.0; model.num_dofs()];
    (model, u)
}

#[test]
fn clamped_strip_reactions_balance_the_follower_pressure() {
    let p = 0.5;
    let (w_dead, r_dead, t_dead, _) = clamped_strip(false, p, true);
    let (w_fol, r_fol, t_fol, reports) = clamped_strip(true, p, true);
    println!("strip clamped at both ends, p = {p}: midspan deflection {w_dead:.5} (dead), {w_fol:.5} (follower); follower total force {t_fol:?}, reactions {r_fol:?}");
    // a large deflection (membrane action), several times h
    assert!(w_dead > 0.3 && w_fol > 0.3, "the strip hardly deflects ({w_dead}, {w_fol}): not a large-deflection test");
    // the reactions balance the applied forces: sum of reactions = - integral of p n da
    for c in 0..3 {
        assert!((r_fol[c] + t_fol[c]).abs() < 1e-8 * p * 10.0, "component {c}: reactions {r_fol:?} do not balance the follower pressure's {t_fol:?}");
        assert!((r_dead[c] + t_dead[c]).abs() < 1e-8 * p * 10.0, "component {c}: reactions {r_dead:?} do not balance the dead pressure's {t_dead:?}");
    }
    // the face's boundary is held: the integral of n da over the deformed face is its reference
    // vector area however it deforms (-p A e3, A = 10 x 1)
    assert!((t_fol[2] + p * 10.0).abs() < 1e-9 * p * 10.0 && t_fol[0].abs() < 1e-9 && t_fol[1].abs() < 1e-9, "follower total force {t_fol:?}, expected (0, 0, {})", -p * 10.0);
    // the first step goes from the flat strip to a membrane: a few more iterations
    assert!(reports.iter().all(|r| r.iterations <= 12), "Newton needed more than 12 iterations in a step: {:?}", reports.iter().map(|r| r.iterations).collect::<Vec<_>>());
}

#[test]
fn cantilever_under_follower_pressure_bends_further_than_under_dead_pressure() {
    // q L^3 / D = 3 (D = E h^3 / (12 (1 - nu^2)) in plane strain): a large deflection
    let d = 1.0e4 * 1e-3 / (12.0 * (1.0 - 0.09));
    let p = 3.0 * d / 1000.0;
    let (w_dead, r_dead, t_dead, _) = clamped_strip(false, p, false);
    let (w_fol, r_fol, t_fol, reports) = clamped_strip(true, p, false);
    println!("cantilever, q L^3 / D = 3: tip deflection {w_dead:.4} (dead), {w_fol:.4} (follower) of L = 10; follower total force {t_fol:?}, reactions {r_fol:?}");
    assert!(w_dead > 2.0, "the cantilever hardly deflects ({w_dead}): not a large-deflection test");
    // a dead load loses lever arm as the strip turns (its moment about the root goes with the
    // horizontal distance, which shrinks), a follower load keeps acting across the strip
    assert!(w_fol > 1.05 * w_dead, "follower pressure tip deflection {w_fol} is not clearly above the dead pressure's {w_dead}");
    // the follower pressure turned with the strip: its total force leans towards the root
    // (normals tilted towards -x2 on the bent strip) and is balanced by the clamp
    assert!(t_fol[1] < -0.05 * p * 10.0, "the follower pressure's total force {t_fol:?} has no horizontal part");
    for c in 0..3 {
        assert!((r_fol[c] + t_fol[c]).abs() < 1e-8 * p * 10.0, "component {c}: reactions {r_fol:?} do not balance the follower pressure's {t_fol:?}");
        assert!((r_dead[c] + t_dead[c]).abs() < 1e-8 * p * 10.0, "component {c}: reactions {r_dead:?} do not balance the dead pressure's {t_dead:?}");
    }
    // steps of 0.05 (pi / 10 of end rotation each) take 9 iterations, shorter ones 5-8
    assert!(reports.iter().all(|r| r.iterations <= 9), "Newton needed more than 9 iterations in a step: {:?}", reports.iter().map(|r| r.iterations).collect::<Vec<_>>());
}

/// The tip deflection (downwards) and the tip's displacement along the strip (towards the root
/// positive) of an inextensible, unshearable cantilever of length `l` and bending stiffness `d`
/// under a follower pressure `p` on its top face (the planar Kirchhoff rod, e.g. S. S. Antman,
/// Nonlinear Problems of Elasticity, 2nd ed., ch. 4): with t = (cos phi, sin phi) the tangent,
/// n = (-sin phi, cos phi) the upward normal, F = N t + V n the force of the outer part on the
/// inner one and M = d phi' the bending moment, equilibrium under the load -q n per unit length is
/// N' = V phi', V' = q - N phi', M' = -V: free of phi, so it is integrated from the free end
/// (N = V = M = 0) to the root, then phi, x2 and x3 from the clamped root (phi = 0). The top face
/// of thickness `h` is 1 - (h/2) phi' times as long as the axis, q = p (1 - (h/2) phi'). RK4.
fn follower_elastica_tip(l: f64, h: f64, d: f64, p: f64) -> (f64, f64) {
    let steps = 20_000;
    let ds = l / steps as f64;
    // from the tip back to the root: y = (N, V, M), curvature kappa = M / d
    let rhs = |y: [f64; 3]| {
        let kappa = y[2] / d;
        let q = p * (1.0 - 0.5 * h * kappa);
        [y[1] * kappa, q - y[0] * kappa, -y[1]]
    };
    let mut y = [0.0; 3];
    let mut kappa = vec![0.0; steps + 1];
    for k in (0..steps).rev() {
        // d/ds with s decreasing: y(s - ds) = y(s) - ds y'
        let add = |y: [f64; 3], f: [f64; 3], c: f64| [y[0] + c * f[0], y[1] + c * f[1], y[2] + c * f[2]];
        let k1 = rhs(y);
        let k2 = rhs(add(y, k1, -0.5 * ds));
        let k3 = rhs(add(y, k2, -0.5 * ds));
        let k4 = rhs(add(y, k3, -ds));
        for i in 0..3 {
            y[i] -= ds / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        kappa[k] = y[2] / d;
    }
    // phi (trapezoidal in kappa), then x2 and x3 (Simpson) from the root
    let (mut phi, mut x2, mut x3) = (0.0f64, 0.0, 0.0);
    for k in 0..steps {
        let phi_mid = phi + 0.125 * ds * (3.0 * kappa[k] + kappa[k + 1]);
        let phi_end = phi + 0.5 * ds * (kappa[k] + kappa[k + 1]);
        x2 += ds / 6.0 * (phi.cos() + 4.0 * phi_mid.cos() + phi_end.cos());
        x3 += ds / 6.0 * (phi.sin() + 4.0 * phi_mid.sin() + phi_end.sin());
        phi = phi_end;
    }
    (-x3, l - x2)
}

#[test]
fn cantilever_under_follower_pressure_follows_the_elastica() {
    // plane strain: D = E h^3 / (12 (1 - nu^2)); q L^3 / D = 3, as above
    let (l, h) = (10.0, 0.1);
    let d = 1.0e4 * h * h * h / (12.0 * (1.0 - 0.09));
    let p = 3.0 * d / (l * l * l);
    let (w_ref, shortening_ref) = follower_elastica_tip(l, h, d, p);
    let (w, _, _, _) = clamped_strip(true, p, false);
    println!("cantilever under a follower pressure, q L^3 / D = 3: tip deflection {w:.5} (plate, 40 cells), {w_ref:.5} (elastica; tip moves {shortening_ref:.5} towards the root)");
    assert!(w_ref > 2.0, "the reference hardly deflects: {w_ref}");
    // measured: 3e-6 apart (the plate's stretching and shear are of order (h / L)^2)
    assert!((w - w_ref).abs() <= 1e-3 * w_ref, "tip deflection {w} against the elastica's {w_ref}");
}

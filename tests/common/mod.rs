//! Helpers shared by the integration tests.
#![allow(dead_code)]

use stamp::element::{Element, LocalSystem};
use stamp::mesh::QuadMesh;
use stamp_elements::{Isotropic, Kinematics, PlateElements, Section};

/// A tiny deterministic random generator (no external crates in tests).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64) / ((1u64 << 53) as f64)
    }
    /// Uniform in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

/// The rotation matrix of the paper's eq. 1.7 from the Euler-Krylov angles (phi, theta, psi).
pub fn euler_krylov(phi: f64, theta: f64, psi: f64) -> [[f64; 3]; 3] {
    let (sf, cf) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    [
        [ct * cp, ct * sp, -st],
        [-cf * sp + sf * st * cp, cf * cp + sf * st * sp, sf * ct],
        [sf * sp + cf * st * cp, -sf * cp + cf * st * sp, cf * ct],
    ]
}

/// A strongly distorted single element (corner angles far from 90 degrees).
pub fn distorted_element() -> QuadMesh {
    QuadMesh::new(vec![[0.0, 0.0], [2.0, 0.3], [2.6, 1.9], [-0.4, 1.2]], vec![[0, 1, 2, 3]]).unwrap()
}

pub fn steel_section(h: f64) -> Section {
    Section::homogeneous(h, Isotropic::new(2.0e5, 0.3).unwrap()).unwrap()
}

/// Evaluate element 0 of a plate at local dofs v.
pub fn eval(plate: &PlateElements, v: &[f64], tangent: bool) -> LocalSystem {
    let mut ws = plate.new_workspace();
    let mut out = LocalSystem::with_preconditioner(24);
    plate.evaluate(0, v, &mut ws, &mut out, tangent);
    out
}

pub fn plate(mesh: &QuadMesh, h: f64, kin: Kinematics) -> PlateElements {
    PlateElements::new(mesh, steel_section(h), kin).unwrap()
}

/// The largest difference between the element's tangent at `v` and central finite differences
/// (step 1e-6) of its internal force, relative to the largest tangent entry.
pub fn tangent_fd_error(plate: &PlateElements, v: &[f64]) -> f64 {
    let n = v.len();
    let k = eval(plate, v, true).tangent;
    let scale = max_abs(&k);
    let step = 1e-6;
    let mut worst: f64 = 0.0;
    for j in 0..n {
        let (mut vp, mut vm) = (v.to_vec(), v.to_vec());
        vp[j] += step;
        vm[j] -= step;
        let (rp, rm) = (eval(plate, &vp, false).residual, eval(plate, &vm, false).residual);
        for i in 0..n {
            worst = worst.max(((rp[i] - rm[i]) / (2.0 * step) - k[i * n + j]).abs() / scale);
        }
    }
    worst
}

pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

use stamp::dofs::DofMap;
use stamp::linalg::linear_solver::SparseLu;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearSolver, StepReport};
use stamp_elements::Face;

/// A cantilever strip along x2 (length l, one element across a unit width, plane strain v1 = 0),
/// clamped at x2 = 0, with a conservative force `force` per unit width in x3 at the free end, at the
/// mid-surface. Returns (tip deflection w, tip horizontal displacement u2, the step reports).
pub fn cantilever_strip(l: f64, h: f64, elements: usize, force: f64, kin: Kinematics, steps: &[f64]) -> (f64, f64, Vec<StepReport>) {
    let mesh = QuadMesh::rectangle(0.0, 1.0, 0.0, l, 1, elements).unwrap();
    let section = Section::homogeneous(h, Isotropic::new(2.0e5, 0.3).unwrap()).unwrap();
    let plate = PlateElements::new(&mesh, section, kin).unwrap();
    let mut dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    let all: Vec<usize> = (0..mesh.num_nodes()).collect();
    dofs.fix(&all, &[0, 3]).unwrap();
    dofs.fix(mesh.group_nodes("bottom").unwrap(), &[0, 1, 2, 3, 4, 5]).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    let tip = mesh.group_nodes("top").unwrap().to_vec();
    for &n in &tip {
        model.add_load(Face::Bottom.dof(n, 2), 0.25 * force).unwrap();
        model.add_load(Face::Top.dof(n, 2), 0.25 * force).unwrap();
    }
    let mut settings = NewtonSettings::default();
    settings.max_increment = 1.0;
    let mut newton = NewtonRaphson::new(SparseLu::new(), settings);
    let mut u = vec![0.0; model.dofs.num_dofs()];
    let mut reports = Vec::new();
    newton.solve_path(&mut model, &mut u, 0.0, steps, &mut |r, _, _| reports.push(r.clone())).unwrap();
    let mid = |c: usize| tip.iter().map(|&n| 0.5 * (u[Face::Bottom.dof(n, c)] + u[Face::Top.dof(n, c)])).sum::<f64>() / tip.len() as f64;
    (mid(2), mid(1), reports)
}

/// Plate bending stiffness E h^3 / (12 (1 - nu^2)) of the test material.
pub fn bending_stiffness(h: f64) -> f64 {
    2.0e5 * h * h * h / (12.0 * (1.0 - 0.09))
}

pub mod cylindrical;
pub mod pagano;
pub mod sphere;

/// A patch test: solves the plate on `mesh` with the nodes `boundary` (both faces) prescribed to
/// `exact(x, x3) -> [v1, v2, v3]` and returns the largest error at the other nodes relative to the
/// largest exact value there.
pub fn patch_error(mesh: &QuadMesh, boundary: &[usize], kin: Kinematics, h: f64, exact: &dyn Fn([f64; 2], f64) -> [f64; 3]) -> f64 {
    use stamp::nonlinear::NonlinearSolver;
    use stamp_elements::Face;
    let section = steel_section(h);
    let (dm, dp) = (section.delta_minus, section.delta_plus);
    let plate = PlateElements::new(mesh, section, kin).unwrap();
    let mut dofs = stamp::dofs::DofMap::new(mesh.num_nodes(), 6).unwrap();
    for &n in boundary {
        for (face, z) in [(Face::Bottom, dm), (Face::Top, dp)] {
            let v = exact(mesh.coords[n], z);
            for c in 0..3 {
                dofs.prescribe(n, face.index() * 3 + c, v[c]).unwrap();
            }
        }
    }
    let mut model = stamp::model::Model::new(plate, dofs).unwrap();
    let mut newton = stamp::nonlinear::NewtonRaphson::new(stamp::linalg::linear_solver::SparseLu::new(), stamp::nonlinear::NewtonSettings::default());
    let mut u = vec![0.0; model.dofs.num_dofs()];
    newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap();
    let (mut err, mut scale) = (0.0f64, 0.0f64);
    for n in (0..mesh.num_nodes()).filter(|n| !boundary.contains(n)) {
        for (face, z) in [(Face::Bottom, dm), (Face::Top, dp)] {
            let v = exact(mesh.coords[n], z);
            for c in 0..3 {
                err = err.max((u[face.dof(n, c)] - v[c]).abs());
                scale = scale.max(v[c].abs());
            }
        }
    }
    err / scale
}

/// A sparse matrix as dense rows (duplicates summed).
pub fn dense(m: faer::sparse::SparseColMatRef<'_, usize, f64>) -> Vec<Vec<f64>> {
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

/// The tangent `k` of a model's last evaluation at `u` against central differences of its
/// residual (steps of 1e-7 along each equation): the worst entry of the difference over the
/// largest entry of `k`, and the number of columns skipped because `state` (the contact's active
/// set, a friction point's stick or slip) differs between the two sides: a point crossed a kink,
/// where the derivative does not exist.
pub fn model_fd_error<S: PartialEq>(model: &mut stamp::model::Model<PlateElements>, u: &[f64], k: &[Vec<f64>], state: impl Fn(&stamp::model::Model<PlateElements>) -> S) -> (f64, usize) {
    use stamp::nonlinear::NonlinearProblem;
    let scale = k.iter().flatten().fold(0.0f64, |m, x| m.max(x.abs()));
    let neq = model.num_equations();
    let step = 1e-7;
    let mut worst = 0.0f64;
    let mut skipped = 0;
    for j in 0..neq {
        let mut du = vec![0.0; neq];
        du[j] = step;
        let mut up = u.to_vec();
        model.add_increment(&mut up, &du);
        du[j] = -step;
        let mut um = u.to_vec();
        model.add_increment(&mut um, &du);
        model.evaluate(&up, 1.0, false).unwrap();
        let rp = model.residual().to_vec();
        let sp = state(model);
        model.evaluate(&um, 1.0, false).unwrap();
        if sp != state(model) {
            skipped += 1;
            continue;
        }
        let rm = model.residual();
        for i in 0..neq {
            let fd = (rp[i] - rm[i]) / (2.0 * step);
            worst = worst.max((fd - k[i][j]).abs() / scale);
        }
    }
    (worst, skipped)
}

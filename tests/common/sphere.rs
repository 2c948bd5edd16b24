//! A square plate pressed at its centre by a rigid sphere, built through the library API the way
//! the CLI builds it (problem/src/model/build.rs): a mesh, PlateElements, a DofMap with the supports, a
//! ContactPair of the top-face nodes with a Sphere, solved by NewtonRaphson + SparseLu along a load
//! path. Used by the verification tests (`tests/verify_*.rs`).
//!
//! The plate is [-a/2, a/2]^2 (full model) or its quarter [0, a/2]^2 with symmetry conditions on
//! x1 = 0 and x2 = 0; the node coordinates of the quarter are bit for bit those of the full model's
//! quarter, so the two discretise exactly the same problem.

use super::Lcg;
use stamp::contact::{ContactKinematics, ContactPair, ContactPoint};
use stamp::dofs::DofMap;
use stamp::linalg::linear_solver::SparseLu;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearSolver, StepReport};
use stamp_contact::Sphere;
use stamp_elements::{Face, Isotropic, Kinematics, PlateElements, Section};
use std::sync::Arc;

pub const YOUNG: f64 = 2.0e5;
pub const NU: f64 = 0.3;

/// What holds the plate's outer edges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Support {
    /// v3- = v3+ = 0 (the CLI's `simply_supported`): the "soft" simple support of a plate with
    /// face displacements; the rotation about the edge normal (beta_t) and the tangential membrane
    /// displacement are free.
    SimplySoft,
    /// v3- = v3+ = 0 and the tangential face displacements v_t- = v_t+ = 0: the "hard" simple
    /// support (beta_t = 0, the Kirchhoff condition w,t = 0 carried over to the rotations).
    SimplyHard,
    /// All six face displacements zero.
    Clamped,
}

#[derive(Debug, Clone)]
pub struct SphereProblem {
    /// Side of the square plate.
    pub a: f64,
    pub h: f64,
    /// Elements along the side of the quarter (the full model has 2n).
    pub n: usize,
    pub quarter: bool,
    pub support: Support,
    pub radius: f64,
    /// Initial gap between the sphere and the top face at the centre.
    pub gap: f64,
    /// Punch motion along -x3 at load factor 1.
    pub depth: f64,
    /// eps_reg; `None`: the CLI's automatic 100 E h / (l_e^2 (2R)^2).
    pub eps_reg: Option<f64>,
    pub kinematics: Kinematics,
    /// Interior nodes moved by up to this fraction of the element size (0: structured).
    pub distortion: f64,
    pub seed: u64,
}

impl SphereProblem {
    pub fn new(a: f64, h: f64, n: usize, support: Support) -> Self {
        SphereProblem {
            a,
            h,
            n,
            quarter: true,
            support,
            radius: a,
            gap: 0.0,
            depth: 0.1 * h,
            eps_reg: None,
            kinematics: Kinematics::Nonlinear,
            distortion: 0.0,
            seed: 1,
        }
    }

    /// Elements along one side of the meshed region.
    pub fn cells_per_side(&self) -> usize {
        if self.quarter { self.n } else { 2 * self.n }
    }

    /// Element size.
    pub fn element_size(&self) -> f64 {
        0.5 * self.a / self.n as f64
    }

    pub fn mesh(&self) -> QuadMesh {
        let m = self.cells_per_side();
        let half = 0.5 * self.a;
        let mut mesh = QuadMesh::rectangle(-half, half, -half, half, m, m).unwrap();
        let offset = if self.quarter { 0 } else { self.n };
        let n = self.n as f64;
        // coordinates (a/2) k / n, k = i - offset: the quarter's nodes bit for bit in the full mesh
        for j in 0..=m {
            for i in 0..=m {
                let x = half * (i as f64 - offset as f64) / n;
                let y = half * (j as f64 - offset as f64) / n;
                mesh.coords[j * (m + 1) + i] = [x, y];
            }
        }
        if self.distortion > 0.0 {
            let mut rng = Lcg(self.seed);
            let le = self.element_size();
            let amp = self.distortion * le;
            let lo = if self.quarter { 0.0 } else { -half };
            for k in 0..mesh.num_nodes() {
                let [x, y] = mesh.coords[k];
                let (dx, dy) = (rng.range(-amp, amp), rng.range(-amp, amp));
                let on = |v: f64, b: f64| (v - b).abs() < 1e-9 * half;
                let x_fixed = on(x, lo) || on(x, half) || on(x, 0.0);
                let y_fixed = on(y, lo) || on(y, half) || on(y, 0.0);
                // nodes on the edges and symmetry lines slide along them only; the centre stays
                mesh.coords[k] = [if x_fixed { x } else { x + dx }, if y_fixed { y } else { y + dy }];
            }
            mesh.validate().unwrap();
        }
        mesh
    }

    /// The node at the plate's centre.
    pub fn centre_node(&self) -> usize {
        let m = self.cells_per_side();
        if self.quarter { 0 } else { self.n * (m + 1) + self.n }
    }

    pub fn section(&self) -> Section {
        Section::homogeneous(self.h, Isotropic::new(YOUNG, NU).unwrap()).unwrap()
    }

    /// Bending stiffness D = E h^3 / (12 (1 - nu^2)).
    pub fn bending_stiffness(&self) -> f64 {
        YOUNG * self.h.powi(3) / (12.0 * (1.0 - NU * NU))
    }

    /// The CLI's automatic eps_reg.
    pub fn eps(&self) -> f64 {
        self.eps_reg.unwrap_or_else(|| 100.0 * YOUNG * self.h / (self.element_size().powi(2) * (2.0 * self.radius).powi(2)))
    }

    /// The supports and symmetry conditions.
    pub fn dofs(&self, mesh: &QuadMesh) -> DofMap {
        let mut dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
        let g = |name: &str| mesh.group_nodes(name).unwrap().to_vec();
        // edges held by the support, with the component tangential to each
        let edges: Vec<(Vec<usize>, [usize; 2])> = if self.quarter {
            vec![(g("right"), [1, 4]), (g("top"), [0, 3])]
        } else {
            vec![(g("left"), [1, 4]), (g("right"), [1, 4]), (g("bottom"), [0, 3]), (g("top"), [0, 3])]
        };
        for (nodes, tangential) in &edges {
            match self.support {
                Support::SimplySoft => dofs.fix(nodes, &[2, 5]).unwrap(),
                Support::SimplyHard => {
                    dofs.fix(nodes, &[2, 5]).unwrap();
                    dofs.fix(nodes, tangential).unwrap();
                }
                Support::Clamped => dofs.fix(nodes, &[0, 1, 2, 3, 4, 5]).unwrap(),
            }
        }
        if self.quarter {
            dofs.fix(&g("left"), &[0, 3]).unwrap(); // symmetry about x1 = 0
            dofs.fix(&g("bottom"), &[1, 4]).unwrap(); // symmetry about x2 = 0
        } else if self.support == Support::SimplySoft {
            // the soft support leaves the in-plane rigid motions free: hold the four edge midpoints
            // in the direction the symmetric solution does not move them anyway
            let near = |p: [f64; 2]| mesh.nodes_where(|x| (x[0] - p[0]).abs() < 1e-9 && (x[1] - p[1]).abs() < 1e-9);
            let h = 0.5 * self.a;
            for p in [[0.0, -h], [0.0, h]] {
                dofs.fix(&near(p), &[0, 3]).unwrap();
            }
            for p in [[-h, 0.0], [h, 0.0]] {
                dofs.fix(&near(p), &[1, 4]).unwrap();
            }
        }
        dofs
    }

    pub fn sphere(&self) -> Sphere {
        Sphere::new(nalgebra::Vector3::new(0.0, 0.0, 0.5 * self.h + self.gap + self.radius), self.radius).unwrap()
    }

    /// The contact pair: every node of the top face against the sphere.
    pub fn contact(&self, mesh: &QuadMesh) -> ContactPair {
        let dp = 0.5 * self.h;
        let areas = mesh.nodal_areas();
        let points = (0..mesh.num_nodes())
            .map(|n| ContactPoint { node: n, x_ref: [mesh.coords[n][0], mesh.coords[n][1], dp], dofs: [0, 1, 2].map(|c| Face::Top.dof(n, c)), weight: areas[n] })
            .collect();
        let ck = match self.kinematics {
            Kinematics::Nonlinear => ContactKinematics::Exact,
            Kinematics::Linear => ContactKinematics::Shallow { direction: [0.0, 0.0, 1.0] },
        };
        let mut pair = ContactPair::new("sphere", Arc::new(self.sphere()), points, self.eps(), ck);
        pair.motion = [0.0, 0.0, -self.depth].into();
        pair
    }

    pub fn build(&self) -> (QuadMesh, Model<PlateElements>) {
        let mesh = self.mesh();
        let plate = PlateElements::new(&mesh, self.section(), self.kinematics).unwrap();
        let mut model = Model::new(plate, self.dofs(&mesh)).unwrap();
        model.contacts.push(self.contact(&mesh));
        (mesh, model)
    }

    /// What one converged state gives, scaled to the full plate.
    pub fn measure(&self, mesh: &QuadMesh, model: &Model<PlateElements>, u: &[f64]) -> SphereResult {
        let c = self.centre_node();
        let pair = &model.contacts[0];
        let scale = if self.quarter { 4.0 } else { 1.0 };
        let mut radius = 0.0f64;
        let (mut fr, mut f) = (0.0, 0.0);
        for (p, s) in pair.points.iter().zip(&pair.state) {
            if s.lambda < 0.0 {
                let x = mesh.coords[p.node];
                let r = (x[0] * x[0] + x[1] * x[1]).sqrt();
                radius = radius.max(r);
                let fz = (p.weight * s.lambda * s.grad[2]).abs();
                fr += fz * r;
                f += fz;
            }
        }
        // the edge of contact on the symmetry axis x2 = 0, x1 >= 0: the zero of the gap Psi / |grad Psi|
        // (a signed distance), interpolated linearly between the outermost node in contact and the
        // next one out
        let mut axis: Vec<(f64, f64)> = pair
            .points
            .iter()
            .zip(&pair.state)
            .filter(|(p, _)| mesh.coords[p.node][1] == 0.0 && mesh.coords[p.node][0] >= 0.0)
            .map(|(p, s)| (mesh.coords[p.node][0], s.psi / nalgebra::Vector3::from(s.grad).norm()))
            .collect();
        axis.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut edge = 0.0;
        for k in (1..axis.len()).rev() {
            let ((x0, g0), (x1, g1)) = (axis[k - 1], axis[k]);
            if g0 <= 0.0 && g1 > 0.0 {
                edge = x0 + (x1 - x0) * (-g0) / (g1 - g0);
                break;
            }
        }
        SphereResult {
            edge,
            w: -0.5 * (u[Face::Bottom.dof(c, 2)] + u[Face::Top.dof(c, 2)]),
            w_top: -u[Face::Top.dof(c, 2)],
            reaction: -scale * pair.reaction()[2],
            radius,
            force_radius: if f > 0.0 { fr / f } else { 0.0 },
            active: pair.state.iter().filter(|s| s.lambda < 0.0).count(),
        }
    }

    pub fn settings(&self) -> NewtonSettings {
        NewtonSettings { max_increment: 0.25, line_search_steps: 4, ..NewtonSettings::default() }
    }

    /// Solve along `targets`; the result of every converged step.
    pub fn solve(&self, targets: &[f64]) -> Vec<(StepReport, SphereResult)> {
        let (mesh, mut model) = self.build();
        let mut newton = NewtonRaphson::new(SparseLu::new(), self.settings());
        let mut u = vec![0.0; model.dofs.num_dofs()];
        let mut out = Vec::new();
        newton
            .solve_path(&mut model, &mut u, 0.0, targets, &mut |r, u, m| out.push((r.clone(), self.measure(&mesh, m, u))))
            .unwrap_or_else(|e| panic!("{self:?}: {e}"));
        out
    }
}

/// Centre deflection (mid-surface, positive down), the punch's force on the whole plate (positive
/// down), the contact radius on the x1 axis (interpolated zero of the gap) and that of the
/// outermost node carrying load (reference distance from the centre), the
/// force-weighted mean radius of the contact force, the number of loaded nodes.
#[derive(Debug, Clone, Copy, Default)]
pub struct SphereResult {
    pub w: f64,
    /// Contact radius: where the gap changes sign on the axis x2 = 0 (interpolated).
    pub edge: f64,
    pub w_top: f64,
    pub reaction: f64,
    pub radius: f64,
    pub force_radius: f64,
    pub active: usize,
}

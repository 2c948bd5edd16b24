//! The paper's section-5 benchmark (SPEC section 5): an infinitely long plate (plane strain, v1 = 0)
//! of length 2l bent around a fixed rigid cylinder by equal end forces towards the punch. Half the
//! plate, 0 <= x2 <= l, 40 elements along x2, symmetry at x2 = 0. Table 1: R = 1000 mm, each end
//! carries P/2, linear and nonlinear; Table 2: R = 100 mm, each end carries P, nonlinear.

use serde::Serialize;
use stamp::contact::{ContactKinematics, ContactPair, ContactPoint};
use stamp::ldlt_gmres::LdltGmres;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearSolver};
use stamp::Result;
use stamp_contact::Cylinder;
use stamp_elements::{Face, Isotropic, Kinematics, PlateElements, Section};
use std::sync::Arc;
use std::time::Instant;

/// The data of the benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct StripProblem {
    /// Half length l (mm).
    pub half_length: f64,
    pub thickness: f64,
    pub young: f64,
    pub poisson: f64,
    /// Elements along x2 on the half plate.
    pub elements: usize,
    /// Width of the one element row across x1 (any value: plane strain).
    pub width: f64,
    pub radius: f64,
    /// Regularisation parameter for lambda as a force per unit area (the paper's eps_reg divided by
    /// the element length, because the paper sums nodal values without weights).
    pub eps_reg: f64,
    pub kinematics: Kinematics,
    /// Relative threshold on |lambda| that defines the loaded zone (SPEC section 6).
    pub loaded_threshold: f64,
}

impl StripProblem {
    /// The paper's plate around a cylinder of radius `radius`. eps_reg is the paper's R = 100 value
    /// (10, for unweighted nodal sums) as a density, 10 / 2.5 = 4, for both radii: with lambda a
    /// density v3 and the zones do not depend on eps_reg over 1..1e6 (SPEC section 6), and the
    /// paper's 1e5 for R = 1000 makes the contact stiffness 1e7 times the plate's, which puts the
    /// round-off floor of the residual above 1e-8.
    pub fn paper(radius: f64, kinematics: Kinematics) -> Self {
        let elements = 40;
        let half_length = 100.0;
        let paper_eps = 10.0;
        StripProblem {
            half_length,
            thickness: 2.0,
            young: 2.0e4,
            poisson: 0.3,
            elements,
            width: 1.0,
            radius,
            eps_reg: paper_eps / (half_length / elements as f64),
            kinematics,
            loaded_threshold: 0.005,
        }
    }
}

/// The result at one load.
#[derive(Debug, Clone, Serialize)]
pub struct StripResult {
    /// Force on each end, per unit length along x1.
    pub load_per_end: f64,
    /// Loaded zone [b_int, b_ext] (reference x2 of the nodes with |lambda| > threshold * max).
    pub b_int: f64,
    pub b_ext: f64,
    /// Geometric active set (x2 of the nodes with Psi <= 0 in the active set).
    pub active_x2: Vec<f64>,
    /// Mid-surface vertical displacement of the end section, (v3- + v3+)/2 at x2 = l.
    pub v3: f64,
    /// Vertical contact reaction on the half plate per unit length (equals the end force).
    pub reaction: f64,
    pub newton_iterations: usize,
    pub steps: usize,
    pub max_penetration: f64,
    /// x2 of every node along the strip, and the contact pressure q_n (per unit area) there.
    pub x2: Vec<f64>,
    pub pressure: Vec<f64>,
    /// Deformed position (x2 + v2+, x3 + v3+) of the contact face along the strip.
    pub deformed: Vec<[f64; 2]>,
}

/// Solve the strip for the given end forces (per end, increasing), continuing from one load to the
/// next. Returns one result per load.
pub fn solve_strip(p: &StripProblem, loads_per_end: &[f64]) -> Result<Vec<StripResult>> {
    let l = p.half_length;
    let mesh = QuadMesh::rectangle(0.0, p.width, 0.0, l, 1, p.elements)?;
    let material = Isotropic::new(p.young, p.poisson)?;
    let section = Section::homogeneous(p.thickness, material)?;
    let delta_plus = section.delta_plus;
    let plate = PlateElements::new(&mesh, section, p.kinematics)?;
    let mut dofs = stamp::dofs::DofMap::new(mesh.num_nodes(), 6)?;
    let all: Vec<usize> = (0..mesh.num_nodes()).collect();
    dofs.fix(&all, &[0, 3])?; // plane strain: v1- = v1+ = 0
    dofs.fix(mesh.group_nodes("bottom")?, &[1, 4])?; // symmetry at x2 = 0
    let mut model = Model::new(plate, dofs)?;
    let p_max = loads_per_end.iter().cloned().fold(0.0, f64::max);
    let end = mesh.group_nodes("top")?.to_vec();
    let areas = mesh.nodal_areas();
    for &n in &end {
        // end force at the mid-surface point: half to each face, the node's share of the width
        let share = p_max * p.width / end.len() as f64;
        model.add_load(Face::Bottom.dof(n, 2), 0.5 * share)?;
        model.add_load(Face::Top.dof(n, 2), 0.5 * share)?;
    }
    let cylinder = Cylinder::along_x1_touching(0.0, delta_plus, p.radius)?;
    let points: Vec<ContactPoint> = (0..mesh.num_nodes())
        .map(|n| {
            let x = mesh.coords[n];
            ContactPoint { node: n, x_ref: [x[0], x[1], delta_plus], dofs: [0, 1, 2].map(|c| Face::Top.dof(n, c)), weight: areas[n] }
        })
        .collect();
    let kin = match p.kinematics {
        Kinematics::Nonlinear => ContactKinematics::Exact,
        Kinematics::Linear => ContactKinematics::Shallow { direction: [0.0, 0.0, 1.0] },
    };
    model.contacts.push(ContactPair::new("cylinder", Arc::new(cylinder), points, p.eps_reg, kin));

    let targets: Vec<f64> = loads_per_end.iter().map(|x| x / p_max).collect();
    let mut settings = NewtonSettings::default();
    settings.initial_increment = 1.0;
    settings.max_increment = 0.25;
    // measured: predicting by extrapolation costs more on the lift-off path of Table 1 (1727
    // Newton iterations against 1330) and moves Table 1 linear P = 0.5 off the paper's zone
    settings.extrapolate = false;
    let mut newton = NewtonRaphson::new(LdltGmres::new(), settings);
    let mut u = vec![0.0; model.dofs.num_dofs()];
    let mut results = Vec::new();
    let mut iters = 0;
    let mut steps = 0;
    let column: Vec<usize> = mesh.nodes_where(|x| x[0] == 0.0);
    newton.solve_path(&mut model, &mut u, 0.0, &targets, &mut |rep, u, m| {
        iters += rep.iterations;
        steps += 1;
        if !rep.is_target {
            return;
        }
        let pair = &m.contacts[0];
        let lam_max = pair.state.iter().map(|s| s.lambda.abs()).fold(0.0, f64::max);
        let loaded: Vec<f64> = pair
            .points
            .iter()
            .zip(&pair.state)
            .filter(|(_, s)| lam_max > 0.0 && s.lambda.abs() > p.loaded_threshold * lam_max)
            .map(|(pt, _)| pt.x_ref[1])
            .collect();
        let mut active_x2: Vec<f64> = pair.points.iter().zip(&pair.state).filter(|(_, s)| s.active && s.psi <= 0.0).map(|(pt, _)| pt.x_ref[1]).collect();
        active_x2.sort_by(|a, b| a.partial_cmp(b).unwrap());
        active_x2.dedup();
        let v3 = end.iter().map(|&n| 0.5 * (u[Face::Bottom.dof(n, 2)] + u[Face::Top.dof(n, 2)])).sum::<f64>() / end.len() as f64;
        let pressures = pair.pressures();
        let pressure = column.iter().map(|&n| pressures[n]).collect();
        let deformed = column
            .iter()
            .map(|&n| [mesh.coords[n][1] + u[Face::Top.dof(n, 1)], delta_plus + u[Face::Top.dof(n, 2)]])
            .collect();
        results.push(StripResult {
            load_per_end: targets[rep.target_index.unwrap()] * p_max,
            b_int: loaded.iter().cloned().fold(f64::INFINITY, f64::min).min(if loaded.is_empty() { 0.0 } else { f64::INFINITY }),
            b_ext: loaded.iter().cloned().fold(0.0, f64::max),
            active_x2,
            v3,
            reaction: pair.reaction()[2].abs() / p.width,
            newton_iterations: iters,
            steps,
            max_penetration: pair.max_penetration(),
            x2: column.iter().map(|&n| mesh.coords[n][1]).collect(),
            pressure,
            deformed,
        });
        iters = 0;
        steps = 0;
    })?;
    Ok(results)
}

/// One row of the paper's Table 1 or 2 with our value beside it.
#[derive(Debug, Clone, Serialize)]
pub struct Compared {
    pub paper: f64,
    pub ours: f64,
    pub rel_diff: f64,
}

fn cmp(paper: f64, ours: f64) -> Compared {
    Compared { paper, ours, rel_diff: if paper != 0.0 { (ours - paper) / paper } else { ours - paper } }
}

/// Table 1 and 2 of the paper (SPEC section 5).
pub const TABLE1: [(f64, [f64; 3], [f64; 3]); 6] = [
    (0.1, [0.0, 0.0, 1.138], [0.0, 0.0, 1.138]),
    (0.3, [0.0, 2.5, 3.410], [0.0, 2.5, 3.407]),
    (0.5, [40.0, 42.5, 4.427], [40.0, 42.5, 4.419]),
    (1.0, [70.0, 72.5, 4.857], [70.0, 72.5, 4.846]),
    (2.0, [85.0, 87.5, 4.965], [85.0, 87.5, 4.952]),
    (3.0, [90.0, 92.5, 4.985], [90.0, 92.5, 4.971]),
];
pub const TABLE2: [(f64, [f64; 3]); 5] = [
    (1.25, [0.0, 2.5, 26.39]),
    (2.5, [0.0, 37.5, 39.62]),
    (5.0, [0.0, 65.0, 43.85]),
    (10.0, [0.0, 82.5, 45.11]),
    (20.0, [0.0, 92.5, 45.50]),
];

#[derive(Debug, Clone, Serialize)]
pub struct ZoneRow {
    pub b_int: f64,
    pub b_ext: f64,
    pub v3: f64,
    pub paper: [f64; 3],
    pub v3_rel_diff: f64,
    pub active_set: Vec<f64>,
    pub newton_iterations: usize,
}

#[derive(Debug, Clone, Serialize)]
pub struct Table1Row {
    #[serde(rename = "P")]
    pub p: f64,
    pub linear: ZoneRow,
    pub nonlinear: ZoneRow,
}

#[derive(Debug, Clone, Serialize)]
pub struct Table2Row {
    #[serde(rename = "P")]
    pub p: f64,
    pub b_int: f64,
    pub b_ext: f64,
    pub v3: f64,
    pub reaction: f64,
    pub load_per_end: f64,
    pub paper: [f64; 3],
    pub v3_rel_diff: f64,
    pub active_set: Vec<f64>,
    pub newton_iterations: usize,
    pub max_penetration: f64,
}

/// The whole benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct PaperReport {
    pub table1: Vec<Table1Row>,
    pub table2: Vec<Table2Row>,
    pub seconds: f64,
    /// The reaction check at P = 20 (Table 2): contact reaction and end force.
    pub reaction_check: Compared,
}

fn zone_row(r: &StripResult, paper: [f64; 3]) -> ZoneRow {
    ZoneRow {
        b_int: r.b_int,
        b_ext: r.b_ext,
        v3: r.v3,
        paper,
        v3_rel_diff: cmp(paper[2], r.v3).rel_diff,
        active_set: r.active_x2.clone(),
        newton_iterations: r.newton_iterations,
    }
}

/// Run Table 1 (linear and nonlinear, R = 1000, P/2 per end) and Table 2 (R = 100, P per end).
pub fn run_paper() -> Result<PaperReport> {
    let start = Instant::now();
    let t1_loads: Vec<f64> = TABLE1.iter().map(|r| 0.5 * r.0).collect();
    let t2_loads: Vec<f64> = TABLE2.iter().map(|r| r.0).collect();
    // the three load paths are independent: solve them side by side (each is too small to use
    // more than one thread by itself)
    let (nl, (lin, t2)) = rayon::join(
        || solve_strip(&StripProblem::paper(1000.0, Kinematics::Nonlinear), &t1_loads),
        || {
            rayon::join(
                || solve_strip(&StripProblem::paper(1000.0, Kinematics::Linear), &t1_loads),
                || solve_strip(&StripProblem::paper(100.0, Kinematics::Nonlinear), &t2_loads),
            )
        },
    );
    let (lin, nl, t2) = (lin?, nl?, t2?);
    let table1 = TABLE1
        .iter()
        .zip(lin.iter().zip(&nl))
        .map(|(row, (a, b))| Table1Row { p: row.0, linear: zone_row(a, row.1), nonlinear: zone_row(b, row.2) })
        .collect();
    let table2: Vec<Table2Row> = TABLE2
        .iter()
        .zip(&t2)
        .map(|(row, r)| Table2Row {
            p: row.0,
            b_int: r.b_int,
            b_ext: r.b_ext,
            v3: r.v3,
            reaction: r.reaction,
            load_per_end: r.load_per_end,
            paper: row.1,
            v3_rel_diff: cmp(row.1[2], r.v3).rel_diff,
            active_set: r.active_x2.clone(),
            newton_iterations: r.newton_iterations,
            max_penetration: r.max_penetration,
        })
        .collect();
    let last = t2.last().expect("five loads");
    Ok(PaperReport {
        table1,
        reaction_check: cmp(last.load_per_end, last.reaction),
        table2,
        seconds: start.elapsed().as_secs_f64(),
    })
}

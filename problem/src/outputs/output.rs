//! What `stamp run` writes for every converged load step: the point and cell fields of the .vtu,
//! the summary.json entry and the contact-pressure CSV, all computed from the displacement vector
//! and the model's contact state.
//!
//! Point data: `displacement` = mid-surface (v- + v+)/2, `displacement_bottom` = v-,
//! `displacement_top` = v+ (3-vectors); `lambda` (the multiplier, <= 0 in contact, force per unit
//! reference area), `contact_pressure` q_n = -lambda |grad Psi| >= 0, `contact_pressure_recovered`
//! (a continuous field made from the nodal forces, [`stamp::contact::recovered_pressure`] with
//! [`stamp::contact::RECOVERY`]), `gap` = Psi / |grad Psi| of the
//! face each punch touches (the smallest over the punches; written only when there are punches),
//! `active` (1 in the active set), `loaded` (1 where |lambda| > loaded_threshold * max |lambda| of
//! that punch). A node that is a candidate of several punches gets the sum of their lambda, q_n and
//! recovered pressure.
//!
//! Cell data (element centre = mean over the 2 x 2 Gauss points of the element's assumed resultants;
//! for the nonlinear plate these are second Piola-Kirchhoff resultants per unit reference length):
//! with T+- = int S N+- dx3, N+- the linear through-thickness shape functions,
//! * membrane forces `N11`, `N22`, `N12` = T- + T+ (since N- + N+ = 1, this is int S dx3);
//! * bending moments `M11`, `M22`, `M12` = int S (x3 - x_m) dx3 about the mid-surface
//!   x_m = (delta- + delta+)/2: N+ - N- = (2 x3 - delta- - delta+)/h = 2 (x3 - x_m)/h, so
//!   M = (h/2)(T+ - T-) for any section (positive when the top fibre is in tension);
//! * transverse shear forces `Q1` = T13- + T13+, `Q2` = T23- + T23+;
//! * the transverse normal force `T33` = int S33 dx3.

use crate::model::build::PunchInfo;
use crate::model::mesh::MeshData;
use crate::model::plate_model::{Layout, Plate};
use nalgebra::Vector3;
use stamp::surface::ContactSurface;
use serde::Serialize;
use stamp::element::Element;
use stamp::io::Field;
use stamp::model::Model;
use stamp_elements::{Face, Section};
use std::collections::BTreeMap;

/// Names of the point arrays of every .vtu (gap only with punches).
pub const POINT_ARRAYS: [&str; 9] = ["displacement", "displacement_bottom", "displacement_top", "lambda", "contact_pressure", "contact_pressure_recovered", "gap", "active", "loaded"];
/// Names of the cell arrays of every .vtu.
pub const CELL_ARRAYS: [&str; 9] = ["N11", "N22", "N12", "M11", "M22", "M12", "Q1", "Q2", "T33"];

/// Bounding box of reference coordinates (x1, x2, x3 of the touched face).
#[derive(Debug, Clone, Serialize)]
pub struct BBox {
    pub min: [f64; 3],
    pub max: [f64; 3],
}

impl BBox {
    fn of(points: &[[f64; 3]]) -> Option<BBox> {
        let first = points.first()?;
        let mut b = BBox { min: *first, max: *first };
        for p in points {
            for i in 0..3 {
                b.min[i] = b.min[i].min(p[i]);
                b.max[i] = b.max[i].max(p[i]);
            }
        }
        Some(b)
    }
}

#[derive(Debug, Clone, Serialize)]
pub struct PointOut {
    /// Mid-surface displacement (v- + v+)/2, averaged over the group's nodes.
    pub displacement: [f64; 3],
    pub displacement_bottom: [f64; 3],
    pub displacement_top: [f64; 3],
}

#[derive(Debug, Clone, Serialize)]
pub struct PunchOut {
    /// Total force of this punch on the plate.
    pub reaction: [f64; 3],
    /// The punch's rigid displacement (t * motion, plus s * direction when force driven).
    pub displacement: [f64; 3],
    /// Force-driven punch: its displacement s along `direction` (the unknown); null otherwise.
    pub drive_displacement: Option<f64>,
    /// Force-driven punch: the applied force t * force along `direction`; null otherwise.
    pub applied_force: Option<f64>,
    pub active_nodes: usize,
    pub loaded_nodes: usize,
    pub loaded_zone: Option<BBox>,
    pub max_penetration: f64,
    pub max_pressure: f64,
    pub eps_reg: f64,
    /// The loaded zone is narrower than the cells: at least three nodes are loaded and none of
    /// them has all its cells' nodes loaded (a line or a ring of nodes): the peak pressure then
    /// depends on the mesh (see [`narrower_than_cells`]).
    pub zone_narrower_than_cells: bool,
    /// With friction: the candidate points sticking and slipping (absent without friction).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sticking_nodes: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub slipping_nodes: Option<usize>,
}

/// Whether the loaded nodes (`loaded[node]`) form a zone narrower than the cells: at least three
/// of them and none whose cells' nodes are all loaded. Such a zone (a cylinder across a plate, the
/// rim of a conforming contact) is a line load at the scale of the mesh: its nodal pressures take
/// the load in turn and their peak does not converge as the cells shrink, while the force and the
/// load per unit length (`<punch>_line_load` of a probe across it) do.
pub fn narrower_than_cells(cells: &[[usize; 4]], loaded: &[bool]) -> bool {
    let count = loaded.iter().filter(|l| **l).count();
    if count < 3 {
        return false;
    }
    let mut open = vec![false; loaded.len()];
    for c in cells {
        if !c.iter().all(|&n| loaded[n]) {
            for &n in c {
                open[n] = true;
            }
        }
    }
    !loaded.iter().zip(&open).any(|(l, o)| *l && !*o)
}

/// One converged step of summary.json.
#[derive(Debug, Clone, Serialize)]
pub struct StepEntry {
    pub step: usize,
    pub load_factor: f64,
    /// Cumulative path length sum |delta t| from the start: the time of the step in the .pvd
    /// (increases even when the load goes down again).
    pub path: f64,
    pub is_target: bool,
    pub converged: bool,
    /// Of the attempt that converged (augmented-Lagrangian rounds included).
    pub newton_iterations: usize,
    pub cutbacks: usize,
    /// Newton iterations of the attempts cut back before it.
    pub failed_iterations: usize,
    pub residual_history: Vec<f64>,
    /// Nodes in the active set of any punch.
    pub active_nodes: usize,
    pub loaded_nodes: usize,
    /// Reference coordinates of the loaded nodes (null when no node carries load).
    pub loaded_zone: Option<BBox>,
    /// Total contact force on the plate (all punches).
    pub reaction: [f64; 3],
    /// Total force of the supports (the prescribed dofs) on the plate.
    pub support_reaction: [f64; 3],
    /// Per `[[boundary]]` group, the force of its supports on the plate (a dof held by two groups
    /// counted in each: see [`crate::outputs::supports`]).
    pub support_reactions: BTreeMap<String, [f64; 3]>,
    /// Total applied load (nodal loads times the load factor, and the follower loads in the
    /// deformed state). In equilibrium
    /// applied_load + reaction + support_reaction = 0.
    pub applied_load: [f64; 3],
    pub max_penetration: f64,
    pub points: BTreeMap<String, PointOut>,
    pub punches: BTreeMap<String, PunchOut>,
    /// The .vtu of this step (relative to the output folder), if written.
    pub vtu: Option<String>,
    pub csv: Vec<String>,
    /// An elastic-plastic plate: the largest equivalent plastic strain at its surfaces and its
    /// least thickness (crate::outputs::plastic).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub max_plastic_strain: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_thickness: Option<f64>,
    /// Per thickness probe with recovered stresses: [s13, s23, s33] integrated from the bottom
    /// face to the top face minus the values the top face's traction gives them (the check of the
    /// recovery, outputs/recovered_stresses.rs); absent when no probe recovers.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub thickness_top_mismatch: BTreeMap<String, [f64; 3]>,
}

/// Everything computed for one step.
pub struct StepData {
    pub entry: StepEntry,
    pub point_fields: Vec<Field>,
    pub cell_fields: Vec<Field>,
    /// Per punch: CSV text and the rows (node, q_n).
    pub punch_rows: Vec<Vec<ContactRow>>,
}

/// One row of the contact CSV.
#[derive(Debug, Clone, Copy)]
pub struct ContactRow {
    pub node: usize,
    pub x: [f64; 2],
    pub deformed: [f64; 3],
    pub q_n: f64,
    pub lambda: f64,
    pub active: bool,
}

/// The names of the cell arrays of a run's .vtu: the resultants, and with layers or three to five
/// surfaces the stresses at every surface of every layer (see [`layer_stress_fields`]).
pub fn cell_array_names(plate: &Plate) -> Vec<String> {
    let mut v: Vec<String> = CELL_ARRAYS.iter().map(|s| s.to_string()).collect();
    if let Some((lam, per_layer, _)) = plate.stress_stack() {
        for k in 0..lam.plies.len() {
            for s in 0..per_layer {
                v.push(stress_field_name(k, s));
            }
        }
    }
    if plate.is_plastic() {
        let n = plate.surfaces();
        v.extend((0..n).map(|s| format!("plastic_strain_surface{s}")));
        v.extend((0..n).map(|s| format!("yielding_surface{s}")));
    }
    v
}

fn stress_field_name(layer: usize, surface: usize) -> String {
    format!("stress_layer{layer}_surface{surface}")
}

/// With layers, or three to five surfaces (one layer, k = 0): per layer k and surface s of it
/// (from its bottom up, its faces included: an interface in each of its two layers), `stress_layer<k>_surface<s>`, the six second
/// Piola-Kirchhoff stresses in the plate's axes at the element centre (the mean over its Gauss
/// points) by the layer's 3D law, as a symmetric tensor in VTK's order [s11, s22, s33, s12, s23, s13].
pub fn layer_stress_fields(model: &Model<Plate>, u: &[f64]) -> Vec<Field> {
    let plate = &model.element;
    let Some((lam, per_layer, _)) = plate.stress_stack() else {
        return Vec::new();
    };
    let b = lam.boundaries();
    let mut ws = plate.new_workspace();
    let ne = plate.num_elements();
    let dpn = plate.dofs_per_node();
    let nl = lam.plies.len();
    let mut out: Vec<Vec<f64>> = vec![Vec::with_capacity(6 * ne); nl * per_layer];
    let mut local = vec![0.0; 4 * dpn];
    for e in 0..ne {
        for (a, &n) in plate.element_nodes(e).iter().enumerate() {
            local[dpn * a..dpn * (a + 1)].copy_from_slice(&u[dpn * n..dpn * (n + 1)]);
        }
        for k in 0..nl {
            for s in 0..per_layer {
                let x3 = b[k] + (b[k + 1] - b[k]) * s as f64 / (per_layer - 1) as f64;
                let g = plate.layer_stresses(e, k, x3, &local, &mut ws).expect("a stack of the 3D law");
                let mean = |c: usize| 0.25 * g.iter().map(|p| p[c]).sum::<f64>();
                out[k * per_layer + s].extend([mean(0), mean(1), mean(2), mean(5), mean(3), mean(4)]);
            }
        }
    }
    out.into_iter().enumerate().map(|(i, v)| Field::new(stress_field_name(i / per_layer, i % per_layer), 6, v)).collect()
}

/// Stress resultants at the element centres.
pub fn cell_fields(model: &Model<Plate>, u: &[f64]) -> Vec<Field> {
    let plate = &model.element;
    let mut ws = plate.new_workspace();
    let ne = plate.num_elements();
    let dpn = plate.dofs_per_node();
    let mut out: Vec<Vec<f64>> = vec![Vec::with_capacity(ne); 9];
    let mut local = vec![0.0; 4 * dpn];
    for e in 0..ne {
        for (a, &n) in plate.element_nodes(e).iter().enumerate() {
            local[dpn * a..dpn * (a + 1)].copy_from_slice(&u[dpn * n..dpn * (n + 1)]);
        }
        let r = plate.centre_resultants(e, &local, &mut ws);
        let vals = [r.n[0], r.n[1], r.n[2], r.m[0], r.m[1], r.m[2], r.q[0], r.q[1], r.t33];
        for (k, v) in vals.iter().enumerate() {
            out[k].push(*v);
        }
    }
    let mut fields: Vec<Field> = CELL_ARRAYS.iter().zip(out).map(|(name, v)| Field::scalar(*name, v)).collect();
    fields.extend(layer_stress_fields(model, u));
    fields.extend(crate::outputs::plastic::plastic_cell_fields(plate, u));
    fields
}

/// Inputs of [`step_data`] that do not change from step to step.
pub struct Context<'a> {
    pub mesh: &'a MeshData,
    pub punches: &'a [PunchInfo],
    pub section: &'a Section,
    pub threshold: f64,
    /// Point groups reported in summary.json.
    pub point_groups: &'a [(String, Vec<usize>)],
    /// The `[[boundary]]` groups whose reactions summary.json reports.
    pub supports: &'a crate::outputs::supports::Supports,
}

/// Fields, summary entry and CSV rows of the state `u` at load factor `t`.
pub fn step_data(cx: &Context, model: &Model<Plate>, u: &[f64], t: f64, path: f64, report: &stamp::nonlinear::StepReport) -> StepData {
    let layout = Layout::of(&model.element);
    let face_disp = |u: &[f64], n: usize, face: Face| layout.face_displacement(u, n, face);
    let mid_disp = |u: &[f64], n: usize| layout.mid_displacement(u, n);
    let n = cx.mesh.mesh.num_nodes();
    let coords = &cx.mesh.mesh.coords;
    let mut lambda = vec![0.0; n];
    let mut pressure = vec![0.0; n];
    let mut recovered = vec![0.0; n];
    let mut active = vec![0.0; n];
    let mut loaded = vec![0.0; n];
    let mut gap = vec![f64::INFINITY; n];
    let mut reaction = [0.0; 3];
    let mut max_pen = 0.0f64;
    let mut punches = BTreeMap::new();
    let mut loaded_pts = Vec::new();
    let mut punch_rows = Vec::new();
    // the friction's arrays of the punches with friction
    let mut friction_fields = Vec::new();
    for (info, pair) in cx.punches.iter().zip(&model.contacts) {
        if let Some(f) = pair.friction_at_points() {
            let (mut traction, mut slip, mut state) = (vec![0.0; 3 * n], vec![0.0; n], vec![0.0; n]);
            for (k, pt) in pair.points.iter().enumerate() {
                traction[3 * pt.node..3 * pt.node + 3].copy_from_slice(&f.traction[k]);
                slip[pt.node] = f.slip[k];
                state[pt.node] = f64::from(f.status[k]);
            }
            friction_fields.push(Field::new(format!("{}_traction", info.name), 3, traction));
            friction_fields.push(Field::scalar(format!("{}_slip", info.name), slip));
            friction_fields.push(Field::scalar(format!("{}_state", info.name), state));
        }
        let q = pair.pressures();
        let p_rec = stamp::contact::recovered_pressure(pair, &cx.mesh.mesh.cells, stamp::contact::RECOVERY).pressure;
        for (pt, v) in pair.points.iter().zip(&p_rec) {
            recovered[pt.node] += v;
        }
        let lam_max = pair.state.iter().map(|s| s.lambda.abs()).fold(0.0, f64::max);
        let mut candidate = vec![false; n];
        let mut p_loaded = Vec::new();
        let mut rows = Vec::with_capacity(pair.points.len());
        let mut n_active = 0;
        let mut loaded_here = vec![false; n];
        for (k, (pt, st)) in pair.points.iter().zip(&pair.state).enumerate() {
            let node = pt.node;
            candidate[node] = true;
            lambda[node] += st.lambda;
            pressure[node] += q[k];
            let g = Vector3::from(st.grad).norm();
            if g > 0.0 {
                gap[node] = gap[node].min(st.psi / g);
            }
            if st.active {
                active[node] = 1.0;
                n_active += 1;
            }
            if lam_max > 0.0 && st.lambda.abs() > cx.threshold * lam_max {
                loaded[node] = 1.0;
                loaded_here[node] = true;
                p_loaded.push(pt.x_ref);
            }
            let d = face_disp(u, node, info.face);
            rows.push(ContactRow {
                node,
                x: coords[node],
                deformed: [pt.x_ref[0] + d[0], pt.x_ref[1] + d[1], pt.x_ref[2] + d[2]],
                q_n: q[k],
                lambda: st.lambda,
                active: st.active,
            });
        }
        // gap of the nodes that are not candidates: the exact gap of the touched face
        let shift = Vector3::from(pair.punch_displacement(u, t));
        let surface = pair.surface_at(t);
        for node in 0..n {
            if candidate[node] {
                continue;
            }
            let d = face_disp(u, node, info.face);
            let x = Vector3::new(coords[node][0] + d[0], coords[node][1] + d[1], info.z + d[2]) - shift;
            let g = surface.gradient(&x).norm();
            if g > 0.0 {
                gap[node] = gap[node].min(surface.psi(&x) / g);
            }
        }
        let r = pair.reaction();
        for i in 0..3 {
            reaction[i] += r[i];
        }
        let pen = pair.max_penetration();
        max_pen = max_pen.max(pen);
        punches.insert(
            info.name.clone(),
            PunchOut {
                reaction: r,
                displacement: pair.punch_displacement(u, t),
                drive_displacement: pair.drive_displacement(u),
                applied_force: pair.drive.map(|f| t * f.force),
                active_nodes: n_active,
                loaded_nodes: p_loaded.len(),
                loaded_zone: BBox::of(&p_loaded),
                max_penetration: pen,
                max_pressure: q.iter().cloned().fold(0.0, f64::max),
                eps_reg: pair.eps_reg,
                zone_narrower_than_cells: narrower_than_cells(&cx.mesh.mesh.cells, &loaded_here),
                sticking_nodes: pair.stick_slip_counts().map(|c| c.0),
                slipping_nodes: pair.stick_slip_counts().map(|c| c.1),
            },
        );
        loaded_pts.extend(p_loaded);
        punch_rows.push(rows);
    }
    let mut point_fields = vec![
        Field::new("displacement", 3, (0..n).flat_map(|k| mid_disp(u, k)).collect()),
        Field::new("displacement_bottom", 3, (0..n).flat_map(|k| face_disp(u, k, Face::Bottom)).collect()),
        Field::new("displacement_top", 3, (0..n).flat_map(|k| face_disp(u, k, Face::Top)).collect()),
        Field::scalar("lambda", lambda),
        Field::scalar("contact_pressure", pressure),
        Field::scalar("contact_pressure_recovered", recovered),
    ];
    if !cx.punches.is_empty() {
        let big = gap.iter().cloned().filter(|g| g.is_finite()).fold(0.0, f64::max);
        point_fields.push(Field::scalar("gap", gap.iter().map(|&g| if g.is_finite() { g } else { big }).collect()));
    }
    point_fields.push(Field::scalar("active", active.clone()));
    point_fields.push(Field::scalar("loaded", loaded.clone()));
    point_fields.extend(friction_fields);
    point_fields.extend(crate::outputs::plastic::plastic_point_fields(&model.element, u, cx.mesh.mesh.num_nodes()));
    let points = cx
        .point_groups
        .iter()
        .map(|(name, nodes)| {
            let avg = |f: &dyn Fn(usize) -> [f64; 3]| {
                let mut s = [0.0; 3];
                for &k in nodes {
                    let v = f(k);
                    for i in 0..3 {
                        s[i] += v[i] / nodes.len() as f64;
                    }
                }
                s
            };
            (
                name.clone(),
                PointOut {
                    displacement: avg(&|k| mid_disp(u, k)),
                    displacement_bottom: avg(&|k| face_disp(u, k, Face::Bottom)),
                    displacement_top: avg(&|k| face_disp(u, k, Face::Top)),
                },
            )
        })
        .collect();
    // supports: at a prescribed dof the force of the support on the plate is the internal plus
    // contact force there minus the applied load there
    let mut support = [0.0; 3];
    let mut applied = [0.0; 3];
    let dpn = model.dofs.dofs_per_node();
    for (d, f) in model.nodal_forces().iter().enumerate() {
        if model.dofs.equation(d).is_none() {
            support[(d % dpn) % 3] += f;
        }
    }
    for (d, f) in model.dead_loads(t) {
        applied[(d % dpn) % 3] += f;
        if model.dofs.equation(d).is_none() {
            support[(d % dpn) % 3] -= f;
        }
    }
    // follower loads (pressures, couples): their force at the last evaluation, already times t
    for (d, &f) in model.follower_forces().iter().enumerate() {
        applied[(d % dpn) % 3] += f;
        if model.dofs.equation(d).is_none() {
            support[(d % dpn) % 3] -= f;
        }
    }
    let entry = StepEntry {
        step: report.step,
        load_factor: t,
        path,
        is_target: report.is_target,
        converged: true,
        newton_iterations: report.iterations,
        cutbacks: report.cutbacks,
        failed_iterations: report.failed_iterations,
        residual_history: report.residual_history.clone(),
        active_nodes: active.iter().filter(|&&a| a > 0.0).count(),
        loaded_nodes: loaded.iter().filter(|&&a| a > 0.0).count(),
        loaded_zone: BBox::of(&loaded_pts),
        reaction,
        support_reaction: support,
        support_reactions: cx.supports.names().into_iter().zip(cx.supports.reactions(model, t)).collect(),
        applied_load: applied,
        max_penetration: max_pen,
        points,
        punches,
        vtu: None,
        csv: Vec::new(),
        // the run's history row has them (computed once per step, crate::outputs::plastic)
        max_plastic_strain: None,
        min_thickness: None,
        thickness_top_mismatch: BTreeMap::new(),
    };
    StepData { entry, point_fields, cell_fields: cell_fields(model, u), punch_rows }
}

/// The contact CSV of one punch: one row per candidate node, in the order given.
pub fn contact_csv(rows: &[ContactRow]) -> String {
    let mut s = String::from("node,x1,x2,x1_deformed,x2_deformed,x3_deformed,q_n,lambda,active\n");
    for r in rows {
        s.push_str(&format!(
            "{},{:e},{:e},{:e},{:e},{:e},{:e},{:e},{}\n",
            r.node, r.x[0], r.x[1], r.deformed[0], r.deformed[1], r.deformed[2], r.q_n, r.lambda, r.active as u8
        ));
    }
    s
}

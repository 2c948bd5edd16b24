//! From a parsed problem to a [`Model`]: section, plate elements, constraints, loads and punches.
//! [`build_on`] calls a builder per table of the problem file, in turn: `build_plate` (`[plate]`
//! and `[[material]]`), `build_boundary` (`[[boundary]]`), `build_loads` (`[[load]]`),
//! `build_punches` (`[[punch]]`) and `build_solver` (`[solver]`).
//!
//! Conventions:
//! * Constraints: `fix` holds components at zero, `prescribe` sets them to value * load factor; the
//!   shorthand `simply_supported` holds v3- and v3+ (the whole normal fibre is held vertically,
//!   rotations are free; in-plane motions must be restrained by other conditions), `clamped` all
//!   six, `symmetry_x1` v1- and v1+ (a symmetry plane with normal x1), `symmetry_x2` v2- and v2+.
//!   `plate.plane_strain = true` holds v1- = v1+ = 0 at every node.
//! * Loads are dead loads (fixed direction, reference geometry), scaled by the load factor, except
//!   `follower = true` ones (see `stamp_elements::follower`): a follower pressure acts normal to
//!   the deformed face on its deformed area; a `moment` (couple per unit length m along a curve
//!   group, node shares as for `line`) is a force pair on each node's two face points,
//!   f+ = (M x d) / |d|^2, f- = -f+, d the current fibre (follower) or the reference one h e3
//!   (fixed, dead forces).
//!   `line`: force per unit length along a curve group, each segment of length L gives F L / 2 to
//!   each end node; `surface`: force per unit area, `pressure`: p > 0 pushes on the face towards the
//!   plate (-x3 on the top face, +x3 on the bottom face), both with the consistent nodal weights
//!   int N_a dA over the group's cells (exact for a constant load on bilinear elements); `point`: the
//!   force at every node of the group. `face = "mid"` (default) puts half on each face.
//! * Punches: the candidate points are the nodes of `group` (default: all) on the touched face
//!   (x3 = delta+ for `top`, delta- for `bottom`), weighted by their tributary area over the group's
//!   cells when the group is a surface, over the whole mesh otherwise.
//! * Automatic eps_reg: [`stamp::contact::automatic_eps_reg`] with the membrane stiffness E h, l_e
//!   the square root of the mean cell area and |grad Psi| at the candidate point closest to the punch
//!   ([`ContactPair::contact_gradient_norm`]: 2R for a touching cylinder or sphere, 1 for a plane),
//!   so eps_reg = 100 E h / (l_e^2 |grad Psi|^2). The penetration is then about q_n l_e^2 / (100 E h);
//!   `penetration_tolerance` adds augmented-Lagrangian updates until it is below the tolerance.
//! * A punch is displacement driven (`motion`, times the load factor) or force driven (`force`
//!   times the load factor along `direction`, default towards the plate): its displacement along
//!   `direction` is then an unknown, reported per step in summary.json. It may start off the plate:
//!   while nothing touches, the closest point pulls it down (see `ContactPair::evaluate`).

use crate::checks::rigid_modes::num;
use crate::model::mesh::{group_error, MeshData};
use crate::model::plate_model::{Layout, Plate};
use crate::outputs::supports::Supports;
use crate::schema::{ContactKinematicsSpec, ContactSpec, KinematicsSpec, LoadFace, LoadKind, Predictor, Problem, PunchFace, Shape, DEFAULT_MAX_INCREMENT};
use nalgebra::Vector3;
use stamp::contact::{automatic_eps_reg, ContactFace, ContactKinematics, ContactPair, ContactPoint, ForceDrive, PunchRotation};
use stamp::dofs::DofMap;
use stamp::model::Model;
use stamp::nonlinear::NewtonSettings;
use stamp::surface::ContactSurface;
use stamp::{Result, StampError};
use stamp_contact::{Cylinder, Expression, Plane, Sphere, StlSurface};
use stamp_elements::{fixed_couple_force, Face, FollowerCouple, FollowerPressure, Isotropic, Kinematics, NormalStress, Section};
use std::sync::Arc;

/// Factor c of the automatic eps_reg (see the module notes).
pub use stamp::contact::AUTO_EPS_FACTOR;

/// What the output needs to know about a punch.
pub struct PunchInfo {
    pub name: String,
    pub face: Face,
    /// Reference x3 of the touched face.
    pub z: f64,
    pub surface: Arc<dyn ContactSurface>,
    pub eps_reg: f64,
    pub eps_automatic: bool,
}

/// A model ready to solve and what the outputs need.
pub struct Setup {
    pub mesh: MeshData,
    pub model: Model<Plate>,
    pub section: Section,
    pub punches: Vec<PunchInfo>,
    pub targets: Vec<f64>,
    pub settings: NewtonSettings,
    /// The plate's stiffness as a force, E h L ([`stiffness_force`]): the scale of Newton's
    /// absolute tolerance and of the smallest force the solve can resolve.
    pub stiffness: f64,
    /// `[solver] predictor = "coarse"`: the same problem on the coarse mesh (solved first, see
    /// crate::model::coarse); None otherwise, and on the meshes of `--refine`.
    pub coarse: Option<Box<CoarseSetup>>,
    /// The `[[boundary]]` groups and the dofs each holds: their reactions are written per step.
    pub supports: Supports,
}

/// The problem on the coarse mesh of `predictor = "coarse"` and the map of its nodal fields
/// onto the problem's mesh.
pub struct CoarseSetup {
    pub setup: Setup,
    pub prolongation: stamp::mesh::transfer::Prolongation,
}

fn face_of(f: PunchFace) -> Face {
    match f {
        PunchFace::Top => Face::Top,
        PunchFace::Bottom => Face::Bottom,
    }
}

/// Put a nodal force on a face, or on the mid-plane (half on each face of the paper's plate, on
/// each surface its weight in the mid-plane's displacement in the others).
/// `path`: the load's path (an index of [`Model::add_load_path`]), None: the load factor.
fn add_force(model: &mut Model<Plate>, layout: &Layout, node: usize, f: [f64; 3], face: LoadFace, path: Option<usize>) -> Result<()> {
    let mut add = |d: usize, v: f64| match path {
        None => model.add_load(d, v),
        Some(k) => model.add_load_along(d, v, k),
    };
    for c in 0..3 {
        if f[c] == 0.0 {
            continue;
        }
        match face {
            LoadFace::Mid => {
                // a force at the mid-plane: on each surface its weight in the mid-plane's displacement
                for (d, w) in layout.mid_terms(node, c) {
                    add(d, w * f[c])?;
                }
            }
            LoadFace::Top => add(layout.face_dof(Face::Top, node, c), f[c])?,
            LoadFace::Bottom => add(layout.face_dof(Face::Bottom, node, c), f[c])?,
        }
    }
    Ok(())
}

/// A mesh error of the plate elements or the model ("element 3 is inverted ...", "node 7 ...",
/// 0-based indices) restated with the file and the user's numbers: the gmsh element or node tag,
/// or the 1-based cell / node of the built-in rectangle.
pub fn mesh_error(p: &Problem, mesh: &MeshData, e: StampError) -> StampError {
    let StampError::Mesh(msg) = &e else { return e };
    let spec = p.spec.mesh.get_ref();
    let (kind, rest) = match msg.split_once(' ') {
        Some((k @ ("element" | "node"), rest)) => (k, rest),
        _ => ("", msg.as_str()),
    };
    let (index, tail) = match rest.split_once(' ') {
        Some((i, tail)) if !kind.is_empty() => (i.parse::<usize>().ok(), tail),
        _ => (None, rest),
    };
    let tags = if kind == "element" { mesh.cell_tags.as_ref() } else { mesh.node_tags.as_ref() };
    match (&spec.file, index) {
        (Some(file), Some(i)) => {
            let who = match tags.and_then(|t| t.get(i)) {
                Some(tag) => format!("gmsh {kind} {tag}"),
                None => format!("{kind} {}", i + 1),
            };
            StampError::Input { file: p.dir().join(file.get_ref()).display().to_string(), message: format!("{who} {tail}") }
        }
        (Some(file), None) => StampError::Input { file: p.dir().join(file.get_ref()).display().to_string(), message: msg.clone() },
        (None, Some(i)) => {
            let what = if kind == "element" { "cell" } else { "node" };
            p.error_at(p.spec.mesh.span(), "mesh.rectangle", format!("{what} {} (counted from 1) {tail}", i + 1))
        }
        (None, None) => p.error_at(p.spec.mesh.span(), "mesh.rectangle", msg),
    }
}

/// Build everything the solve needs.
pub fn build(p: &Problem) -> Result<Setup> {
    let s = &p.spec;
    crate::run::parallel::check_options(p)?;
    let mesh = MeshData::load(p).map_err(|e| match e {
        StampError::Mesh(m) => p.error_at(s.mesh.span(), "mesh", m),
        e => e,
    })?;
    // a gmsh mesh is read first (its size bounded by its file); refuse it before the model is built,
    // and a rectangle (checked for the paper's plate when read) too if the plate has more unknowns
    let dofs_per_node = s.plate.get_ref().dofs_per_node();
    let fits = crate::model::memory::check_problem_fits(&stl_dies(p), mesh.mesh.num_nodes() as u64, dofs_per_node);
    match &s.mesh.get_ref().file {
        _ if p.given_mesh.is_some() => fits.map_err(|m| p.error_at(s.mesh.span(), "mesh.nodes", m))?,
        Some(file) => fits.map_err(|m| p.error_at(file.span(), "mesh.file", m))?,
        None => fits.map_err(|m| p.error_at(s.mesh.span(), "mesh.rectangle", m))?,
    }
    let mut setup = build_on(p, mesh)?;
    if s.solver.predictor.as_ref().is_some_and(|k| *k.get_ref() == Predictor::Coarse) {
        setup.coarse = Some(Box::new(build_coarse(p, &setup.mesh)?));
    }
    Ok(setup)
}

/// The problem on the coarse mesh of `predictor = "coarse"`; its errors say that they are the
/// coarse mesh's (a group the coarse file lacks, a rectangle too coarse for a `center`, a mesh
/// that does not cover the plate).
fn build_coarse(p: &Problem, fine: &MeshData) -> Result<CoarseSetup> {
    let key = p.spec.solver.predictor.as_ref().map(|k| k.span()).unwrap_or_else(|| p.spec.mesh.span());
    let (what, span, span_key) = match &p.spec.mesh.get_ref().coarse_file {
        Some(f) => (format!("the coarse mesh {}", f.get_ref()), f.span(), "mesh.coarse_file"),
        None => {
            let r = p.spec.mesh.get_ref().rectangle.as_ref().expect("checked: file or rectangle");
            (format!("the coarse mesh (the rectangle with n = [{}, {}])", r.n[0] / 2, r.n[1] / 2), key, "solver.predictor")
        }
    };
    let coarse = MeshData::load_coarse(p).map_err(|e| match e {
        StampError::Mesh(m) => p.error_at(span.clone(), span_key, m),
        e => e,
    })?;
    if coarse.mesh.num_nodes() >= fine.mesh.num_nodes() {
        return Err(p.error_at(
            span,
            span_key,
            format!("{what} has {} nodes, the mesh {}: the coarse mesh must have fewer", coarse.mesh.num_nodes(), fine.mesh.num_nodes()),
        ));
    }
    // the same plate: no node of the mesh farther outside the coarse one than a fifth of a coarse
    // cell (a curved edge meshed twice leaves its nodes a sagitta outside, l^2 / 8R)
    let prolongation = stamp::mesh::transfer::Prolongation::between(&coarse.mesh, &fine.mesh);
    let (node, distance) = prolongation.farthest_outside();
    let allowed = 0.2 * coarse.element_size();
    if distance > allowed {
        return Err(p.error_at(
            span,
            span_key,
            format!(
                "{what} does not cover the plate: {} of the mesh lies {} outside it (at most {} allowed, a fifth of its mean cell size); the coarse mesh must mesh the same plate",
                crate::model::mesh::where_node(fine, node),
                num(distance),
                num(allowed)
            ),
        ));
    }
    // ... and the other way round: no node of the coarse mesh farther outside the mesh (a coarse
    // mesh of a larger plate covers the plate and more), and the same area
    let (node, distance) = stamp::mesh::transfer::Prolongation::between(&fine.mesh, &coarse.mesh).farthest_outside();
    if distance > allowed {
        return Err(p.error_at(
            span,
            span_key,
            format!(
                "{what} is not the same plate: {} of the coarse mesh lies {} outside the mesh (at most {} allowed, a fifth of its mean cell size); the coarse mesh must mesh the same plate",
                crate::model::mesh::where_node(&coarse, node),
                num(distance),
                num(allowed)
            ),
        ));
    }
    let area = |m: &MeshData| m.mesh.nodal_areas().iter().sum::<f64>();
    let (a_coarse, a_fine) = (area(&coarse), area(fine));
    if (a_coarse - a_fine).abs() > 0.05 * a_fine {
        return Err(p.error_at(
            span,
            span_key,
            format!("{what} is not the same plate: its area is {}, the mesh's {} (they may differ by at most 5%)", num(a_coarse), num(a_fine)),
        ));
    }
    // a mesh error of the coarse file names the coarse file (mesh_error names `mesh.file`)
    let fine_file = p.spec.mesh.get_ref().file.as_ref().map(|f| p.dir().join(f.get_ref()).display().to_string());
    let coarse_file = p.spec.mesh.get_ref().coarse_file.as_ref().map(|f| p.dir().join(f.get_ref()).display().to_string());
    let setup = build_on(p, coarse).map_err(|e| match e {
        StampError::Input { file, message } => {
            let file = if Some(&file) == fine_file.as_ref() { coarse_file.clone().unwrap_or(file) } else { file };
            StampError::Input { file, message: format!("{what} of [solver] predictor = \"coarse\" does not fit the problem: {message}") }
        }
        e => StampError::Problem(format!("{what} of [solver] predictor = \"coarse\": {e}")),
    })?;
    Ok(CoarseSetup { setup, prolongation })
}

/// Build everything the solve needs on the given mesh (the problem's own, or its refinement: the
/// caller has checked that it fits in memory): the builders of the problem file's tables in turn,
/// `[plate]` (with `[[material]]`), `[[boundary]]`, `[[load]]`, `[[punch]]` and `[solver]`.
pub fn build_on(p: &Problem, mesh: MeshData) -> Result<Setup> {
    let PlateBuild { plate, section, young, kinematics } = build_plate(p, &mesh)?;
    let layout = Layout::of(&plate);
    let (dofs, supports) = build_boundary(p, &mesh, &layout)?;
    let mut model = Model::new(plate, dofs).map_err(|e| match e {
        e @ StampError::Mesh(_) => mesh_error(p, &mesh, e),
        e => StampError::Input { file: p.path.display().to_string(), message: e.to_string() },
    })?;
    build_loads(p, &mesh, &section, &layout, &mut model)?;
    let punches = build_punches(p, &mesh, &section, young, kinematics, &layout, &mut model)?;
    let stiffness = stiffness_force(&mesh, &section, young);
    let settings = build_solver(p, &mut model, stiffness)?;
    Ok(Setup { mesh, model, section, punches, targets: p.targets(), settings, stiffness, coarse: None, supports })
}

/// The plate of `[plate]` (with the `[[material]]` tables of its layers): its elements, the
/// section (the plate's, or the laminate's faces with a modulus standing for it: the geometry the
/// loads and punches use), that modulus and the kinematics.
struct PlateBuild {
    plate: Plate,
    section: Section,
    young: f64,
    kinematics: Kinematics,
}

/// `[plate]` and `[[material]]`: the section, the laminate and the plate elements on the mesh.
fn build_plate(p: &Problem, mesh: &MeshData) -> Result<PlateBuild> {
    let s = &p.spec;
    let ps = s.plate.get_ref();
    let kin = match ps.kinematics {
        KinematicsSpec::Nonlinear => Kinematics::Nonlinear,
        KinematicsSpec::Linear => Kinematics::Linear,
    };
    let laminate = crate::model::laminate_spec::laminate(p)?;
    let plate_material = crate::model::plasticity_spec::plate_material(p)?;
    // the section: the plate's (homogeneous), or the laminate's faces and a modulus standing for it
    // (the geometry the loads and punches use; the elements take the laminate itself)
    let (section, young) = match &laminate {
        Some((lam, _)) => {
            let young = crate::model::laminate_spec::reference_modulus(lam);
            let stand_in = Isotropic::new(young, 0.0).map_err(|e| p.error_at(s.plate.span(), "plate.layers", e))?;
            (Section::homogeneous(lam.thickness(), stand_in).map_err(|e| p.error_at(s.plate.span(), "plate.layers", e))?, young)
        }
        None => {
            let m = plate_material.as_ref().expect("a plate without layers");
            let (young, nu) = (m.young, m.poisson);
            let material = Isotropic::new(young, nu).map_err(|e| p.error_at(s.plate.span(), "plate", e))?;
            let (dm, dp) = match ps.thickness {
                Some(h) => (-0.5 * h.0, 0.5 * h.0),
                None => (ps.delta_minus.unwrap().0, ps.delta_plus.unwrap().0),
            };
            let mut section = Section::homogeneous_offset(dm, dp, material).map_err(|e| p.error_at(s.plate.span(), "plate", e))?;
            section.normal_stress = ps.normal_stress;
            if let Some(k) = ps.shear_factor {
                section = section.with_shear_factor(k.0).map_err(|e| p.error_at(s.plate.span(), "plate.shear_factor", e))?;
            }
            (section, young)
        }
    };
    let surfaces = ps.surfaces();
    if surfaces > 2 && laminate.is_none() {
        let bad = if ps.shear_factor.is_some() { Some("shear_factor") } else if ps.normal_stress != NormalStress::Dropped { Some("normal_stress") } else { None };
        if let Some(key) = bad {
            return Err(p.error_at(
                s.plate.span(),
                &format!("plate.{key}"),
                format!("is a correction of the two-surface plate; with surfaces = {surfaces} the plate has the full 3D law and takes no shear_factor or normal_stress"),
            ));
        }
    }
    let plate = match laminate {
        Some((lam, per_layer)) => Plate::layered(per_layer, &mesh.mesh, lam, kin),
        None => Plate::new(surfaces, &mesh.mesh, section.clone(), kin),
    }
    .map_err(|e| mesh_error(p, mesh, e))?;
    let plate = match plate_material.and_then(|m| m.plasticity) {
        Some(plasticity) => plate.with_plasticity(plasticity).map_err(|e| p.error_at(s.plate.span(), "plate.material", e))?,
        None => plate,
    };
    Ok(PlateBuild { plate, section, young, kinematics: kin })
}

/// `[[boundary]]` (and `[plate] plane_strain`): the components held at zero or prescribed, by
/// group; and the dofs each group holds (plane_strain's are no group's).
fn build_boundary(p: &Problem, mesh: &MeshData, layout: &Layout) -> Result<(DofMap, Supports)> {
    let s = &p.spec;
    let ps = s.plate.get_ref();
    let n_nodes = mesh.mesh.num_nodes();
    let mut dofs = DofMap::new(n_nodes, layout.dofs_per_node)?;
    let mut supports = Supports::default();
    if ps.plane_strain {
        let all: Vec<usize> = (0..n_nodes).collect();
        dofs.fix(&all, &layout.fibre_components(&[0, 3]))?;
    }
    for (i, b) in s.boundary.iter().enumerate() {
        let bs = b.get_ref();
        let key = format!("boundary[{i}].group");
        let name = bs.group.get_ref();
        let nodes = mesh.nodes(name).ok_or_else(|| group_error(p, bs.group.span(), &key, name, "", mesh))?;
        let comps: Vec<usize> = layout.fibre_components(&bs.fix.iter().flat_map(|d| d.components.clone()).collect::<Vec<_>>());
        dofs.fix(&nodes, &comps).map_err(|e| p.error_at(b.span(), &format!("boundary[{i}]"), e))?;
        let dpn = layout.dofs_per_node;
        supports.hold(name, nodes.iter().flat_map(|&n| comps.iter().map(move |&c| n * dpn + c)));
        let path = bs.path.as_ref().map(|q| dofs.add_path(q.get_ref().0.clone()));
        for (k, v) in &bs.prescribe {
            let comps = layout.fibre_components(&crate::schema::dof_components(&k.0).expect("checked word"));
            for &n in &nodes {
                for &c in &comps {
                    dofs.prescribe_along(n, c, v.0, path).map_err(|e| p.error_at(b.span(), &format!("boundary[{i}].prescribe"), e))?;
                }
            }
            supports.hold(name, nodes.iter().flat_map(|&n| comps.iter().map(move |&c| n * dpn + c)));
        }
    }
    Ok((dofs, supports))
}

/// `[[load]]`: line, surface, pressure, moment and point loads, as nodal forces of the model or
/// follower loads.
fn build_loads(p: &Problem, mesh: &MeshData, section: &Section, layout: &Layout, model: &mut Model<Plate>) -> Result<()> {
    let s = &p.spec;
    let n_nodes = mesh.mesh.num_nodes();
    for (i, l) in s.load.iter().enumerate() {
        let ls = l.get_ref();
        let key = format!("load[{i}].group");
        let name = ls.group.get_ref();
        let face = ls.face.unwrap_or_default();
        let path = ls.path.as_ref().map(|q| model.add_load_path(q.0.clone()));
        match ls.kind {
            LoadKind::Line => {
                let segs = mesh.curves.get(name).ok_or_else(|| group_error(p, ls.group.span(), &key, name, "curve", mesh))?;
                let f = ls.force.unwrap().0;
                for s in segs {
                    let len = segment_length(mesh, s);
                    for &n in s {
                        add_force(model, layout, n, f.map(|x| 0.5 * len * x), face, path)?;
                    }
                }
            }
            LoadKind::Surface | LoadKind::Pressure => {
                let cells = mesh.surfaces.get(name).ok_or_else(|| group_error(p, ls.group.span(), &key, name, "surface", mesh))?;
                let size = model_size(mesh, section, None);
                if ls.kind == LoadKind::Pressure {
                    let spec = ls.pressure.as_ref().unwrap();
                    let q = crate::model::pressure::pressure_function(spec.get_ref(), size);
                    let pkey = format!("load[{i}].pressure");
                    if ls.follower {
                        let (f, z) = match face {
                            LoadFace::Top => (Face::Top, section.delta_plus),
                            _ => (Face::Bottom, section.delta_minus),
                        };
                        // the values at the Gauss points are checked as for a dead load
                        crate::model::pressure::nodal_forces(p, spec.span(), &pkey, &mesh.mesh, cells, &*q)?;
                        let quads: Vec<[usize; 4]> = cells.iter().map(|&c| mesh.mesh.cells[c]).collect();
                        let what = format!("follower pressure on '{}'", stamp::quote(name));
                        let load = Box::new(FollowerPressure::varying(what, &mesh.mesh.coords, &quads, f, z, &*q).with_dofs_per_node(layout.dofs_per_node));
                        match path {
                            None => model.add_follower_load(load),
                            Some(k) => model.add_follower_load_along(load, k)?,
                        }
                        continue;
                    }
                    let sign = if face == LoadFace::Top { -1.0 } else { 1.0 };
                    let nodal = match spec.get_ref() {
                        // int N_a dA times q, as before pressures could vary
                        crate::schema::PressureSpec::Uniform(q) => mesh.nodal_areas_of(cells).into_iter().map(|a| a * q).collect(),
                        _ => crate::model::pressure::nodal_forces(p, spec.span(), &pkey, &mesh.mesh, cells, &*q)?,
                    };
                    for (n, &fz) in nodal.iter().enumerate() {
                        if fz != 0.0 {
                            add_force(model, layout, n, [0.0, 0.0, sign * fz], face, path)?;
                        }
                    }
                    continue;
                }
                let f = ls.force.unwrap().0;
                let w = mesh.nodal_areas_of(cells);
                for (n, &a) in w.iter().enumerate() {
                    if a > 0.0 {
                        add_force(model, layout, n, f.map(|x| a * x), face, path)?;
                    }
                }
            }
            LoadKind::Moment => {
                let segs = mesh.curves.get(name).ok_or_else(|| group_error(p, ls.group.span(), &key, name, "curve", mesh))?;
                let m = ls.moment.unwrap().0;
                let mut share = vec![0.0; n_nodes];
                for s in segs {
                    let len = segment_length(mesh, s);
                    for &n in s {
                        share[n] += 0.5 * len;
                    }
                }
                let h = section.thickness();
                let couples: Vec<(usize, [f64; 3])> = share.iter().enumerate().filter(|(_, &w)| w > 0.0).map(|(n, &w)| (n, m.map(|x| w * x))).collect();
                if ls.follower {
                    let what = format!("follower couple on '{}'", stamp::quote(name));
                    let load = Box::new(FollowerCouple::new(what, couples, h).with_dofs_per_node(layout.dofs_per_node));
                    match path {
                        None => model.add_follower_load(load),
                        Some(k) => model.add_follower_load_along(load, k)?,
                    }
                } else {
                    for (n, mn) in couples {
                        let f = fixed_couple_force(mn, h);
                        add_force(model, layout, n, f, LoadFace::Top, path)?;
                        add_force(model, layout, n, f.map(|x| -x), LoadFace::Bottom, path)?;
                    }
                }
            }
            LoadKind::Point => {
                let nodes = mesh.points.get(name).cloned().or_else(|| mesh.nodes(name)).ok_or_else(|| group_error(p, ls.group.span(), &key, name, "", mesh))?;
                for n in nodes {
                    add_force(model, layout, n, ls.force.unwrap().0, face, path)?;
                }
            }
        }
    }
    Ok(())
}

/// The length of a segment of a curve group, in the reference plane.
fn segment_length(mesh: &MeshData, s: &[usize; 2]) -> f64 {
    let (a, b) = (mesh.mesh.coords[s[0]], mesh.mesh.coords[s[1]]);
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

/// `[[punch]]`: each punch's surface, candidate points, contact pair (eps_reg, motion or force)
/// added to the model, and the model's penetration tolerance; what the outputs need of them.
fn build_punches(p: &Problem, mesh: &MeshData, section: &Section, young: f64, kin: Kinematics, layout: &Layout, model: &mut Model<Plate>) -> Result<Vec<PunchInfo>> {
    let s = &p.spec;
    let n_nodes = mesh.mesh.num_nodes();
    let h = section.thickness();
    let le = mesh.element_size();
    let mut punches = Vec::new();
    let mut tolerance: Option<f64> = None;
    for (i, pu) in s.punch.iter().enumerate() {
        let spec = pu.get_ref();
        let name = p.punch_name(i);
        let key = format!("punch[{i}]");
        let wrap = |e: StampError| p.error_at(pu.span(), &key, e);
        let surface: Arc<dyn ContactSurface> = match spec.shape {
            Shape::Cylinder => Arc::new(Cylinder::new(Vector3::from(spec.point.unwrap().0), Vector3::from(spec.axis.unwrap().0), spec.radius.unwrap().0).map_err(wrap)?),
            Shape::Sphere => Arc::new(Sphere::new(Vector3::from(spec.center.unwrap().0), spec.radius.unwrap().0).map_err(wrap)?),
            Shape::Plane => Arc::new(Plane::new(Vector3::from(spec.point.unwrap().0), Vector3::from(spec.normal.unwrap().0)).map_err(wrap)?),
            Shape::Expression => {
                let psi = spec.psi.as_ref().unwrap();
                Arc::new(Expression::new(psi.get_ref(), model_size(mesh, section, None)).map_err(|e| p.psi_error(psi, e.column, &format!("{key}.psi"), &e.message))?)
            }
            Shape::Stl => Arc::new(stl_die(p, spec.file.as_ref().expect("checked: stl has file"), &key)?),
        };
        let face = face_of(spec.face);
        let z = match face {
            Face::Top => section.delta_plus,
            Face::Bottom => section.delta_minus,
        };
        let (nodes, weights) = match &spec.group {
            None => ((0..n_nodes).collect::<Vec<_>>(), mesh.mesh.nodal_areas()),
            Some(g) => {
                let gname = g.get_ref();
                let nodes = mesh.nodes(gname).ok_or_else(|| group_error(p, g.span(), &format!("{key}.group"), gname, "", mesh))?;
                let w = match mesh.surfaces.get(gname) {
                    Some(cells) => mesh.nodal_areas_of(cells),
                    None => mesh.mesh.nodal_areas(),
                };
                (nodes, w)
            }
        };
        let points: Vec<ContactPoint> = nodes
            .iter()
            .map(|&n| {
                let x = mesh.mesh.coords[n];
                ContactPoint { node: n, x_ref: [x[0], x[1], z], dofs: [0, 1, 2].map(|c| layout.face_dof(face, n, c)), weight: weights[n] }
            })
            .collect();
        let ck = match spec.kinematics {
            Some(ContactKinematicsSpec::Exact) => ContactKinematics::Exact,
            Some(ContactKinematicsSpec::Shallow) => ContactKinematics::Shallow { direction: [0.0, 0.0, 1.0] },
            None => match kin {
                Kinematics::Nonlinear => ContactKinematics::Exact,
                Kinematics::Linear => ContactKinematics::Shallow { direction: [0.0, 0.0, 1.0] },
            },
        };
        let mut pair = ContactPair::new(name.clone(), surface.clone(), points, 1.0, ck);
        if spec.contact.unwrap_or(DEFAULT_CONTACT) == ContactSpec::Integrated {
            pair = integrated(pair, mesh, spec.group.as_ref().map(|g| g.get_ref().as_str())).map_err(|e| p.error_at(pu.span(), &format!("{key}.contact"), e))?;
            // the pattern couples the patches of the points within a thickness of the punch
            pair.coupling_reach = 0.02 * h;
        }
        let (eps_reg, eps_automatic) = match spec.eps_reg {
            Some(e) => (e.0, false),
            None => (automatic_eps_reg(young * h, le, pair.contact_gradient_norm()), true),
        };
        pair.eps_reg = eps_reg;
        pair.motion = spec.motion.as_ref().map(|m| m.0.clone()).unwrap_or_default();
        if let Some(r) = &spec.rotation {
            // a cylinder turns about its own axis through its point unless told otherwise, a
            // sphere about its centre
            let axis = match spec.shape {
                Shape::Cylinder => spec.rotation_axis.or(spec.axis),
                _ => spec.axis,
            };
            let pivot = spec.pivot.or(spec.point.filter(|_| spec.shape == Shape::Cylinder)).or(spec.center);
            // (check_rotation_keys refused a rotation without them)
            let (axis, pivot) = (axis.map_or([0.0; 3], |a| a.0), pivot.map_or([f64::NAN; 3], |v| v.0));
            pair.rotation = Some(PunchRotation::new(axis, pivot, &r.get_ref().0).map_err(|e| p.error_at(r.span(), &format!("{key}.rotation"), e))?);
        }
        // an expression must be finite (and smooth) at every candidate point where the punch starts
        if let Some(psi) = &spec.psi {
            for q in &pair.points {
                let x = Vector3::from(q.x_ref);
                let _ = (surface.psi(&x), surface.hessian(&x));
            }
            if let Some(m) = surface.evaluation_error() {
                return Err(p.error_at(psi.span(), &format!("{key}.psi"), m));
            }
        }
        if let Some(f) = spec.force {
            let dir = spec.direction.map(|d| d.0).unwrap_or(match face {
                Face::Top => [0.0, 0.0, -1.0],
                Face::Bottom => [0.0, 0.0, 1.0],
            });
            pair.drive = Some(ForceDrive::new(dir, f.0).map_err(wrap)?);
        }
        if let Some(mu) = spec.friction.as_ref().filter(|m| m.get_ref().0 > 0.0) {
            let fkey = format!("{key}.friction");
            if pair.kinematics != ContactKinematics::Exact {
                return Err(p.error_at(mu.span(), &fkey, "friction needs kinematics = \"exact\" (the default for a nonlinear plate), not the shallow constraint"));
            }
            pair.set_friction(mu.get_ref().0).map_err(|e| p.error_at(mu.span(), &fkey, e))?;
        }
        model.add_contact(pair);
        if let Some(t) = &spec.penetration_tolerance {
            let tol = t.get_ref().0;
            // below the round-off of the model's size the penetration cannot be measured
            let size = model_size(mesh, section, spec.radius.map(|r| r.0));
            let floor = crate::schema::limits::MIN_PENETRATION_TOLERANCE * size;
            if tol < floor {
                return Err(p.error_at(
                    t.span(),
                    &format!("{key}.penetration_tolerance"),
                    format!("{:e} is below the round-off of a model of size {:e}; the smallest allowed is {floor:.1e}", tol, size),
                ));
            }
            tolerance = Some(tolerance.map_or(tol, |x: f64| x.min(tol)));
        } else {
            // the default: a penetration of a sizeable part of the thickness is never converged
            let tol = crate::schema::punches::DEFAULT_PENETRATION * h;
            tolerance = Some(tolerance.map_or(tol, |x: f64| x.min(tol)));
        }
        punches.push(PunchInfo { name, face, z, surface, eps_reg, eps_automatic });
    }
    model.augmented_tolerance = tolerance;
    Ok(punches)
}

/// The plate's stiffness as a force: E h L (the modulus, the thickness and the plate's larger
/// side), the force that stretches it by its own length. Newton's absolute tolerance and the
/// smallest loads are measured against it, so that a problem in other units (E = 1e-20, or a
/// force of 1e-15 on steel) is judged as the same problem in MPa and mm.
pub fn stiffness_force(mesh: &MeshData, section: &Section, young: f64) -> f64 {
    let (lo, hi) = mesh.bounding_box();
    let span = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    young * section.thickness() * span
}

/// Newton's absolute tolerance as a fraction of [`stiffness_force`] (without `[solver] abs_tol`):
/// just above the round-off floor of the plate's internal forces (measured 3.6e-16 E h L on the
/// shipped sphere-ss: 1.5e-9 for E h L = 4.2e6), so that a step whose forces are round-off (an
/// `initial_increment` of 1e-12, a plate of E = 1e-20 in the same units) is judged by what can
/// be computed. The shipped problems take the same Newton iterations as with the former absolute
/// 1e-14 (sphere-ss, sphere-ss-displacement, cylinder-30deg compared step by step).
pub const ABS_TOL_OF_STIFFNESS: f64 = 1e-15;

/// `[solver]`: Newton's settings, and its tangent on the model; `stiffness` the force E h L
/// that the absolute tolerance is a fraction of.
fn build_solver(p: &Problem, model: &mut Model<Plate>, stiffness: f64) -> Result<NewtonSettings> {
    let s = &p.spec;
    model.mixed_tangent = s.solver.newton.unwrap_or_default() == crate::schema::NewtonTangent::Mip;
    let sv = &s.solver;
    let mut settings = NewtonSettings { max_increment: DEFAULT_MAX_INCREMENT, ..NewtonSettings::default() };
    if let Some(x) = &sv.max_increment {
        settings.max_increment = x.get_ref().0;
    }
    if let Some(x) = sv.initial_increment {
        settings.initial_increment = x.0;
    }
    if let Some(x) = &sv.min_increment {
        settings.min_increment = x.get_ref().0;
    }
    if let Some(x) = sv.rel_tol {
        settings.rel_tol = x.0;
    }
    settings.abs_tol = match sv.abs_tol {
        Some(x) => x.0,
        None => ABS_TOL_OF_STIFFNESS * stiffness,
    };
    if let Some(x) = sv.max_iterations {
        settings.max_iterations = x.0;
    }
    if let Some(x) = sv.max_cutbacks {
        settings.max_cutbacks = x.0;
    }
    if let Some(x) = sv.line_search_steps {
        settings.line_search_steps = x.0;
    }
    if let Some(x) = sv.cycling_after {
        settings.cycling_after = x.0;
    }
    if let Some(x) = sv.resolve_contact {
        settings.resolve_contact = x;
    }
    settings.validate().map_err(|e| StampError::Input { file: p.path.display().to_string(), message: format!("[solver]: {e}") })?;
    Ok(settings)
}

/// The default of `[[punch]] contact` (see docs/design.md).
pub const DEFAULT_CONTACT: ContactSpec = ContactSpec::Nodal;

/// The pair with the integrated discretisation on the cells of `group` (a surface group; None:
/// every cell).
fn integrated(pair: ContactPair, mesh: &MeshData, group: Option<&str>) -> Result<ContactPair> {
    let cells: Vec<[usize; 4]> = match group {
        None => mesh.mesh.cells.clone(),
        Some(g) => match mesh.surfaces.get(g) {
            Some(cells) => cells.iter().map(|&c| mesh.mesh.cells[c]).collect(),
            None => {
                return Err(StampError::Problem(format!(
                    "\"integrated\" integrates over the cells of the punch's group, but '{}' is not a surface group (use a surface group, or contact = \"nodal\")",
                    stamp::quote(g)
                )))
            }
        },
    };
    let mut point_of_node = vec![None; mesh.mesh.num_nodes()];
    for (k, q) in pair.points.iter().enumerate() {
        point_of_node[q.node] = Some(k);
    }
    let face = ContactFace::new(&mesh.mesh.coords, &cells, &point_of_node, pair.points.len())?;
    pair.with_face(face)
}

/// The STL dies of the punches: (the name as written, quoted; its path), for the memory check.
fn stl_dies(p: &Problem) -> Vec<(String, std::path::PathBuf)> {
    p.spec.punch.iter().filter_map(|s| s.get_ref().file.as_ref()).map(|f| (stamp::quote(f.get_ref()), p.dir().join(f.get_ref()))).collect()
}

/// The STL die of a punch: `file` relative to the problem file; errors name the problem file, the
/// key and the STL file.
fn stl_die(p: &Problem, file: &toml::Spanned<String>, key: &str) -> Result<StlSurface> {
    let path = p.dir().join(file.get_ref());
    StlSurface::from_file(&path).map_err(|e| p.error_at(file.span(), &format!("{key}.file"), e))
}

/// The size of the model as a length: the largest of the coordinates' magnitudes, the face
/// offsets and the punch radius (the scale of the round-off in a penetration).
fn model_size(mesh: &MeshData, section: &Section, radius: Option<f64>) -> f64 {
    let coords = mesh.mesh.coords.iter().flat_map(|x| x.iter()).fold(0.0f64, |m, v| m.max(v.abs()));
    coords.max(section.delta_minus.abs()).max(section.delta_plus.abs()).max(radius.unwrap_or(0.0))
}

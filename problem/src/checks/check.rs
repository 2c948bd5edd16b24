//! `stamp check`: what is wrong with a built problem, said before any solve, and a short summary
//! of the model. `stamp run` runs the same checks first.
//!
//! Errors (no solve):
//! * a support, load or punch on a group with nothing in it (no nodes; a line load on a curve with
//!   no edges; a pressure or surface load on a surface with no cells);
//! * a punch that starts inside the plate by more than its penetration tolerance
//!   (`penetration_tolerance`, default [`DEFAULT_PENETRATION`] times the thickness), at its
//!   contact face or anywhere between the faces (the plate's volume);
//! * an expression punch without a usable gradient of Psi along its motion
//!   ([`crate::checks::psi_checks`]);
//! * rigid-body motions held by nothing (see [`crate::checks::rigid_modes`]): the rows are the supports'
//!   held components (fixed and prescribed dofs, plane strain) at their faces, and the line x3 at
//!   the points where a punch touches the plate at the start (gap <= [`TOUCH`] times the model
//!   size, or the penetration tolerance), or, for a force-driven punch that touches nothing yet,
//!   at the points closest to it (it comes down onto them). A frictionless punch meets the flat
//!   face tangentially at the first contact, so it holds along the face normal only: grad Psi at
//!   the nodes beside the contact line is tilted by the mesh (the node is not where the punch
//!   touches), and counting the tilt as holding the plate in its plane passed plates that slide;
//! * the travel of a force-driven punch held by nothing (see [`crate::checks::travel_modes`]): its
//!   direction across x3, or a rigid motion of the plate held by that punch alone (plate and punch
//!   move away together).
//!
//! Warnings (the solve goes on): a punch whose motion or force moves it away from its contact face;
//! a motion that carries a punch through the plate within an increment of `max_increment`
//! ([`crate::checks::psi_checks::sweep_warning`]);
//! a punch on the side of the plate away from its contact face; cells of extreme aspect ratio
//! ([`crate::checks::cell_shape`]); after a run, a punch that never touched the plate or touched it on a
//! zone narrower than the cells ([`after_the_run`]).

use crate::checks::punch_start::{first_gap, gap_at, start_gaps, PointGap};
use crate::checks::rigid_modes::{direction_words, join_and, num, RigidModes};
use crate::checks::travel_modes::TravelModes;
use crate::model::build::Setup;
use crate::model::mesh::{where_node, MeshData};
use crate::schema::{LoadFace, LoadKind, PlotAxis, Problem};
use nalgebra::Vector3;
use stamp::surface::ContactSurface;
use stamp::dofs::PRESCRIBED;
use stamp::nonlinear::NonlinearProblem;
use stamp::{quote, Result, StampError};
use stamp_elements::Face;
use std::fmt::Write as _;
use std::path::Path;

pub use crate::schema::punches::DEFAULT_PENETRATION;
/// A punch touches the plate at the start where the gap is below this fraction of the model size.
pub const TOUCH: f64 = 1e-6;

/// Where every punch starts.
#[derive(Debug, Clone)]
pub struct PunchStart {
    pub key: String,
    pub name: String,
    /// The candidate point closest to the punch.
    pub first: Option<PointGap>,
    /// Points that hold rigid motions at the start (touching, or closest for a force-driven punch).
    pub holding: Vec<PointGap>,
    /// The holding points touch the plate (not merely closest to a force-driven punch).
    pub touching: bool,
}

/// What the checks found: the summary of the model and the warnings.
#[derive(Debug, Clone)]
pub struct CheckReport {
    pub summary: String,
    pub warnings: Vec<String>,
    pub punches: Vec<PunchStart>,
}

/// Run every check on a built problem: Err with the first error, else the summary and warnings.
pub fn check(p: &Problem, setup: &Setup) -> Result<CheckReport> {
    check_groups(p, &setup.mesh)?;
    check_punch_forces(p, setup)?;
    let probe_warnings = check_outputs(p, setup)?;
    let size = model_size(setup);
    let mut starts = Vec::new();
    for i in 0..setup.punches.len() {
        crate::checks::psi_checks::check_expression(p, setup, i, size)?;
        starts.push(punch_start(p, setup, i, size)?);
        check_supported_nodes_under(p, setup, i)?;
    }
    let rigid = check_rigid_modes(p, setup, &starts, size)?;
    let mut warnings = punch_warnings(p, setup, &starts);
    warnings.extend(crate::checks::cell_shape::aspect_warning(p, &setup.mesh));
    warnings.extend(probe_warnings);
    let summary = summary(p, setup, &starts, &rigid);
    Ok(CheckReport { summary, warnings, punches: starts })
}

/// The smallest punch force the solve resolves, as a fraction of the plate's stiffness force
/// E h L: the internal forces carry a round-off of about 4e-16 E h L (measured: the shipped
/// sphere-ss's residual floor 1.5e-9 for E h L = 4.2e6), which must stay below 1e-6 of the force.
/// A force of 1e-15 on that plate "converged" at once with the punch unmoved and a reaction of 0;
/// 1e-6 failed after 12 cut-backs.
pub const MIN_FORCE_OF_STIFFNESS: f64 = 1e-9;

/// A force-driven punch whose force the solve cannot tell from round-off: refused with the
/// numbers (its reaction would be round-off, or Newton would never reach its tolerance).
fn check_punch_forces(p: &Problem, setup: &Setup) -> Result<()> {
    for (i, pu) in p.spec.punch.iter().enumerate() {
        let Some(f) = pu.get_ref().force else { continue };
        let least = MIN_FORCE_OF_STIFFNESS * setup.stiffness;
        if f.0.abs() < least {
            return Err(p.error_at(
                pu.span(),
                &format!("punch[{i}].force"),
                format!(
                    "{:e} is below {least:.1e}, 1e-9 of the plate's stiffness as a force (E h L = {:.3e}: modulus x thickness x larger side): the plate's own round-off (about 1e-16 E h L) would swamp it. Values are numbers in the file's units ([units] only labels them): check the force's and the modulus's units",
                    f.0, setup.stiffness
                ),
            ));
        }
    }
    Ok(())
}

/// What the run checks of the outputs before its first step, checked here too so that `stamp
/// check` passes only what `stamp run` accepts: probe lines and thickness probes on the plate (a
/// point off the mesh, "equilibrium" where the cells around the point cannot be fitted), and
/// thickness probes only on plates that have stresses through the thickness. Returns the thickness
/// probes' warnings (a default recovery the mesh cannot fit).
fn check_outputs(p: &Problem, setup: &Setup) -> Result<Vec<String>> {
    let names: Vec<String> = setup.punches.iter().map(|i| i.name.clone()).collect();
    crate::outputs::probe::Probes::new(p, &setup.mesh, &p.spec.output.probe, &names)?;
    let warnings = crate::outputs::thickness_probe::ThicknessProbes::new(p, &setup.mesh)?.warnings;
    if let Some(first) = p.spec.output.thickness_probe.first() {
        if setup.model.element.stress_stack().is_none() {
            return Err(p.error_at(first.span(), "output.thickness_probe[0]", "a thickness probe reads the stresses through the thickness: it needs `[plate] surfaces` = 3 to 5, or `layers`"));
        }
    }
    Ok(warnings)
}

/// How deep punch `i` may reach, in its undeformed position, below a node whose surfaces the
/// supports hold along the punch's travel: its penetration tolerance where the contact face
/// itself is held, this fraction of the thickness where only another surface is (the plate can
/// give that much by thinning under huge forces, not more).
pub const SUPPORTED_THINNING: f64 = 0.1;

/// A displacement-driven punch whose travel presses it onto nodes that the supports hold in its
/// direction: a fixed node cannot give way, so the run would report "converged" steps with
/// enormous forces and penetrations (a roller across a plate whose long edges are simply
/// supported, pressed 4 mm into a 3 mm plate: 1e7 N, 5e6 MPa, 0.46 mm inside), then fail.
/// Refused with the first such node, how deep the punch reaches there and at what load factor.
fn check_supported_nodes_under(p: &Problem, setup: &Setup, i: usize) -> Result<()> {
    let pair = &setup.model.contacts[i];
    if pair.drive.is_some() || (pair.motion.is_zero() && pair.rotation.is_none()) {
        return Ok(());
    }
    let dofs = &setup.model.dofs;
    let dpn = dofs.dofs_per_node();
    let h = setup.section.thickness();
    let tol = penetration_tolerance(p, setup, i);
    // the load factors where the punch is deepest: the targets and the path's rows
    let mut samples: Vec<f64> = setup.targets.clone();
    if let stamp::contact::PunchMotion::Path(rows) = &pair.motion {
        let end = setup.targets.iter().cloned().fold(0.0, f64::max);
        samples.extend(rows.iter().map(|r| r.0).filter(|&t| t <= end));
    }
    // and those where a turning punch turns differently (its surface as turned there)
    if let Some(r) = &pair.rotation {
        let end = setup.targets.iter().cloned().fold(0.0, f64::max);
        samples.extend(r.rows().iter().map(|r| r.0).filter(|&t| t <= end));
    }
    for &t in &samples {
        let d = pair.motion.displacement(t);
        let surface = pair.surface_at(t);
        if d == [0.0; 3] && surface.turn.is_none() {
            continue;
        }
        for q in &pair.points {
            let x = Vector3::from(q.x_ref) - Vector3::from(d);
            let (psi, g) = surface.psi_and_gradient(&x);
            let gn = g.norm();
            if !(gn > 0.0 && psi.is_finite() && psi < 0.0) {
                continue;
            }
            // the axis the punch's surface pushes the node along most (its normal there): a
            // punch dragged along x1 still presses along x3
            let axis = (0..3).max_by(|&a, &b| g[a].abs().total_cmp(&g[b].abs())).unwrap_or(2);
            let own = dofs.equation(q.dofs[axis]).is_none();
            let any = own || (0..dpn / 3).any(|s| dofs.equation(q.node * dpn + 3 * s + axis).is_none());
            if !any {
                continue;
            }
            let depth = -psi / gn;
            let allowed = if own { tol } else { SUPPORTED_THINNING * h };
            if depth > allowed {
                let axis_word = ["x1", "x2", "x3"][axis];
                return Err(p.error_at(
                    p.spec.punch[i].span(),
                    &format!("punch[{i}]"),
                    format!(
                        "'{}' presses onto {}, which the supports hold along {axis_word}: at load factor {} its surface lies {} beyond that node's undeformed {}, and a held node cannot give way (the run would end in enormous forces). Move the punch or the supports, or shorten its motion",
                        quote(&setup.punches[i].name),
                        where_node(&setup.mesh, q.node),
                        num(t),
                        num(depth),
                        if own { "contact face" } else { "face (the plate would have to thin by more than a tenth)" }
                    ),
                ));
            }
        }
    }
    Ok(())
}

fn file(p: &Problem) -> String {
    p.path.display().to_string()
}

/// Half the diagonal of the plate's bounding box, at least the thickness.
fn model_size(setup: &Setup) -> f64 {
    let (lo, hi) = setup.mesh.bounding_box();
    (0.5 * ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).sqrt()).max(setup.section.thickness())
}

fn vec3(v: [f64; 3]) -> String {
    format!("({}, {}, {})", num(v[0]), num(v[1]), num(v[2]))
}

// ---------------------------------------------------------------------------------------------
// empty groups

fn check_groups(p: &Problem, mesh: &MeshData) -> Result<()> {
    let s = &p.spec;
    let empty = |span: std::ops::Range<usize>, key: &str, name: &str, what: &str| p.error_at(span, key, format!("the group '{}' {what}", quote(name)));
    for (i, b) in s.boundary.iter().enumerate() {
        let g = &b.get_ref().group;
        if mesh.nodes(g.get_ref()).is_some_and(|n| n.is_empty()) {
            return Err(empty(g.span(), &format!("boundary[{i}].group"), g.get_ref(), "has no nodes: the support holds nothing"));
        }
    }
    for (i, l) in s.load.iter().enumerate() {
        let ls = l.get_ref();
        let (g, key) = (&ls.group, format!("load[{i}].group"));
        let name = g.get_ref();
        match ls.kind {
            LoadKind::Line | LoadKind::Moment => {
                if mesh.curves.get(name).is_some_and(|c| c.is_empty()) {
                    let kind = if ls.kind == LoadKind::Moment { "moment" } else { "line load" };
                    return Err(empty(g.span(), &key, name, &format!("has no edges (2-node lines): a {kind} acts along the edges of a curve group")));
                }
            }
            LoadKind::Surface | LoadKind::Pressure => {
                if mesh.surfaces.get(name).is_some_and(|c| c.is_empty()) {
                    let kind = if ls.kind == LoadKind::Pressure { "pressure" } else { "surface load" };
                    return Err(empty(g.span(), &key, name, &format!("has no cells: a {kind} acts over the cells of a surface group")));
                }
            }
            LoadKind::Point => {
                if mesh.points.get(name).cloned().or_else(|| mesh.nodes(name)).is_some_and(|n| n.is_empty()) {
                    return Err(empty(g.span(), &key, name, "has no nodes: the point load acts nowhere"));
                }
            }
        }
    }
    for (i, pu) in s.punch.iter().enumerate() {
        if let Some(g) = &pu.get_ref().group {
            if mesh.nodes(g.get_ref()).is_some_and(|n| n.is_empty()) {
                return Err(empty(g.span(), &format!("punch[{i}].group"), g.get_ref(), "has no nodes: the punch has no point that may touch"));
            }
        }
    }
    // the plot group as the run reads it (a curve for plot_axis = "arc", any group else)
    if let Some(g) = &s.output.plot_group {
        let name = g.get_ref();
        let found = if s.output.plot_axis == PlotAxis::Arc { mesh.curve_chain(name).is_some() } else { mesh.nodes(name).is_some() };
        if !found {
            let kind = if s.output.plot_axis == PlotAxis::Arc { "curve" } else { "" };
            return Err(crate::model::mesh::group_error(p, g.span(), "output.plot_group", name, kind, mesh));
        }
    }
    Ok(())
}

// ---------------------------------------------------------------------------------------------
// punches at the start

/// The penetration tolerance of punch `i`: its own, or [`DEFAULT_PENETRATION`] h.
fn penetration_tolerance(p: &Problem, setup: &Setup, i: usize) -> f64 {
    p.spec.punch[i].get_ref().penetration_tolerance.as_ref().map(|t| t.get_ref().0).unwrap_or(DEFAULT_PENETRATION * setup.section.thickness())
}

/// Where punch `i` starts; Err when it starts inside the plate.
fn punch_start(p: &Problem, setup: &Setup, i: usize, size: f64) -> Result<PunchStart> {
    let pair = &setup.model.contacts[i];
    let info = &setup.punches[i];
    let key = format!("punch[{i}]");
    let gaps = start_gaps(pair);
    let first = first_gap(&gaps);
    let tol = penetration_tolerance(p, setup, i);
    if let Some(f) = &first {
        if f.gap < -tol {
            let face = face_word(info.face);
            return Err(p.error_at(
                p.spec.punch[i].span(),
                &key,
                format!(
                    "'{}' starts inside the plate: {} deep at {} on the {face} face (x3 = {}), more than the penetration tolerance {}; move the punch out of the plate",
                    quote(&info.name),
                    num(-f.gap),
                    where_node(&setup.mesh, f.node),
                    num(info.z),
                    num(tol)
                ),
            ));
        }
    }
    inside_volume(p, setup, i, &gaps, tol)?;
    let touch = (TOUCH * size).max(p.spec.punch[i].get_ref().penetration_tolerance.as_ref().map(|t| t.get_ref().0).unwrap_or(0.0));
    let mut holding: Vec<PointGap> = gaps.iter().filter(|g| g.gap <= touch).copied().collect();
    let touching = !holding.is_empty();
    if !touching && pair.drive.is_some() {
        if let Some(f) = &first {
            holding = gaps.iter().filter(|g| g.gap <= f.gap + touch).copied().collect();
        }
    }
    Ok(PunchStart { key, name: info.name.clone(), first, holding, touching })
}

/// Err when punch `i` starts inside the plate's volume, between its faces (deeper than the
/// penetration tolerance `tol` from either face): where the flow from a candidate point meets the
/// punch's surface, or a point of the mid-plane under a candidate point inside the punch. The
/// face check above cannot see it (`thickness = 2000` where 2 was meant: the punch sits between
/// the faces, away from both).
fn inside_volume(p: &Problem, setup: &Setup, i: usize, gaps: &[PointGap], tol: f64) -> Result<()> {
    let (dm, dp) = (setup.section.delta_minus, setup.section.delta_plus);
    let pair = &setup.model.contacts[i];
    let info = &setup.punches[i];
    let between = |z: f64| z > dm + tol && z < dp - tol;
    let mid = 0.5 * (dm + dp);
    let found = gaps.iter().find_map(|g| g.foot.filter(|f| between(f[2])).map(|f| (g.node, f[2], "its surface passes")));
    let found = found.or_else(|| {
        gaps.iter().find_map(|g| {
            let x = Vector3::new(g.x[0], g.x[1], mid);
            let (psi, grad) = (pair.surface.psi(&x), pair.surface.gradient(&x).norm());
            (psi < 0.0 && psi.is_finite() && grad.is_finite() && psi < -tol * grad).then_some((g.node, mid, "the mid-plane is inside it"))
        })
    });
    let Some((node, z, what)) = found else { return Ok(()) };
    Err(p.error_at(
        p.spec.punch[i].span(),
        &format!("punch[{i}]"),
        format!(
            "'{}' starts inside the plate's volume: {what} at x3 = {}, on the fibre of {}, between the faces x3 = {} and {} (thickness {}); is plate.thickness right, or the punch's position?",
            quote(&info.name),
            num(z),
            where_node(&setup.mesh, node),
            num(dm),
            num(dp),
            num(dp - dm)
        ),
    ))
}

fn face_word(f: Face) -> &'static str {
    match f {
        Face::Top => "top",
        Face::Bottom => "bottom",
    }
}

/// Outward normal of a face of the plate.
fn face_normal(f: Face) -> Vector3<f64> {
    match f {
        Face::Top => Vector3::new(0.0, 0.0, 1.0),
        Face::Bottom => Vector3::new(0.0, 0.0, -1.0),
    }
}

// ---------------------------------------------------------------------------------------------
// rigid-body motions

/// Err when the supports and the punches at the start leave a rigid motion free; else a line for
/// the summary saying what holds them.
fn check_rigid_modes(p: &Problem, setup: &Setup, starts: &[PunchStart], size: f64) -> Result<String> {
    let (lo, hi) = setup.mesh.bounding_box();
    let (dm, dp) = (setup.section.delta_minus, setup.section.delta_plus);
    let mut modes = RigidModes::new([0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (dm + dp)], size);
    let coords = &setup.mesh.mesh.coords;
    let dofs = &setup.model.dofs;
    let per = dofs.dofs_per_node();
    let layout = crate::model::plate_model::Layout::of(&setup.model.element);
    for (d, &e) in dofs.equations().iter().enumerate() {
        if e == PRESCRIBED {
            let (n, c) = (d / per, d % per);
            // components 0-2: S-, 3-5: S+, then the inner surfaces'
            let z = 0.5 * (dm + dp) + 0.5 * (dp - dm) * layout.zeta_of_component(c);
            modes.hold_component([coords[n][0], coords[n][1], z], c % 3);
        }
    }
    let supports_only = modes.describe_free();
    let with_supports = modes.clone();
    // a frictionless punch meets the flat face tangentially at the first contact: it holds the
    // plate along the face normal x3 only, wherever it touches (the tilt of grad Psi at nodes
    // beside the contact line is the mesh's, not the contact's)
    let mut holders = Vec::new();
    for s in starts {
        for g in &s.holding {
            modes.hold(g.x, FACE_NORMAL_LINE);
        }
        if !s.holding.is_empty() {
            holders.push(format!("'{}'", s.name));
        }
    }
    if let Some(free) = modes.describe_free() {
        let basis = modes.free_basis();
        let involves = |idx: &[usize]| basis.iter().any(|b| idx.iter().any(|&i| b[i].abs() > 1e-6 * b.norm()));
        let mut advice = Vec::new();
        if involves(&[0, 1, 5]) {
            advice.push("fix = [\"v1-\", \"v2-\"] on a point group and fix = [\"v2-\"] on a second point along x1 from it (one face: \"v1\" and \"v2\" hold both faces, which also clamps the fibre's rotation there), or symmetry conditions (symmetry_x1, symmetry_x2 on symmetry edges)");
        }
        if involves(&[2, 3, 4]) {
            advice.push("fix = [\"simply_supported\"] on an edge or on three points not in a line, or a punch touching the plate at the start");
        }
        let why = if holders.is_empty() {
            "no support holds them and no punch touches the plate at the start"
        } else {
            "no support holds them, and a frictionless punch holds the plate only along x3, the normal of the face it first touches"
        };
        return Err(StampError::Input { file: file(p), message: format!("boundary: {free} ({why}): add supports, e.g. {}", advice.join("; ")) });
    }
    check_travels(p, setup, starts, &with_supports)?;
    Ok(match supports_only {
        None => "all six held by the supports".into(),
        Some(_) => format!("all six held by the supports and the punch{} {} at the start", if holders.len() > 1 { "es" } else { "" }, holders.join(", ")),
    })
}

/// The line along which a punch holds the plate at the first contact: the face normal.
const FACE_NORMAL_LINE: [f64; 3] = [0.0, 0.0, 1.0];

/// Err when the travel of a force-driven punch is held by nothing: its direction is across x3
/// (it slides past the plate), or it alone holds a rigid motion of the plate (plate and punch
/// move away together and nothing takes its force). `supports` holds the supports' rows.
fn check_travels(p: &Problem, setup: &Setup, starts: &[PunchStart], supports: &RigidModes) -> Result<()> {
    let driven: Vec<usize> = (0..starts.len()).filter(|&i| setup.model.contacts[i].drive.is_some()).collect();
    if driven.is_empty() {
        return Ok(());
    }
    let mut t = TravelModes::new(supports, driven.len());
    for (i, s) in starts.iter().enumerate() {
        let travel = driven.iter().position(|&j| j == i).map(|k| (k, setup.model.contacts[i].drive.unwrap().direction));
        for g in &s.holding {
            t.hold(g.x, FACE_NORMAL_LINE, travel);
        }
    }
    let Some(f) = t.free().into_iter().next() else { return Ok(()) };
    let names: Vec<String> = driven.iter().zip(&f.travels).filter(|(_, w)| w.abs() > 1e-6).map(|(&i, _)| format!("'{}'", starts[i].name)).collect();
    let (punches, its) = if names.len() == 1 { (format!("the force-driven punch {}", names[0]), "its") } else { (format!("the force-driven punches {}", join_and(&names.iter().map(|s| s.as_str()).collect::<Vec<_>>())), "their") };
    let message = if f.plate_still {
        let dirs: Vec<String> = driven.iter().zip(&f.travels).filter(|(_, w)| w.abs() > 1e-6).map(|(&i, _)| direction_words(&Vector3::from(setup.model.contacts[i].drive.unwrap().direction))).collect();
        format!(
            "boundary: the travel of {punches} (along {}) is held by nothing: at the first contact a frictionless punch pushes the plate only along x3, the normal of the face, and {its} direction has no x3 component; give {its} direction an x3 component, or drive it by motion",
            dirs.join(", ")
        )
    } else {
        format!(
            "boundary: {} together with the travel of {punches} is held by nothing ({punches} alone hold{} the plate there, so nothing takes {its} force): add supports, e.g. fix = [\"simply_supported\"] on an edge or on three points not in a line, or drive {} by motion",
            supports.describe_motion(&f.plate),
            if names.len() == 1 { "s" } else { "" },
            if names.len() == 1 { "it" } else { "them" }
        )
    };
    Err(StampError::Input { file: file(p), message })
}

// ---------------------------------------------------------------------------------------------
// warnings

fn punch_warnings(p: &Problem, setup: &Setup, starts: &[PunchStart]) -> Vec<String> {
    let mut out = Vec::new();
    let h = setup.section.thickness();
    for (i, (info, pair)) in setup.punches.iter().zip(&setup.model.contacts).enumerate() {
        let head = format!("{}: punch[{i}] ('{}')", stamp::show_path(&p.path), quote(&info.name));
        let n_face = face_normal(info.face);
        let face = face_word(info.face);
        let sign = if info.face == Face::Top { "+" } else { "-" };
        let mut wrong_side = false;
        // the punch is on the other side of the plate
        let other = match info.face {
            Face::Top => (Face::Bottom, setup.section.delta_minus),
            Face::Bottom => (Face::Top, setup.section.delta_plus),
        };
        let other_first = pair
            .points
            .iter()
            .filter_map(|q| gap_at(&*pair.surface, &Vector3::new(q.x_ref[0], q.x_ref[1], other.1)).map(|g| g.0))
            .fold(f64::INFINITY, f64::min);
        if let Some(first) = starts[i].first {
            if other_first < first.gap - 0.5 * h {
                wrong_side = true;
                out.push(format!(
                    "{head}: it is on the {} side of the plate (first gap {} to the {} face) but its contact face is the {face} face (first gap {}): set face = \"{}\"?",
                    face_word(other.0),
                    num(other_first),
                    face_word(other.0),
                    num(first.gap),
                    face_word(other.0)
                ));
            }
        }
        // the prescribed motion or force moves it away from its face (said only when the punch is
        // on the face's side: else the warning above says what is wrong)
        let (push, what) = match &pair.drive {
            Some(f) => (Vector3::from(f.direction) * f.force, format!("its force {} along {}", num(f.force), vec3(f.direction))),
            None => (Vector3::from(pair.motion.approach()), format!("its {}", motion_words(&pair.motion))),
        };
        if !wrong_side && push.norm() > 0.0 && push.dot(&n_face) > 1e-9 * push.norm() {
            out.push(format!("{head}: {what} moves it away from its contact face ({face}, outward normal {sign}x3): it will not press the plate"));
        }
        out.extend(crate::checks::psi_checks::sweep_warning(p, setup, i));
    }
    out
}

/// After a run, from `summary` (summary.json), one warning each: a punch that had no node in
/// contact at any recorded step, and a punch whose loaded zone at the last step is narrower than
/// the cells (see [`crate::outputs::output::narrower_than_cells`]).
pub fn after_the_run(p: &Problem, summary: &Path) -> Vec<String> {
    let Ok(Some(text)) = crate::run::regular::read_regular(summary) else { return Vec::new() };
    let Ok(json) = serde_json::from_str::<serde_json::Value>(&text) else { return Vec::new() };
    let Some(steps) = json["steps"].as_array() else { return Vec::new() };
    let converged: Vec<&serde_json::Value> = steps.iter().filter(|s| s["converged"] == serde_json::Value::Bool(true)).collect();
    if converged.is_empty() {
        return Vec::new();
    }
    let mut out = Vec::new();
    for i in 0..p.spec.punch.len() {
        let name = p.punch_name(i);
        let counts: Vec<u64> = converged.iter().filter_map(|s| s["punches"][&name]["active_nodes"].as_u64()).collect();
        if let Some(last) = converged.last() {
            if last["punches"][&name]["zone_narrower_than_cells"] == serde_json::Value::Bool(true) {
                out.push(format!(
                    "{}: punch[{i}] ('{}') touches the plate on a zone narrower than the cells (a line or ring of nodes, none with all its neighbours in contact) at the last step: its peak pressure depends on the mesh and will not converge as the cells shrink; the force does, and so does the load per unit length: across a straight line what a probe across it reads (column {}_line_load), around a ring the force over the ring's circumference",
                    file(p),
                    quote(&name),
                    name
                ));
            }
        }
        if counts.len() == converged.len() && counts.iter().all(|&c| c == 0) {
            out.push(format!(
                "{}: punch[{i}] ('{}') never touched the plate: no node was in contact at any of the {} recorded steps; check its position, motion and face",
                stamp::show_path(&p.path),
                quote(&name),
                converged.len()
            ));
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// summary

/// Total force of load `i` at load factor 1.
fn load_total(p: &Problem, mesh: &MeshData, i: usize) -> [f64; 3] {
    let ls = p.spec.load[i].get_ref();
    let name = ls.group.get_ref();
    let area = |cells: &[usize]| cells.iter().map(|&c| stamp::mesh::quad_signed_area(&mesh.mesh.cell_coords(c)).abs()).sum::<f64>();
    match ls.kind {
        LoadKind::Line => {
            let len: f64 = mesh.curves.get(name).map(|s| s.iter().map(|s| {
                let (a, b) = (mesh.mesh.coords[s[0]], mesh.mesh.coords[s[1]]);
                (a[0] - b[0]).hypot(a[1] - b[1])
            }).sum()).unwrap_or(0.0);
            ls.force.unwrap().0.map(|f| f * len)
        }
        LoadKind::Surface => {
            let a = mesh.surfaces.get(name).map(|c| area(c)).unwrap_or(0.0);
            ls.force.unwrap().0.map(|f| f * a)
        }
        LoadKind::Pressure => {
            let total = match ls.pressure.as_ref().unwrap().get_ref() {
                crate::schema::PressureSpec::Uniform(q) => q * mesh.surfaces.get(name).map(|c| area(c)).unwrap_or(0.0),
                spec => {
                    let q = crate::model::pressure::pressure_function(spec, 1.0);
                    let cells = mesh.surfaces.get(name).cloned().unwrap_or_default();
                    let mut f = 0.0;
                    for &c in &cells {
                        let x = mesh.mesh.cell_coords(c);
                        for (s, t) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)].map(|(s, t): (f64, f64)| (s * 0.577_350_269_189_625_8, t * 0.577_350_269_189_625_8)) {
                            let (n, dn) = stamp::mesh::bilinear(s, t);
                            let at = |i: usize| (0..4).map(|a| n[a] * x[a][i]).sum::<f64>();
                            f += q(at(0), at(1)) * stamp::mesh::bilinear_jacobian(&x, &dn).abs();
                        }
                    }
                    f
                }
            };
            [0.0, 0.0, if ls.face == Some(LoadFace::Top) { -total } else { total }]
        }
        // a couple: force pairs without resultant
        LoadKind::Moment => [0.0; 3],
        LoadKind::Point => {
            let n = mesh.points.get(name).cloned().or_else(|| mesh.nodes(name)).map(|v| v.len()).unwrap_or(0);
            ls.force.unwrap().0.map(|f| f * n as f64)
        }
    }
}

/// What kind of group `name` is, with its size.
fn group_line(mesh: &MeshData, name: &str) -> String {
    let nodes = plural(mesh.nodes(name).map(|v| v.len()).unwrap_or(0), "node");
    if let Some(c) = mesh.surfaces.get(name) {
        format!("surface, {nodes}, {}", plural(c.len(), "cell"))
    } else if let Some(c) = mesh.curves.get(name) {
        format!("curve, {nodes}, {}", plural(c.len(), "edge"))
    } else if mesh.points.contains_key(name) {
        format!("point, {nodes}")
    } else {
        nodes
    }
}

/// "1 node", "3 nodes".
fn plural(n: usize, word: &str) -> String {
    format!("{n} {word}{}", if n == 1 { "" } else { "s" })
}

fn summary(p: &Problem, setup: &Setup, starts: &[PunchStart], rigid: &str) -> String {
    let s = &p.spec;
    let mesh = &setup.mesh;
    let mut o = String::new();
    let _ = writeln!(o, "problem: {}", p.path.display());
    if let Some(t) = &s.title {
        let _ = writeln!(o, "title: {}", quote(t));
    }
    let spec = s.mesh.get_ref();
    let source = match (&spec.file, &spec.rectangle) {
        _ if p.given_mesh.is_some() => "given as arrays".to_string(),
        (Some(f), _) => format!("gmsh file {}", quote(f.get_ref())),
        (None, Some(r)) => format!("rectangle x = [{}, {}], y = [{}, {}], {} x {} cells", num(r.x[0]), num(r.x[1]), num(r.y[0]), num(r.y[1]), r.n[0], r.n[1]),
        (None, None) => "none".to_string(),
    };
    let _ = writeln!(o, "mesh: {source}: {} nodes, {} elements", mesh.mesh.num_nodes(), mesh.mesh.num_cells());
    if let Some(split) = &mesh.split {
        let _ = writeln!(o, "  cut into 4-node plate elements: {split}");
    }
    let ps = s.plate.get_ref();
    if let Some((lam, per_layer)) = setup.model.element.laminate() {
        let _ = writeln!(
            o,
            "plate: {} layers of {per_layer} surfaces each ({} surfaces, the 3D law of each layer), thickness {} (x3 from {} to {}), {}{}",
            lam.plies.len(),
            setup.model.element.surfaces(),
            num(setup.section.thickness()),
            num(setup.section.delta_minus),
            num(setup.section.delta_plus),
            format!("{:?}", ps.kinematics).to_lowercase(),
            if ps.plane_strain { ", plane strain" } else { "" },
        );
        for line in crate::model::laminate_spec::describe(p, lam, per_layer) {
            let _ = writeln!(o, "  {line}");
        }
    } else {
        let _ = writeln!(
            o,
            "plate: {}, thickness {} (x3 from {} to {}), E = {}, nu = {}, {}{}{}{}",
            match setup.model.element.surfaces() {
                2 => "two surfaces (the paper's plate)".to_string(),
                n if setup.model.element.is_plastic() => format!("{n} surfaces (displacement of degree {} through the thickness, 3D law), elastic-plastic", n - 1),
                n => format!("{n} surfaces (displacement of degree {} through the thickness, 3D law)", n - 1),
            },
            num(setup.section.thickness()),
            num(setup.section.delta_minus),
            num(setup.section.delta_plus),
            num(setup.section.layers[0].material.young),
            num(setup.section.layers[0].material.poisson),
            format!("{:?}", ps.kinematics).to_lowercase(),
            if ps.plane_strain { ", plane strain" } else { "" },
            if setup.section.normal_stress == stamp_elements::NormalStress::Mean { ", mean S33 in the in-plane law" } else { "" },
            if setup.section.shear_factor != 1.0 { format!(", shear factor {}", num(setup.section.shear_factor)) } else { String::new() }
        );
    }
    let nodal = setup.model.dofs.num_equations();
    let drives = setup.model.num_drives();
    let _ = writeln!(
        o,
        "unknowns: {} equations ({nodal} nodal of {} dofs, {} held by supports; {drives} punch travel{})",
        setup.model.num_equations(),
        setup.model.dofs.num_dofs(),
        setup.model.dofs.num_dofs() - nodal,
        if drives == 1 { "" } else { "s" }
    );
    // groups in use
    let mut groups: Vec<(String, Vec<String>)> = Vec::new();
    let mut use_group = |name: &str, key: String| match groups.iter_mut().find(|g| g.0 == name) {
        Some(g) => g.1.push(key),
        None => groups.push((name.to_string(), vec![key])),
    };
    for (i, b) in s.boundary.iter().enumerate() {
        use_group(b.get_ref().group.get_ref(), format!("boundary[{i}]"));
    }
    for (i, l) in s.load.iter().enumerate() {
        use_group(l.get_ref().group.get_ref(), format!("load[{i}]"));
    }
    for (i, pu) in s.punch.iter().enumerate() {
        if let Some(g) = &pu.get_ref().group {
            use_group(g.get_ref(), format!("punch[{i}]"));
        }
    }
    if !groups.is_empty() {
        let _ = writeln!(o, "groups:");
        for (name, keys) in &groups {
            let _ = writeln!(o, "  '{}' ({}): {}", quote(name), group_line(mesh, name), keys.join(", "));
        }
    }
    let _ = writeln!(o, "supports:");
    if ps.plane_strain {
        let _ = writeln!(o, "  plate.plane_strain: v1- = v1+ = 0 at every node");
    }
    for (i, b) in s.boundary.iter().enumerate() {
        let bs = b.get_ref();
        let mut what: Vec<String> = Vec::new();
        if !bs.fix.is_empty() {
            what.push(format!("fix {}", bs.fix.iter().map(|d| d.word.as_str()).collect::<Vec<_>>().join(", ")));
        }
        let factor = if bs.path.is_some() { "its path's factor" } else { "load factor" };
        for (k, v) in &bs.prescribe {
            what.push(format!("{} = {} x {factor}", k.0, num(v.0)));
        }
        let _ = writeln!(o, "  boundary[{i}] on '{}': {}", quote(bs.group.get_ref()), what.join("; "));
    }
    if s.boundary.is_empty() && !ps.plane_strain {
        let _ = writeln!(o, "  none");
    }
    if !s.load.is_empty() {
        let _ = writeln!(o, "loads (at load factor 1):");
        let mut sum = [0.0; 3];
        for (i, l) in s.load.iter().enumerate() {
            let ls = l.get_ref();
            let t = load_total(p, mesh, i);
            for c in 0..3 {
                sum[c] += t[c];
            }
            let kind = format!("{:?}", ls.kind).to_lowercase();
            let face = format!("{:?}", ls.face.unwrap_or_default()).to_lowercase();
            let follows = match (ls.follower, ls.path.is_some()) {
                (true, false) => " (follower: in the reference state)",
                (true, true) => " (follower: in the reference state; times its path's factor, not the load factor)",
                (false, true) => " (times its path's factor, not the load factor)",
                (false, false) => "",
            };
            if ls.kind == LoadKind::Moment {
                let m = ls.moment.map(|m| m.0).unwrap_or([0.0; 3]);
                let _ = writeln!(o, "  load[{i}]: moment on '{}', per unit length {}{follows}: total force 0", quote(ls.group.get_ref()), vec3(m));
            } else {
                let _ = writeln!(o, "  load[{i}]: {kind} on '{}', face {face}: total force {}{follows}", quote(ls.group.get_ref()), vec3(t));
            }
        }
        let _ = writeln!(o, "  all loads: total force {}", vec3(sum));
    }
    if !setup.punches.is_empty() {
        let _ = writeln!(o, "punches:");
    }
    for (i, ((info, pair), st)) in setup.punches.iter().zip(&setup.model.contacts).zip(starts).enumerate() {
        let mut drive = match &pair.drive {
            Some(f) => format!("driven by force {} along {}", num(f.force), vec3(f.direction)),
            None => format!("driven by {}", motion_words(&pair.motion)),
        };
        if let Some(r) = &pair.rotation {
            let (t, last) = r.rows().last().copied().unwrap_or((0.0, 0.0));
            let _ = write!(drive, ", turning about {} through {} ({} degrees from t = {})", vec3(r.axis()), vec3(r.pivot()), num(last), num(t));
        }
        let gap = match &st.first {
            Some(f) => format!(
                "first gap {} at {}{}",
                num(f.gap),
                where_node(mesh, f.node),
                if st.touching { format!(" (touching at {})", plural(st.holding.len(), "node")) } else { String::new() }
            ),
            None => "no first gap".into(),
        };
        let _ = writeln!(
            o,
            "  punch[{i}] '{}': {}, {} face (x3 = {}), {drive}, {} candidate nodes, {gap}",
            quote(&info.name),
            info.surface.describe(),
            face_word(info.face),
            num(info.z),
            pair.points.len()
        );
    }
    let _ = writeln!(o, "rigid-body motions: {rigid}");
    let targets = &setup.targets;
    let _ = write!(o, "load factors: {} target{} up to {}", targets.len(), if targets.len() == 1 { "" } else { "s" }, num(targets.iter().cloned().fold(0.0, f64::max)));
    if let Some(coarse) = &setup.coarse {
        let _ = write!(
            o,
            "\npredictor: every step starts from the solution on the coarse mesh ({} nodes, {} elements, {} equations), solved first",
            coarse.setup.mesh.mesh.num_nodes(),
            coarse.setup.mesh.mesh.num_cells(),
            coarse.setup.model.num_equations()
        );
    }
    o
}

/// "motion [..]" or "path of N points (approach [..], last displacement [..] at t = ..)".
fn motion_words(m: &stamp::contact::PunchMotion) -> String {
    match m {
        stamp::contact::PunchMotion::Linear(v) => format!("motion {}", vec3(*v)),
        stamp::contact::PunchMotion::Path(points) => {
            let (t, last) = points.last().copied().unwrap_or((0.0, [0.0; 3]));
            format!("path of {} points (approach {}, last displacement {} from t = {})", points.len(), vec3(m.approach()), vec3(last), num(t))
        }
    }
}

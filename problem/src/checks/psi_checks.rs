//! Checks of a punch's Psi that the contact code cannot make itself: a Psi without a usable
//! gradient, at the start (`stamp check` and `stamp run`) and after every step, and a motion that
//! carries the punch through the plate between two converged load factors.
//!
//! * **A usable gradient.** The contact force of a point is w lambda grad Psi with
//!   lambda = eps_reg Psi and eps_reg ~ 1 / |grad Psi|^2: where |grad Psi| is zero, not finite, or
//!   so small that its square underflows (below [`MIN_GRADIENT`]; an expression scaled by 1e-170),
//!   a point inside the punch pushes with no force and the step "converges" with the punch in the
//!   plate (so does a point gone down to a cylinder's side under shallow contact kinematics, whose
//!   gradient is grad Psi . e3 e3).
//!   A gradient that puts the surface more than [`FAR`] model sizes away (|Psi| / |grad Psi|) is no
//!   surface near the plate either. [`check_expression`] samples the candidate points along the
//!   prescribed motion before the solve; [`after_step`] refuses an active point without one.
//! * **Through the plate within one step.** A motion path may carry the punch down through the
//!   plate and out again between two load factors the solver visits: both ends converge with no
//!   contact. [`after_step`] samples the motion inside every converged step (its path rows and
//!   [`SWEEP_SAMPLES`] points between), with the plate as at either end of the step, and stops
//!   the run when the punch reaches the plate's far face (the other face than its contact face)
//!   there, with the plate at both ends, but not at the step's ends.

use crate::checks::rigid_modes::num;
use crate::model::build::Setup;
use crate::model::mesh::MeshData;
use crate::model::mesh::where_node;
use crate::model::plate_model::Layout;
use crate::schema::{Problem, Shape};
use nalgebra::Vector3;
use stamp::contact::{ContactPair, PunchMotion, PunchRotation};
use stamp::surface::ContactSurface;
use stamp::{quote, Result, StampError};
use stamp_elements::Face;

/// Smallest |grad Psi| whose square is a normal floating-point number, with room to spare.
pub const MIN_GRADIENT: f64 = 1e-150;
/// Largest |grad Psi| whose square stays finite, with room to spare.
pub const MAX_GRADIENT: f64 = 1e150;
/// A surface farther than this many model sizes from a point (|Psi| / |grad Psi|) is no surface
/// near the plate.
pub const FAR: f64 = 1e12;
/// Load factors sampled inside a step for [`after_step`] (besides the path's rows there).
pub const SWEEP_SAMPLES: usize = 16;
/// Load factors sampled along the motion at the start for [`check_expression`], at most.
const MOTION_SAMPLES: usize = 64;

/// |g| without underflow or overflow in the squares (scaled by its largest component).
pub fn robust_norm(g: &Vector3<f64>) -> f64 {
    let m = g.amax();
    if m == 0.0 || !m.is_finite() {
        return m;
    }
    m * (g / m).norm()
}

/// Whether Psi = `psi` with gradient `g` has a gradient the contact force can use at a model of
/// size `size` (see the module notes); else what is wrong with it.
pub fn gradient_problem(psi: f64, g: &Vector3<f64>, size: f64) -> Option<String> {
    let gn = robust_norm(g);
    if !psi.is_finite() || !g.iter().all(|c| c.is_finite()) {
        return Some(format!("Psi = {} with gradient ({}, {}, {}) is not finite", num(psi), num(g.x), num(g.y), num(g.z)));
    }
    if gn == 0.0 {
        return Some("|grad Psi| = 0 (Psi is constant there)".into());
    }
    if gn < MIN_GRADIENT {
        return Some(format!("|grad Psi| = {gn:e} underflows (its square is below the smallest normal number: Psi is scaled too small)"));
    }
    if gn > MAX_GRADIENT {
        return Some(format!("|grad Psi| = {gn:e} overflows in its square (Psi is scaled too large)"));
    }
    if psi.abs() > FAR * size * gn {
        return Some(format!("Psi / |grad Psi| = {} puts the surface more than {FAR:e} model sizes away", num(psi / gn)));
    }
    None
}

/// The load factors at which the start check samples the motion: 0, the targets, the path's rows
/// up to the largest target and points between them, at most `most` (and [`MOTION_SAMPLES`]) and
/// the last.
fn motion_samples(motion: &PunchMotion, rotation: Option<&PunchRotation>, targets: &[f64], most: usize) -> Vec<f64> {
    let end = targets.iter().cloned().fold(0.0, f64::max);
    let mut t: Vec<f64> = std::iter::once(0.0).chain(targets.iter().copied()).collect();
    if let PunchMotion::Path(rows) = motion {
        t.extend(rows.iter().map(|r| r.0).filter(|&r| r <= end));
    }
    if let Some(r) = rotation {
        t.extend(r.rows().iter().map(|r| r.0).filter(|&r| r <= end));
    }
    t.sort_by(f64::total_cmp);
    t.dedup();
    let mut all = Vec::new();
    for w in t.windows(2) {
        for k in 0..4 {
            all.push(w[0] + (w[1] - w[0]) * k as f64 / 4.0);
        }
    }
    all.extend(t.last());
    let most = most.clamp(1, MOTION_SAMPLES);
    if all.len() > most {
        let step = all.len() as f64 / most as f64;
        all = (0..most).map(|k| all[(k as f64 * step) as usize]).chain(all.last().copied()).collect();
    }
    all
}

/// Err when the expression punch `i` has no usable gradient where it matters: at no candidate
/// point along its motion (a constant Psi, or one scaled until its gradient underflows: no
/// surface), or at a point it covers (Psi <= 0) somewhere along the motion (that point would be
/// active with no force). Other shapes have analytic gradients checked by their constructors.
pub fn check_expression(p: &Problem, setup: &Setup, i: usize, size: f64) -> Result<()> {
    let spec = p.spec.punch[i].get_ref();
    let (Shape::Expression, Some(psi_key)) = (spec.shape, spec.psi.as_ref()) else { return Ok(()) };
    let pair = &setup.model.contacts[i];
    // (about 2 million evaluations at most: a few seconds on the largest meshes)
    let most = 2_000_000 / pair.points.len().max(1);
    let samples = if pair.drive.is_some() { vec![0.0] } else { motion_samples(&pair.motion, pair.rotation.as_ref(), &setup.targets, most) };
    let mut usable = false;
    let mut covered_without: Option<(usize, f64, String)> = None;
    let mut first_problem: Option<String> = None;
    for &t in &samples {
        let d = Vector3::from(pair.motion.displacement(t));
        let surface = pair.surface_at(t);
        for q in &pair.points {
            let x = Vector3::from(q.x_ref) - d;
            let (psi, g) = surface.psi_and_gradient(&x);
            match gradient_problem(psi, &g, size) {
                None => usable = true,
                Some(what) => {
                    if psi <= 0.0 && covered_without.is_none() {
                        covered_without = Some((q.node, t, what.clone()));
                    }
                    first_problem.get_or_insert(what);
                }
            }
        }
    }
    let key = format!("punch[{i}].psi");
    let name = quote(&setup.punches[i].name);
    if !usable {
        let what = first_problem.unwrap_or_default();
        return Err(p.error_at(
            psi_key.span(),
            &key,
            format!("'{name}' has no surface near the plate: at every candidate point along its motion Psi has no usable gradient (the first: {what}); write Psi like a distance (negative inside the punch, changing sign on its surface, gradient of order 1)"),
        ));
    }
    if let Some((node, t, what)) = covered_without {
        return Err(p.error_at(
            psi_key.span(),
            &key,
            format!(
                "'{name}' covers {} at load factor {} (Psi <= 0) where {what}: a point in contact there would push with no force; write Psi like a distance (gradient of order 1)",
                crate::model::mesh::where_node(&setup.mesh, node),
                num(t)
            ),
        ));
    }
    Ok(())
}

/// For `stamp check`: a warning when the motion of punch `i` carries it through the undeformed
/// plate within one of the largest increments the solver may take (steps of `max_increment`
/// towards each target), which the run would then refuse after that step.
pub fn sweep_warning(p: &Problem, setup: &Setup, i: usize) -> Option<String> {
    let c = &setup.model.contacts[i];
    if c.drive.is_some() || (c.motion.is_zero() && c.rotation.is_none()) {
        return None;
    }
    let layout = Layout::of(&setup.model.element);
    let zero = vec![0.0; stamp::nonlinear::NonlinearProblem::num_dofs(&setup.model)];
    let max_inc = setup.settings.max_increment;
    let (mut t, mut k) = (0.0f64, 0usize);
    for &target in &setup.targets {
        while t != target {
            let next = if (target - t).abs() <= max_inc { target } else { t + max_inc.copysign(target - t) };
            k += 1;
            if let Some(e) = swept_through(p, &setup.mesh, c, i, &layout, k, (t, &zero), (next, &zero)) {
                let message = match e {
                    StampError::Input { message, .. } => message,
                    e => e.to_string(),
                };
                // the first line, without the file's place (the warning names the file)
                let first = message.lines().next().unwrap_or("").to_string();
                return Some(format!("{}: increments of max_increment = {}: {}; the run stops there", stamp::show_path(&p.path), num(max_inc), first.split_once(": ").map_or(first.as_str(), |x| x.1)));
            }
            t = next;
        }
    }
    None
}

/// The checks after a converged step from load factor `t0` (state `u0`) to `t1` (state `u1`):
/// an active point without a usable gradient, and a punch carried through the plate between the
/// two (see the module notes). `step` is the step's number as the outputs count it.
#[allow(clippy::too_many_arguments)]
pub fn after_step(p: &Problem, mesh: &MeshData, contacts: &[ContactPair], layout: &Layout, size: f64, step: usize, (t0, u0): (f64, &[f64]), (t1, u1): (f64, &[f64])) -> Option<StampError> {
    let file = || p.path.display().to_string();
    for (i, c) in contacts.iter().enumerate() {
        // (a touching point, Psi = 0, loses nothing without a gradient; a penetrating one does)
        let bad = c.state.iter().zip(&c.points).find_map(|(s, q)| if s.active && !(s.psi >= 0.0) { gradient_problem(s.psi, &Vector3::from(s.grad), size).map(|w| (q.node, w)) } else { None });
        if let Some((node, what)) = bad {
            return Some(StampError::Input {
                file: file(),
                message: format!(
                    "punch[{i}] ('{}'): at step {step} (load factor {}) {} is inside the punch where {what}: its contact force is zero and the answer would be wrong (a constant or badly scaled psi, or, with shallow contact kinematics, a point gone down to a cylinder's or sphere's side: use smaller increments or kinematics = \"exact\")",
                    quote(&c.name),
                    num(t1),
                    where_node(mesh, node)
                ),
            });
        }
        if c.drive.is_some() || (c.motion.is_zero() && c.rotation.is_none()) {
            continue;
        }
        if let Some(e) = swept_through(p, mesh, c, i, layout, step, (t0, u0), (t1, u1)) {
            return Some(e);
        }
    }
    None
}

/// Err when punch `i`'s motion between `t0` and `t1` reaches the plate's far face at a load factor
/// inside the step but at neither end.
#[allow(clippy::too_many_arguments)]
fn swept_through(p: &Problem, mesh: &MeshData, c: &ContactPair, i: usize, layout: &Layout, step: usize, (t0, u0): (f64, &[f64]), (t1, u1): (f64, &[f64])) -> Option<StampError> {
    let (lo, hi) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
    let mut rows: Vec<(usize, f64)> = match &c.motion {
        PunchMotion::Path(points) => points.iter().enumerate().filter(|(_, r)| r.0 > lo && r.0 < hi).map(|(k, r)| (k, r.0)).collect(),
        PunchMotion::Linear(_) => Vec::new(),
    };
    // a rotation's rows are where the punch turns differently too
    if let Some(r) = &c.rotation {
        rows.extend(r.rows().iter().enumerate().filter(|(_, r)| r.0 > lo && r.0 < hi).map(|(k, r)| (k, r.0)));
        rows.sort_by(|a, b| a.1.total_cmp(&b.1));
        rows.dedup_by(|a, b| a.1 == b.1);
    }
    let mut samples: Vec<f64> = (1..SWEEP_SAMPLES).map(|k| lo + (hi - lo) * k as f64 / SWEEP_SAMPLES as f64).chain(rows.iter().map(|r| r.1)).collect();
    samples.sort_by(f64::total_cmp);
    // the face offsets: a point's far face is the other one than its contact face (x_ref's x3)
    let h = p.spec.plate.get_ref();
    let (dm, dp) = match h.thickness {
        Some(t) => (-0.5 * t.0, 0.5 * t.0),
        None => (h.delta_minus.map_or(0.0, |x| x.0), h.delta_plus.map_or(0.0, |x| x.0)),
    };
    let inside = |t: f64, u: &dyn Fn(usize) -> f64| -> Option<usize> {
        let d = Vector3::from(c.motion.displacement(t));
        c.points.iter().find_map(|q| {
            let top = (q.x_ref[2] - dp).abs() <= (q.x_ref[2] - dm).abs();
            let other = if top { Face::Bottom } else { Face::Top };
            let z = if top { dm } else { dp };
            let x = Vector3::new(q.x_ref[0] + u(layout.face_dof(other, q.node, 0)), q.x_ref[1] + u(layout.face_dof(other, q.node, 1)), z + u(layout.face_dof(other, q.node, 2)));
            let (psi, g) = c.surface_at(t).psi_and_gradient(&(x - d));
            let gn = robust_norm(&g);
            (psi < 0.0 && gn > 0.0 && psi / gn < -1e-9 * (dp - dm)).then_some(q.node)
        })
    };
    // to reach the far face from outside the plate the punch moves at least half the thickness
    // (its penetration at a converged end is far below that): shorter motions need no samples
    let mut knots: Vec<f64> = std::iter::once(lo).chain(rows.iter().map(|r| r.1)).chain(std::iter::once(hi)).collect();
    knots.dedup();
    let mut travel: f64 = knots.windows(2).map(|w| Vector3::from(c.motion.displacement(w[1])).metric_distance(&Vector3::from(c.motion.displacement(w[0])))).sum();
    if let Some(r) = &c.rotation {
        // the arc a candidate point's place on the punch sweeps as the punch turns
        let pivot = Vector3::from(r.pivot());
        let reach = c.points.iter().map(|q| Vector3::from(q.x_ref).metric_distance(&pivot)).fold(0.0, f64::max);
        travel += knots.windows(2).map(|w| (r.angle(w[1]) - r.angle(w[0])).abs().to_radians() * reach).sum::<f64>();
    }
    if travel < 0.5 * (dp - dm) {
        return None;
    }
    let end0 = |k: usize| u0[k];
    let end1 = |k: usize| u1[k];
    if inside(t0, &end0).is_some() || inside(t1, &end1).is_some() {
        return None;
    }
    for &t in &samples {
        // the plate as at either end of the step (not interpolated: a bent plate's points
        // interpolated linearly cut the chord, towards a punch it wraps)
        if let Some(node) = inside(t, &end0).filter(|_| inside(t, &end1).is_some()) {
            let rows_text = match rows.as_slice() {
                [] => String::new(),
                [(_, t)] => format!(" (the path's row at t = {} lies inside the step)", num(*t)),
                ts => format!(" (the path's rows from t = {} to {} lie inside the step)", num(ts[0].1), num(ts[ts.len() - 1].1)),
            };
            // an increment that moves the punch by at most half the thickness and does not skip
            // over a path row's turn
            let dist = |a: [f64; 3], b: [f64; 3]| Vector3::from(a).metric_distance(&Vector3::from(b));
            let (speed, shortest) = match &c.motion {
                PunchMotion::Path(points) => points.windows(2).fold((0.0f64, f64::INFINITY), |(v, l), w| {
                    let dt = w[1].0 - w[0].0;
                    (v.max(dist(w[0].1, w[1].1) / dt), l.min(dt))
                }),
                PunchMotion::Linear(m) => (Vector3::from(*m).norm(), f64::INFINITY),
            };
            let advice = (0.5 * (dp - dm) / speed).min(0.5 * shortest);
            return Some(p.error_at(
                p.spec.punch[i].span(),
                &format!("punch[{i}].motion"),
                format!(
                    "step {step} from load factor {} to {}: the motion carries '{}' through the plate (at load factor {} it reaches the far face at {}), which neither end of the step sees{rows_text}; use more steps: [solver] max_increment at most {} (the punch then moves at most half the thickness per increment and stops at every path row)",
                    num(t0),
                    num(t1),
                    quote(&c.name),
                    num(t),
                    where_node(mesh, node),
                    num(advice)
                ),
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gradient_is_usable_when_its_square_is_a_normal_number_and_the_surface_is_near() {
        let g = |s: f64| Vector3::new(0.0, 0.0, s);
        assert!(gradient_problem(-1.0, &g(1.0), 10.0).is_none());
        assert!(gradient_problem(-1e-170, &g(1e-172), 10.0).unwrap().contains("underflows"));
        assert!(gradient_problem(-1.0, &g(0.0), 10.0).unwrap().contains("= 0"));
        assert!(gradient_problem(f64::NAN, &g(1.0), 10.0).unwrap().contains("not finite"));
        assert!(gradient_problem(1.0, &g(1e160), 10.0).unwrap().contains("overflows"));
        assert!(gradient_problem(1.0, &g(1e-20), 10.0).unwrap().contains("model sizes away"));
        // the robust norm of a tiny vector is not 0 (nalgebra's norm squares first)
        assert_eq!(Vector3::new(1e-172, 0.0, 0.0).norm(), 0.0);
        assert!((robust_norm(&Vector3::new(3e-172, 4e-172, 0.0)) / 5e-172 - 1.0).abs() < 1e-12);
    }

    #[test]
    fn motion_samples_hold_the_targets_and_the_path_rows() {
        let path = PunchMotion::path(&[(0.3, [0.0, 0.0, -1.0]), (0.7, [0.0, 0.0, 0.0]), (2.0, [0.0, 0.0, -5.0])]).unwrap();
        let t = motion_samples(&path, None, &[0.5, 1.0], MOTION_SAMPLES);
        for want in [0.0, 0.3, 0.5, 0.7, 1.0] {
            assert!(t.contains(&want), "{want} not in {t:?}");
        }
        assert!(t.iter().all(|&x| x <= 1.0), "{t:?}");
        let many: Vec<f64> = (1..=1000).map(|k| k as f64 / 1000.0).collect();
        let t = motion_samples(&PunchMotion::Linear([0.0, 0.0, -1.0]), None, &many, MOTION_SAMPLES);
        assert!(t.len() <= MOTION_SAMPLES + 1 && t[0] == 0.0 && *t.last().unwrap() == 1.0, "{}", t.len());
    }

    /// A strip under a cylinder built from a problem text, and a point of it put inside the punch
    /// with a zero gradient: the check after the step refuses it.
    #[test]
    fn a_penetrating_active_point_without_a_gradient_stops_the_run() {
        let dir = std::env::temp_dir().join(format!("stamp-psi-checks-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let text = "[mesh]\nrectangle = { x = [0.0, 1.0], y = [0.0, 10.0], n = [1, 4] }\n[plate]\nthickness = 1.0\nE = 1000.0\nnu = 0.3\n\
                    [[boundary]]\ngroup = \"bottom\"\nfix = [\"clamped\"]\n[[punch]]\nshape = \"cylinder\"\npoint = [0.0, 5.0, 3.0]\naxis = [1.0, 0.0, 0.0]\nradius = 2.5\nmotion = [0.0, 0.0, -1.0]\n";
        let path = dir.join("strip.toml");
        std::fs::write(&path, text).unwrap();
        let p = Problem::read(&path).unwrap();
        let mut setup = crate::model::build::build(&p).unwrap();
        let layout = Layout::of(&setup.model.element);
        let n = stamp::nonlinear::NonlinearProblem::num_dofs(&setup.model);
        let u = vec![0.0; n];
        let c = &mut setup.model.contacts[0];
        assert!(after_step(&p, &setup.mesh, std::slice::from_ref(c), &layout, 10.0, 1, (0.0, &u), (0.5, &u)).is_none());
        c.state[3] = stamp::contact::PointState { psi: -0.5, grad: [0.0; 3], lambda: 0.0, active: true };
        let e = after_step(&p, &setup.mesh, std::slice::from_ref(c), &layout, 10.0, 1, (0.0, &u), (0.5, &u)).unwrap().to_string();
        assert!(e.contains("strip.toml") && e.contains("punch[0]") && e.contains("step 1") && e.contains("|grad Psi| = 0"), "{e}");
        // touching (Psi = 0) loses nothing
        c.state[3].psi = 0.0;
        assert!(after_step(&p, &setup.mesh, std::slice::from_ref(c), &layout, 10.0, 1, (0.0, &u), (0.5, &u)).is_none());
        let _ = std::fs::remove_dir_all(&dir);
    }
}

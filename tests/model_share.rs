//! A model evaluated by several processes, each its own share (stamp::share): three threads stand
//! for three processes, with a reduction over them. At a large-displacement state with points in
//! contact with a force-driven punch and a follower pressure, every share's residual, energy and
//! contact state are the whole model's, the shares' tangents and preconditioners add up to the
//! whole model's in the nodal block, and the punch's row and column are whole in every share; so
//! are the nodal forces at every dof and the follower loads' forces (the supports' reactions that
//! `stamp run` writes are read from them at the held dofs on every rank).
//! Each share's pattern is its own, smaller than the whole's, and holds the whole rows of the
//! nodes it owns. Each share keeps its own elements' data only; an element that refuses the state
//! on one share gives every share the same error, its reason told by that share.
//!
//! The contact points are shared too: each share evaluates the points of its own nodes (and, for
//! the integrated discretisation, a halo of their cells). Through a scripted run of Newton's calls
//! -- evaluations with and without a tangent, multiplier updates, an active-set update, a
//! checkpoint -- every share's residual, norms and counts of changes are the whole model's, and
//! after the checkpoint every share holds the whole contact state, pressures and reaction; each
//! share queried the punch's surface at fewer points than the whole model.

mod common;
use common::*;
use stamp::contact::{ContactFace, ContactKinematics, ContactPair, ContactPoint, ForceDrive};
use stamp::surface::ContactSurface;
use std::sync::atomic::{AtomicUsize, Ordering};
use stamp::dofs::DofMap;
use stamp::element::Element;
use stamp::error::Result;
use stamp::linalg::partition::{node_owners, partition_elements};
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::NonlinearProblem;
use stamp::share::{Reduce, Share};
use stamp_contact::Sphere;
use stamp_elements::{Face, FollowerPressure, Kinematics, PlateElements};
use std::collections::BTreeMap;
use std::sync::{Arc, Barrier, Mutex};

/// Sums and minima over `n` threads: each adds its entries into a common buffer, all wait, all
/// read the result, all wait again before the next reduction.
struct Threads {
    barrier: Barrier,
    sum: Mutex<Vec<f64>>,
    min: Mutex<Vec<u64>>,
}

impl Reduce for Threads {
    fn sum(&self, v: &mut [f64]) -> Result<()> {
        {
            let mut acc = self.sum.lock().unwrap();
            if acc.is_empty() {
                acc.extend_from_slice(v);
            } else {
                acc.iter_mut().zip(v.iter()).for_each(|(a, b)| *a += b);
            }
        }
        self.barrier.wait();
        v.copy_from_slice(&self.sum.lock().unwrap());
        if self.barrier.wait().is_leader() {
            self.sum.lock().unwrap().clear();
        }
        self.barrier.wait();
        Ok(())
    }
    fn min(&self, v: &mut [u64]) -> Result<()> {
        {
            let mut acc = self.min.lock().unwrap();
            if acc.is_empty() {
                acc.extend_from_slice(v);
            } else {
                acc.iter_mut().zip(v.iter()).for_each(|(a, b)| *a = (*a).min(*b));
            }
        }
        self.barrier.wait();
        v.copy_from_slice(&self.min.lock().unwrap());
        if self.barrier.wait().is_leader() {
            self.min.lock().unwrap().clear();
        }
        self.barrier.wait();
        Ok(())
    }
}

const PARTS: usize = 3;

/// A sphere that counts the points it was queried at.
struct Counted {
    sphere: Sphere,
    queries: AtomicUsize,
}

impl ContactSurface for Counted {
    fn psi(&self, x: &nalgebra::Vector3<f64>) -> f64 {
        self.sphere.psi(x)
    }
    fn gradient(&self, x: &nalgebra::Vector3<f64>) -> nalgebra::Vector3<f64> {
        self.sphere.gradient(x)
    }
    fn psi_and_gradient(&self, x: &nalgebra::Vector3<f64>) -> (f64, nalgebra::Vector3<f64>) {
        self.queries.fetch_add(1, Ordering::Relaxed);
        self.sphere.psi_and_gradient(x)
    }
    fn hessian(&self, x: &nalgebra::Vector3<f64>) -> nalgebra::Matrix3<f64> {
        self.sphere.hessian(x)
    }
}

fn model(mesh: &QuadMesh) -> Model<PlateElements> {
    let mut m = contact_model(mesh, false, Arc::new(Sphere::new(nalgebra::Vector3::new(1.2, 1.1, 0.1 + 1.0), 1.0).unwrap()));
    m.contacts[0].entry_fraction = 0.0;
    m
}

/// The plate of [`model`] with the punch `surface`, its contact nodal or `integrated`, with the
/// default active-set rules and an augmented-Lagrangian tolerance.
fn contact_model(mesh: &QuadMesh, integrated: bool, surface: Arc<dyn ContactSurface>) -> Model<PlateElements> {
    let section = steel_section(0.2);
    let dp = section.delta_plus;
    let plate = PlateElements::new(mesh, section, Kinematics::Nonlinear).unwrap();
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
        pair.coupling_reach = 0.05;
    }
    pair.drive = Some(ForceDrive::new([0.0, 0.0, -1.0], 7.0).unwrap());
    model.add_contact(pair);
    model.add_follower_load(Box::new(FollowerPressure::new("pressure", &mesh.coords, &mesh.cells, Face::Bottom, -0.1, 40.0)));
    model.want_preconditioner(true);
    model.augmented_tolerance = Some(1e-4);
    model
}

/// A sparse matrix's stored entries (zeros too), (row, column) -> value.
type Entries = BTreeMap<(usize, usize), f64>;

/// (residual, energy, active flags, tangent, preconditioner, the nodal forces over all dofs
/// followed by the follower loads' forces) at `u`, or the error.
type Outcome = std::result::Result<(Vec<f64>, f64, Vec<bool>, Entries, Entries, Vec<f64>), String>;

fn entries(m: faer::sparse::SparseColMatRef<'_, usize, f64>) -> Entries {
    let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
    (0..m.ncols()).flat_map(|j| (cp[j]..cp[j + 1]).map(move |k| ((ri[k], j), k))).map(|(ij, k)| (ij, m.val()[k])).collect()
}

fn evaluate(model: &mut Model<PlateElements>, u: &[f64]) -> Outcome {
    model.evaluate(u, 1.0, true).map_err(|e| e.to_string())?;
    // the points' state whole on every share (collective)
    model.contacts[0].gather_state().map_err(|e| e.to_string())?;
    let active = model.contacts[0].state.iter().map(|s| s.active).collect();
    let forces = model.nodal_forces().iter().chain(model.follower_forces()).copied().collect();
    Ok((model.residual().to_vec(), model.energy(), active, entries(model.matrix()), entries(model.preconditioner().unwrap()), forces))
}

/// The PARTS shares of METIS's partition of the mesh over one reduction, each with its elements'
/// flags; and the owner of every node.
fn shares(mesh: &QuadMesh) -> (Vec<(Share, Vec<bool>)>, Vec<u32>) {
    let cells = |e: usize| mesh.cells[e].to_vec();
    let part = partition_elements(mesh.num_nodes(), mesh.num_cells(), cells, PARTS).unwrap();
    let owner = node_owners(mesh.num_nodes(), mesh.num_cells(), cells, &part);
    let reduce = Arc::new(Threads { barrier: Barrier::new(PARTS), sum: Mutex::new(Vec::new()), min: Mutex::new(Vec::new()) });
    let shares = (0..PARTS as u32)
        .map(|k| {
            let share = Share {
                elements: (0..mesh.num_cells()).filter(|&e| part[e] == k).collect(),
                owned_nodes: owner.iter().map(|&o| o == k).collect(),
                reduce: reduce.clone(),
                leader: k == 0,
            };
            (share, part.iter().map(|&q| q == k).collect())
        })
        .collect();
    (shares, owner)
}

/// Each share's outcome at `u`, and the owner of every node.
fn shared(mesh: &QuadMesh, u: &[f64]) -> (Vec<Outcome>, Vec<u32>) {
    let (shares, owner) = shares(mesh);
    let outcomes = std::thread::scope(|s| {
        let handles: Vec<_> = shares
            .into_iter()
            .map(|(share, own)| {
                s.spawn(move || {
                    let mut m = model(mesh);
                    m.set_share(Some(share)).unwrap();
                    // each share holds its own elements' data only: an element of another
                    // share that refuses the state is told of by that share
                    m.element.retain_elements(&own);
                    evaluate(&mut m, u)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    (outcomes, owner)
}

#[test]
fn shares_add_up_to_the_whole_model() {
    let mesh = QuadMesh::rectangle(0.0, 2.4, 0.0, 2.2, 8, 7).unwrap();
    let mut whole = model(&mesh);
    let n = whole.num_dofs();
    let mut rng = Lcg(7);
    // a sag under the punch, small random in-plane motion; the punch's unknown s = 0.12
    let mut u = vec![0.0; n];
    for k in 0..mesh.num_nodes() {
        let [x, y] = mesh.coords[k];
        let w = -0.08 * (x / 2.4) * (1.0 - ((x - 1.2).powi(2) + (y - 1.1).powi(2)) / 3.0);
        for face in [Face::Top, Face::Bottom] {
            u[face.dof(k, 2)] = w;
            u[face.dof(k, 0)] = rng.range(-1e-3, 1e-3) * x;
            u[face.dof(k, 1)] = rng.range(-1e-3, 1e-3) * x;
        }
    }
    u[n - 1] = 0.12;
    whole.apply_prescribed(&mut u, 1.0);
    let (r, energy, active, k, p, forces) = evaluate(&mut whole, &u).unwrap();
    // the clamped edge's reactions are not zero, nor are the follower pressure's forces there
    let held: Vec<usize> = (0..whole.dofs.num_dofs()).filter(|&d| whole.dofs.equation(d).is_none()).collect();
    assert!(held.iter().any(|&d| forces[d].abs() > 1e-6) && held.iter().any(|&d| whole.follower_forces()[d].abs() > 1e-6));
    let fscale = forces.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(active.iter().filter(|a| **a).count() >= 3, "points in contact: {}", active.iter().filter(|a| **a).count());
    let scale = r.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let kscale = k.values().fold(0.0f64, |m, x| m.max(x.abs()));
    let (outcomes, owner) = shared(&mesh, &u);
    let (mut ks, mut ps): (Entries, Entries) = (BTreeMap::new(), BTreeMap::new());
    let neq = whole.num_equations();
    let border = neq - 1;
    // the node of each nodal equation
    let mut node_of = vec![usize::MAX; neq];
    for d in 0..whole.dofs.num_dofs() {
        if let Some(e) = whole.dofs.equation(d) {
            node_of[e] = d / 6;
        }
    }
    for (i, o) in outcomes.iter().enumerate() {
        let (ri, ei, ai, ki, pi, fi) = o.as_ref().unwrap();
        let df = forces.iter().zip(fi).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(fi.len() == forces.len() && df <= 1e-12 * fscale, "share {i}: nodal or follower forces differ by {df:e} of {fscale:e}");
        let dr = r.iter().zip(ri).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(dr <= 1e-12 * scale, "share {i}: residual differs by {dr:e} of {scale:e}");
        assert!((ei - energy).abs() <= 1e-12 * energy.abs(), "share {i}: energy {ei} against {energy}");
        assert_eq!(ai, &active, "share {i}: active set");
        // a pattern of its own: within the whole's, smaller, with the whole rows of its nodes
        assert!(ki.keys().all(|ij| k.contains_key(ij)), "share {i}: an entry outside the whole pattern");
        assert!(ki.keys().eq(pi.keys()), "share {i}: the preconditioner's pattern is the tangent's");
        assert!(ki.len() < k.len() * 3 / 4, "share {i}: {} entries of the whole's {}", ki.len(), k.len());
        for &(a, b) in k.keys() {
            if a != border && owner[node_of[a]] == i as u32 {
                assert!(ki.contains_key(&(a, b)), "share {i}: entry ({a}, {b}) of a row it owns is missing");
            }
        }
        for (ij, v) in ki {
            *ks.entry(*ij).or_default() += v;
        }
        for (ij, v) in pi {
            *ps.entry(*ij).or_default() += v;
        }
        // the punch's row and column are whole in every share
        for (&(a, b), v) in &k {
            if a == border || b == border {
                assert_eq!(ki.get(&(a, b)), Some(v), "share {i}: entry ({a}, {b}) of the punch's row or column");
            }
        }
    }
    // the nodal block: the sum of the shares (the border counted once)
    for (&(i, j), &whole_k) in &k {
        let parts = if i == border || j == border { PARTS as f64 } else { 1.0 };
        let (sum_k, sum_p) = (ks[&(i, j)] / parts, ps[&(i, j)] / parts);
        assert!((sum_k - whole_k).abs() <= 1e-12 * kscale, "tangent ({i}, {j}): shares add to {sum_k}, whole {whole_k}");
        assert!((sum_p - p[&(i, j)]).abs() <= 1e-12 * kscale, "preconditioner ({i}, {j}): shares add to {sum_p}, whole {}", p[&(i, j)]);
    }
    // an element turned inside out on one share: the same error everywhere
    let mut bad = u.clone();
    let corner = mesh.cells[mesh.num_cells() - 1][2];
    for face in [Face::Top, Face::Bottom] {
        bad[face.dof(corner, 0)] = -3.0;
    }
    let want = evaluate(&mut whole, &bad).expect_err("an element refuses");
    for (i, o) in shared(&mesh, &bad).0.iter().enumerate() {
        assert_eq!(o.as_ref().expect_err("refused on every share"), &want, "share {i}");
    }
}

/// A sagging plate state (as above) scaled by `depth`, with the punch's unknown `s`.
fn sag(mesh: &QuadMesh, whole: &Model<PlateElements>, depth: f64, s: f64) -> Vec<f64> {
    let n = whole.num_dofs();
    let mut rng = Lcg(11);
    let mut u = vec![0.0; n];
    for k in 0..mesh.num_nodes() {
        let [x, y] = mesh.coords[k];
        let w = -depth * (x / 2.4) * (1.0 - ((x - 1.2).powi(2) + (y - 1.1).powi(2)) / 3.0);
        for face in [Face::Top, Face::Bottom] {
            u[face.dof(k, 2)] = w;
            u[face.dof(k, 0)] = rng.range(-1e-3, 1e-3) * x;
            u[face.dof(k, 1)] = rng.range(-1e-3, 1e-3) * x;
        }
    }
    u[n - 1] = s;
    u
}

/// What one call of the script gave: the residual, its norm, the force scale, the changes.
#[derive(Debug, Clone, PartialEq)]
struct Call {
    what: &'static str,
    residual: Vec<f64>,
    norm: f64,
    scale: f64,
    changes: usize,
}

/// After the script: every point's (psi, lambda, active), the pressures, the reaction.
type Ending = (Vec<(f64, f64, bool)>, Vec<f64>, [f64; 3]);

/// The re-solve's rows at a tangent evaluation: (id, coefficients, weight, eps, trial, active).
type Rows = Vec<((usize, usize), Vec<(usize, f64)>, f64, f64, f64, bool)>;

/// Newton's calls on a model, in order: a step start, evaluations with and without a tangent
/// through a contact that grows, the multiplier update, the active-set update, a checkpoint.
fn script(m: &mut Model<PlateElements>, states: &[Vec<f64>]) -> (Vec<Call>, Ending, Vec<Rows>) {
    let mut calls = Vec::new();
    let mut rows = Vec::new();
    let mut record = |m: &mut Model<PlateElements>, what: &'static str, u: &[f64], tangent: bool| {
        let ev = m.evaluate(u, 1.0, tangent).unwrap();
        calls.push(Call { what, residual: m.residual().to_vec(), norm: ev.residual_norm, scale: ev.force_scale, changes: ev.active_changes });
    };
    m.checkpoint();
    m.start_step(false);
    for (k, u) in states.iter().enumerate() {
        record(m, "trial", u, false);
        record(m, "tangent", u, true);
        // the re-solve's rows (every point's on every share), and a state it hands back: the
        // least penetrating of the points out of contact enters, the next evaluation's business
        let r: Rows = m.constraint_rows().unwrap().into_iter().map(|r| (r.id, r.coef, r.weight, r.eps, r.trial, r.active)).collect();
        if k == 0 {
            if let Some(enter) = r.iter().filter(|r| !r.5).min_by(|a, b| a.4.abs().total_cmp(&b.4.abs())) {
                m.set_constraint_state(enter.0, true);
                record(m, "after a re-solve's state", u, true);
            }
        }
        rows.push(r);
        if k == 1 {
            let updated = m.update_multipliers();
            record(m, if updated { "after an update" } else { "no update" }, u, true);
        }
    }
    let changes = m.update_active_set();
    calls.push(Call { what: "active-set update", residual: Vec::new(), norm: 0.0, scale: 0.0, changes });
    m.checkpoint();
    let c = &m.contacts[0];
    let state = c.state.iter().map(|s| (s.psi, s.lambda, s.active)).collect();
    (calls, (state, c.pressures(), c.reaction()), rows)
}

/// Both discretisations: the shares' scripted runs are the whole model's, each share queried the
/// surface at its own points (and its halo) only.
#[test]
fn shares_evaluate_their_own_contact_points_and_agree_with_the_whole_model() {
    let mesh = QuadMesh::rectangle(0.0, 2.4, 0.0, 2.2, 12, 11).unwrap();
    let sphere = || Arc::new(Counted { sphere: Sphere::new(nalgebra::Vector3::new(1.2, 1.1, 0.1 + 1.0), 1.0).unwrap(), queries: AtomicUsize::new(0) });
    for integrated in [false, true] {
        let surface = sphere();
        let mut whole = contact_model(&mesh, integrated, surface.clone());
        // the punch pressed deeper and deeper into a sagging plate
        let states: Vec<Vec<f64>> = [(0.06, 0.09), (0.08, 0.12), (0.085, 0.125)]
            .iter()
            .map(|&(d, s)| {
                let mut u = sag(&mesh, &whole, d, s);
                whole.apply_prescribed(&mut u, 1.0);
                u
            })
            .collect();
        let (calls, ending, rows) = script(&mut whole, &states);
        let whole_queries = surface.queries.load(Ordering::Relaxed);
        let kind = if integrated { "integrated" } else { "nodal" };
        let active = ending.0.iter().filter(|s| s.2).count();
        assert!(active >= 6, "{kind}: {active} points in contact at the end");
        assert!(calls.iter().any(|c| c.what == "after an update"), "{kind}: the script made no multiplier update: {:?}", calls.iter().map(|c| c.what).collect::<Vec<_>>());
        assert!(calls.iter().any(|c| c.changes > 0), "{kind}: no active-set change in the script");
        // the re-solve is the nodal scheme's: rows at every tangent, one of them handed back
        let row_count: Vec<usize> = rows.iter().map(|r| r.len()).collect();
        if integrated {
            assert!(row_count.iter().all(|&n| n == 0), "integrated: rows {row_count:?}");
        } else {
            assert!(row_count.iter().all(|&n| n >= 6) && calls.iter().any(|c| c.what == "after a re-solve's state"), "nodal: rows {row_count:?}");
        }
        let runs: Vec<(Vec<Call>, Ending, usize, Vec<Rows>)> = std::thread::scope(|s| {
            let handles: Vec<_> = shares(&mesh)
                .0
                .into_iter()
                .map(|(share, _)| {
                    let (mesh, states) = (&mesh, &states);
                    s.spawn(move || {
                        let surface = sphere();
                        let mut m = contact_model(mesh, integrated, surface.clone());
                        m.set_share(Some(share)).unwrap();
                        let (calls, ending, rows) = script(&mut m, states);
                        (calls, ending, surface.queries.load(Ordering::Relaxed), rows)
                    })
                })
                .collect();
            handles.into_iter().map(|h| h.join().unwrap()).collect()
        });
        let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-11 * scale.max(1e-300);
        for (i, (c, e, queries, r)) in runs.iter().enumerate() {
            // every share holds every row, the whole model's to the bit (each from its owner)
            assert_eq!(r, &rows, "{kind}, share {i}: the re-solve's rows");
            assert_eq!(c.len(), calls.len(), "{kind}, share {i}: calls");
            for (a, b) in c.iter().zip(&calls) {
                assert_eq!((a.what, a.changes), (b.what, b.changes), "{kind}, share {i}: {} changes", b.what);
                let scale = b.residual.iter().fold(b.norm, |m, x| m.max(x.abs()));
                assert!(close(a.norm, b.norm, scale) && close(a.scale, b.scale, b.scale), "{kind}, share {i}, {}: norms {} {} against {} {}", b.what, a.norm, a.scale, b.norm, b.scale);
                let dr = a.residual.iter().zip(&b.residual).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
                assert!(dr <= 1e-11 * scale, "{kind}, share {i}, {}: residual differs by {dr:e} of {scale:e}", b.what);
            }
            let lam = ending.0.iter().fold(0.0f64, |m, s| m.max(s.1.abs()));
            for (k, (a, b)) in e.0.iter().zip(&ending.0).enumerate() {
                assert!(a.2 == b.2 && close(a.0, b.0, 1.0) && close(a.1, b.1, lam), "{kind}, share {i}, point {k}: {a:?} against {b:?}");
            }
            let q = ending.1.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(e.1.iter().zip(&ending.1).all(|(a, b)| close(*a, *b, q)), "{kind}, share {i}: pressures");
            let r = ending.2.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(e.2.iter().zip(&ending.2).all(|(a, b)| close(*a, *b, r)), "{kind}, share {i}: reaction {:?} against {:?}", e.2, ending.2);
            assert!(*queries < whole_queries * 3 / 4, "{kind}, share {i}: the surface queried {queries} times, the whole model {whole_queries}");
        }
        let all: usize = runs.iter().map(|r| r.2).sum();
        assert!(all >= whole_queries, "{kind}: the shares queried {all} times, the whole model {whole_queries}");
    }
}

/// After a checkpoint, what a share holds of the punch's friction: per site (a point, or the
/// integrated face's quadrature point: status, traction,
/// anchor, tangential multiplier, slip, dissipation), the counts of sticking and slipping points,
/// the friction force, the dissipation, the reaction.
type FrictionState = (Vec<(u8, [f64; 3], [f64; 3], [f64; 3], f64, f64)>, (usize, usize), [f64; 3], f64, [f64; 3]);

/// One step of Newton's calls on a model with friction, per step: the residuals of its
/// evaluations, the tangent and preconditioner of its last evaluation with a tangent, and the
/// friction state after its checkpoint.
type FrictionStep = (Vec<Vec<f64>>, Entries, Entries, FrictionState);

/// Newton's calls through three steps of a punch pressed and dragged along x1 at load factors
/// 0.4, 0.7, 1: a step start, evaluations without and with a tangent, a multiplier update and an
/// evaluation after it, a checkpoint (which commits the slip of the step).
fn friction_script(m: &mut Model<PlateElements>, states: &[(f64, Vec<f64>)]) -> Vec<FrictionStep> {
    m.checkpoint();
    states
        .iter()
        .map(|(t, u)| {
            m.start_step(false);
            let mut residuals = Vec::new();
            for tangent in [false, true] {
                m.evaluate(u, *t, tangent).unwrap();
                residuals.push(m.residual().to_vec());
            }
            m.update_multipliers();
            m.evaluate(u, *t, true).unwrap();
            residuals.push(m.residual().to_vec());
            let (k, p) = (entries(m.matrix()), entries(m.preconditioner().unwrap()));
            m.checkpoint();
            let c = &m.contacts[0];
            let f = c.friction.as_ref().unwrap();
            let points = (0..f.status.len()).map(|i| (f.status[i], f.traction[i], f.anchor[i], f.lambda_t_bar[i], f.slip[i], f.dissipation[i])).collect();
            (residuals, k, p, (points, c.stick_slip_counts().unwrap(), c.friction_force(), c.friction_dissipation().unwrap(), c.reaction()))
        })
        .collect()
}

/// Coulomb friction (mu = 0.3) in a distributed model, nodal and integrated contact: a sphere
/// pressed by a force into a sagging plate and dragged along x1 over three steps. Every share's
/// residuals are the whole model's; the shares' tangents and preconditioners (friction's
/// unsymmetric entries and their symmetric stand-ins) add up to the whole's; after each checkpoint
/// every share holds the whole friction state -- each site's stick or slip, traction, anchor,
/// tangential multiplier, slip length and dissipation -- and the punch's totals, the whole
/// model's.
#[test]
fn friction_shares_agree_with_the_whole_model() {
    for integrated in [false, true] {
        friction_shares_agree(integrated);
    }
}

fn friction_shares_agree(integrated: bool) {
    let mesh = QuadMesh::rectangle(0.0, 2.4, 0.0, 2.2, 12, 11).unwrap();
    let build = || {
        let mut m = contact_model(&mesh, integrated, Arc::new(Sphere::new(nalgebra::Vector3::new(1.2, 1.1, 0.1 + 1.0), 1.0).unwrap()));
        // dragged less with the integrated contact, where a point slips when any of its
        // quadrature points does
        let drag = if integrated { 0.003 } else { 0.03 };
        m.contacts[0].motion = [drag, drag / 3.0, 0.0].into();
        m.contacts[0].set_friction(0.3).unwrap();
        m
    };
    let mut whole = build();
    let states: Vec<(f64, Vec<f64>)> = [(0.4, 0.06, 0.09), (0.7, 0.08, 0.12), (1.0, 0.085, 0.125)]
        .iter()
        .map(|&(t, d, s)| {
            let mut u = sag(&mesh, &whole, d, s);
            whole.apply_prescribed(&mut u, t);
            (t, u)
        })
        .collect();
    let want = friction_script(&mut whole, &states);
    // the script goes through stick and slip, and commits slip
    let counts: Vec<(usize, usize)> = want.iter().map(|s| s.3 .1).collect();
    println!("integrated {integrated}, whole model: (sticking, slipping) points after each step {counts:?}");
    assert!(counts.iter().any(|c| c.0 >= 2) && counts.iter().any(|c| c.1 >= 2), "stick and slip: {counts:?}");
    let last = &want[want.len() - 1].3;
    assert!(last.0.iter().filter(|p| p.4 > 0.0).count() >= 2 && last.3 > 0.0, "slip committed: dissipation {}", last.3);
    let k = &want[want.len() - 1].1;
    assert!(k.iter().any(|(&(i, j), v)| (v - k.get(&(j, i)).copied().unwrap_or(0.0)).abs() > 1e-6 * v.abs()), "the friction's tangent is not symmetric");
    let border = whole.num_equations() - 1;
    let runs: Vec<Vec<FrictionStep>> = std::thread::scope(|s| {
        let handles: Vec<_> = shares(&mesh)
            .0
            .into_iter()
            .map(|(share, _)| {
                let (build, states) = (&build, &states);
                s.spawn(move || {
                    let mut m = build();
                    m.set_share(Some(share)).unwrap();
                    friction_script(&mut m, states)
                })
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let close = |a: f64, b: f64, scale: f64| (a - b).abs() <= 1e-11 * scale.max(1e-300);
    let max_abs = |v: &mut dyn Iterator<Item = f64>| v.fold(0.0f64, |m, x| m.max(x.abs()));
    for (step, w) in want.iter().enumerate() {
        let (wp, wcounts, wforce, wdiss, wreaction) = &w.3;
        let t_scale = max_abs(&mut wp.iter().flat_map(|p| p.1.into_iter().chain(p.3)));
        let a_scale = max_abs(&mut wp.iter().flat_map(|p| p.2));
        let f_scale = max_abs(&mut wforce.iter().chain(wreaction).copied());
        for (i, run) in runs.iter().enumerate() {
            let (residuals, _, _, (points, counts, force, diss, reaction)) = &run[step];
            for (a, b) in residuals.iter().zip(&w.0) {
                let scale = max_abs(&mut b.iter().copied());
                let dr = a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
                assert!(dr <= 1e-11 * scale, "integrated {integrated}, step {step}, share {i}: residual differs by {dr:e} of {scale:e}");
            }
            assert_eq!(counts, wcounts, "integrated {integrated}, step {step}, share {i}: sticking and slipping points");
            for (k, (a, b)) in points.iter().zip(wp).enumerate() {
                let same = a.0 == b.0
                    && (0..3).all(|c| close(a.1[c], b.1[c], t_scale) && close(a.2[c], b.2[c], a_scale) && close(a.3[c], b.3[c], t_scale))
                    && close(a.4, b.4, a_scale)
                    && close(a.5, b.5, *wdiss);
                assert!(same, "integrated {integrated}, step {step}, share {i}, point {k}: {a:?} against the whole model's {b:?}");
            }
            assert!(close(*diss, *wdiss, *wdiss), "integrated {integrated}, step {step}, share {i}: dissipation {diss} against {wdiss}");
            assert!((0..3).all(|c| close(force[c], wforce[c], f_scale) && close(reaction[c], wreaction[c], f_scale)), "integrated {integrated}, step {step}, share {i}: friction force {force:?} against {wforce:?}");
        }
        // the shares' tangents and preconditioners add up to the whole's (the border whole in each)
        let (k, p) = (&w.1, &w.2);
        let kscale = max_abs(&mut k.values().copied());
        let (mut ks, mut ps): (Entries, Entries) = (BTreeMap::new(), BTreeMap::new());
        for run in &runs {
            for (ij, v) in &run[step].1 {
                *ks.entry(*ij).or_default() += v;
            }
            for (ij, v) in &run[step].2 {
                *ps.entry(*ij).or_default() += v;
            }
        }
        for (&(i, j), &whole_k) in k {
            let parts = if i == border || j == border { PARTS as f64 } else { 1.0 };
            let (sum_k, sum_p) = (ks[&(i, j)] / parts, ps[&(i, j)] / parts);
            assert!((sum_k - whole_k).abs() <= 1e-11 * kscale, "integrated {integrated}, step {step}: tangent ({i}, {j}): shares add to {sum_k}, whole {whole_k}");
            assert!((sum_p - p[&(i, j)]).abs() <= 1e-11 * kscale, "integrated {integrated}, step {step}: preconditioner ({i}, {j}): shares add to {sum_p}, whole {}", p[&(i, j)]);
        }
    }
}

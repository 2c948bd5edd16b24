//! A model evaluated by several processes, each its own share (stamp::share): three threads stand
//! for three processes, with a reduction over them. At a large-displacement state with points in
//! contact with a force-driven punch and a follower pressure, every share's residual, energy and
//! contact state are the whole model's, the shares' tangents and preconditioners add up to the
//! whole model's in the nodal block, and the punch's row and column are whole in every share.
//! Each share's pattern is its own, smaller than the whole's, and holds the whole rows of the
//! nodes it owns. Each share keeps its own elements' data only; an element that refuses the state
//! on one share gives every share the same error, its reason told by that share.

mod common;
use common::*;
use stamp::contact::{ContactKinematics, ContactPair, ContactPoint, ForceDrive};
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

fn model(mesh: &QuadMesh) -> Model<PlateElements> {
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
    let mut pair = ContactPair::new("punch", Arc::new(Sphere::new(nalgebra::Vector3::new(1.2, 1.1, 0.1 + 1.0), 1.0).unwrap()), points, 3.0e3, ContactKinematics::Exact);
    pair.entry_fraction = 0.0;
    pair.drive = Some(ForceDrive::new([0.0, 0.0, -1.0], 7.0).unwrap());
    model.add_contact(pair);
    model.add_follower_load(Box::new(FollowerPressure::new("pressure", &mesh.coords, &mesh.cells, Face::Bottom, -0.1, 40.0)));
    model.want_preconditioner(true);
    model
}

/// A sparse matrix's stored entries (zeros too), (row, column) -> value.
type Entries = BTreeMap<(usize, usize), f64>;

/// (residual, energy, active flags, tangent, preconditioner) at `u`, or the error.
type Outcome = std::result::Result<(Vec<f64>, f64, Vec<bool>, Entries, Entries), String>;

fn entries(m: faer::sparse::SparseColMatRef<'_, usize, f64>) -> Entries {
    let (cp, ri) = (m.symbolic().col_ptr(), m.symbolic().row_idx());
    (0..m.ncols()).flat_map(|j| (cp[j]..cp[j + 1]).map(move |k| ((ri[k], j), k))).map(|(ij, k)| (ij, m.val()[k])).collect()
}

fn evaluate(model: &mut Model<PlateElements>, u: &[f64]) -> Outcome {
    model.evaluate(u, 1.0, true).map_err(|e| e.to_string())?;
    let active = model.contacts[0].state.iter().map(|s| s.active).collect();
    Ok((model.residual().to_vec(), model.energy(), active, entries(model.matrix()), entries(model.preconditioner().unwrap())))
}

/// Each share's outcome at `u`, and the owner of every node.
fn shared(mesh: &QuadMesh, u: &[f64]) -> (Vec<Outcome>, Vec<u32>) {
    let cells = |e: usize| mesh.cells[e].to_vec();
    let part = partition_elements(mesh.num_nodes(), mesh.num_cells(), cells, PARTS).unwrap();
    let owner = node_owners(mesh.num_nodes(), mesh.num_cells(), cells, &part);
    let reduce = Arc::new(Threads { barrier: Barrier::new(PARTS), sum: Mutex::new(Vec::new()), min: Mutex::new(Vec::new()) });
    let outcomes = std::thread::scope(|s| {
        let handles: Vec<_> = (0..PARTS as u32)
            .map(|k| {
                let share = Share {
                    elements: (0..mesh.num_cells()).filter(|&e| part[e] == k).collect(),
                    owned_nodes: owner.iter().map(|&o| o == k).collect(),
                    reduce: reduce.clone(),
                };
                let own: Vec<bool> = part.iter().map(|&q| q == k).collect();
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
    let (r, energy, active, k, p) = evaluate(&mut whole, &u).unwrap();
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
        let (ri, ei, ai, ki, pi) = o.as_ref().unwrap();
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

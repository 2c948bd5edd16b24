//! The linear solver of `stamp run`, and the processes it runs on.
//!
//! Built without the cargo feature `petsc` (the default): one process, stamp's own
//! [`LdltGmres`] (faer). With it (`cargo build --release -p stamp-cli --features petsc`),
//! `mpirun -n P stamp run PROBLEM.toml` runs on P processes, and the Newton linear solve of every
//! run goes through PETSc (`stamp_petsc::PetscSolver`: by default GMRES on the tangent
//! preconditioned by MUMPS's LDL^T of the plate's P, the scheme of [`LdltGmres`]; `[solver]
//! petsc_options` on top, with the rigid-body modes as the near-null space for GAMG).
//!
//! What is distributed ([`share`], on P > 1 ranks): METIS splits the mesh's elements into P
//! parts and each rank evaluates only its own elements (internal forces, tangent, the plate's P);
//! each node belongs to the rank of the lowest-numbered element around it, and a rank evaluates
//! the contact points and the follower-load pieces at its own nodes (`stamp::share`). The forces
//! and the energy are summed over the ranks (MPI) right after, so every rank holds the whole
//! residual; what the active-set rules read of a whole punch is reduced likewise. PETSc keeps a
//! node's rows of the distributed matrices on its rank, so each rank's share of the tangent goes
//! mostly into its own rows (PETSc adds the shares: `stamp_petsc::PetscSolver::set_partition`).
//! MUMPS's factorisation and the Krylov iterations are distributed too.
//!
//! What is replicated: every rank reads the problem and holds the whole mesh, the vectors of one
//! entry per unknown and per contact point, and runs the same Newton iterations on the gathered
//! solution with the same summed residual; so the active sets' counts, the augmented-Lagrangian
//! updates, the line search and every convergence test are the same on every rank (PetscSolver
//! checks that the right-hand sides agree to the bit). The outputs are computed and written by
//! rank 0 only ([`writes_outputs`]), from the contact state gathered after each step.
//! A failure in the solve is agreed over the ranks; one in writing (rank 0 only) is agreed where
//! it happens ([`on_writer`]) or stops every rank after the step ([`any_rank`]).

use crate::schema::Problem;
use stamp::Result;

/// The linear solver of the run's Newton iterations (inside the bordered solver of the
/// force-driven punches).
#[cfg(not(feature = "petsc"))]
pub type Linear = stamp::linalg::ldlt_gmres::LdltGmres;
#[cfg(feature = "petsc")]
pub type Linear = stamp_petsc::PetscSolver;

pub use stamp::linalg::ldlt_gmres::LdltGmres;

/// The processes of the run: the size of PETSC_COMM_WORLD while PETSc is initialised (`stamp`
/// initialises it at its start under the feature `petsc`), else 1.
pub fn ranks() -> usize {
    #[cfg(feature = "petsc")]
    if let Some(p) = stamp_petsc::Petsc::current() {
        return p.size();
    }
    1
}

/// This process's rank (0 without the feature).
pub fn rank() -> usize {
    #[cfg(feature = "petsc")]
    if let Some(p) = stamp_petsc::Petsc::current() {
        return p.rank();
    }
    0
}

/// True on every rank if `flag` is true on any (collective under MPI; `flag` itself otherwise).
pub fn any_rank(flag: bool) -> bool {
    #[cfg(feature = "petsc")]
    if let Some(p) = stamp_petsc::Petsc::current() {
        if p.size() > 1 {
            let mut v = [flag as u64];
            return p.max_u64(&mut v).map(|_| v[0] != 0).unwrap_or(true);
        }
    }
    flag
}

/// Whether this process writes the run's output files and prints its table: rank 0 (the one
/// process without MPI). The other ranks write nothing at all; they take part in every collective
/// call and skip the rest.
pub fn writes_outputs() -> bool {
    rank() == 0
}

/// The same outcome on every rank (collective under MPI; `local` itself otherwise): Ok where
/// every rank is Ok (each keeps its own value), else an error on every rank -- a failing rank
/// keeps its own, the others get the lowest failing rank's message. For a step that can fail on
/// some ranks only (the writes of rank 0), so that the ranks stop together.
pub fn agree<T>(local: Result<T>) -> Result<T> {
    #[cfg(feature = "petsc")]
    if let Some(p) = stamp_petsc::Petsc::current() {
        if p.size() > 1 {
            return match p.agree(local.as_ref().map(|_| ()).map_err(|e| e.to_string())) {
                Ok(()) => local,
                Err(message) => Err(local.err().unwrap_or(stamp::StampError::Remote(message))),
            };
        }
    }
    local
}

/// `write` run by the process that writes the outputs ([`writes_outputs`]), its outcome agreed
/// over the ranks ([`agree`], collective): Some(its value) there, None on the other ranks, or its
/// error on every rank.
pub fn on_writer<T>(write: impl FnOnce() -> Result<T>) -> Result<Option<T>> {
    agree(if writes_outputs() { write().map(Some) } else { Ok(None) })
}

/// For Newton's interrupt checks on P > 1 ranks ([`stamp::nonlinear::NewtonRaphson::agree_interrupt`]):
/// the largest signal any rank received (MPI_Allreduce at every check, which every rank makes at
/// the same point of the same iterations), recorded on the ranks it did not reach
/// ([`crate::run::interrupt::note`]), so that every rank abandons the step at the same check and ends
/// with the same status. None on one rank.
pub fn agreed_interrupt() -> Option<Box<dyn Fn(bool) -> bool>> {
    #[cfg(feature = "petsc")]
    if let Some(p) = stamp_petsc::Petsc::current() {
        if p.size() > 1 {
            return Some(Box::new(move |local| {
                // a flag set with no signal recorded counts as 1
                let mut v = [if local { crate::run::interrupt::received().map_or(1, |s| s as u64) } else { 0 }];
                if p.max_u64(&mut v).is_err() {
                    return local;
                }
                if v[0] > 1 && crate::run::interrupt::received().is_none() {
                    crate::run::interrupt::note(v[0] as i32);
                }
                v[0] > 0
            }));
        }
    }
    None
}

/// A hash of what a rank solves: the problem file's text (or the table a dict was turned into)
/// and the mesh's coordinates and cells (a gmsh file read beside it). The ranks compare it before
/// they share the model: ranks whose problem files differ (E on one rank, another punch force)
/// deadlocked after the first Newton iteration or ignored the difference.
pub fn inputs_hash(p: &Problem, mesh: &stamp::mesh::QuadMesh) -> u64 {
    let h = fnv(FNV_START, p.source.bytes());
    let h = fnv(h, mesh.coords.iter().flat_map(|x| x.iter().flat_map(|v| v.to_bits().to_le_bytes())));
    fnv(h, mesh.cells.iter().flatten().flat_map(|&n| (n as u64).to_le_bytes()))
}

/// The FNV-1a hash's starting value.
const FNV_START: u64 = 0xcbf2_9ce4_8422_2325;

/// `h` with `bytes` folded in (FNV-1a): what the ranks compare.
fn fnv(h: u64, bytes: impl IntoIterator<Item = u8>) -> u64 {
    bytes.into_iter().fold(h, |h, b| (h ^ b as u64).wrapping_mul(0x0100_0000_01b3))
}

/// Every rank's hash `h` the same, or the error `differs` that stops them all (collective).
#[cfg(feature = "petsc")]
fn same_on_every_rank(petsc: &stamp_petsc::Petsc, h: u64, differs: impl FnOnce() -> String) -> Result<()> {
    let (mut hi, mut lo) = ([h], [h]);
    petsc.max_u64(&mut hi)?;
    petsc.min_u64(&mut lo)?;
    if hi != lo {
        return Err(stamp::StampError::Problem(differs()));
    }
    Ok(())
}

/// On P > 1 ranks, share the model over them (see `stamp::share`): METIS splits the elements
/// into P parts, each rank evaluates only its own, and each node (its equations, its contact and
/// follower-load tangent rows) belongs to the rank of the lowest-numbered element around it; the
/// linear solver is told the same owners, so that each rank's rows of the distributed matrices are
/// mostly its own elements' entries. On one rank, with fewer elements than ranks, or without the
/// feature `petsc`: nothing (every rank evaluates the whole model).
pub fn share<E: stamp::element::Element>(model: &mut stamp::model::Model<E>, linear: &mut Linear, inputs: u64) -> Result<()> {
    #[cfg(not(feature = "petsc"))]
    {
        let _ = (model, linear, inputs);
        Ok(())
    }
    #[cfg(feature = "petsc")]
    {
        use stamp::linalg::partition::{node_owners, partition_elements};
        let Some(petsc) = stamp_petsc::Petsc::current() else { return Ok(()) };
        let (p, rank) = (petsc.size(), petsc.rank());
        if p <= 1 {
            return Ok(());
        }
        same_on_every_rank(&petsc, inputs, || {
            format!("the ranks read different problems (rank {rank} read one whose problem file or mesh hashes to {inputs:016x}; another rank's differs): every rank must read the same problem file and mesh")
        })?;
        let (ne, nn) = (model.element.num_elements(), model.dofs.num_nodes());
        if ne < p {
            // fewer elements than ranks: every rank evaluates the whole model
            return Ok(());
        }
        let element = &model.element;
        let nodes = |e: usize| element.element_nodes(e).to_vec();
        let part = partition_elements(nn, ne, nodes, p)?;
        // METIS is deterministic: every rank computed the same parts (checked, since a rank that
        // disagreed would wait for ever in a collective call)
        same_on_every_rank(&petsc, fnv(FNV_START, part.iter().flat_map(|x| x.to_le_bytes())), || "the ranks partitioned the mesh differently".into())?;
        let owner = node_owners(nn, ne, nodes, &part);
        let dpn = model.dofs.dofs_per_node();
        let mut equation_owner = vec![0u32; model.dofs.num_equations()];
        for (dof, &eq) in model.dofs.equations().iter().enumerate() {
            if eq != stamp::dofs::PRESCRIBED {
                equation_owner[eq as usize] = owner[dof / dpn];
            }
        }
        let r = rank as u32;
        let share = stamp::share::Share {
            elements: (0..ne).filter(|&e| part[e] == r).collect(),
            owned_nodes: owner.iter().map(|&o| o == r).collect(),
            reduce: std::sync::Arc::new(MpiReduce(petsc)),
            leader: rank == 0,
        };
        let own: Vec<bool> = part.iter().map(|&q| q == r).collect();
        model.set_share(Some(share))?;
        // the ranks that write no outputs evaluate only their own elements: they drop the others'
        // geometry (rank 0 keeps it: the outputs are every element's)
        if !writes_outputs() {
            model.element.retain_elements(&own);
        }
        linear.set_partition(Some(equation_owner));
        Ok(())
    }
}

/// Sums and minima over the ranks (MPI_Allreduce on PETSc's communicator); a sum is then
/// broadcast from rank 0, so that every rank holds the same bits whatever order MPI added in.
#[cfg(feature = "petsc")]
struct MpiReduce(stamp_petsc::Petsc);

#[cfg(feature = "petsc")]
impl stamp::share::Reduce for MpiReduce {
    fn sum(&self, v: &mut [f64]) -> Result<()> {
        self.0.sum_f64(v)?;
        // SAFETY: any f64 is 8 plain bytes; the byte view lives only for the broadcast
        let bytes = unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast::<u8>(), std::mem::size_of_val(v)) };
        self.0.broadcast(bytes, 0)?;
        Ok(())
    }
    fn min(&self, v: &mut [u64]) -> Result<()> {
        Ok(self.0.min_u64(v)?)
    }
}

/// `[solver] petsc_options` is for a stamp built with the feature `petsc`: an error at the key
/// without it.
pub fn check_options(p: &Problem) -> Result<()> {
    let Some(opts) = &p.spec.solver.petsc_options else { return Ok(()) };
    if cfg!(feature = "petsc") {
        return Ok(());
    }
    Err(p.error_at(opts.span(), "solver.petsc_options", "PETSc options need a stamp built with PETSc: cargo build --release -p stamp-cli --features petsc"))
}

/// The linear solver for a model of `dofs_per_node` unknowns per node at `coords`, whose
/// equations are numbered by `equations` (dof -> equation, PRESCRIBED for none), the first
/// `inner` of them solved by the inner solver; `z_of_component(c)`: the height of the surface
/// that unknown c of a node moves.
pub fn linear_solver(p: &Problem, coords: &[[f64; 2]], equations: &[u32], dofs_per_node: usize, inner: usize, z_of_component: impl Fn(usize) -> f64) -> Result<Linear> {
    #[cfg(not(feature = "petsc"))]
    {
        let _ = (p, coords, equations, dofs_per_node, inner, z_of_component);
        Ok(LdltGmres::new())
    }
    #[cfg(feature = "petsc")]
    {
        let petsc = stamp_petsc::Petsc::initialize()?;
        let options = p.spec.solver.petsc_options.as_ref().map(|o| o.get_ref().clone()).unwrap_or_default();
        let mut solver = stamp_petsc::PetscSolver::with_options(&petsc, &options).map_err(|e| match &p.spec.solver.petsc_options {
            Some(o) => p.error_at(o.span(), "solver.petsc_options", e.to_string()),
            None => e,
        })?;
        solver.set_near_null_space(rigid_body_modes(coords, equations, dofs_per_node, inner, z_of_component));
        Ok(solver)
    }
}

/// The six rigid-body motions u(X) = a + w x (X - O) (O the centre of the nodes, rotations scaled
/// by the model size) at the plate's unknowns, one entry per equation below `inner`: unknown c of
/// a node is component c % 3 of the displacement of the surface at height `z_of_component(c)`.
pub fn rigid_body_modes(coords: &[[f64; 2]], equations: &[u32], dofs_per_node: usize, inner: usize, z_of_component: impl Fn(usize) -> f64) -> Vec<Vec<f64>> {
    let n = coords.len().max(1) as f64;
    let o = [coords.iter().map(|x| x[0]).sum::<f64>() / n, coords.iter().map(|x| x[1]).sum::<f64>() / n];
    let s = coords.iter().map(|x| (x[0] - o[0]).abs().max((x[1] - o[1]).abs())).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
    let mut modes = vec![vec![0.0; inner]; 6];
    for (dof, &eq) in equations.iter().enumerate() {
        if eq == stamp::dofs::PRESCRIBED || eq as usize >= inner {
            continue;
        }
        let (node, c) = (dof / dofs_per_node, dof % dofs_per_node);
        let r = [(coords[node][0] - o[0]) / s, (coords[node][1] - o[1]) / s, z_of_component(c) / s];
        let k = c % 3;
        modes[k][eq as usize] = 1.0;
        // w x r for w = e_x, e_y, e_z: component k
        let cross = [[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]];
        for w in 0..3 {
            modes[3 + w][eq as usize] = cross[w][k];
        }
    }
    modes
}

/// "LDL^T + GMRES (faer)" or PETSc's "gmres + cholesky (mumps)": the linear solver in use.
pub fn describe(l: &Linear) -> String {
    #[cfg(not(feature = "petsc"))]
    {
        let _ = l;
        "faer: LDL^T of P, GMRES where the tangent is not symmetric".into()
    }
    #[cfg(feature = "petsc")]
    {
        format!("PETSc {}: {}", l.petsc().version(), l.describe())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The six modes are the rigid motions a + w x (X - O) at each unknown's surface point, O the
    /// centre of the nodes and lengths scaled by the largest distance from it; prescribed dofs
    /// and the border (equations from `inner` on) are left out.
    #[test]
    fn rigid_body_modes_are_rigid_motions_at_the_surfaces() {
        // two nodes, the paper's two surfaces (components 0-2 at z = -0.5, 3-5 at z = 0.5)
        let coords = [[0.0, 0.0], [2.0, 0.0]];
        let z = |c: usize| if c < 3 { -0.5 } else { 0.5 };
        let p = stamp::dofs::PRESCRIBED;
        // dof 2 (node 0, u3 of S-) prescribed; node 1's last dof is equation 10, beyond inner = 10
        let equations: Vec<u32> = vec![0, 1, p, 2, 3, 4, 5, 6, 7, 8, 9, 10];
        let modes = rigid_body_modes(&coords, &equations, 6, 10, z);
        assert_eq!(modes.len(), 6);
        assert!(modes.iter().all(|m| m.len() == 10));
        // O = (1, 0), scale 1: node 0 at r = (-1, 0, z), node 1 at (1, 0, z)
        for (dof, &eq) in equations.iter().enumerate() {
            if eq == p || eq >= 10 {
                continue;
            }
            let (node, c) = (dof / 6, dof % 6);
            let r = [if node == 0 { -1.0 } else { 1.0 }, 0.0, z(c)];
            let k = c % 3;
            for t in 0..3 {
                assert_eq!(modes[t][eq as usize], if t == k { 1.0 } else { 0.0 });
            }
            // w x r for the unit rotations about x, y, z
            let rot = [[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]];
            for w in 0..3 {
                assert_eq!(modes[3 + w][eq as usize], rot[w][k], "dof {dof}, rotation {w}");
            }
        }
        // a rotation about z moves node 1 along +x2 and node 0 along -x2
        assert_eq!(modes[5][equations[7] as usize], 1.0);
        assert_eq!(modes[5][equations[1] as usize], -1.0);
    }

    /// Without the feature `petsc`, `[solver] petsc_options` is an error at its line and key, not
    /// an option silently ignored; with it, the problem builds.
    #[test]
    fn petsc_options_need_the_feature() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../meshes");
        let source = std::fs::read_to_string(dir.join("sphere-ss.toml")).unwrap().replace("[solver]", "[solver]\npetsc_options = \"-pc_type gamg\"");
        let p = Problem::parse(&dir.join("sphere-ss.toml"), source).unwrap();
        let built = crate::model::build::build(&p);
        if cfg!(feature = "petsc") {
            assert!(built.is_ok());
        } else {
            let e = built.err().expect("petsc_options refused").to_string();
            assert!(e.contains("solver.petsc_options") && e.contains("--features petsc") && e.contains("line "), "{e}");
        }
    }
}

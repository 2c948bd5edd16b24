//! [`PetscSolver`]: stamp's [`LinearSolver`] on PETSc, for `mpirun -n P`.
//!
//! Two ways to hand over the matrices. By default every rank is handed the whole matrix (stamp's
//! compressed-column tangent, assembled on every rank) and copies only its own contiguous range
//! of rows (split evenly by index) into a distributed MPIAIJ matrix. After
//! [`PetscSolver::set_partition`] each rank is handed only its share (a model evaluated by its own
//! elements on each rank, `stamp::share`), in a pattern of its own that holds the whole rows the
//! rank owns: PETSc's rows are numbered rank after rank by the owner of each equation, every rank
//! adds the nonzero entries of its share (`ADD_VALUES`: PETSc sends those of other ranks' rows at
//! the assembly) into the pattern of its rows, which is allocated once and kept (built anew on
//! every rank when any rank's pattern changes), so MUMPS keeps its symbolic factorisation. Either way the factorisation (MUMPS), the
//! Krylov iterations and their memory are spread over the ranks, and the solution is gathered
//! onto every rank, so that every rank goes on with the same iterate; a hash of every
//! right-hand side is compared over the ranks, so that ranks whose replicated states drifted
//! apart stop with an error instead of waiting on each other.
//!
//! The default scheme is stamp's own (`LdltGmres`): restarted GMRES (40 vectors, at most 200
//! iterations, preconditioned from the right so that it judges the true residual) on the tangent
//! A, preconditioned by MUMPS's LDL^T factorisation of the symmetric matrix P the problem gives
//! with A (PCCHOLESKY on an AIJ matrix: MUMPS's symmetric indefinite mode; the plate's P, see
//! `Element::has_preconditioner`); without a P, MUMPS's LU of A itself. Options given to
//! [`PetscSolver::with_options`] ("-ksp_type cg -pc_type gamg") are read after these defaults
//! and override them; a near-null space ([`PetscSolver::set_near_null_space`], the rigid-body
//! modes) is attached to P for algebraic multigrid. The pattern is analysed once: a matrix of the
//! same pattern only refills the values, and PETSc keeps MUMPS's symbolic factorisation.
//!
//! Every failure is agreed over the ranks ([`Petsc::agree`]): a solve that fails on one rank
//! fails on all, with the same message.

use crate::error::PetscError;
use crate::ksp::Ksp;
use crate::matrix::{AijMatrix, RowPattern};
use crate::ffi::PetscInt as pint_t;
use crate::petsc::{pint, Petsc};
use crate::vector::{DVec, Gather};
use faer::sparse::SparseColMatRef;
use stamp::error::{Result, StampError};
use stamp::linalg::linear_solver::{LinearSolver, SolverTimings};
use std::time::Instant;

/// Relative residual of a full-accuracy solve, and the floor of an inexact one.
pub const RTOL: f64 = 1e-12;
/// Most Krylov iterations of one solve.
pub const MAX_ITERATIONS: usize = 200;
/// Krylov vectors kept before GMRES restarts.
pub const GMRES_RESTART: usize = 40;

/// The distributed matrices and solver of one pattern.
struct Setup {
    /// (rows, entries, hash of the pattern) it was built for.
    key: (usize, usize, u64),
    /// Position in the compressed-column value array of each entry of this rank's rows.
    src: Vec<usize>,
    /// PETSc's row (and column) of each of stamp's equations.
    perm: Vec<usize>,
    /// stamp's equations of this rank's rows, in PETSc's order.
    own: Vec<usize>,
    /// A full-length vector in PETSc's order (the gathered solution).
    full: Vec<f64>,
    values: Vec<f64>,
    /// A share's nonzero entries in other ranks' rows, (PETSc row, column, value) (scratch).
    foreign: Vec<(pint_t, pint_t, f64)>,
    a: AijMatrix,
    p: Option<AijMatrix>,
    ksp: Ksp,
    b: DVec,
    x: DVec,
    gather: Gather,
    /// (rtol, atol, most iterations) after the user's options: a solve to a looser tolerance
    /// raises rtol, never lowers it below this one.
    tolerances: (f64, f64, usize),
}

impl Setup {
    /// This rank's rows of a full-length vector in stamp's order into `b`.
    fn load(&mut self, v: &[f64]) -> std::result::Result<(), PetscError> {
        let own = &self.own;
        self.b.with_local_mut(|x| x.iter_mut().zip(own).for_each(|(x, &i)| *x = v[i]))
    }

    /// `x` gathered from every rank into a full-length vector in stamp's order.
    fn unload(&mut self, v: &mut [f64]) -> std::result::Result<(), PetscError> {
        self.gather.gather(&self.x, &mut self.full)?;
        v.iter_mut().zip(&self.perm).for_each(|(x, &k)| *x = self.full[k]);
        Ok(())
    }
}

/// stamp's linear solver on PETSc (see the module documentation).
pub struct PetscSolver {
    petsc: Petsc,
    options: String,
    setup: Option<Setup>,
    factored: bool,
    /// Full-length vectors (one entry per equation) spanning the near-null space.
    near_null: Vec<Vec<f64>>,
    timings: SolverTimings,
    iterations: usize,
    /// The rank owning each equation, when the matrices are shared ([`PetscSolver::set_partition`]).
    partition: Option<Vec<u32>>,
}

impl PetscSolver {
    /// The default scheme on PETSc, which must be initialised (every rank the same).
    pub fn new(petsc: &Petsc) -> Self {
        PetscSolver { petsc: petsc.clone(), options: String::new(), setup: None, factored: false, near_null: Vec::new(), timings: SolverTimings::default(), iterations: 0, partition: None }
    }

    /// The default scheme with PETSc options on top ("-ksp_type cg -pc_type gamg"), inserted into
    /// PETSc's options database now (an option PETSc cannot parse is an error).
    pub fn with_options(petsc: &Petsc, options: &str) -> Result<Self> {
        petsc.insert_options(options).map_err(|e| StampError::LinearSolver(format!("petsc_options {options:?}: {}", e.message)))?;
        Ok(PetscSolver { options: options.to_string(), ..Self::new(petsc) })
    }

    /// The options given to [`PetscSolver::with_options`].
    pub fn options(&self) -> &str {
        &self.options
    }

    /// Vectors spanning the near-null space of the matrices to come (one entry per equation,
    /// every rank the same): the rigid-body modes of an elastic body, from which algebraic
    /// multigrid (`-pc_type gamg`) builds its coarse spaces. Taken at the next new pattern.
    pub fn set_near_null_space(&mut self, vectors: Vec<Vec<f64>>) {
        self.near_null = vectors;
        self.setup = None;
        self.factored = false;
    }

    /// From now on each rank hands over its share of the matrices, which PETSc sums (a model
    /// evaluated by its share of the elements on each rank, see `stamp::share`): `owners[i]`, the
    /// rank owning equation i (equations from `owners.len()` on: rank 0), whose rows PETSc keeps
    /// on that rank (numbered rank after rank). Every rank passes the same owners; the right-hand
    /// sides stay whole on every rank, and so do the solutions. A rank's matrices may have a
    /// pattern of their own, as long as it holds every entry of the rows the rank owns (the
    /// preallocation of its rows) and every nonzero entry of its share. None: every rank hands
    /// over the whole matrices, split by rows evenly.
    pub fn set_partition(&mut self, owners: Option<Vec<u32>>) {
        self.partition = owners;
        self.setup = None;
        self.factored = false;
    }

    /// "gmres + cholesky (mumps)": the method and preconditioner in use (once set up), else the
    /// default's name.
    pub fn describe(&self) -> String {
        match &self.setup {
            Some(s) => s.ksp.describe(),
            None => "gmres + cholesky (mumps)".into(),
        }
    }

    /// Krylov iterations of all solves so far.
    pub fn iterations(&self) -> usize {
        self.iterations
    }

    pub fn petsc(&self) -> &Petsc {
        &self.petsc
    }

    /// The same on every rank: Ok, or the error of the lowest failing rank.
    fn agree<T>(&self, local: std::result::Result<T, PetscError>) -> Result<T> {
        self.petsc.agree(local).map_err(StampError::LinearSolver)
    }

    /// The rank owning each of n equations: [`PetscSolver::set_partition`]'s, else an even
    /// split by index.
    fn owners(&self, n: usize) -> std::result::Result<Vec<usize>, PetscError> {
        let p = self.petsc.size();
        match &self.partition {
            Some(o) => (0..n)
                .map(|i| {
                    let r = o.get(i).map_or(0, |&r| r as usize);
                    if r < p { Ok(r) } else { Err(PetscError::new(format!("equation {i} is given to rank {r} of {p}"))) }
                })
                .collect(),
            None => Ok((0..p).flat_map(|r| std::iter::repeat_n(r, n * (r + 1) / p - n * r / p)).collect()),
        }
    }

    /// Build the distributed matrices and the solver for the pattern of `a`.
    fn analyse(&mut self, a: SparseColMatRef<'_, usize, f64>, with_p: bool, key: (usize, usize, u64)) -> std::result::Result<Setup, PetscError> {
        let n = a.nrows();
        let owner = self.owners(n)?;
        // PETSc's numbering: the equations of rank 0, then those of rank 1, ... each in stamp's order
        let mut start = vec![0usize; self.petsc.size() + 1];
        owner.iter().for_each(|&r| start[r + 1] += 1);
        for r in 0..self.petsc.size() {
            start[r + 1] += start[r];
        }
        let mut next = start.clone();
        let perm: Vec<usize> = owner
            .iter()
            .map(|&r| {
                next[r] += 1;
                next[r] - 1
            })
            .collect();
        let rank = self.petsc.rank();
        let (lo, hi) = (start[rank], start[rank + 1]);
        let own: Vec<usize> = (0..n).filter(|&i| owner[i] == rank).collect();
        let sym = a.symbolic();
        let (cp, ri) = (sym.col_ptr(), sym.row_idx());
        // this rank's rows, compressed by rows: the transpose of the columns' entries in its rows
        let mut count = vec![0usize; hi - lo + 1];
        for &i in ri {
            if owner[i] == rank {
                count[perm[i] - lo + 1] += 1;
            }
        }
        for k in 0..hi - lo {
            count[k + 1] += count[k];
        }
        let row_ptr = count.clone();
        let mut fill = count;
        let nnz = row_ptr[hi - lo];
        let mut entries = vec![(0usize, 0usize); nnz];
        for j in 0..n {
            for p in cp[j]..cp[j + 1] {
                let i = ri[p];
                if owner[i] == rank {
                    let slot = &mut fill[perm[i] - lo];
                    entries[*slot] = (perm[j], p);
                    *slot += 1;
                }
            }
        }
        // columns ascending within each row (they are already, unless the numbering permutes)
        for k in 0..hi - lo {
            entries[row_ptr[k]..row_ptr[k + 1]].sort_unstable();
        }
        let cols = entries.iter().map(|&(c, _)| pint(c)).collect::<std::result::Result<Vec<_>, _>>()?;
        let src: Vec<usize> = entries.into_iter().map(|(_, p)| p).collect();
        let pattern = RowPattern { lo, hi, n, row_ptr, cols };
        let am = AijMatrix::new(&self.petsc, pattern.clone())?;
        let mut pm = if with_p {
            let mut pm = AijMatrix::new(&self.petsc, pattern)?;
            pm.set_symmetric(false)?;
            Some(pm)
        } else {
            None
        };
        if !self.near_null.is_empty() {
            if let Some(bad) = self.near_null.iter().find(|v| v.len() != n) {
                return Err(PetscError::new(format!("a near-null vector has {} entries for a matrix of {n} rows", bad.len())));
            }
            let local: Vec<Vec<f64>> = self.near_null.iter().map(|v| own.iter().map(|&i| v[i]).collect()).collect();
            match pm.as_mut() {
                Some(pm) => pm.set_near_null_space(&self.petsc, &local)?,
                None => {
                    // the preconditioner is built from A
                    let mut am = am;
                    am.set_near_null_space(&self.petsc, &local)?;
                    return self.finish(am, None, src, key, perm, own);
                }
            }
        }
        self.finish(am, pm, src, key, perm, own)
    }

    fn finish(&self, mut a: AijMatrix, mut p: Option<AijMatrix>, src: Vec<usize>, key: (usize, usize, u64), perm: Vec<usize>, own: Vec<usize>) -> std::result::Result<Setup, PetscError> {
        let n = perm.len();
        if self.partition.is_some() {
            // the whole pattern of this rank's rows, in zeros: the nonzero structure every later
            // sum of shares keeps (shares add only their nonzero entries)
            let zeros = vec![0.0; src.len()];
            a.set_values(&zeros)?;
            if let Some(p) = p.as_mut() {
                p.set_values(&zeros)?;
            }
        }
        let mut ksp = Ksp::new(&self.petsc)?;
        ksp.set_operators(&a, p.as_ref().unwrap_or(&a))?;
        ksp.set_type("gmres")?;
        ksp.set_gmres_restart(GMRES_RESTART)?;
        ksp.set_tolerances(RTOL, 0.0, MAX_ITERATIONS)?;
        ksp.set_pc_type(if p.is_some() { "cholesky" } else { "lu" })?;
        ksp.set_factor_solver("mumps")?;
        // MUMPS sizes its workspace from the analysis plus ICNTL(14) per cent (20 to 35 by
        // default); the pivoting of some steps on 4 ranks needed more and failed with
        // FACTOR_OUTMEMORY (the laminate example, now and then): 100 per cent, unless the user's
        // options say otherwise
        if !self.options.contains("-mat_mumps_icntl_14") {
            self.petsc.insert_options("-mat_mumps_icntl_14 100")?;
        }
        ksp.set_from_options()?;
        // GMRES (the default, unless the options chose another method) is preconditioned from the
        // right, so that it judges the true residual; CG and others keep PETSc's side
        if ksp.ksp_type() == "gmres" && !self.options.contains("-ksp_pc_side") {
            ksp.set_right_preconditioning()?;
        }
        let tolerances = ksp.tolerances()?;
        let b = DVec::new(&self.petsc, own.len(), n)?;
        let x = DVec::new(&self.petsc, own.len(), n)?;
        let gather = Gather::new(&self.petsc, &x)?;
        // (shares are added row by row from the map: no copy of the values)
        let values = if self.partition.is_some() { Vec::new() } else { vec![0.0; src.len()] };
        Ok(Setup { key, src, perm, own, full: vec![0.0; n], values, foreign: Vec::new(), a, p, ksp, b, x, gather, tolerances })
    }

    fn factorize_local(&mut self, a: SparseColMatRef<'_, usize, f64>, p: Option<SparseColMatRef<'_, usize, f64>>) -> std::result::Result<(), PetscError> {
        if a.nrows() != a.ncols() {
            return Err(PetscError::new(format!("a {} x {} matrix is not square", a.nrows(), a.ncols())));
        }
        if let Some(p) = p {
            if !stamp::linalg::sparse::same_pattern(p.symbolic(), a.symbolic()) {
                return Err(PetscError::new("the preconditioner's pattern is not the matrix's"));
            }
        }
        let key = (a.nrows(), a.symbolic().row_idx().len(), pattern_hash(a));
        let rebuild = match &self.setup {
            Some(s) => s.key != key || s.p.is_some() != p.is_some(),
            None => true,
        };
        // each rank hands over a pattern of its own (its share's, see set_partition), which may
        // change on some ranks only: the matrices are built anew on every rank (collective) if
        // any rank's changed
        let mut any = [rebuild as u64];
        self.petsc.max_u64(&mut any)?;
        let rebuild = any[0] != 0;
        if rebuild {
            let t = Instant::now();
            self.setup = None;
            self.setup = Some(self.analyse(a, p.is_some(), key)?);
            self.timings.symbolic += t.elapsed().as_secs_f64();
        }
        let t = Instant::now();
        let s = self.setup.as_mut().unwrap();
        if self.partition.is_some() {
            // each rank's share, summed by PETSc: its own rows through the map, its nonzero
            // entries in other ranks' rows sent
            let sym = a.symbolic();
            let (cp, ri) = (sym.col_ptr(), sym.row_idx());
            let (lo, hi) = (s.b.ownership_range()?.0, s.b.ownership_range()?.1);
            let foreign = |out: &mut Vec<(pint_t, pint_t, f64)>, val: &[f64]| -> std::result::Result<(), PetscError> {
                out.clear();
                for j in 0..cp.len() - 1 {
                    for k in cp[j]..cp[j + 1] {
                        let i = s.perm[ri[k]];
                        if (i < lo || i >= hi) && val[k] != 0.0 {
                            out.push((pint(i)?, pint(s.perm[j])?, val[k]));
                        }
                    }
                }
                Ok(())
            };
            foreign(&mut s.foreign, a.val())?;
            let (src, val) = (&s.src, a.val());
            s.a.set_sum(|k| val[src[k]], &s.foreign)?;
            if let (Some(pm), Some(p)) = (s.p.as_mut(), p) {
                foreign(&mut s.foreign, p.val())?;
                let val = p.val();
                pm.set_sum(|k| val[src[k]], &s.foreign)?;
            }
        } else {
            // the whole matrices on every rank: this rank's rows
            let fill = |values: &mut Vec<f64>, src: &[usize], from: &[f64]| values.iter_mut().zip(src).for_each(|(v, &k)| *v = from[k]);
            fill(&mut s.values, &s.src, a.val());
            s.a.set_values(&s.values)?;
            if let (Some(pm), Some(p)) = (s.p.as_mut(), p) {
                fill(&mut s.values, &s.src, p.val());
                pm.set_values(&s.values)?;
            }
        }
        // the same matrices again: PETSc rebuilds the preconditioner, keeping its symbolic phase
        s.ksp.set_operators(&s.a, s.p.as_ref().unwrap_or(&s.a))?;
        s.ksp.set_up()?;
        self.timings.factorization += t.elapsed().as_secs_f64();
        self.timings.factorizations += 1;
        Ok(())
    }

    fn solve_local(&mut self, b: &mut [f64], rtol: f64) -> std::result::Result<(), PetscError> {
        // the replicated right-hand side must be the same on every rank, bit for bit
        let h = b.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, x| (h ^ x.to_bits()).wrapping_mul(0x0100_0000_01b3));
        let (mut hi, mut lo) = ([h], [h]);
        self.petsc.max_u64(&mut hi)?;
        self.petsc.min_u64(&mut lo)?;
        if hi != lo {
            return Err(PetscError::new("the ranks hold different right-hand sides: their replicated states drifted apart"));
        }
        let s = self.setup.as_mut().ok_or_else(|| PetscError::new("solve called without a successful factorisation"))?;
        if b.len() != s.key.0 {
            return Err(PetscError::new(format!("a right-hand side of {} entries for a matrix of {} rows", b.len(), s.key.0)));
        }
        let t = Instant::now();
        let (base, atol, max_it) = s.tolerances;
        s.ksp.set_tolerances(rtol.max(base), atol, max_it)?;
        s.load(b)?;
        let report = s.ksp.solve(&s.b, &mut s.x)?;
        s.unload(b)?;
        self.iterations += report.iterations;
        self.timings.solve += t.elapsed().as_secs_f64();
        self.timings.solves += 1;
        if b.iter().any(|x| !x.is_finite()) {
            return Err(PetscError::new("the solution has non-finite entries: the matrix is singular"));
        }
        Ok(())
    }
}

impl PetscSolver {
    /// `f` after a successful factorisation (an error otherwise), agreed over the ranks.
    fn when_factored<T>(&mut self, f: impl FnOnce(&mut Self) -> std::result::Result<T, PetscError>) -> Result<T> {
        let r = if self.factored { f(self) } else { Err(PetscError::new("solve called without a successful factorisation")) };
        self.agree(r)
    }

    fn compliance_local(&mut self, a: &[Vec<(usize, f64)>], b: &[Vec<(usize, f64)>]) -> std::result::Result<nalgebra::DMatrix<f64>, PetscError> {
        let s = self.setup.as_mut().ok_or_else(|| PetscError::new("solve called without a successful factorisation"))?;
        let n = s.key.0;
        let t = Instant::now();
        // the PETSc rows of the vectors' indices
        let rows_of = |v: &[Vec<(usize, f64)>]| -> std::result::Result<Vec<usize>, PetscError> {
            let mut r = Vec::new();
            for &(e, _) in v.iter().flatten() {
                r.push(*s.perm.get(e).ok_or_else(|| PetscError::new(format!("index {e} of a matrix of {n} rows")))?);
            }
            r.sort_unstable();
            r.dedup();
            Ok(r)
        };
        let (rows, cols) = (rows_of(a)?, rows_of(b)?);
        // the requested entries (i, j), i in rows, j in cols: row j of a matrix on rank 0
        let root = self.petsc.rank() == 0;
        let (lo, hi) = if root { (0, n) } else { (n, n) };
        let mut row_ptr = vec![0usize; hi - lo + 1];
        let mut pattern = Vec::new();
        if root {
            let mut next = cols.iter().peekable();
            for j in 0..n {
                if next.peek() == Some(&&j) {
                    next.next();
                    for &i in &rows {
                        pattern.push(pint(i)?);
                    }
                }
                row_ptr[j + 1] = pattern.len();
            }
        }
        let nnz = pattern.len();
        let mut requested = AijMatrix::new(&self.petsc, RowPattern { lo, hi, n, row_ptr, cols: pattern })?;
        requested.set_values(&vec![0.0; nnz])?;
        s.ksp.inverse_entries(&mut requested)?;
        let mut entries = vec![0.0; rows.len() * cols.len()];
        if root {
            let mut row = Vec::new();
            for (c, &j) in cols.iter().enumerate() {
                requested.row_values(j, &mut row)?;
                if row.len() != rows.len() {
                    return Err(PetscError::new(format!("MUMPS gave {} entries of the inverse in row {j}, {} requested", row.len(), rows.len())));
                }
                entries[c * rows.len()..(c + 1) * rows.len()].copy_from_slice(&row);
            }
        }
        self.petsc.sum_f64(&mut entries)?;
        let at = |list: &[usize], e: usize| list.binary_search(&s.perm[e]).expect("an index of the vectors");
        let mut out = nalgebra::DMatrix::zeros(a.len(), b.len());
        for (i, ga) in a.iter().enumerate() {
            for (j, gb) in b.iter().enumerate() {
                let mut sum = 0.0;
                for &(f, y) in gb {
                    let base = at(&cols, f) * rows.len();
                    for &(e, x) in ga {
                        sum += x * entries[base + at(&rows, e)] * y;
                    }
                }
                out[(i, j)] = sum;
            }
        }
        self.timings.solve += t.elapsed().as_secs_f64();
        if out.iter().any(|x| !x.is_finite()) {
            return Err(PetscError::new("the inverse's entries are not finite: the matrix is singular"));
        }
        Ok(out)
    }

    fn precondition_local(&mut self, b: &mut [f64], ncols: usize) -> std::result::Result<(), PetscError> {
        let s = self.setup.as_mut().ok_or_else(|| PetscError::new("solve called without a successful factorisation"))?;
        let n = s.key.0;
        if ncols == 0 || b.len() != n * ncols {
            return if b.is_empty() { Ok(()) } else { Err(PetscError::new(format!("{} entries for {ncols} columns of a matrix of {n} rows", b.len()))) };
        }
        let t = Instant::now();
        for col in b.chunks_mut(n) {
            s.load(col)?;
            s.ksp.apply_preconditioner(&s.b, &mut s.x)?;
            s.unload(col)?;
        }
        self.timings.solve += t.elapsed().as_secs_f64();
        if b.iter().any(|x| !x.is_finite()) {
            return Err(PetscError::new("the preconditioner gave non-finite entries: the matrix is singular"));
        }
        Ok(())
    }
}

/// A hash of a compressed-column pattern (its column offsets and row indices).
fn pattern_hash(a: SparseColMatRef<'_, usize, f64>) -> u64 {
    let sym = a.symbolic();
    sym.col_ptr().iter().chain(sym.row_idx()).fold(0xcbf2_9ce4_8422_2325u64, |h, &x| (h ^ x as u64).wrapping_mul(0x0100_0000_01b3))
}

impl LinearSolver for PetscSolver {
    fn factorize(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<()> {
        self.factorize_preconditioned(a, None)
    }

    fn factorize_preconditioned(&mut self, a: SparseColMatRef<'_, usize, f64>, p: Option<SparseColMatRef<'_, usize, f64>>) -> Result<()> {
        self.factored = false;
        let r = self.factorize_local(a, p);
        self.agree(r)?;
        self.factored = true;
        Ok(())
    }

    fn uses_preconditioner(&self) -> bool {
        true
    }

    fn solve_in_place(&mut self, b: &mut [f64]) -> Result<()> {
        self.solve_in_place_to(b, RTOL)
    }

    fn solve_in_place_to(&mut self, b: &mut [f64], rtol: f64) -> Result<()> {
        self.when_factored(|s| s.solve_local(b, rtol))
    }

    /// Selected entries of the inverse of MUMPS's factor (of P by default): the entries on the
    /// vectors' indices only, computed on rank 0 and shared. None without MUMPS (a multigrid
    /// preconditioner, say).
    fn compliance(&mut self, a: &[Vec<(usize, f64)>], b: &[Vec<(usize, f64)>]) -> Result<Option<nalgebra::DMatrix<f64>>> {
        let mumps = self.setup.as_ref().is_some_and(|s| s.ksp.factor_solver().as_deref() == Some("mumps"));
        if !mumps {
            return Ok(None);
        }
        self.when_factored(|s| s.compliance_local(a, b)).map(Some)
    }

    /// Each column by the preconditioner alone (MUMPS's factor of P by default), as
    /// `LdltGmres` does with its own: the estimates of the contact points' compliance.
    fn solve_many_approx(&mut self, b: &mut [f64], ncols: usize) -> Result<()> {
        self.when_factored(|s| s.precondition_local(b, ncols))
    }

    fn timings(&self) -> SolverTimings {
        self.timings
    }
}

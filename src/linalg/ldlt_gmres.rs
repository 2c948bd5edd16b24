//! The fast linear solver for large plates: a sparse LDL^T of the symmetric part of the matrix,
//! used directly when the matrix is symmetric and as the preconditioner of GMRES when it is not.
//!
//! Why: the unsymmetric sparse LU orders its columns by COLAMD, which bounds the factors by the
//! structure of A^T A; on a 2D plate mesh its factors are about 10 times larger than the Cholesky
//! factor of the same pattern under AMD, and its factorisation several times slower (measured at
//! 60 400 unknowns, README "Speed": 2.1 s and a 1.4 GiB process for the LU against 0.32-0.45 s
//! and 0.4 GiB for the LDL^T). The plate's tangent is not symmetric only
//! because of the paper's b_ab33 = 0 (the thickness stress depends on the in-plane strains, not
//! the converse; SPEC section 2): its symmetric part S = (A + A^T) / 2 is a good preconditioner,
//! GMRES on S^-1 converging by a decade every two iterations. Better still is a symmetric P that
//! the problem may give with A ([`LinearSolver::factorize_preconditioned`]; the plate's is its
//! tangent without that one-way coupling, see `Element::has_preconditioner`): when given, P is
//! factorised instead of S (the default, [`LdltGmres::with_preconditioner`]), and GMRES needs
//! about half the iterations (the coupling that P leaves out acts one way only, so P^-1 A - I is
//! close to nilpotent; measured on the sphere problem: 5 iterations instead of 15 to full
//! accuracy, `tests/linear_solvers.rs`; in `stamp bench` about half the iterations at every size,
//! README "Speed"). The framework does not know the plate: it measures the asymmetry of every
//! matrix and chooses.
//!
//! - A symmetric to round-off: A = L D L^T, checked solve (backward error measured, up to two
//!   steps of iterative refinement).
//! - Otherwise: S (or the given P) = L D L^T, then right-preconditioned restarted GMRES on A x = b to
//!   |b - A x| <= [`GMRES_TOL`] (|A| |x| + |b|).
//! - A matrix whose LDL^T meets a zero pivot, whose pattern is not symmetric, or on which the
//!   solve does not reach its tolerance is factorised by [`SparseLu`] instead (that matrix only).
//!
//! The symbolic phase (fill-reducing ordering, elimination tree, supernodes) is computed once per
//! pattern and reused, with all workspaces, by every numeric factorisation.
//!
//! Solves with the factor (the direct ones and GMRES's preconditioner): with a supernodal factor,
//! the tree-parallel solve of [`crate::linalg::supernodal_solve`] (its schedule built with the symbolic
//! phase; on one thread when the parallelism is sequential, still about 30 % faster than faer's);
//! faer's with a simplicial factor.
//! Measured with `stamp bench` (2 threads, the quieter of two A/B runs): the solve column at
//! n = 200 from 8.0 s to 4.2 s, at n = 100 from 1.6 s to 0.8 s; the answers are the same, but
//! the round-off differs from faer's and the Newton path with it (n = 200: 30 Newton iterations
//! and 24 factorisations instead of 32 and 25; n = 100: 28 instead of 27).
//!
//! Ordering ([`Ordering`], [`LdltGmres::ordering`]): by default nested dissection (METIS on the
//! nodal graph, [`crate::linalg::ordering::nested_dissection`]) from [`ND_MIN_UNKNOWNS`] unknowns on and
//! faer's AMD below. Measured 2026-11-23 on the tangent of `stamp bench`'s plate (n x n, punch
//! travel 0.6, contact active; the ignored test `ordering_comparison` in cli/src/bench.rs): one
//! symbolic and three numeric factorisations of its symmetric part per ordering, the numeric ones
//! of the two orderings taking turns, 2 threads on the 2 cores, the minimum of the 3 seconds. The
//! fill (faer's `len_val`) and the flops (sum over the columns of L of their count squared) are
//! exact; the seconds are those of the quietest run (load average below 2):
//!
//! | n | unknowns | entries of L, AMD / ND | flops, AMD / ND | symbolic s, AMD / ND (METIS incl.) | numeric s, AMD / ND |
//! |---|---|---|---|---|---|
//! | 25 | 3 850 | 0.49 M / 0.45 M | 5.7e7 / 5.0e7 | 0.006 / 0.005 | 0.011 / 0.012 |
//! | 50 | 15 200 | 2.54 M / 2.46 M | 4.9e8 / 4.6e8 | 0.026 / 0.022 | 0.056 / 0.068 |
//! | 100 | 60 400 | 13.9 M / 12.6 M | 5.3e9 / 3.9e9 | 0.16 / 0.13 | 0.30 / 0.32 |
//! | 120 | 86 880 | 21.8 M / 19.2 M | 9.8e9 / 6.8e9 | 0.21 / 0.21 | 0.51 / 0.61 |
//! | 141 | 119 850 | 36.6 M / 28.5 M | 2.2e10 / 1.1e10 | 0.25 / 0.27 | 0.89 / 0.74 |
//! | 200 | 240 800 | 75.2 M / 61.7 M | 6.0e10 / 3.2e10 | 0.50 / 0.56 | 1.84 / 1.51 |
//! | 400 | 961 600 | 398 M / 310 M | 6.4e11 / 3.2e11 | 2.41 / 2.52 | 15.0 / 10.3 |
//!
//! Other runs, while another benchmark shared the machine (load average up to 3.9), moved the
//! seconds by up to 85 %. Over all runs, at 60 400 and 86 880 unknowns either ordering came out
//! ahead (AMD in 8 of 12; ND saves flops there, not time); from 119 850 unknowns on (n = 141,
//! 160, 200, 400) ND was faster in all 15, by 13 % or more, and its factor is 18-22 % smaller.
//! METIS takes 0.09 s at n = 100, 0.3 s at 200, 1.4 s at 400, once per pattern; if it fails,
//! AMD is used. The whole bench solve (the ignored test `ordering_bench`, one run each, load
//! average about 2) at n = 200: 86 s with ND against 103 s with AMD (factorisations 44 s against
//! 54 s, solves 29 s against 35 s), the same answer; at n = 100 (where the default stays AMD)
//! 18.3 s against 19.2 s, the factorisations 8.4 s either way.
//!
//! Reuse of the numeric factor (off by default, [`LdltGmres::reuse`]): a new matrix of the same
//! pattern (the next Newton iteration) is first solved by GMRES preconditioned with the factor of
//! an earlier one, which costs extra GMRES iterations instead of a factorisation. The solver keeps
//! the cost model honest with its own clock: a stale solve may spend at most as many extra
//! iterations (over those of the last fresh solve) as one factorisation costs in time; if it needs
//! more, the matrix is factorised on the spot and solved again; and once a stale solve has spent
//! more than half a factorisation in extra iterations, the next matrix is factorised. The
//! accuracy of every solve stays the same ([`GMRES_TOL`]), so the Newton iterates do too.
//! Measured with `stamp bench` (README): it saves two thirds of the factorisations for
//! more GMRES iterations (17-75 %), 8 % of the time at 240 800 unknowns, nothing at 60 400 and a little
//! loss below; hence off by default.

use crate::error::{Result, StampError};
use crate::linalg::gmres::{Gmres, GmresReport};
use crate::linalg::linear_solver::{parallelism_for, LinearSolver, SolverTimings, SparseLu};
use crate::linalg::ordering;
use crate::linalg::supernodal_solve::{ForwardColumn, SparseForward, SupernodalSolve};
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::sparse::linalg::cholesky::{factorize_symbolic_cholesky, CholeskySymbolicParams, LdltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::perm::PermRef;
use faer::{Conj, MatMut, Par, Side};
use std::time::Instant;

/// Backward error |b - A x| / (|A| |x| + |b|) a GMRES solve must reach.
pub const GMRES_TOL: f64 = 1e-12;
/// Most GMRES iterations of one solve before the LU takes over.
pub const GMRES_MAX_ITERATIONS: usize = 200;
/// Krylov vectors kept before a restart.
pub const GMRES_RESTART: usize = 40;
/// Relative asymmetry max |a_ij - a_ji| / max |a| up to which A is treated as symmetric.
pub const SYMMETRY_TOL: f64 = 1e-12;
/// Unknowns from which [`Ordering::Auto`] orders by nested dissection (measured on the bench
/// plate: a tie or AMD ahead at 60 400 and 86 880 unknowns, ND ahead by 13 % or more from 119 850
/// on, see the module doc).
pub const ND_MIN_UNKNOWNS: usize = 100_000;
/// Backward error of a direct LDL^T solve accepted without refinement.
const ACCEPT: f64 = 1e-14;
/// Backward error above which, after refinement, the matrix goes to the LU.
const FALLBACK: f64 = 1e-10;
/// Bytes the sparse LU is taken to need per entry of the LDL^T factor of the same pattern: its
/// factors hold about ten times the entries (module doc), each a value and a row index.
const LU_BYTES_PER_LDLT_ENTRY: usize = 10 * 16;

/// Fill-reducing ordering of the LDL^T factor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Ordering {
    /// faer's approximate minimum degree.
    Amd,
    /// Nested dissection by METIS on the compressed (nodal) graph,
    /// [`crate::linalg::ordering::nested_dissection`]; AMD if METIS fails.
    NestedDissection,
    /// Nested dissection from [`ND_MIN_UNKNOWNS`] unknowns on, AMD below (the default).
    #[default]
    Auto,
}

/// How the last matrix is solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Direct,
    Preconditioned,
    Lu,
}

/// Counters of what the solver did, for benchmarks and tests.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct LdltGmresStats {
    /// Matrices factorised by LDL^T of A itself (symmetric).
    pub direct: usize,
    /// Matrices factorised by LDL^T of their symmetric part, solved by GMRES.
    pub preconditioned: usize,
    /// Matrices handed to the LU.
    pub lu_fallbacks: usize,
    /// Matrices solved with the factor of an earlier matrix (GMRES).
    pub reused: usize,
    /// GMRES iterations, all solves.
    pub gmres_iterations: usize,
    /// Iterative-refinement steps of direct solves.
    pub refinements: usize,
}

/// LDL^T of the symmetric part, direct or as GMRES preconditioner; LU fallback.
pub struct LdltGmres {
    symbolic: Option<SymbolicCholesky<usize>>,
    /// The tree-parallel solve with a supernodal factor of `symbolic` (None: simplicial, faer's
    /// solve), used unless the parallelism is sequential.
    supernodal: Option<SupernodalSolve>,
    /// The sparse forward solves of `forward_columns`, built at its first call for a pattern.
    sparse_forward: Option<SparseForward>,
    /// The ordering asked for, and the one the current symbolic factor uses (Amd or
    /// NestedDissection).
    ordering: Ordering,
    ordering_used: Option<Ordering>,
    factor: Vec<f64>,
    /// Pattern of the last matrix A; its values in that pattern only when the LU needs them (a
    /// pattern that is not symmetric, or an LU fallback: A is otherwise kept by rows, below); the
    /// values of the matrix factorised (A's symmetric part, or the given P).
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
    symmetric_values: Vec<f64>,
    /// The values of A^T in A's (symmetric) pattern, i.e. A by rows: for the products A x of
    /// GMRES, computed row by row in parallel.
    row_values: Vec<f64>,
    /// Position of a_ji for every stored a_ij (None: the pattern is not symmetric).
    transpose: Option<Vec<usize>>,
    /// max_i sum_j |a_ij|.
    norm_inf: f64,
    buffer: Option<MemBuffer>,
    lu: Option<SparseLu>,
    gmres: Gmres,
    mode: Mode,
    factored: bool,
    /// Reuse of the numeric factor across matrices of one pattern allowed.
    reuse: bool,
    /// Factorise a given preconditioner matrix P instead of the symmetric part.
    use_preconditioner: bool,
    /// The LDL^T factor holds a valid factorisation (of some earlier matrix if `stale`).
    factor_valid: bool,
    stale: bool,
    /// The last matrix was symmetric to round-off.
    symmetric: bool,
    /// Factorise the next matrix whatever.
    refactor_next: bool,
    /// Seconds of the last numeric factorisation and of one GMRES iteration; GMRES iterations of
    /// the last solve with a fresh factor.
    factor_seconds: f64,
    /// Whether faer's numeric factorisation runs on the threads or on one (measured per pattern).
    factor_parallelism: FactorParallelism,
    iteration_seconds: f64,
    fresh_iterations: usize,
    par: Par,
    timings: SolverTimings,
    stats: LdltGmresStats,
    /// Workspaces of a solve.
    rhs: Vec<f64>,
    r: Vec<f64>,
}

impl Default for LdltGmres {
    fn default() -> Self {
        Self::new()
    }
}

impl LdltGmres {
    /// A solver that uses faer's global parallelism setting.
    pub fn new() -> Self {
        LdltGmres {
            symbolic: None,
            supernodal: None,
            sparse_forward: None,
            ordering: Ordering::default(),
            ordering_used: None,
            factor: Vec::new(),
            col_ptr: Vec::new(),
            row_idx: Vec::new(),
            values: Vec::new(),
            symmetric_values: Vec::new(),
            row_values: Vec::new(),
            transpose: None,
            norm_inf: 0.0,
            buffer: None,
            lu: None,
            gmres: Gmres::new(GMRES_RESTART),
            mode: Mode::Direct,
            factored: false,
            reuse: false,
            use_preconditioner: true,
            factor_valid: false,
            stale: false,
            symmetric: false,
            refactor_next: false,
            factor_seconds: 0.0,
            factor_parallelism: FactorParallelism::default(),
            iteration_seconds: 0.0,
            fresh_iterations: 0,
            par: faer::get_global_parallelism(),
            timings: SolverTimings::default(),
            stats: LdltGmresStats::default(),
            rhs: Vec::new(),
            r: Vec::new(),
        }
    }

    /// Use a given parallelism for the factorisation and solves.
    pub fn with_parallelism(par: Par) -> Self {
        LdltGmres { par, ..Self::new() }
    }

    /// Factorise the symmetric matrix P a problem gives with A
    /// ([`LinearSolver::factorize_preconditioned`]) instead of A's symmetric part (default: yes).
    /// Measured on the plate (`stamp bench`): half the GMRES iterations at every size, the same
    /// answers, and a third less time at n = 400 (README "Speed"). `false` factorises the
    /// symmetric part whatever the problem gives.
    pub fn with_preconditioner(mut self, on: bool) -> Self {
        self.use_preconditioner = on;
        self
    }

    /// Allow or forbid (default) the reuse of a factor for later matrices of the same pattern.
    pub fn reuse(mut self, allow: bool) -> Self {
        self.reuse = allow;
        self
    }

    /// The fill-reducing ordering (default [`Ordering::Auto`]); takes effect at the next new
    /// pattern.
    pub fn ordering(mut self, ordering: Ordering) -> Self {
        self.ordering = ordering;
        self
    }

    /// The ordering of the current LDL^T factor ([`Ordering::Amd`] or
    /// [`Ordering::NestedDissection`]); None before the first symmetric pattern.
    pub fn ordering_used(&self) -> Option<Ordering> {
        self.ordering_used
    }

    /// Stored entries of the LDL^T factor of the current pattern (faer's `len_val`); 0 before the
    /// first symmetric pattern.
    pub fn factor_len(&self) -> usize {
        self.symbolic.as_ref().map_or(0, |s| s.len_val())
    }

    /// Whether the numeric factorisations of the current pattern settled on faer's parallel
    /// setting (true) or on one thread (false), once both were measured; None before (see
    /// `FactorParallelism`).
    pub fn factorizes_in_parallel(&self) -> Option<bool> {
        self.factor_parallelism.threads_won()
    }

    /// What the solver did so far.
    pub fn stats(&self) -> LdltGmresStats {
        self.stats
    }

    /// Ordering, elimination structure and workspaces for a new pattern.
    fn analyse(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<()> {
        let t = Instant::now();
        let n = a.nrows();
        let nested = match self.ordering {
            Ordering::Amd => false,
            Ordering::NestedDissection => true,
            Ordering::Auto => n >= ND_MIN_UNKNOWNS,
        };
        // METIS runs on one thread: the copies of the pattern and its transpose positions (0.12 s
        // at n = 200 in `stamp bench`, against METIS's 0.23 s) are made beside it. A pattern that
        // turns out not symmetric has no LDL^T: its ordering goes unused (the LU orders its own).
        let (col_ptr, row_idx) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
        let (perm, (transpose, (col_ptr, row_idx))) = rayon::join(
            || if nested { ordering::nested_dissection(col_ptr, row_idx).ok() } else { None },
            || (transpose_positions(col_ptr, row_idx), (col_ptr.to_vec(), row_idx.to_vec())),
        );
        (self.col_ptr, self.row_idx, self.transpose) = (col_ptr, row_idx, transpose);
        let nnz = self.row_idx.len();
        // a symmetric pattern keeps A by rows only (the LU fallback rebuilds the columns)
        self.values = if self.transpose.is_some() { Vec::new() } else { vec![0.0; nnz] };
        // filled (and sized) only when the symmetric part is factorised or a factor may be renewed
        // later from kept values (reuse): a given P or a symmetric A is factorised where it lies
        self.symmetric_values = Vec::new();
        self.row_values = if self.transpose.is_some() { vec![0.0; nnz] } else { Vec::new() };
        self.symbolic = None;
        self.supernodal = None;
        self.sparse_forward = None;
        self.ordering_used = None;
        self.factor_valid = false;
        if self.transpose.is_some() {
            // a METIS failure leaves AMD
            let inverse = perm.as_deref().map(ordering::inverse);
            let order = match (&perm, &inverse) {
                (Some(p), Some(i)) => SymmetricOrdering::Custom(PermRef::new_checked(p, i, n)),
                _ => SymmetricOrdering::Amd,
            };
            let sym = factorize_symbolic_cholesky(a.symbolic(), Side::Lower, order, CholeskySymbolicParams::default())
                .map_err(|e| StampError::LinearSolver(format!("symbolic LDL^T failed: {e:?}")))?;
            self.ordering_used = Some(if perm.is_some() { Ordering::NestedDissection } else { Ordering::Amd });
            let scratch = sym.factorize_numeric_ldlt_scratch::<f64>(self.par, Default::default()).or(sym.solve_in_place_scratch::<f64>(1, self.par));
            self.buffer = Some(MemBuffer::try_new(scratch).map_err(|_| StampError::LinearSolver("out of memory for the LDL^T workspace".into()))?);
            // written, not only allocated: the pages are mapped here, not in the first
            // factorisation, whose time decides the parallelism (FactorParallelism); by all
            // threads, as the hypervisor maps fresh memory faster to two (512 MiB in a probe:
            // 0.18 s on one thread, 0.10 s on two when the host is quick)
            self.factor = vec![0.0; sym.len_val()];
            touch_pages(&mut self.factor);
            self.factor_parallelism = FactorParallelism::default();
            self.supernodal = Some(SupernodalSolve::new(&sym)).filter(SupernodalSolve::is_parallel);
            self.symbolic = Some(sym);
        }
        self.timings.symbolic += t.elapsed().as_secs_f64();
        Ok(())
    }

    fn same_pattern(&self, a: SparseColMatRef<'_, usize, f64>) -> bool {
        !self.col_ptr.is_empty() && a.symbolic().col_ptr() == self.col_ptr.as_slice() && a.symbolic().row_idx() == self.row_idx.as_slice()
    }

    fn factorize_lu(&mut self) -> Result<()> {
        let n = self.col_ptr.len() - 1;
        // the LU's factors are about ten times the LDL^T's: on a large plate more than the machine
        // has (at n = 400 in `stamp bench`, 50 GB against a 2.5 GB LDL^T factor), and a process
        // that outgrows it is killed with nothing said. Refused instead: Newton cuts the step back.
        if let Some(why) = lu_refusal(n, self.factor_len(), crate::memory::available_bytes().map(|b| b as usize)) {
            return Err(StampError::LinearSolver(why));
        }
        if let Some(tr) = &self.transpose {
            // A's columns from its rows: a_ij sits at the transposed position of a_ji
            self.values = tr.iter().map(|&k| self.row_values[k]).collect();
        }
        let lu = self.lu.get_or_insert_with(|| SparseLu::with_parallelism(self.par));
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx);
        lu.factorize(SparseColMatRef::new(pattern, &self.values))?;
        self.mode = Mode::Lu;
        // a matrix the LDL^T could not serve: its factor is no preconditioner for the next one
        self.factor_valid = false;
        self.stats.lu_fallbacks += 1;
        Ok(())
    }

    /// The LDL^T of `values` (in the pattern's slots; the lower triangle is read), or of the kept
    /// symmetric values; false on a zero pivot or a non-finite factor.
    fn factorize_ldlt(&mut self, values: Option<&[f64]>) -> bool {
        let n = self.col_ptr.len() - 1;
        let par = self.factor_parallelism.choose(parallelism_for(n, self.par));
        let (Some(sym), Some(buffer)) = (self.symbolic.as_ref(), self.buffer.as_mut()) else { return false };
        factorize_numeric(sym, buffer, &mut self.factor, &self.col_ptr, &self.row_idx, values.unwrap_or(&self.symmetric_values), par)
    }

    /// x = S^-1 x with the LDL^T factor: by the tree-parallel solve `supernodal` when given (on
    /// one thread if `par` is sequential; about 30 % faster than faer's there too), by faer's
    /// otherwise.
    fn ldlt_solve(symbolic: &SymbolicCholesky<usize>, supernodal: Option<&SupernodalSolve>, factor: &[f64], buffer: &mut MemBuffer, par: Par, x: &mut [f64]) {
        match supernodal {
            Some(fast) => fast.solve_in_place(symbolic, factor, x, par != Par::Seq),
            None => {
                let n = x.len();
                LdltRef::new(symbolic, factor).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(x, n, 1), par, MemStack::new(buffer));
                crate::linalg::vector_state::clean_upper_vector_state();
            }
        }
    }

    /// The direct solve with iterative refinement; returns the backward error reached.
    fn direct_solve(&mut self, b: &mut [f64]) -> f64 {
        let par = parallelism_for(b.len(), self.par);
        let (sym, buffer) = (self.symbolic.as_ref().unwrap(), self.buffer.as_mut().unwrap());
        let fast = self.supernodal.as_ref();
        Self::ldlt_solve(sym, fast, &self.factor, buffer, par, b);
        let parallel = matches!(par, Par::Rayon(_));
        let mut error = backward_error(&self.col_ptr, &self.row_idx, &self.row_values, parallel, self.norm_inf, &self.rhs, b, &mut self.r);
        for _ in 0..2 {
            if !(error > ACCEPT) || !error.is_finite() {
                break;
            }
            Self::ldlt_solve(sym, fast, &self.factor, buffer, par, &mut self.r);
            for (x, d) in b.iter_mut().zip(&self.r) {
                *x += d;
            }
            self.stats.refinements += 1;
            error = backward_error(&self.col_ptr, &self.row_idx, &self.row_values, parallel, self.norm_inf, &self.rhs, b, &mut self.r);
        }
        error
    }

    /// GMRES on A preconditioned by the LDL^T of S.
    /// GMRES stops at a backward error of [`GMRES_TOL`] or at a relative residual `rtol`.
    fn preconditioned_solve(&mut self, b: &mut [f64], max_iterations: usize, rtol: f64) -> GmresReport {
        let par = parallelism_for(b.len(), self.par);
        let (sym, buffer) = (self.symbolic.as_ref().unwrap(), self.buffer.as_mut().unwrap());
        let fast = self.supernodal.as_ref();
        let (col_ptr, row_idx, row_values, factor) = (&self.col_ptr, &self.row_idx, &self.row_values, &self.factor);
        let parallel = matches!(par, Par::Rayon(_));
        // from x = 0: the first iteration finds the best multiple of S^-1 b, as good as starting
        // from S^-1 b and one preconditioner application cheaper
        b.iter_mut().for_each(|v| *v = 0.0);
        let report = self.gmres.solve(
            &self.rhs,
            b,
            GMRES_TOL,
            rtol,
            self.norm_inf,
            max_iterations,
            &mut |x, y| multiply_rows(col_ptr, row_idx, row_values, x, y, parallel),
            &mut |z: &mut [f64]| -> std::result::Result<(), ()> {
                Self::ldlt_solve(sym, fast, factor, buffer, par, z);
                Ok(())
            },
        );
        let report = report.unwrap_or(GmresReport { iterations: 0, backward_error: f64::INFINITY, converged: false });
        self.stats.gmres_iterations += report.iterations;
        report
    }
}

impl LdltGmres {
    /// The LDL^T of the current matrix's symmetric part (or the LU where that fails).
    /// After the pass over A ([`split_values`], row sums in `r`): its infinity norm, and whether
    /// it is symmetric (largest asymmetry `worst`, largest entry `size`).
    fn passed_over(&mut self, worst: f64, size: f64) {
        self.norm_inf = self.r.iter().fold(0.0f64, |m, x| m.max(*x));
        self.symmetric = worst <= SYMMETRY_TOL * size;
    }

    /// `values` as in [`LdltGmres::factorize_ldlt`].
    fn fresh_factorization(&mut self, values: Option<&[f64]>) -> Result<()> {
        let t = Instant::now();
        let ok = self.factorize_ldlt(values);
        self.factorized(ok, t.elapsed().as_secs_f64())
    }

    /// The bookkeeping after a numeric LDL^T that took `seconds` and succeeded if `ok` (the LU
    /// otherwise).
    fn factorized(&mut self, ok: bool, seconds: f64) -> Result<()> {
        self.factor_seconds = seconds;
        if ok {
            self.factor_parallelism.record(self.factor_seconds);
        }
        self.timings.factorization += self.factor_seconds;
        self.timings.factorizations += 1;
        self.refactor_next = false;
        self.stale = false;
        self.factor_valid = ok;
        if !ok {
            return self.factorize_lu();
        }
        if self.symmetric {
            self.mode = Mode::Direct;
            self.stats.direct += 1;
        } else {
            self.mode = Mode::Preconditioned;
            self.stats.preconditioned += 1;
        }
        Ok(())
    }
}

/// Why the sparse LU of a matrix of `n` unknowns whose LDL^T factor holds `ldlt_entries` would
/// not fit in `available` bytes (None: it fits, or the memory is not known).
fn lu_refusal(n: usize, ldlt_entries: usize, available: Option<usize>) -> Option<String> {
    let need = ldlt_entries.saturating_mul(LU_BYTES_PER_LDLT_ENTRY);
    let available = available.filter(|&a| need > a)?;
    let gib = |b: usize| b as f64 / (1u64 << 30) as f64;
    Some(format!(
        "the LDL^T-preconditioned GMRES did not solve this matrix of {n} unknowns, and the sparse LU that would take over needs about {:.1} GiB, more than the {:.1} GiB available",
        gib(need),
        gib(available)
    ))
}

/// The parallelism of faer's numeric LDL^T, chosen by measurement, not assumed. With a parallel setting, the first numeric
/// factorisation of a pattern runs on the threads and the second on one; every later one the way
/// that was faster. Measured on the 2-core machine with `stamp bench` (2026-11-24): faer's
/// parallel supernodal factorisation spends its time in scheduling (a third of the samples in
/// the kernel's sched_yield and task switches), one factorisation 0.95 s on two threads against
/// 0.65 s on one at n = 200 (240 800 unknowns), 5.2 s either way at n = 400; on a machine with
/// more cores the threads may win, and then they are kept.
#[derive(Debug, Clone, Copy, Default)]
struct FactorParallelism {
    /// Seconds of the factorisation on the threads and on one, once measured.
    threads: Option<f64>,
    one: Option<f64>,
    /// The setting of the factorisation under way.
    trying: Option<Par>,
}

impl FactorParallelism {
    /// The setting for the next factorisation, given the solver's (`par`), without choosing it.
    fn next(&self, par: Par) -> Par {
        match (par, self.threads, self.threads_won()) {
            (Par::Seq, _, _) | (_, Some(_), None | Some(false)) => Par::Seq,
            _ => par,
        }
    }

    /// The setting for the next factorisation, given the solver's (`par`).
    fn choose(&mut self, par: Par) -> Par {
        let chosen = self.next(par);
        self.trying = Some(chosen);
        chosen
    }

    /// The seconds of the factorisation made with the last [`FactorParallelism::choose`].
    fn record(&mut self, seconds: f64) {
        match self.trying.take() {
            Some(Par::Seq) if self.threads.is_some() && self.one.is_none() => self.one = Some(seconds),
            Some(Par::Rayon(_)) if self.threads.is_none() => self.threads = Some(seconds),
            _ => {}
        }
    }

    /// Whether the threads were faster than one thread, once both were measured (a tie goes to
    /// one thread).
    fn threads_won(&self) -> Option<bool> {
        Some(self.threads? < self.one?)
    }
}

/// The numeric LDL^T of the matrix with `values` in the pattern (`col_ptr`, `row_idx`; the lower
/// triangle is read) into `factor`; false on a failure, a zero or a non-finite pivot.
fn factorize_numeric(sym: &SymbolicCholesky<usize>, buffer: &mut MemBuffer, factor: &mut [f64], col_ptr: &[usize], row_idx: &[usize], values: &[f64], par: Par) -> bool {
    let n = col_ptr.len() - 1;
    let pattern = SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx);
    let s = SparseColMatRef::new(pattern, values);
    let ok = sym.factorize_numeric_ldlt(factor, s, Side::Lower, LdltRegularization::default(), par, MemStack::new(buffer), Default::default()).is_ok();
    crate::linalg::vector_state::clean_upper_vector_state();
    ok && pivots(sym, factor).all(|d| d.is_finite() && d != 0.0)
}

/// The pivots D of an LDL^T factor, in the factor's (permuted) order: faer keeps them on L's
/// unit diagonal, the first entry of each column of a simplicial factor and the diagonal of each
/// supernode's dense block. Finite nonzero pivots mean a usable factor: every entry l_ij of L
/// enters the pivot d_i = a_ii - sum_j l_ij^2 d_j, so a NaN or infinity anywhere in L (a zero
/// pivot divided by) reaches a pivot; checking the n pivots replaces a pass over the whole
/// factor (310 M entries at n = 400 in `stamp bench`) and also catches a zero last pivot.
fn pivots<'a>(symbolic: &'a SymbolicCholesky<usize>, factor: &'a [f64]) -> Box<dyn Iterator<Item = f64> + 'a> {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => Box::new(s.col_ptr()[..s.ncols()].iter().map(move |&k| factor[k])),
        SymbolicCholeskyRaw::Supernodal(s) => Box::new((0..s.n_supernodes()).flat_map(move |k| {
            let (begin, end) = (s.supernode_begin()[k], s.supernode_end()[k]);
            let (first, last) = (s.col_ptr_for_val()[k], s.col_ptr_for_val()[k + 1]);
            let (ncols, nrows) = (end - begin, (last - first) / (end - begin));
            (0..ncols).map(move |j| factor[first + j * nrows + j])
        })),
    }
}

/// Rows per task of the parallel product.
const ROWS_PER_TASK: usize = 4096;

/// From A's values `a` in its symmetric pattern (`transpose`: the position of a_ji for each
/// a_ij): A by rows (`row_values`, see [`multiply_rows`]), the row sums of |A| (`row_sums`) and,
/// if given, the symmetric part (`symmetric`); returns max |a_ij - a_ji| and max |a_ij|. Columns
/// in parallel when `parallel`.
fn split_values(col_ptr: &[usize], transpose: &[usize], a: &[f64], row_values: &mut [f64], symmetric: Option<&mut [f64]>, row_sums: &mut [f64], parallel: bool) -> (f64, f64) {
    // the columns first..first + sums.len(), whose entries start at slot `base`
    let columns = |first: usize, base: usize, rows: &mut [f64], mut sym: Option<&mut [f64]>, sums: &mut [f64]| {
        crate::linalg::vector_state::clean_upper_vector_state();
        let (mut worst, mut size) = (0.0f64, 0.0f64);
        for (c, sum) in sums.iter_mut().enumerate() {
            let mut total = 0.0;
            for k in col_ptr[first + c]..col_ptr[first + c + 1] {
                let (v, t) = (a[k], a[transpose[k]]);
                rows[k - base] = t;
                total += t.abs();
                worst = worst.max((v - t).abs());
                size = size.max(v.abs());
                if let Some(s) = sym.as_deref_mut() {
                    s[k - base] = 0.5 * (v + t);
                }
            }
            *sum = total;
        }
        (worst, size)
    };
    let n = row_sums.len();
    if !parallel {
        return columns(0, 0, row_values, symmetric, row_sums);
    }
    // disjoint pieces of the output, ROWS_PER_TASK columns each
    let mut tasks = Vec::with_capacity(n.div_ceil(ROWS_PER_TASK));
    let (mut rows, mut sym, mut sums) = (row_values, symmetric, row_sums);
    let mut first = 0;
    while first < n {
        let last = (first + ROWS_PER_TASK).min(n);
        let len = col_ptr[last] - col_ptr[first];
        let (r_here, r_rest) = std::mem::take(&mut rows).split_at_mut(len);
        let (s_here, s_rest) = match sym.take() {
            Some(s) => {
                let (h, r) = s.split_at_mut(len);
                (Some(h), Some(r))
            }
            None => (None, None),
        };
        let (m_here, m_rest) = std::mem::take(&mut sums).split_at_mut(last - first);
        tasks.push((first, r_here, s_here, m_here));
        (rows, sym, sums) = (r_rest, s_rest, m_rest);
        first = last;
    }
    use rayon::prelude::*;
    tasks
        .into_par_iter()
        .map(|(first, rows, sym, sums)| columns(first, col_ptr[first], rows, sym, sums))
        .reduce(|| (0.0, 0.0), |x, y| (x.0.max(y.0), x.1.max(y.1)))
}

/// y = A x computed by rows, for a matrix of symmetric pattern: `row_values[k]` is
/// a_{c, row_idx[k]} for the k-th stored entry of column c (A^T stored in A's pattern), so that
/// y_c = sum_k row_values[k] x[row_idx[k]] over column c. Rows in parallel when `parallel`.
fn multiply_rows(col_ptr: &[usize], row_idx: &[usize], row_values: &[f64], x: &[f64], y: &mut [f64], parallel: bool) {
    let rows = |first: usize, out: &mut [f64]| {
        // a worker thread may come from faer's kernels (see crate::linalg::vector_state)
        crate::linalg::vector_state::clean_upper_vector_state();
        for (i, yi) in out.iter_mut().enumerate() {
            let c = first + i;
            *yi = (col_ptr[c]..col_ptr[c + 1]).map(|k| row_values[k] * x[row_idx[k]]).sum();
        }
    };
    if parallel {
        use rayon::prelude::*;
        y.par_chunks_mut(ROWS_PER_TASK).enumerate().for_each(|(chunk, out)| rows(chunk * ROWS_PER_TASK, out));
    } else {
        rows(0, y);
    }
}

/// y = A x for A in compressed columns.
#[cfg(test)]
fn multiply(col_ptr: &[usize], row_idx: &[usize], values: &[f64], x: &[f64], y: &mut [f64]) {
    y.iter_mut().for_each(|v| *v = 0.0);
    for (j, &xj) in x.iter().enumerate() {
        for k in col_ptr[j]..col_ptr[j + 1] {
            y[row_idx[k]] += values[k] * xj;
        }
    }
}

/// r = b - A x (A by rows, see [`multiply_rows`]); returns |r| / (|A| |x| + |b|) in infinity
/// norms.
#[allow(clippy::too_many_arguments)]
fn backward_error(col_ptr: &[usize], row_idx: &[usize], row_values: &[f64], parallel: bool, norm_inf: f64, b: &[f64], x: &[f64], r: &mut [f64]) -> f64 {
    multiply_rows(col_ptr, row_idx, row_values, x, r, parallel);
    for (ri, bi) in r.iter_mut().zip(b) {
        *ri = bi - *ri;
    }
    let inf = |v: &[f64]| v.iter().fold(0.0f64, |m, y| m.max(y.abs()));
    let denominator = norm_inf * inf(x) + inf(b);
    if denominator == 0.0 { 0.0 } else { inf(r) / denominator }
}

/// Map the memory of a zero-filled `v` now, by all threads: one write of zero per 4 KiB page
/// (512 values), volatile since the allocation is zero already and a plain write of zero could
/// be elided. The values stay zero.
fn touch_pages(v: &mut [f64]) {
    use rayon::prelude::*;
    v.par_chunks_mut(1 << 16).for_each(|chunk| {
        for page in chunk.chunks_mut(512) {
            // SAFETY: `page` is a non-empty slice (chunks_mut never yields an empty one)
            unsafe { std::ptr::write_volatile(page.as_mut_ptr(), 0.0) };
        }
    });
}

/// For every stored (i, j), the position of (j, i); None if the pattern is not symmetric. Row
/// indices must be sorted within each column (faer's invariant).
fn transpose_positions(col_ptr: &[usize], row_idx: &[usize]) -> Option<Vec<usize>> {
    let mut out = vec![0usize; row_idx.len()];
    crate::linalg::sparse::pair_transposed(col_ptr, row_idx, |k, partner| out[k] = partner).then_some(out)
}

/// Columns solved together by [`LdltGmres`]'s `solve_many_approx`.
const MANY_BLOCK: usize = 32;

impl LinearSolver for LdltGmres {
    fn factorize(&mut self, a: SparseColMatRef<'_, usize, f64>) -> Result<()> {
        self.factorize_preconditioned(a, None)
    }

    /// As `factorize`, with `p` (when given, A is not symmetric and
    /// [`LdltGmres::with_preconditioner`] is on) factorised as GMRES's preconditioner in place of
    /// A's symmetric part. `p` must have A's pattern; its lower
    /// triangle is read.
    fn uses_preconditioner(&self) -> bool {
        self.use_preconditioner
    }

    fn factorize_preconditioned(&mut self, a: SparseColMatRef<'_, usize, f64>, p: Option<SparseColMatRef<'_, usize, f64>>) -> Result<()> {
        self.factored = false;
        if a.nrows() != a.ncols() {
            return Err(StampError::LinearSolver(format!("a {} x {} matrix is not square", a.nrows(), a.ncols())));
        }
        if !self.same_pattern(a) {
            self.analyse(a)?;
        }
        self.r.resize(a.nrows(), 0.0);
        let Some(tr) = &self.transpose else {
            self.values.copy_from_slice(a.val());
            self.r.iter_mut().for_each(|v| *v = 0.0);
            for (k, v) in self.values.iter().enumerate() {
                self.r[self.row_idx[k]] += v.abs();
            }
            self.norm_inf = self.r.iter().fold(0.0f64, |m, x| m.max(*x));
            self.factorize_lu()?;
            self.factored = true;
            return Ok(());
        };
        let given = match p {
            Some(p) if self.use_preconditioner => {
                if !crate::linalg::sparse::same_pattern(p.symbolic(), a.symbolic()) {
                    return Err(StampError::LinearSolver("the preconditioner's pattern is not the matrix's".into()));
                }
                Some(p)
            }
            _ => None,
        };
        let par = parallelism_for(a.nrows(), self.par);
        let parallel = par != Par::Seq;
        // A given P factorised on one thread (FactorParallelism) leaves the other threads idle:
        // one of them takes A apart meanwhile (the pass below; at n = 400 in `stamp bench` about
        // 0.1 s per factorisation, hidden). Should A turn out symmetric, A itself is factorised
        // after. (Without reuse every factorisation is fresh.)
        if let (Some(p), true, false) = (given, parallel, self.reuse) {
            if self.factor_parallelism.next(par) == Par::Seq {
                self.factor_parallelism.choose(par);
                let (Some(sym), Some(buffer)) = (self.symbolic.as_ref(), self.buffer.as_mut()) else {
                    return Err(StampError::LinearSolver("no symbolic LDL^T for a symmetric pattern".into()));
                };
                let (col_ptr, row_idx, factor, row_values, r) = (&self.col_ptr, &self.row_idx, &mut self.factor, &mut self.row_values, &mut self.r);
                let t = Instant::now();
                let (ok, (worst, size)) = rayon::join(
                    || factorize_numeric(sym, buffer, factor, col_ptr, row_idx, p.val(), Par::Seq),
                    || split_values(col_ptr, tr, a.val(), row_values, None, r, false),
                );
                let seconds = t.elapsed().as_secs_f64();
                self.passed_over(worst, size);
                if self.symmetric {
                    // not the matrix to factorise after all (its time is not a measurement)
                    self.fresh_factorization(Some(a.val()))?;
                } else {
                    self.factorized(ok, seconds)?;
                }
                self.factored = true;
                return Ok(());
            }
        }
        // one pass over A: A by rows, its row sums, its asymmetry and size, and its symmetric
        // part unless a P will be factorised instead
        if given.is_none() || self.reuse {
            self.symmetric_values.resize(self.row_idx.len(), 0.0);
        }
        let sym = if given.is_some() { None } else { Some(self.symmetric_values.as_mut_slice()) };
        let (worst, size) = split_values(&self.col_ptr, tr, a.val(), &mut self.row_values, sym, &mut self.r, parallel);
        self.passed_over(worst, size);
        // the values to factorise: a symmetric A itself, else the given P, else the symmetric part
        // just written; kept when a factor may have to be renewed later (reuse), else read where
        // they lie (no copy: 0.4 GB at n = 400 in `stamp bench`)
        let mut values = match given {
            Some(_) if self.symmetric => Some(a.val()),
            Some(p) => Some(p.val()),
            None => None,
        };
        if let (Some(v), true) = (values, self.reuse) {
            self.symmetric_values.copy_from_slice(v);
            values = None;
        }
        if self.reuse && self.factor_valid && !self.refactor_next {
            self.mode = Mode::Preconditioned;
            self.stale = true;
            self.stats.reused += 1;
        } else {
            self.fresh_factorization(values)?;
        }
        self.factored = true;
        Ok(())
    }

    fn solve_in_place(&mut self, b: &mut [f64]) -> Result<()> {
        self.solve_in_place_to(b, 0.0)
    }

    fn solve_in_place_to(&mut self, b: &mut [f64], rtol: f64) -> Result<()> {
        let rtol = rtol.max(0.0);
        if !self.factored {
            return Err(StampError::LinearSolver("solve called without a successful factorisation".into()));
        }
        if self.mode == Mode::Lu {
            return self.lu.as_mut().unwrap().solve_in_place(b);
        }
        let t = Instant::now();
        self.rhs.clear();
        self.rhs.extend_from_slice(b);
        let ok = match self.mode {
            Mode::Direct => {
                let error = self.direct_solve(b);
                // what one preconditioned iteration would cost, for the budget of a stale solve
                self.iteration_seconds = t.elapsed().as_secs_f64();
                self.fresh_iterations = 1;
                error <= FALLBACK
            }
            _ => {
                // a stale factor may spend, over the iterations of the last fresh solve, at most
                // the iterations one factorisation costs
                let budget = if self.iteration_seconds > 0.0 { (self.factor_seconds / self.iteration_seconds).ceil() as usize } else { GMRES_MAX_ITERATIONS };
                let max_iterations = if self.stale { (self.fresh_iterations + budget.max(10)).min(GMRES_MAX_ITERATIONS) } else { GMRES_MAX_ITERATIONS };
                let ts = Instant::now();
                let report = self.preconditioned_solve(b, max_iterations, rtol);
                if report.iterations > 0 {
                    self.iteration_seconds = ts.elapsed().as_secs_f64() / report.iterations as f64;
                }
                if !self.stale {
                    self.fresh_iterations = report.iterations;
                } else if report.converged {
                    let extra = report.iterations.saturating_sub(self.fresh_iterations) as f64;
                    if extra * self.iteration_seconds > 0.5 * self.factor_seconds {
                        self.refactor_next = true;
                    }
                } else {
                    // the old factor is too far off: factorise this matrix and solve again
                    self.timings.solve += t.elapsed().as_secs_f64();
                    self.fresh_factorization(None)?;
                    b.copy_from_slice(&self.rhs);
                    return self.solve_in_place_to(b, rtol);
                }
                if !report.converged && std::env::var_os("STAMP_DEBUG").is_some() {
                    eprintln!("  GMRES: backward error {:.2e} after {} iterations (asked {rtol:.1e})", report.backward_error, report.iterations);
                }
                report.converged
            }
        };
        self.timings.solve += t.elapsed().as_secs_f64();
        self.timings.solves += 1;
        if !ok || b.iter().any(|x| !x.is_finite()) {
            if std::env::var_os("STAMP_DEBUG").is_some() {
                eprintln!("  linear solve not accurate enough ({:?}): the LU takes over", self.mode);
            }
            // not accurate enough on this matrix: the LU of the same values
            self.factorize_lu()?;
            b.copy_from_slice(&self.rhs);
            return self.lu.as_mut().unwrap().solve_in_place(b);
        }
        Ok(())
    }

    /// The LDL^T factor (of A when it is symmetric, of its preconditioner otherwise) applied to
    /// all the columns at once, in blocks of `MANY_BLOCK` (32) (a block of columns reads the factor
    /// once); the LU where that took over.
    fn solve_many_approx(&mut self, b: &mut [f64], ncols: usize) -> Result<()> {
        if ncols == 0 {
            return Ok(());
        }
        if !self.factored {
            return Err(StampError::LinearSolver("solve called without a successful factorisation".into()));
        }
        let n = b.len() / ncols;
        if self.mode == Mode::Lu {
            for col in b.chunks_mut(n) {
                self.lu.as_mut().unwrap().solve_in_place(col)?;
            }
            return Ok(());
        }
        let t = Instant::now();
        let sym = self.symbolic.as_ref().unwrap();
        let par = parallelism_for(n, self.par);
        let block = ncols.min(MANY_BLOCK);
        let scratch = sym.solve_in_place_scratch::<f64>(block, par);
        let mut buffer = MemBuffer::try_new(scratch).map_err(|_| StampError::LinearSolver("out of memory for the LDL^T solve's workspace".into()))?;
        for cols in b.chunks_mut(n * block) {
            let k = cols.len() / n;
            LdltRef::new(sym, &self.factor).solve_in_place_with_conj(Conj::No, MatMut::from_column_major_slice_mut(cols, n, k), par, MemStack::new(&mut buffer));
        }
        crate::linalg::vector_state::clean_upper_vector_state();
        self.timings.solve += t.elapsed().as_secs_f64();
        if b.iter().any(|x| !x.is_finite()) {
            return Err(StampError::LinearSolver("the solution has non-finite entries: the matrix is singular".into()));
        }
        Ok(())
    }

    /// With a supernodal factor large enough for the parallel solve (below that a whole solve is
    /// cheap); the factor of A when it is symmetric, of its preconditioner otherwise.
    fn forward_columns(&mut self, b: &[Vec<(usize, f64)>]) -> Result<Option<Vec<ForwardColumn>>> {
        if !self.factored || self.mode == Mode::Lu || self.supernodal.is_none() {
            return Ok(None);
        }
        let t = Instant::now();
        let sym = self.symbolic.as_ref().unwrap();
        if self.sparse_forward.is_none() {
            self.sparse_forward = SparseForward::new(sym);
        }
        let Some(forward) = self.sparse_forward.as_mut() else { return Ok(None) };
        let columns = b.iter().map(|g| forward.column(sym, &self.factor, g)).collect();
        self.timings.solve += t.elapsed().as_secs_f64();
        Ok(Some(columns))
    }

    fn timings(&self) -> SolverTimings {
        let mut t = self.timings;
        if let Some(lu) = &self.lu {
            let l = lu.timings();
            t.symbolic += l.symbolic;
            t.factorization += l.factorization;
            t.solve += l.solve;
            t.factorizations += l.factorizations;
            t.solves += l.solves;
        }
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    fn matrix(n: usize, entries: &[(usize, usize, f64)]) -> SparseColMat<usize, f64> {
        let t: Vec<Triplet<usize, usize, f64>> = entries.iter().map(|&(i, j, v)| Triplet::new(i, j, v)).collect();
        SparseColMat::try_new_from_triplets(n, n, &t).unwrap()
    }

    /// 1D Laplacian-like matrix of size n with a skew part `skew` on the off-diagonals and a
    /// diagonal shift.
    fn tridiagonal(n: usize, skew: f64, shift: f64) -> SparseColMat<usize, f64> {
        let mut e = Vec::new();
        for i in 0..n {
            e.push((i, i, 2.0 + shift));
            if i + 1 < n {
                e.push((i, i + 1, -1.0 + skew));
                e.push((i + 1, i, -1.0 - skew));
            }
        }
        matrix(n, &e)
    }

    /// The row-wise (parallel) product equals the column-wise one on a non-symmetric matrix of
    /// symmetric pattern spanning several row chunks.
    #[test]
    fn row_wise_product_matches_column_wise() {
        let n = 3 * ROWS_PER_TASK + 17;
        let a = tridiagonal(n, 0.3, 0.5);
        let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        let tr = transpose_positions(cp, ri).unwrap();
        let rows: Vec<f64> = tr.iter().map(|&k| v[k]).collect();
        let x: Vec<f64> = (0..n).map(|i| (0.7 * i as f64).sin()).collect();
        let mut expected = vec![0.0; n];
        multiply(cp, ri, v, &x, &mut expected);
        for parallel in [false, true] {
            let mut y = vec![f64::NAN; n];
            multiply_rows(cp, ri, &rows, &x, &mut y, parallel);
            let err = y.iter().zip(&expected).fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(err <= 1e-14, "parallel {parallel}: {err:e}");
        }
    }

    fn check_solution(a: &SparseColMat<usize, f64>, solver: &mut LdltGmres) {
        let n = a.nrows();
        let exact: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos() + 0.1 * i as f64).collect();
        let mut b = vec![0.0; n];
        multiply(a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val(), &exact, &mut b);
        solver.factorize(a.as_ref()).unwrap();
        solver.solve_in_place(&mut b).unwrap();
        let scale = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let err = b.iter().zip(&exact).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale;
        assert!(err < 1e-9, "error {err:e}, {:?}", solver.stats());
    }

    /// The LU is refused where ten times the LDL^T's entries exceed the memory available (the
    /// factor of n = 400 in `stamp bench`, 312 million entries, on a 24 GiB machine), allowed
    /// where they fit or the memory is not known.
    #[test]
    fn lu_refused_where_it_cannot_fit() {
        let gib = 1usize << 30;
        let why = lu_refusal(961_600, 312_000_000, Some(20 * gib)).expect("refused");
        assert!(why.contains("961600 unknowns") && why.contains("46.5 GiB") && why.contains("20.0 GiB available"), "{why}");
        assert_eq!(lu_refusal(60_400, 6_000_000, Some(20 * gib)), None);
        assert_eq!(lu_refusal(961_600, 312_000_000, None), None);
    }

    #[test]
    fn transpose_map_pairs_entries() {
        let a = tridiagonal(5, 0.3, 0.0);
        let (cp, ri, v) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        let tr = transpose_positions(cp, ri).unwrap();
        let col = |k: usize| cp.partition_point(|&c| c <= k) - 1;
        for (k, &p) in tr.iter().enumerate() {
            assert_eq!((ri[k], col(k)), (col(p), ri[p]));
            // below the diagonal -1 - skew, its partner above -1 + skew
            if ri[k] == col(k) + 1 {
                assert_eq!((v[k], v[p]), (-1.3, -0.7));
            }
        }
        // (0, 1) without (1, 0): not symmetric
        let b = matrix(2, &[(0, 0, 1.0), (0, 1, 1.0), (1, 1, 1.0)]);
        assert!(transpose_positions(b.symbolic().col_ptr(), b.symbolic().row_idx()).is_none());
    }

    /// The pivots read from faer's factor are those of A: their log sum is log det A, for a
    /// simplicial and a supernodal factor of the 2D Laplacian with three coupled unknowns per
    /// grid point (L (x) B, eigenvalues the products of L's and B's).
    #[test]
    fn pivots_multiply_to_the_determinant() {
        let b = [[2.0, 1.0, 0.0], [1.0, 2.0, 1.0], [0.0, 1.0, 2.0]];
        let b_eigen = [2.0 - 2f64.sqrt(), 2.0, 2.0 + 2f64.sqrt()];
        let mut kinds = Vec::new();
        for m in [6, 60] {
            let id = |i: usize, j: usize| i * m + j;
            let mut e = Vec::new();
            let mut couple = |p: usize, q: usize, v: f64| {
                for r in 0..3 {
                    for c in 0..3 {
                        if b[r][c] != 0.0 {
                            e.push((3 * p + r, 3 * q + c, v * b[r][c]));
                        }
                    }
                }
            };
            for i in 0..m {
                for j in 0..m {
                    couple(id(i, j), id(i, j), 4.0);
                    if i + 1 < m {
                        couple(id(i, j), id(i + 1, j), -1.0);
                        couple(id(i + 1, j), id(i, j), -1.0);
                    }
                    if j + 1 < m {
                        couple(id(i, j), id(i, j + 1), -1.0);
                        couple(id(i, j + 1), id(i, j), -1.0);
                    }
                }
            }
            let a = matrix(3 * m * m, &e);
            let mut s = LdltGmres::new();
            s.factorize(a.as_ref()).unwrap();
            let sym = s.symbolic.as_ref().unwrap();
            kinds.push(matches!(sym.raw(), SymbolicCholeskyRaw::Supernodal(_)));
            let log_det: f64 = pivots(sym, &s.factor).map(f64::ln).sum();
            let angle = |k: usize| 2.0 - 2.0 * (k as f64 * std::f64::consts::PI / (m + 1) as f64).cos();
            let expected: f64 = (1..=m).flat_map(|j| (1..=m).flat_map(move |k| b_eigen.map(|mu| ((angle(j) + angle(k)) * mu).ln()))).sum();
            assert!((log_det - expected).abs() <= 1e-10 * expected.abs(), "m = {m}: {log_det} against {expected}");
            assert_eq!(pivots(sym, &s.factor).count(), 3 * m * m);
        }
        assert_eq!(kinds, [false, true], "the factor kinds this test means to cover (supernodal?)");
    }

    #[test]
    fn symmetric_matrix_is_solved_directly() {
        let mut s = LdltGmres::new();
        check_solution(&tridiagonal(300, 0.0, 0.01), &mut s);
        assert_eq!((s.stats().direct, s.stats().preconditioned, s.stats().lu_fallbacks, s.stats().gmres_iterations), (1, 0, 0, 0));
    }

    #[test]
    fn symmetric_indefinite_matrix_is_solved_directly() {
        // a saddle point: [[2, 1], [1, -1]] blocks, quasi-definite
        let mut e = Vec::new();
        for k in 0..50 {
            let (i, j) = (2 * k, 2 * k + 1);
            e.extend([(i, i, 2.0), (i, j, 1.0), (j, i, 1.0), (j, j, -1.0)]);
        }
        let mut s = LdltGmres::new();
        check_solution(&matrix(100, &e), &mut s);
        assert_eq!(s.stats().direct, 1);
    }

    #[test]
    fn nonsymmetric_matrix_is_solved_by_preconditioned_gmres() {
        let mut s = LdltGmres::new().reuse(false);
        check_solution(&tridiagonal(300, 0.2, 0.01), &mut s);
        let st = s.stats();
        assert_eq!((st.preconditioned, st.lu_fallbacks), (1, 0), "{st:?}");
        assert!(st.gmres_iterations > 0);
        // the same pattern again: the symbolic phase is reused
        let before = s.timings().symbolic;
        check_solution(&tridiagonal(300, 0.1, 0.02), &mut s);
        assert_eq!(s.timings().symbolic, before);
        assert_eq!(s.stats().preconditioned, 2);
    }

    #[test]
    fn a_factor_is_reused_for_a_nearby_matrix_and_renewed_for_a_distant_one() {
        let mut s = LdltGmres::new().reuse(true);
        check_solution(&tridiagonal(400, 0.2, 0.01), &mut s);
        let first = s.stats().gmres_iterations;
        // nearby: solved with the first matrix's factor, to the same accuracy
        check_solution(&tridiagonal(400, 0.21, 0.011), &mut s);
        let st = s.stats();
        assert_eq!((st.preconditioned, st.reused, s.timings().factorizations), (1, 1, 1), "{st:?}");
        assert!(st.gmres_iterations > first, "{st:?}");
        // far off: after a nearly singular symmetric matrix (solved directly) a well-conditioned
        // one, whose GMRES on the old factor would need thousands of iterations: the stale solve
        // gives up (within 200 iterations whatever the clock says), the matrix is factorised and
        // solved again, accurately
        let mut s = LdltGmres::new().reuse(true);
        check_solution(&tridiagonal(400, 0.0, 1e-6), &mut s);
        check_solution(&tridiagonal(400, 0.4, 3.0), &mut s);
        let st = s.stats();
        assert_eq!((st.direct, st.reused, st.preconditioned, st.lu_fallbacks), (1, 1, 1, 0), "{st:?}");
        assert_eq!(s.timings().factorizations, 2, "{st:?}");
        // without reuse (the default) every matrix is factorised
        let mut s = LdltGmres::new();
        check_solution(&tridiagonal(400, 0.2, 0.01), &mut s);
        check_solution(&tridiagonal(400, 0.21, 0.011), &mut s);
        assert_eq!((s.stats().reused, s.timings().factorizations), (0, 2));
    }

    /// A k x k grid Laplacian with a skew part on the x couplings.
    fn grid(k: usize, skew: f64) -> SparseColMat<usize, f64> {
        let mut e = Vec::new();
        for (x, y) in (0..k).flat_map(|x| (0..k).map(move |y| (x, y))) {
            let i = x * k + y;
            e.push((i, i, 4.01));
            if x + 1 < k {
                e.extend([(i, i + k, -1.0 + skew), (i + k, i, -1.0 - skew)]);
            }
            if y + 1 < k {
                e.extend([(i, i + 1, -1.0), (i + 1, i, -1.0)]);
            }
        }
        matrix(k * k, &e)
    }

    /// Touching the pages of a zero vector keeps it zero, at every length (chunks and pages cut
    /// anywhere, the empty vector included).
    #[test]
    fn touched_pages_stay_zero() {
        for len in [0, 1, 511, 512, 513, (1 << 16) + 7, 3 << 16] {
            let mut v = vec![0.0; len];
            touch_pages(&mut v);
            assert!(v.len() == len && v.iter().all(|&x| x == 0.0), "{len}");
        }
    }

    #[test]
    fn both_orderings_solve_the_same_systems() {
        for skew in [0.0, 0.3] {
            let a = grid(40, skew);
            let mut amd = LdltGmres::new().ordering(Ordering::Amd);
            let mut nd = LdltGmres::new().ordering(Ordering::NestedDissection);
            // Auto: AMD below ND_MIN_UNKNOWNS
            let mut auto = LdltGmres::new();
            for s in [&mut amd, &mut nd, &mut auto] {
                check_solution(&a, s);
                assert_eq!(s.stats().lu_fallbacks, 0);
            }
            assert_eq!(amd.ordering_used(), Some(Ordering::Amd));
            assert_eq!(nd.ordering_used(), Some(Ordering::NestedDissection));
            assert_eq!(auto.ordering_used(), Some(Ordering::Amd));
            assert!(nd.factor_len() > 0 && nd.factor_len() != amd.factor_len());
            assert_eq!(auto.factor_len(), amd.factor_len());
        }
        // a structurally non-symmetric pattern: no LDL^T, no ordering
        let mut s = LdltGmres::new().ordering(Ordering::NestedDissection);
        check_solution(&matrix(3, &[(0, 0, 2.0), (0, 1, 1.0), (1, 1, 3.0), (2, 2, 1.0), (2, 0, 0.5)]), &mut s);
        assert_eq!((s.ordering_used(), s.factor_len()), (None, 0));
    }

    /// From `PARALLEL_MIN_ROWS` unknowns on, with a supernodal factor, the solves are the
    /// tree-parallel ones; they give the answers (and the GMRES iterations) of the same solve
    /// on one thread, which a sequential solver uses (both against faer's own solve: the unit
    /// tests of `crate::linalg::supernodal_solve`).
    #[test]
    fn large_matrices_use_the_parallel_supernodal_solve() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        for skew in [0.0, 0.3] {
            let a = grid(150, skew);
            assert!(a.nrows() >= crate::linalg::linear_solver::PARALLEL_MIN_ROWS);
            let mut parallel = LdltGmres::with_parallelism(Par::rayon(2));
            let mut sequential = LdltGmres::with_parallelism(Par::Seq);
            pool.install(|| check_solution(&a, &mut parallel));
            check_solution(&a, &mut sequential);
            assert!(parallel.supernodal.is_some() && sequential.supernodal.is_some());
            let (p, s) = (parallel.stats(), sequential.stats());
            assert_eq!((p.direct, p.preconditioned, p.lu_fallbacks), (s.direct, s.preconditioned, 0));
            assert_eq!(p.gmres_iterations, s.gmres_iterations, "{p:?} {s:?}");
            assert_eq!(p.direct, usize::from(skew == 0.0));
        }
    }

    /// The estimates for the linearised contact re-solve: many columns at once give what one
    /// solve each gives (the factor of A when symmetric, of S otherwise: there within GMRES's
    /// distance of A^-1 b); the forward halves of sparse vectors give b^T A^-1 c of a whole solve
    /// with a supernodal factor, and none with a simplicial one.
    #[test]
    fn many_columns_and_forward_halves_agree_with_single_solves() {
        for (k, skew) in [(150, 0.0), (150, 0.05), (12, 0.0)] {
            let a = grid(k, skew);
            let n = a.nrows();
            let mut solver = LdltGmres::new();
            solver.factorize(a.as_ref()).unwrap();
            let columns: Vec<Vec<f64>> = (0..3).map(|c| (0..n).map(|i| ((i * (c + 2)) as f64 * 0.37).sin()).collect()).collect();
            let mut many: Vec<f64> = columns.concat();
            solver.solve_many_approx(&mut many, 3).unwrap();
            for (c, col) in columns.iter().enumerate() {
                let mut one = col.clone();
                solver.solve_in_place(&mut one).unwrap();
                let scale = one.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let err = many[c * n..(c + 1) * n].iter().zip(&one).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale;
                let allowed = if skew == 0.0 { 1e-10 } else { 0.2 };
                assert!(err < allowed, "k = {k}, skew {skew}, column {c}: {err:e}");
            }
            let sparse: Vec<Vec<(usize, f64)>> = vec![vec![(n / 2, 1.0), (n / 2 + 1, -0.5)], vec![(7, 2.0)], vec![(n - 3, 1.0), (n / 3, 0.25)]];
            match solver.forward_columns(&sparse).unwrap() {
                Some(fc) => {
                    assert_eq!(k, 150, "forward halves from a simplicial factor");
                    for (i, bi) in sparse.iter().enumerate() {
                        let mut x = vec![0.0; n];
                        bi.iter().for_each(|&(e, v)| x[e] += v);
                        // the same factor (of A or S) applied whole
                        solver.solve_many_approx(&mut x, 1).unwrap();
                        for (j, bj) in sparse.iter().enumerate() {
                            let expected: f64 = bj.iter().map(|&(e, c)| c * x[e]).sum();
                            let got = fc[j].dot(&fc[i]);
                            assert!((got - expected).abs() <= 1e-12 * expected.abs().max(1e-3), "k = {k}, skew {skew}: {got} against {expected}");
                        }
                    }
                }
                None => assert!(k == 12, "no forward halves from the supernodal factor of {n} unknowns"),
            }
        }
    }

    /// With a parallel setting the first factorisation of a pattern runs on the threads, the
    /// second on one, the later ones the faster way; a sequential solver never tries the threads;
    /// a new pattern measures again.
    #[test]
    fn the_factorisation_parallelism_is_measured_then_chosen() {
        let mut f = FactorParallelism::default();
        assert_eq!(f.choose(Par::rayon(2)), Par::rayon(2));
        f.record(2.0);
        assert_eq!((f.choose(Par::rayon(2)), f.threads_won()), (Par::Seq, None));
        f.record(1.0);
        assert_eq!((f.choose(Par::rayon(2)), f.threads_won()), (Par::Seq, Some(false)));
        f.record(5.0);
        assert_eq!(f.choose(Par::rayon(2)), Par::Seq, "later timings do not undo the choice");
        let mut g = FactorParallelism::default();
        g.choose(Par::rayon(2));
        g.record(1.0);
        g.choose(Par::rayon(2));
        g.record(3.0);
        assert_eq!((g.choose(Par::rayon(2)), g.threads_won()), (Par::rayon(2), Some(true)));
        let mut h = FactorParallelism::default();
        assert_eq!(h.choose(Par::Seq), Par::Seq);
        h.record(1.0);
        assert_eq!((h.choose(Par::Seq), h.threads_won()), (Par::Seq, None));
        // in the solver: two factorisations of a large pattern settle it, a new pattern resets
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        let mut s = LdltGmres::with_parallelism(Par::rayon(2));
        pool.install(|| {
            check_solution(&grid(150, 0.0), &mut s);
            assert_eq!(s.factorizes_in_parallel(), None);
            check_solution(&grid(150, 0.0), &mut s);
            assert!(s.factorizes_in_parallel().is_some());
            check_solution(&grid(151, 0.0), &mut s);
            assert_eq!(s.factorizes_in_parallel(), None);
        });
    }

    /// A given P factorised on one thread while another takes A apart (the second factorisation
    /// of a pattern always runs on one thread) solves as the plain path does; a symmetric A with
    /// a P is factorised itself (direct), whichever path it takes.
    #[test]
    fn a_preconditioner_factorised_beside_the_pass_over_a_solves_the_same() {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        for skew in [0.3, 0.0] {
            let a = grid(150, skew);
            assert!(a.nrows() >= crate::linalg::linear_solver::PARALLEL_MIN_ROWS);
            let p = grid(150, 0.0);
            let n = a.nrows();
            let exact: Vec<f64> = (0..n).map(|i| (0.3 * i as f64).cos() + 0.1 * i as f64).collect();
            let mut s = LdltGmres::with_parallelism(Par::rayon(2));
            for round in 0..3 {
                // another A each round (a stale pass over A would show)
                let mut a = a.clone();
                a.val_mut().iter_mut().for_each(|v| *v *= 1.0 + 0.5 * round as f64);
                let mut x = vec![0.0; n];
                multiply(a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val(), &exact, &mut x);
                pool.install(|| {
                    s.factorize_preconditioned(a.as_ref(), Some(p.as_ref())).unwrap();
                    s.solve_in_place(&mut x).unwrap();
                });
                let scale = exact.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                let err = x.iter().zip(&exact).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max) / scale;
                assert!(err < 1e-9, "skew {skew}, round {round}: error {err:e}, {:?}", s.stats());
            }
            let st = s.stats();
            let expected = if skew == 0.0 { (3, 0) } else { (0, 3) };
            assert_eq!((st.direct, st.preconditioned, st.lu_fallbacks), (expected.0, expected.1, 0), "skew {skew}");
            assert!(s.factorizes_in_parallel().is_some());
        }
    }

    #[test]
    fn a_useless_symmetric_part_hands_over_to_the_lu() {
        // symmetric part singular (zero): [[0, 1], [-1, 0]] blocks
        let mut e = Vec::new();
        for k in 0..20 {
            let (i, j) = (2 * k, 2 * k + 1);
            e.extend([(i, i, 0.0), (i, j, 1.0), (j, i, -1.0), (j, j, 0.0)]);
        }
        let mut s = LdltGmres::new();
        check_solution(&matrix(40, &e), &mut s);
        assert_eq!(s.stats().lu_fallbacks, 1, "{:?}", s.stats());
    }

    #[test]
    fn a_structurally_nonsymmetric_matrix_goes_to_the_lu() {
        let a = matrix(3, &[(0, 0, 2.0), (0, 1, 1.0), (1, 1, 3.0), (2, 2, 1.0), (2, 0, 0.5)]);
        let mut s = LdltGmres::new();
        check_solution(&a, &mut s);
        assert_eq!(s.stats().lu_fallbacks, 1);
    }

    #[test]
    fn singular_matrix_is_an_error() {
        let a = matrix(3, &[(0, 0, 1.0), (1, 1, 0.0), (2, 2, 1.0), (0, 1, 0.0), (1, 0, 0.0)]);
        let mut s = LdltGmres::new();
        let mut b = vec![1.0, 1.0, 1.0];
        let r = s.factorize(a.as_ref()).and_then(|_| s.solve_in_place(&mut b));
        assert!(r.is_err(), "{b:?}");
    }
}

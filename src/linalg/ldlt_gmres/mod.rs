//! The fast linear solver for large plates: a sparse LDL^T of the symmetric part of the matrix,
//! used directly when the matrix is symmetric and as the preconditioner of GMRES when it is not.
//!
//! Why: the unsymmetric sparse LU orders its columns by COLAMD, which bounds the factors by the
//! structure of A^T A; on a 2D plate mesh its factors are about 10 times larger than the Cholesky
//! factor of the same pattern under AMD, and its factorisation several times slower (measured at
//! 60 400 unknowns, README "Speed": 2.1 s and a 1.4 GiB process for the LU against 0.32-0.45 s
//! and 0.4 GiB for the LDL^T). The plate's tangent is not symmetric only
//! because of the paper's b_ab33 = 0 (the thickness stress depends on the in-plane strains, not
//! the converse: the plate stiffness of the paper's eq. 2.6, docs/design.md "The model"): its symmetric part S = (A + A^T) / 2 is a good preconditioner,
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
//!
//! The files: `analysis.rs` the symbolic phase of a new pattern; `factorisation.rs` the numeric LDL^T
//! and the choice between the direct solve and GMRES; `solve.rs` the solves with the factor;
//! `fallback.rs` when and how the sparse LU takes over; `parallelism.rs` the factorisation's threads,
//! chosen by measurement; `matrix.rs` the passes over A's values (by rows, its symmetric part, its
//! backward error).

mod analysis;
mod factorisation;
mod fallback;
mod matrix;
mod parallelism;
mod solve;
#[cfg(test)]
mod tests;

use crate::error::Result;
use crate::linalg::gmres::Gmres;
use crate::linalg::linear_solver::{LinearSolver, SolverTimings, SparseLu};
use crate::linalg::supernodal_solve::{ForwardColumn, SparseForward, SupernodalSolve};
use faer::dyn_stack::MemBuffer;
use faer::sparse::linalg::cholesky::SymbolicCholesky;
use faer::sparse::SparseColMatRef;
use faer::Par;
use parallelism::FactorParallelism;

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
}

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
        self.factorize_matrix(a, p)
    }

    fn solve_in_place(&mut self, b: &mut [f64]) -> Result<()> {
        self.solve_in_place_to(b, 0.0)
    }

    fn solve_in_place_to(&mut self, b: &mut [f64], rtol: f64) -> Result<()> {
        self.solve_to(b, rtol)
    }

    /// The LDL^T factor (of A when it is symmetric, of its preconditioner otherwise) applied to
    /// all the columns at once, in blocks of 32 (a block of columns reads the factor once); the LU
    /// where that took over.
    fn solve_many_approx(&mut self, b: &mut [f64], ncols: usize) -> Result<()> {
        self.solve_many(b, ncols)
    }

    /// With a supernodal factor large enough for the parallel solve (below that a whole solve is
    /// cheap); the factor of A when it is symmetric, of its preconditioner otherwise.
    fn forward_columns(&mut self, b: &[Vec<(usize, f64)>]) -> Result<Option<Vec<ForwardColumn>>> {
        self.forward(b)
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

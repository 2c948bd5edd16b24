//! Sparse linear algebra: everything the nonlinear solver needs to solve K du = r, and nothing
//! that knows about elements, meshes or contact.
//!
//! - [`linear_solver`]: the [`LinearSolver`](linear_solver::LinearSolver) trait ("analyse the
//!   pattern once, factorise, solve") and [`SparseLu`](linear_solver::SparseLu), faer's sparse LU
//!   behind it; the thread-count rule shared by the solvers.
//! - [`ldlt_gmres`]: [`LdltGmres`](ldlt_gmres::LdltGmres), the solver for large meshes: a sparse
//!   LDL^T of the symmetric part, used directly when the matrix is symmetric and as the
//!   preconditioner of GMRES when it is not.
//! - [`gmres`]: restarted, right-preconditioned GMRES judged on the true backward error.
//! - [`supernodal_solve`]: the triangular solves with a supernodal LDL^T factor, scheduled on the
//!   elimination tree so that independent subtrees run in parallel.
//! - [`ordering`]: nested-dissection fill-reducing ordering (METIS on the nodal graph).
//! - [`partition`]: the elements split into parts for processes (METIS's k-way partition).
//! - [`bordered`]: [`BorderedSolver`](bordered::BorderedSolver), a sparse matrix bordered by a few
//!   dense rows and columns (the unknown punch displacement of a force-controlled step), solved
//!   by block elimination around any inner solver.
//! - [`sparse`]: the compressed-column sparsity pattern of the global tangent and the map from an
//!   element's local entries to its value slots, so that assembly refills values in place.
//! - [`vector_state`]: clearing the CPU's upper vector state after faer's AVX kernels, which
//!   otherwise slows the scalar code that runs after them.

pub mod bordered;
pub mod gmres;
pub mod ldlt_gmres;
pub mod linear_solver;
pub mod ordering;
pub mod partition;
pub mod sparse;
pub mod supernodal_solve;
pub mod vector_state;

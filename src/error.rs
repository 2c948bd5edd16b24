//! Errors of the framework. Every failure that bad input or a failed solve can cause is a value of
//! [`StampError`]; nothing in the library panics on user input.

use thiserror::Error;

/// Result alias used throughout stamp.
pub type Result<T> = std::result::Result<T, StampError>;

/// Everything that can go wrong in stamp, with enough context to act on it.
#[derive(Debug, Error)]
pub enum StampError {
    /// A mesh that cannot be used: empty, bad node indices, degenerate or inverted cells.
    #[error("mesh error: {0}")]
    Mesh(String),
    /// A material or section property out of its admissible range.
    #[error("invalid material or section: {0}")]
    Material(String),
    /// Bad input in a file: names the file and, where known, the line or entity.
    #[error("{file}: {message}")]
    Input { file: String, message: String },
    /// A boundary condition, load or punch that refers to something that does not exist.
    #[error("invalid problem definition: {0}")]
    Problem(String),
    /// A NaN or infinity appeared where a finite number was required.
    #[error("non-finite value: {0}")]
    NonFinite(String),
    /// An element refused the state it was evaluated at (see
    /// [`crate::element::LocalSystem::inadmissible`]).
    #[error("element {element} is in an inadmissible state: {reason}")]
    Inadmissible { element: usize, reason: String },
    /// The sparse factorisation failed (singular or structurally deficient matrix).
    #[error("linear solver failed: {0}")]
    LinearSolver(String),
    /// Newton-Raphson did not converge after all step cut-backs. Whatever converged before is kept
    /// by the caller; this error says where it stopped.
    #[error(
        "Newton-Raphson did not converge in load step {step} (load factor {load_factor:.6e}) after \
         {cutbacks} cut-backs: last residual {residual:.3e} (tolerance {tolerance:.3e}); {reason}"
    )]
    NoConvergence {
        step: usize,
        load_factor: f64,
        cutbacks: usize,
        residual: f64,
        tolerance: f64,
        reason: String,
    },
    /// An I/O error with the path it concerns.
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
}

impl StampError {
    /// Wrap an I/O error with the path it happened on.
    pub fn io(path: impl AsRef<std::path::Path>, source: std::io::Error) -> Self {
        StampError::Io { path: path.as_ref().display().to_string(), source }
    }
}

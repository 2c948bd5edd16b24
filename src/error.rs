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
    #[error("{}: {message}", short_path(file))]
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
         {cutbacks} cut-backs of this step: last residual {residual:.3e} (tolerance {tolerance:.3e}); {reason}"
    )]
    NoConvergence {
        step: usize,
        load_factor: f64,
        cutbacks: usize,
        residual: f64,
        tolerance: f64,
        reason: String,
    },
    /// The solve was interrupted on request (a signal): the step in progress was abandoned, the
    /// state is that of the last converged step.
    #[error("interrupted after load step {steps} (load factor {load_factor:.6e}): the step in progress was abandoned")]
    Interrupted { steps: usize, load_factor: f64 },
    /// The load path was given up before its end: more steps than allowed, or a pace that would
    /// need more ([`crate::nonlinear::NewtonSettings::max_steps`]).
    #[error("the load path was stopped after load step {steps} (load factor {load_factor:.6e}): {reason}")]
    StepLimit { steps: usize, load_factor: f64, reason: String },
    /// An error raised by another process of a distributed run, as it told it (the same message
    /// on every process).
    #[error("{0}")]
    Remote(String),
    /// An I/O error with the path it concerns.
    #[error("{}: {source}", short_path(path))]
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

/// Longest file path that a message shows in full; a longer one keeps its start and its end
/// (where the file's own name is) around an ellipsis.
pub const PATH_LIMIT: usize = 120;

/// A file path made fit to show in a message: control characters become `?`, and a path longer
/// than [`PATH_LIMIT`] characters keeps its first 40 and last 70 characters around
/// "...(N characters)...".
pub fn short_path(path: &str) -> String {
    let clean = |s: String| s.chars().map(|c| if c.is_control() { '?' } else { c }).collect::<String>();
    let total = path.chars().count();
    if total <= PATH_LIMIT {
        return clean(path.to_string());
    }
    let head: String = path.chars().take(40).collect();
    let tail: String = path.chars().skip(total - 70).collect();
    clean(format!("{head}...({total} characters)...{tail}"))
}

/// [`short_path`] of a path.
pub fn show_path(path: &std::path::Path) -> String {
    short_path(&path.display().to_string())
}

/// Longest piece of user text (a name, a value, a line of a file) that a message quotes.
pub const QUOTE_LIMIT: usize = 80;

/// User text made fit to quote in a message: control characters and bytes that are not printable
/// text become `?`, and anything past [`QUOTE_LIMIT`] characters is cut with "... (N characters)",
/// so that a message never echoes binary bytes or an unbounded string.
pub fn quote(text: &str) -> String {
    let total = text.chars().count();
    let mut out: String =
        text.chars().take(QUOTE_LIMIT).map(|c| if c.is_control() || c == '\u{fffd}' { '?' } else { c }).collect();
    if total > QUOTE_LIMIT {
        out.push_str(&format!("... ({total} characters)"));
    }
    out
}

/// [`quote`] for raw bytes (read from a file that may be binary).
pub fn quote_bytes(bytes: &[u8]) -> String {
    quote(&String::from_utf8_lossy(&bytes[..bytes.len().min(4 * QUOTE_LIMIT)]))
        + if bytes.len() > 4 * QUOTE_LIMIT { "..." } else { "" }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_paths_keep_their_start_and_end() {
        assert_eq!(short_path("meshes/plate.msh"), "meshes/plate.msh");
        let long = format!("/home/user/{}/plate.msh", "d".repeat(5000));
        let s = short_path(&long);
        assert!(s.chars().count() < 150, "{s}");
        assert!(s.starts_with("/home/user/ddd") && s.ends_with("ddd/plate.msh") && s.contains("...(5021 characters)..."), "{s}");
        let e = StampError::Input { file: long.clone(), message: "bad".into() };
        assert!(e.to_string().chars().count() < 160, "{e}");
        let e = StampError::io(&long, std::io::Error::other("no"));
        assert!(e.to_string().ends_with("plate.msh: no"), "{e}");
        assert_eq!(short_path("a\nb"), "a?b");
    }

    #[test]
    fn quote_cuts_long_text_and_hides_control_bytes() {
        assert_eq!(quote("abc"), "abc");
        assert_eq!(quote("a\u{0}b\nc"), "a?b?c");
        let long = "x".repeat(100_000);
        let q = quote(&long);
        assert!(q.len() < 120, "{q}");
        assert!(q.ends_with("(100000 characters)"), "{q}");
        assert_eq!(quote_bytes(&[b'a', 0xff, 0x00, b'b']), "a??b");
    }
}

//! The ranges of the settings: every number read from a problem file is checked against these
//! before it sizes anything or bounds a loop.

/// Largest magnitude of any length, modulus, force or coordinate: squares and products of
/// such numbers stay finite.
pub const MAX_MAGNITUDE: f64 = 1e100;
/// Smallest positive length, modulus or tolerance.
pub const MIN_MAGNITUDE: f64 = 1e-100;
/// Most equal steps (`solver.steps`) and most load increments a path may need at
/// `max_increment` (path length / max_increment).
pub const MAX_STEPS: u64 = 100_000;
/// Largest `solver.max_steps`.
pub const MAX_STEP_BUDGET: u64 = 10_000_000;
/// The default `solver.max_steps`: at least this many steps, and [`STEP_BUDGET_FACTOR`] times
/// the increments the path needs at max_increment (or its targets) if that is more.
pub const DEFAULT_MAX_STEPS: usize = 1000;
/// See [`DEFAULT_MAX_STEPS`].
pub const STEP_BUDGET_FACTOR: usize = 10;
/// Largest load factor of a target.
pub const MAX_LOAD_FACTOR: f64 = 1e6;
/// Smallest load increment (max_increment, min_increment, initial_increment).
pub const MIN_INCREMENT: f64 = 1e-12;
/// Smallest relative tolerance: a residual below 1e-15 of the forces is round-off.
pub const MIN_REL_TOL: f64 = 1e-15;
/// Newton iterations per step.
pub const MAX_ITERATIONS: u64 = 1000;
/// Line-search halvings (0.5^60 is below any meaningful step).
pub const MAX_LINE_SEARCH_STEPS: u64 = 60;
/// Cut-backs in a row (2^-100 of any increment is below MIN_INCREMENT).
pub const MAX_CUTBACKS: u64 = 100;
/// Cells along one side of the built-in rectangle.
pub const MAX_CELLS_PER_SIDE: u64 = 1_000_000;
/// Characters of a punch name (it names output files).
pub const MAX_NAME_CHARS: usize = 64;
/// The most rows of a punch's motion path.
pub const MAX_PATH_ROWS: usize = 10_000;
/// Bytes of a problem file.
pub const MAX_FILE_BYTES: u64 = 1 << 20;
/// Smallest penetration tolerance relative to the model size (largest coordinate, thickness
/// or punch radius): below it the penetration is round-off.
pub const MIN_PENETRATION_TOLERANCE: f64 = 1e-12;

//! The problem file of `stamp run`: a TOML document read with serde, every table with
//! `deny_unknown_fields`. Range checks happen while deserialising, so that toml's error carries the
//! line and column of the offending value; checks that need the mesh (group names) use the spans kept
//! in [`Spanned`] values and report `file:line:column` themselves.
//!
//! See `meshes/paper-r100.toml` for a complete annotated example.

pub mod units;

use serde::de::{Deserializer, Error as _};
use serde::Deserialize;
use stamp::error::QUOTE_LIMIT;
use stamp::{quote, Result, StampError};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

// ---------------------------------------------------------------------------------------------
// validated numbers: the error is raised inside the deserializer, so toml reports its line

/// A number as a message shows it: plain decimals for ordinary sizes, `{:e}` for tiny or huge ones
/// (so that 1e300 is not printed with 300 digits and 1e-200 does not show as 0).
pub fn num(v: f64) -> String {
    if v == 0.0 || (v.is_finite() && v.abs() >= 1e-4 && v.abs() < 1e15) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A vector as a message shows it (see [`num`]).
pub fn vec_text(v: &[f64]) -> String {
    format!("[{}]", v.iter().map(|x| num(*x)).collect::<Vec<_>>().join(", "))
}

macro_rules! checked_number {
    ($name:ident, $what:expr, $ok:expr) => {
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct $name(pub f64);
        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
                let v = f64::deserialize(d)?;
                let ok: fn(f64) -> bool = $ok;
                if v.is_finite() && ok(v) {
                    Ok($name(v))
                } else {
                    Err(D::Error::custom(format!("expected {}, got {}", $what, num(v))))
                }
            }
        }
    };
}

checked_number!(Positive, "a positive number from 1e-100 to 1e100", |v| (limits::MIN_MAGNITUDE..=limits::MAX_MAGNITUDE).contains(&v));
checked_number!(NonNegative, "a number from 0 to 1e100", |v| (0.0..=limits::MAX_MAGNITUDE).contains(&v));
checked_number!(Finite, "a finite number of magnitude at most 1e100", |v| v.abs() <= limits::MAX_MAGNITUDE);
checked_number!(Poisson, "Poisson's ratio in (-1, 0.5)", |v| v > -1.0 && v < 0.5);
checked_number!(Fraction, "a number in [0, 1)", |v| (0.0..1.0).contains(&v));
checked_number!(Increment, "a load increment in [1e-12, 1e6]", |v| (limits::MIN_INCREMENT..=limits::MAX_LOAD_FACTOR).contains(&v));
checked_number!(InitialIncrement, "a fraction of the first target in [1e-12, 1]", |v| (limits::MIN_INCREMENT..=1.0).contains(&v));
checked_number!(RelTol, "a relative tolerance in [1e-15, 0.1] (below 1e-15 floating point cannot reach it)", |v| (limits::MIN_REL_TOL..=0.1).contains(&v));

/// The ranges of the settings: every number read from a problem file is checked against these
/// before it sizes anything or bounds a loop.
pub mod limits {
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
}

/// Any number as written (a whole number of any size, or a float), for range messages that show
/// what was given instead of serde's "expected i64".
struct AnyNumber(std::result::Result<i128, f64>);

impl<'de> Deserialize<'de> for AnyNumber {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = AnyNumber;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a whole number")
            }
            fn visit_i64<E>(self, v: i64) -> std::result::Result<AnyNumber, E> {
                Ok(AnyNumber(Ok(v.into())))
            }
            fn visit_u64<E>(self, v: u64) -> std::result::Result<AnyNumber, E> {
                Ok(AnyNumber(Ok(v.into())))
            }
            fn visit_f64<E>(self, v: f64) -> std::result::Result<AnyNumber, E> {
                Ok(AnyNumber(Err(v)))
            }
        }
        d.deserialize_any(V)
    }
}

/// A whole number in a range, checked while deserialising (so toml gives the line).
macro_rules! checked_count {
    ($name:ident, $min:expr, $max:expr) => {
        #[derive(Debug, Clone, Copy, PartialEq, Eq)]
        pub struct $name(pub usize);
        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
                let (min, max): (u64, u64) = ($min, $max);
                match AnyNumber::deserialize(d)?.0 {
                    Ok(v) if v >= min as i128 && v <= max as i128 => Ok($name(v as usize)),
                    Ok(v) => Err(D::Error::custom(format!("expected a whole number from {min} to {max}, got {v}"))),
                    Err(v) => Err(D::Error::custom(format!("expected a whole number from {min} to {max}, got the decimal number {}", num(v)))),
                }
            }
        }
    };
}

checked_count!(StepCount, 1, limits::MAX_STEPS);
checked_count!(IterationCount, 1, limits::MAX_ITERATIONS);
checked_count!(CycleCount, 0, limits::MAX_ITERATIONS);
checked_count!(LineSearchCount, 0, limits::MAX_LINE_SEARCH_STEPS);
checked_count!(CutbackCount, 0, limits::MAX_CUTBACKS);
checked_count!(MaxStepCount, 1, limits::MAX_STEP_BUDGET);

/// A 3-vector of finite numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vec3(pub [f64; 3]);
impl<'de> Deserialize<'de> for Vec3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = <[f64; 3]>::deserialize(d)?;
        if v.iter().all(|x| x.is_finite() && x.abs() <= limits::MAX_MAGNITUDE) {
            Ok(Vec3(v))
        } else {
            Err(D::Error::custom(format!("expected three finite numbers of magnitude at most 1e100, got {}", vec_text(&v))))
        }
    }
}

/// A punch's prescribed motion: `[d1, d2, d3]` (the displacement at load factor 1, times the load
/// factor) or rows `[[t, d1, d2, d3], ...]`, a path piecewise linear in the load factor (checked by
/// [`stamp::contact::PunchMotion::path`]).
#[derive(Debug, Clone, PartialEq)]
pub struct MotionSpec(pub stamp::contact::PunchMotion);
impl<'de> Deserialize<'de> for MotionSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Linear(Vec<f64>),
            Path(Vec<Vec<f64>>),
        }
        const FORMS: &str = "expected [d1, d2, d3] (the displacement at load factor 1) or rows [[t, d1, d2, d3], ...] (a path in the load factor t)";
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite() && x.abs() <= limits::MAX_MAGNITUDE);
        match Raw::deserialize(d).map_err(|_| D::Error::custom(FORMS))? {
            Raw::Linear(v) if v.len() == 3 && finite(&v) => Ok(MotionSpec(stamp::contact::PunchMotion::Linear([v[0], v[1], v[2]]))),
            Raw::Linear(v) if v.len() == 3 => Err(D::Error::custom(format!("expected three finite numbers of magnitude at most 1e100, got {}", vec_text(&v)))),
            Raw::Linear(v) => Err(D::Error::custom(format!("{FORMS}, got {} numbers", v.len()))),
            Raw::Path(rows) => {
                if rows.len() > limits::MAX_PATH_ROWS {
                    return Err(D::Error::custom(format!("a path has at most {} rows, got {}", limits::MAX_PATH_ROWS, rows.len())));
                }
                let mut path = Vec::with_capacity(rows.len());
                for (k, r) in rows.iter().enumerate() {
                    if r.len() != 4 {
                        return Err(D::Error::custom(format!("path row {k}: expected [t, d1, d2, d3], got {} numbers", r.len())));
                    }
                    if !finite(r) {
                        return Err(D::Error::custom(format!("path row {k}: expected finite numbers of magnitude at most 1e100, got {}", vec_text(r))));
                    }
                    path.push((r[0], [r[1], r[2], r[3]]));
                }
                stamp::contact::PunchMotion::path(&path).map(MotionSpec).map_err(|e| D::Error::custom(format!("path {e}")))
            }
        }
    }
}

/// A non-zero 3-vector (a direction).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Direction(pub [f64; 3]);
impl<'de> Deserialize<'de> for Direction {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = Vec3::deserialize(d)?.0;
        // the squares must stay normal numbers, or normalising loses accuracy (or divides by 0)
        let largest = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        if largest == 0.0 {
            Err(D::Error::custom("expected a non-zero direction, got [0, 0, 0]"))
        } else if largest < 1e-150 {
            Err(D::Error::custom(format!("the direction [{}] is too small to normalise accurately (its largest component must be at least 1e-150)", v.map(|x| format!("{x:e}")).join(", "))))
        } else {
            Ok(Direction(v))
        }
    }
}

/// Load factors to reach in turn: finite, >= 0, each different from the one before (the path starts
/// at 0). They may go down again: loading, then unloading.
#[derive(Debug, Clone, PartialEq)]
pub struct Targets(pub Vec<f64>);
impl<'de> Deserialize<'de> for Targets {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        if v.len() as u64 > limits::MAX_STEPS {
            return Err(D::Error::custom(format!("at most {} load factors, got {}", limits::MAX_STEPS, v.len())));
        }
        if v.is_empty() {
            return Err(D::Error::custom("expected at least one load factor"));
        }
        let mut last = 0.0;
        for &t in &v {
            if !(t.is_finite() && t >= 0.0) {
                return Err(D::Error::custom(format!("load factors must be finite and >= 0, got {}", num(t))));
            }
            if t > limits::MAX_LOAD_FACTOR {
                return Err(D::Error::custom(format!("load factors must be at most {:e}, got {}", limits::MAX_LOAD_FACTOR, num(t))));
            }
            if t == last {
                return Err(D::Error::custom(format!("each load factor must differ from the one before (the path starts at 0): {} after {}", num(t), num(last))));
            }
            last = t;
        }
        Ok(Targets(v))
    }
}

// ---------------------------------------------------------------------------------------------
// degrees of freedom by name

/// Component indices (0..6: v1-, v2-, v3-, v1+, v2+, v3+) named by one constraint word.
#[derive(Debug, Clone, PartialEq)]
pub struct DofSet {
    pub word: String,
    pub components: Vec<usize>,
}

/// The constraint words: the six face displacements, v1/v2/v3 (both faces) and the shorthands.
pub const DOF_WORDS: &str = "v1-, v2-, v3-, v1+, v2+, v3+, v1, v2, v3 (both faces), clamped (all six), \
simply_supported (v3- and v3+), symmetry_x1 (v1- and v1+), symmetry_x2 (v2- and v2+)";

pub fn dof_components(word: &str) -> Option<Vec<usize>> {
    Some(match word {
        "v1-" => vec![0],
        "v2-" => vec![1],
        "v3-" => vec![2],
        "v1+" => vec![3],
        "v2+" => vec![4],
        "v3+" => vec![5],
        "v1" | "symmetry_x1" => vec![0, 3],
        "v2" | "symmetry_x2" => vec![1, 4],
        "v3" | "simply_supported" => vec![2, 5],
        "clamped" => vec![0, 1, 2, 3, 4, 5],
        _ => return None,
    })
}

impl<'de> Deserialize<'de> for DofSet {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let word = String::deserialize(d)?;
        match dof_components(&word) {
            Some(components) => Ok(DofSet { word, components }),
            None => Err(D::Error::custom(format!(
                "unknown displacement or constraint '{}'; expected one of v1-, v2-, v3-, v1+, v2+, v3+, v1, v2, v3, clamped, simply_supported, symmetry_x1, symmetry_x2",
                quote(&word)
            ))),
        }
    }
}

/// A dof word usable as a key of `prescribe` (anything but the shorthands with several meanings is
/// fine: "v3" prescribes both faces).
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct DofKey(pub String);
impl<'de> Deserialize<'de> for DofKey {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let word = String::deserialize(d)?;
        match word.as_str() {
            "v1-" | "v2-" | "v3-" | "v1+" | "v2+" | "v3+" | "v1" | "v2" | "v3" => Ok(DofKey(word)),
            _ => Err(D::Error::custom(format!("'{}' cannot be prescribed; expected one of v1-, v2-, v3-, v1+, v2+, v3+, v1, v2, v3", quote(&word)))),
        }
    }
}

// ---------------------------------------------------------------------------------------------
// the schema

/// The whole problem file.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProblemFile {
    /// Free text copied into summary.json.
    #[serde(default)]
    pub title: Option<String>,
    pub mesh: Spanned<MeshSpec>,
    pub plate: Spanned<PlateSpec>,
    /// Materials of the layers (`[[material]]`, see laminate_spec.rs).
    #[serde(default)]
    pub material: Vec<Spanned<MaterialSpec>>,
    #[serde(default)]
    pub boundary: Vec<Spanned<BoundarySpec>>,
    #[serde(default)]
    pub load: Vec<Spanned<LoadSpec>>,
    #[serde(default)]
    pub punch: Vec<Spanned<PunchSpec>>,
    #[serde(default)]
    pub solver: SolverSpec,
    #[serde(default)]
    pub output: OutputSpec,
    /// Unit names for labels (see units.rs).
    #[serde(default)]
    pub units: Option<crate::schema::units::UnitsSpec>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MeshSpec {
    /// gmsh MSH 4.1 file, relative to the problem file.
    #[serde(default)]
    pub file: Option<Spanned<String>>,
    /// Built-in structured mesh.
    #[serde(default)]
    pub rectangle: Option<RectangleSpec>,
    /// With `[solver] predictor = "coarse"` and a gmsh `file`: the coarse mesh of the same plate
    /// (the same physical groups), relative to the problem file.
    #[serde(default)]
    pub coarse_file: Option<Spanned<String>>,
}

/// The default largest load increment (`[solver] max_increment`).
pub const DEFAULT_MAX_INCREMENT: f64 = 0.25;

/// One `[[output.probe]]` table (the probe itself: probe.rs).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProbeSpec {
    pub name: String,
    pub from: [f64; 2],
    pub to: [f64; 2],
    #[serde(default)]
    pub points: Option<usize>,
}

/// Check the probes of a problem file (called by [`Problem::parse`]; see probe.rs) (names, ends, number of points), with file, line and key.
pub fn check_probes(p: &Problem, probes: &[Spanned<ProbeSpec>]) -> Result<()> {
    let mut names = std::collections::BTreeSet::new();
    for (i, s) in probes.iter().enumerate() {
        let spec = s.get_ref();
        let key = format!("output.probe[{i}]");
        let name = &spec.name;
        if name.is_empty() || name.len() > 64 || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
            return Err(p.error_at(s.span(), &format!("{key}.name"), format!("{} must be 1 to 64 letters, digits, '_' or '-' (it names files)", stamp::quote(name))));
        }
        if !names.insert(name.clone()) {
            return Err(p.error_at(s.span(), &format!("{key}.name"), format!("two probes are named {}", stamp::quote(name))));
        }
        if spec.from.iter().chain(&spec.to).any(|v| !v.is_finite()) {
            return Err(p.error_at(s.span(), &key, format!("from = {:?} and to = {:?} must be finite", spec.from, spec.to)));
        }
        if spec.from == spec.to {
            return Err(p.error_at(s.span(), &format!("{key}.to"), format!("the line has no length: from = to = {:?}", spec.from)));
        }
        if let Some(n) = spec.points {
            if !(2..=100_000).contains(&n) {
                return Err(p.error_at(s.span(), &format!("{key}.points"), format!("expected 2 to 100000 points, got {n}")));
            }
        }
    }
    Ok(())
}

/// A number or three numbers, as written.
#[derive(Debug, Clone, PartialEq)]
pub enum OneOrThree {
    One(f64),
    Three([f64; 3]),
}

impl<'de> Deserialize<'de> for OneOrThree {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            One(f64),
            Many(Vec<f64>),
        }
        const FORMS: &str = "expected a number (isotropic) or three numbers [1, 2, 3] in the ply's axes (orthotropic)";
        match Raw::deserialize(d).map_err(|_| D::Error::custom(FORMS))? {
            Raw::One(v) if v.is_finite() => Ok(OneOrThree::One(v)),
            Raw::Many(v) if v.len() == 3 && v.iter().all(|x| x.is_finite()) => Ok(OneOrThree::Three([v[0], v[1], v[2]])),
            Raw::Many(v) if v.len() == 3 => Err(D::Error::custom("expected three finite numbers")),
            Raw::Many(v) => Err(D::Error::custom(format!("{FORMS}, got {} numbers", v.len()))),
            Raw::One(_) => Err(D::Error::custom("expected a finite number")),
        }
    }
}

/// One `[[material]]` table (turned into a laminate by laminate_spec.rs).
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub name: String,
    #[serde(rename = "E")]
    pub young: OneOrThree,
    #[serde(rename = "G", default)]
    pub shear: Option<OneOrThree>,
    pub nu: OneOrThree,
}

/// One entry of `[plate] layers`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayerSpec {
    pub thickness: f64,
    pub material: String,
    #[serde(default)]
    pub angle: f64,
}

/// The default rows per layer.
pub const DEFAULT_POINTS_PER_LAYER: usize = 9;

/// One `[[output.thickness_probe]]` table (the probe itself: thickness_probe.rs).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ThicknessProbeSpec {
    pub name: String,
    pub at: [f64; 2],
    #[serde(default)]
    pub points_per_layer: Option<usize>,
    /// `"law"` (default): s13, s23 by each layer's 3D law; `"equilibrium"`: integrated from the
    /// bottom face (equilibrium_shear.rs).
    #[serde(default)]
    pub transverse_shear: Option<String>,
}

/// Names, points and counts, with file, line and key; a laminate is needed.
pub fn check_thickness_probes(p: &Problem, probes: &[Spanned<ThicknessProbeSpec>]) -> Result<()> {
    let mut names = std::collections::BTreeSet::new();
    for (i, s) in probes.iter().enumerate() {
        let spec = s.get_ref();
        let key = format!("output.thickness_probe[{i}]");
        let plate = p.spec.plate.get_ref();
        if plate.layers.is_none() && plate.surfaces() < 3 {
            return Err(p.error_at(
                s.span(),
                &key,
                "the stresses through the thickness are those of the 3D law: the plate needs `layers` or `surfaces` = 3 to 5 (the two-surface plate has the paper's plane-stress law)",
            ));
        }
        let name = &spec.name;
        if name.is_empty() || name.len() > 64 || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
            return Err(p.error_at(s.span(), &format!("{key}.name"), format!("{} must be 1 to 64 letters, digits, '_' or '-' (it names files)", stamp::quote(name))));
        }
        if !names.insert(name.clone()) {
            return Err(p.error_at(s.span(), &format!("{key}.name"), format!("two thickness probes are named {}", stamp::quote(name))));
        }
        if spec.at.iter().any(|v| !v.is_finite()) {
            return Err(p.error_at(s.span(), &format!("{key}.at"), format!("must be two finite numbers, got {:?}", spec.at)));
        }
        if let Some(t) = &spec.transverse_shear {
            if t != "law" && t != "equilibrium" {
                return Err(p.error_at(s.span(), &format!("{key}.transverse_shear"), format!("expected \"law\" or \"equilibrium\", got {}", stamp::quote(t))));
            }
        }
        if let Some(n) = spec.points_per_layer {
            if !(2..=1000).contains(&n) {
                return Err(p.error_at(s.span(), &format!("{key}.points_per_layer"), format!("expected 2 to 1000 points (the layer's faces among them), got {n}")));
            }
        }
    }
    Ok(())
}

/// The built-in rectangle, checked while deserialising: finite increasing intervals with a finite
/// extent, cells large enough for distinct node coordinates, and a node count (checked
/// arithmetic). Whether its model fits in memory is checked before the mesh is built (mesh.rs).
#[derive(Debug)]
pub struct RectangleSpec {
    pub x: [f64; 2],
    pub y: [f64; 2],
    pub n: [usize; 2],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawRectangle {
    // read as lists: serde's [f64; 2] takes the first two numbers of a longer array and drops the
    // rest without a word
    x: Vec<f64>,
    y: Vec<f64>,
    n: Vec<AnyNumber>,
}

/// Exactly two entries of `key`, else what is wrong.
fn exactly_two<T>(key: &str, what: &str, v: Vec<T>) -> std::result::Result<[T; 2], String> {
    let len = v.len();
    <[T; 2]>::try_from(v).map_err(|_| format!("mesh.rectangle.{key}: expected exactly two numbers {what}, got {len}"))
}

impl RectangleSpec {
    /// What is wrong with these values, if anything.
    fn check(x: [f64; 2], y: [f64; 2], n: [AnyNumber; 2]) -> std::result::Result<[usize; 2], String> {
        let max = limits::MAX_CELLS_PER_SIDE;
        let shown = |k: &AnyNumber| match k.0 {
            Ok(v) => v.to_string(),
            Err(v) => num(v),
        };
        let n = match (&n[0].0, &n[1].0) {
            (Ok(a), Ok(b)) if (1..=max as i128).contains(a) && (1..=max as i128).contains(b) => [*a as i64, *b as i64],
            _ => return Err(format!("mesh.rectangle.n: expected two whole numbers from 1 to {max}, got [{}, {}]", shown(&n[0]), shown(&n[1]))),
        };
        for (key, v, k) in [("x", x, n[0]), ("y", y, n[1])] {
            let extent = v[1] - v[0];
            if !(v.iter().all(|c| c.abs() <= limits::MAX_MAGNITUDE) && extent > 0.0) {
                return Err(format!("mesh.rectangle.{key}: expected an increasing interval of finite numbers (magnitude at most 1e100), got {}", vec_text(&v)));
            }
            // neighbouring nodes must have distinct coordinates with room to spare
            let scale = v[0].abs().max(v[1].abs());
            if extent / (k as f64) < 1e-9 * scale || extent / (k as f64) < 1e-150 {
                return Err(format!("mesh.rectangle.{key}: {} cells across {} are too small to tell their nodes apart (cell size {} against coordinates up to {})", k, vec_text(&v), num(extent / k as f64), num(scale)));
            }
        }
        let (nx, ny) = (n[0] as u64, n[1] as u64);
        (nx + 1).checked_mul(ny + 1).ok_or_else(|| format!("mesh.rectangle.n: [{nx}, {ny}] gives more nodes than this machine can count"))?;
        Ok([nx as usize, ny as usize])
    }
}

impl<'de> Deserialize<'de> for RectangleSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let r = RawRectangle::deserialize(d)?;
        let x = exactly_two("x", "[x_min, x_max]", r.x).map_err(D::Error::custom)?;
        let y = exactly_two("y", "[y_min, y_max]", r.y).map_err(D::Error::custom)?;
        let n = exactly_two("n", "[cells along x, cells along y]", r.n).map_err(D::Error::custom)?;
        let n = RectangleSpec::check(x, y, n).map_err(D::Error::custom)?;
        Ok(RectangleSpec { x, y, n })
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum KinematicsSpec {
    #[default]
    Nonlinear,
    Linear,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlateSpec {
    /// Thickness h of a plate centred on the reference plane (delta-+ = -+h/2) ...
    #[serde(default)]
    pub thickness: Option<Positive>,
    /// ... or the face planes x3 = delta_minus and x3 = delta_plus.
    #[serde(default)]
    pub delta_minus: Option<Finite>,
    #[serde(default)]
    pub delta_plus: Option<Finite>,
    /// Young's modulus and Poisson's ratio of a homogeneous plate (not with `layers`).
    #[serde(rename = "E", default)]
    pub young: Option<Positive>,
    #[serde(default)]
    pub nu: Option<Poisson>,
    /// The layers from the bottom face up (laminate_spec.rs); excludes `E`, `nu` and the thickness keys.
    #[serde(default)]
    pub layers: Option<Spanned<Vec<Spanned<LayerSpec>>>>,
    #[serde(default)]
    pub kinematics: KinematicsSpec,
    /// v1- = v1+ = 0 at every node.
    #[serde(default)]
    pub plane_strain: bool,
    /// Transverse shear factor k in (0, 1] (S_a3 = k G 2E_a3); default 1, the paper's.
    #[serde(default)]
    pub shear_factor: Option<Positive>,
    /// How S_33 enters the in-plane law: "dropped" (default, b_ab33 = 0) or "mean".
    #[serde(default)]
    pub normal_stress: stamp_elements::NormalStress,
    /// Surfaces through the thickness whose displacements are the unknowns: 2 (default, the
    /// paper's plate) to 5; with `layers`, the surfaces in each layer (3 to 5).
    #[serde(default)]
    pub surfaces: Option<Surfaces>,
}

impl PlateSpec {
    /// Surfaces through the thickness of a plate without layers (default 2).
    pub fn surfaces(&self) -> usize {
        self.surfaces.unwrap_or_default().0
    }
    /// Unknowns per node: 3 per surface; with L layers of N surfaces, 3 (L (N - 1) + 1).
    pub fn dofs_per_node(&self) -> u64 {
        match &self.layers {
            Some(l) => 3 * (l.get_ref().len() as u64 * (self.surfaces().max(2) as u64 - 1) + 1),
            None => 3 * self.surfaces() as u64,
        }
    }
}

/// `[plate] surfaces`: an integer from 2 to 5.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Surfaces(pub usize);
impl From<Surfaces> for usize {
    fn from(s: Surfaces) -> usize {
        s.0
    }
}
impl Default for Surfaces {
    fn default() -> Self {
        Surfaces(2)
    }
}
impl<'de> Deserialize<'de> for Surfaces {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = i64::deserialize(d)?;
        if (2..=5).contains(&v) {
            Ok(Surfaces(v as usize))
        } else {
            Err(D::Error::custom(format!(
                "{v}: expected 2 (the paper's plate: the two faces, displacement linear through the thickness) to 5 (faces and inner surfaces, displacement of degree surfaces - 1 through the thickness, the 3D law)"
            )))
        }
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundarySpec {
    pub group: Spanned<String>,
    /// Components held at zero.
    #[serde(default)]
    pub fix: Vec<DofSet>,
    /// Components prescribed to value * load factor.
    #[serde(default)]
    pub prescribe: BTreeMap<DofKey, Finite>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LoadKind {
    /// Force per unit length along a curve group.
    Line,
    /// Pressure on a face over a surface group.
    Pressure,
    /// Force per unit area over a surface group.
    Surface,
    /// Force at every node of a point group.
    Point,
    /// Couple per unit length along a curve group, carried by the two faces.
    Moment,
}

/// Where a load acts through the thickness.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum LoadFace {
    /// Half on each face (the mid-surface).
    #[default]
    Mid,
    Top,
    Bottom,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    #[serde(rename = "type")]
    pub kind: LoadKind,
    pub group: Spanned<String>,
    /// line: per unit length; surface: per unit area; point: a force. At load factor 1.
    #[serde(default)]
    pub force: Option<Vec3>,
    /// pressure: value at load factor 1, positive pushes on the face towards the plate; a number
    /// or an expression in x1, x2 (the syntax of a punch's `psi`).
    #[serde(default)]
    pub pressure: Option<Spanned<PressureSpec>>,
    #[serde(default)]
    pub face: Option<LoadFace>,
    /// moment: couple per unit length [m1, m2, m3] at load factor 1 (right-hand rule).
    #[serde(default)]
    pub moment: Option<Vec3>,
    /// pressure, moment: the load follows the deformation (default false: a dead load).
    #[serde(default)]
    pub follower: bool,
}

/// A pressure: one number, or an expression in x1, x2.
#[derive(Debug, Clone, PartialEq)]
pub enum PressureSpec {
    Uniform(f64),
    Expression(String),
}

impl<'de> Deserialize<'de> for PressureSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Raw {
            Number(f64),
            Text(String),
        }
        match Raw::deserialize(d).map_err(|_| D::Error::custom("expected a number or an expression in x1, x2 (a string, e.g. \"sin(pi*x1/10)*sin(pi*x2/10)\")"))? {
            Raw::Number(v) if v.is_finite() && v.abs() <= limits::MAX_MAGNITUDE => Ok(PressureSpec::Uniform(v)),
            Raw::Number(v) => Err(D::Error::custom(format!("expected a finite number of magnitude at most 1e100, got {}", num(v)))),
            Raw::Text(t) => Ok(PressureSpec::Expression(t)),
        }
    }
}

/// Whether an expression uses x3.
fn uses_x3(node: &stamp_contact::expression_parser::Node) -> bool {
    use stamp_contact::expression_parser::Node;
    match node {
        Node::Var(i) => *i == 2,
        Node::Const(_) => false,
        Node::Neg(a) => uses_x3(a),
        Node::Bin(_, a, b) => uses_x3(a) || uses_x3(b),
        Node::Call(_, args) => args.iter().any(uses_x3),
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Shape {
    Cylinder,
    Sphere,
    Plane,
    /// Psi written as an expression in x1, x2, x3 (`psi`).
    Expression,
    /// A triangulated surface read from an STL file (`file`).
    Stl,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum PunchFace {
    #[default]
    Top,
    Bottom,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ContactKinematicsSpec {
    Exact,
    Shallow,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PunchSpec {
    #[serde(default)]
    pub name: Option<String>,
    pub shape: Shape,
    /// cylinder: a point of the axis; plane: a point of the plane.
    #[serde(default)]
    pub point: Option<Vec3>,
    /// cylinder: the axis direction.
    #[serde(default)]
    pub axis: Option<Direction>,
    /// sphere: the centre.
    #[serde(default)]
    pub center: Option<Vec3>,
    /// cylinder, sphere.
    #[serde(default)]
    pub radius: Option<Positive>,
    /// plane: the normal pointing out of the punch, towards the plate.
    #[serde(default)]
    pub normal: Option<Direction>,
    /// stl: the STL file (ASCII or binary), relative to the problem file; its facet normals point
    /// to the plate's side.
    #[serde(default)]
    pub file: Option<Spanned<String>>,
    /// expression: Psi in x1, x2, x3 (negative inside the punch, zero on its surface).
    #[serde(default)]
    pub psi: Option<Spanned<String>>,
    /// Punch displacement at load factor 1, or a path of rows [t, d1, d2, d3] ...
    #[serde(default)]
    pub motion: Option<MotionSpec>,
    /// ... or the force pressing the punch at load factor 1 (its displacement along `direction` is
    /// then an unknown).
    #[serde(default)]
    pub force: Option<Finite>,
    /// Direction of the force (default: towards the plate, -x3 for a punch on the top face, +x3 on
    /// the bottom face).
    #[serde(default)]
    pub direction: Option<Direction>,
    #[serde(default)]
    pub face: PunchFace,
    /// Nodes that may touch (default: every node).
    #[serde(default)]
    pub group: Option<Spanned<String>>,
    /// Regularisation parameter (default: automatic, see build.rs).
    #[serde(default)]
    pub eps_reg: Option<Positive>,
    /// Augmented-Lagrangian penetration tolerance (a length).
    #[serde(default)]
    pub penetration_tolerance: Option<Spanned<Positive>>,
    /// Default: exact for a nonlinear plate, shallow (along x3) for a linear one.
    #[serde(default)]
    pub kinematics: Option<ContactKinematicsSpec>,
    /// How the constraint is discretised: "nodal" (the paper's collocation at the nodes) or
    /// "integrated" (each node's weighted gap over its cells); default: see build.rs.
    #[serde(default)]
    pub contact: Option<ContactSpec>,
}

/// `[[punch]] contact`: the discretisation of the contact constraint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ContactSpec {
    Nodal,
    Integrated,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Load factors at which results are wanted (default [1.0]) ...
    #[serde(default)]
    pub targets: Option<Spanned<Targets>>,
    /// ... or this many equal steps to load factor 1.
    #[serde(default)]
    pub steps: Option<Spanned<StepCount>>,
    #[serde(default)]
    pub max_increment: Option<Spanned<Increment>>,
    #[serde(default)]
    pub initial_increment: Option<InitialIncrement>,
    #[serde(default)]
    pub min_increment: Option<Spanned<Increment>>,
    #[serde(default)]
    pub rel_tol: Option<RelTol>,
    #[serde(default)]
    pub abs_tol: Option<NonNegative>,
    #[serde(default)]
    pub max_iterations: Option<IterationCount>,
    #[serde(default)]
    pub max_cutbacks: Option<CutbackCount>,
    /// Most converged load steps of the path (see [`Problem::max_steps`]).
    #[serde(default)]
    pub max_steps: Option<Spanned<MaxStepCount>>,
    #[serde(default)]
    pub line_search_steps: Option<LineSearchCount>,
    /// Give up a step whose active set swings at every iteration without progress from this
    /// iteration on, and cut it back (off by default; see NewtonSettings::cycling_after).
    #[serde(default)]
    pub cycling_after: Option<CycleCount>,
    /// Solve the linearised contact problem again on each factorisation (default true; see
    /// NewtonSettings::resolve_contact).
    #[serde(default)]
    pub resolve_contact: Option<bool>,
    /// Where each load step starts (default "secant").
    #[serde(default)]
    pub predictor: Option<Spanned<Predictor>>,
    /// Newton's tangent (default "mip").
    #[serde(default)]
    pub newton: Option<NewtonTangent>,
    /// PETSc options for the linear solve ("-ksp_type cg -pc_type gamg"), for a stamp built with
    /// the feature `petsc` (see crate::run::parallel).
    #[serde(default)]
    pub petsc_options: Option<Spanned<String>>,
}

/// `[solver] newton`: the stresses of Newton's geometric stiffness.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum NewtonTangent {
    /// The stresses of the strains linearised about the last iterate (the mixed-integration-point
    /// iteration, stamp::element::Element::evaluate_about): the same answers in fewer iterations
    /// on thin plates under large rotations.
    #[default]
    Mip,
    /// The stresses at the iterate: the exact derivative of the residual (the paper's Newton).
    Standard,
}

/// `[solver] predictor`: the start of each load step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Predictor {
    /// The last converged increment again (scaled to the step).
    #[default]
    Secant,
    /// The problem solved first on a coarse mesh (the rectangle with half its n, or
    /// `mesh.coarse_file`), interpolated onto the mesh (stamp::mesh::coarse_path).
    Coarse,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum PlotAxis {
    X1,
    #[default]
    X2,
    /// Arc length along `plot_group` (a curve group), in reference coordinates.
    Arc,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputSpec {
    /// Write one .vtu per converged step (and the .pvd).
    #[serde(default = "yes")]
    pub vtu: bool,
    /// Write the contact-pressure CSV per step and punch.
    #[serde(default = "yes")]
    pub csv: bool,
    /// Draw the probe plots (PNG and SVG); with no `[[output.probe]]`, a default probe through the
    /// first contact point along x1. On by default.
    #[serde(default = "yes")]
    pub plot: bool,
    #[serde(default)]
    pub plot_axis: PlotAxis,
    /// Only these nodes in the plot (required for plot_axis = "arc": a curve group).
    #[serde(default)]
    pub plot_group: Option<Spanned<String>>,
    /// Every converged step (true) or the targets only (false).
    #[serde(default = "yes")]
    pub every_step: bool,
    /// A node is in the loaded zone when |lambda| > loaded_threshold * max |lambda| (0.5 %: docs/verification.md,
    /// "The paper's benchmark").
    #[serde(default = "default_threshold")]
    pub loaded_threshold: Fraction,
    /// Lines along which the fields are sampled (see probe.rs).
    #[serde(default)]
    pub probe: Vec<Spanned<ProbeSpec>>,
    /// Points whose fields through the thickness are written (see thickness_probe.rs).
    #[serde(default)]
    pub thickness_probe: Vec<Spanned<ThicknessProbeSpec>>,
}

fn yes() -> bool {
    true
}
fn default_threshold() -> Fraction {
    Fraction(0.005)
}

impl Default for OutputSpec {
    fn default() -> Self {
        OutputSpec {
            vtu: true,
            csv: true,
            plot: true,
            plot_axis: PlotAxis::X2,
            plot_group: None,
            every_step: true,
            loaded_threshold: default_threshold(),
            probe: Vec::new(),
            thickness_probe: Vec::new(),
        }
    }
}

// ---------------------------------------------------------------------------------------------

/// "line L, column C" (1-based; the column counts characters) of a byte offset of `source`.
pub fn line_col_of(source: &str, offset: usize) -> (usize, usize) {
    let mut offset = offset.min(source.len());
    while !source.is_char_boundary(offset) {
        offset -= 1;
    }
    let before = &source[..offset];
    let line = before.matches('\n').count() + 1;
    let col = before[before.rfind('\n').map(|i| i + 1).unwrap_or(0)..].chars().count() + 1;
    (line, col)
}

/// toml's error as "line L, column C: what is wrong" followed by the offending line, both cut to
/// fit a message (toml itself would echo a line of any length in full).
fn toml_message(source: &str, e: &toml::de::Error) -> String {
    // serde quotes user text (an unknown key, a bad string) in full: cut every long word at 80
    // characters, and the whole at 300
    let what: Vec<String> = e.message().trim().split(' ').map(|w| if w.chars().count() > QUOTE_LIMIT { quote(w) } else { w.to_string() }).collect();
    let what = quote_long(&what.join(" "), 300);
    let Some(span) = e.span() else { return what };
    let (line, col) = line_col_of(source, span.start);
    // `E = 210 GPa`: toml asks for quotes, but the value is meant as a number
    // (toml may point inside the value, at the unit of `2e4MPa`: back to the value's start)
    let before = source.get(..span.start).unwrap_or("");
    let value_start = before.trim_end_matches(|c: char| c.is_ascii_digit() || matches!(c, '.' | '+' | '-' | '_' | 'e' | 'E')).len();
    let what = match number_with_unit(source.get(value_start..).unwrap_or("")) {
        Some((number, unit)) => format!(
            "'{}' is a number followed by a unit: values are plain numbers in the file's own consistent units (write {}); unit names are labels, given once in [units] (length, force, pressure)",
            quote(&format!("{number} {unit}")),
            quote(number)
        ),
        None => what,
    };
    // an unknown key: toml points at the key itself, which the message names; its table is named
    // before it ("punch[0]: unknown field `radios`")
    let unknown_key = || {
        let text = source.lines().nth(line.checked_sub(1)?)?;
        let eq = text.chars().skip(col.saturating_sub(1)).position(|c| c == '=')?;
        let key = key_at(source, line, col + eq + 1)?;
        key.rsplit_once('.').map(|(table, _)| table.to_string())
    };
    let key = if what.starts_with("unknown field") { unknown_key() } else { key_at(source, line, col) };
    let what = match key {
        // our own checks may name the key already ("mesh.rectangle.n: ...")
        Some(key) if !what.starts_with(&key) => format!("{}: {what}", quote(&key)),
        _ => what,
    };
    format!("line {line}, column {col}: {what}\n{}", source_window(source, line, col))
}

/// A value written as a number followed by a unit word (`210 GPa`, `2mm`, `0.05 N/mm`): the
/// number and the unit, else None. `text` starts at the value.
fn number_with_unit(text: &str) -> Option<(&str, &str)> {
    let line = text.lines().next()?;
    let end = line.find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '+' | '-' | '_' | 'e' | 'E'))).unwrap_or(line.len());
    // the longest prefix that is a number ("2e4MPa": "2e4"; "5em": "5")
    let (number, rest) = (1..=end).rev().map(|k| line.split_at(k)).find(|(n, _)| n.replace('_', "").parse::<f64>().is_ok())?;
    let rest = rest.trim_start();
    let unit_end = rest.find(|c: char| c.is_whitespace() || matches!(c, ',' | ']' | '}' | '#')).unwrap_or(rest.len());
    let unit = &rest[..unit_end];
    unit.chars().next().is_some_and(|c| c.is_alphabetic() || c == '%').then_some((number, unit))
}

/// "  L | <the line around the column>": the problem file's line under an error (at most 60
/// characters of it, from 30 before the column, control bytes hidden).
fn source_window(source: &str, line: usize, col: usize) -> String {
    let text = source.lines().nth(line.saturating_sub(1)).unwrap_or("");
    let skip = col.saturating_sub(30);
    let shown: String = text.chars().skip(skip).collect();
    format!("  {line} | {}{}", if skip > 0 { "..." } else { "" }, quote_long(&shown, 60))
}

/// The dotted key whose value sits at (line, column), for toml errors, which give only a place:
/// the last `key =` before the column on that line, after the last `[table]` header above it
/// ("solver.steps", "mesh.n" inside an inline table). None when the place is not a value.
fn key_at(source: &str, line: usize, col: usize) -> Option<String> {
    let text = source.lines().nth(line.checked_sub(1)?)?;
    let before: String = text.chars().take(col.saturating_sub(1)).collect();
    // walk the line up to the column: `key =` sets the pending key, `{` opens an inline table
    // under it, `}` closes one (strings are skipped)
    let (mut stack, mut pending, mut word, mut in_string): (Vec<String>, Option<String>, String, bool) = (Vec::new(), None, String::new(), false);
    for c in before.chars() {
        match c {
            '"' => in_string = !in_string,
            _ if in_string => {}
            '=' => pending = Some(std::mem::take(&mut word).trim().trim_matches('"').to_string()).filter(|k| !k.is_empty()),
            '{' => stack.extend(pending.take()),
            '}' => {
                stack.pop();
                pending = None;
            }
            ',' => word.clear(),
            c if c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.') => word.push(c),
            c if c.is_whitespace() => {}
            _ => word.clear(),
        }
    }
    stack.extend(pending);
    if stack.is_empty() {
        return None;
    }
    let key = stack.join(".");
    // the last header above; an array of tables ([[punch]]) gets its index, as in "punch[1]"
    let headers: Vec<(bool, String)> = source
        .lines()
        .take(line - 1)
        .filter_map(|l| {
            let l = l.trim();
            l.starts_with('[').then(|| (l.starts_with("[["), l.trim_start_matches('[').split(']').next().unwrap_or("").trim().to_string()))
        })
        .collect();
    Some(match headers.last() {
        Some((true, t)) => format!("{t}[{}].{key}", headers.iter().filter(|(a, h)| *a && h == t).count() - 1),
        Some((false, t)) if !t.is_empty() => format!("{t}.{key}"),
        _ => key,
    })
}

/// [`quote`] with a longer limit (toml's messages list expected keys): control characters become
/// '?', the text is cut at `limit` characters.
fn quote_long(text: &str, limit: usize) -> String {
    let total = text.chars().count();
    let mut out: String = text.chars().take(limit).map(|c| if c.is_control() { '?' } else { c }).collect();
    if total > limit {
        out.push_str(&format!("... ({total} characters)"));
    }
    out
}

/// A parsed problem with its file name and source text (for line numbers).
#[derive(Debug)]
pub struct Problem {
    pub path: PathBuf,
    pub source: String,
    pub spec: ProblemFile,
    /// A mesh given in memory (the Python package's arrays, [`stamp::io::mesh_from_arrays`]) in
    /// place of `[mesh] file` or `rectangle`.
    pub given_mesh: Option<std::sync::Arc<stamp::io::GmshMesh>>,
}

impl Problem {
    /// Read and parse a problem file.
    /// Only a regular file of at most [`limits::MAX_FILE_BYTES`] is read: a FIFO, a device or a
    /// folder is refused from its metadata, before it is opened (opening a FIFO blocks).
    pub fn read(path: &Path) -> Result<Problem> {
        let meta = std::fs::metadata(path).map_err(|e| StampError::io(path, e))?;
        let input = |message: String| StampError::Input { file: path.display().to_string(), message };
        if !meta.is_file() {
            let kind = if meta.is_dir() { "a folder" } else { "not a regular file (a FIFO, socket or device)" };
            return Err(input(format!("is {kind}; a problem file must be a regular file")));
        }
        if meta.len() > limits::MAX_FILE_BYTES {
            return Err(input(format!("is {} bytes long; a problem file has at most {} bytes", meta.len(), limits::MAX_FILE_BYTES)));
        }
        let mut bytes = Vec::new();
        let file = std::fs::File::open(path).map_err(|e| StampError::io(path, e))?;
        // the file may have grown since: read no more than the limit allows
        std::io::Read::read_to_end(&mut std::io::Read::take(file, limits::MAX_FILE_BYTES + 1), &mut bytes).map_err(|e| StampError::io(path, e))?;
        if bytes.len() as u64 > limits::MAX_FILE_BYTES {
            return Err(input(format!("has more than {} bytes; a problem file has at most that many", limits::MAX_FILE_BYTES)));
        }
        let source = String::from_utf8(bytes).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let (line, _) = line_col_of(&String::from_utf8_lossy(&e.as_bytes()[..at]), at);
            input(format!("line {line}: not UTF-8 text (byte {at})"))
        })?;
        Problem::parse(path, source)
    }

    /// The problem of a table built in memory (the Python package's dict), with the same schema,
    /// checks and messages as a file: the table is written as TOML (the text errors point into,
    /// [`Problem::source`]) and parsed as a file named `path` would be, relative paths starting
    /// in the folder of `path`. `mesh`, if given, takes the place of `[mesh] file` or `rectangle`
    /// (the table's `mesh` then has neither).
    pub fn from_table(path: &Path, table: toml::Table, mesh: Option<stamp::io::GmshMesh>) -> Result<Problem> {
        let source = toml::to_string(&table).map_err(|e| StampError::Input { file: path.display().to_string(), message: format!("cannot be written as TOML: {e}") })?;
        Problem::parse_with_mesh(path, source, mesh.map(std::sync::Arc::new))
    }

    /// Parse problem text (`path` names it in errors and anchors relative paths).
    pub fn parse(path: &Path, source: String) -> Result<Problem> {
        Problem::parse_with_mesh(path, source, None)
    }

    fn parse_with_mesh(path: &Path, source: String, given_mesh: Option<std::sync::Arc<stamp::io::GmshMesh>>) -> Result<Problem> {
        if source.trim_start().starts_with("$MeshFormat") {
            return Err(StampError::Input {
                file: path.display().to_string(),
                message: "this is a gmsh mesh, not a problem file: write a problem file (TOML) whose [mesh] file = names it".into(),
            });
        }
        let spec: ProblemFile = toml::from_str(&source).map_err(|e| StampError::Input { file: path.display().to_string(), message: toml_message(&source, &e) })?;
        let p = Problem { path: path.to_path_buf(), source, spec, given_mesh };
        p.check()?;
        Ok(p)
    }

    /// "line L, column C" of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        line_col_of(&self.source, offset)
    }

    /// An input error located at `span`, naming `key`.
    pub fn error_at(&self, span: std::ops::Range<usize>, key: &str, message: impl std::fmt::Display) -> StampError {
        let (line, col) = self.line_col(span.start);
        StampError::Input { file: self.path.display().to_string(), message: format!("line {line}, column {col}: {key}: {message}\n{}", source_window(&self.source, line, col)) }
    }

    /// An error in the expression `psi` at its 1-based character `column`: located in the file
    /// when the string is written without escapes (the column inside the string maps to the file),
    /// else at the string's start, naming the column inside it.
    pub fn psi_error(&self, psi: &Spanned<String>, column: usize, key: &str, message: &str) -> StampError {
        let span = psi.span();
        let raw = self.source.get(span.clone()).unwrap_or("");
        let text = psi.get_ref();
        let inner = raw.strip_prefix('"').and_then(|r| r.strip_suffix('"')).or_else(|| raw.strip_prefix('\'').and_then(|r| r.strip_suffix('\'')));
        if inner == Some(text.as_str()) && !text.contains('\n') {
            let offset: usize = text.chars().take(column - 1).map(char::len_utf8).sum();
            self.error_at(span.start + 1 + offset..span.end, key, message)
        } else {
            self.error_at(span, key, format!("column {column} of the expression: {message}"))
        }
    }

    /// Checks between keys that serde cannot express.
    fn check(&self) -> Result<()> {
        let s = &self.spec;
        let mesh = s.mesh.get_ref();
        let coarse = s.solver.predictor.as_ref().filter(|k| *k.get_ref() == Predictor::Coarse);
        if self.given_mesh.is_some() {
            if mesh.file.is_some() || mesh.rectangle.is_some() {
                return Err(self.error_at(s.mesh.span(), "mesh", "give the mesh as arrays (`nodes`, `cells`) or as `file` or `rectangle`, not both"));
            }
            if let Some(f) = &mesh.coarse_file {
                return Err(self.error_at(f.span(), "mesh.coarse_file", "belongs to a gmsh `file`, not to a mesh given as arrays"));
            }
            if let Some(k) = coarse {
                return Err(self.error_at(k.span(), "solver.predictor", "\"coarse\" needs a coarse mesh of the same plate: give the mesh as `rectangle`, or as a gmsh `file` with `coarse_file`"));
            }
            return self.check_rest();
        }
        if mesh.file.is_some() == mesh.rectangle.is_some() {
            return Err(self.error_at(s.mesh.span(), "mesh", "give exactly one of `file` (a gmsh .msh) and `rectangle`"));
        }
        if let Some(r) = &mesh.rectangle {
            if !(r.x[1] > r.x[0] && r.y[1] > r.y[0]) || r.x.iter().chain(&r.y).any(|v| !v.is_finite()) {
                return Err(self.error_at(s.mesh.span(), "mesh.rectangle", format!("x = {:?} and y = {:?} must be finite, increasing intervals", r.x, r.y)));
            }
            if r.n[0] == 0 || r.n[1] == 0 {
                return Err(self.error_at(s.mesh.span(), "mesh.rectangle.n", format!("needs at least one cell each way, got {:?}", r.n)));
            }
        }
        match (&mesh.rectangle, &mesh.coarse_file, coarse) {
            (Some(_), Some(f), _) => {
                return Err(self.error_at(f.span(), "mesh.coarse_file", "belongs to a gmsh `file`: with `rectangle`, predictor = \"coarse\" halves its n"));
            }
            (None, Some(f), None) => {
                return Err(self.error_at(f.span(), "mesh.coarse_file", "is read only with [solver] predictor = \"coarse\""));
            }
            (None, None, Some(k)) => {
                return Err(self.error_at(k.span(), "solver.predictor", "\"coarse\" with a gmsh mesh needs [mesh] coarse_file: the same plate meshed coarser, with the same physical groups"));
            }
            (Some(r), None, Some(k)) if r.n[0] % 2 == 1 || r.n[1] % 2 == 1 => {
                return Err(self.error_at(
                    k.span(),
                    "solver.predictor",
                    format!("\"coarse\" solves first on the rectangle with half its n: mesh.rectangle.n = {:?} must be even numbers", r.n),
                ));
            }
            _ => {}
        }
        self.check_rest()
    }

    /// The checks after the mesh's.
    fn check_rest(&self) -> Result<()> {
        let s = &self.spec;
        let plate = s.plate.get_ref();
        if plate.layers.is_none() {
            for (k, given) in [("E", plate.young.is_some()), ("nu", plate.nu.is_some())] {
                if !given {
                    return Err(self.error_at(s.plate.span(), &format!("plate.{k}"), format!("missing field `{k}`: give E and nu of a homogeneous plate, or `layers` with [[material]] tables")));
                }
            }
        }
        match (plate.thickness, plate.delta_minus, plate.delta_plus) {
            _ if plate.layers.is_some() => {}
            (Some(_), None, None) => {}
            (None, Some(a), Some(b)) => {
                if !(b.0 > a.0) {
                    return Err(self.error_at(s.plate.span(), "plate.delta_plus", format!("must exceed delta_minus (thickness delta_plus - delta_minus = {} must be positive)", b.0 - a.0)));
                }
            }
            _ => {
                return Err(self.error_at(s.plate.span(), "plate.thickness", "give either `thickness` or both `delta_minus` and `delta_plus`"));
            }
        }
        for (i, b) in s.boundary.iter().enumerate() {
            let bs = b.get_ref();
            if bs.fix.is_empty() && bs.prescribe.is_empty() {
                return Err(self.error_at(b.span(), &format!("boundary[{i}]"), "needs `fix` or `prescribe`"));
            }
        }
        for (i, l) in s.load.iter().enumerate() {
            let ls = l.get_ref();
            let key = format!("load[{i}]");
            match ls.kind {
                LoadKind::Pressure => {
                    if ls.pressure.is_none() || ls.force.is_some() {
                        return Err(self.error_at(l.span(), &key, "a pressure load needs `pressure` (and no `force`)"));
                    }
                    if ls.face.is_none() || ls.face == Some(LoadFace::Mid) {
                        return Err(self.error_at(l.span(), &format!("{key}.face"), "a pressure acts on face = \"top\" or \"bottom\""));
                    }
                    let q = ls.pressure.as_ref().unwrap();
                    if let PressureSpec::Expression(text) = q.get_ref() {
                        let spanned = Spanned::new(q.span(), text.clone());
                        match stamp_contact::expression_parser::parse(text) {
                            Err(e) => return Err(self.psi_error(&spanned, e.column, &format!("{key}.pressure"), &e.message)),
                            Ok(node) if uses_x3(&node) => {
                                return Err(self.error_at(q.span(), &format!("{key}.pressure"), "a pressure over the plate is a function of x1 and x2; it cannot use x3"));
                            }
                            Ok(_) => {}
                        }
                    }
                }
                LoadKind::Moment => {
                    let Some(m) = ls.moment else {
                        return Err(self.error_at(l.span(), &key, "a moment load needs `moment` = [m1, m2, m3] (a couple per unit length)"));
                    };
                    if ls.force.is_some() || ls.pressure.is_some() || ls.face.is_some() {
                        return Err(self.error_at(l.span(), &key, "a moment load takes `moment` (and no `force`, `pressure` or `face`: it acts through both faces)"));
                    }
                    // the plate's fibre carries no twist about itself: the part of the couple along
                    // the fibre is dropped (all of m3 at the start, fixed or follower alike)
                    if m.0[2] != 0.0 {
                        let kind = if ls.follower { "a follower couple (follower = true)" } else { "a fixed couple (follower = false)" };
                        let whole = if m.0[0] == 0.0 && m.0[1] == 0.0 { " (with m1 = m2 = 0 the whole load would be dropped)" } else { "" };
                        return Err(self.error_at(
                            l.span(),
                            &format!("{key}.moment"),
                            format!("{kind} cannot twist about the plate's normal: m3 must be 0, got {}{whole}", num(m.0[2])),
                        ));
                    }
                }
                _ => {
                    if ls.force.is_none() || ls.pressure.is_some() || ls.moment.is_some() {
                        return Err(self.error_at(l.span(), &key, "a line, surface or point load needs `force` (and no `pressure` or `moment`)"));
                    }
                    if ls.follower {
                        return Err(self.error_at(l.span(), &format!("{key}.follower"), "only a pressure or a moment load can follow the deformation"));
                    }
                }
            }
            if ls.kind == LoadKind::Pressure && ls.moment.is_some() {
                return Err(self.error_at(l.span(), &key, "a pressure load takes no `moment`"));
            }
        }
        let mut names = std::collections::BTreeSet::new();
        for (i, p) in s.punch.iter().enumerate() {
            let ps = p.get_ref();
            let key = format!("punch[{i}]");
            let need = |ok: bool, what: &str| -> Result<()> {
                if ok {
                    Ok(())
                } else {
                    Err(self.error_at(p.span(), &key, what))
                }
            };
            match ps.shape {
                Shape::Cylinder => need(
                    ps.point.is_some() && ps.axis.is_some() && ps.radius.is_some() && ps.center.is_none() && ps.normal.is_none(),
                    "a cylinder needs `point`, `axis` and `radius` (and no `center` or `normal`)",
                )?,
                Shape::Sphere => need(
                    ps.center.is_some() && ps.radius.is_some() && ps.point.is_none() && ps.axis.is_none() && ps.normal.is_none(),
                    "a sphere needs `center` and `radius` (and no `point`, `axis` or `normal`)",
                )?,
                Shape::Plane => need(
                    ps.point.is_some() && ps.normal.is_some() && ps.radius.is_none() && ps.axis.is_none() && ps.center.is_none(),
                    "a plane needs `point` and `normal` (and no `radius`, `axis` or `center`)",
                )?,
                Shape::Expression => {
                    need(
                        ps.psi.is_some() && ps.point.is_none() && ps.axis.is_none() && ps.center.is_none() && ps.radius.is_none() && ps.normal.is_none(),
                        "an expression punch needs `psi` (and no `point`, `axis`, `center`, `radius` or `normal`)",
                    )?;
                    let psi = ps.psi.as_ref().unwrap();
                    if let Err(e) = stamp_contact::expression_parser::parse(psi.get_ref()) {
                        return Err(self.psi_error(psi, e.column, &format!("{key}.psi"), &e.message));
                    }
                }
                Shape::Stl => need(
                    ps.file.is_some() && ps.point.is_none() && ps.axis.is_none() && ps.center.is_none() && ps.radius.is_none() && ps.normal.is_none(),
                    "an stl die needs `file` (and no `point`, `axis`, `center`, `radius` or `normal`: the die is where the file puts it)",
                )?,
            }
            if ps.shape != Shape::Expression && ps.psi.is_some() {
                return Err(self.error_at(ps.psi.as_ref().unwrap().span(), &format!("{key}.psi"), "`psi` belongs to shape = \"expression\""));
            }
            if ps.file.is_some() && ps.shape != Shape::Stl {
                return Err(self.error_at(ps.file.as_ref().unwrap().span(), &format!("{key}.file"), "`file` is the STL file of shape = \"stl\""));
            }
            if ps.force.is_some() && ps.motion.is_some() {
                return Err(self.error_at(p.span(), &format!("{key}.force"), "give `motion` (displacement driven) or `force` (force driven), not both"));
            }
            if ps.direction.is_some() && ps.force.is_none() {
                return Err(self.error_at(p.span(), &format!("{key}.direction"), "`direction` is the direction of `force`; it needs `force`"));
            }
            let name = self.punch_name(i);
            if name.is_empty() || name.chars().count() > limits::MAX_NAME_CHARS || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
                return Err(self.error_at(
                    p.span(),
                    &format!("{key}.name"),
                    format!("'{}' must be 1 to {} letters, digits, '_' or '-' (it names files)", quote(&name), limits::MAX_NAME_CHARS),
                ));
            }
            if !names.insert(name.clone()) {
                return Err(self.error_at(p.span(), &format!("{key}.name"), format!("two punches are named '{}'", quote(&name))));
            }
        }
        if s.solver.targets.is_some() && s.solver.steps.is_some() {
            let t = s.solver.targets.as_ref().unwrap();
            return Err(self.error_at(t.span(), "solver.targets", "give `targets` or `steps`, not both"));
        }
        self.check_increments()?;
        check_probes(self, &s.output.probe)?;
        check_thickness_probes(self, &s.output.thickness_probe)?;
        if s.output.plot_axis == PlotAxis::Arc && s.output.plot_group.is_none() {
            return Err(StampError::Input {
                file: self.path.display().to_string(),
                message: "output.plot_axis = \"arc\" needs output.plot_group (a curve group)".into(),
            });
        }
        Ok(())
    }

    /// The load increments against the path: min_increment <= max_increment, at most
    /// [`limits::MAX_STEPS`] increments of max_increment along the path, and a min_increment above
    /// the round-off of the largest load factor (so that every increment moves the load).
    fn check_increments(&self) -> Result<()> {
        let sv = &self.spec.solver;
        let defaults = stamp::nonlinear::NewtonSettings::default();
        let max_inc = sv.max_increment.as_ref().map_or(DEFAULT_MAX_INCREMENT, |x| x.get_ref().0);
        let min_inc = sv.min_increment.as_ref().map_or(defaults.min_increment, |x| x.get_ref().0);
        // where to point: the key given, else the [solver] targets/steps, else the file
        let span_of = |k: &Option<Spanned<Increment>>| k.as_ref().map(|x| x.span()).or_else(|| sv.targets.as_ref().map(|t| t.span())).or_else(|| sv.steps.as_ref().map(|t| t.span()));
        let fail = |span: Option<std::ops::Range<usize>>, key: &str, message: String| match span {
            Some(sp) => self.error_at(sp, key, message),
            None => StampError::Input { file: self.path.display().to_string(), message: format!("{key}: {message}") },
        };
        if min_inc > max_inc {
            return Err(fail(span_of(&sv.min_increment), "solver.min_increment", format!("{} exceeds max_increment = {}", num(min_inc), num(max_inc))));
        }
        let targets = self.targets();
        let path: f64 = targets.iter().fold((0.0, 0.0), |(len, last): (f64, f64), &t| (len + (t - last).abs(), t)).0;
        let increments = path / max_inc;
        if increments > limits::MAX_STEPS as f64 {
            return Err(fail(
                span_of(&sv.max_increment),
                "solver.max_increment",
                format!("the load path (length {}) needs {} increments of max_increment = {}; at most {} are allowed: raise max_increment or shorten the targets", num(path), num(increments.ceil()), num(max_inc), limits::MAX_STEPS),
            ));
        }
        if let Some(m) = &sv.max_steps {
            let least = self.least_steps();
            if m.get_ref().0 < least {
                return Err(self.error_at(m.span(), "solver.max_steps", format!("{} is fewer than the {least} steps the path needs at least (its targets, and increments of at most max_increment = {})", m.get_ref().0, num(max_inc))));
            }
        }
        let largest = targets.iter().cloned().fold(1.0, f64::max);
        let floor = 1e-12 * largest;
        if min_inc < floor {
            return Err(fail(span_of(&sv.min_increment), "solver.min_increment", format!("{} is below the round-off of load factors up to {}; the smallest allowed is {}", num(min_inc), num(largest), num(floor))));
        }
        Ok(())
    }

    /// The fewest steps the path can take: one per target, and as many increments of
    /// max_increment as its length needs.
    pub fn least_steps(&self) -> usize {
        let max_inc = self.spec.solver.max_increment.as_ref().map_or(DEFAULT_MAX_INCREMENT, |x| x.get_ref().0);
        let targets = self.targets();
        let path: f64 = targets.iter().fold((0.0, 0.0), |(len, last): (f64, f64), &t| (len + (t - last).abs(), t)).0;
        // bounded by limits::MAX_STEPS (check_increments)
        let increments = (path / max_inc * (1.0 - 1e-12)).ceil().min(limits::MAX_STEPS as f64) as usize;
        increments.max(targets.len())
    }

    /// `[solver] max_steps`: the most converged load steps of the path before it is given up (see
    /// [`stamp::nonlinear::NewtonSettings::max_steps`]); by default [`limits::DEFAULT_MAX_STEPS`],
    /// or [`limits::STEP_BUDGET_FACTOR`] times [`least_steps`](Self::least_steps) if that is more.
    pub fn max_steps(&self) -> usize {
        match &self.spec.solver.max_steps {
            Some(m) => m.get_ref().0,
            None => limits::DEFAULT_MAX_STEPS.max(limits::STEP_BUDGET_FACTOR * self.least_steps()),
        }
    }

    /// The name of punch `i` (its `name`, or "`punch<i>`").
    pub fn punch_name(&self, i: usize) -> String {
        self.spec.punch[i].get_ref().name.clone().unwrap_or_else(|| if self.spec.punch.len() == 1 { "punch".into() } else { format!("punch{i}") })
    }

    /// The load factors to reach.
    pub fn targets(&self) -> Vec<f64> {
        if let Some(t) = &self.spec.solver.targets {
            t.get_ref().0.clone()
        } else if let Some(n) = &self.spec.solver.steps {
            let n = n.get_ref().0;
            (1..=n).map(|k| k as f64 / n as f64).collect()
        } else {
            vec![1.0]
        }
    }

    /// The folder of the problem file (relative paths start there).
    pub fn dir(&self) -> PathBuf {
        self.path.parent().map(|p| if p.as_os_str().is_empty() { Path::new(".") } else { p }).unwrap_or(Path::new(".")).to_path_buf()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "[mesh]\nrectangle = { x = [0.0, 1.0], y = [0.0, 1.0], n = [2, 2] }\n\n[plate]\nthickness = 0.1\nE = 1.0\nnu = 0.3\n";

    fn table(text: &str) -> toml::Table {
        toml::from_str(text).unwrap()
    }

    #[test]
    fn a_table_is_read_as_its_file_is() {
        let file = Problem::parse(Path::new("p.toml"), TEXT.into()).unwrap();
        let built = Problem::from_table(Path::new("p.toml"), table(TEXT), None).unwrap();
        assert_eq!(format!("{:?}", built.spec.plate.get_ref()), format!("{:?}", file.spec.plate.get_ref()));
        assert_eq!(format!("{:?}", built.spec.mesh.get_ref().rectangle), format!("{:?}", file.spec.mesh.get_ref().rectangle));
        // the same message, but for the line, which is the written table's
        let bad = TEXT.replace("nu = 0.3", "nu = 0.7");
        let from_file = Problem::parse(Path::new("p.toml"), bad.clone()).unwrap_err().to_string();
        let from_table = Problem::from_table(Path::new("p.toml"), table(&bad), None).unwrap_err().to_string();
        let what = |m: &str| m.split_once("plate.nu: ").map(|(_, w)| w.lines().next().unwrap().to_string()).unwrap();
        assert_eq!(what(&from_table), what(&from_file));
        assert_eq!(what(&from_file), "expected Poisson's ratio in (-1, 0.5), got 0.7");
    }

    #[test]
    fn a_given_mesh_takes_the_place_of_file_and_rectangle() {
        let nodes = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let mesh = || Some(stamp::io::mesh_from_arrays(Path::new("mesh"), &nodes, &[vec![0, 1, 2, 3]], &[]).unwrap());
        let given = TEXT.replace("rectangle = { x = [0.0, 1.0], y = [0.0, 1.0], n = [2, 2] }\n", "");
        let p = Problem::from_table(Path::new("p"), table(&given), mesh()).unwrap();
        assert_eq!(p.given_mesh.as_ref().unwrap().mesh.num_cells(), 1);
        let both = Problem::from_table(Path::new("p"), table(TEXT), mesh()).unwrap_err().to_string();
        assert!(both.contains("mesh: give the mesh as arrays (`nodes`, `cells`) or as `file` or `rectangle`, not both"), "{both}");
        let coarse = format!("{given}\n[solver]\npredictor = \"coarse\"\n");
        let e = Problem::from_table(Path::new("p"), table(&coarse), mesh()).unwrap_err().to_string();
        assert!(e.contains("solver.predictor: \"coarse\" needs a coarse mesh"), "{e}");
        // without the mesh the table is a file without a mesh
        let e = Problem::from_table(Path::new("p"), table(&given), None).unwrap_err().to_string();
        assert!(e.contains("give exactly one of `file` (a gmsh .msh) and `rectangle`"), "{e}");
    }
}

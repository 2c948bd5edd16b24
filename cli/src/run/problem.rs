//! The problem file of `stamp run`: a TOML document read with serde, every table with
//! `deny_unknown_fields`. Range checks happen while deserialising, so that toml's error carries the
//! line and column of the offending value; checks that need the mesh (group names) use the spans kept
//! in [`Spanned`] values and report `file:line:column` themselves.
//!
//! See `meshes/paper-r100.toml` for a complete annotated example.

use serde::de::{Deserializer, Error as _};
use serde::Deserialize;
use stamp::{Result, StampError};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use toml::Spanned;

// ---------------------------------------------------------------------------------------------
// validated numbers: the error is raised inside the deserializer, so toml reports its line

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
                    Err(D::Error::custom(format!("expected {}, got {v}", $what)))
                }
            }
        }
    };
}

checked_number!(Positive, "a positive finite number", |v| v > 0.0);
checked_number!(NonNegative, "a finite number >= 0", |v| v >= 0.0);
checked_number!(Finite, "a finite number", |_| true);
checked_number!(Poisson, "Poisson's ratio in (-1, 0.5)", |v| v > -1.0 && v < 0.5);
checked_number!(Fraction, "a number in [0, 1)", |v| (0.0..1.0).contains(&v));

/// A 3-vector of finite numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vec3(pub [f64; 3]);
impl<'de> Deserialize<'de> for Vec3 {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = <[f64; 3]>::deserialize(d)?;
        if v.iter().all(|x| x.is_finite()) {
            Ok(Vec3(v))
        } else {
            Err(D::Error::custom(format!("expected three finite numbers, got {v:?}")))
        }
    }
}

/// A non-zero 3-vector (a direction).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Direction(pub [f64; 3]);
impl<'de> Deserialize<'de> for Direction {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = Vec3::deserialize(d)?.0;
        if v.iter().map(|x| x * x).sum::<f64>() > 0.0 {
            Ok(Direction(v))
        } else {
            Err(D::Error::custom("expected a non-zero direction, got [0, 0, 0]"))
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
        if v.is_empty() {
            return Err(D::Error::custom("expected at least one load factor"));
        }
        let mut last = 0.0;
        for &t in &v {
            if !(t.is_finite() && t >= 0.0) {
                return Err(D::Error::custom(format!("load factors must be finite and >= 0, got {t}")));
            }
            if t == last {
                return Err(D::Error::custom(format!("each load factor must differ from the one before (the path starts at 0): {t} after {last}")));
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
            None => Err(D::Error::custom(format!("unknown displacement or constraint '{word}'; expected one of {DOF_WORDS}"))),
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
            _ => Err(D::Error::custom(format!("'{word}' cannot be prescribed; expected one of v1-, v2-, v3-, v1+, v2+, v3+, v1, v2, v3"))),
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
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RectangleSpec {
    pub x: [f64; 2],
    pub y: [f64; 2],
    pub n: [usize; 2],
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
    #[serde(rename = "E")]
    pub young: Positive,
    pub nu: Poisson,
    #[serde(default)]
    pub kinematics: KinematicsSpec,
    /// v1- = v1+ = 0 at every node.
    #[serde(default)]
    pub plane_strain: bool,
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
    /// pressure: value at load factor 1, positive pushes on the face towards the plate.
    #[serde(default)]
    pub pressure: Option<Finite>,
    #[serde(default)]
    pub face: Option<LoadFace>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Shape {
    Cylinder,
    Sphere,
    Plane,
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
    /// Punch displacement at load factor 1 ...
    #[serde(default)]
    pub motion: Option<Vec3>,
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
    pub penetration_tolerance: Option<Positive>,
    /// Default: exact for a nonlinear plate, shallow (along x3) for a linear one.
    #[serde(default)]
    pub kinematics: Option<ContactKinematicsSpec>,
}

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Load factors at which results are wanted (default [1.0]) ...
    #[serde(default)]
    pub targets: Option<Spanned<Targets>>,
    /// ... or this many equal steps to load factor 1.
    #[serde(default)]
    pub steps: Option<Spanned<usize>>,
    #[serde(default)]
    pub max_increment: Option<Positive>,
    #[serde(default)]
    pub initial_increment: Option<Positive>,
    #[serde(default)]
    pub min_increment: Option<Positive>,
    #[serde(default)]
    pub rel_tol: Option<Positive>,
    #[serde(default)]
    pub abs_tol: Option<NonNegative>,
    #[serde(default)]
    pub max_iterations: Option<usize>,
    #[serde(default)]
    pub max_cutbacks: Option<usize>,
    #[serde(default)]
    pub line_search_steps: Option<usize>,
    /// Give up a step whose active set swings at every iteration without progress from this
    /// iteration on, and cut it back (off by default; see NewtonSettings::cycling_after).
    #[serde(default)]
    pub cycling_after: Option<usize>,
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
    /// Plot q_n along the contact face (PNG and SVG).
    #[serde(default)]
    pub plot: bool,
    #[serde(default)]
    pub plot_axis: PlotAxis,
    /// Only these nodes in the plot (required for plot_axis = "arc": a curve group).
    #[serde(default)]
    pub plot_group: Option<Spanned<String>>,
    /// Every converged step (true) or the targets only (false).
    #[serde(default = "yes")]
    pub every_step: bool,
    /// A node is in the loaded zone when |lambda| > loaded_threshold * max |lambda| (SPEC 6).
    #[serde(default = "default_threshold")]
    pub loaded_threshold: Fraction,
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
            plot: false,
            plot_axis: PlotAxis::X2,
            plot_group: None,
            every_step: true,
            loaded_threshold: default_threshold(),
        }
    }
}

// ---------------------------------------------------------------------------------------------

/// A parsed problem with its file name and source text (for line numbers).
#[derive(Debug)]
pub struct Problem {
    pub path: PathBuf,
    pub source: String,
    pub spec: ProblemFile,
}

impl Problem {
    /// Read and parse a problem file.
    pub fn read(path: &Path) -> Result<Problem> {
        let source = std::fs::read_to_string(path).map_err(|e| StampError::io(path, e))?;
        Problem::parse(path, source)
    }

    /// Parse problem text (`path` names it in errors and anchors relative paths).
    pub fn parse(path: &Path, source: String) -> Result<Problem> {
        let spec: ProblemFile = toml::from_str(&source).map_err(|e| StampError::Input {
            file: path.display().to_string(),
            message: e.to_string().trim_end().to_string(),
        })?;
        let p = Problem { path: path.to_path_buf(), source, spec };
        p.check()?;
        Ok(p)
    }

    /// "line L, column C" of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let before = &self.source[..offset.min(self.source.len())];
        let line = before.matches('\n').count() + 1;
        let col = before.len() - before.rfind('\n').map(|i| i + 1).unwrap_or(0) + 1;
        (line, col)
    }

    /// An input error located at `span`, naming `key`.
    pub fn error_at(&self, span: std::ops::Range<usize>, key: &str, message: impl std::fmt::Display) -> StampError {
        let (line, col) = self.line_col(span.start);
        StampError::Input { file: self.path.display().to_string(), message: format!("line {line}, column {col}: {key}: {message}") }
    }

    /// Checks between keys that serde cannot express.
    fn check(&self) -> Result<()> {
        let s = &self.spec;
        let mesh = s.mesh.get_ref();
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
        let plate = s.plate.get_ref();
        match (plate.thickness, plate.delta_minus, plate.delta_plus) {
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
                }
                _ => {
                    if ls.force.is_none() || ls.pressure.is_some() {
                        return Err(self.error_at(l.span(), &key, "a line, surface or point load needs `force` (and no `pressure`)"));
                    }
                }
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
            }
            if ps.force.is_some() && ps.motion.is_some() {
                return Err(self.error_at(p.span(), &format!("{key}.force"), "give `motion` (displacement driven) or `force` (force driven), not both"));
            }
            if ps.direction.is_some() && ps.force.is_none() {
                return Err(self.error_at(p.span(), &format!("{key}.direction"), "`direction` is the direction of `force`; it needs `force`"));
            }
            let name = self.punch_name(i);
            if !names.insert(name.clone()) {
                return Err(self.error_at(p.span(), &format!("{key}.name"), format!("two punches are named '{name}'")));
            }
            if name.is_empty() || !name.chars().all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-') {
                return Err(self.error_at(p.span(), &format!("{key}.name"), format!("'{name}' must be non-empty letters, digits, '_' or '-' (it names files)")));
            }
        }
        if s.solver.targets.is_some() && s.solver.steps.is_some() {
            let t = s.solver.targets.as_ref().unwrap();
            return Err(self.error_at(t.span(), "solver.targets", "give `targets` or `steps`, not both"));
        }
        if let Some(n) = &s.solver.steps {
            if *n.get_ref() == 0 {
                return Err(self.error_at(n.span(), "solver.steps", "must be at least 1"));
            }
        }
        if s.output.plot_axis == PlotAxis::Arc && s.output.plot_group.is_none() {
            return Err(StampError::Input {
                file: self.path.display().to_string(),
                message: "output.plot_axis = \"arc\" needs output.plot_group (a curve group)".into(),
            });
        }
        Ok(())
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
            let n = *n.get_ref();
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

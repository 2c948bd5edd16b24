//! `[mesh]`: a gmsh `file` or the built-in `rectangle` (checked while deserialising), and the
//! `coarse_file` of the coarse predictor; the mesh itself is built by crate::model::mesh.

use super::Problem;
use super::limits;
use super::solver::Predictor;
use super::values::{num, vec_text, AnyNumber};
use serde::Deserialize;
use serde::de::{Deserializer, Error as _};
use stamp::Result;
use toml::Spanned;

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

/// The built-in rectangle, checked while deserialising: finite increasing intervals with a finite
/// extent, cells large enough for distinct node coordinates, and a node count (checked
/// arithmetic). Whether its model fits in memory is checked before the mesh is built (model/mesh.rs).
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

impl Problem {
    /// The checks of `[mesh]` (with the coarse predictor of `[solver]`): a mesh given in memory,
    /// or exactly one of `file` and `rectangle`, and a `coarse_file` only where it is read.
    pub(super) fn check_mesh(&self) -> Result<()> {
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
            return Ok(());
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
        Ok(())
    }
}

//! `[[punch]]`: the rigid punches: shape, motion or force, the face they press and the contact
//! settings.

use super::Problem;
use super::limits;
use super::values::{vec_text, Finite, FrictionCoefficient, Positive, Vec3};
use serde::Deserialize;
use serde::de::{Deserializer, Error as _};
use stamp::{quote, Result};
use toml::Spanned;

/// A punch's prescribed motion: `[d1, d2, d3]` (the displacement at load factor 1, times the load
/// factor) or rows `[[t, d1, d2, d3], ...]`, a path piecewise linear in the load factor (checked by
/// [`stamp::contact::PunchMotion::path`]).
/// Default penetration tolerance, as a fraction of the plate thickness: a punch may start inside
/// the plate by this much, and a step whose punch ends deeper (or held off by more) is not
/// converged: augmented-Lagrangian updates press it out first (a step is never reported
/// converged with the punch deep inside the plate). `[[punch]] penetration_tolerance` sets it.
pub const DEFAULT_PENETRATION: f64 = 1e-3;

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

/// A punch's prescribed rotation: rows `[[t, angle], ...]`, the angle in degrees piecewise linear
/// in the load factor t (checked as a path's rows by [`stamp::contact::PunchRotation::new`]); its
/// axis and pivot are other keys (`axis` or a cylinder's `rotation_axis`, `pivot`).
#[derive(Debug, Clone, PartialEq)]
pub struct RotationSpec(pub Vec<(f64, f64)>);
impl<'de> Deserialize<'de> for RotationSpec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        const FORM: &str = "expected rows [[t, angle], ...] (the angle in degrees, piecewise linear in the load factor t)";
        let rows = Vec::<Vec<f64>>::deserialize(d).map_err(|_| D::Error::custom(FORM))?;
        if rows.len() > limits::MAX_PATH_ROWS {
            return Err(D::Error::custom(format!("a rotation has at most {} rows, got {}", limits::MAX_PATH_ROWS, rows.len())));
        }
        let mut out = Vec::with_capacity(rows.len());
        for (k, r) in rows.iter().enumerate() {
            if r.len() != 2 {
                return Err(D::Error::custom(format!("rotation row {k}: expected [t, angle], got {} numbers", r.len())));
            }
            if !r.iter().all(|x| x.is_finite() && x.abs() <= limits::MAX_MAGNITUDE) {
                return Err(D::Error::custom(format!("rotation row {k}: expected finite numbers of magnitude at most 1e100, got {}", vec_text(r))));
            }
            out.push((r[0], r[1]));
        }
        // the rows' own checks (the axis and pivot come later)
        stamp::contact::PunchRotation::new([0.0, 0.0, 1.0], [0.0; 3], &out).map_err(|e| D::Error::custom(format!("rotation {e}")))?;
        Ok(RotationSpec(out))
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
    /// cylinder: the axis direction (and the axis of its `rotation` unless `rotation_axis` is
    /// given); other shapes: the axis of their `rotation`.
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
    /// Regularisation parameter (default: automatic, see model/build.rs).
    #[serde(default)]
    pub eps_reg: Option<Positive>,
    /// Augmented-Lagrangian penetration tolerance (a length).
    #[serde(default)]
    pub penetration_tolerance: Option<Spanned<Positive>>,
    /// Default: exact for a nonlinear plate, shallow (along x3) for a linear one.
    #[serde(default)]
    pub kinematics: Option<ContactKinematicsSpec>,
    /// How the constraint is discretised: "nodal" (the paper's collocation at the nodes) or
    /// "integrated" (each node's weighted gap over its cells); default: see model/build.rs.
    #[serde(default)]
    pub contact: Option<ContactSpec>,
    /// The Coulomb friction coefficient mu between the plate and the punch (default 0:
    /// frictionless). Exact kinematics only; nodal or integrated contact.
    #[serde(default)]
    pub friction: Option<Spanned<FrictionCoefficient>>,
    /// The punch's rotation: rows [t, angle in degrees] about `axis` (a cylinder: its own axis,
    /// or `rotation_axis`) through `pivot`, a point of the punch that travels with its
    /// translation (default: a cylinder's `point`, a sphere's `center`).
    #[serde(default)]
    pub rotation: Option<Spanned<RotationSpec>>,
    /// The point the rotation turns the punch about, at t = 0.
    #[serde(default)]
    pub pivot: Option<Vec3>,
    /// cylinder: the rotation's axis when it is not the cylinder's own (a roller that tilts or
    /// steers).
    #[serde(default)]
    pub rotation_axis: Option<Direction>,
}

/// `[[punch]] contact`: the discretisation of the contact constraint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ContactSpec {
    Nodal,
    Integrated,
}

impl Problem {
    /// The checks of `[[punch]]`: the keys each shape takes, motion or force, the names.
    pub(super) fn check_punches(&self) -> Result<()> {
        let s = &self.spec;
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
            // a shape without an axis of its own takes `axis` as its rotation's
            let no_axis = ps.axis.is_none() || ps.rotation.is_some();
            let axis_note = if ps.axis.is_some() { "; `axis` only as the axis of a `rotation`" } else { "" };
            match ps.shape {
                Shape::Cylinder => need(
                    ps.point.is_some() && ps.axis.is_some() && ps.radius.is_some() && ps.center.is_none() && ps.normal.is_none(),
                    "a cylinder needs `point`, `axis` and `radius` (and no `center` or `normal`)",
                )?,
                Shape::Sphere => need(
                    ps.center.is_some() && ps.radius.is_some() && ps.point.is_none() && no_axis && ps.normal.is_none(),
                    &format!("a sphere needs `center` and `radius` (and no `point`, `axis` or `normal`){axis_note}"),
                )?,
                Shape::Plane => need(
                    ps.point.is_some() && ps.normal.is_some() && ps.radius.is_none() && no_axis && ps.center.is_none(),
                    &format!("a plane needs `point` and `normal` (and no `radius`, `axis` or `center`){axis_note}"),
                )?,
                Shape::Expression => {
                    need(
                        ps.psi.is_some() && ps.point.is_none() && no_axis && ps.center.is_none() && ps.radius.is_none() && ps.normal.is_none(),
                        &format!("an expression punch needs `psi` (and no `point`, `axis`, `center`, `radius` or `normal`){axis_note}"),
                    )?;
                    let psi = ps.psi.as_ref().unwrap();
                    if let Err(e) = stamp_contact::expression_parser::parse(psi.get_ref()) {
                        return Err(self.psi_error(psi, e.column, &format!("{key}.psi"), &e.message));
                    }
                }
                Shape::Stl => need(
                    ps.file.is_some() && ps.point.is_none() && no_axis && ps.center.is_none() && ps.radius.is_none() && ps.normal.is_none(),
                    &format!("an stl die needs `file` (and no `point`, `axis`, `center`, `radius` or `normal`: the die is where the file puts it){axis_note}"),
                )?,
            }
            self.check_rotation_keys(i)?;
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
        Ok(())
    }

    /// The keys of a punch's rotation: `pivot` and `rotation_axis` need `rotation`; a shape
    /// without an axis of its own needs `axis` (the rotation's) and, but for a sphere (about its
    /// centre by default), `pivot`; `rotation_axis` is a cylinder's.
    fn check_rotation_keys(&self, i: usize) -> Result<()> {
        let p = &self.spec.punch[i];
        let ps = p.get_ref();
        let key = format!("punch[{i}]");
        let err = |k: &str, what: String| Err(self.error_at(p.span(), &format!("{key}.{k}"), what));
        let what = match ps.shape {
            Shape::Cylinder => "cylinder",
            Shape::Sphere => "sphere",
            Shape::Plane => "plane",
            Shape::Expression => "expression punch",
            Shape::Stl => "stl die",
        };
        let Some(rotation) = &ps.rotation else {
            if ps.pivot.is_some() {
                return err("pivot", "`pivot` is the point a `rotation` turns the punch about; it needs `rotation` (rows [t, angle])".into());
            }
            if ps.rotation_axis.is_some() {
                return err("rotation_axis", "`rotation_axis` is the axis of a cylinder's `rotation`; it needs `rotation` (rows [t, angle])".into());
            }
            return Ok(());
        };
        if ps.shape == Shape::Cylinder {
            return Ok(());
        }
        if ps.rotation_axis.is_some() {
            return err("rotation_axis", format!("`rotation_axis` is a cylinder's (whose `axis` is its own); a {what} gives the axis of its rotation as `axis`"));
        }
        if ps.axis.is_none() {
            return Err(self.error_at(rotation.span(), &format!("{key}.axis"), format!("a {what} turned by `rotation` needs `axis` (the direction it turns about) and `pivot` (a point of the punch on that axis)")));
        }
        if ps.pivot.is_none() && ps.shape != Shape::Sphere {
            return Err(self.error_at(rotation.span(), &format!("{key}.pivot"), format!("a {what} turned by `rotation` needs `pivot`, a point of the punch (at t = 0) on the rotation's axis")));
        }
        Ok(())
    }

    /// The name of punch `i` (its `name`, or "`punch<i>`").
    pub fn punch_name(&self, i: usize) -> String {
        self.spec.punch[i].get_ref().name.clone().unwrap_or_else(|| if self.spec.punch.len() == 1 { "punch".into() } else { format!("punch{i}") })
    }

}

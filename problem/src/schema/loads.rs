//! `[[load]]`: line, surface, point, pressure and moment loads, with the face they act on and the
//! pressure as a number or an expression in x1, x2 (turned into nodal forces by
//! crate::model::pressure).

use super::Problem;
use super::limits;
use super::values::{num, PathSpec, Vec3};
use serde::Deserialize;
use serde::de::{Deserializer, Error as _};
use stamp::Result;
use toml::Spanned;

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
    /// Rows [t, factor]: the load is its value times this factor at load factor t (default: t).
    #[serde(default)]
    pub path: Option<PathSpec>,
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

impl Problem {
    /// The checks of `[[load]]`: the keys each type of load takes, a pressure expression in x1, x2.
    pub(super) fn check_loads(&self) -> Result<()> {
        let s = &self.spec;
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
        Ok(())
    }
}

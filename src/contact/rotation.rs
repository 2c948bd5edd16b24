//! How a punch turns: a prescribed rotation about a fixed axis through a pivot, its angle
//! piecewise linear in the load factor ([`PunchRotation`]), and the rigid placement it gives at one
//! load factor ([`Turn`]).
//!
//! A punch point X (where the punch's geometry puts it, at t = 0) is at
//! x(t) = R(t) (X - pivot) + pivot + d(t), d the punch's translation (prescribed, plus a
//! force-driven punch's travel): the pivot travels with the translation. The contact constraint
//! works in the translated frame y = x - d (as without rotation) and [`Turn`] takes y to the
//! punch's body frame, X = R^T (y - pivot) + pivot.

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

/// A prescribed rotation of a punch: by `angle(t)` degrees (right-handed) about the unit `axis`
/// through `pivot`, the angle piecewise linear in the load factor t through rows (t_k, angle_k)
/// (see [`PunchRotation::new`]).
#[derive(Debug, Clone, PartialEq)]
pub struct PunchRotation {
    axis: [f64; 3],
    pivot: [f64; 3],
    /// (t, angle in degrees), t strictly increasing from 0, the angle 0 at t = 0.
    path: Vec<(f64, f64)>,
}

impl PunchRotation {
    /// A rotation about `axis` (normalised here; non-zero and finite) through `pivot` by angles
    /// in degrees given as rows (t, angle): the rows' t finite and strictly increasing, the first
    /// at least 0; when the first t is 0 its angle must be 0 (the punch starts where its geometry
    /// puts it), and when it is above 0 the path starts at (0, 0) implicitly; held at the last
    /// angle beyond the last t. The error says what is wrong with which row (0-based), as
    /// [`PunchMotion::path`](super::PunchMotion::path)'s does.
    pub fn new(axis: [f64; 3], pivot: [f64; 3], rows: &[(f64, f64)]) -> Result<PunchRotation, String> {
        let a = Vector3::from(axis);
        let len = a.norm();
        if !(len > 0.0 && len.is_finite()) {
            return Err(format!("the rotation's axis must be a finite, non-zero direction, got {axis:?}"));
        }
        if !pivot.iter().all(|x| x.is_finite()) {
            return Err(format!("the rotation's pivot must be finite, got {pivot:?}"));
        }
        if rows.is_empty() {
            return Err("a rotation needs at least one row [t, angle]".into());
        }
        for (k, &(t, angle)) in rows.iter().enumerate() {
            if !(t.is_finite() && angle.is_finite()) {
                return Err(format!("row {k}: every number must be finite"));
            }
            if k == 0 && t < 0.0 {
                return Err(format!("row 0: the load factor t = {t} must be at least 0"));
            }
            if k == 0 && t == 0.0 && angle != 0.0 {
                return Err("row 0: at t = 0 the angle must be 0 (turn the punch by its geometry; the rotation starts there)".into());
            }
            if k > 0 && t <= rows[k - 1].0 {
                return Err(format!("row {k}: the load factors must increase strictly, but t = {t} follows t = {}", rows[k - 1].0));
            }
        }
        let mut path = Vec::with_capacity(rows.len() + 1);
        if rows[0].0 > 0.0 {
            path.push((0.0, 0.0));
        }
        path.extend_from_slice(rows);
        Ok(PunchRotation { axis: (a / len).into(), pivot, path })
    }

    /// The unit axis.
    pub fn axis(&self) -> [f64; 3] {
        self.axis
    }

    /// The pivot (a point of the punch at t = 0; it travels with the punch's translation).
    pub fn pivot(&self) -> [f64; 3] {
        self.pivot
    }

    /// The load factors at which the angular rate changes sign or starts or stops (see
    /// [`crate::contact::PunchMotion::corners`]).
    pub fn corners(&self) -> Vec<f64> {
        let p = &self.path;
        let sign = |k: usize| if k + 1 < p.len() { (p[k + 1].1 - p[k].1).signum() * ((p[k + 1].1 != p[k].1) as u8 as f64) } else { 0.0 };
        (1..p.len()).filter(|&k| sign(k - 1) != sign(k)).map(|k| p[k].0).collect()
    }

    /// The rows (t, angle in degrees), starting at (0, 0).
    pub fn rows(&self) -> &[(f64, f64)] {
        &self.path
    }

    /// The angle in degrees at load factor `t`: interpolated between the rows, the last beyond
    /// the last row, 0 below 0.
    pub fn angle(&self, t: f64) -> f64 {
        let points = &self.path;
        let Some(k) = points.iter().position(|p| p.0 > t) else {
            return points.last().map_or(0.0, |p| p.1);
        };
        if k == 0 {
            return points[0].1;
        }
        let ((t0, a), (t1, b)) = (points[k - 1], points[k]);
        a + (t - t0) / (t1 - t0) * (b - a)
    }

    /// The punch's rotation at load factor `t`; None where the angle is 0 (the frames agree, and
    /// the contact code then does exactly what it does for a punch that never turns).
    pub fn turn(&self, t: f64) -> Option<Turn> {
        let angle = self.angle(t);
        (angle != 0.0).then(|| Turn::new(self.axis, self.pivot, angle))
    }
}

/// The rotation of a punch at one load factor: R and the pivot, in the translated frame
/// y = x - d (see the module's documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turn {
    /// R: a body direction v points along R v in global axes.
    pub r: Matrix3<f64>,
    pub pivot: Vector3<f64>,
}

impl Turn {
    /// The rotation by `degrees` about the unit `axis` through `pivot`.
    pub fn new(axis: [f64; 3], pivot: [f64; 3], degrees: f64) -> Turn {
        let r = Rotation3::from_axis_angle(&Unit::new_normalize(Vector3::from(axis)), degrees.to_radians()).into_inner();
        Turn { r, pivot: Vector3::from(pivot) }
    }

    /// The body-frame position X = R^T (y - pivot) + pivot of a point at `y` in the translated
    /// frame.
    pub fn to_body(&self, y: &Vector3<f64>) -> Vector3<f64> {
        self.r.tr_mul(&(y - self.pivot)) + self.pivot
    }

    /// The translated-frame position y = R (X - pivot) + pivot of the body point `x`.
    pub fn to_translated(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.r * (x - self.pivot) + self.pivot
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_angle_interpolates_holds_and_starts_at_zero() {
        let r = PunchRotation::new([0.0, 0.0, 2.0], [1.0, 2.0, 3.0], &[(0.5, 10.0), (1.0, -20.0)]).unwrap();
        assert_eq!(r.axis(), [0.0, 0.0, 1.0]);
        assert_eq!(r.angle(0.0), 0.0);
        assert_eq!(r.angle(0.25), 5.0);
        assert_eq!(r.angle(0.75), -5.0);
        assert_eq!(r.angle(2.0), -20.0);
        assert_eq!(r.angle(-1.0), 0.0);
        assert!(r.turn(0.0).is_none());
        // 90 degrees about x3 through (1, 2, 3): (2, 2, 3) goes to (1, 3, 3)
        let t = Turn::new([0.0, 0.0, 1.0], [1.0, 2.0, 3.0], 90.0);
        let y = t.to_translated(&Vector3::new(2.0, 2.0, 3.0));
        assert!((y - Vector3::new(1.0, 3.0, 3.0)).norm() < 1e-15, "{y}");
        assert!((t.to_body(&y) - Vector3::new(2.0, 2.0, 3.0)).norm() < 1e-15);
    }

    #[test]
    fn bad_rotations_are_refused_with_the_row() {
        let e = |rows: &[(f64, f64)]| PunchRotation::new([0.0, 1.0, 0.0], [0.0; 3], rows).unwrap_err();
        assert!(e(&[]).contains("at least one row"));
        assert!(e(&[(0.5, 1.0), (0.5, 2.0)]).contains("row 1: the load factors must increase strictly"));
        assert!(e(&[(-0.5, 0.0)]).contains("row 0"));
        assert!(e(&[(0.0, 3.0)]).contains("at t = 0 the angle must be 0"));
        assert!(e(&[(1.0, f64::NAN)]).contains("finite"));
        assert!(PunchRotation::new([0.0; 3], [0.0; 3], &[(1.0, 1.0)]).unwrap_err().contains("axis"));
    }
}

//! How a punch moves: a prescribed displacement ([`PunchMotion`]) or a prescribed force ([`ForceDrive`]).

use nalgebra::Vector3;

/// A punch pressed by a prescribed force instead of moved by a prescribed displacement: the force
/// `force * t` (t the load factor) pushes the punch along the unit `direction`, and its rigid
/// displacement s along `direction` is an unknown. `dof` is the index of s in the full unknown
/// vector; [`crate::model::Model`] assigns it (after the nodal dofs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForceDrive {
    pub direction: [f64; 3],
    pub force: f64,
    pub dof: usize,
}

impl ForceDrive {
    /// A force `force` (at load factor 1) along `direction` (normalised here; must be non-zero).
    pub fn new(direction: [f64; 3], force: f64) -> crate::Result<Self> {
        let n = Vector3::from(direction);
        let len = n.norm();
        if !(len > 0.0 && len.is_finite() && force.is_finite()) {
            return Err(crate::StampError::Problem(format!("a force-driven punch needs a finite, non-zero direction and a finite force, got {direction:?} and {force}")));
        }
        Ok(ForceDrive { direction: (n / len).into(), force, dof: usize::MAX })
    }
}

/// How a displacement-driven punch moves with the load factor t. The punch position is data, not
/// an unknown: the model only evaluates [`displacement`](PunchMotion::displacement) at each t.
#[derive(Debug, Clone, PartialEq)]
pub enum PunchMotion {
    /// t times this displacement (the displacement at load factor 1).
    Linear([f64; 3]),
    /// Piecewise linear in t through the points (t_k, d_k), t strictly increasing from t_0 = 0
    /// with d_0 = 0 (see [`PunchMotion::path`]); held at the last displacement beyond the last t,
    /// and at zero below 0.
    Path(Vec<(f64, [f64; 3])>),
}

impl From<[f64; 3]> for PunchMotion {
    fn from(m: [f64; 3]) -> Self {
        PunchMotion::Linear(m)
    }
}

impl Default for PunchMotion {
    fn default() -> Self {
        PunchMotion::Linear([0.0; 3])
    }
}

impl PunchMotion {
    /// The load factors at which the path turns (its direction changes between two rows): the
    /// load stepping does not extrapolate a step across them (a punch lifted after pressing would
    /// be predicted deeper still). None for a linear motion.
    pub fn corners(&self) -> Vec<f64> {
        let PunchMotion::Path(points) = self else {
            return Vec::new();
        };
        let unit = |a: &[f64; 3], b: &[f64; 3]| {
            let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            if n > 0.0 { d.map(|x| x / n) } else { [0.0; 3] }
        };
        let mut out = Vec::new();
        for k in 1..points.len() {
            let before = unit(&points[k - 1].1, &points[k].1);
            let after = if k + 1 < points.len() { unit(&points[k].1, &points[k + 1].1) } else { [0.0; 3] };
            if before.iter().zip(&after).map(|(a, b)| a * b).sum::<f64>() < 1.0 - 1e-9 {
                out.push(points[k].0);
            }
        }
        out
    }

    /// A path through `rows` (t, displacement). The rows' t must be finite and strictly
    /// increasing, the first at least 0; when the first t is 0 its displacement must be zero (the
    /// punch starts where its geometry puts it), and when it is above 0 the path starts at (0, 0)
    /// implicitly. The error says what is wrong with which row (0-based).
    pub fn path(rows: &[(f64, [f64; 3])]) -> Result<PunchMotion, String> {
        if rows.is_empty() {
            return Err("a path needs at least one row [t, d1, d2, d3]".into());
        }
        for (k, (t, d)) in rows.iter().enumerate() {
            if !(t.is_finite() && d.iter().all(|x| x.is_finite())) {
                return Err(format!("row {k}: every number must be finite"));
            }
            if k == 0 && *t < 0.0 {
                return Err(format!("row 0: the load factor t = {t} must be at least 0"));
            }
            if k == 0 && *t == 0.0 && *d != [0.0; 3] {
                return Err("row 0: at t = 0 the displacement must be [0, 0, 0] (place the punch by its geometry; the path starts there)".into());
            }
            if k > 0 && !(*t > rows[k - 1].0) {
                return Err(format!("row {k}: the load factors must increase strictly, but t = {t} follows t = {}", rows[k - 1].0));
            }
        }
        let mut points = Vec::with_capacity(rows.len() + 1);
        if rows[0].0 > 0.0 {
            points.push((0.0, [0.0; 3]));
        }
        points.extend_from_slice(rows);
        Ok(PunchMotion::Path(points))
    }

    /// The punch displacement at load factor `t`.
    pub fn displacement(&self, t: f64) -> [f64; 3] {
        match self {
            PunchMotion::Linear(m) => m.map(|x| x * t),
            PunchMotion::Path(points) => {
                let Some(k) = points.iter().position(|p| p.0 > t) else {
                    return points.last().map_or([0.0; 3], |p| p.1);
                };
                if k == 0 {
                    return points[0].1;
                }
                let ((t0, a), (t1, b)) = (points[k - 1], points[k]);
                let s = (t - t0) / (t1 - t0);
                [0, 1, 2].map(|i| a[i] + s * (b[i] - a[i]))
            }
        }
    }

    /// True when the punch never moves.
    pub fn is_zero(&self) -> bool {
        match self {
            PunchMotion::Linear(m) => *m == [0.0; 3],
            PunchMotion::Path(points) => points.iter().all(|p| p.1 == [0.0; 3]),
        }
    }

    /// The direction in which the punch first moves, not normalised: the linear motion itself, or
    /// the first non-zero displacement of a path (its approach: a die that comes down then slides
    /// approaches along -x3). Zero for a punch that never moves.
    pub fn approach(&self) -> [f64; 3] {
        match self {
            PunchMotion::Linear(m) => *m,
            PunchMotion::Path(points) => points.iter().map(|p| p.1).find(|d| *d != [0.0; 3]).unwrap_or([0.0; 3]),
        }
    }
}

#[cfg(test)]
mod motion_tests {
    use super::PunchMotion;

    #[test]
    fn a_path_interpolates_holds_and_starts_at_zero() {
        let p = PunchMotion::path(&[(0.5, [0.0, 0.0, -1.0]), (1.0, [2.0, 0.0, -1.0])]).unwrap();
        assert_eq!(p.displacement(0.0), [0.0, 0.0, 0.0]);
        assert_eq!(p.displacement(0.25), [0.0, 0.0, -0.5]);
        assert_eq!(p.displacement(0.5), [0.0, 0.0, -1.0]);
        assert_eq!(p.displacement(0.75), [1.0, 0.0, -1.0]);
        assert_eq!(p.displacement(1.0), [2.0, 0.0, -1.0]);
        // held beyond the last row, zero below 0
        assert_eq!(p.displacement(3.0), [2.0, 0.0, -1.0]);
        assert_eq!(p.displacement(-1.0), [0.0, 0.0, 0.0]);
        assert_eq!(p.approach(), [0.0, 0.0, -1.0]);
        assert!(!p.is_zero());
        // a path equal to a linear motion gives the same displacements
        let lin = PunchMotion::Linear([0.1, 0.2, -0.3]);
        let path = PunchMotion::path(&[(1.0, [0.1, 0.2, -0.3])]).unwrap();
        for t in [0.0, 0.125, 0.5, 0.9, 1.0] {
            assert_eq!(lin.displacement(t), path.displacement(t), "t = {t}");
        }
        assert_eq!(path.approach(), lin.approach());
    }

    #[test]
    fn bad_paths_are_refused_with_the_row() {
        let e = |rows: &[(f64, [f64; 3])]| PunchMotion::path(rows).unwrap_err();
        assert!(e(&[]).contains("at least one row"));
        assert!(e(&[(0.5, [0.0; 3]), (0.5, [1.0; 3])]).contains("row 1: the load factors must increase strictly"));
        assert!(e(&[(-0.5, [0.0; 3])]).contains("row 0"));
        assert!(e(&[(0.0, [1.0, 0.0, 0.0])]).contains("at t = 0 the displacement must be [0, 0, 0]"));
        assert!(e(&[(1.0, [f64::NAN, 0.0, 0.0])]).contains("finite"));
        assert!(PunchMotion::path(&[(0.0, [0.0; 3]), (1.0, [0.0, 0.0, -1.0])]).is_ok());
    }
}

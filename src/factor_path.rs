//! A factor that follows the load factor t along a path: the multiplier of a load or of a
//! prescribed displacement that is not simply t (a weight put on, then held while the plate is
//! pushed; an edge moved first one way, then another). Piecewise linear through rows (t_k, f_k),
//! starting at (0, 0) and held at the last row beyond it, like a punch's `motion` path
//! ([`crate::contact::PunchMotion::path`]).

/// Piecewise linear in the load factor t through (t_k, f_k): t strictly increasing from t_0 = 0
/// with f_0 = 0, held at the last factor beyond the last t, zero below 0.
#[derive(Debug, Clone, PartialEq)]
pub struct FactorPath {
    points: Vec<(f64, f64)>,
}

impl FactorPath {
    /// A path through `rows` (t, factor). The rows' t must be finite and strictly increasing, the
    /// first at least 0; when the first t is 0 its factor must be 0 (at t = 0 the plate is
    /// unloaded, where the solve starts), and when it is above 0 the path starts at (0, 0)
    /// implicitly. The error says what is wrong with which row (0-based).
    pub fn new(rows: &[(f64, f64)]) -> Result<FactorPath, String> {
        if rows.is_empty() {
            return Err("a path needs at least one row [t, factor]".into());
        }
        for (k, &(t, f)) in rows.iter().enumerate() {
            if !(t.is_finite() && f.is_finite()) {
                return Err(format!("row {k}: every number must be finite"));
            }
            if k == 0 && t < 0.0 {
                return Err(format!("row 0: the load factor t = {t} must be at least 0"));
            }
            if k == 0 && t == 0.0 && f != 0.0 {
                return Err(format!("row 0: at t = 0 the factor must be 0 (the path starts from the unloaded plate), got {f}"));
            }
            if k > 0 && !(t > rows[k - 1].0) {
                return Err(format!("row {k}: the load factors must increase strictly, but t = {t} follows t = {}", rows[k - 1].0));
            }
        }
        let mut points = Vec::with_capacity(rows.len() + 1);
        if rows[0].0 > 0.0 {
            points.push((0.0, 0.0));
        }
        points.extend_from_slice(rows);
        Ok(FactorPath { points })
    }

    /// The factor at load factor `t`.
    pub fn at(&self, t: f64) -> f64 {
        let Some(k) = self.points.iter().position(|p| p.0 > t) else {
            return self.points.last().map_or(0.0, |p| p.1);
        };
        if k == 0 {
            return self.points[0].1;
        }
        let ((t0, a), (t1, b)) = (self.points[k - 1], self.points[k]);
        a + (t - t0) / (t1 - t0) * (b - a)
    }

    /// The rows, starting at (0, 0).
    pub fn rows(&self) -> &[(f64, f64)] {
        &self.points
    }
}

#[cfg(test)]
mod tests {
    use super::FactorPath;

    #[test]
    fn a_path_interpolates_holds_and_starts_at_zero() {
        let p = FactorPath::new(&[(0.5, 1.0), (1.0, 1.0), (2.0, -1.0)]).unwrap();
        assert_eq!(p.rows()[0], (0.0, 0.0));
        for (t, f) in [(-1.0, 0.0), (0.0, 0.0), (0.25, 0.5), (0.5, 1.0), (0.75, 1.0), (1.0, 1.0), (1.5, 0.0), (2.0, -1.0), (9.0, -1.0)] {
            assert_eq!(p.at(t), f, "t = {t}");
        }
        // one row [1, 1] is the plain load factor up to 1
        let lin = FactorPath::new(&[(1.0, 1.0)]).unwrap();
        for t in [0.0, 0.125, 0.3, 1.0] {
            assert_eq!(lin.at(t), t);
        }
        assert!(FactorPath::new(&[(0.0, 0.0), (1.0, 2.0)]).is_ok());
    }

    #[test]
    fn bad_rows_are_refused_with_the_row() {
        let e = |rows: &[(f64, f64)]| FactorPath::new(rows).unwrap_err();
        assert!(e(&[]).contains("at least one row"));
        assert!(e(&[(0.5, 1.0), (0.5, 2.0)]).contains("row 1: the load factors must increase strictly"));
        assert!(e(&[(0.5, 1.0), (0.25, 2.0)]).contains("row 1"));
        assert!(e(&[(-0.5, 0.0)]).contains("row 0: the load factor t = -0.5 must be at least 0"));
        assert!(e(&[(0.0, 1.0)]).contains("at t = 0 the factor must be 0"));
        assert!(e(&[(1.0, f64::NAN)]).contains("row 0: every number must be finite"));
    }
}

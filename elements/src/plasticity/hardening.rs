//! Isotropic hardening: the yield stress as a function of the equivalent plastic strain ep.

use stamp::{Result, StampError};

/// sigma_y(ep), ep the equivalent plastic strain (the work conjugate of the yield function's
/// equivalent stress: sigma_y dep = T : dHp).
#[derive(Debug, Clone, PartialEq)]
pub enum Hardening {
    /// sigma_y = yield + modulus ep (perfectly plastic with modulus 0).
    Linear { yield_stress: f64, modulus: f64 },
    /// Swift's law sigma_y = k (e0 + ep)^n.
    Swift { k: f64, e0: f64, n: f64 },
    /// A table of (ep, sigma_y) rows, ep ascending from 0, interpolated linearly and constant
    /// past its last row (as Abaqus reads `*PLASTIC`).
    Table(Vec<(f64, f64)>),
}

impl Hardening {
    /// The checks of the law's numbers, with what is wrong.
    pub fn validate(&self) -> Result<()> {
        let bad = |m: String| Err(StampError::Material(m));
        match self {
            Hardening::Linear { yield_stress, modulus } => {
                if !(yield_stress.is_finite() && *yield_stress > 0.0) {
                    return bad(format!("the initial yield stress must be positive and finite, got {yield_stress}"));
                }
                if !(modulus.is_finite() && *modulus >= 0.0) {
                    return bad(format!("the hardening modulus H must be >= 0 and finite (softening is not supported), got {modulus}"));
                }
            }
            Hardening::Swift { k, e0, n } => {
                if !(k.is_finite() && *k > 0.0) {
                    return bad(format!("Swift's K must be positive and finite, got {k}"));
                }
                if !(e0.is_finite() && *e0 > 0.0) {
                    return bad(format!("Swift's e0 must be positive (sigma_y(0) = K e0^n is the initial yield stress), got {e0}"));
                }
                if !(n.is_finite() && (0.0..=1.0).contains(n)) {
                    return bad(format!("Swift's exponent n must lie in [0, 1], got {n}"));
                }
            }
            Hardening::Table(rows) => {
                if rows.is_empty() {
                    return bad("the hardening table needs at least one row [plastic strain, yield stress]".into());
                }
                if rows[0].0 != 0.0 {
                    return bad(format!("the hardening table's first row must be at plastic strain 0 (the initial yield stress), got {}", rows[0].0));
                }
                for (i, &(e, s)) in rows.iter().enumerate() {
                    if !(e.is_finite() && s.is_finite() && s > 0.0) {
                        return bad(format!("row {i} of the hardening table: expected a finite plastic strain and a positive yield stress, got [{e}, {s}]"));
                    }
                    if i > 0 {
                        let (ep, sp) = rows[i - 1];
                        if e <= ep {
                            return bad(format!("row {i} of the hardening table: the plastic strains must increase, got {e} after {ep}"));
                        }
                        if s < sp {
                            return bad(format!("row {i} of the hardening table: the yield stress must not decrease (softening is not supported), got {s} after {sp}"));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// sigma_y(ep) and d sigma_y / d ep.
    pub fn yield_stress(&self, ep: f64) -> (f64, f64) {
        match self {
            Hardening::Linear { yield_stress, modulus } => (yield_stress + modulus * ep, *modulus),
            Hardening::Swift { k, e0, n } => {
                let x = e0 + ep;
                let s = k * x.powf(*n);
                (s, n * s / x)
            }
            Hardening::Table(rows) => {
                // the segment that holds ep (the slope of the segment to the right at a row)
                match rows.iter().rposition(|&(e, _)| e <= ep) {
                    Some(i) if i + 1 < rows.len() => {
                        let ((e0, s0), (e1, s1)) = (rows[i], rows[i + 1]);
                        let slope = (s1 - s0) / (e1 - e0);
                        (s0 + slope * (ep - e0), slope)
                    }
                    Some(i) => (rows[i].1, 0.0),
                    None => (rows[0].1, 0.0),
                }
            }
        }
    }

    /// The initial yield stress sigma_y(0).
    pub fn initial(&self) -> f64 {
        self.yield_stress(0.0).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_laws_and_their_slopes() {
        let laws = [
            Hardening::Linear { yield_stress: 150.0, modulus: 1000.0 },
            Hardening::Swift { k: 530.0, e0: 0.005, n: 0.25 },
            Hardening::Table(vec![(0.0, 150.0), (0.1, 260.0), (0.3, 300.0)]),
        ];
        for law in &laws {
            law.validate().unwrap();
            for ep in [0.01, 0.05, 0.2, 0.45] {
                let (_, d) = law.yield_stress(ep);
                let fd = (law.yield_stress(ep + 1e-7).0 - law.yield_stress(ep - 1e-7).0) / 2e-7;
                assert!((d - fd).abs() <= 1e-6 * (1.0 + d.abs()), "{law:?} at {ep}: {d} against {fd}");
            }
        }
        assert_eq!(laws[0].yield_stress(0.1).0, 250.0);
        assert!((laws[1].initial() - 530.0 * 0.005f64.powf(0.25)).abs() < 1e-12);
        assert!((laws[2].yield_stress(0.05).0 - 205.0).abs() < 1e-12);
        assert_eq!(laws[2].yield_stress(1.0), (300.0, 0.0));
    }

    #[test]
    fn bad_laws_are_refused_with_the_reason() {
        let e = Hardening::Table(vec![(0.0, 150.0), (0.1, 140.0)]).validate().unwrap_err().to_string();
        assert!(e.contains("must not decrease"), "{e}");
        let e = Hardening::Table(vec![(0.01, 150.0)]).validate().unwrap_err().to_string();
        assert!(e.contains("plastic strain 0"), "{e}");
        let e = Hardening::Swift { k: 530.0, e0: 0.0, n: 0.25 }.validate().unwrap_err().to_string();
        assert!(e.contains("e0"), "{e}");
        let e = Hardening::Linear { yield_stress: 150.0, modulus: -1.0 }.validate().unwrap_err().to_string();
        assert!(e.contains("softening"), "{e}");
    }
}

//! The quadratic yield functions: von Mises (J2) and Hill's 1948 anisotropy of rolled sheet,
//! phi(T) = sqrt(T . M T) with T the stress in Voigt order [11, 22, 33, 23, 13, 12].
//!
//! Hill (1948): phi^2 = F (T22 - T33)^2 + G (T33 - T11)^2 + H (T11 - T22)^2 + 2 L T23^2 + 2 M T13^2
//! + 2 N T12^2 in the sheet's axes (1 the rolling direction, 3 the normal), with the constants
//! from the r-values normalised so that phi is the uniaxial stress along the rolling direction:
//! H = r0 / (1 + r0), G = 1 / (1 + r0), F = r0 / (r90 (1 + r0)),
//! N = (r0 + r90)(1 + 2 r45) / (2 r90 (1 + r0)), and L = M = 3/2 (the transverse shears, which
//! sheet tests do not measure, as von Mises'). r0 = r45 = r90 = 1 is von Mises.

use crate::orthotropic::Stiffness;
use stamp::{Result, StampError};

/// The 6 x 6 matrix M of phi^2 = T . M T.
pub type Quadratic = Stiffness;

/// M of von Mises: phi^2 = 3/2 s : s.
pub fn von_mises() -> Quadratic {
    hill([1.0, 1.0, 1.0]).expect("r = 1 is valid")
}

/// M of Hill's 1948 function from the r-values [r0, r45, r90] in the sheet's axes.
pub fn hill(r: [f64; 3]) -> Result<Quadratic> {
    if let Some(bad) = r.iter().find(|x| !(x.is_finite() && **x > 0.0 && **x <= 100.0)) {
        return Err(StampError::Material(format!("the r-values [r0, r45, r90] must be positive (Lankford coefficients, 0.1 to 10 in practice), got {bad}")));
    }
    let [r0, r45, r90] = r;
    let h = r0 / (1.0 + r0);
    let g = 1.0 / (1.0 + r0);
    let f = r0 / (r90 * (1.0 + r0));
    let n = (r0 + r90) * (1.0 + 2.0 * r45) / (2.0 * r90 * (1.0 + r0));
    let mut m = [[0.0; 6]; 6];
    m[0][0] = g + h;
    m[0][1] = -h;
    m[0][2] = -g;
    m[1][0] = -h;
    m[1][1] = f + h;
    m[1][2] = -f;
    m[2][0] = -g;
    m[2][1] = -f;
    m[2][2] = f + g;
    m[3][3] = 3.0;
    m[4][4] = 3.0;
    m[5][5] = 2.0 * n;
    Ok(m)
}

/// M in axes turned by `theta` about x3 from the sheet's (the sheet's rolling direction at
/// -theta in them): with S' = R S the stresses in the sheet's axes, phi^2 = S . (R^T M R) S.
pub fn turned(m: &Quadratic, theta: f64) -> Quadratic {
    // the columns of R: the sheet-axes stresses of unit stresses
    let cols: [[f64; 6]; 6] = std::array::from_fn(|j| {
        let mut s = [0.0; 6];
        s[j] = 1.0;
        crate::orthotropic::rotate_stress(&s, -theta)
    });
    std::array::from_fn(|i| std::array::from_fn(|j| (0..6).map(|a| (0..6).map(|b| cols[i][a] * m[a][b] * cols[j][b]).sum::<f64>()).sum()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn phi(m: &Quadratic, t: &[f64; 6]) -> f64 {
        (0..6).map(|i| (0..6).map(|j| t[i] * m[i][j] * t[j]).sum::<f64>()).sum::<f64>().sqrt()
    }

    #[test]
    fn von_mises_is_the_equivalent_stress() {
        let m = von_mises();
        let t: [f64; 6] = [100.0, -30.0, 20.0, 15.0, -7.0, 40.0];
        let p = (t[0] + t[1] + t[2]) / 3.0;
        let s = [t[0] - p, t[1] - p, t[2] - p];
        let vm = (1.5 * (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]) + 3.0 * (t[3] * t[3] + t[4] * t[4] + t[5] * t[5])).sqrt();
        assert!((phi(&m, &t) - vm).abs() < 1e-12 * vm);
        // uniaxial and hydrostatic
        assert!((phi(&m, &[250.0, 0.0, 0.0, 0.0, 0.0, 0.0]) - 250.0).abs() < 1e-12);
        assert!(phi(&m, &[5.0, 5.0, 5.0, 0.0, 0.0, 0.0]) < 1e-12);
    }

    /// Hill's phi of a uniaxial stress sigma at 0, 45 and 90 degrees to the rolling direction
    /// is sigma times sqrt of the closed-form ratios, and turning the function by theta is the
    /// same as turning the stress.
    #[test]
    fn hill_uniaxial_stresses() {
        let r = [1.8, 1.4, 2.2];
        let m = hill(r).unwrap();
        let [r0, r45, r90] = r;
        let uni = |deg: f64| {
            let a = deg.to_radians();
            [a.cos().powi(2), a.sin().powi(2), 0.0, 0.0, 0.0, a.sin() * a.cos()]
        };
        assert!((phi(&m, &uni(0.0)) - 1.0).abs() < 1e-12);
        // sigma_90 / sigma_0 = sqrt(r90 (1 + r0) / (r0 (1 + r90)))
        let s90 = (r90 * (1.0 + r0) / (r0 * (1.0 + r90))).sqrt();
        assert!((1.0 / phi(&m, &uni(90.0)) - s90).abs() < 1e-12);
        let mt = turned(&m, 30f64.to_radians());
        // in axes turned by 30 degrees a stress along their axis 1 is at 30 degrees to rolling
        assert!((phi(&mt, &uni(0.0)) - phi(&m, &uni(30.0))).abs() < 1e-12);
        let _ = r45;
    }
}

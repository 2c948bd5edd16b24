//! The elastic-plastic law of a material point: Hencky elasticity and the return map in the
//! logarithmic strain space, mapped to the plate's Green-Lagrange strain E and second
//! Piola-Kirchhoff stress S ([`super::hencky`]).

use super::hardening::Hardening;
use super::hencky::Hencky;
use super::return_map::{isotropic_stiffness, return_map, PlasticState, YieldBasis};
use super::yield_function::{hill, turned, von_mises, Quadratic};
use stamp::Result;

/// What a problem file's `plasticity = { ... }` gives: the hardening and, for rolled sheet, the
/// r-values [r0, r45, r90] of Hill's function relative to the plate's x1 axis (the rolling
/// direction); none is von Mises.
#[derive(Debug, Clone, PartialEq)]
pub struct Plasticity {
    pub hardening: Hardening,
    pub r_values: Option<[f64; 3]>,
}

impl Plasticity {
    pub fn validate(&self) -> Result<()> {
        self.hardening.validate()?;
        if let Some(r) = self.r_values {
            hill(r)?;
        }
        Ok(())
    }
}

/// The law of a material point: isotropic Hencky elasticity (Lame's lambda and mu) and
/// [`Plasticity`].
#[derive(Debug, Clone)]
pub struct PlasticLaw {
    stiffness: [[f64; 6]; 6],
    compliance: [[f64; 6]; 6],
    quadratic: Quadratic,
    isotropic: bool,
    /// The yield function's basis in the plate's axes.
    basis: YieldBasis,
    pub hardening: Hardening,
}

/// A point's answer: S, dS/dE, the state the step would commit, and whether it yields.
#[derive(Debug, Clone, Copy)]
pub struct PointResponse {
    pub stress: [f64; 6],
    pub tangent: [[f64; 6]; 6],
    pub state: PlasticState,
    pub yielding: bool,
    /// The Hencky strain (for outputs).
    pub log_strain: [f64; 6],
}

impl PlasticLaw {
    /// The law of a material of Lame constants `lambda`, `mu` with `plasticity` (validated).
    pub fn new(lambda: f64, mu: f64, plasticity: &Plasticity) -> Result<PlasticLaw> {
        plasticity.validate()?;
        let young = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
        let nu = lambda / (2.0 * (lambda + mu));
        let mut compliance = [[0.0; 6]; 6];
        for i in 0..3 {
            for j in 0..3 {
                compliance[i][j] = if i == j { 1.0 / young } else { -nu / young };
            }
            compliance[i + 3][i + 3] = 1.0 / mu;
        }
        let (quadratic, isotropic) = match plasticity.r_values {
            Some(r) => (hill(r)?, r == [1.0, 1.0, 1.0]),
            None => (von_mises(), true),
        };
        let basis = YieldBasis::new(&quadratic, &compliance);
        Ok(PlasticLaw { stiffness: isotropic_stiffness(lambda, mu), compliance, quadratic, isotropic, basis, hardening: plasticity.hardening.clone() })
    }

    /// The yield function's matrix in axes turned by `angle` about x3 from the plate's (an
    /// element's local frame), computed once per element.
    pub fn quadratic_in(&self, angle: f64) -> YieldBasis {
        if self.isotropic || angle == 0.0 {
            self.basis
        } else {
            YieldBasis::new(&turned(&self.quadratic, angle), &self.compliance)
        }
    }

    /// S and dS/dE at the Green-Lagrange strain `e` from the converged `state`, with the yield
    /// function `m` of [`PlasticLaw::quadratic_in`]. None when I + 2E is not positive definite or the return map fails.
    pub fn respond(&self, e: &[f64; 6], state: &PlasticState, m: &YieldBasis) -> Option<PointResponse> {
        self.respond_with(e, state, m, true)
    }

    /// [`PlasticLaw::respond`], with the tangent only when `with_tangent` (zeros otherwise: the
    /// geometric part of dS/dE is the costliest step of the point).
    pub fn respond_with(&self, e: &[f64; 6], state: &PlasticState, m: &YieldBasis, with_tangent: bool) -> Option<PointResponse> {
        let h = Hencky::new(e)?;
        let r = return_map(&h.strain, state, &self.stiffness, m, &self.hardening)?;
        let tangent = if with_tangent { h.tangent(&r.stress, &r.tangent) } else { [[0.0; 6]; 6] };
        Some(PointResponse { stress: h.stress(&r.stress), tangent, state: r.state, yielding: r.yielding, log_strain: h.strain })
    }

    /// The same with the strains themselves for H (the linear theory: small strains).
    pub fn respond_small(&self, e: &[f64; 6], state: &PlasticState, m: &YieldBasis) -> Option<PointResponse> {
        let r = return_map(e, state, &self.stiffness, m, &self.hardening)?;
        Some(PointResponse { stress: r.stress, tangent: r.tangent, state: r.state, yielding: r.yielding, log_strain: *e })
    }

    /// The elastic energy density at the Hencky strain `h` with plastic strain `hp`.
    pub fn elastic_energy(&self, h: &[f64; 6], hp: &[f64; 6]) -> f64 {
        let e: [f64; 6] = std::array::from_fn(|i| h[i] - hp[i]);
        0.5 * (0..6).map(|i| (0..6).map(|j| e[i] * self.stiffness[i][j] * e[j]).sum::<f64>()).sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const E: f64 = 210000.0;
    const NU: f64 = 0.3;

    fn law(p: &Plasticity) -> PlasticLaw {
        let mu = E / (2.0 * (1.0 + NU));
        let lambda = E * NU / ((1.0 + NU) * (1.0 - 2.0 * NU));
        PlasticLaw::new(lambda, mu, p).unwrap()
    }

    /// The response to E11 with the other strains found so that the stresses `free` vanish
    /// (Newton on the point's tangent), from `state`; returns (response, strain).
    fn driven(l: &PlasticLaw, m: &YieldBasis, e11: f64, guess: [f64; 6], free: &[usize], state: &PlasticState) -> (PointResponse, [f64; 6]) {
        let mut e = guess;
        e[0] = e11;
        for _ in 0..50 {
            let r = l.respond(&e, state, m).unwrap();
            let res: Vec<f64> = free.iter().map(|&i| r.stress[i]).collect();
            if res.iter().all(|x| x.abs() < 1e-9) {
                return (r, e);
            }
            let k = nalgebra::DMatrix::from_fn(free.len(), free.len(), |a, b| r.tangent[free[a]][free[b]]);
            let d = k.lu().solve(&nalgebra::DVector::from_vec(res)).unwrap();
            for (a, &i) in free.iter().enumerate() {
                e[i] -= d[a];
            }
        }
        panic!("no lateral equilibrium");
    }

    /// Uniaxial stress, small strain, each hardening law: past yield sigma = sigma_y(ep) with
    /// ep = eps - sigma / E, in increments from the committed states (the path).
    #[test]
    fn uniaxial_stress_follows_each_hardening_law() {
        let laws = [
            Hardening::Linear { yield_stress: 150.0, modulus: 0.0 },
            Hardening::Linear { yield_stress: 150.0, modulus: 1000.0 },
            Hardening::Swift { k: 530.0, e0: 0.005, n: 0.25 },
            Hardening::Table(vec![(0.0, 150.0), (0.001, 200.0), (0.003, 230.0)]),
        ];
        for hardening in laws {
            let l = law(&Plasticity { hardening: hardening.clone(), r_values: None });
            let m = l.quadratic_in(0.0);
            let mut state = PlasticState::default();
            let mut e = [0.0; 6];
            for k in 1..=20 {
                // small strains: 0.4 % at the end; the log and Green-Lagrange strains differ
                // by O(eps^2), so compare in the Hencky measure with the Kirchhoff stress
                let e11 = 2e-4 * k as f64;
                let (r, en) = driven(&l, &m, e11, e, &[1, 2, 3, 4, 5], &state);
                e = en;
                state = r.state;
                let c = 1.0 + 2.0 * e[0];
                let tau = r.stress[0] * c; // Kirchhoff = S11 C11 in uniaxial stress
                let h = 0.5 * c.ln();
                if r.yielding {
                    let (sy, _) = hardening.yield_stress(state.ep);
                    assert!((tau - sy).abs() < 1e-9 * sy, "{hardening:?}: tau {tau} against sigma_y {sy}");
                    assert!((state.ep - (h - tau / E)).abs() < 1e-10, "{hardening:?}: ep {} against {}", state.ep, h - tau / E);
                } else {
                    assert!((tau - E * h).abs() < 1e-9 * E * h.abs());
                }
            }
            assert!(state.ep > 1e-3, "{hardening:?} yielded: ep = {}", state.ep);
        }
    }

    /// Plane strain (E22 = 0, S33 = 0), perfectly plastic: S11 tends to 2 / sqrt(3) sigma_y as
    /// the plastic strain grows (S22 to S11 / 2).
    #[test]
    fn plane_strain_tends_to_two_over_root_three() {
        let sy = 150.0;
        let l = law(&Plasticity { hardening: Hardening::Linear { yield_stress: sy, modulus: 0.0 }, r_values: None });
        let m = l.quadratic_in(0.0);
        let mut state = PlasticState::default();
        let mut e = [0.0; 6];
        let mut tau = 0.0;
        for k in 1..=40 {
            let (r, en) = driven(&l, &m, 5e-4 * k as f64, e, &[2, 3, 4, 5], &state);
            e = en;
            state = r.state;
            tau = r.stress[0] * (1.0 + 2.0 * e[0]);
        }
        let limit = 2.0 / 3f64.sqrt() * sy;
        assert!((tau - limit).abs() < 1e-6 * limit, "plane strain: tau11 = {tau} against {limit}");
    }

    /// Hill's r-values come back from uniaxial pulls at 0, 45 and 90 degrees to the rolling
    /// direction: r = dHp_width / dHp_thickness.
    #[test]
    fn hill_r_values_from_uniaxial_pulls() {
        let r = [1.8, 1.4, 2.2];
        let l = law(&Plasticity { hardening: Hardening::Linear { yield_stress: 150.0, modulus: 500.0 }, r_values: Some(r) });
        for (deg, want) in [(0.0, r[0]), (45.0, r[1]), (90.0, r[2])] {
            // pull along x1 of axes turned by deg from the rolling direction
            let m = l.quadratic_in(f64::to_radians(deg));
            let mut state = PlasticState::default();
            let mut e = [0.0; 6];
            let mut prev = state;
            // small strains (0.1 % past yield): at 45 degrees the free shear strain turns the
            // strain's axes by O(strain), which the r-value (a ratio of rates) leaves out
            for k in 1..=10 {
                let (resp, en) = driven(&l, &m, 7e-4 + 1e-4 * k as f64, e, &[1, 2, 3, 4, 5], &state);
                e = en;
                prev = state;
                state = resp.state;
            }
            let got = (state.hp[1] - prev.hp[1]) / (state.hp[2] - prev.hp[2]);
            assert!((got - want).abs() < 1e-5 * want, "r at {deg} degrees: {got} against {want}");
        }
    }

    /// Large strain, perfectly plastic uniaxial stress: the Kirchhoff stress stays at sigma_y at
    /// 50 % stretch (S11 = sigma_y / C11), and the volume of the plastic flow is preserved.
    #[test]
    fn finite_strain_uniaxial_plateau() {
        let sy = 150.0;
        let l = law(&Plasticity { hardening: Hardening::Linear { yield_stress: sy, modulus: 0.0 }, r_values: None });
        let m = l.quadratic_in(0.0);
        let mut state = PlasticState::default();
        let mut e = [0.0; 6];
        for k in 1..=25 {
            let stretch: f64 = 1.0 + 0.02 * k as f64;
            let (r, en) = driven(&l, &m, 0.5 * (stretch * stretch - 1.0), e, &[1, 2, 3, 4, 5], &state);
            e = en;
            state = r.state;
            let tau = r.stress[0] * (1.0 + 2.0 * e[0]);
            assert!((tau - sy).abs() < 1e-9 * sy || k < 2, "stretch {stretch}: tau = {tau}");
        }
        assert!((state.hp[0] + state.hp[1] + state.hp[2]).abs() < 1e-12, "plastic flow is isochoric");
        assert!((state.ep - state.hp[0]).abs() < 1e-12, "ep is the axial plastic log strain");
    }

    /// dS/dE against central differences of S, elastic and plastic, von Mises and Hill, each
    /// hardening law.
    #[test]
    fn consistent_tangent_against_finite_differences() {
        let cases = [
            Plasticity { hardening: Hardening::Linear { yield_stress: 150.0, modulus: 1000.0 }, r_values: None },
            Plasticity { hardening: Hardening::Swift { k: 530.0, e0: 0.005, n: 0.25 }, r_values: Some([1.8, 1.4, 2.2]) },
            Plasticity { hardening: Hardening::Table(vec![(0.0, 150.0), (0.1, 260.0), (0.3, 300.0)]), r_values: Some([0.8, 1.2, 1.0]) },
        ];
        let committed = PlasticState { hp: [0.01, -0.004, -0.006, 0.002, 0.0, 0.003], ep: 0.012, active: true };
        for p in &cases {
            let l = law(p);
            let m = l.quadratic_in(0.3);
            for e in [[0.05, -0.01, -0.02, 0.004, 0.002, 0.01], [0.012, -0.004, -0.006, 0.002, 0.0, 0.003], [0.3, -0.1, -0.12, 0.05, -0.02, 0.08]] {
                let r = l.respond(&e, &committed, &m).unwrap();
                let scale = r.tangent.iter().flatten().fold(0.0f64, |a, x| a.max(x.abs()));
                for b in 0..6 {
                    let d = 1e-7;
                    let (mut ep, mut em) = (e, e);
                    ep[b] += d;
                    em[b] -= d;
                    let (sp, sm) = (l.respond(&ep, &committed, &m).unwrap().stress, l.respond(&em, &committed, &m).unwrap().stress);
                    for a in 0..6 {
                        let fd = (sp[a] - sm[a]) / (2.0 * d);
                        assert!((fd - r.tangent[a][b]).abs() < 1e-6 * scale, "{p:?} at {e:?} (yielding {}): K[{a}][{b}] = {} against {fd}", r.yielding, r.tangent[a][b]);
                    }
                }
            }
        }
    }
}

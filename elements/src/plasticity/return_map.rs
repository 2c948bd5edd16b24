//! The return map of associative plasticity with a quadratic yield function and isotropic
//! hardening, in a strain space where the elastic law is linear and the plastic strain additive
//! (the logarithmic strains of [`super::hencky`]; Miehe, Apel & Lambrecht 2002):
//!
//!   T = C (H - Hp),  phi(T) = sqrt(T . M T) <= sigma_y(ep),
//!   dHp = dlambda M T,  dep = dlambda phi(T)   (so that T : dHp = sigma_y dep).
//!
//! Backward Euler from the last converged (Hp_n, ep_n): T = (C^-1 + dlambda M)^-1 (H - Hp_n), and
//! the one unknown dlambda >= 0 solves g(dlambda) = phi(T) - sigma_y(ep_n + dlambda phi(T)) = 0
//! (Newton safeguarded by bisection), in the generalised eigenbasis of M and C^-1
//! ([`YieldBasis`]) where T(dlambda) is explicit. The consistent tangent dT/dH comes from
//! differentiating the local equations [C^-1 T + dlambda M T - (H - Hp_n), g] in (T, dlambda):
//! dT/dH = Xi - c (Xi n)(Xi n)^T / (c n . Xi n + sigma_y'), Xi = (C^-1 + dlambda M)^-1,
//! n = M T / phi, c = 1 - sigma_y' dlambda, so that the plate's Newton iteration stays quadratic.

use super::hardening::Hardening;
use super::yield_function::Quadratic;
use nalgebra::SMatrix;

type M6 = SMatrix<f64, 6, 6>;

/// The converged state of a material point: the plastic strain Hp (Voigt, engineering shears) and
/// the equivalent plastic strain ep.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PlasticState {
    pub hp: [f64; 6],
    pub ep: f64,
    /// Whether the point flowed plastically in the step that made this state (the yield state).
    pub active: bool,
}

/// The stress, the consistent tangent dT/dH, the new state and whether the point yields.
#[derive(Debug, Clone, Copy)]
pub struct Response {
    pub stress: [f64; 6],
    pub tangent: [[f64; 6]; 6],
    pub state: PlasticState,
    pub yielding: bool,
}

/// The isotropic elastic stiffness (Voigt, engineering shears).
pub fn isotropic_stiffness(lambda: f64, mu: f64) -> [[f64; 6]; 6] {
    let mut c = [[0.0; 6]; 6];
    for i in 0..3 {
        for j in 0..3 {
            c[i][j] = lambda + if i == j { 2.0 * mu } else { 0.0 };
        }
        c[i + 3][i + 3] = mu;
    }
    c
}

fn m6(a: &[[f64; 6]; 6]) -> M6 {
    M6::from_fn(|i, j| a[i][j])
}

/// A yield function with the elastic compliance in one basis: the generalised eigenvectors
/// M v_i = omega_i C^-1 v_i, normalised v_i . C^-1 v_j = delta_ij, so that
/// (C^-1 + dlambda M)^-1 = sum_i v_i v_i^T / (1 + dlambda omega_i): the return map then solves its
/// scalar equation without a linear solve. Made once per law and frame (an element's).
#[derive(Debug, Clone, Copy)]
pub struct YieldBasis {
    pub m: Quadratic,
    /// `v[i]`: the i-th generalised eigenvector.
    pub v: [[f64; 6]; 6],
    pub omega: [f64; 6],
}

impl YieldBasis {
    /// The basis of `m` with the compliance `compliance` (symmetric positive definite).
    pub fn new(m: &Quadratic, compliance: &[[f64; 6]; 6]) -> YieldBasis {
        let s = m6(compliance);
        let l = s.cholesky().expect("the compliance is positive definite").l();
        let li = l.try_inverse().expect("regular");
        let b = li * m6(m) * li.transpose();
        let b = (b + b.transpose()) * 0.5;
        let eig = nalgebra::SymmetricEigen::new(b);
        let vm = li.transpose() * eig.eigenvectors;
        YieldBasis { m: *m, v: std::array::from_fn(|i| std::array::from_fn(|k| vm[(k, i)])), omega: std::array::from_fn(|i| eig.eigenvalues[i].max(0.0)) }
    }
}

/// The return map at strain `h` from the converged `state` (see the module doc), with the elastic
/// `stiffness` and the yield function in `basis`. None for a strain that is not finite or a return
/// that fails (the state is then refused, and Newton backs off).
pub fn return_map(h: &[f64; 6], state: &PlasticState, stiffness: &[[f64; 6]; 6], basis: &YieldBasis, hardening: &Hardening) -> Option<Response> {
    if !h.iter().all(|x| x.is_finite()) {
        return None;
    }
    let e: [f64; 6] = std::array::from_fn(|i| h[i] - state.hp[i]);
    // the components of e in the basis: a_i = v_i . e (T = sum_i v_i a_i / (1 + dl omega_i))
    let a: [f64; 6] = std::array::from_fn(|i| (0..6).map(|k| basis.v[i][k] * e[k]).sum());
    let om = &basis.omega;
    // phi(dl) and d phi / d dl
    let phi_at = |dl: f64| -> (f64, f64) {
        let (mut p2, mut d) = (0.0, 0.0);
        for i in 0..6 {
            let q = 1.0 / (1.0 + dl * om[i]);
            let w = om[i] * a[i] * a[i] * q * q;
            p2 += w;
            d -= 2.0 * w * om[i] * q;
        }
        let phi = p2.max(0.0).sqrt();
        (phi, if phi > 0.0 { 0.5 * d / phi } else { 0.0 })
    };
    let (phi_tr, _) = phi_at(0.0);
    let (sy0, _) = hardening.yield_stress(state.ep);
    if phi_tr <= sy0 {
        let stress = std::array::from_fn(|i| (0..6).map(|j| stiffness[i][j] * e[j]).sum());
        return Some(Response { stress, tangent: *stiffness, state: PlasticState { active: false, ..*state }, yielding: false });
    }
    let g_at = |dl: f64| -> (f64, f64, f64) {
        let (phi, dphi) = phi_at(dl);
        let (sy, hs) = hardening.yield_stress(state.ep + dl * phi);
        (phi, phi - sy, dphi - hs * (phi + dl * dphi))
    };
    // a bracket [lo, hi] with g(lo) > 0 >= g(hi), from von Mises' radial return's dlambda
    let omax = om.iter().cloned().fold(0.0, f64::max);
    let mut lo = 0.0;
    let mut hi = (phi_tr / sy0 - 1.0) / omax.max(f64::MIN_POSITIVE);
    let mut tries = 0;
    while g_at(hi).1 > 0.0 {
        lo = hi;
        hi *= 4.0;
        tries += 1;
        if tries > 200 || !hi.is_finite() {
            return None;
        }
    }
    let mut dl = hi;
    let mut r = g_at(dl);
    for _ in 0..200 {
        let (phi, g, dg) = r;
        if !g.is_finite() {
            return None;
        }
        if g.abs() <= 1e-13 * phi.max(sy0) {
            break;
        }
        if g > 0.0 {
            lo = dl;
        } else {
            hi = dl;
        }
        let newton = dl - g / dg;
        dl = if dg < 0.0 && newton > lo && newton < hi { newton } else { 0.5 * (lo + hi) };
        r = g_at(dl);
        if hi - lo <= 1e-16 * hi {
            break;
        }
    }
    let (phi, _, _) = r;
    let (_, hs) = hardening.yield_stress(state.ep + dl * phi);
    // T, Xi = (C^-1 + dl M)^-1 and n = M T / phi
    let q: [f64; 6] = std::array::from_fn(|i| 1.0 / (1.0 + dl * om[i]));
    let t: [f64; 6] = std::array::from_fn(|k| (0..6).map(|i| basis.v[i][k] * a[i] * q[i]).sum());
    let mt: [f64; 6] = std::array::from_fn(|i| (0..6).map(|j| basis.m[i][j] * t[j]).sum());
    let xi: [[f64; 6]; 6] = std::array::from_fn(|k| std::array::from_fn(|l| (0..6).map(|i| basis.v[i][k] * q[i] * basis.v[i][l]).sum()));
    let n: [f64; 6] = std::array::from_fn(|i| mt[i] / phi);
    let xn: [f64; 6] = std::array::from_fn(|i| (0..6).map(|j| xi[i][j] * n[j]).sum());
    // dT/dH = Xi - c (Xi n)(Xi n)^T / (c n.Xi n + sigma_y'), c = 1 - sigma_y' dl (implicit
    // differentiation of the local equations, see the module doc)
    let c = 1.0 - hs * dl;
    let den = c * (0..6).map(|i| n[i] * xn[i]).sum::<f64>() + hs;
    if !(den.abs() > 0.0) {
        return None;
    }
    let tangent = std::array::from_fn(|i| std::array::from_fn(|j| xi[i][j] - c * xn[i] * xn[j] / den));
    let hp = std::array::from_fn(|i| state.hp[i] + dl * mt[i]);
    Some(Response { stress: t, tangent, state: PlasticState { hp, ep: state.ep + dl * phi, active: true }, yielding: true })
}

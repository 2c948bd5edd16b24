//! The return map of associative plasticity with a quadratic yield function and isotropic
//! hardening, in a strain space where the elastic law is linear and the plastic strain additive
//! (the logarithmic strains of [`super::hencky`]; Miehe, Apel & Lambrecht 2002):
//!
//!   T = C (H - Hp),  phi(T) = sqrt(T . M T) <= sigma_y(ep),
//!   dHp = dlambda M T,  dep = dlambda phi(T)   (so that T : dHp = sigma_y dep).
//!
//! Backward Euler from the last converged (Hp_n, ep_n): T = (C^-1 + dlambda M)^-1 (H - Hp_n), and
//! the one unknown dlambda >= 0 solves g(dlambda) = phi(T) - sigma_y(ep_n + dlambda phi(T)) = 0
//! (Newton safeguarded by bisection). The consistent tangent dT/dH is the 6 x 6 block of the
//! inverse Jacobian of the local equations [C^-1 T + dlambda M T - (H - Hp_n), g] in (T, dlambda)
//! (implicit differentiation), so that the plate's Newton iteration stays quadratic.

use super::hardening::Hardening;
use super::yield_function::Quadratic;
use nalgebra::{SMatrix, SVector};

type M6 = SMatrix<f64, 6, 6>;
type V6 = SVector<f64, 6>;

/// The converged state of a material point: the plastic strain Hp (Voigt, engineering shears) and
/// the equivalent plastic strain ep.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct PlasticState {
    pub hp: [f64; 6],
    pub ep: f64,
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

/// The return map at strain `h` from the converged `state` (see the module doc). `compliance` is
/// C^-1 of the elastic stiffness `stiffness`. None for a strain that is not finite or a return
/// that fails (the state is then refused, and Newton backs off).
pub fn return_map(h: &[f64; 6], state: &PlasticState, stiffness: &[[f64; 6]; 6], compliance: &[[f64; 6]; 6], m: &Quadratic, hardening: &Hardening) -> Option<Response> {
    if !h.iter().all(|x| x.is_finite()) {
        return None;
    }
    let c = m6(stiffness);
    let s = m6(compliance);
    let mq = m6(m);
    let e = V6::from_fn(|i, _| h[i] - state.hp[i]);
    let trial = c * e;
    let phi_of = |t: &V6| t.dot(&(mq * t)).max(0.0).sqrt();
    let phi_tr = phi_of(&trial);
    let (sy0, _) = hardening.yield_stress(state.ep);
    if phi_tr <= sy0 {
        return Some(Response { stress: trial.into(), tangent: *stiffness, state: *state, yielding: false });
    }
    // T(dlambda) and g(dlambda), with dg/ddlambda
    let at = |dl: f64| -> Option<(V6, f64, f64, f64)> {
        let a = s + mq * dl;
        let lu = a.lu();
        let t = lu.solve(&e)?;
        let mt = mq * t;
        let phi = t.dot(&mt).max(0.0).sqrt();
        let dt = -lu.solve(&mt)?;
        let dphi = if phi > 0.0 { mt.dot(&dt) / phi } else { 0.0 };
        let (sy, hs) = hardening.yield_stress(state.ep + dl * phi);
        let g = phi - sy;
        let dg = dphi - hs * (phi + dl * dphi);
        g.is_finite().then_some((t, phi, g, dg))
    };
    // a bracket [lo, hi] with g(lo) > 0 > g(hi): von Mises' radial return as the first guess
    let mu3 = 3.0 * c[(3, 3)];
    let mut lo = 0.0;
    let mut hi = (phi_tr / sy0 - 1.0) / mu3.max(f64::MIN_POSITIVE);
    let mut tries = 0;
    while at(hi)?.2 > 0.0 {
        lo = hi;
        hi *= 4.0;
        tries += 1;
        if tries > 200 {
            return None;
        }
    }
    let mut dl = hi;
    let mut result = at(dl)?;
    for _ in 0..100 {
        let (_, phi, g, dg) = result;
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
        result = at(dl)?;
        if hi - lo <= 1e-16 * hi {
            break;
        }
    }
    let (t, phi, _, _) = result;
    let (_, hs) = hardening.yield_stress(state.ep + dl * phi);
    let mt = mq * t;
    // the local Jacobian in (T, dlambda) and its inverse's T block: dT/dH
    let mut j = SMatrix::<f64, 7, 7>::zeros();
    j.fixed_view_mut::<6, 6>(0, 0).copy_from(&(s + mq * dl));
    j.fixed_view_mut::<6, 1>(0, 6).copy_from(&mt);
    let n = mt / phi;
    j.fixed_view_mut::<1, 6>(6, 0).copy_from(&(n.transpose() * (1.0 - hs * dl)));
    j[(6, 6)] = -hs * phi;
    let inv = j.try_inverse()?;
    let tangent: [[f64; 6]; 6] = std::array::from_fn(|a| std::array::from_fn(|b| inv[(a, b)]));
    let hp = std::array::from_fn(|i| state.hp[i] + dl * mt[i]);
    Some(Response { stress: t.into(), tangent, state: PlasticState { hp, ep: state.ep + dl * phi }, yielding: true })
}

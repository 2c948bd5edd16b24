//! The plastic history of a multi-surface plate: the converged [`PlasticState`] of every
//! integration point (element, level through the thickness, Gauss point in the plane) and the
//! laws of the layers, with what the element's kernel needs from them.

use super::law::{PlasticLaw, Plasticity};
use super::return_map::PlasticState;
use super::return_map::YieldBasis;
use stamp::Result;

/// The plastic layers of a section and the history of their points.
#[derive(Debug, Clone)]
pub struct PlasticPoints {
    /// Per layer (the index of its law): its plastic law, or None for an elastic layer.
    pub laws: Vec<Option<PlasticLaw>>,
    /// Per element, level and Gauss point (`(e * levels + q) * 4 + g`): the converged state.
    pub states: Vec<PlasticState>,
    /// Integration levels per element.
    pub levels: usize,
    /// Logarithmic strains (nonlinear kinematics) or the strains themselves (linear).
    pub finite: bool,
}

/// What the kernel of one element reads: the laws, their yield functions in the element's frame,
/// the element's converged states.
pub struct ElementPlasticity<'a> {
    pub laws: &'a [Option<PlasticLaw>],
    pub quadratics: &'a [YieldBasis],
    pub committed: &'a [PlasticState],
    pub finite: bool,
}

impl PlasticPoints {
    /// The points of `elements` elements of `levels` levels for the layers' `plasticity` (None:
    /// elastic) with Lame constants `lame` [(lambda, mu)].
    pub fn new(plasticity: &[Option<Plasticity>], lame: &[(f64, f64)], elements: usize, levels: usize, finite: bool) -> Result<PlasticPoints> {
        let laws = plasticity.iter().zip(lame).map(|(p, &(l, m))| p.as_ref().map(|p| PlasticLaw::new(l, m, p)).transpose()).collect::<Result<Vec<_>>>()?;
        Ok(PlasticPoints { laws, states: vec![PlasticState::default(); elements * levels * 4], levels, finite })
    }

    /// The converged states of element `e`.
    pub fn of_element(&self, e: usize) -> &[PlasticState] {
        let n = self.levels * 4;
        &self.states[e * n..(e + 1) * n]
    }

    /// The yield functions of the layers in a frame turned by `angle` from the plate's axes, into
    /// `out` (one per law; the elastic layers' entries are not read).
    pub fn quadratics_into(&self, angle: f64, out: &mut Vec<YieldBasis>) {
        out.clear();
        out.extend(self.laws.iter().map(|l| match l {
            Some(l) => l.quadratic_in(angle),
            None => YieldBasis { m: [[0.0; 6]; 6], v: [[0.0; 6]; 6], omega: [0.0; 6] },
        }));
    }
}

impl ElementPlasticity<'_> {
    /// S and dS/dE at strain `e` of the point `point` (level q, Gauss point g: 4 q + g) of law
    /// `law`, None if that law is elastic; Some(None) when I + 2E is not positive definite.
    #[inline]
    pub fn respond(&self, law: usize, point: usize, e: &[f64; 6], with_tangent: bool) -> Option<Option<super::law::PointResponse>> {
        let l = self.laws.get(law)?.as_ref()?;
        Some(if self.finite { l.respond_with(e, &self.committed[point], &self.quadratics[law], with_tangent) } else { l.respond_small(e, &self.committed[point], &self.quadratics[law]) })
    }
}

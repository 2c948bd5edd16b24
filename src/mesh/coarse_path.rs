//! A load path solved on a coarse mesh, as the start of every load step on a fine one.
//!
//! On a fine mesh the secant predictor (the last increment again) misplaces what the step
//! changes most: where a punch's contact zone grows, the band the rim sweeps over in the step is
//! predicted a free plate's increment deep inside the punch, and the active set has to walk there
//! ring by ring. The same problem solved first on a coarse mesh (a quarter of the unknowns for a
//! mesh with half the element size) knows where the rim goes; its solution interpolated onto the
//! fine mesh ([`crate::mesh::transfer::Prolongation`]) starts each fine step within the coarse
//! mesh's discretisation error of the answer. Measured on `stamp bench --problem
//! sphere-displacement` (docs/performance.md).
//!
//! The coarse path is recorded step by step ([`CoarsePath::record`]); a fine step to load factor
//! t starts from the coarse state at the same point of the path, interpolated linearly in the
//! path's length (sum of |dt|) between the two coarse states around it, so a fine path with other
//! step sizes or cut-backs, going up and down, is predicted all the same.

use crate::mesh::transfer::Prolongation;

/// The converged states of a coarse path and the map onto the fine mesh.
pub struct CoarsePath {
    prolongation: Prolongation,
    components: usize,
    /// (path length, load factor, state) of each converged coarse state, in path order.
    states: Vec<(f64, f64, Vec<f64>)>,
    /// The fine path: converged steps, load factor and path length of its last converged state.
    fine_steps: usize,
    fine_t: f64,
    fine_length: f64,
    scratch: Vec<f64>,
}

impl CoarsePath {
    /// An empty path from the coarse mesh onto the fine one, `components` unknowns per node.
    pub fn new(prolongation: Prolongation, components: usize) -> Self {
        CoarsePath { prolongation, components, states: Vec::new(), fine_steps: 0, fine_t: 0.0, fine_length: 0.0, scratch: Vec::new() }
    }

    /// Record a converged coarse state at load factor `t` (the first one is the path's start).
    pub fn record(&mut self, t: f64, u: &[f64]) {
        let length = self.states.last().map(|(s, t_last, _)| s + (t - t_last).abs()).unwrap_or(0.0);
        self.states.push((length, t, u.to_vec()));
    }

    /// Load factor of the last recorded state (None before the first).
    pub fn last_load_factor(&self) -> Option<f64> {
        self.states.last().map(|s| s.1)
    }

    /// Converged coarse states recorded (the start included).
    pub fn len(&self) -> usize {
        self.states.len()
    }

    /// No state recorded yet.
    pub fn is_empty(&self) -> bool {
        self.states.is_empty()
    }

    /// Set `fine` to the coarse path's state for the fine step from load factor `from` (the fine
    /// path's state after `converged_steps` converged steps) to `to`. False (and `fine` left as
    /// it is) where the coarse path does not reach (it stopped short: a coarse run that did not
    /// converge to the end).
    pub fn predict(&mut self, converged_steps: usize, from: f64, to: f64, fine: &mut [f64]) -> bool {
        if converged_steps != self.fine_steps {
            // a step converged since the last call: the path went on from fine_t to `from`
            self.fine_length += (from - self.fine_t).abs();
            self.fine_t = from;
            self.fine_steps = converged_steps;
        }
        let target = self.fine_length + (to - from).abs();
        let Some(k) = self.states.windows(2).position(|w| target <= w[1].0 * (1.0 + 1e-12) + 1e-14) else {
            return false;
        };
        let ((s0, _, u0), (s1, _, u1)) = (&self.states[k], &self.states[k + 1]);
        let w = if s1 > s0 { ((target - s0) / (s1 - s0)).clamp(0.0, 1.0) } else { 1.0 };
        self.scratch.clear();
        self.scratch.extend(u0.iter().zip(u1).map(|(a, b)| a + w * (b - a)));
        self.prolongation.apply(&self.scratch, self.components, fine);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::QuadMesh;

    /// A coarse path u(t) = t x1 (one unknown per node) recorded at t = 0, 0.5, 1, 0.5 (loading,
    /// then unloading) predicts the fine mesh's t x1 at every fine step, whatever its size, on the
    /// way up and on the way down; past the coarse path's end there is no prediction.
    #[test]
    fn follows_the_coarse_path_up_and_down() {
        let coarse = QuadMesh::rectangle(0.0, 2.0, 0.0, 1.0, 2, 1).unwrap();
        let fine = crate::mesh::refine::refine(&coarse).mesh;
        let field = |mesh: &QuadMesh, t: f64| mesh.coords.iter().map(|p| t * p[0]).collect::<Vec<f64>>();
        let mut path = CoarsePath::new(Prolongation::between(&coarse, &fine), 1);
        for t in [0.0, 0.5, 1.0, 0.5] {
            path.record(t, &field(&coarse, t));
        }
        assert_eq!(path.len(), 4);
        let mut u = vec![0.0; fine.num_nodes()];
        // fine steps 0 -> 0.3 -> 0.8 -> 1.0 -> 0.7 -> 0.5, one converged step after another
        let steps = [(0.0, 0.3), (0.3, 0.8), (0.8, 1.0), (1.0, 0.7), (0.7, 0.5)];
        for (k, &(from, to)) in steps.iter().enumerate() {
            assert!(path.predict(k, from, to, &mut u), "step {k}");
            let want = field(&fine, to);
            for (a, b) in u.iter().zip(&want) {
                assert!((a - b).abs() < 1e-12, "step {k} to {to}: {a} against {b}");
            }
        }
        // a cut-back: the same start asked again with a shorter step
        assert!(path.predict(steps.len() - 1, 0.7, 0.6, &mut u));
        assert!((u[2] - 0.6 * fine.coords[2][0]).abs() < 1e-12);
        // beyond the coarse path's end (path length 1.5): nothing
        let before = u.clone();
        assert!(!path.predict(steps.len(), 0.5, 0.4, &mut u));
        assert_eq!(u, before);
    }
}

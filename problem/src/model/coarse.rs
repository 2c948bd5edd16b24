//! `[solver] predictor = "coarse"`: the problem is solved first on a coarse mesh (the rectangle
//! with half its n, or `[mesh] coarse_file`), with the same load steps and settings, and every
//! load step on the problem's mesh starts from that solution interpolated onto it
//! ([`stamp::mesh::coarse_path`]). The coarse solve writes no files; summary.json's `coarse_predictor`
//! and a line on stderr report what it cost. A coarse solve that fails leaves the steps beyond
//! its last converged state to the secant predictor (the run goes on and says so). `stamp run
//! --refine` starts each finer mesh from the run before it the same way ([`PreviousLevel`]).

use crate::model::build::{CoarseSetup, Setup};
use serde::Serialize;
use stamp::linalg::bordered::BorderedSolver;
use stamp::mesh::QuadMesh;
use stamp::mesh::coarse_path::CoarsePath;
use stamp::mesh::transfer::Prolongation;
use stamp::nonlinear::{NewtonRaphson, NonlinearProblem, NonlinearSolver};
use std::sync::Arc;
use std::time::Instant;

/// A run on a coarser mesh whose converged states start every load step of another (`stamp run
/// --refine`: the mesh before).
#[derive(Debug, Clone)]
pub struct PreviousLevel {
    pub mesh: QuadMesh,
    /// (load factor, unknowns) of every converged step.
    pub states: Arc<Vec<(f64, Vec<f64>)>>,
}

impl PreviousLevel {
    /// Its path (from the unloaded start) mapped onto `fine`, `components` unknowns per node.
    pub fn path_onto(&self, fine: &QuadMesh, components: usize) -> CoarsePath {
        let mut path = CoarsePath::new(Prolongation::between(&self.mesh, fine), components);
        // prescribed values scale with the load factor: zero at the start
        path.record(0.0, &vec![0.0; self.states.first().map(|s| s.1.len()).unwrap_or(0)]);
        for (t, u) in self.states.iter() {
            path.record(*t, u);
        }
        path
    }
}

/// What the coarse solve cost and how far it went (summary.json `coarse_predictor`).
#[derive(Debug, Clone, Serialize)]
pub struct CoarseReport {
    pub nodes: usize,
    pub equations: usize,
    pub steps: usize,
    /// Of the converged steps (a failed solve's last step: in `error`).
    pub cutbacks: usize,
    /// Of the converged steps' attempts that converged.
    pub newton_iterations: usize,
    /// Of the attempts that failed and were cut back (a failed solve's last step included).
    pub failed_iterations: usize,
    pub seconds: f64,
    /// The load factor of its last converged state (the run's last target when it converged).
    pub reached_load_factor: f64,
    /// Why it stopped short, if it did.
    pub error: Option<String>,
}

impl CoarseReport {
    /// One line for stderr.
    pub fn line(&self) -> String {
        let cost = format!("{} steps, {} Newton iterations, {:.2} s", self.steps, self.newton_iterations, self.seconds);
        match &self.error {
            None => format!("coarse predictor: solved on {} nodes ({cost})", self.nodes),
            Some(e) => format!(
                "warning: coarse predictor: the coarse mesh ({} nodes) stopped at load factor {:.6e} ({cost}): {e}; the steps beyond start from the secant predictor",
                self.nodes, self.reached_load_factor
            ),
        }
    }
}

/// Solve `coarse` along `targets` and return its path mapped onto the problem's mesh, with its
/// report.
pub fn solve_coarse(coarse: CoarseSetup, targets: &[f64]) -> (CoarsePath, CoarseReport) {
    let start = Instant::now();
    let CoarseSetup { setup: Setup { mesh, mut model, settings, .. }, prolongation } = coarse;
    let mut path = CoarsePath::new(prolongation, model.dofs.dofs_per_node());
    let mut u = vec![0.0; model.num_dofs()];
    model.apply_prescribed(&mut u, 0.0);
    path.record(0.0, &u);
    let mut newton = NewtonRaphson::new(BorderedSolver::new(model.num_drives()), settings);
    newton.interrupt = crate::run::interrupt::install();
    newton.agree_interrupt = crate::run::parallel::agreed_interrupt();
    // counted per converged step: a failed solve returns no summary
    let (mut iterations, mut cutbacks) = (0, 0);
    let result = newton.solve_path(&mut model, &mut u, 0.0, targets, &mut |rep, u, _| {
        iterations += rep.iterations;
        cutbacks += rep.cutbacks;
        path.record(rep.load_factor, u);
    });
    let report = CoarseReport {
        nodes: mesh.mesh.num_nodes(),
        equations: model.num_equations(),
        steps: path.len() - 1,
        cutbacks,
        newton_iterations: iterations,
        seconds: start.elapsed().as_secs_f64(),
        reached_load_factor: path.last_load_factor().unwrap_or(0.0),
        failed_iterations: newton.iterations_done().saturating_sub(iterations),
        error: result.err().map(|e| e.to_string()),
    };
    (path, report)
}

/// Set `newton` to start every load step from `path`.
pub fn predict_from<L: stamp::linalg::linear_solver::LinearSolver>(newton: &mut NewtonRaphson<L>, mut path: CoarsePath) {
    newton.predictor = Some(Box::new(move |steps, from, to, u| path.predict(steps, from, to, u)));
}

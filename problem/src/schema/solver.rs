//! `[solver]`: the load targets (or steps), the increments, Newton's settings, the predictor and
//! the linear solver's options.

use super::Problem;
use super::limits;
use super::values::{num, CutbackCount, CycleCount, Increment, InitialIncrement, IterationCount, LineSearchCount, MaxStepCount, NonNegative, RelTol, StepCount};
use serde::Deserialize;
use serde::de::{Deserializer, Error as _};
use stamp::{Result, StampError};
use toml::Spanned;

/// Load factors to reach in turn: finite, >= 0, each different from the one before (the path starts
/// at 0). They may go down again: loading, then unloading.
#[derive(Debug, Clone, PartialEq)]
pub struct Targets(pub Vec<f64>);
impl<'de> Deserialize<'de> for Targets {
    fn deserialize<D: Deserializer<'de>>(d: D) -> std::result::Result<Self, D::Error> {
        let v = Vec::<f64>::deserialize(d)?;
        if v.len() as u64 > limits::MAX_STEPS {
            return Err(D::Error::custom(format!("at most {} load factors, got {}", limits::MAX_STEPS, v.len())));
        }
        if v.is_empty() {
            return Err(D::Error::custom("expected at least one load factor"));
        }
        let mut last = 0.0;
        for &t in &v {
            if !(t.is_finite() && t >= 0.0) {
                return Err(D::Error::custom(format!("load factors must be finite and >= 0, got {}", num(t))));
            }
            if t > limits::MAX_LOAD_FACTOR {
                return Err(D::Error::custom(format!("load factors must be at most {:e}, got {}", limits::MAX_LOAD_FACTOR, num(t))));
            }
            if t == last {
                return Err(D::Error::custom(format!("each load factor must differ from the one before (the path starts at 0): {} after {}", num(t), num(last))));
            }
            last = t;
        }
        Ok(Targets(v))
    }
}

/// The default largest load increment (`[solver] max_increment`).
pub const DEFAULT_MAX_INCREMENT: f64 = 0.25;

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Load factors at which results are wanted (default [1.0]) ...
    #[serde(default)]
    pub targets: Option<Spanned<Targets>>,
    /// ... or this many equal steps to load factor 1.
    #[serde(default)]
    pub steps: Option<Spanned<StepCount>>,
    #[serde(default)]
    pub max_increment: Option<Spanned<Increment>>,
    #[serde(default)]
    pub initial_increment: Option<InitialIncrement>,
    #[serde(default)]
    pub min_increment: Option<Spanned<Increment>>,
    #[serde(default)]
    pub rel_tol: Option<RelTol>,
    #[serde(default)]
    pub abs_tol: Option<NonNegative>,
    #[serde(default)]
    pub max_iterations: Option<IterationCount>,
    #[serde(default)]
    pub max_cutbacks: Option<CutbackCount>,
    /// Most converged load steps of the path (see [`Problem::max_steps`]).
    #[serde(default)]
    pub max_steps: Option<Spanned<MaxStepCount>>,
    #[serde(default)]
    pub line_search_steps: Option<LineSearchCount>,
    /// Give up a step whose active set swings at every iteration without progress from this
    /// iteration on, and cut it back (off by default; see NewtonSettings::cycling_after).
    #[serde(default)]
    pub cycling_after: Option<CycleCount>,
    /// Solve the linearised contact problem again on each factorisation (default true; see
    /// NewtonSettings::resolve_contact).
    #[serde(default)]
    pub resolve_contact: Option<bool>,
    /// Where each load step starts (default "secant").
    #[serde(default)]
    pub predictor: Option<Spanned<Predictor>>,
    /// Newton's tangent (default "mip").
    #[serde(default)]
    pub newton: Option<NewtonTangent>,
    /// PETSc options for the linear solve ("-ksp_type cg -pc_type gamg"), for a stamp built with
    /// the feature `petsc` (see crate::run::parallel).
    #[serde(default)]
    pub petsc_options: Option<Spanned<String>>,
}

/// `[solver] newton`: the stresses of Newton's geometric stiffness.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum NewtonTangent {
    /// The stresses of the strains linearised about the last iterate (the mixed-integration-point
    /// iteration, stamp::element::Element::evaluate_about): the same answers in fewer iterations
    /// on thin plates under large rotations.
    #[default]
    Mip,
    /// The stresses at the iterate: the exact derivative of the residual (the paper's Newton).
    Standard,
}

/// `[solver] predictor`: the start of each load step.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Predictor {
    /// The last converged increment again (scaled to the step).
    #[default]
    Secant,
    /// The problem solved first on a coarse mesh (the rectangle with half its n, or
    /// `mesh.coarse_file`), interpolated onto the mesh (stamp::mesh::coarse_path).
    Coarse,
}

impl Problem {
    /// The checks of `[solver]`: `targets` or `steps`, and the load increments against the path.
    pub(super) fn check_solver(&self) -> Result<()> {
        let s = &self.spec;
        if s.solver.targets.is_some() && s.solver.steps.is_some() {
            let t = s.solver.targets.as_ref().unwrap();
            return Err(self.error_at(t.span(), "solver.targets", "give `targets` or `steps`, not both"));
        }
        self.check_increments()?;
        Ok(())
    }

    /// The load increments against the path: min_increment <= max_increment, at most
    /// [`limits::MAX_STEPS`] increments of max_increment along the path, and a min_increment above
    /// the round-off of the largest load factor (so that every increment moves the load).
    fn check_increments(&self) -> Result<()> {
        let sv = &self.spec.solver;
        let defaults = stamp::nonlinear::NewtonSettings::default();
        let max_inc = sv.max_increment.as_ref().map_or(DEFAULT_MAX_INCREMENT, |x| x.get_ref().0);
        let min_inc = sv.min_increment.as_ref().map_or(defaults.min_increment, |x| x.get_ref().0);
        // where to point: the key given, else the [solver] targets/steps, else the file
        let span_of = |k: &Option<Spanned<Increment>>| k.as_ref().map(|x| x.span()).or_else(|| sv.targets.as_ref().map(|t| t.span())).or_else(|| sv.steps.as_ref().map(|t| t.span()));
        let fail = |span: Option<std::ops::Range<usize>>, key: &str, message: String| match span {
            Some(sp) => self.error_at(sp, key, message),
            None => StampError::Input { file: self.path.display().to_string(), message: format!("{key}: {message}") },
        };
        if min_inc > max_inc {
            return Err(fail(span_of(&sv.min_increment), "solver.min_increment", format!("{} exceeds max_increment = {}", num(min_inc), num(max_inc))));
        }
        let targets = self.targets();
        let path = path_length(&targets);
        let increments = path / max_inc;
        if increments > limits::MAX_STEPS as f64 {
            return Err(fail(
                span_of(&sv.max_increment),
                "solver.max_increment",
                format!("the load path (length {}) needs {} increments of max_increment = {}; at most {} are allowed: raise max_increment or shorten the targets", num(path), num(increments.ceil()), num(max_inc), limits::MAX_STEPS),
            ));
        }
        if let Some(m) = &sv.max_steps {
            let least = self.least_steps();
            if m.get_ref().0 < least {
                return Err(self.error_at(m.span(), "solver.max_steps", format!("{} is fewer than the {least} steps the path needs at least (its targets, and increments of at most max_increment = {})", m.get_ref().0, num(max_inc))));
            }
        }
        let largest = targets.iter().cloned().fold(1.0, f64::max);
        let floor = 1e-12 * largest;
        if min_inc < floor {
            return Err(fail(span_of(&sv.min_increment), "solver.min_increment", format!("{} is below the round-off of load factors up to {}; the smallest allowed is {}", num(min_inc), num(largest), num(floor))));
        }
        Ok(())
    }

    /// The fewest steps the path can take: one per target, and as many increments of
    /// max_increment as its length needs.
    pub fn least_steps(&self) -> usize {
        let max_inc = self.spec.solver.max_increment.as_ref().map_or(DEFAULT_MAX_INCREMENT, |x| x.get_ref().0);
        let targets = self.targets();
        let path = path_length(&targets);
        // bounded by limits::MAX_STEPS (check_increments)
        let increments = (path / max_inc * (1.0 - 1e-12)).ceil().min(limits::MAX_STEPS as f64) as usize;
        increments.max(targets.len())
    }

    /// `[solver] max_steps`: the most converged load steps of the path before it is given up (see
    /// [`stamp::nonlinear::NewtonSettings::max_steps`]); by default [`limits::DEFAULT_MAX_STEPS`],
    /// or [`limits::STEP_BUDGET_FACTOR`] times [`least_steps`](Self::least_steps) if that is more.
    pub fn max_steps(&self) -> usize {
        match &self.spec.solver.max_steps {
            Some(m) => m.get_ref().0,
            None => limits::DEFAULT_MAX_STEPS.max(limits::STEP_BUDGET_FACTOR * self.least_steps()),
        }
    }


    /// The load factors to reach.
    pub fn targets(&self) -> Vec<f64> {
        if let Some(t) = &self.spec.solver.targets {
            t.get_ref().0.clone()
        } else if let Some(n) = &self.spec.solver.steps {
            let n = n.get_ref().0;
            (1..=n).map(|k| k as f64 / n as f64).collect()
        } else {
            vec![1.0]
        }
    }

}

/// The length of the load path through `targets` from 0 (down again counts too).
fn path_length(targets: &[f64]) -> f64 {
    targets.iter().fold((0.0, 0.0), |(len, last): (f64, f64), &t| (len + (t - last).abs(), t)).0
}

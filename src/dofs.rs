//! Degrees of freedom: `dofs_per_node` unknowns at every node, numbered node-major
//! (dof = node * dofs_per_node + component). Dirichlet constraints remove a dof from the system of
//! equations and prescribe its value as `load_factor * value`, or `path(load_factor) * value` along
//! a [`FactorPath`]; the remaining dofs get consecutive equation numbers in node order.

use crate::error::{Result, StampError};
use crate::factor_path::FactorPath;

/// Marks a prescribed dof that follows the load factor itself (no [`FactorPath`]).
const NO_PATH: u32 = u32::MAX;

/// Marks a dof that has no equation (it is prescribed).
pub const PRESCRIBED: u32 = u32::MAX;

/// Numbering of the unknowns and the Dirichlet constraints on them.
#[derive(Debug, Clone)]
pub struct DofMap {
    num_nodes: usize,
    dofs_per_node: usize,
    /// Equation number of each dof, or [`PRESCRIBED`].
    equation: Vec<u32>,
    /// Prescribed value at load factor 1 of each dof (0 for free dofs).
    prescribed: Vec<f64>,
    /// The path each prescribed dof follows (an index into `paths`, or [`NO_PATH`]: the load
    /// factor); empty while no dof has a path.
    path_of: Vec<u32>,
    paths: Vec<FactorPath>,
    num_equations: usize,
}

impl DofMap {
    /// All dofs free.
    pub fn new(num_nodes: usize, dofs_per_node: usize) -> Result<Self> {
        if num_nodes == 0 || dofs_per_node == 0 {
            return Err(StampError::Problem("a dof map needs at least one node and one dof per node".into()));
        }
        let n = num_nodes * dofs_per_node;
        if n >= PRESCRIBED as usize {
            return Err(StampError::Problem(format!("{n} dofs is more than stamp can number")));
        }
        let mut map = DofMap {
            num_nodes,
            dofs_per_node,
            equation: vec![0; n],
            prescribed: vec![0.0; n],
            path_of: Vec::new(),
            paths: Vec::new(),
            num_equations: 0,
        };
        map.renumber();
        Ok(map)
    }

    fn renumber(&mut self) {
        let mut next = 0u32;
        for e in self.equation.iter_mut() {
            if *e != PRESCRIBED {
                *e = next;
                next += 1;
            }
        }
        self.num_equations = next as usize;
    }

    /// Prescribe `component` of `node` to `load_factor * value`. Prescribing the same dof twice with
    /// different values is an error.
    pub fn prescribe(&mut self, node: usize, component: usize, value: f64) -> Result<()> {
        self.prescribe_along(node, component, value, None)
    }

    /// A path prescribed values may follow ([`DofMap::prescribe_along`]); its index.
    pub fn add_path(&mut self, path: FactorPath) -> usize {
        if let Some(k) = self.paths.iter().position(|p| *p == path) {
            return k;
        }
        self.paths.push(path);
        self.paths.len() - 1
    }

    /// The factor of a prescribed dof at load factor `t`: `t`, or its path's factor.
    #[inline]
    pub fn factor(&self, dof: usize, t: f64) -> f64 {
        match self.path_of.get(dof) {
            Some(&k) if k != NO_PATH => self.paths[k as usize].at(t),
            _ => t,
        }
    }

    /// Prescribe `component` of `node` to `value` times the factor of `path` (an index from
    /// [`DofMap::add_path`]) at each load factor, or times the load factor itself (`None`).
    /// Prescribing the same dof twice with different values or paths is an error.
    pub fn prescribe_along(&mut self, node: usize, component: usize, value: f64, path: Option<usize>) -> Result<()> {
        if node >= self.num_nodes || component >= self.dofs_per_node {
            return Err(StampError::Problem(format!(
                "cannot constrain component {component} of node {node}: the model has {} nodes with {} dofs each",
                self.num_nodes, self.dofs_per_node
            )));
        }
        if !value.is_finite() {
            return Err(StampError::NonFinite(format!("prescribed value {value} at node {node}, component {component}")));
        }
        if path.is_some_and(|k| k >= self.paths.len()) {
            return Err(StampError::Problem(format!("no path {} (the dof map has {})", path.unwrap_or(0), self.paths.len())));
        }
        let d = node * self.dofs_per_node + component;
        let tag = path.map_or(NO_PATH, |k| k as u32);
        let old_tag = self.path_of.get(d).copied().unwrap_or(NO_PATH);
        if self.equation[d] == PRESCRIBED && self.prescribed[d] != value {
            return Err(StampError::Problem(format!(
                "component {component} of node {node} is prescribed twice, to {} and to {value}",
                self.prescribed[d]
            )));
        }
        if self.equation[d] == PRESCRIBED && old_tag != tag && value != 0.0 {
            return Err(StampError::Problem(format!("component {component} of node {node} is prescribed twice, along two different paths")));
        }
        self.equation[d] = PRESCRIBED;
        self.prescribed[d] = value;
        if tag != NO_PATH && self.path_of.is_empty() {
            self.path_of = vec![NO_PATH; self.equation.len()];
        }
        if let Some(p) = self.path_of.get_mut(d) {
            *p = tag;
        }
        self.renumber();
        Ok(())
    }

    /// Prescribe the same components to zero on many nodes (renumbers once).
    pub fn fix(&mut self, nodes: &[usize], components: &[usize]) -> Result<()> {
        for &n in nodes {
            for &c in components {
                if n >= self.num_nodes || c >= self.dofs_per_node {
                    return Err(StampError::Problem(format!(
                        "cannot fix component {c} of node {n}: the model has {} nodes with {} dofs each",
                        self.num_nodes, self.dofs_per_node
                    )));
                }
                let d = n * self.dofs_per_node + c;
                if self.equation[d] == PRESCRIBED && self.prescribed[d] != 0.0 {
                    return Err(StampError::Problem(format!(
                        "component {c} of node {n} is fixed to 0 and prescribed to {}",
                        self.prescribed[d]
                    )));
                }
                self.equation[d] = PRESCRIBED;
            }
        }
        self.renumber();
        Ok(())
    }

    pub fn num_nodes(&self) -> usize {
        self.num_nodes
    }
    pub fn dofs_per_node(&self) -> usize {
        self.dofs_per_node
    }
    /// Total number of dofs, free and prescribed.
    pub fn num_dofs(&self) -> usize {
        self.equation.len()
    }
    /// Number of equations (free dofs).
    pub fn num_equations(&self) -> usize {
        self.num_equations
    }
    /// Equation number of a dof, `None` when it is prescribed.
    #[inline]
    pub fn equation(&self, dof: usize) -> Option<usize> {
        let e = self.equation[dof];
        (e != PRESCRIBED).then_some(e as usize)
    }
    /// Raw equation numbers ([`PRESCRIBED`] for prescribed dofs).
    pub fn equations(&self) -> &[u32] {
        &self.equation
    }
    /// Global dof index.
    #[inline]
    pub fn dof(&self, node: usize, component: usize) -> usize {
        node * self.dofs_per_node + component
    }
    /// Set every prescribed dof of `u` to `load_factor * value` (its path's factor times value for
    /// a dof on a path).
    pub fn apply_prescribed(&self, u: &mut [f64], load_factor: f64) {
        for (d, e) in self.equation.iter().enumerate() {
            if *e == PRESCRIBED {
                u[d] = self.factor(d, load_factor) * self.prescribed[d];
            }
        }
    }
    /// Add an increment given per equation to the free dofs of `u`.
    pub fn add_increment(&self, u: &mut [f64], du: &[f64]) {
        for (d, e) in self.equation.iter().enumerate() {
            if *e != PRESCRIBED {
                u[d] += du[*e as usize];
            }
        }
    }
    /// Gather the free dofs of a full vector into equation order.
    pub fn gather(&self, full: &[f64], out: &mut [f64]) {
        for (d, e) in self.equation.iter().enumerate() {
            if *e != PRESCRIBED {
                out[*e as usize] = full[d];
            }
        }
    }
}

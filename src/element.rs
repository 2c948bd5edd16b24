//! The element interface: what the assembler needs from a finite-element formulation. In the spirit
//! of MFEM's integrators, one object gives the residual (internal force), the tangent and the energy
//! of an element; like fenris, it works in a caller-owned workspace so that the hot loop allocates
//! nothing.

/// The local result of one element: internal force vector, tangent matrix (row-major, square),
/// strain energy and, from elements with [`Element::has_preconditioner`], the local preconditioner
/// matrix. Allocated once per thread and reused for every element.
#[derive(Debug, Clone)]
pub struct LocalSystem {
    pub residual: Vec<f64>,
    pub tangent: Vec<f64>,
    /// Row-major and square like `tangent`, filled with it by elements that have a preconditioner;
    /// empty (not asked for) unless made by [`LocalSystem::with_preconditioner`].
    pub preconditioner: Vec<f64>,
    pub energy: f64,
    /// Set by the element when the state it was evaluated at is not physically admissible (a
    /// finite-strain element turned inside out, say), with the reason: the assembler then refuses
    /// the whole state, naming the element, and Newton's line search or load stepping backs off.
    pub inadmissible: Option<String>,
}

impl LocalSystem {
    pub fn new(num_dofs: usize) -> Self {
        LocalSystem { residual: vec![0.0; num_dofs], tangent: vec![0.0; num_dofs * num_dofs], preconditioner: Vec::new(), energy: 0.0, inadmissible: None }
    }
    /// The same with room for the preconditioner matrix: asks the element to fill it.
    pub fn with_preconditioner(num_dofs: usize) -> Self {
        LocalSystem { preconditioner: vec![0.0; num_dofs * num_dofs], ..Self::new(num_dofs) }
    }
    pub fn num_dofs(&self) -> usize {
        self.residual.len()
    }
    /// Zero what an evaluation with or without the tangent fills: a residual-only evaluation
    /// leaves the tangent and preconditioner arrays alone (nothing reads them then; clearing a
    /// 24 x 24 or 48 x 48 array per element cost more than the paper's residual kernel spends on
    /// some of its sums).
    pub fn clear(&mut self, with_tangent: bool) {
        self.residual.fill(0.0);
        if with_tangent {
            self.tangent.fill(0.0);
            self.preconditioner.fill(0.0);
        }
        self.energy = 0.0;
        self.inadmissible = None;
    }
}

/// A set of finite elements of one kind over a mesh (the plate elements of a plate, say).
///
/// Element dofs are node-major: local dof `a * dofs_per_node() + c` is component `c` at the element's
/// node `a`. `evaluate` must be a pure function of the element's dof values (any history lives in the
/// implementor and is updated outside the assembly), so that elements can be evaluated in parallel.
pub trait Element: Sync {
    /// Per-thread scratch memory.
    type Workspace: Send;

    /// Number of unknowns at each node.
    fn dofs_per_node(&self) -> usize;
    /// Nodes of each element (all elements of one set have the same number).
    fn nodes_per_element(&self) -> usize;
    /// Number of elements.
    fn num_elements(&self) -> usize;
    /// Global node indices of element `e`.
    fn element_nodes(&self, e: usize) -> &[usize];
    /// Whether `evaluate` also gives a symmetric matrix P close to a non-symmetric tangent, whose
    /// factorisation preconditions the linear solves better than the tangent's symmetric part
    /// (see [`crate::linalg::ldlt_gmres`]). Default: no.
    fn has_preconditioner(&self) -> bool {
        false
    }
    /// Keep what is stored per element (its reference geometry, say) only for the elements
    /// flagged in `keep` (one flag per element): for a process of a shared model that evaluates
    /// those alone (see [`crate::share`]), so that it does not hold the whole model's element
    /// data. The others must not be evaluated afterwards. Default: nothing is dropped.
    fn retain_elements(&mut self, _keep: &[bool]) {}
    /// A fresh workspace.
    fn new_workspace(&self) -> Self::Workspace;
    /// Evaluate element `e` at the local dof values `u`: fill `out.residual` (internal force), the
    /// strain energy and, when `with_tangent`, `out.tangent` = d residual / d u (not necessarily
    /// symmetric), and with it `out.preconditioner` if [`Element::has_preconditioner`] and that is
    /// not empty; and `out.inadmissible` with the reason if the state `u` is not admissible (the
    /// residual then need not be meaningful). `out` is cleared by the caller.
    fn evaluate(&self, e: usize, u: &[f64], ws: &mut Self::Workspace, out: &mut LocalSystem, with_tangent: bool);

    /// [`evaluate`](Self::evaluate) with the tangent linearised about the stresses of an earlier
    /// iterate: `reference` holds the element's dof values at the last Newton iterate (or at the
    /// last converged state at the start of a load step), and an element with a geometric
    /// stiffness may take its stresses there from the strains linearised about `reference`,
    /// E(reference) + dE/du (u - reference), instead of E(u). The residual is that of `evaluate`.
    /// This is the mixed-integration-point Newton iteration of Magisano, Leonetti & Garcea (2017):
    /// the same converged answer, and far fewer iterations on thin plates under large rotations,
    /// whose displacement-based stresses at an iterate carry the spurious membrane and thickness
    /// stretch of the last linearised rotation. Default: [`evaluate`](Self::evaluate).
    fn evaluate_about(&self, e: usize, u: &[f64], _reference: &[f64], ws: &mut Self::Workspace, out: &mut LocalSystem, with_tangent: bool) {
        self.evaluate(e, u, ws, out, with_tangent)
    }

    /// Whether the elements carry a history that depends on the load path (plasticity): the
    /// model then calls [`commit`](Self::commit) on every element it evaluates after each
    /// converged load step. `evaluate` reads the history of the last converged step only, so that a
    /// failed step, cut back, leaves nothing to undo. Default: no history.
    fn has_history(&self) -> bool {
        false
    }
    /// Make the state at the local dof values `u` (a converged step's) element `e`'s history.
    fn commit(&mut self, _e: usize, _u: &[f64], _ws: &mut Self::Workspace) {}
}

//! Displacement-dependent external loads: loads whose value depends on the current state, such as
//! a pressure that follows the deformed surface or a couple that turns with an edge. The model
//! ([`crate::model::Model`]) calls every such load when it assembles, after the elements and the
//! contact pairs, and subtracts the load (times the load factor) from the residual and its
//! derivative from the tangent: R(u, t) = f_int(u) + f_contact(u, t) - t f_ext - t F(u), and
//! K = dR/du gets -t dF/du (in general not symmetric: it is not added to the symmetric
//! preconditioner of elements that have one).

/// An external load F(u) that depends on the displacements, given at load factor 1.
///
/// `u` holds every nodal dof (node-major, as in [`crate::dofs::DofMap`]; prescribed ones at their
/// prescribed values). The load adds F(u) to `force` (over the nodal dofs) and, when `tangent` is
/// given, every entry dF_r/du_c as `tangent(r, c, value)` (global dof indices; entries at
/// prescribed dofs are dropped by the caller). The caller scales both by the load factor.
/// The load must only couple dofs that share an element (the sparsity pattern is the elements').
pub trait DeformationDependentLoad: Send + Sync {
    /// A short description for messages ("follower pressure on 'top'", say).
    fn name(&self) -> &str;
    /// Add F(u) to `force` and dF/du to `tangent`.
    fn add_force_and_stiffness(&self, u: &[f64], force: &mut [f64], tangent: Option<&mut dyn FnMut(usize, usize, f64)>);
    /// In a distributed run (see [`crate::share`]), evaluate from now on only the pieces (cells,
    /// nodes) that touch a node of `own` (`own[n]`: this process owns node n); None: every piece.
    /// The caller keeps only the forces and tangent rows of the own nodes, so a load that
    /// ignores this (the default) is still right, only slower.
    fn share_nodes(&mut self, own: Option<&[bool]>) {
        let _ = own;
    }
}

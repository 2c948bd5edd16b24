//! A model: one element set on a mesh, its dofs and constraints, nodal loads, displacement-dependent
//! loads and punches. It is the [`NonlinearProblem`] the solver drives:
//! R(u, t) = f_int(u) + f_contact(u, t) - t f_ext - t F(u), F the
//! [`crate::follower::DeformationDependentLoad`]s (follower pressures, say).
//!
//! The unknowns are the nodal dofs (node-major, as in [`DofMap`]) followed by one displacement per
//! force-driven punch (see [`crate::contact::ForceDrive`]), in the order of `contacts`; so are the
//! equations: the punch's equilibrium is appended after the nodal equations and the sparse
//! pattern is bordered by one row and column per such punch, coupled to its candidate points'
//! dofs, so the same sparse LU solves the whole system.

use crate::assembly::Assembler;
use crate::contact::{ContactPair, PointState};
use crate::dofs::DofMap;
use crate::element::Element;
use crate::follower::DeformationDependentLoad;
use crate::error::{Result, StampError};
use crate::factor_path::FactorPath;
use crate::nonlinear::{Evaluation, NonlinearProblem};
use crate::share::Share;
use crate::linalg::sparse::SparsePattern;
use faer::sparse::SparseColMatRef;
use std::time::Instant;

/// Seconds spent assembling, cumulative.
#[derive(Debug, Clone, Copy, Default, serde::Serialize)]
pub struct ModelTimings {
    pub assembly: f64,
    pub contact: f64,
    pub assemblies: usize,
}

/// What a checkpoint keeps of a contact pair: lambda_bar, the point states, the active flags of
/// the last evaluation with a tangent, and the friction state.
type SavedContact = (Vec<f64>, Vec<PointState>, Vec<bool>, Option<crate::contact::Friction>);

/// Elements + dofs + loads + contact: everything that defines R(u, t).
pub struct Model<E: Element> {
    pub element: E,
    pub dofs: DofMap,
    /// Nodal forces (dof, value at load factor 1), scaled by the load factor.
    pub loads: Vec<(usize, f64)>,
    /// Nodal forces along a path: (dof, value, index into `load_paths`), scaled by the path's
    /// factor instead of the load factor ([`Model::dead_loads`] gives both kinds at a load factor).
    pub path_loads: Vec<(usize, f64, usize)>,
    /// The paths of `path_loads` and of the displacement-dependent loads added with one.
    pub load_paths: Vec<FactorPath>,
    /// The path of each displacement-dependent load (index into `load_paths`), None: the load
    /// factor; parallel to `follower_loads` (a load pushed there directly follows the load factor).
    follower_paths: Vec<Option<usize>>,
    pub contacts: Vec<ContactPair>,
    /// Displacement-dependent loads (follower pressures, couples), at load factor 1, scaled by
    /// the load factor like `loads`.
    pub follower_loads: Vec<Box<dyn DeformationDependentLoad>>,
    /// The displacement-dependent loads' force over all nodal dofs at the last evaluation (at the
    /// evaluation's load factor).
    follower_force: Vec<f64>,
    /// Augmented-Lagrangian tolerance on the penetration (a length; see
    /// [`ContactPair::constraint_violation`]); `None` for the plain perturbed Lagrangian.
    pub augmented_tolerance: Option<f64>,
    /// The nodal pattern, bordered by the force-driven punches' rows and columns when there are
    /// any (the nodal one is not kept beside it: a pattern can be 0.4 GB; see
    /// [`SparsePattern::unbordered`]).
    pattern: SparsePattern,
    /// Per force-driven punch: (index in `contacts`, number of candidate points) the pattern was
    /// bordered for.
    border: Vec<(usize, usize)>,
    /// The punches with an integrated discretisation (index in `contacts`, their
    /// [`ContactPair::coupling_version`]) the nodal pattern couples (see
    /// [`ContactPair::coupled_nodes`]).
    coupled: Vec<(usize, u64)>,
    assembler: Assembler,
    /// Internal + contact force over all dofs at the last evaluation (reactions at prescribed dofs).
    force: Vec<f64>,
    values: Vec<f64>,
    /// The preconditioner matrix in the same pattern (empty when the element has none or it was
    /// not asked for, see [`NonlinearProblem::want_preconditioner`]).
    preconditioner: Vec<f64>,
    residual: Vec<f64>,
    energy: f64,
    saved: Vec<SavedContact>,
    /// Force scale of the last evaluation, and the largest over the converged steps so far.
    last_scale: f64,
    peak_scale: f64,
    pub timings: ModelTimings,
    /// This process's share of a model evaluated by several (see [`crate::share`]); None: the
    /// whole model.
    share: Option<Share>,
    /// With a share: the elements whose entries the pattern holds (its own, and every element
    /// around a node it owns, so that the rows of its nodes are whole); None: every element.
    pattern_elements: Option<Vec<bool>>,
    /// The tangent's reference state (see [`Element::evaluate_about`]): the nodal dofs of the
    /// last evaluation with a tangent, or of the last converged state at the start of a step;
    /// empty: every tangent is the exact derivative at its iterate.
    reference: Vec<f64>,
    /// The nodal dofs of the last evaluation (the converged state's at a checkpoint).
    last_u: Vec<f64>,
    /// The nodal dofs of the last converged state.
    converged_u: Vec<f64>,
    /// Newton's tangent from the stresses linearised about the last iterate
    /// ([`Element::evaluate_about`]: the mixed-integration-point Newton iteration); false (the
    /// default): every tangent is the exact derivative of the residual at its iterate.
    pub mixed_tangent: bool,
    /// With a share: this process's contact forces at the last evaluation (over all dofs, the
    /// force-driven punches' too), kept apart from the internal forces until they are summed.
    contact_force: Vec<f64>,
    /// With a share: a failed reduction in a step that cannot return it (an active-set update, a
    /// checkpoint), returned by the next evaluation.
    pending: Option<StampError>,
    /// The pattern is built (at the first evaluation, after a share is set: a shared model never
    /// holds the whole model's pattern, 8 bytes per entry).
    pattern_ready: bool,
    /// The preconditioner was asked for ([`NonlinearProblem::want_preconditioner`]): its values
    /// are sized with the pattern.
    wants_preconditioner: bool,
}

impl<E: Element> Model<E> {
    /// Check the connectivity and build the element colouring; the sparse pattern is built at the
    /// first evaluation ([`NonlinearProblem::evaluate`]), after a share is set if one is.
    pub fn new(element: E, dofs: DofMap) -> Result<Self> {
        if element.dofs_per_node() != dofs.dofs_per_node() {
            return Err(StampError::Problem(format!(
                "the element has {} dofs per node, the dof map {}",
                element.dofs_per_node(),
                dofs.dofs_per_node()
            )));
        }
        if dofs.num_equations() == 0 {
            return Err(StampError::Problem("every dof is prescribed: nothing to solve".into()));
        }
        SparsePattern::check_elements(dofs.num_nodes(), element.num_elements(), element.nodes_per_element(), |e| element.element_nodes(e).to_vec())?;
        let assembler = Assembler::new(&element, dofs.num_nodes());
        Ok(Model {
            force: vec![0.0; dofs.num_dofs()],
            values: Vec::new(),
            preconditioner: Vec::new(),
            residual: vec![0.0; dofs.num_equations()],
            element,
            dofs,
            loads: Vec::new(),
            path_loads: Vec::new(),
            load_paths: Vec::new(),
            follower_paths: Vec::new(),
            contacts: Vec::new(),
            follower_loads: Vec::new(),
            follower_force: Vec::new(),
            augmented_tolerance: None,
            pattern: SparsePattern::empty(),
            border: Vec::new(),
            coupled: Vec::new(),
            assembler,
            energy: 0.0,
            saved: Vec::new(),
            last_scale: 0.0,
            peak_scale: 0.0,
            timings: ModelTimings::default(),
            share: None,
            pattern_elements: None,
            reference: Vec::new(),
            last_u: Vec::new(),
            converged_u: Vec::new(),
            mixed_tangent: false,
            contact_force: Vec::new(),
            pending: None,
            pattern_ready: false,
            wants_preconditioner: false,
        })
    }

    /// Add a nodal force (value at load factor 1) on a dof.
    pub fn add_load(&mut self, dof: usize, value: f64) -> Result<()> {
        if dof >= self.dofs.num_dofs() || !value.is_finite() {
            return Err(StampError::Problem(format!("invalid load {value} on dof {dof}")));
        }
        self.loads.push((dof, value));
        Ok(())
    }

    /// A path loads may follow ([`Model::add_load_along`], [`Model::add_follower_load_along`]);
    /// its index.
    pub fn add_load_path(&mut self, path: FactorPath) -> usize {
        if let Some(k) = self.load_paths.iter().position(|p| *p == path) {
            return k;
        }
        self.load_paths.push(path);
        self.load_paths.len() - 1
    }

    /// Add a nodal force `value` times the factor of `path` (from [`Model::add_load_path`]) at
    /// each load factor.
    pub fn add_load_along(&mut self, dof: usize, value: f64, path: usize) -> Result<()> {
        if dof >= self.dofs.num_dofs() || !value.is_finite() || path >= self.load_paths.len() {
            return Err(StampError::Problem(format!("invalid load {value} on dof {dof} along path {path}")));
        }
        self.path_loads.push((dof, value, path));
        Ok(())
    }

    /// The factor of a load on `path` (None: the load factor itself) at load factor `t`.
    pub fn load_factor_of(&self, path: Option<usize>, t: f64) -> f64 {
        path.map_or(t, |k| self.load_paths[k].at(t))
    }

    /// Every nodal dead load at load factor `t`: (dof, force), those of `loads` times t and those
    /// of `path_loads` times their path's factor.
    pub fn dead_loads(&self, t: f64) -> impl Iterator<Item = (usize, f64)> + '_ {
        let on_paths = self.path_loads.iter().map(move |&(d, v, k)| (d, self.load_paths[k].at(t) * v));
        self.loads.iter().map(move |&(d, v)| (d, t * v)).chain(on_paths)
    }

    /// Internal + contact forces over all nodal dofs at the last evaluation; at prescribed dofs
    /// these are the support reactions (plus any load applied there): the force the support exerts
    /// on the body.
    pub fn nodal_forces(&self) -> &[f64] {
        &self.force[..self.dofs.num_dofs()]
    }

    /// Add a displacement-dependent load (at load factor 1).
    pub fn add_follower_load(&mut self, load: Box<dyn DeformationDependentLoad>) {
        self.follower_paths.resize(self.follower_loads.len(), None);
        self.follower_loads.push(load);
        self.follower_paths.push(None);
        self.share_loads();
    }

    /// Add a displacement-dependent load scaled by the factor of `path` (from
    /// [`Model::add_load_path`]) instead of the load factor.
    pub fn add_follower_load_along(&mut self, load: Box<dyn DeformationDependentLoad>, path: usize) -> Result<()> {
        if path >= self.load_paths.len() {
            return Err(StampError::Problem(format!("no load path {path} (the model has {})", self.load_paths.len())));
        }
        self.add_follower_load(load);
        if let Some(p) = self.follower_paths.last_mut() {
            *p = Some(path);
        }
        Ok(())
    }

    /// The displacement-dependent loads' force over all nodal dofs at the last evaluation, at its
    /// load factor (empty when there are none): the external force they apply, including at
    /// prescribed dofs, where [`Model::nodal_forces`] does not count it.
    pub fn follower_forces(&self) -> &[f64] {
        &self.follower_force
    }

    /// Add a punch; a force-driven one gets its unknown (after the nodal dofs and the earlier
    /// force-driven punches) and borders the pattern. Pushing onto `contacts` directly works too:
    /// the model catches up at the next evaluation, but [`NonlinearProblem::num_dofs`] and
    /// `num_equations` count the punches at once.
    pub fn add_contact(&mut self, pair: ContactPair) {
        self.contacts.push(pair);
        self.share_loads();
        self.number_drives();
    }

    /// Give the punches and the displacement-dependent loads this process's share (see
    /// [`crate::share`]): each evaluates the points and pieces at its own nodes.
    fn share_loads(&mut self) {
        let own = self.share.as_ref().map(|s| (s.owned_nodes.as_slice(), s.reduce.clone(), s.leader));
        for c in self.contacts.iter_mut() {
            c.set_share(own.clone());
        }
        for l in self.follower_loads.iter_mut() {
            l.share_nodes(own.as_ref().map(|o| o.0));
        }
    }

    /// Number of force-driven punches (extra unknowns).
    pub fn num_drives(&self) -> usize {
        self.contacts.iter().filter(|c| c.drive.is_some()).count()
    }

    /// Number each force-driven punch's unknown (after the nodal dofs) and size the force and
    /// residual vectors for them; the signature (index in `contacts`, points) of each.
    fn number_drives(&mut self) -> Vec<(usize, usize)> {
        let nd = self.dofs.num_dofs();
        let mut sig = Vec::new();
        for (i, c) in self.contacts.iter_mut().enumerate() {
            if let Some(f) = c.drive.as_mut() {
                f.dof = nd + sig.len();
                sig.push((i, c.points.len()));
            }
        }
        self.force.resize(nd + sig.len(), 0.0);
        self.residual.resize(self.dofs.num_equations() + sig.len(), 0.0);
        sig
    }

    /// Number each force-driven punch's unknown and border the pattern for them (when they
    /// changed), and couple the nodes of the integrated punches' patches in it; the pattern is
    /// built here the first time.
    fn sync_drives(&mut self) {
        let coupled: Vec<(usize, u64)> = self.contacts.iter().enumerate().filter(|(_, c)| c.face().is_some()).map(|(i, c)| (i, c.coupling_version())).collect();
        if coupled != self.coupled || !self.pattern_ready {
            self.coupled = coupled;
            self.rebuild_pattern();
        }
        let sig = self.number_drives();
        if sig == self.border {
            return;
        }
        // the nodal pattern: the present one, without its border if it has one
        let unbordered = (!self.border.is_empty()).then(|| self.pattern.unbordered(self.dofs.num_equations()));
        if sig.is_empty() {
            if let Some(nodal) = unbordered {
                self.pattern = nodal;
            }
        } else {
            let border: Vec<Vec<usize>> = sig.iter().map(|&(i, _)| self.contacts[i].points.iter().flat_map(|p| p.dofs).collect()).collect();
            self.pattern = unbordered.as_ref().unwrap_or(&self.pattern).bordered(&self.dofs, &border);
        }
        self.border = sig;
        self.size_values();
    }

    /// The value arrays sized to the pattern (the preconditioner's if it was asked for).
    fn size_values(&mut self) {
        self.values = vec![0.0; self.pattern.nnz()];
        self.preconditioner = if self.wants_preconditioner && self.element.has_preconditioner() { vec![0.0; self.pattern.nnz()] } else { Vec::new() };
    }

    /// Build the nodal pattern again (the elements of [`pattern_elements`](Self::pattern_elements)
    /// and the integrated punches' couplings of `coupled`); the border follows in
    /// [`sync_drives`](Self::sync_drives), and the values are sized anew.
    fn rebuild_pattern(&mut self) {
        let groups: Vec<Vec<usize>> = self.coupled.iter().flat_map(|&(i, _)| self.contacts[i].coupled_nodes()).collect();
        let element = &self.element;
        let nodes = |e: usize| element.element_nodes(e).to_vec();
        let (ne, npe) = (element.num_elements(), element.nodes_per_element());
        let nodal = match &self.pattern_elements {
            None => SparsePattern::coupled(&self.dofs, ne, npe, nodes, &groups),
            Some(subset) => SparsePattern::coupled_subset(&self.dofs, ne, npe, nodes, &groups, subset),
        }
        .expect("the connectivity was checked (Model::new); contact points are nodes of the model");
        self.pattern = nodal;
        self.pattern_ready = true;
        // border again in sync_drives, and size the values
        self.border.clear();
        self.size_values();
    }

    /// Strain energy at the last evaluation.
    pub fn energy(&self) -> f64 {
        self.energy
    }

    /// The sparsity pattern (empty before the first evaluation).
    pub fn pattern(&self) -> &SparsePattern {
        &self.pattern
    }

    /// Evaluate only this process's share of the model from now on (see [`crate::share`]: its
    /// elements, and the contact and displacement-dependent-load tangent rows of its nodes, with
    /// the forces and energy summed over the processes); None: the whole model again. The
    /// sparse pattern and its value arrays, built at the next evaluation, hold the share's
    /// entries: those of its own elements and the whole rows of its own nodes (every element
    /// around them), the rows and columns of the force-driven punches whole.
    pub fn set_share(&mut self, share: Option<Share>) -> Result<()> {
        let (ne, nn) = (self.element.num_elements(), self.dofs.num_nodes());
        self.assembler = match &share {
            Some(s) => {
                if s.elements.windows(2).any(|w| w[0] >= w[1]) || s.elements.last().is_some_and(|&e| e >= ne) {
                    return Err(StampError::Problem(format!("a share's elements must ascend below {ne}")));
                }
                if s.owned_nodes.len() != nn {
                    return Err(StampError::Problem(format!("a share owns {} nodes of a model of {nn}", s.owned_nodes.len())));
                }
                Assembler::for_elements(&self.element, nn, s.elements.clone())
            }
            None => Assembler::new(&self.element, nn),
        };
        self.pattern_elements = share.as_ref().map(|s| {
            let mut taken = vec![false; ne];
            s.elements.iter().for_each(|&e| taken[e] = true);
            for (e, t) in taken.iter_mut().enumerate() {
                *t = *t || self.element.element_nodes(e).iter().any(|&n| s.owned_nodes[n]);
            }
            taken
        });
        self.share = share;
        self.share_loads();
        // the share's pattern is built at the next evaluation
        self.pattern = SparsePattern::empty();
        self.pattern_ready = false;
        self.border.clear();
        self.values = Vec::new();
        self.preconditioner = Vec::new();
        Ok(())
    }

    /// Number of element colours of the parallel assembly.
    pub fn num_colors(&self) -> usize {
        self.assembler.num_colors()
    }
}

impl<E: Element> Model<E> {
    /// The augmented-Lagrangian update (lambda_bar <- lambda, [`ContactPair::augment`]) of every
    /// punch whose constraints at the last evaluation are violated beyond
    /// [`augmented_tolerance`](Self::augmented_tolerance): a penetration above it, or an active
    /// point whose multiplier lambda_bar holds it off the punch (a gap) by more. True when any was
    /// updated (the residual changed); false without a tolerance. With a share the violations are
    /// the largest over the processes (collective).
    fn augment_violated(&mut self) -> bool {
        let Some(tol) = self.augmented_tolerance else { return false };
        let mut violation: Vec<f64> = self.contacts.iter().map(|c| c.constraint_violation()).collect();
        if let Some(share) = &self.share {
            if let Err(e) = share.reduce.max_f64(&mut violation) {
                self.pending.get_or_insert(e);
                return true;
            }
        }
        let mut again = false;
        for (c, v) in self.contacts.iter_mut().zip(violation) {
            if v > tol {
                c.augment();
                again = true;
            }
        }
        again
    }

    /// Sum a force-driven punch's row and column of the tangent and the preconditioner over the
    /// processes (each added the part of its own points).
    fn sum_border(&mut self) -> Result<()> {
        let Some(share) = &self.share else { return Ok(()) };
        let neq = self.dofs.num_equations();
        let sym = self.pattern.symbolic();
        let (col_ptr, row_idx) = (sym.col_ptr(), sym.row_idx());
        let mut slots = Vec::new();
        for b in neq..neq + self.border.len() {
            for (s, &r) in row_idx.iter().enumerate().take(col_ptr[b + 1]).skip(col_ptr[b]) {
                slots.push(s);
                if r != b {
                    slots.extend(self.pattern.find(b, r));
                }
            }
        }
        let with_p = !self.preconditioner.is_empty();
        let mut buf: Vec<f64> = slots.iter().map(|&s| self.values[s]).collect();
        if with_p {
            buf.extend(slots.iter().map(|&s| self.preconditioner[s]));
        }
        share.reduce.sum(&mut buf)?;
        for (k, &s) in slots.iter().enumerate() {
            self.values[s] = buf[k];
            if with_p {
                self.preconditioner[s] = buf[slots.len() + k];
            }
        }
        Ok(())
    }
}

/// The equation of dof `d`: a nodal dof's (None where it is prescribed), or a force-driven
/// punch's unknown (dofs from `dofs.num_dofs()` on) after the nodal equations.
fn equation_of(dofs: &DofMap, d: usize) -> Option<usize> {
    let nd = dofs.num_dofs();
    if d < nd { dofs.equation(d) } else { Some(dofs.num_equations() + d - nd) }
}

/// Whether this process adds the tangent entry (row dof r, column dof c) of a contact or
/// displacement-dependent load (all of them without a share): those of the rows of its own nodes,
/// of a force-driven punch's row (dofs from `nd` on) those of the columns of its own nodes, and
/// the punch's own entry (the contact adds its part of it). The punch's row and column are summed
/// over the processes afterwards ([`Model::sum_border`]): the bordered solver reads them whole.
fn owns_row(share: &Option<Share>, dofs_per_node: usize, nd: usize) -> impl Fn(usize, usize) -> bool + '_ {
    move |r, c| {
        let node = if r < nd { r } else if c < nd { c } else { return true };
        share.as_ref().is_none_or(|s| s.owned_nodes[node / dofs_per_node])
    }
}

impl<E: Element> Model<E> {
    /// [`Element::commit`] on every element this model evaluates, at the last evaluation's state
    /// (the last evaluation is the whole model's on every process: see [`crate::share`]).
    fn commit_elements(&mut self) {
        if !self.element.has_history() || self.last_u.is_empty() {
            return;
        }
        let dpn = self.dofs.dofs_per_node();
        let mut ws = self.element.new_workspace();
        let mut local = vec![0.0; dpn * self.element.nodes_per_element()];
        // the process that writes the outputs (a share's leader, which keeps every element)
        // commits every element, so that it writes every point's state; the others their own
        let every: Vec<usize>;
        let elements = match &self.share {
            Some(s) if s.leader => {
                every = (0..self.element.num_elements()).collect();
                &every[..]
            }
            _ => self.assembler.elements(),
        };
        for &e in elements {
            for (a, &n) in self.element.element_nodes(e).iter().enumerate() {
                local[a * dpn..(a + 1) * dpn].copy_from_slice(&self.last_u[n * dpn..(n + 1) * dpn]);
            }
            self.element.commit(e, &local, &mut ws);
        }
    }
}

impl<E: Element> NonlinearProblem for Model<E> {
    fn num_dofs(&self) -> usize {
        self.dofs.num_dofs() + self.num_drives()
    }
    fn num_equations(&self) -> usize {
        self.dofs.num_equations() + self.num_drives()
    }
    fn apply_prescribed(&self, u: &mut [f64], t: f64) {
        self.dofs.apply_prescribed(u, t);
    }

    fn evaluate(&mut self, u: &[f64], t: f64, with_tangent: bool) -> Result<Evaluation> {
        self.sync_drives();
        let nd = self.dofs.num_dofs();
        let neq = self.dofs.num_equations();
        if u.len() != nd + self.border.len() {
            return Err(StampError::Problem(format!("the unknown vector has {} entries, the model {} (nodal dofs and force-driven punches)", u.len(), nd + self.border.len())));
        }
        let start = Instant::now();
        let values = if with_tangent { Some(self.values.as_mut_slice()) } else { None };
        let preconditioner = if with_tangent && !self.preconditioner.is_empty() { Some(self.preconditioner.as_mut_slice()) } else { None };
        let reference = (with_tangent && self.mixed_tangent && self.reference.len() == nd).then_some(self.reference.as_slice());
        let (mut energy, mut refused) = self.assembler.assemble_elements(&self.element, &self.dofs, &self.pattern, u, reference, &mut self.force[..nd], values, preconditioner);
        if self.mixed_tangent {
            self.last_u.clear();
            self.last_u.extend_from_slice(&u[..nd]);
            if with_tangent {
                self.reference.clear();
                self.reference.extend_from_slice(&u[..nd]);
            }
        }
        if let Some(e) = self.pending.take() {
            return Err(e);
        }
        if let Some(share) = &self.share {
            // the lowest refusing element of any process (the forces are summed with the
            // contact forces below)
            let mut r = [refused as u64];
            share.reduce.min(&mut r)?;
            refused = usize::try_from(r[0]).unwrap_or(usize::MAX);
        }
        if refused != usize::MAX {
            if let Some(share) = &self.share {
                // the element's own process says why: the others may not hold its data
                let mine = share.elements.binary_search(&refused).is_ok().then(|| Assembler::refusal_reason(&self.element, &self.dofs, u, refused));
                let reason = share.reduce.text(mine.as_deref())?;
                return Err(StampError::Inadmissible { element: refused, reason });
            }
            return Err(Assembler::refusal(&self.element, &self.dofs, u, refused));
        }
        self.force[nd..].fill(0.0);
        // with a share: this process's part (the forces are summed below)
        let mut internal_norm = self.force.iter().map(|x| x * x).sum::<f64>().sqrt();
        let t_contact = Instant::now();
        self.timings.assembly += (t_contact - start).as_secs_f64();
        self.timings.assemblies += 1;
        let mut changes = 0;
        let mut contact_sq = 0.0;
        let mut ext_sq = 0.0;
        let shared = self.share.is_some();
        if shared {
            // this process's contact forces apart from its internal ones (see below)
            self.contact_force.clear();
            self.contact_force.resize(self.force.len(), 0.0);
        }
        {
            let pattern = &self.pattern;
            let dofs = &self.dofs;
            let values = &mut self.values;
            let preconditioner = &mut self.preconditioner;
            let force = if shared { &mut self.contact_force } else { &mut self.force };
            let eq = |d: usize| equation_of(dofs, d);
            let mine = owns_row(&self.share, dofs.dofs_per_node(), nd);
            for pair in self.contacts.iter_mut() {
                {
                    // the contact stiffness is symmetric: it belongs to the preconditioner as it is
                    let mut add = |r: usize, c: usize, v: f64| {
                        if !mine(r, c) {
                            return;
                        }
                        if let (Some(re), Some(ce)) = (eq(r), eq(c)) {
                            if let Some(s) = pattern.find(re, ce) {
                                values[s] += v;
                                if let Some(p) = preconditioner.get_mut(s) {
                                    *p += v;
                                }
                            }
                        }
                    };
                    changes += if with_tangent { pair.evaluate(u, t, force, Some(&mut add))? } else { pair.evaluate(u, t, force, None)? };
                }
                if with_tangent {
                    // friction's tangent is not symmetric: the preconditioner gets a symmetric
                    // stand-in (see stamp::contact::PointFriction). With a share the pair lists
                    // only this process's entries: the rows of its own points and its part of a
                    // force-driven punch's row (summed in sum_border)
                    for &(r, c, v, pv) in pair.friction_entries() {
                        if let (Some(re), Some(ce)) = (eq(r), eq(c)) {
                            if let Some(s) = pattern.find(re, ce) {
                                values[s] += v;
                                if let Some(p) = preconditioner.get_mut(s) {
                                    *p += pv;
                                }
                            }
                        }
                    }
                }
                // an integrated punch whose contact reached points the pattern does not couple:
                // couple them from the next evaluation on (this tangent lacks those entries)
                if pair.needs_coupling() {
                    pair.extend_coupling();
                }
                contact_sq += if shared { pair.force_norm_squared() } else { pair.force_norm().powi(2) };
                if let Some(f) = &pair.drive {
                    ext_sq += (t * f.force).powi(2);
                }
            }
        }
        if !self.follower_loads.is_empty() {
            // each load's factor: t, or its path's (the loads on the load factor alone are summed
            // first and scaled once, as before paths)
            let scales: Vec<f64> = (0..self.follower_loads.len()).map(|k| self.load_factor_of(self.follower_paths.get(k).copied().flatten(), t)).collect();
            let on_paths = self.follower_paths.iter().any(|p| p.is_some());
            self.follower_force.clear();
            self.follower_force.resize(nd, 0.0);
            let mut own = if on_paths { vec![0.0; nd] } else { Vec::new() };
            let pattern = &self.pattern;
            let dofs = &self.dofs;
            let values = &mut self.values;
            let mine = owns_row(&self.share, dofs.dofs_per_node(), nd);
            for (k, load) in self.follower_loads.iter().enumerate() {
                let scale = scales[k];
                // R gets -s F, K gets -s dF/du (not symmetric: kept out of the preconditioner)
                let mut add = |r: usize, c: usize, v: f64| {
                    if !mine(r, c) {
                        return;
                    }
                    if let (Some(re), Some(ce)) = (dofs.equation(r), dofs.equation(c)) {
                        if let Some(s) = pattern.find(re, ce) {
                            values[s] -= scale * v;
                        }
                    }
                };
                let target = if on_paths { &mut own } else { &mut self.follower_force };
                if with_tangent {
                    load.add_force_and_stiffness(&u[..nd], target, Some(&mut add));
                } else {
                    load.add_force_and_stiffness(&u[..nd], target, None);
                }
                if on_paths {
                    for (f, o) in self.follower_force.iter_mut().zip(own.iter_mut()) {
                        *f += scale * *o;
                        *o = 0.0;
                    }
                }
            }
            if !on_paths {
                for f in self.follower_force.iter_mut() {
                    *f *= t;
                }
            }
            if let Some(share) = &self.share {
                // this process's own nodes' forces, then every process's
                let dpn = self.dofs.dofs_per_node();
                for (d, f) in self.follower_force.iter_mut().enumerate() {
                    if !share.owned_nodes[d / dpn] {
                        *f = 0.0;
                    }
                }
                share.reduce.sum(&mut self.follower_force)?;
            }
            ext_sq += self.follower_force.iter().map(|x| x * x).sum::<f64>();
        }
        if let Some(share) = &self.share {
            // The whole model's forces: the internal forces of every process's elements and the
            // contact forces of every process's points, in one sum. The internal forces' norm is
            // the sum over the processes of their own nodes' part (no other process adds contact
            // forces there); the contact forces' likewise.
            for (f, c) in self.force.iter_mut().zip(&self.contact_force) {
                *f += c;
            }
            share.reduce.sum(&mut self.force)?;
            let dpn = self.dofs.dofs_per_node();
            let own_internal: f64 = (0..nd).filter(|&d| share.owned_nodes[d / dpn]).map(|d| (self.force[d] - self.contact_force[d]).powi(2)).sum();
            let mut scalars = [energy, own_internal, contact_sq];
            share.reduce.sum(&mut scalars)?;
            [energy, internal_norm, contact_sq] = [scalars[0], scalars[1].sqrt(), scalars[2]];
            if with_tangent && !self.border.is_empty() {
                self.sum_border()?;
            }
        }
        self.energy = energy;
        self.timings.contact += t_contact.elapsed().as_secs_f64();
        self.dofs.gather(&self.force[..nd], &mut self.residual[..neq]);
        for (d, &f) in self.follower_force.iter().enumerate() {
            if f != 0.0 {
                if let Some(e) = self.dofs.equation(d) {
                    self.residual[e] -= f;
                }
            }
        }
        for k in 0..self.border.len() {
            self.residual[neq + k] = self.force[nd + k];
        }
        let on_paths = self.path_loads.iter().map(|&(d, v, k)| (d, self.load_paths[k].at(t) * v));
        for (d, f) in self.loads.iter().map(|&(d, v)| (d, t * v)).chain(on_paths) {
            ext_sq += f * f;
            if let Some(e) = self.dofs.equation(d) {
                self.residual[e] -= f;
            }
        }
        let norm = self.residual.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !norm.is_finite() {
            return Err(StampError::NonFinite(format!("the residual at load factor {t} is not finite (element or contact produced NaN)")));
        }
        // The internal forces carry a round-off that does not vanish with the load (Green-Lagrange
        // strains from positions): back at zero load the forces in play would be that round-off
        // alone. So the scale never drops below 1e-3 of the largest converged one (a tolerance of
        // rel_tol * 1e-3 of the peak forces: no loosening that matters).
        let scale = internal_norm.max(ext_sq.sqrt()).max(contact_sq.sqrt()).max(1e-3 * self.peak_scale);
        self.last_scale = scale;
        Ok(Evaluation { residual_norm: norm, force_scale: scale, active_changes: changes })
    }

    fn residual(&self) -> &[f64] {
        &self.residual
    }
    fn matrix(&self) -> SparseColMatRef<'_, usize, f64> {
        self.pattern.matrix(&self.values)
    }
    fn preconditioner(&self) -> Option<SparseColMatRef<'_, usize, f64>> {
        (!self.preconditioner.is_empty()).then(|| self.pattern.matrix(&self.preconditioner))
    }
    /// Allocates (or frees) the preconditioner's values; the element must have one.
    fn want_preconditioner(&mut self, on: bool) {
        self.wants_preconditioner = on;
        let on = on && self.element.has_preconditioner();
        if self.pattern_ready && on == self.preconditioner.is_empty() {
            self.preconditioner = if on { vec![0.0; self.pattern.nnz()] } else { Vec::new() };
        }
    }
    fn add_increment(&self, u: &mut [f64], du: &[f64]) {
        self.dofs.add_increment(u, du);
        let (nd, neq) = (self.dofs.num_dofs(), self.dofs.num_equations());
        for k in 0..self.num_drives() {
            u[nd + k] += du[neq + k];
        }
    }
    /// The contact points of every pair, their coefficients renumbered from dofs to equations
    /// (a prescribed dof's dropped); with a share every point's, from its owner (collective).
    fn constraint_rows(&self) -> Result<Vec<crate::linearised_contact::ConstraintRow>> {
        let mut out = Vec::new();
        for (pi, pair) in self.contacts.iter().enumerate() {
            for mut row in pair.linearised_rows()? {
                row.coef = row.coef.iter().filter_map(|&(d, c)| equation_of(&self.dofs, d).map(|e| (e, c))).collect();
                row.id.0 = pi;
                out.push(row);
            }
        }
        Ok(out)
    }
    fn set_constraint_state(&mut self, id: (usize, usize), active: bool) {
        self.contacts[id.0].set_linearised_state(id.1, active);
    }
    fn update_active_set(&mut self) -> usize {
        let mut changes = 0;
        for c in self.contacts.iter_mut() {
            match c.update_active_set() {
                Ok(n) => changes += n,
                // a failed reduction: the next evaluation returns it
                Err(e) => {
                    self.pending.get_or_insert(e);
                    changes += 1;
                }
            }
        }
        changes
    }
    fn start_step(&mut self, predicted: bool) {
        self.reference.clone_from(&self.converged_u);
        for c in self.contacts.iter_mut() {
            c.start_step(predicted);
        }
    }
    /// The augmented-Lagrangian update of [`end_step`](Self::end_step), at the last evaluation's
    /// iterate (Newton calls it before it converged, see [`crate::nonlinear::NewtonSettings::multiplier_tol`]).
    fn update_multipliers(&mut self) -> bool {
        self.augment_violated()
    }
    fn end_step(&mut self, _u: &[f64], _t: f64) -> bool {
        self.augment_violated()
    }
    fn path_corners(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self.contacts.iter().flat_map(|c| c.motion.corners().into_iter().chain(c.rotation.iter().flat_map(|r| r.corners()))).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    }
    fn checkpoint(&mut self) {
        // called after a converged step (and once before the first): its last evaluation is the
        // converged state's
        self.peak_scale = self.peak_scale.max(self.last_scale);
        self.converged_u.clone_from(&self.last_u);
        // path-dependent elements (plasticity): the converged state becomes their history
        self.commit_elements();
        // with a share: every point's state whole on every process (the outputs read it)
        for c in self.contacts.iter_mut() {
            if let Err(e) = c.gather_state() {
                self.pending.get_or_insert(e);
            }
        }
        // friction: the slipping points' anchors follow their slip
        for c in self.contacts.iter_mut() {
            c.commit_friction();
        }
        self.saved = self.contacts.iter().map(|c| (c.lambda_bar.clone(), c.state.clone(), c.last_active.clone(), c.friction.clone())).collect();
    }
    fn restore(&mut self) {
        for (c, (lb, st, la, fr)) in self.contacts.iter_mut().zip(&self.saved) {
            c.lambda_bar.clone_from(lb);
            c.state.clone_from(st);
            c.last_active.clone_from(la);
            c.friction.clone_from(fr);
        }
    }
}

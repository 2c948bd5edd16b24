//! The reaction of each support: per `[[boundary]]` group, the force that the group's held
//! components (`fix` and `prescribe`) exert on the plate, in global axes, written per converged
//! step as summary.json's `support_reactions` and history.csv's `<group>_reaction_x1`, `_x2`, `_x3`.
//!
//! At a held dof d the support's force on the plate is what balances the plate there:
//! r_d = f_int,d + f_contact,d - t f_ext,d - t F_d(u), the internal and contact forces of the last
//! evaluation ([`Model::nodal_forces`], the converged state's after a step) less the dead loads and
//! the displacement-dependent (follower) loads applied at d. Every unknown of the plate is a
//! displacement of one surface along a global axis (component c of surface s is dof 3 s + c of its
//! node), so r_d adds to the x1, x2 or x3 component of the group's reaction; for a plate of 3 to 5
//! surfaces (and for layers) that is every surface's held components at the group's nodes.
//!
//! Conventions:
//! * A group that holds only some directions (`simply_supported`: v3- and v3+) has reactions along
//!   those only; the other components are exactly 0.
//! * Several `[[boundary]]` tables on one group are one support: the union of their held dofs.
//! * A dof held by two groups (the corner node of two clamped edges) is counted in each group
//!   that holds it: a group's reaction is the force through its own nodes, as a node set's sum of
//!   reaction forces is in other codes, and the groups' reactions add up to the total (summary.json's
//!   `support_reaction`, each held dof once) only when no dof is held twice.
//! * `[plate] plane_strain = true` holds v1 at every node without a group: those reactions are in
//!   the total `support_reaction` only.
//!
//! Under MPI the nodal forces are summed over the ranks in every evaluation (see
//! [`stamp::model::Model::set_share`]) and the loads are whole on every rank, so every rank computes
//! the one-process reactions.

use crate::model::plate_model::Plate;
use stamp::model::Model;

/// One support: a `[[boundary]]` group and the dofs it holds.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportGroup {
    /// The group's name as the problem file gives it.
    pub name: String,
    /// The held dofs, ascending, each once.
    pub dofs: Vec<usize>,
}

/// The supports of a model, in the order of their first `[[boundary]]` table.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Supports {
    pub groups: Vec<SupportGroup>,
}

impl Supports {
    /// Add the dofs that `name` holds (to the group's earlier ones, if it has a support already).
    pub fn hold(&mut self, name: &str, dofs: impl IntoIterator<Item = usize>) {
        let i = match self.groups.iter().position(|g| g.name == name) {
            Some(i) => i,
            None => {
                self.groups.push(SupportGroup { name: name.to_string(), dofs: Vec::new() });
                self.groups.len() - 1
            }
        };
        let g = &mut self.groups[i];
        g.dofs.extend(dofs);
        g.dofs.sort_unstable();
        g.dofs.dedup();
    }

    /// The groups' names, in order.
    pub fn names(&self) -> Vec<String> {
        self.groups.iter().map(|g| g.name.clone()).collect()
    }

    /// Each group's reaction [f1, f2, f3] at the model's last evaluation, at load factor `t`
    /// (the factor of the dead loads; the follower loads' force is the evaluation's own).
    pub fn reactions(&self, model: &Model<Plate>, t: f64) -> Vec<[f64; 3]> {
        let dpn = model.dofs.dofs_per_node();
        let force = model.nodal_forces();
        let follower = model.follower_forces();
        self.groups
            .iter()
            .map(|g| {
                let mut r = [0.0; 3];
                for &d in &g.dofs {
                    r[(d % dpn) % 3] += force[d] - follower.get(d).copied().unwrap_or(0.0);
                }
                for (d, f) in model.dead_loads(t) {
                    if g.dofs.binary_search(&d).is_ok() {
                        r[(d % dpn) % 3] -= f;
                    }
                }
                r
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_group_named_twice_is_one_support_with_each_dof_once() {
        let mut s = Supports::default();
        s.hold("left", [12, 2, 8]);
        s.hold("edge", [8, 9]);
        s.hold("left", [2, 5]);
        assert_eq!(s.names(), ["left", "edge"]);
        assert_eq!(s.groups[0].dofs, [2, 5, 8, 12]);
        assert_eq!(s.groups[1].dofs, [8, 9]);
    }
}

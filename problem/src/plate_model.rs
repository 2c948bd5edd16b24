//! The plate model a problem file chooses (`[plate] surfaces`): the paper's two-surface plate or a
//! plate of three to five surfaces through the thickness, plug-ins of the elements crate, behind
//! one [`Element`] for the rest of the run, with where each keeps its surfaces' displacements
//! among the unknowns ([`Layout`]).

use stamp::element::{Element, LocalSystem};
use stamp::mesh::QuadMesh;
use stamp::Result;
use stamp_elements::multi_surface::{lagrange, surface_zetas, MultiSurfaceWorkspace, Resultants};
use stamp_elements::plate::PlateWorkspace;
use stamp_elements::{FiveSurfacePlate, FourSurfacePlate, Kinematics, PlateElements, Section, ThreeSurfacePlate};
use stamp_elements::Face;

/// The plate elements of a run.
pub enum Plate {
    /// The paper's plate: the displacements of the two face planes, linear through the thickness.
    TwoSurface(PlateElements),
    /// Faces and mid-plane: quadratic through the thickness, the full 3D law.
    ThreeSurface(ThreeSurfacePlate),
    /// Faces and two inner surfaces: cubic through the thickness.
    FourSurface(FourSurfacePlate),
    /// Faces and three inner surfaces: quartic through the thickness.
    FiveSurface(FiveSurfacePlate),
}

/// The workspace of any of them.
pub enum PlateWs {
    TwoSurface(PlateWorkspace),
    ThreeSurface(MultiSurfaceWorkspace<12, 36>),
    FourSurface(MultiSurfaceWorkspace<16, 48>),
    FiveSurface(MultiSurfaceWorkspace<20, 60>),
}

/// Dispatch `$body` on the plate's variant with the element bound to `$p`.
macro_rules! each {
    ($plate:expr, $p:ident => $body:expr) => {
        match $plate {
            Plate::TwoSurface($p) => $body,
            Plate::ThreeSurface($p) => $body,
            Plate::FourSurface($p) => $body,
            Plate::FiveSurface($p) => $body,
        }
    };
}

impl Plate {
    /// The plate of `surfaces` surfaces (2 to 5) on `mesh`.
    pub fn new(surfaces: usize, mesh: &QuadMesh, section: Section, kinematics: Kinematics) -> Result<Plate> {
        Ok(match surfaces {
            2 => Plate::TwoSurface(PlateElements::new(mesh, section, kinematics)?),
            3 => Plate::ThreeSurface(ThreeSurfacePlate::new(mesh, section, kinematics)?),
            4 => Plate::FourSurface(FourSurfacePlate::new(mesh, section, kinematics)?),
            5 => Plate::FiveSurface(FiveSurfacePlate::new(mesh, section, kinematics)?),
            n => return Err(stamp::StampError::Material(format!("a plate has 2 to 5 surfaces, not {n}"))),
        })
    }
    /// Surfaces through the thickness.
    pub fn surfaces(&self) -> usize {
        Element::dofs_per_node(self) / 3
    }
    /// The section's resultants at the centre of element `e` at the local dofs `v` (the mean over
    /// its Gauss points): membrane forces, moments about the mid-plane, shear forces and T33. The
    /// paper's plate gives them from its face resultants T- and T+ (eq. 2.7), the others by
    /// integrating the stresses through the thickness.
    pub fn centre_resultants(&self, e: usize, v: &[f64], ws: &mut PlateWs) -> Resultants {
        match (self, ws) {
            (Plate::TwoSurface(p), PlateWs::TwoSurface(w)) => {
                let gs = p.gauss_state(e, v, w);
                let mut t = [0.0; 11];
                for g in 0..4 {
                    for r in 0..11 {
                        t[r] += 0.25 * gs.resultant[g][r];
                    }
                }
                let half_h = 0.5 * p.section().thickness();
                Resultants {
                    n: [t[0] + t[1], t[2] + t[3], t[4] + t[5]],
                    m: [half_h * (t[1] - t[0]), half_h * (t[3] - t[2]), half_h * (t[5] - t[4])],
                    q: [t[6] + t[7], t[8] + t[9]],
                    t33: t[10],
                }
            }
            (Plate::ThreeSurface(p), PlateWs::ThreeSurface(w)) => p.resultants(e, v, w),
            (Plate::FourSurface(p), PlateWs::FourSurface(w)) => p.resultants(e, v, w),
            (Plate::FiveSurface(p), PlateWs::FiveSurface(w)) => p.resultants(e, v, w),
            _ => unreachable!("a workspace is made by its own plate"),
        }
    }
}

/// Where the surfaces' displacements are among the unknowns: per node, the faces S- and S+ first
/// (three components each), then the inner surfaces from the bottom up.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    pub surfaces: usize,
    pub dofs_per_node: usize,
    /// zeta in [-1, 1] of each surface, in the order of the unknowns.
    zetas: Vec<f64>,
    /// Weights of the surfaces' displacements in the mid-plane's (the Lagrange functions at zeta = 0).
    mid_weights: Vec<f64>,
}

impl Layout {
    pub fn new(surfaces: usize) -> Layout {
        let zetas = surface_zetas(surfaces);
        let mid_weights = lagrange(&zetas, 0.0).0;
        Layout { surfaces, dofs_per_node: 3 * surfaces, zetas, mid_weights }
    }
    pub fn of(plate: &Plate) -> Layout {
        Layout::new(plate.surfaces())
    }
    /// The paper's six unknowns per node.
    pub fn two_surface() -> Layout {
        Layout::new(2)
    }
    /// Global dof of component `comp` of `face` at `node`.
    pub fn face_dof(&self, face: Face, node: usize, comp: usize) -> usize {
        face.dof_in(self.dofs_per_node, node, comp)
    }
    /// Displacement of `face` at node `n`.
    pub fn face_displacement(&self, u: &[f64], n: usize, face: Face) -> [f64; 3] {
        [0, 1, 2].map(|c| u[self.face_dof(face, n, c)])
    }
    /// The mid-plane's displacement at node `n` as weights of its surfaces' unknowns: (dof, weight)
    /// per surface for component `comp` ((v- + v+)/2 in the paper's plate, the displacement
    /// interpolated at zeta = 0 in the others: the mid-plane's own unknowns with three surfaces).
    pub fn mid_terms(&self, node: usize, comp: usize) -> impl Iterator<Item = (usize, f64)> + '_ {
        self.mid_weights.iter().enumerate().filter(|(_, &w)| w != 0.0).map(move |(s, &w)| (node * self.dofs_per_node + 3 * s + comp, w))
    }
    /// Displacement of the mid-plane at node `n`.
    pub fn mid_displacement(&self, u: &[f64], n: usize) -> [f64; 3] {
        [0, 1, 2].map(|c| self.mid_terms(n, c).map(|(d, w)| w * u[d]).sum())
    }
    /// The displacements of every surface at node `n`, from the bottom face (zeta = -1) up to the
    /// top face (zeta = 1).
    pub fn surface_displacements(&self, u: &[f64], n: usize) -> Vec<[f64; 3]> {
        let mut order: Vec<usize> = (0..self.surfaces).collect();
        order.sort_by(|&a, &b| self.zetas[a].total_cmp(&self.zetas[b]));
        order.iter().map(|&s| [0, 1, 2].map(|c| u[n * self.dofs_per_node + 3 * s + c])).collect()
    }
    /// zeta in [-1, 1] of the surface that holds component `c` (0 .. dofs per node) of a node.
    pub fn zeta_of_component(&self, c: usize) -> f64 {
        self.zetas[c / 3]
    }
    /// The constrained components of a boundary word, extended to this plate: a word that holds a
    /// component on both faces (v1, symmetry_x1, simply_supported, clamped, ...) holds it on the
    /// inner surfaces too, i.e. on the whole fibre.
    pub fn fibre_components(&self, comps: &[usize]) -> Vec<usize> {
        let mut out = comps.to_vec();
        for c in 0..3 {
            if comps.contains(&c) && comps.contains(&(c + 3)) {
                out.extend((2..self.surfaces).map(|s| 3 * s + c));
            }
        }
        out
    }
}

impl Element for Plate {
    type Workspace = PlateWs;

    fn dofs_per_node(&self) -> usize {
        each!(self, p => p.dofs_per_node())
    }
    fn nodes_per_element(&self) -> usize {
        4
    }
    fn num_elements(&self) -> usize {
        each!(self, p => p.num_elements())
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        each!(self, p => p.element_nodes(e))
    }
    fn has_preconditioner(&self) -> bool {
        each!(self, p => p.has_preconditioner())
    }
    fn new_workspace(&self) -> PlateWs {
        match self {
            Plate::TwoSurface(p) => PlateWs::TwoSurface(p.new_workspace()),
            Plate::ThreeSurface(p) => PlateWs::ThreeSurface(p.new_workspace()),
            Plate::FourSurface(p) => PlateWs::FourSurface(p.new_workspace()),
            Plate::FiveSurface(p) => PlateWs::FiveSurface(p.new_workspace()),
        }
    }
    fn evaluate(&self, e: usize, u: &[f64], ws: &mut PlateWs, out: &mut LocalSystem, with_tangent: bool) {
        match (self, ws) {
            (Plate::TwoSurface(p), PlateWs::TwoSurface(w)) => p.evaluate(e, u, w, out, with_tangent),
            (Plate::ThreeSurface(p), PlateWs::ThreeSurface(w)) => p.evaluate(e, u, w, out, with_tangent),
            (Plate::FourSurface(p), PlateWs::FourSurface(w)) => p.evaluate(e, u, w, out, with_tangent),
            (Plate::FiveSurface(p), PlateWs::FiveSurface(w)) => p.evaluate(e, u, w, out, with_tangent),
            _ => unreachable!("a workspace is made by its own plate"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_place_faces_first_and_interpolate_the_mid_plane() {
        let two = Layout::two_surface();
        assert_eq!((two.dofs_per_node, two.face_dof(Face::Top, 2, 1)), (6, 16));
        assert_eq!(two.mid_terms(1, 2).collect::<Vec<_>>(), vec![(8, 0.5), (11, 0.5)]);
        let three = Layout::new(3);
        assert_eq!((three.dofs_per_node, three.face_dof(Face::Top, 2, 1)), (9, 22));
        assert_eq!(three.mid_terms(1, 2).collect::<Vec<_>>(), vec![(9 + 6 + 2, 1.0)]);
        assert_eq!(three.fibre_components(&[2, 5]), vec![2, 5, 8]);
        assert_eq!(three.fibre_components(&[2]), vec![2]);
        let four = Layout::new(4);
        assert_eq!(four.fibre_components(&[0, 3]), vec![0, 3, 6, 9]);
        // the mid-plane of four surfaces at zeta = -1, 1, -1/3, 1/3: a field linear in zeta is
        // interpolated exactly, so its mid value is the faces' mean
        let u: Vec<f64> = (0..12).map(|d| [-1.0, 1.0, -1.0 / 3.0, 1.0 / 3.0][d / 3] * 2.0 + 5.0).collect();
        assert!((four.mid_displacement(&u, 0)[1] - 5.0).abs() < 1e-14);
        assert!((four.zeta_of_component(7) + 1.0 / 3.0).abs() < 1e-15);
        // bottom, the two inner surfaces, top: the unknowns' zeta order -1, 1, -1/3, 1/3 sorted
        let by_surface: Vec<f64> = four.surface_displacements(&u, 0).iter().map(|d| d[0]).collect();
        assert_eq!(by_surface, vec![3.0, 5.0 - 2.0 / 3.0, 5.0 + 2.0 / 3.0, 7.0]);
        assert_eq!(two.surface_displacements(&(0..12).map(f64::from).collect::<Vec<_>>(), 1), vec![[6.0, 7.0, 8.0], [9.0, 10.0, 11.0]]);
    }
}

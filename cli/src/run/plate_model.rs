//! The plate model a problem file chooses (`[plate] model`): the paper's two-surface plate or the
//! three-surface plate, both plug-ins of the elements crate, behind one [`Element`] for the rest
//! of the run, with where each keeps its surfaces' displacements among the unknowns.

use stamp::element::{Element, LocalSystem};
use stamp_elements::plate::PlateWorkspace;
use stamp_elements::three_surface::ThreeSurfaceWorkspace;
use stamp_elements::{Face, Kinematics, PlateElements, ThreeSurfacePlate};

/// The plate elements of a run.
pub enum Plate {
    /// The paper's plate: the displacements of the two face planes, linear through the thickness.
    TwoSurface(PlateElements),
    /// Faces and mid-plane: quadratic through the thickness, the full 3D law.
    ThreeSurface(ThreeSurfacePlate),
}

/// The workspace of either.
pub enum PlateWs {
    TwoSurface(PlateWorkspace),
    ThreeSurface(ThreeSurfaceWorkspace),
}

impl Plate {
    /// Unknowns per node.
    pub fn dofs_per_node(&self) -> usize {
        match self {
            Plate::TwoSurface(p) => p.dofs_per_node(),
            Plate::ThreeSurface(p) => p.dofs_per_node(),
        }
    }
    pub fn kinematics(&self) -> Kinematics {
        match self {
            Plate::TwoSurface(p) => p.kinematics(),
            Plate::ThreeSurface(p) => p.kinematics(),
        }
    }
    /// The model's name in the problem file.
    pub fn name(&self) -> &'static str {
        match self {
            Plate::TwoSurface(_) => "two-surface",
            Plate::ThreeSurface(_) => "three-surface",
        }
    }
}

/// Where the surfaces' displacements are among the unknowns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Layout {
    pub dofs_per_node: usize,
}

impl Layout {
    pub fn of(plate: &Plate) -> Self {
        Layout { dofs_per_node: plate.dofs_per_node() }
    }
    /// The paper's six unknowns per node.
    pub const TWO_SURFACE: Layout = Layout { dofs_per_node: stamp_elements::DOFS_PER_NODE };
    /// Global dof of component `comp` of `face` at `node`.
    pub fn face_dof(&self, face: Face, node: usize, comp: usize) -> usize {
        face.dof_in(self.dofs_per_node, node, comp)
    }
    /// Global dof of component `comp` of the mid-plane at `node`, in a plate that has it.
    pub fn mid_dof(&self, node: usize, comp: usize) -> Option<usize> {
        (self.dofs_per_node == stamp_elements::three_surface::DOFS_PER_NODE).then(|| node * self.dofs_per_node + 6 + comp)
    }
    /// Displacement of `face` at node `n`.
    pub fn face_displacement(&self, u: &[f64], n: usize, face: Face) -> [f64; 3] {
        [0, 1, 2].map(|c| u[self.face_dof(face, n, c)])
    }
    /// Displacement of the mid-plane at node `n`: the mid-plane's own unknowns where the plate has
    /// them, otherwise (v- + v+)/2 (the paper's displacement is linear through the thickness).
    pub fn mid_displacement(&self, u: &[f64], n: usize) -> [f64; 3] {
        match self.mid_dof(n, 0) {
            Some(d) => [u[d], u[d + 1], u[d + 2]],
            None => [0, 1, 2].map(|c| 0.5 * (u[self.face_dof(Face::Bottom, n, c)] + u[self.face_dof(Face::Top, n, c)])),
        }
    }
    /// The constrained components of a boundary word, extended to this plate: a word that holds a
    /// component on both faces (v1, symmetry_x1, simply_supported, clamped, ...) holds it on the
    /// mid-plane too, i.e. on the whole fibre.
    pub fn fibre_components(&self, comps: &[usize]) -> Vec<usize> {
        let mut out = comps.to_vec();
        if self.mid_dof(0, 0).is_some() {
            for c in 0..3 {
                if comps.contains(&c) && comps.contains(&(c + 3)) {
                    out.push(6 + c);
                }
            }
        }
        out
    }
}

impl Element for Plate {
    type Workspace = PlateWs;

    fn dofs_per_node(&self) -> usize {
        Plate::dofs_per_node(self)
    }
    fn nodes_per_element(&self) -> usize {
        4
    }
    fn num_elements(&self) -> usize {
        match self {
            Plate::TwoSurface(p) => p.num_elements(),
            Plate::ThreeSurface(p) => p.num_elements(),
        }
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        match self {
            Plate::TwoSurface(p) => p.element_nodes(e),
            Plate::ThreeSurface(p) => p.element_nodes(e),
        }
    }
    fn has_preconditioner(&self) -> bool {
        match self {
            Plate::TwoSurface(p) => p.has_preconditioner(),
            Plate::ThreeSurface(p) => p.has_preconditioner(),
        }
    }
    fn new_workspace(&self) -> PlateWs {
        match self {
            Plate::TwoSurface(p) => PlateWs::TwoSurface(p.new_workspace()),
            Plate::ThreeSurface(p) => PlateWs::ThreeSurface(p.new_workspace()),
        }
    }
    fn evaluate(&self, e: usize, u: &[f64], ws: &mut PlateWs, out: &mut LocalSystem, with_tangent: bool) {
        match (self, ws) {
            (Plate::TwoSurface(p), PlateWs::TwoSurface(w)) => p.evaluate(e, u, w, out, with_tangent),
            (Plate::ThreeSurface(p), PlateWs::ThreeSurface(w)) => p.evaluate(e, u, w, out, with_tangent),
            _ => unreachable!("a workspace is made by its own plate"),
        }
    }
}

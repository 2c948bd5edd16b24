//! The plate model a problem file chooses (`[plate] surfaces`, `layers`): the paper's two-surface
//! plate, a plate of three to five surfaces through the thickness, or a laminate of layers of three
//! to five surfaces each (interfaces shared), plug-ins of the elements crate, behind
//! one [`Element`] for the rest of the run, with where each keeps its surfaces' displacements
//! among the unknowns ([`Layout`]).

use stamp::Result;
use stamp::element::{Element, LocalSystem};
use stamp::mesh::QuadMesh;
use stamp_elements::laminate::LaminateWorkspace;
use stamp_elements::multi_surface::{lagrange, surface_zetas, MultiSurfaceWorkspace, Resultants};
use stamp_elements::plate::PlateWorkspace;
use stamp_elements::{
    FiveSurfaceLaminate, FiveSurfacePlate, FourSurfaceLaminate, FourSurfacePlate, Kinematics, Laminate, Ply, PlyMaterial, PlateElements, Section, ThreeSurfaceLaminate, ThreeSurfacePlate,
};
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
    /// Layers of three, four or five surfaces each.
    ThreeSurfaceLayers(ThreeSurfaceLaminate),
    FourSurfaceLayers(FourSurfaceLaminate),
    FiveSurfaceLayers(FiveSurfaceLaminate),
}

/// The workspace of any of them.
pub enum PlateWs {
    TwoSurface(PlateWorkspace),
    ThreeSurface(MultiSurfaceWorkspace<12, 36>),
    FourSurface(MultiSurfaceWorkspace<16, 48>),
    FiveSurface(MultiSurfaceWorkspace<20, 60>),
    ThreeSurfaceLayers(LaminateWorkspace<12, 36>),
    FourSurfaceLayers(LaminateWorkspace<16, 48>),
    FiveSurfaceLayers(LaminateWorkspace<20, 60>),
}

/// Dispatch `$body` on the plate's variant with the element bound to `$p`.
macro_rules! each {
    ($plate:expr, $p:ident => $body:expr) => {
        match $plate {
            Plate::TwoSurface($p) => $body,
            Plate::ThreeSurface($p) => $body,
            Plate::FourSurface($p) => $body,
            Plate::FiveSurface($p) => $body,
            Plate::ThreeSurfaceLayers($p) => $body,
            Plate::FourSurfaceLayers($p) => $body,
            Plate::FiveSurfaceLayers($p) => $body,
        }
    };
}

/// Dispatch `$body` on the plate's variant and its workspace's, bound to `$p` and `$w` (a
/// workspace is made by its own plate: see `new_workspace`).
macro_rules! each_with_workspace {
    ($plate:expr, $ws:expr, ($p:ident, $w:ident) => $body:expr) => {
        match ($plate, $ws) {
            (Plate::TwoSurface($p), PlateWs::TwoSurface($w)) => $body,
            (Plate::ThreeSurface($p), PlateWs::ThreeSurface($w)) => $body,
            (Plate::FourSurface($p), PlateWs::FourSurface($w)) => $body,
            (Plate::FiveSurface($p), PlateWs::FiveSurface($w)) => $body,
            (Plate::ThreeSurfaceLayers($p), PlateWs::ThreeSurfaceLayers($w)) => $body,
            (Plate::FourSurfaceLayers($p), PlateWs::FourSurfaceLayers($w)) => $body,
            (Plate::FiveSurfaceLayers($p), PlateWs::FiveSurfaceLayers($w)) => $body,
            _ => unreachable!("a workspace is made by its own plate"),
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
    /// The laminate of `per_layer` surfaces in each layer on `mesh`.
    pub fn layered(per_layer: usize, mesh: &QuadMesh, laminate: Laminate, kinematics: Kinematics) -> Result<Plate> {
        Ok(match per_layer {
            3 => Plate::ThreeSurfaceLayers(ThreeSurfaceLaminate::new(mesh, laminate, kinematics)?),
            4 => Plate::FourSurfaceLayers(FourSurfaceLaminate::new(mesh, laminate, kinematics)?),
            5 => Plate::FiveSurfaceLayers(FiveSurfaceLaminate::new(mesh, laminate, kinematics)?),
            n => return Err(stamp::StampError::Material(format!("a layer has 3 to 5 surfaces, not {n}"))),
        })
    }
    /// The plate with one `plasticity` for its material (three to five surfaces without layers;
    /// the others refuse it).
    pub fn with_plasticity(self, plasticity: stamp_elements::plasticity::Plasticity) -> Result<Plate> {
        let p = [Some(plasticity)];
        Ok(match self {
            Plate::ThreeSurface(e) => Plate::ThreeSurface(e.with_plasticity(&p)?),
            Plate::FourSurface(e) => Plate::FourSurface(e.with_plasticity(&p)?),
            Plate::FiveSurface(e) => Plate::FiveSurface(e.with_plasticity(&p)?),
            _ => return Err(stamp::StampError::Material("plasticity needs a plate of three to five surfaces without layers".into())),
        })
    }
    /// Whether the plate has plastic points.
    pub fn is_plastic(&self) -> bool {
        matches!(self, Plate::ThreeSurface(e) if e.plastic_points().is_some())
            || matches!(self, Plate::FourSurface(e) if e.plastic_points().is_some())
            || matches!(self, Plate::FiveSurface(e) if e.plastic_points().is_some())
    }
    /// The laminate and the surfaces in each of its layers, for a layered plate.
    pub fn laminate(&self) -> Option<(&Laminate, usize)> {
        match self {
            Plate::ThreeSurfaceLayers(p) => Some((p.laminate(), 3)),
            Plate::FourSurfaceLayers(p) => Some((p.laminate(), 4)),
            Plate::FiveSurfaceLayers(p) => Some((p.laminate(), 5)),
            _ => None,
        }
    }
    /// The stack whose stresses the output writes, the surfaces in each of its layers, and x3 of
    /// its mid-plane: a laminate's plies (mid-plane 0), or for a plate of three to five surfaces
    /// without layers one layer of the plate's thickness and material (mid-plane between its
    /// faces); None for the paper's two-surface plate, whose law is not the 3D one.
    pub fn stress_stack(&self) -> Option<(Laminate, usize, f64)> {
        if let Some((lam, per_layer)) = self.laminate() {
            return Some((lam.clone(), per_layer, 0.0));
        }
        let (section, n) = match self {
            Plate::ThreeSurface(p) => (p.section(), 3),
            Plate::FourSurface(p) => (p.section(), 4),
            Plate::FiveSurface(p) => (p.section(), 5),
            _ => return None,
        };
        let ply = Ply { thickness: section.thickness(), material: PlyMaterial::Isotropic(section.layers[0].material), angle: 0.0 };
        Some((Laminate::new(vec![ply]).expect("a valid section"), n, 0.5 * (section.delta_minus + section.delta_plus)))
    }
    /// The six stresses (Voigt order [11, 22, 33, 23, 13, 12], the plate's axes) at height `x3`
    /// (from the mid-plane of [`Plate::stress_stack`]) of its layer `k` of element `e` at the four
    /// Gauss points, by the layer's 3D law; None for the two-surface plate.
    pub fn layer_stresses(&self, e: usize, k: usize, x3: f64, v: &[f64], ws: &mut PlateWs) -> Option<[[f64; 6]; 4]> {
        match (self, ws) {
            (Plate::ThreeSurfaceLayers(p), PlateWs::ThreeSurfaceLayers(w)) => Some(p.stresses_at(e, k, x3, v, w)),
            (Plate::FourSurfaceLayers(p), PlateWs::FourSurfaceLayers(w)) => Some(p.stresses_at(e, k, x3, v, w)),
            (Plate::FiveSurfaceLayers(p), PlateWs::FiveSurfaceLayers(w)) => Some(p.stresses_at(e, k, x3, v, w)),
            (Plate::ThreeSurface(p), PlateWs::ThreeSurface(w)) => Some(p.stresses_at(e, x3, v, w)),
            (Plate::FourSurface(p), PlateWs::FourSurface(w)) => Some(p.stresses_at(e, x3, v, w)),
            (Plate::FiveSurface(p), PlateWs::FiveSurface(w)) => Some(p.stresses_at(e, x3, v, w)),
            _ => None,
        }
    }
    /// The equivalent plastic strain and the yield state at height `x3` (from the mid-plane) of
    /// element `e` at its four Gauss points; None for an elastic plate.
    pub fn plastic_strain_at(&self, e: usize, x3: f64, v: &[f64], ws: &mut PlateWs) -> Option<[(f64, bool); 4]> {
        match (self, ws) {
            (Plate::ThreeSurface(p), PlateWs::ThreeSurface(w)) => p.plastic_strain_at(e, x3, v, w),
            (Plate::FourSurface(p), PlateWs::FourSurface(w)) => p.plastic_strain_at(e, x3, v, w),
            (Plate::FiveSurface(p), PlateWs::FiveSurface(w)) => p.plastic_strain_at(e, x3, v, w),
            _ => None,
        }
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
            (Plate::ThreeSurfaceLayers(p), PlateWs::ThreeSurfaceLayers(w)) => p.resultants(e, v, w),
            (Plate::FourSurfaceLayers(p), PlateWs::FourSurfaceLayers(w)) => p.resultants(e, v, w),
            (Plate::FiveSurfaceLayers(p), PlateWs::FiveSurfaceLayers(w)) => p.resultants(e, v, w),
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
        match plate.laminate() {
            Some((lam, per_layer)) => Layout::layered(lam, per_layer),
            None => Layout::new(plate.surfaces()),
        }
    }
    /// The layout of a laminate with `per_layer` surfaces in each layer: zeta = 2 x3 / h of the
    /// surfaces in the order of the unknowns, the mid-plane x3 = 0 interpolated in the layer that
    /// holds it.
    pub fn layered(lam: &Laminate, per_layer: usize) -> Layout {
        let h = lam.thickness();
        let dof_order = lam.surfaces_in_dof_order(per_layer);
        let upwards = lam.surfaces_upwards(per_layer);
        let m = dof_order.len();
        let zetas: Vec<f64> = dof_order.iter().map(|z| 2.0 * z / h).collect();
        let k = lam.ply_at(0.0);
        let own: Vec<f64> = (0..per_layer).map(|s| upwards[k * (per_layer - 1) + s]).collect();
        let (l, _) = lagrange(&own, 0.0);
        let mut mid_weights = vec![0.0; m];
        for (s, w) in l.into_iter().enumerate() {
            let j = k * (per_layer - 1) + s;
            let slot = if j == 0 { 0 } else if j == m - 1 { 1 } else { j + 1 };
            mid_weights[slot] = w;
        }
        Layout { surfaces: m, dofs_per_node: 3 * m, zetas, mid_weights }
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
    fn retain_elements(&mut self, keep: &[bool]) {
        each!(self, p => p.retain_elements(keep))
    }
    fn new_workspace(&self) -> PlateWs {
        match self {
            Plate::TwoSurface(p) => PlateWs::TwoSurface(p.new_workspace()),
            Plate::ThreeSurface(p) => PlateWs::ThreeSurface(p.new_workspace()),
            Plate::FourSurface(p) => PlateWs::FourSurface(p.new_workspace()),
            Plate::FiveSurface(p) => PlateWs::FiveSurface(p.new_workspace()),
            Plate::ThreeSurfaceLayers(p) => PlateWs::ThreeSurfaceLayers(p.new_workspace()),
            Plate::FourSurfaceLayers(p) => PlateWs::FourSurfaceLayers(p.new_workspace()),
            Plate::FiveSurfaceLayers(p) => PlateWs::FiveSurfaceLayers(p.new_workspace()),
        }
    }
    fn evaluate(&self, e: usize, u: &[f64], ws: &mut PlateWs, out: &mut LocalSystem, with_tangent: bool) {
        each_with_workspace!(self, ws, (p, w) => p.evaluate(e, u, w, out, with_tangent))
    }
    fn evaluate_about(&self, e: usize, u: &[f64], reference: &[f64], ws: &mut PlateWs, out: &mut LocalSystem, with_tangent: bool) {
        each_with_workspace!(self, ws, (p, w) => p.evaluate_about(e, u, reference, w, out, with_tangent))
    }
    fn has_history(&self) -> bool {
        each!(self, p => p.has_history())
    }
    fn commit(&mut self, e: usize, u: &[f64], ws: &mut PlateWs) {
        each_with_workspace!(self, ws, (p, w) => p.commit(e, u, w))
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

    /// A laminate's layout: the faces first, x3 = 0 interpolated in its own layer (here an
    /// interface of two layers with three surfaces: that surface's unknowns alone; and inside the
    /// middle layer of three).
    #[test]
    fn layered_layouts_interpolate_the_mid_plane_in_its_layer() {
        use stamp_elements::{Isotropic, Ply, PlyMaterial};
        let iso = PlyMaterial::Isotropic(Isotropic::new(1.0, 0.3).unwrap());
        let ply = |t: f64| Ply { thickness: t, material: iso, angle: 0.0 };
        let two = Layout::layered(&Laminate::new(vec![ply(0.5), ply(0.5)]).unwrap(), 3);
        // surfaces upwards -0.5, -0.25, 0, 0.25, 0.5; in dof order -0.5, 0.5, -0.25, 0, 0.25
        assert_eq!((two.surfaces, two.dofs_per_node), (5, 15));
        assert_eq!(two.mid_terms(1, 2).collect::<Vec<_>>(), vec![(15 + 9 + 2, 1.0)]);
        assert_eq!(two.fibre_components(&[2, 5]), vec![2, 5, 8, 11, 14]);
        let three = Layout::layered(&Laminate::new(vec![ply(0.3), ply(0.4), ply(0.3)]).unwrap(), 4);
        // a field linear in x3 is interpolated exactly: its mid value from the surfaces' values
        let z: Vec<f64> = three.zetas.iter().map(|&zeta| 0.5 * zeta).collect();
        let u: Vec<f64> = (0..3 * three.surfaces).map(|d| 3.0 * z[d / 3] + 2.0).collect();
        assert!((three.mid_displacement(&u, 0)[0] - 2.0).abs() < 1e-14);
        assert_eq!(three.mid_terms(0, 0).count(), 4, "the four surfaces of the middle layer");
    }
}

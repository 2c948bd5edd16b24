//! Laminated plates: a stack of plies, each a multi-surface section of its own
//! ([`crate::multi_surface`]) with N surfaces (its two faces and N - 2 inner surfaces equally spaced
//! between them), the plies sharing their interface surfaces. The displacement is continuous
//! through the thickness and a polynomial of degree N - 1 in each ply (a layerwise model: the
//! sampling surfaces of G. M. Kulikov and S. V. Plotnikova, "Exact 3D stress analysis of laminated
//! composite plates by sampling surfaces method", Compos. Struct. 94 (2012), with equally spaced
//! surfaces in each layer), so the transverse shear strain may jump at an interface where the
//! shear moduli do, as in 3D. Each ply has its own 3D Saint Venant-Kirchhoff law, orthotropic in
//! its axes turned by its angle ([`crate::orthotropic`]).
//!
//! Unknowns per node: 3 M, M = L (N - 1) + 1 surfaces for L plies, in the order of the
//! multi-surface plate: the bottom face S-, the top face S+, then the other surfaces (inner
//! surfaces and interfaces) from the bottom up. So contact, loads and supports on a face see the
//! same unknowns as on the paper's plate.
//!
//! Every ply is integrated exactly as the multi-surface plate integrates its section: N Gauss
//! levels through the ply, the paper's assumed strains at each, the stabilised E33; the element's
//! internal force, energy and tangent are the sums over the plies, each scattered from the ply's
//! 12 N unknowns to the element's 12 M. The ply's law is turned into the element's local frame
//! (its t1 along dX/dxi1 at the centre) by the angle between t1 and the ply's fibres.

use crate::geometries::Geometries;
use crate::geometry::ElementGeometry;
use crate::multi_surface::{compute_samples, evaluate_levels, inside_out, resultants_of, strain, workspace, Law, Level, MultiSurfaceWorkspace, Resultants};
use crate::orthotropic::{rotate, PlyMaterial, Stiffness};
use crate::plate::Kinematics;
use stamp::element::{Element, LocalSystem};
use stamp::mesh::QuadMesh;
use stamp::{Result, StampError};

/// One ply: its thickness, material and angle (degrees, the fibre direction from x1 towards x2).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Ply {
    pub thickness: f64,
    pub material: PlyMaterial,
    pub angle: f64,
}

/// The plies from the bottom face up; the mid-plane of the stack at x3 = 0.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Laminate {
    pub plies: Vec<Ply>,
}

impl Laminate {
    /// A validated stack.
    pub fn new(plies: Vec<Ply>) -> Result<Self> {
        let l = Laminate { plies };
        l.validate()?;
        Ok(l)
    }

    /// At least one ply, every thickness positive and finite, every angle finite, every material valid.
    pub fn validate(&self) -> Result<()> {
        if self.plies.is_empty() {
            return Err(StampError::Material("the laminate has no ply".into()));
        }
        for (k, p) in self.plies.iter().enumerate() {
            if !(p.thickness.is_finite() && p.thickness > 0.0) {
                return Err(StampError::Material(format!("layer {k}: the thickness must be positive and finite, got {}", p.thickness)));
            }
            if !p.angle.is_finite() {
                return Err(StampError::Material(format!("layer {k}: the angle must be finite, got {}", p.angle)));
            }
            p.material.validate().map_err(|e| StampError::Material(format!("layer {k}: {e}")))?;
        }
        Ok(())
    }

    pub fn thickness(&self) -> f64 {
        self.plies.iter().map(|p| p.thickness).sum()
    }
    /// x3 of the bottom face.
    pub fn delta_minus(&self) -> f64 {
        -0.5 * self.thickness()
    }
    /// x3 of the top face.
    pub fn delta_plus(&self) -> f64 {
        0.5 * self.thickness()
    }
    /// x3 of the ply boundaries from the bottom face up (L + 1 values).
    pub fn boundaries(&self) -> Vec<f64> {
        let mut z = vec![self.delta_minus()];
        for p in &self.plies {
            z.push(z.last().unwrap() + p.thickness);
        }
        *z.last_mut().unwrap() = self.delta_plus();
        z
    }

    /// x3 of the M = L (N - 1) + 1 surfaces of a plate of N surfaces per ply, from the bottom up.
    pub fn surfaces_upwards(&self, per_layer: usize) -> Vec<f64> {
        let b = self.boundaries();
        let mut z = vec![b[0]];
        for k in 0..self.plies.len() {
            for s in 1..per_layer {
                z.push(if s + 1 == per_layer { b[k + 1] } else { b[k] + (b[k + 1] - b[k]) * s as f64 / (per_layer - 1) as f64 });
            }
        }
        z
    }

    /// x3 of the surfaces in the order of the unknowns: S-, S+, then the others upwards.
    pub fn surfaces_in_dof_order(&self, per_layer: usize) -> Vec<f64> {
        let up = self.surfaces_upwards(per_layer);
        let m = up.len();
        let mut z = vec![up[0], up[m - 1]];
        z.extend_from_slice(&up[1..m - 1]);
        z
    }

    /// The slots, in the order of the unknowns, of the `per_layer` surfaces of ply `k` from its
    /// bottom up.
    pub fn ply_slots(&self, per_layer: usize, k: usize) -> Vec<usize> {
        let m = self.plies.len() * (per_layer - 1) + 1;
        (0..per_layer).map(|s| slot_of_upward(k * (per_layer - 1) + s, m)).collect()
    }

    /// The ply that holds x3 (the upper one at an interface, the top ply at the top face).
    pub fn ply_at(&self, x3: f64) -> usize {
        let b = self.boundaries();
        (1..self.plies.len()).rev().find(|&k| x3 >= b[k]).unwrap_or(0)
    }
}

/// The slot, in the order of the unknowns, of the surface that is `j`-th from the bottom among `m`.
fn slot_of_upward(j: usize, m: usize) -> usize {
    if j == 0 {
        0
    } else if j == m - 1 {
        1
    } else {
        j + 1
    }
}

/// One ply of the element: its levels, its law, and where its unknowns sit among the element's.
struct PlyPart<const N: usize, const D: usize> {
    levels: Vec<Level<N>>,
    /// The law in the plate's axes (turned by the ply angle).
    c: Stiffness,
    isotropic: Option<(f64, f64)>,
    /// Element dof of each of the ply's local dofs 3 (N a + s) + i (s counted upwards in the ply).
    dofs: [usize; D],
}

/// The laminated plate elements of a mesh, N surfaces per ply; P = 4 N and D = 12 N are a ply's
/// (node, surface) pairs and dofs.
pub struct LaminatePlate<const N: usize, const P: usize, const D: usize> {
    cells: Vec<[usize; 4]>,
    geometry: Geometries,
    /// The angle of each element's local t1 from x1.
    frame_angle: Vec<f64>,
    plies: Vec<PlyPart<N, D>>,
    surfaces: usize,
    laminate: Laminate,
    kinematics: Kinematics,
}

/// Three, four or five surfaces per ply.
pub type ThreeSurfaceLaminate = LaminatePlate<3, 12, 36>;
pub type FourSurfaceLaminate = LaminatePlate<4, 16, 48>;
pub type FiveSurfaceLaminate = LaminatePlate<5, 20, 60>;

/// Per-thread scratch memory: a ply's workspace and its local system.
pub struct LaminateWorkspace<const P: usize, const D: usize> {
    inner: MultiSurfaceWorkspace<P, D>,
    v: [f64; D],
    /// A ply's dofs at the reference state of [`Element::evaluate_about`].
    v_ref: [f64; D],
    residual: [f64; D],
    tangent: Vec<f64>,
    laws: [Law; 1],
}

impl<const N: usize, const P: usize, const D: usize> LaminatePlate<N, P, D> {
    /// Elements on every cell of `mesh`.
    pub fn new(mesh: &QuadMesh, laminate: Laminate, kinematics: Kinematics) -> Result<Self> {
        assert!((3..=5).contains(&N) && P == 4 * N && D == 12 * N, "a ply has 3 to 5 surfaces, P = 4 N, D = 12 N");
        laminate.validate()?;
        mesh.validate()?;
        let geometry = (0..mesh.num_cells()).map(|c| ElementGeometry::new(&mesh.cell_coords(c), c)).collect::<Result<Vec<_>>>()?;
        let frame_angle = geometry.iter().map(|g| g.frame[0][1].atan2(g.frame[0][0])).collect();
        let m = laminate.plies.len() * (N - 1) + 1;
        let zs: Vec<f64> = (0..N).map(|s| -1.0 + 2.0 * s as f64 / (N - 1) as f64).collect();
        let b = laminate.boundaries();
        let plies = laminate
            .plies
            .iter()
            .enumerate()
            .map(|(k, ply)| {
                let (bottom, top) = (b[k], b[k + 1]);
                let centre = 0.5 * (bottom + top);
                let mut levels = Level::<N>::of_layer(bottom, top, centre, top - bottom, &zs, 0);
                for lv in &mut levels {
                    lv.x3 += centre; // moments about the stack's mid-plane, x3 = 0
                }
                let dofs = std::array::from_fn(|d| {
                    let (pair, i) = (d / 3, d % 3);
                    let (a, s) = (pair / N, pair % N);
                    3 * m * a + 3 * slot_of_upward(k * (N - 1) + s, m) + i
                });
                let isotropic = match ply.material {
                    PlyMaterial::Isotropic(iso) => Some((iso.lame_lambda(), iso.shear_modulus())),
                    PlyMaterial::Orthotropic(_) => None,
                };
                PlyPart { levels, c: rotate(&ply.material.stiffness(), ply.angle.to_radians()), isotropic, dofs }
            })
            .collect();
        Ok(LaminatePlate { cells: mesh.cells.clone(), geometry: Geometries::new(geometry), frame_angle, plies, surfaces: m, laminate, kinematics })
    }

    pub fn laminate(&self) -> &Laminate {
        &self.laminate
    }
    pub fn kinematics(&self) -> Kinematics {
        self.kinematics
    }
    /// Surfaces through the whole thickness, M = L (N - 1) + 1.
    pub fn surfaces(&self) -> usize {
        self.surfaces
    }

    /// The law of ply k in the local frame of element e.
    fn law(&self, e: usize, k: usize) -> Law {
        let ply = &self.plies[k];
        match ply.isotropic {
            Some((lambda, mu)) => Law::Isotropic { lambda, mu },
            None if self.frame_angle[e] == 0.0 => Law::General(ply.c),
            // the ply's axes lie at (angle - alpha) from the element's t1, alpha the angle of t1
            None => Law::General(rotate(&ply.c, -self.frame_angle[e])),
        }
    }

    /// The ply's unknowns from the element's.
    fn gather(ply: &PlyPart<N, D>, v: &[f64], out: &mut [f64; D]) {
        for (o, &d) in out.iter_mut().zip(&ply.dofs) {
            *o = v[d];
        }
    }

    /// The resultants at the centre of element `e` at local dofs `v` (the mean over its Gauss
    /// points; moments about the stack's mid-plane), for output.
    pub fn resultants(&self, e: usize, v: &[f64], ws: &mut LaminateWorkspace<P, D>) -> Resultants {
        let mut r = Resultants::default();
        for (k, ply) in self.plies.iter().enumerate() {
            Self::gather(ply, v, &mut ws.v);
            ws.laws[0] = self.law(e, k);
            resultants_of(&self.geometry[e], &ply.levels, &ws.laws, None, self.kinematics, &ws.v, &mut ws.inner, &mut r);
        }
        r
    }

    /// The six stresses (second Piola-Kirchhoff, Voigt order [11, 22, 33, 23, 13, 12]) in the
    /// plate's axes x1, x2, x3 at height `x3` of ply `k` at the four Gauss points of element `e`,
    /// by the ply's 3D law from the element's strains there (the assumed strains of the plate: the
    /// membrane strains projected over the element's rows and columns, the transverse shear tied
    /// at the edge midpoints); their mean is the value at the element's centre.
    pub fn stresses_at(&self, e: usize, k: usize, x3: f64, v: &[f64], ws: &mut LaminateWorkspace<P, D>) -> [[f64; 6]; 4] {
        let ply = &self.plies[k];
        let b = self.laminate.boundaries();
        let (bottom, top) = (b[k], b[k + 1]);
        let centre = 0.5 * (bottom + top);
        let zs: [f64; N] = std::array::from_fn(|s| -1.0 + 2.0 * s as f64 / (N - 1) as f64);
        let level = Level::<N>::at(x3 - centre, top - bottom, &zs, 0);
        Self::gather(ply, v, &mut ws.v);
        let geo = &self.geometry[e];
        compute_samples(geo, std::slice::from_ref(&level), self.kinematics, &ws.v, &mut ws.inner);
        let law = self.law(e, k);
        std::array::from_fn(|g| crate::orthotropic::rotate_stress(&law.stress(&strain(geo, ws.inner.samples(), 0, g)), -self.frame_angle[e]))
    }

    /// The smallest volume ratio det[g1, g2, g3] / det[G1, G2, G3] over the integration points of
    /// element `e` at local dofs `v`.
    pub fn smallest_volume_ratio(&self, e: usize, v: &[f64], ws: &mut LaminateWorkspace<P, D>) -> f64 {
        let mut ratio = f64::INFINITY;
        for ply in &self.plies {
            Self::gather(ply, v, &mut ws.v);
            compute_samples(&self.geometry[e], &ply.levels, self.kinematics, &ws.v, &mut ws.inner);
            ratio = ratio.min(ws.inner.volume_ratio);
        }
        ratio
    }
}

impl<const N: usize, const P: usize, const D: usize> Element for LaminatePlate<N, P, D> {
    type Workspace = LaminateWorkspace<P, D>;

    fn retain_elements(&mut self, keep: &[bool]) {
        self.geometry.retain(keep);
    }
    fn dofs_per_node(&self) -> usize {
        3 * self.surfaces
    }
    fn nodes_per_element(&self) -> usize {
        4
    }
    fn num_elements(&self) -> usize {
        self.cells.len()
    }
    fn element_nodes(&self, e: usize) -> &[usize] {
        &self.cells[e]
    }
    fn new_workspace(&self) -> LaminateWorkspace<P, D> {
        LaminateWorkspace { inner: workspace(N), v: [0.0; D], v_ref: [0.0; D], residual: [0.0; D], tangent: vec![0.0; D * D], laws: [Law::Isotropic { lambda: 0.0, mu: 0.0 }] }
    }

    /// The sum over the plies; the nonlinear element refuses a state in which a ply turned inside
    /// out.
    fn evaluate(&self, e: usize, v: &[f64], ws: &mut LaminateWorkspace<P, D>, out: &mut LocalSystem, with_tangent: bool) {
        self.evaluate_from(e, v, None, ws, out, with_tangent);
    }

    /// The geometric stiffness of every ply from the stresses of its strains linearised about
    /// `reference`.
    fn evaluate_about(&self, e: usize, v: &[f64], reference: &[f64], ws: &mut LaminateWorkspace<P, D>, out: &mut LocalSystem, with_tangent: bool) {
        self.evaluate_from(e, v, Some(reference), ws, out, with_tangent);
    }
}

impl<const N: usize, const P: usize, const D: usize> LaminatePlate<N, P, D> {
    /// [`Element::evaluate`] and [`Element::evaluate_about`].
    fn evaluate_from(&self, e: usize, v: &[f64], reference: Option<&[f64]>, ws: &mut LaminateWorkspace<P, D>, out: &mut LocalSystem, with_tangent: bool) {
        let dt = 12 * self.surfaces;
        let mut ratio = f64::INFINITY;
        for (k, ply) in self.plies.iter().enumerate() {
            Self::gather(ply, v, &mut ws.v);
            if let Some(r) = reference {
                Self::gather(ply, r, &mut ws.v_ref);
            }
            ws.laws[0] = self.law(e, k);
            ws.residual = [0.0; D];
            if with_tangent {
                ws.tangent.fill(0.0);
            }
            let LaminateWorkspace { inner, v: vl, v_ref, residual, tangent, laws } = ws;
            let reference = reference.map(|_| &v_ref[..]);
            evaluate_levels(&self.geometry[e], &ply.levels, laws, self.kinematics, vl, reference, None, inner, residual, tangent, &mut out.energy, with_tangent);
            ratio = ratio.min(inner.volume_ratio);
            for (i, &di) in ply.dofs.iter().enumerate() {
                out.residual[di] += residual[i];
            }
            if with_tangent {
                for (i, &di) in ply.dofs.iter().enumerate() {
                    let row = &mut out.tangent[di * dt..(di + 1) * dt];
                    for (j, &dj) in ply.dofs.iter().enumerate() {
                        row[dj] += tangent[i * D + j];
                    }
                }
            }
        }
        if self.kinematics == Kinematics::Nonlinear && ratio <= 0.0 {
            out.inadmissible = Some(inside_out(ratio));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Isotropic;

    #[test]
    fn surfaces_are_shared_at_the_interfaces_and_faces_come_first() {
        let iso = PlyMaterial::Isotropic(Isotropic::new(1.0, 0.3).unwrap());
        let l = Laminate::new(vec![
            Ply { thickness: 0.5, material: iso, angle: 0.0 },
            Ply { thickness: 1.0, material: iso, angle: 0.0 },
        ])
        .unwrap();
        assert_eq!(l.boundaries(), vec![-0.75, -0.25, 0.75]);
        assert_eq!(l.surfaces_upwards(3), vec![-0.75, -0.5, -0.25, 0.25, 0.75]);
        assert_eq!(l.surfaces_in_dof_order(3), vec![-0.75, 0.75, -0.5, -0.25, 0.25]);
        assert_eq!((l.ply_at(-0.75), l.ply_at(-0.25), l.ply_at(0.75)), (0, 1, 1));
        assert_eq!((0..5).map(|j| slot_of_upward(j, 5)).collect::<Vec<_>>(), vec![0, 2, 3, 4, 1]);
        assert!(Laminate::new(vec![]).is_err());
        assert!(Laminate::new(vec![Ply { thickness: 0.0, material: iso, angle: 0.0 }]).unwrap_err().to_string().contains("layer 0"));
    }
}

//! The multi-surface plate: the paper's plate (section 1) with N >= 3 surfaces through the thickness
//! instead of its two faces, as a second stamp [`Element`]. Unknowns per node: the 3 N
//! displacements [v-, v+, v^(1), ..., v^(N-2)] of the face planes S-, S+ (first, at the same places
//! as in the paper's element, so that contact and loads on a face see the same dofs) and of the
//! inner surfaces, equally spaced between them from the bottom up (N = 3: the mid-plane).
//!
//! The displacement is a polynomial of degree N - 1 through the thickness instead of linear (the
//! paper's eq. 1.1 with more terms): with zeta = 2 (x3 - x3m) / h in [-1, 1] and the Lagrange
//! functions L_s(zeta) of the surfaces' zeta_s,
//!
//!   u(x1, x2, x3) = sum_s L_s(zeta) v^s(x1, x2).
//!
//! So the transverse shear strain may take its parabolic (or richer) profile without a correction
//! factor, the thickness may change across the section (local indentation under a punch), and the
//! full 3D Saint Venant-Kirchhoff law S = lambda tr(E) I + 2 mu E holds at every point: no
//! plane-stress reduction and no b_ab33 = 0 (the paper's eq. 2.6), because E33, now at least linear in
//! x3, can follow the linear in-plane strains of bending, and the Poisson locking that b_ab33 = 0
//! cures in the paper's plate does not arise. The paper's plate is the case N = 2; as N grows the
//! model converges to 3D elasticity.
//!
//! Strains are exact Green-Lagrange strains 2 E_ij = g_i . g_j - G_i . G_j of base vectors affine
//! in the nodal displacements ([`crate::strain`]), so any rigid-body motion gives zero strain
//! exactly (a rigid motion is linear in x3, which the interpolation reproduces: eqs. 1.6-1.8 of
//! the paper). The element uses the paper's assumed strains at every level through the thickness
//! (section 4, eqs. 4.4-4.5, see [`crate::geometry`]): E11 projected on {1, xi2}, E22 on {1, xi1},
//! E12 on {1}, and the transverse shear interpolated between the covariant strains at the edge
//! midpoints (the tying form the paper's element uses on non-parallelograms). The residual is
//! int (dE/dV)^T S dV, the tangent int (dE/dV)^T C (dE/dV) + S : d2E/dV2 dV (exact, symmetric).
//! Each layer is integrated by N Gauss points through the thickness (exact for the linear
//! theory's energy), 2 x 2 in the plane.
//!
//! E33 is where this element departs from the paper's (which keeps it bilinear): the assumed E33
//! is its element mean plus a tenth of its variation over the element (`E33_STABILISATION`). In
//! the 3D law lambda tr(E) couples E33 to the in-plane strains; the Poisson change of thickness
//! follows the bending moment along the plate, so a bilinear E33 varies inside an element where
//! E11 and E22 are constant along their own directions, and the element locks in bending (the
//! paper's cantilever strip, three surfaces: -0.47 % on 40 elements, converging like h^1). The
//! element mean alone cures that but leaves two spurious zero-energy modes per element; a tenth
//! of the variation gives them a stiffness of the order of the bending modes' (4e-4 of the
//! largest eigenvalue on a 2 x 1 x 2 element) and costs -0.12 % on the cantilever's 40 elements.
//! It is a stabilisation in the sense of hourglass control: constant strains (the patch test) and
//! rigid motions are untouched, and the variation it scales vanishes as the mesh is refined.
//! Measured variants: docs/verification/elasticity-3d.md.

use crate::geometries::Geometries;
use crate::geometry::{ElementGeometry, GAUSS_POINTS};
use crate::material::{NormalStress, Section};
use crate::orthotropic::Stiffness;
use crate::plate::Kinematics;
use crate::plasticity::return_map::YieldBasis;
use crate::plasticity::{ElementPlasticity, PlasticPoints, PlasticState, Plasticity};
use crate::strain::{add_geometric_stiffness, axpy, triple, Affine, Sample};
use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};
use stamp::element::{Element, LocalSystem};
use stamp::linalg::vector_state::clean_upper_vector_state;
use stamp::mesh::QuadMesh;
use stamp::{Result, StampError};

/// Strain samples per level through the thickness: E11, E22, 2E12, E33 at the four Gauss points,
/// then the covariant shear g_xi . g3 at the four tying points.
const PER_LEVEL: usize = 20;
const TYING_SAMPLE: usize = 16;
/// The strain vector at a point: [E11, E22, E33, 2E23, 2E13, 2E12] (local Cartesian frame).
const NVOIGT: usize = 6;
/// The share of E33's variation over an element that the assumed E33 keeps (see the module doc):
/// 1 is the displacement-based bilinear E33, 0 its element mean.
const E33_STABILISATION: f64 = 0.1;
/// The sub-layers over which a plastic layer is integrated, N levels each: the stresses through
/// the thickness of a section that yields have kinks where it does, which N Gauss levels miss.
/// A strip bent to 1.5 to 10 times its first-yield curvature (tests/plasticity_plate.rs), five
/// surfaces: the moment within 1.5 % of the closed form with 2 sub-layers, 0.23 % with 4, 0.29 %
/// with 8.
pub const PLASTIC_SUBLAYERS: usize = 4;

/// The plate with three surfaces (faces and mid-plane): 9 unknowns per node.
pub type ThreeSurfacePlate = MultiSurfacePlate<3, 12, 36>;
/// The plate with four surfaces (faces and two inner surfaces at the thirds): 12 unknowns per node.
pub type FourSurfacePlate = MultiSurfacePlate<4, 16, 48>;
/// The plate with five surfaces: 15 unknowns per node.
pub type FiveSurfacePlate = MultiSurfacePlate<5, 20, 60>;

/// Abscissae and weights of the N-point Gauss rules on [-1, 1], N = 3, 4, 5.
fn gauss_rule(n: usize) -> &'static [(f64, f64)] {
    const G3: [(f64, f64); 3] = [(-0.774_596_669_241_483_4, 5.0 / 9.0), (0.0, 8.0 / 9.0), (0.774_596_669_241_483_4, 5.0 / 9.0)];
    const G4: [(f64, f64); 4] = [
        (-0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
        (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
        (0.861_136_311_594_052_6, 0.347_854_845_137_453_9),
    ];
    const G5: [(f64, f64); 5] = [
        (-0.906_179_845_938_664_0, 0.236_926_885_056_189_1),
        (-0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (0.0, 0.568_888_888_888_888_9),
        (0.538_469_310_105_683_1, 0.478_628_670_499_366_5),
        (0.906_179_845_938_664_0, 0.236_926_885_056_189_1),
    ];
    match n {
        3 => &G3,
        4 => &G4,
        5 => &G5,
        _ => unreachable!("checked by MultiSurfacePlate::new"),
    }
}

/// zeta of the N surfaces in the order of the dofs: -1 (S-), +1 (S+), then the inner ones upwards.
pub fn surface_zetas(n: usize) -> Vec<f64> {
    let mut z = vec![-1.0, 1.0];
    z.extend((1..n - 1).map(|k| -1.0 + 2.0 * k as f64 / (n - 1) as f64));
    z
}

/// The Lagrange functions of the surfaces `zs` at `z`, and their derivatives d/dzeta.
pub fn lagrange(zs: &[f64], z: f64) -> (Vec<f64>, Vec<f64>) {
    let n = zs.len();
    let mut l = vec![1.0; n];
    let mut dl = vec![0.0; n];
    for s in 0..n {
        for k in (0..n).filter(|&k| k != s) {
            let d = zs[s] - zs[k];
            dl[s] = dl[s] * (z - zs[k]) / d + l[s] / d;
            l[s] *= (z - zs[k]) / d;
        }
    }
    (l, dl)
}

/// One integration level through the thickness.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Level<const N: usize> {
    /// L_s(zeta) and dL_s/dx3 = (2 / h) dL_s/dzeta at this level.
    l: [f64; N],
    dl: [f64; N],
    /// x3 - x3m.
    pub(crate) x3: f64,
    /// Gauss weight times the length it stands for (sums to h).
    weight: f64,
    /// Index of the level's law in the laws the kernel is given (its layer's).
    law: usize,
}

impl<const N: usize> Level<N> {
    /// A level at height `x3` from the middle of a thickness `h` whose surfaces are at `zs`
    /// (zeta in [-1, 1]), with no weight: for evaluating strains there.
    pub(crate) fn at(x3: f64, h: f64, zs: &[f64], law: usize) -> Level<N> {
        let (l, dl) = lagrange(zs, 2.0 * x3 / h);
        Level { l: std::array::from_fn(|s| l[s]), dl: std::array::from_fn(|s| 2.0 * dl[s] / h), x3, weight: 0.0, law }
    }

    /// The N Gauss levels of the layer [bottom, top] for the surfaces at `zs` (zeta in [-1, 1]
    /// over the thickness [mid - h/2, mid + h/2] they interpolate), measured from x3 = mid.
    pub(crate) fn of_layer(bottom: f64, top: f64, mid: f64, h: f64, zs: &[f64], law: usize) -> Vec<Level<N>> {
        let half = 0.5 * (top - bottom);
        let centre = 0.5 * (top + bottom);
        gauss_rule(N)
            .iter()
            .map(|&(x, w)| {
                let x3 = centre + half * x;
                let (l, dl) = lagrange(zs, 2.0 * (x3 - mid) / h);
                Level { l: std::array::from_fn(|s| l[s]), dl: std::array::from_fn(|s| 2.0 * dl[s] / h), x3: x3 - mid, weight: w * half, law }
            })
            .collect()
    }
}

/// The 3D elastic law of a level, in the element's local frame.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Law {
    /// S = lambda tr(E) I + 2 mu E.
    Isotropic { lambda: f64, mu: f64 },
    /// S = C E, Voigt order [11, 22, 33, 23, 13, 12], engineering shear strains.
    General(Stiffness),
}

impl Law {
    /// S = C E.
    #[inline(always)]
    pub(crate) fn stress(&self, e: &[f64; NVOIGT]) -> [f64; NVOIGT] {
        match self {
            Law::Isotropic { lambda, mu } => stress(*lambda, *mu, e),
            Law::General(c) => std::array::from_fn(|i| (0..NVOIGT).map(|j| c[i][j] * e[j]).sum()),
        }
    }

    /// cb = w C B for the six rows `r` = dE/dV of one point.
    #[inline(always)]
    fn apply_rows<const D: usize>(&self, w: f64, r: &[[f64; D]], cb: &mut [[f64; D]]) {
        match self {
            Law::Isotropic { lambda, mu } => {
                let (l, m) = (w * lambda, w * mu);
                for i in 0..D {
                    let tr = r[0][i] + r[1][i] + r[2][i];
                    cb[0][i] = l * tr + 2.0 * m * r[0][i];
                    cb[1][i] = l * tr + 2.0 * m * r[1][i];
                    cb[2][i] = l * tr + 2.0 * m * r[2][i];
                    cb[3][i] = m * r[3][i];
                    cb[4][i] = m * r[4][i];
                    cb[5][i] = m * r[5][i];
                }
            }
            Law::General(c) => {
                for a in 0..NVOIGT {
                    let row = &mut cb[a];
                    row.fill(0.0);
                    for b in 0..NVOIGT {
                        let f = w * c[a][b];
                        if f != 0.0 {
                            axpy(row, f, &r[b]);
                        }
                    }
                }
            }
        }
    }
}

/// The resultants of the section at the element centre, in its local frame: membrane forces
/// N_ab = int S_ab dx3, moments M_ab = int S_ab (x3 - x3m) dx3, shear forces Q_a = int S_a3 dx3 and
/// T33 = int S33 dx3 (second Piola-Kirchhoff stresses).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Resultants {
    pub n: [f64; 3],
    pub m: [f64; 3],
    pub q: [f64; 2],
    pub t33: f64,
}

/// Per-thread scratch memory.
pub struct MultiSurfaceWorkspace<const P: usize, const D: usize> {
    samples: Vec<Sample<P, D>>,
    /// Per level and Gauss point, the six rows dE/dV, and the same times w C.
    b: Vec<[f64; D]>,
    cb: Vec<[f64; D]>,
    /// Weights of the sample gradients in the residual and of their Hessians in the tangent.
    mu: Vec<f64>,
    /// The samples' values linearised about a reference state (only `val` is used; see
    /// [`Element::evaluate_about`]).
    linear: Vec<Sample<P, D>>,
    pub(crate) volume_ratio: f64,
    /// Per level and Gauss point of the last evaluation of a plastic plate: the state it would
    /// commit (see [`crate::plasticity::points`]).
    pub(crate) trial: Vec<PlasticState>,
    /// Set when a plastic point's strain was not admissible (I + 2E not positive definite).
    pub(crate) bad_strain: bool,
    /// Scratch for the plastic laws' yield functions in the element's frame.
    bases: Vec<YieldBasis>,
}

impl<const P: usize, const D: usize> MultiSurfaceWorkspace<P, D> {
    pub(crate) fn samples(&self) -> &[Sample<P, D>] {
        &self.samples
    }
}

/// The N-surface plate elements of a mesh; P = 4 N (node, surface) pairs and D = 12 N dofs per
/// element, node-major: pair N a + s is surface s at node a, local dof 3 (N a + s) + i its
/// component i.
pub struct MultiSurfacePlate<const N: usize, const P: usize, const D: usize> {
    cells: Vec<[usize; 4]>,
    geometry: Geometries,
    levels: Vec<Level<N>>,
    laws: Vec<Law>,
    section: Section,
    kinematics: Kinematics,
    /// The plastic layers' laws and their points' history, for an elastic-plastic plate.
    plastic: Option<PlasticPoints>,
}

impl<const N: usize, const P: usize, const D: usize> MultiSurfacePlate<N, P, D> {
    /// Unknowns per node.
    pub const DOFS_PER_NODE: usize = 3 * N;

    /// Elements on every cell of `mesh`. The section's `shear_factor` and `normal_stress` belong to
    /// the paper's plate and must be left at their defaults: this plate has the full 3D law.
    pub fn new(mesh: &QuadMesh, section: Section, kinematics: Kinematics) -> Result<Self> {
        assert!((3..=5).contains(&N) && P == 4 * N && D == 12 * N, "a multi-surface plate has 3 to 5 surfaces, P = 4 N, D = 12 N");
        section.validate()?;
        mesh.validate()?;
        if section.shear_factor != 1.0 || section.normal_stress != NormalStress::Dropped {
            return Err(StampError::Material(
                "shear_factor and normal_stress are corrections of the two-surface plate; a plate of more surfaces has the full 3D law and takes neither".into(),
            ));
        }
        let geometry = (0..mesh.num_cells()).map(|c| ElementGeometry::new(&mesh.cell_coords(c), c)).collect::<Result<Vec<_>>>()?;
        let (levels, laws) = levels_of::<N>(&section);
        Ok(MultiSurfacePlate { cells: mesh.cells.clone(), geometry: Geometries::new(geometry), levels, laws, section, kinematics, plastic: None })
    }

    /// The plate with the layers' `plasticity` (one entry per layer of the section; None keeps a
    /// layer elastic): von Mises or Hill yield functions with isotropic hardening at finite strain
    /// ([`crate::plasticity`]; the linear kinematics takes the strains for the logarithmic ones).
    /// Every point starts from the virgin state. A plastic layer is integrated over
    /// [`PLASTIC_SUBLAYERS`] sub-layers, which [`MultiSurfacePlate::section`] then lists.
    pub fn with_plasticity(mut self, plasticity: &[Option<Plasticity>]) -> Result<Self> {
        if plasticity.len() != self.section.layers.len() {
            return Err(StampError::Material(format!("{} plasticity entries for {} layers", plasticity.len(), self.section.layers.len())));
        }
        if plasticity.iter().all(Option::is_none) {
            return Ok(self);
        }
        // each plastic layer integrated over PLASTIC_SUBLAYERS sub-layers of N levels
        let mut layers = Vec::new();
        let mut per_layer = Vec::new();
        for (layer, p) in self.section.layers.iter().zip(plasticity) {
            let parts = if p.is_some() { PLASTIC_SUBLAYERS } else { 1 };
            let t = (layer.top - layer.bottom) / parts as f64;
            for k in 0..parts {
                let top = if k + 1 == parts { layer.top } else { layer.bottom + (k + 1) as f64 * t };
                layers.push(crate::material::Layer { bottom: layer.bottom + k as f64 * t, top, material: layer.material });
                per_layer.push(p.clone());
            }
        }
        self.section.layers = layers;
        (self.levels, self.laws) = levels_of::<N>(&self.section);
        let plasticity = &per_layer[..];
        let lame: Vec<(f64, f64)> = self.section.layers.iter().map(|l| (l.material.lame_lambda(), l.material.shear_modulus())).collect();
        self.plastic = Some(PlasticPoints::new(plasticity, &lame, self.cells.len(), self.levels.len(), self.kinematics == Kinematics::Nonlinear)?);
        Ok(self)
    }

    /// The plastic points, for an elastic-plastic plate.
    pub fn plastic_points(&self) -> Option<&PlasticPoints> {
        self.plastic.as_ref()
    }

    /// What element `e`'s kernel reads of the plastic points: `quadratics` is scratch for the
    /// yield functions in its frame.
    fn element_plasticity<'a>(&'a self, e: usize, quadratics: &'a mut Vec<YieldBasis>) -> Option<ElementPlasticity<'a>> {
        let p = self.plastic.as_ref()?;
        let geo = &self.geometry[e];
        p.quadratics_into(geo.frame[0][1].atan2(geo.frame[0][0]), quadratics);
        Some(ElementPlasticity { laws: &p.laws, quadratics, committed: p.of_element(e), finite: p.finite })
    }

    /// The equivalent plastic strain and the yield state (whether it flowed in the last converged
    /// step) at `x3` from the middle of the section at the four Gauss points of element `e`: the
    /// converged states of the layer's levels interpolated through its thickness (a polynomial
    /// through its N levels, extrapolated to its faces), the return map from there at the
    /// element's strain at `x3`, so that the stresses of [`MultiSurfacePlate::stresses_at`] lie on
    /// or inside the yield surface; the yield state is the nearest level's. None for an elastic
    /// plate or layer.
    pub fn plastic_strain_at(&self, e: usize, x3: f64, v: &[f64], ws: &mut MultiSurfaceWorkspace<P, D>) -> Option<[(f64, bool); 4]> {
        let r = self.plastic_point_at(e, x3, v, ws)?;
        let p = self.plastic.as_ref()?;
        let states = p.of_element(e);
        let mid = 0.5 * (self.section.delta_minus + self.section.delta_plus);
        let k = self.section.layers.iter().rposition(|l| x3 + mid >= l.bottom).unwrap_or(0);
        let nearest = (0..self.levels.len()).filter(|&q| self.levels[q].law == k).min_by(|&a, &b| (self.levels[a].x3 - x3).abs().total_cmp(&(self.levels[b].x3 - x3).abs()))?;
        Some(std::array::from_fn(|g| (r[g].state.ep, states[4 * nearest + g].active)))
    }

    /// The plastic answer at `x3` (see [`MultiSurfacePlate::plastic_strain_at`]), None where the
    /// plate or the layer is elastic.
    fn plastic_point_at(&self, e: usize, x3: f64, v: &[f64], ws: &mut MultiSurfaceWorkspace<P, D>) -> Option<[crate::plasticity::law::PointResponse; 4]> {
        let p = self.plastic.as_ref()?;
        let h = self.section.thickness();
        let mid = 0.5 * (self.section.delta_minus + self.section.delta_plus);
        let k = self.section.layers.iter().rposition(|l| x3 + mid >= l.bottom).unwrap_or(0);
        let law = p.laws[k].as_ref()?;
        let geo = &self.geometry[e];
        let m = law.quadratic_in(geo.frame[0][1].atan2(geo.frame[0][0]));
        // the layer's levels and the Lagrange weights of x3 among them
        let own: Vec<usize> = (0..self.levels.len()).filter(|&q| self.levels[q].law == k).collect();
        let xs: Vec<f64> = own.iter().map(|&q| self.levels[q].x3).collect();
        let weights: Vec<f64> = (0..xs.len()).map(|i| (0..xs.len()).filter(|&j| j != i).map(|j| (x3 - xs[j]) / (xs[i] - xs[j])).product()).collect();
        let states = p.of_element(e);
        let level = Level::<N>::at(x3, h, &surface_zetas(N), k);
        compute_samples(geo, std::slice::from_ref(&level), self.kinematics, v, ws);
        let samples = ws.samples();
        Some(std::array::from_fn(|g| {
            let mut st = PlasticState::default();
            for (&q, &w) in own.iter().zip(&weights) {
                let s = &states[4 * q + g];
                st.ep += w * s.ep;
                for i in 0..6 {
                    st.hp[i] += w * s.hp[i];
                }
            }
            st.ep = st.ep.max(0.0);
            let e6 = strain(geo, samples, 0, g);
            let r = if p.finite { law.respond(&e6, &st, &m) } else { law.respond_small(&e6, &st, &m) };
            // a strain with no logarithm (the state was refused, it is not a converged one)
            r.unwrap_or(crate::plasticity::law::PointResponse { stress: [f64::NAN; 6], tangent: [[f64::NAN; 6]; 6], state: st, yielding: false, log_strain: e6 })
        }))
    }

    pub fn section(&self) -> &Section {
        &self.section
    }
    pub fn kinematics(&self) -> Kinematics {
        self.kinematics
    }

    /// The resultants at the centre of element `e` at local dofs `v` (the mean over its Gauss
    /// points), for output.
    pub fn resultants(&self, e: usize, v: &[f64], ws: &mut MultiSurfaceWorkspace<P, D>) -> Resultants {
        let mut r = Resultants::default();
        let mut quadratics = std::mem::take(&mut ws.bases);
        let plastic = self.element_plasticity(e, &mut quadratics);
        resultants_of(&self.geometry[e], &self.levels, &self.laws, plastic.as_ref(), self.kinematics, v, ws, &mut r);
        drop(plastic);
        ws.bases = quadratics;
        r
    }

    /// The six stresses (second Piola-Kirchhoff, Voigt order [11, 22, 33, 23, 13, 12]) in the
    /// plate's axes x1, x2, x3 at `x3` from the middle of the section at the four Gauss points of
    /// element `e`, by the 3D law of the section's layer there from the element's strains (the
    /// assumed strains, as [`crate::LaminatePlate::stresses_at`]); their mean is the value at the
    /// element's centre.
    pub fn stresses_at(&self, e: usize, x3: f64, v: &[f64], ws: &mut MultiSurfaceWorkspace<P, D>) -> [[f64; 6]; 4] {
        let h = self.section.thickness();
        let mid = 0.5 * (self.section.delta_minus + self.section.delta_plus);
        let level = Level::<N>::at(x3, h, &surface_zetas(N), 0);
        let geo = &self.geometry[e];
        compute_samples(geo, std::slice::from_ref(&level), self.kinematics, v, ws);
        let k = self.section.layers.iter().rposition(|l| x3 + mid >= l.bottom).unwrap_or(0);
        let law = self.laws[k];
        let angle = geo.frame[0][1].atan2(geo.frame[0][0]);
        let elastic: [[f64; 6]; 4] = std::array::from_fn(|g| law.stress(&strain(geo, ws.samples(), 0, g)));
        let local = match self.plastic_point_at(e, x3, v, ws) {
            Some(r) => r.map(|r| r.stress),
            None => elastic,
        };
        local.map(|s| crate::orthotropic::rotate_stress(&s, -angle))
    }

    /// The smallest volume ratio det[g1, g2, g3] / det[G1, G2, G3] over the integration points of
    /// element `e` at local dofs `v` (1 in the reference state and under any rigid motion; <= 0 once
    /// the element turned inside out).
    pub fn smallest_volume_ratio(&self, e: usize, v: &[f64], ws: &mut MultiSurfaceWorkspace<P, D>) -> f64 {
        compute_samples(&self.geometry[e], &self.levels, self.kinematics, v, ws);
        ws.volume_ratio
    }
}

/// The integration levels of a section (N per layer) and the laws of its layers.
fn levels_of<const N: usize>(section: &Section) -> (Vec<Level<N>>, Vec<Law>) {
    let h = section.thickness();
    let mid = 0.5 * (section.delta_minus + section.delta_plus);
    let zs = surface_zetas(N);
    let mut levels = Vec::new();
    let mut laws = Vec::new();
    for (k, layer) in section.layers.iter().enumerate() {
        laws.push(Law::Isotropic { lambda: layer.material.lame_lambda(), mu: layer.material.shear_modulus() });
        levels.extend(Level::<N>::of_layer(layer.bottom, layer.top, mid, h, &zs, k));
    }
    (levels, laws)
}

/// The in-plane tangent g0 + u_,i at a level: `dn` the shape-function derivatives, `l` the
/// through-thickness functions.
#[inline(always)]
fn tangent<const N: usize, const P: usize>(g0: [f64; 2], dn: [f64; 4], l: &[f64; N], v: &[f64]) -> Affine<P> {
    let mut c = [0.0; P];
    for a in 0..4 {
        for s in 0..N {
            c[N * a + s] = dn[a] * l[s];
        }
    }
    Affine::new([g0[0], g0[1], 0.0], c, v)
}

/// The transverse base vector e3 + u_,3 at a level, `n` the shape functions at the point.
#[inline(always)]
fn transverse<const N: usize, const P: usize>(n: &[f64; 4], dl: &[f64; N], v: &[f64]) -> Affine<P> {
    let mut c = [0.0; P];
    for a in 0..4 {
        for s in 0..N {
            c[N * a + s] = n[a] * dl[s];
        }
    }
    Affine::new([0.0, 0.0, 1.0], c, v)
}

/// Every displacement-based strain sample of an element of geometry `geo` at local dofs `v` at
/// the `levels`, and the smallest volume ratio det[g1, g2, g3] / det[G1, G2, G3] at the
/// integration points.
pub(crate) fn compute_samples<const N: usize, const P: usize, const D: usize>(
    geo: &ElementGeometry,
    levels: &[Level<N>],
    kinematics: Kinematics,
    v: &[f64],
    ws: &mut MultiSurfaceWorkspace<P, D>,
) {
    let full = kinematics == Kinematics::Nonlinear;
    let reference = geo.frame[0][0] * geo.frame[1][1] - geo.frame[0][1] * geo.frame[1][0];
    let mut volume_ratio = f64::INFINITY;
    for (q, lv) in levels.iter().enumerate() {
        let s = &mut ws.samples[q * PER_LEVEL..(q + 1) * PER_LEVEL];
        for g in 0..4 {
            let dn = geo.dndy[g];
            let g1 = tangent::<N, P>(geo.frame[0], [dn[0][0], dn[1][0], dn[2][0], dn[3][0]], &lv.l, v);
            let g2 = tangent::<N, P>(geo.frame[1], [dn[0][1], dn[1][1], dn[2][1], dn[3][1]], &lv.l, v);
            let g3 = transverse::<N, P>(&geo.n[g], &lv.dl, v);
            volume_ratio = volume_ratio.min(triple(&g1.g, &g2.g, &g3.g) / reference);
            s[4 * g].set(full, 0.5, &g1, &g1);
            s[4 * g + 1].set(full, 0.5, &g2, &g2);
            s[4 * g + 2].set(full, 1.0, &g1, &g2);
            s[4 * g + 3].set(full, 0.5, &g3, &g3);
        }
        for (t, sp) in geo.tying.iter().enumerate() {
            let gt = tangent::<N, P>(sp.base, sp.dn, &lv.l, v);
            let g3 = transverse::<N, P>(&sp.n, &lv.dl, v);
            s[TYING_SAMPLE + t].set(full, 1.0, &gt, &g3);
        }
    }
    ws.volume_ratio = volume_ratio;
}

/// The (sample within the level, coefficient) terms of strain component `c` (Voigt order) at
/// Gauss point `g`: the paper's projections of the membrane strains, the tying interpolation
/// of the transverse shear (as in [`crate::plate`]).
fn terms(geo: &ElementGeometry, g: usize, c: usize) -> ([(usize, f64); 4], usize) {
    let mut t = [(0, 0.0); 4];
    let mut n = 0;
    let mut push = |s: usize, w: f64| {
        if w != 0.0 {
            t[n] = (s, w);
            n += 1;
        }
    };
    match c {
        0 | 1 | 5 => {
            // E11 over its row, E22 over its column, 2E12 over all four Gauss points
            let (kind, comp) = match c {
                0 => (0, 0),
                1 => (1, 1),
                _ => (2, 2),
            };
            for h in 0..4 {
                push(4 * h + comp, geo.proj[kind][g][h]);
            }
        }
        2 => {
            // E33: its mean over the element plus E33_STABILISATION times the rest
            for h in 0..4 {
                let own = if h == g { E33_STABILISATION } else { 0.0 };
                push(4 * h + 3, (1.0 - E33_STABILISATION) * geo.proj[2][g][h] + own);
            }
        }
        _ => {
            // 2E23 (c = 3, local row 1) or 2E13 (c = 4, row 0) from the covariant shear
            let row = if c == 4 { 0 } else { 1 };
            let [x1, x2] = GAUSS_POINTS[g];
            for (a, (tp, xi)) in [(0usize, x2), (2usize, x1)].into_iter().enumerate() {
                let w = geo.jit[g][row][a];
                push(TYING_SAMPLE + tp, w * 0.5 * (1.0 - xi));
                push(TYING_SAMPLE + tp + 1, w * 0.5 * (1.0 + xi));
            }
        }
    }
    (t, n)
}

/// The strains [E11, E22, E33, 2E23, 2E13, 2E12] at Gauss point g of level q from the samples.
pub(crate) fn strain<const P: usize, const D: usize>(geo: &ElementGeometry, samples: &[Sample<P, D>], q: usize, g: usize) -> [f64; NVOIGT] {
    std::array::from_fn(|c| {
        let (t, n) = terms(geo, g, c);
        t[..n].iter().map(|&(s, w)| w * samples[q * PER_LEVEL + s].val).sum()
    })
}

/// Adds the resultants of the `levels` (membrane forces, moments about the levels' x3 = 0, shear
/// forces, T33) at the element's centre, the mean over its Gauss points, to `r`.
pub(crate) fn resultants_of<const N: usize, const P: usize, const D: usize>(
    geo: &ElementGeometry,
    levels: &[Level<N>],
    laws: &[Law],
    plastic: Option<&ElementPlasticity>,
    kinematics: Kinematics,
    v: &[f64],
    ws: &mut MultiSurfaceWorkspace<P, D>,
    r: &mut Resultants,
) {
    compute_samples(geo, levels, kinematics, v, ws);
    for (q, lv) in levels.iter().enumerate() {
        for g in 0..4 {
            let e = strain(geo, &ws.samples, q, g);
            let s = match plastic.and_then(|p| p.respond(lv.law, 4 * q + g, &e, false)) {
                Some(Some(r)) => r.stress,
                _ => laws[lv.law].stress(&e),
            };
            let w = 0.25 * lv.weight;
            for (k, c) in [0, 1, 5].into_iter().enumerate() {
                r.n[k] += w * s[c];
                r.m[k] += w * s[c] * lv.x3;
            }
            r.q[0] += w * s[4];
            r.q[1] += w * s[3];
            r.t33 += w * s[2];
        }
    }
}

/// S = C E of the 3D isotropic law, Voigt order [11, 22, 33, 23, 13, 12] with engineering shear
/// strains.
#[inline(always)]
fn stress(l: f64, m: f64, e: &[f64; NVOIGT]) -> [f64; NVOIGT] {
    let tr = e[0] + e[1] + e[2];
    [l * tr + 2.0 * m * e[0], l * tr + 2.0 * m * e[1], l * tr + 2.0 * m * e[2], m * e[3], m * e[4], m * e[5]]
}

/// A workspace for `levels` integration levels.
pub(crate) fn workspace<const P: usize, const D: usize>(levels: usize) -> MultiSurfaceWorkspace<P, D> {
    MultiSurfaceWorkspace {
        samples: vec![Sample::default(); levels * PER_LEVEL],
        b: vec![[0.0; D]; levels * 4 * NVOIGT],
        cb: vec![[0.0; D]; levels * 4 * NVOIGT],
        mu: vec![0.0; levels * PER_LEVEL],
        linear: vec![Sample::default(); levels * PER_LEVEL],
        volume_ratio: 1.0,
        trial: vec![PlasticState::default(); levels * 4],
        bad_strain: false,
        bases: Vec::new(),
    }
}

/// The element of geometry `geo` over the `levels` at local dofs `v`: adds its internal force to
/// `residual` (D), its energy to `energy` and, `with_tangent`, its tangent to `tangent` (D x D,
/// row-major). Leaves the smallest volume ratio in `ws.volume_ratio`.
#[allow(clippy::too_many_arguments)]
pub(crate) fn evaluate_levels<const N: usize, const P: usize, const D: usize>(
    geo: &ElementGeometry,
    levels: &[Level<N>],
    laws: &[Law],
    kinematics: Kinematics,
    v: &[f64],
    reference: Option<&[f64]>,
    plastic: Option<&ElementPlasticity>,
    ws: &mut MultiSurfaceWorkspace<P, D>,
    residual_out: &mut [f64],
    tangent_out: &mut [f64],
    energy: &mut f64,
    with_tangent: bool,
) {
    compute_samples(geo, levels, kinematics, v, ws);
    let MultiSurfaceWorkspace { samples, b, cb, mu, linear, trial, bad_strain, .. } = ws;
    *bad_strain = false;
    mu.fill(0.0);
    for (q, lv) in levels.iter().enumerate() {
        for g in 0..4 {
            let w = geo.wdet[g] * lv.weight;
            let strain = strain(geo, samples, q, g);
            // an elastic level's law, or a plastic point's answer from its converged state
            let response = plastic.and_then(|p| p.respond(lv.law, 4 * q + g, &strain, with_tangent));
            let law = match response {
                None => laws[lv.law],
                Some(Some(r)) => {
                    trial[4 * q + g] = r.state;
                    Law::General(r.tangent)
                }
                Some(None) => {
                    *bad_strain = true;
                    laws[lv.law]
                }
            };
            let s = match response {
                Some(Some(r)) => r.stress,
                _ => law.stress(&strain),
            };
            *energy += 0.5 * w * (0..NVOIGT).map(|c| strain[c] * s[c]).sum::<f64>();
            let rows = (q * 4 + g) * NVOIGT;
            for c in 0..NVOIGT {
                let (t, n) = terms(geo, g, c);
                let mut row = [0.0; D];
                for &(smp, coef) in &t[..n] {
                    let k = q * PER_LEVEL + smp;
                    mu[k] += w * s[c] * coef;
                    if with_tangent {
                        axpy(&mut row, coef, &samples[k].grad);
                    }
                }
                b[rows + c] = row;
            }
            if with_tangent {
                // w C B: the law applied to the rows
                law.apply_rows(w, &b[rows..rows + NVOIGT], &mut cb[rows..rows + NVOIGT]);
            }
        }
    }
    let mut residual = [0.0; D];
    for (k, smp) in samples.iter().enumerate() {
        if mu[k] != 0.0 {
            axpy(&mut residual, mu[k], &smp.grad);
        }
    }
    for (r, x) in residual_out.iter_mut().zip(residual) {
        *r += x;
    }
    if !with_tangent {
        return;
    }
    // material stiffness: B^T (w C B) over all rows, one D x rows x D product
    let rows = b.len();
    let bm = MatRef::from_row_major_slice(b.as_flattened(), rows, D);
    let cbm = MatRef::from_row_major_slice(cb.as_flattened(), rows, D);
    let k = MatMut::from_row_major_slice_mut(&mut tangent_out[..D * D], D, D);
    matmul(k, Accum::Add, bm.transpose(), cbm, 1.0, Par::Seq);
    clean_upper_vector_state();
    // geometric stiffness: sum_s mu_s scale_s (a b^T + b a^T) (x) I3
    if kinematics == Kinematics::Nonlinear {
        if let Some(reference) = reference {
            linearised_weights(geo, levels, laws, plastic, v, reference, samples, mu, linear);
        }
        let mut x = [[0.0; P]; P];
        for (k, smp) in samples.iter().enumerate() {
            let f = mu[k] * smp.scale;
            if f == 0.0 {
                continue;
            }
            for p in 0..P {
                let fa = f * smp.a[p];
                if fa != 0.0 {
                    for l in 0..P {
                        x[p][l] += fa * smp.b[l];
                    }
                }
            }
        }
        add_geometric_stiffness(&x, tangent_out);
    }
}

/// The weights mu of the geometric stiffness with the stresses of the strains linearised about
/// `reference` (see [`Element::evaluate_about`]): every sample's value less its quadratic
/// remainder in v - reference ([`Sample::remainder`]), through the levels' laws.
#[allow(clippy::too_many_arguments)]
fn linearised_weights<const N: usize, const P: usize, const D: usize>(
    geo: &ElementGeometry,
    levels: &[Level<N>],
    laws: &[Law],
    plastic: Option<&ElementPlasticity>,
    v: &[f64],
    reference: &[f64],
    samples: &[Sample<P, D>],
    mu: &mut [f64],
    linear: &mut [Sample<P, D>],
) {
    let mut dv = [0.0; D];
    for (k, x) in dv.iter_mut().enumerate() {
        *x = v[k] - reference[k];
    }
    for (l, s) in linear.iter_mut().zip(samples) {
        l.val = s.val - s.remainder(&dv);
    }
    mu.fill(0.0);
    for (q, lv) in levels.iter().enumerate() {
        let law = &laws[lv.law];
        for g in 0..4 {
            let w = geo.wdet[g] * lv.weight;
            let e = strain(geo, linear, q, g);
            let s = match plastic.and_then(|p| p.respond(lv.law, 4 * q + g, &e, false)) {
                Some(Some(r)) => r.stress,
                _ => law.stress(&e),
            };
            for c in 0..NVOIGT {
                let (t, n) = terms(geo, g, c);
                for &(smp, coef) in &t[..n] {
                    mu[q * PER_LEVEL + smp] += w * s[c] * coef;
                }
            }
        }
    }
}

/// The message of an element turned inside out.
pub(crate) fn inside_out(volume_ratio: f64) -> String {
    format!("it turned inside out (smallest volume ratio det[g1, g2, g3] / det[G1, G2, G3] at an integration point: {volume_ratio:.3e})")
}

impl<const N: usize, const P: usize, const D: usize> Element for MultiSurfacePlate<N, P, D> {
    type Workspace = MultiSurfaceWorkspace<P, D>;

    fn retain_elements(&mut self, keep: &[bool]) {
        self.geometry.retain(keep);
    }
    fn dofs_per_node(&self) -> usize {
        Self::DOFS_PER_NODE
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
    fn new_workspace(&self) -> MultiSurfaceWorkspace<P, D> {
        workspace(self.levels.len())
    }

    /// The nonlinear element refuses a state in which it turned inside out (it still computes the
    /// residual and tangent there); the linear theory has no such limit.
    fn evaluate(&self, e: usize, v: &[f64], ws: &mut MultiSurfaceWorkspace<P, D>, out: &mut LocalSystem, with_tangent: bool) {
        self.evaluate_from(e, v, None, ws, out, with_tangent);
    }

    /// The geometric stiffness from the stresses of the strains linearised about `reference`.
    fn evaluate_about(&self, e: usize, v: &[f64], reference: &[f64], ws: &mut MultiSurfaceWorkspace<P, D>, out: &mut LocalSystem, with_tangent: bool) {
        self.evaluate_from(e, v, Some(reference), ws, out, with_tangent);
    }

    fn has_history(&self) -> bool {
        self.plastic.is_some()
    }

    /// The plastic points' states at the converged `v` become their history.
    fn commit(&mut self, e: usize, v: &[f64], ws: &mut MultiSurfaceWorkspace<P, D>) {
        if self.plastic.is_none() {
            return;
        }
        let mut out = LocalSystem::new(D);
        self.evaluate_from(e, v, None, ws, &mut out, false);
        let p = self.plastic.as_mut().expect("checked");
        let n = p.levels * 4;
        for (k, st) in p.states[e * n..(e + 1) * n].iter_mut().enumerate() {
            if p.laws[self.levels[k / 4].law].is_some() {
                *st = ws.trial[k];
            }
        }
    }
}

impl<const N: usize, const P: usize, const D: usize> MultiSurfacePlate<N, P, D> {
    /// [`Element::evaluate`] and [`Element::evaluate_about`].
    fn evaluate_from(&self, e: usize, v: &[f64], reference: Option<&[f64]>, ws: &mut MultiSurfaceWorkspace<P, D>, out: &mut LocalSystem, with_tangent: bool) {
        let LocalSystem { residual, tangent, energy, .. } = out;
        let mut quadratics = std::mem::take(&mut ws.bases);
        let plastic = self.element_plasticity(e, &mut quadratics);
        evaluate_levels(&self.geometry[e], &self.levels, &self.laws, self.kinematics, v, reference, plastic.as_ref(), ws, residual, tangent, energy, with_tangent);
        drop(plastic);
        ws.bases = quadratics;
        if self.kinematics == Kinematics::Nonlinear && ws.volume_ratio <= 0.0 {
            out.inadmissible = Some(inside_out(ws.volume_ratio));
        } else if ws.bad_strain {
            out.inadmissible = Some("a plastic point's strain has I + 2E not positive definite (no logarithmic strain)".into());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Lagrange functions are 1 at their own surface and 0 at the others, sum to 1, and their
    /// derivatives match central differences.
    #[test]
    fn lagrange_functions_interpolate_the_surfaces() {
        for n in 3..=5 {
            let zs = surface_zetas(n);
            assert_eq!((zs[0], zs[1]), (-1.0, 1.0));
            for (k, &z) in zs.iter().enumerate() {
                let (l, _) = lagrange(&zs, z);
                for (s, &ls) in l.iter().enumerate() {
                    assert!((ls - (s == k) as u8 as f64).abs() < 1e-14, "n = {n}: L_{s}({z}) = {ls}");
                }
            }
            let z = 0.3;
            let (l, dl) = lagrange(&zs, z);
            assert!((l.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for s in 0..n {
                let fd = (lagrange(&zs, z + 1e-6).0[s] - lagrange(&zs, z - 1e-6).0[s]) / 2e-6;
                assert!((fd - dl[s]).abs() < 1e-8, "n = {n}, s = {s}: dL = {} against {fd}", dl[s]);
            }
        }
    }
}

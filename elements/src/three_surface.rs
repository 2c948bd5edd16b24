//! The three-surface plate: the paper's plate (section 1) with a third surface, the mid-plane,
//! between its two faces, as a second stamp [`Element`]. Unknowns per node: the nine displacements
//! [v1-, v2-, v3-, v1+, v2+, v3+, v1_0, v2_0, v3_0] of the face planes S-, S+ (at the same places as
//! in the paper's element, so that contact and loads on a face see the same dofs) and of the
//! mid-plane S0.
//!
//! The displacement is quadratic through the thickness instead of linear (the paper's eq. 1.1 with
//! one more term): with zeta = 2 (x3 - x3m) / h in [-1, 1] and the quadratic Lagrange functions
//! L-(zeta) = zeta (zeta - 1) / 2, L0 = 1 - zeta^2, L+ = zeta (zeta + 1) / 2,
//!
//!   u(x1, x2, x3) = L-(zeta) v- + L0(zeta) v0 + L+(zeta) v+.
//!
//! So the transverse shear strain may take its parabolic profile (no shear correction factor), the
//! thickness may change across the section (E33 linear in x3, local indentation under a punch),
//! and the full 3D Saint Venant-Kirchhoff law S = lambda tr(E) I + 2 mu E holds at every point:
//! no plane-stress reduction and no b_ab33 = 0 (SPEC section 2), because a linear E33 can follow
//! the linear in-plane strains of bending and the Poisson locking that b_ab33 = 0 cures in the
//! paper's plate does not arise. The paper's plate is the case of two surfaces.
//!
//! Strains are exact Green-Lagrange strains 2 E_ij = g_i . g_j - G_i . G_j of base vectors affine
//! in the nodal displacements ([`crate::strain`]), so any rigid-body motion gives zero strain
//! exactly (a rigid motion is linear in x3 and the quadratic interpolation reproduces it,
//! eqs. 1.6-1.8 of the paper). The element uses the paper's assumed strains at every level
//! through the thickness (section 4, eqs. 4.4-4.5, see [`crate::geometry`]): E11 projected on
//! {1, xi2}, E22 on {1, xi1}, E12 on {1}, E33 on the bilinear functions, and the transverse shear
//! interpolated between the covariant strains at the edge midpoints (the tying form the paper's
//! element uses on non-parallelograms). The residual is int (dE/dV)^T S dV, the tangent
//! int (dE/dV)^T C (dE/dV) + S : d2E/dV2 dV (exact, symmetric). Through the thickness each layer
//! is integrated by three Gauss points, in the plane by 2 x 2.

use crate::geometry::{ElementGeometry, GAUSS_POINTS};
use crate::material::{Isotropic, Section};
use crate::plate::Kinematics;
use crate::strain::{Affine, Sample};
use stamp::element::{Element, LocalSystem};
use stamp::mesh::QuadMesh;
use stamp::Result;

/// Dofs per node: v-_1, v-_2, v-_3, v+_1, v+_2, v+_3, v0_1, v0_2, v0_3.
pub const DOFS_PER_NODE: usize = 9;
/// (node, surface) pairs of an element: pair 3 a + s is surface s (0: S-, 1: S+, 2: S0) at node a.
const NPAIR: usize = 12;
/// Element dofs: local dof 3 k + i is component i of pair k (node-major, 9 per node).
const NDOF: usize = 36;
/// Strain samples per level through the thickness: E11, E22, 2E12, E33 at the four Gauss points,
/// then the covariant shear g_xi . g3 at the four tying points.
const PER_LEVEL: usize = 20;
const TYING_SAMPLE: usize = 16;
/// The strain vector at a point: [E11, E22, E33, 2E23, 2E13, 2E12] (local Cartesian frame).
const NVOIGT: usize = 6;

type Affine12 = Affine<NPAIR>;
type Sample12 = Sample<NPAIR, NDOF>;

/// Abscissae and weights of the three-point Gauss rule on [-1, 1].
const GAUSS3: [(f64, f64); 3] = [(-0.774_596_669_241_483_4, 5.0 / 9.0), (0.0, 8.0 / 9.0), (0.774_596_669_241_483_4, 5.0 / 9.0)];

/// The quadratic Lagrange functions of zeta [L-, L+, L0] (in the order of the surfaces in the dofs).
fn lagrange(z: f64) -> [f64; 3] {
    [0.5 * z * (z - 1.0), 0.5 * z * (z + 1.0), 1.0 - z * z]
}
/// Their derivatives d/dzeta.
fn lagrange_derivative(z: f64) -> [f64; 3] {
    [z - 0.5, z + 0.5, -2.0 * z]
}

/// One integration level through the thickness.
#[derive(Debug, Clone, Copy)]
struct Level {
    /// L_s(zeta) and dL_s/dx3 = (2 / h) dL_s/dzeta at this level.
    l: [f64; 3],
    dl: [f64; 3],
    /// Gauss weight times the length it stands for (sums to h).
    weight: f64,
    /// lambda, mu of the layer.
    lambda: f64,
    mu: f64,
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
pub struct ThreeSurfaceWorkspace {
    samples: Vec<Sample12>,
    /// Per level and Gauss point, the six rows dE/dV, and the same times w C.
    b: Vec<[f64; NDOF]>,
    cb: Vec<[f64; NDOF]>,
    /// Weights of the sample gradients in the residual and of their Hessians in the tangent.
    mu: Vec<f64>,
    volume_ratio: f64,
}

/// The three-surface plate elements of a mesh.
pub struct ThreeSurfacePlate {
    cells: Vec<[usize; 4]>,
    geometry: Vec<ElementGeometry>,
    levels: Vec<Level>,
    section: Section,
    kinematics: Kinematics,
}

impl ThreeSurfacePlate {
    /// Three-surface elements on every cell of `mesh`. The section's `shear_factor` and
    /// `normal_stress` belong to the paper's plate and must be left at their defaults: this plate
    /// has the full 3D law.
    pub fn new(mesh: &QuadMesh, section: Section, kinematics: Kinematics) -> Result<Self> {
        section.validate()?;
        mesh.validate()?;
        if section.shear_factor != 1.0 || section.normal_stress != crate::material::NormalStress::Dropped {
            return Err(stamp::StampError::Material(
                "shear_factor and normal_stress are corrections of the two-surface plate; the three-surface plate has the full 3D law and takes neither".into(),
            ));
        }
        let geometry = (0..mesh.num_cells()).map(|c| ElementGeometry::new(&mesh.cell_coords(c), c)).collect::<Result<Vec<_>>>()?;
        let h = section.thickness();
        let mid = 0.5 * (section.delta_minus + section.delta_plus);
        let mut levels = Vec::new();
        for layer in &section.layers {
            let (lambda, mu) = lame(&layer.material);
            let half = 0.5 * (layer.top - layer.bottom);
            let centre = 0.5 * (layer.top + layer.bottom);
            for &(x, w) in &GAUSS3 {
                let z = 2.0 * (centre + half * x - mid) / h;
                levels.push(Level { l: lagrange(z), dl: lagrange_derivative(z).map(|d| 2.0 * d / h), weight: w * half, lambda, mu });
            }
        }
        Ok(ThreeSurfacePlate { cells: mesh.cells.clone(), geometry, levels, section, kinematics })
    }

    pub fn section(&self) -> &Section {
        &self.section
    }
    pub fn kinematics(&self) -> Kinematics {
        self.kinematics
    }

    /// The in-plane tangent g0 + u_,i at a level: `dn` the shape-function derivatives, `l` the
    /// through-thickness functions.
    #[inline(always)]
    fn tangent(g0: [f64; 2], dn: [f64; 4], l: &[f64; 3], v: &[f64]) -> Affine12 {
        let mut c = [0.0; NPAIR];
        for a in 0..4 {
            for s in 0..3 {
                c[3 * a + s] = dn[a] * l[s];
            }
        }
        Affine::new([g0[0], g0[1], 0.0], c, v)
    }

    /// The transverse base vector e3 + u_,3 at a level, `n` the shape functions at the point.
    #[inline(always)]
    fn transverse(n: &[f64; 4], dl: &[f64; 3], v: &[f64]) -> Affine12 {
        let mut c = [0.0; NPAIR];
        for a in 0..4 {
            for s in 0..3 {
                c[3 * a + s] = n[a] * dl[s];
            }
        }
        Affine::new([0.0, 0.0, 1.0], c, v)
    }

    /// Every displacement-based strain sample of element e at local dofs `v`, and the smallest
    /// volume ratio det[g1, g2, g3] / det[G1, G2, G3] at the integration points.
    fn compute_samples(&self, e: usize, v: &[f64], ws: &mut ThreeSurfaceWorkspace) {
        let geo = &self.geometry[e];
        let full = self.kinematics == Kinematics::Nonlinear;
        let reference = geo.frame[0][0] * geo.frame[1][1] - geo.frame[0][1] * geo.frame[1][0];
        let mut volume_ratio = f64::INFINITY;
        for (q, lv) in self.levels.iter().enumerate() {
            let s = &mut ws.samples[q * PER_LEVEL..(q + 1) * PER_LEVEL];
            for g in 0..4 {
                let dn = geo.dndy[g];
                let g1 = Self::tangent(geo.frame[0], [dn[0][0], dn[1][0], dn[2][0], dn[3][0]], &lv.l, v);
                let g2 = Self::tangent(geo.frame[1], [dn[0][1], dn[1][1], dn[2][1], dn[3][1]], &lv.l, v);
                let g3 = Self::transverse(&geo.n[g], &lv.dl, v);
                volume_ratio = volume_ratio.min(triple(&g1.g, &g2.g, &g3.g) / reference);
                put(&mut s[4 * g], full, 0.5, &g1, &g1);
                put(&mut s[4 * g + 1], full, 0.5, &g2, &g2);
                put(&mut s[4 * g + 2], full, 1.0, &g1, &g2);
                put(&mut s[4 * g + 3], full, 0.5, &g3, &g3);
            }
            for (t, sp) in geo.tying.iter().enumerate() {
                let gt = Self::tangent(sp.base, sp.dn, &lv.l, v);
                let g3 = Self::transverse(&sp.n, &lv.dl, v);
                put(&mut s[TYING_SAMPLE + t], full, 1.0, &gt, &g3);
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
            2 => push(4 * g + 3, 1.0),
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
    fn strain(&self, geo: &ElementGeometry, samples: &[Sample12], q: usize, g: usize) -> [f64; NVOIGT] {
        std::array::from_fn(|c| {
            let (t, n) = Self::terms(geo, g, c);
            t[..n].iter().map(|&(s, w)| w * samples[q * PER_LEVEL + s].val).sum()
        })
    }

    /// The resultants at the centre of element `e` at local dofs `v` (the mean over its Gauss
    /// points), for output.
    pub fn resultants(&self, e: usize, v: &[f64], ws: &mut ThreeSurfaceWorkspace) -> Resultants {
        self.compute_samples(e, v, ws);
        let geo = &self.geometry[e];
        let h = self.section.thickness();
        let mut r = Resultants::default();
        for (q, lv) in self.levels.iter().enumerate() {
            // x3 - x3m of this level, from L+ - L- = zeta
            let x3 = 0.5 * h * (lv.l[1] - lv.l[0]);
            for g in 0..4 {
                let s = stress(lv, &self.strain(geo, &ws.samples, q, g));
                let w = 0.25 * lv.weight;
                for (k, c) in [0, 1, 5].into_iter().enumerate() {
                    r.n[k] += w * s[c];
                    r.m[k] += w * s[c] * x3;
                }
                r.q[0] += w * s[4];
                r.q[1] += w * s[3];
                r.t33 += w * s[2];
            }
        }
        r
    }

    /// The smallest volume ratio det[g1, g2, g3] / det[G1, G2, G3] over the integration points of
    /// element `e` at local dofs `v` (1 in the reference state and under any rigid motion; <= 0 once
    /// the element turned inside out).
    pub fn smallest_volume_ratio(&self, e: usize, v: &[f64], ws: &mut ThreeSurfaceWorkspace) -> f64 {
        self.compute_samples(e, v, ws);
        ws.volume_ratio
    }
}

/// lambda and mu of an isotropic material.
fn lame(m: &Isotropic) -> (f64, f64) {
    (m.lame_lambda(), m.shear_modulus())
}

/// S = C E of the 3D isotropic law, Voigt order [11, 22, 33, 23, 13, 12] with engineering shear
/// strains.
#[inline(always)]
fn stress(lv: &Level, e: &[f64; NVOIGT]) -> [f64; NVOIGT] {
    let tr = e[0] + e[1] + e[2];
    let (l, m) = (lv.lambda, lv.mu);
    [l * tr + 2.0 * m * e[0], l * tr + 2.0 * m * e[1], l * tr + 2.0 * m * e[2], m * e[3], m * e[4], m * e[5]]
}

/// a . (b x c)
fn triple(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> f64 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) + a[1] * (b[2] * c[0] - b[0] * c[2]) + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// The strain s gA . gB - its reference value, full (Green-Lagrange) or linear part.
#[inline(always)]
fn put(sample: &mut Sample12, full: bool, scale: f64, a: &Affine12, b: &Affine12) {
    if full {
        sample.quadratic(scale, a, b)
    } else {
        sample.linear(scale, a, b)
    }
}

impl Element for ThreeSurfacePlate {
    type Workspace = ThreeSurfaceWorkspace;

    fn dofs_per_node(&self) -> usize {
        DOFS_PER_NODE
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
    fn new_workspace(&self) -> ThreeSurfaceWorkspace {
        let nq = self.levels.len();
        ThreeSurfaceWorkspace {
            samples: vec![Sample12::default(); nq * PER_LEVEL],
            b: vec![[0.0; NDOF]; nq * 4 * NVOIGT],
            cb: vec![[0.0; NDOF]; nq * 4 * NVOIGT],
            mu: vec![0.0; nq * PER_LEVEL],
            volume_ratio: 1.0,
        }
    }

    /// The nonlinear element refuses a state in which it turned inside out (it still computes the
    /// residual and tangent there); the linear theory has no such limit.
    fn evaluate(&self, e: usize, v: &[f64], ws: &mut ThreeSurfaceWorkspace, out: &mut LocalSystem, with_tangent: bool) {
        self.compute_samples(e, v, ws);
        if self.kinematics == Kinematics::Nonlinear && ws.volume_ratio <= 0.0 {
            out.inadmissible = Some(format!(
                "it turned inside out (smallest volume ratio det[g1, g2, g3] / det[G1, G2, G3] at an integration point: {:.3e})",
                ws.volume_ratio
            ));
        }
        let geo = &self.geometry[e];
        let ThreeSurfaceWorkspace { samples, b, cb, mu, .. } = ws;
        mu.fill(0.0);
        for (q, lv) in self.levels.iter().enumerate() {
            for g in 0..4 {
                let w = geo.wdet[g] * lv.weight;
                let strain = self.strain(geo, samples, q, g);
                let s = stress(lv, &strain);
                out.energy += 0.5 * w * (0..NVOIGT).map(|c| strain[c] * s[c]).sum::<f64>();
                let rows = (q * 4 + g) * NVOIGT;
                for c in 0..NVOIGT {
                    let (t, n) = Self::terms(geo, g, c);
                    let mut row = [0.0; NDOF];
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
                    // w C B: the isotropic law applied to the rows
                    let r = &b[rows..rows + NVOIGT];
                    let (l, m) = (w * lv.lambda, w * lv.mu);
                    for i in 0..NDOF {
                        let tr = r[0][i] + r[1][i] + r[2][i];
                        cb[rows][i] = l * tr + 2.0 * m * r[0][i];
                        cb[rows + 1][i] = l * tr + 2.0 * m * r[1][i];
                        cb[rows + 2][i] = l * tr + 2.0 * m * r[2][i];
                        cb[rows + 3][i] = m * r[3][i];
                        cb[rows + 4][i] = m * r[4][i];
                        cb[rows + 5][i] = m * r[5][i];
                    }
                }
            }
        }
        let mut residual = [0.0; NDOF];
        for (k, smp) in samples.iter().enumerate() {
            if mu[k] != 0.0 {
                axpy(&mut residual, mu[k], &smp.grad);
            }
        }
        for (r, x) in out.residual.iter_mut().zip(residual) {
            *r += x;
        }
        if !with_tangent {
            return;
        }
        // material stiffness sum over the rows of B^T (w C B)
        let k = &mut out.tangent[..NDOF * NDOF];
        for (br, cr) in b.iter().zip(cb.iter()) {
            for i in 0..NDOF {
                let bi = br[i];
                if bi != 0.0 {
                    let row = &mut k[i * NDOF..(i + 1) * NDOF];
                    for (kij, &c) in row.iter_mut().zip(cr) {
                        *kij += bi * c;
                    }
                }
            }
        }
        // geometric stiffness sum_s mu_s scale_s (a b^T + b a^T) (x) I3
        if self.kinematics == Kinematics::Nonlinear {
            let mut x = [[0.0; NPAIR]; NPAIR];
            for (k, smp) in samples.iter().enumerate() {
                let f = mu[k] * smp.scale;
                if f == 0.0 {
                    continue;
                }
                for p in 0..NPAIR {
                    let fa = f * smp.a[p];
                    if fa != 0.0 {
                        for l in 0..NPAIR {
                            x[p][l] += fa * smp.b[l];
                        }
                    }
                }
            }
            for p in 0..NPAIR {
                for l in 0..NPAIR {
                    let val = x[p][l] + x[l][p];
                    for i in 0..3 {
                        out.tangent[(3 * p + i) * NDOF + 3 * l + i] += val;
                    }
                }
            }
        }
    }
}

/// y += a x over the element dofs.
#[inline(always)]
fn axpy(y: &mut [f64; NDOF], a: f64, x: &[f64; NDOF]) {
    for (yi, &xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

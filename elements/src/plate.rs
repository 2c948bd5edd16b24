//! The mixed (Hu-Washizu) four-node plate element of the paper (section 4), as a stamp
//! [`Element`]. Unknowns per node: the six face displacements [v1-, v2-, v3-, v1+, v2+, v3+].
//!
//! With the strains E and the resultants T eliminated on the element (eqs. 4.7, 4.11), the internal
//! force is G(V) = int (dE/dV)^T D E dA (eq. 4.12), E the assumed strains of [`crate::geometry`], and
//! the tangent K = int (dE/dV)^T D (dE/dV) + sum_c T_c d2E_c/dV2 dA (eq. 4.13), exact: Newton
//! converges quadratically. D is not symmetric (b_ab33 = 0), nor is K. With K the element gives
//! the symmetric P = K without the one-way coupling of T33 to the in-plane strains (`D[E33][in-plane]`
//! dropped from the material stiffness), the linear solver's preconditioner
//! ([`Element::has_preconditioner`]).

use crate::geometries::Geometries;
use crate::geometry::{ElementGeometry, GAUSS_POINTS};
use crate::material::{NormalStress, Section, NSTRAIN};
use crate::strain::{add_geometric_stiffness, axpy, triple, Affine, Sample, NDOF, NPAIR};
use stamp::element::{Element, LocalSystem};
use stamp::linalg::vector_state::clean_upper_vector_state;
use stamp::mesh::QuadMesh;
use stamp::Result;
use faer::linalg::matmul::matmul;
use faer::{Accum, MatMut, MatRef, Par};

/// Dofs per node: v-_1, v-_2, v-_3, v+_1, v+_2, v+_3.
pub const DOFS_PER_NODE: usize = 6;

/// The two face planes of the plate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Face {
    /// S-, at x3 = delta-.
    Bottom,
    /// S+, at x3 = delta+.
    Top,
}

impl Face {
    /// 0 for S-, 1 for S+.
    pub fn index(self) -> usize {
        match self {
            Face::Bottom => 0,
            Face::Top => 1,
        }
    }
    /// Global dof of displacement component `comp` (0, 1, 2) of this face at `node`, in the
    /// paper's plate (six dofs per node).
    pub fn dof(self, node: usize, comp: usize) -> usize {
        self.dof_in(DOFS_PER_NODE, node, comp)
    }
    /// The same in a plate with `dofs_per_node` unknowns per node whose first six are the faces'
    /// (the paper's plate: 6; a plate of N surfaces: 3 N, see [`crate::multi_surface`]).
    pub fn dof_in(self, dofs_per_node: usize, node: usize, comp: usize) -> usize {
        node * dofs_per_node + 3 * self.index() + comp
    }
}

/// Geometrically nonlinear (Green-Lagrange, exact rigid-body motions) or linear (eta = 0).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Kinematics {
    Nonlinear,
    Linear,
}

// Sample numbering (see strain.rs): displacement-based strains evaluated per element.
const MEM: usize = 0; // + g*6 + face*3 + {0: E11, 1: E22, 2: 2E12}
const E33: usize = 24; // + g
const LINE: usize = 28; // + pt*2 + face: full covariant shear on the lines (parallelograms)
const TYING: usize = 36; // + pt*2 + face: full covariant shear at the edge midpoints (other quads)
const NSAMPLE: usize = 44;
/// Per membrane strain kind (E11, E22, E12) and Gauss point, the first Gauss point of its
/// projection group (same xi2, same xi1, all; see [`crate::geometry`]'s `proj`).
const MEMBRANE_GROUP_FIRST: [[usize; 4]; 3] = [[0, 0, 2, 2], [0, 1, 1, 0], [0, 0, 0, 0]];
/// Row of T33 (and E33) in D.
const E33_ROW: usize = crate::material::idx::E33;

/// The deformed transverse fibre g3 = e3 + (v+ - v-)/h at the point with shape functions `n`.
#[inline(always)]
fn fibre(n: &[f64; 4], h: f64, v: &[f64]) -> Affine {
    let mut c = [0.0; NPAIR];
    for a in 0..4 {
        c[2 * a] = -n[a] / h;
        c[2 * a + 1] = n[a] / h;
    }
    Affine::new([0.0, 0.0, 1.0], c, v)
}

/// The deformed tangent g0 + v_face,a of a face, `dn` the shape-function derivatives along it.
#[inline(always)]
fn face_tangent(g0: [f64; 2], dn: [f64; 4], face: usize, v: &[f64]) -> Affine {
    let mut c = [0.0; NPAIR];
    for a in 0..4 {
        c[2 * a + face] = dn[a];
    }
    Affine::new([g0[0], g0[1], 0.0], c, v)
}

/// Per-thread scratch memory of the plate element.
pub struct PlateWorkspace {
    samples: Box<[Sample; NSAMPLE]>,
    /// Rows dE_c/dV of the assumed strains, Gauss point after Gauss point (4 x 11 rows).
    b: [[f64; NDOF]; 4 * NSTRAIN],
    /// The same rows multiplied by w D (the Gauss weight times det J times the stiffness).
    db: [[f64; NDOF]; 4 * NSTRAIN],
    /// Per Gauss point, w sum_c `D[E33][c]` dE_c/dV over the in-plane strains c: the row of the
    /// tangent's one-way coupling (b_ab33 = 0, b_33ab != 0).
    coupling: [[f64; NDOF]; 4],
    mu: [f64; NSAMPLE],
    /// The (sample, coefficient) terms of every assumed strain at every Gauss point (of a shared
    /// membrane strain: at the first point of its group only).
    terms: [[Terms; NSTRAIN]; 4],
    /// The smallest volume ratio det[g1, g2, g3] / det[G1, G2, G3] of the faces at the Gauss
    /// points found by the last `compute_samples` (see [`PlateElements::smallest_volume_ratio`]).
    volume_ratio: f64,
}

/// The assumed strains and resultants at the element's Gauss points.
#[derive(Debug, Clone, Copy, Default)]
pub struct GaussState {
    pub strain: [[f64; NSTRAIN]; 4],
    pub resultant: [[f64; NSTRAIN]; 4],
}

/// The plate elements of a mesh.
pub struct PlateElements {
    cells: Vec<[usize; 4]>,
    geometry: Geometries,
    d: [[f64; NSTRAIN]; NSTRAIN],
    /// The nonzero entries (column, value) of every row of D.
    d_rows: [([(usize, f64); NSTRAIN], usize); NSTRAIN],
    section: Section,
    kinematics: Kinematics,
    /// D has the one-way coupling of T33 to the in-plane strains (nu != 0): the tangent is not
    /// symmetric, and the element gives the preconditioner P (see [`Element::has_preconditioner`]).
    coupled: bool,
}

/// Up to 4 (sample, coefficient) terms of an assumed strain (4 projection weights of a membrane
/// strain, 2 covariant components times 1 line or 2 tying samples of a shear strain).
type Terms = ([(usize, f64); 4], usize);

impl PlateElements {
    /// Plate elements on every cell of `mesh`, with a validated section.
    pub fn new(mesh: &QuadMesh, section: Section, kinematics: Kinematics) -> Result<Self> {
        section.validate()?;
        mesh.validate()?;
        let geometry = (0..mesh.num_cells()).map(|c| ElementGeometry::new(&mesh.cell_coords(c), c)).collect::<Result<Vec<_>>>()?;
        let d = section.stiffness();
        // the split preconditioner needs D0 (D without the row of T33's coupling) symmetric: not so
        // when S_33 enters the in-plane law, which then leaves the preconditioner to the solver
        let coupled = section.normal_stress == NormalStress::Dropped
            && (0..NSTRAIN).any(|c| c != E33_ROW && d[E33_ROW][c] != 0.0);
        let mut d_rows = [([(0, 0.0); NSTRAIN], 0); NSTRAIN];
        for (r, (entries, n)) in d_rows.iter_mut().enumerate() {
            for c in (0..NSTRAIN).filter(|&c| d[r][c] != 0.0) {
                entries[*n] = (c, d[r][c]);
                *n += 1;
            }
        }
        Ok(PlateElements { cells: mesh.cells.clone(), geometry: Geometries::new(geometry), d, d_rows, section, kinematics, coupled })
    }

    pub fn section(&self) -> &Section {
        &self.section
    }
    pub fn kinematics(&self) -> Kinematics {
        self.kinematics
    }
    /// The plate stiffness D (eq. 2.6, with b_ab33 = 0).
    pub fn stiffness(&self) -> &[[f64; NSTRAIN]; NSTRAIN] {
        &self.d
    }
    /// Geometry of element e.
    pub fn geometry(&self, e: usize) -> &ElementGeometry {
        &self.geometry[e]
    }

    /// The (sample, coefficient) terms of assumed strain component `c` at Gauss point `g`, written
    /// in place (a returned copy was read back before its stores had retired: store-forwarding stalls).
    #[inline(always)]
    fn terms(geo: &ElementGeometry, g: usize, c: usize, out: &mut Terms) {
        let (t, n) = out;
        *n = 0;
        let mut push = |s: usize, w: f64| {
            if w != 0.0 {
                t[*n] = (s, w);
                *n += 1;
            }
        };
        let face = c % 2;
        match c {
            0 | 1 | 2 | 3 | 4 | 5 => {
                let kind = c / 2; // 0: E11 rows, 1: E22 columns, 2: E12 all
                for h in 0..4 {
                    push(MEM + h * 6 + face * 3 + kind, geo.proj[kind][g][h]);
                }
            }
            6 | 7 | 8 | 9 => {
                let row = if c < 8 { 0 } else { 1 }; // 2E13 or 2E23 (local Cartesian)
                let [x1, x2] = GAUSS_POINTS[g];
                // covariant gamma_xi1 on the line xi1 = 0 at xi2 = x2, gamma_xi2 on xi2 = 0 at xi1 = x1
                let comps = [(if x2 < 0.0 { 0 } else { 1 }, x2, 0usize), (if x1 < 0.0 { 2 } else { 3 }, x1, 2usize)];
                for (a, &(pt, xi, tp)) in comps.iter().enumerate() {
                    let w = geo.jit[g][row][a];
                    if geo.parallelogram {
                        push(LINE + pt * 2 + face, w);
                    } else {
                        push(TYING + tp * 2 + face, w * 0.5 * (1.0 - xi));
                        push(TYING + (tp + 1) * 2 + face, w * 0.5 * (1.0 + xi));
                    }
                }
            }
            _ => push(E33 + g, 1.0),
        }
    }

    /// Evaluate every displacement-based strain sample of element e at local dofs `v`.
    #[inline(always)]
    fn compute_samples(&self, e: usize, v: &[f64], ws: &mut PlateWorkspace) {
        let geo = &self.geometry[e];
        let h = self.section.thickness();
        let nonlinear = self.kinematics == Kinematics::Nonlinear;
        // (no closures: they would not be inlined into the AVX2 build)
        let s = &mut ws.samples;
        // the reference frame's orientation: det[G1, G2, G3] with G3 = e3
        let reference = geo.frame[0][0] * geo.frame[1][1] - geo.frame[0][1] * geo.frame[1][0];
        let mut volume_ratio = f64::INFINITY;
        for g in 0..4 {
            let g3 = fibre(&geo.n[g], h, v);
            s[E33 + g].set(nonlinear, 0.5, &g3, &g3);
            let dn = geo.dndy[g];
            for face in 0..2 {
                let g1 = face_tangent(geo.frame[0], [dn[0][0], dn[1][0], dn[2][0], dn[3][0]], face, v);
                let g2 = face_tangent(geo.frame[1], [dn[0][1], dn[1][1], dn[2][1], dn[3][1]], face, v);
                volume_ratio = volume_ratio.min(triple(&g1.g, &g2.g, &g3.g) / reference);
                let base = MEM + g * 6 + face * 3;
                s[base].set(nonlinear, 0.5, &g1, &g1);
                s[base + 1].set(nonlinear, 0.5, &g2, &g2);
                s[base + 2].set(nonlinear, 1.0, &g1, &g2);
            }
        }
        ws.volume_ratio = volume_ratio;
        for pt in 0..4 {
            // only the shear samples this element's interpolation uses (see terms())
            let sp = if geo.parallelogram { &geo.line[pt] } else { &geo.tying[pt] };
            let base = if geo.parallelogram { LINE } else { TYING };
            let g3 = fibre(&sp.n, h, v);
            for face in 0..2 {
                let gt = face_tangent(sp.base, sp.dn, face, v);
                s[base + pt * 2 + face].set(nonlinear, 1.0, &gt, &g3);
            }
        }
    }

    /// The smallest volume ratio J = det[g1, g2, g3] / det[G1, G2, G3] over both faces at the four
    /// Gauss points of element `e` at local dofs `v` (g_a the deformed face tangents, g3 the
    /// deformed fibre (eq. 1.4); 1 in the reference state and under any rigid motion). J <= 0
    /// means that the element turned inside out: a fibre passed through its face, or a face
    /// folded over. Green-Lagrange strains cannot see this (a mirror image has the same strains),
    /// so the nonlinear element refuses such states ([`LocalSystem::inadmissible`]).
    pub fn smallest_volume_ratio(&self, e: usize, v: &[f64], ws: &mut PlateWorkspace) -> f64 {
        self.compute_samples(e, v, ws);
        ws.volume_ratio
    }

    /// Assumed strains and stress resultants at the Gauss points of element `e` for local dofs `v`
    /// (for output: membrane forces, moments, shear forces follow from the face resultants).
    pub fn gauss_state(&self, e: usize, v: &[f64], ws: &mut PlateWorkspace) -> GaussState {
        self.compute_samples(e, v, ws);
        let geo = &self.geometry[e];
        let mut out = GaussState::default();
        for g in 0..4 {
            for c in 0..NSTRAIN {
                let mut terms = ([(0, 0.0); 4], 0);
                Self::terms(geo, g, c, &mut terms);
                let (t, n) = terms;
                out.strain[g][c] = t[..n].iter().map(|&(s, w)| w * ws.samples[s].val).sum();
            }
            for r in 0..NSTRAIN {
                out.resultant[g][r] = (0..NSTRAIN).map(|c| self.d[r][c] * out.strain[g][c]).sum();
            }
        }
        out
    }
}

impl Element for PlateElements {
    type Workspace = PlateWorkspace;

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
    /// P = the tangent without the one-way coupling of T33 to the in-plane strains, i.e. with
    /// D0 = D minus its entries `D[E33][in-plane]` (symmetric) in the material stiffness; the
    /// geometric and contact stiffnesses are symmetric and kept whole. Measured against the
    /// symmetric part of the tangent as GMRES's preconditioner, on the sphere problem: about half
    /// the GMRES iterations (README "Speed").
    fn retain_elements(&mut self, keep: &[bool]) {
        self.geometry.retain(keep);
    }
    fn has_preconditioner(&self) -> bool {
        self.coupled
    }
    fn new_workspace(&self) -> PlateWorkspace {
        PlateWorkspace {
            samples: Box::new([Sample::default(); NSAMPLE]),
            b: [[0.0; NDOF]; 4 * NSTRAIN],
            db: [[0.0; NDOF]; 4 * NSTRAIN],
            coupling: [[0.0; NDOF]; 4],
            mu: [0.0; NSAMPLE],
            terms: [[([(0, 0.0); 4], 0); NSTRAIN]; 4],
            volume_ratio: 1.0,
        }
    }

    /// The nonlinear element refuses a state in which it turned inside out (see
    /// [`PlateElements::smallest_volume_ratio`]; it still computes the residual and tangent there,
    /// which the tangent tests use); the linear theory has no such limit.
    fn evaluate(&self, e: usize, v: &[f64], ws: &mut PlateWorkspace, out: &mut LocalSystem, with_tangent: bool) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            return unsafe { self.evaluate_avx2(e, v, None, ws, out, with_tangent) };
        }
        self.evaluate_kernel(e, v, None, ws, out, with_tangent)
    }

    /// The geometric stiffness from the resultants of the strains linearised about `reference`
    /// (see [`Element::evaluate_about`]): a Green-Lagrange sample is exactly quadratic, so its
    /// linearisation about the reference is its value at `v` less s (C_a dv) . (C_b dv),
    /// dv = v - reference.
    fn evaluate_about(&self, e: usize, v: &[f64], reference: &[f64], ws: &mut PlateWorkspace, out: &mut LocalSystem, with_tangent: bool) {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has AVX2.
            return unsafe { self.evaluate_avx2(e, v, Some(reference), ws, out, with_tangent) };
        }
        self.evaluate_kernel(e, v, Some(reference), ws, out, with_tangent)
    }
}

impl PlateElements {
    /// [`Element::evaluate`] compiled for AVX2 (no FMA: the same operations, the same results).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn evaluate_avx2(&self, e: usize, v: &[f64], reference: Option<&[f64]>, ws: &mut PlateWorkspace, out: &mut LocalSystem, with_tangent: bool) {
        self.evaluate_kernel(e, v, reference, ws, out, with_tangent)
    }

    /// The body of [`Element::evaluate`], inlined into the baseline and the AVX2 builds.
    #[inline(always)]
    fn evaluate_kernel(&self, e: usize, v: &[f64], reference: Option<&[f64]>, ws: &mut PlateWorkspace, out: &mut LocalSystem, with_tangent: bool) {
        self.compute_samples(e, v, ws);
        if self.kinematics == Kinematics::Nonlinear && ws.volume_ratio <= 0.0 {
            out.inadmissible = Some(format!(
                "it turned inside out (smallest volume ratio det[g1, g2, g3] / det[G1, G2, G3] of a face at a Gauss point: {:.3e})",
                ws.volume_ratio
            ));
        }
        let geo = &self.geometry[e];
        let d = &self.d;
        // P asked for and different from the tangent
        let split = with_tangent && self.coupled && !out.preconditioner.is_empty();
        let PlateWorkspace { samples, b, db, coupling, mu, terms, .. } = ws;
        let samples: &[Sample; NSAMPLE] = samples;
        *mu = [0.0; NSAMPLE];
        let mut strains = [[0.0; NSTRAIN]; 4];
        for g in 0..4 {
            let w = geo.wdet[g];
            for c in 0..NSTRAIN {
                // a membrane strain projected over a row, column or all of the Gauss points is the
                // same at every point of its group: computed at the group's first point, copied
                let first = if c < 6 { MEMBRANE_GROUP_FIRST[c / 2][g] } else { g };
                if first < g {
                    strains[g][c] = strains[first][c];
                    continue;
                }
                Self::terms(geo, g, c, &mut terms[g][c]);
                let (t, n) = &terms[g][c];
                strains[g][c] = t[..*n].iter().fold(0.0, |sum, &(s, coef)| sum + coef * samples[s].val);
            }
            let strain = strains[g];
            let mut stress = [0.0; NSTRAIN];
            for r in 0..NSTRAIN {
                stress[r] = (0..NSTRAIN).map(|c| d[r][c] * strain[c]).sum();
            }
            out.energy += 0.5 * w * (0..NSTRAIN).map(|c| strain[c] * stress[c]).sum::<f64>();
            // weights mu_s = sum over the assumed strains c that use sample s of w T_c coef_cs:
            // of the sample gradients in the internal force, of the sample Hessians in the
            // geometric stiffness
            for c in 0..NSTRAIN {
                let first = if c < 6 { MEMBRANE_GROUP_FIRST[c / 2][g] } else { g };
                let (t, n) = &terms[first][c];
                for &(s, coef) in &t[..*n] {
                    mu[s] += w * stress[c] * coef;
                }
            }
        }
        // internal force sum_g w B_g^T T_g = sum_s mu_s dE_s/dV over the samples this element uses
        // (sums in local arrays, kept in registers: no store-to-load chain through memory)
        let shear = if geo.parallelogram { LINE } else { TYING };
        let mut residual = [0.0; NDOF];
        for s in (MEM..E33 + 4).chain(shear..shear + 8) {
            axpy(&mut residual, mu[s], &samples[s].grad);
        }
        for (r, x) in out.residual.iter_mut().zip(residual) {
            *r += x;
        }
        if !with_tangent {
            return;
        }
        for g in 0..4 {
            let w = geo.wdet[g];
            // the rows dE_c/dV of B at this Gauss point (shared membrane rows copied)
            for c in 0..NSTRAIN {
                let first = if c < 6 { MEMBRANE_GROUP_FIRST[c / 2][g] } else { g };
                if first < g {
                    b[g * NSTRAIN + c] = b[first * NSTRAIN + c];
                    continue;
                }
                let (t, n) = &terms[g][c];
                let mut row = [0.0; NDOF];
                for &(s, coef) in &t[..*n] {
                    axpy(&mut row, coef, &samples[s].grad);
                }
                b[g * NSTRAIN + c] = row;
            }
            // w D B at this Gauss point; for P the row of T33 split into its own strain's part
            // (kept in db: w D0 B, D0 symmetric) and the one-way coupling to the in-plane strains
            let rows = &b[g * NSTRAIN..(g + 1) * NSTRAIN];
            for r in 0..NSTRAIN {
                let (mut row, mut cpl) = ([0.0; NDOF], [0.0; NDOF]);
                for &(c, drc) in &self.d_rows[r].0[..self.d_rows[r].1] {
                    if split && r == E33_ROW && c != E33_ROW {
                        axpy(&mut cpl, w * drc, &rows[c]);
                    } else {
                        axpy(&mut row, w * drc, &rows[c]);
                    }
                }
                db[g * NSTRAIN + r] = row;
                if split && r == E33_ROW {
                    coupling[g] = cpl;
                }
            }
        }
        // material stiffness: sum over the Gauss points of B^T (w D0 B), one 24 x 44 x 24 product,
        // and of the coupling b33^T (w c^T B_in): P gets the first, the tangent both
        let bm = MatRef::from_row_major_slice(b.as_flattened(), 4 * NSTRAIN, NDOF);
        let dbm = MatRef::from_row_major_slice(db.as_flattened(), 4 * NSTRAIN, NDOF);
        let k = MatMut::from_row_major_slice_mut(&mut out.tangent[..NDOF * NDOF], NDOF, NDOF);
        matmul(k, Accum::Add, bm.transpose(), dbm, 1.0, Par::Seq);
        clean_upper_vector_state();
        if split {
            out.preconditioner[..NDOF * NDOF].copy_from_slice(&out.tangent[..NDOF * NDOF]);
            // the rows dE33/dV of the four Gauss points: every NSTRAIN-th row of B
            let b33 = MatRef::from_row_major_slice_with_stride(&b.as_flattened()[E33_ROW * NDOF..], 4, NDOF, NSTRAIN * NDOF);
            let cm = MatRef::from_row_major_slice(coupling.as_flattened(), 4, NDOF);
            let k = MatMut::from_row_major_slice_mut(&mut out.tangent[..NDOF * NDOF], NDOF, NDOF);
            matmul(k, Accum::Add, b33.transpose(), cm, 1.0, Par::Seq);
            clean_upper_vector_state();
        }
        // geometric stiffness: sum_s mu_s Hess_s (x) I3, Hess_s = scale (a b^T + b a^T)
        if self.kinematics == Kinematics::Nonlinear {
            if let Some(reference) = reference {
                linearised_weights(geo, &self.d, samples, terms, v, reference, mu);
            }
            // X = sum_s mu_s scale_s a_s b_s^T, and H = X + X^T; a_s and b_s of a membrane sample
            // have nonzeros only at the pairs of its face, a_s of a shear sample likewise
            let mut x = [[0.0; NPAIR]; NPAIR];
            let face_pairs = |face: usize| [face, face + 2, face + 4, face + 6];
            let mut add = |s: usize, rows: &[usize], cols: &[usize]| {
                let smp = &samples[s];
                let f = mu[s] * smp.scale;
                for &kk in rows {
                    let fa = f * smp.a[kk];
                    for &l in cols {
                        x[kk][l] += fa * smp.b[l];
                    }
                }
            };
            let all: [usize; NPAIR] = std::array::from_fn(|k| k);
            for s in MEM..E33 {
                let pairs = face_pairs((s - MEM) % 6 / 3);
                add(s, &pairs, &pairs);
            }
            for s in E33..E33 + 4 {
                add(s, &all, &all);
            }
            for s in shear..shear + 8 {
                add(s, &face_pairs(s % 2), &all);
            }
            add_geometric_stiffness(&x, &mut out.tangent);
            if split {
                add_geometric_stiffness(&x, &mut out.preconditioner);
            }
        }
    }
}

/// The weights mu_s = sum_c w T_c coef_cs of the geometric stiffness with the resultants T = D E
/// of the assumed strains linearised about `reference` (see [`Element::evaluate_about`]): each
/// sample's value less its quadratic remainder s (C_a dv) . (C_b dv), dv = v - reference.
#[inline(always)]
fn linearised_weights(geo: &ElementGeometry, d: &[[f64; NSTRAIN]; NSTRAIN], samples: &[Sample; NSAMPLE], terms: &[[Terms; NSTRAIN]; 4], v: &[f64], reference: &[f64], mu: &mut [f64; NSAMPLE]) {
    let mut dv = [0.0; NDOF];
    for (k, x) in dv.iter_mut().enumerate() {
        *x = v[k] - reference[k];
    }
    let mut linear = [0.0; NSAMPLE];
    let shear = if geo.parallelogram { LINE } else { TYING };
    for s in (MEM..E33 + 4).chain(shear..shear + 8) {
        linear[s] = samples[s].val - samples[s].remainder(&dv);
    }
    *mu = [0.0; NSAMPLE];
    for g in 0..4 {
        let w = geo.wdet[g];
        let mut strain = [0.0; NSTRAIN];
        for c in 0..NSTRAIN {
            let first = if c < 6 { MEMBRANE_GROUP_FIRST[c / 2][g] } else { g };
            let (t, n) = &terms[first][c];
            strain[c] = t[..*n].iter().fold(0.0, |sum, &(s, coef)| sum + coef * linear[s]);
        }
        for c in 0..NSTRAIN {
            let stress: f64 = (0..NSTRAIN).map(|k| d[c][k] * strain[k]).sum();
            let first = if c < 6 { MEMBRANE_GROUP_FIRST[c / 2][g] } else { g };
            let (t, n) = &terms[first][c];
            for &(s, coef) in &t[..*n] {
                mu[s] += w * stress * coef;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The membrane rows shared between Gauss points (MEMBRANE_GROUP_FIRST) are those whose
    /// projection weights are equal, on a distorted element where the weights all differ.
    #[test]
    fn membrane_groups_share_their_projection_weights() {
        let geo = ElementGeometry::new(&[[0.0, 0.0], [2.0, 0.3], [2.6, 1.9], [-0.4, 1.2]], 0).unwrap();
        for kind in 0..3 {
            for g in 0..4 {
                let first = MEMBRANE_GROUP_FIRST[kind][g];
                assert_eq!(geo.proj[kind][g], geo.proj[kind][first], "kind {kind}, Gauss point {g}");
                for h in 0..4 {
                    // a point outside the group has different weights
                    if MEMBRANE_GROUP_FIRST[kind][h] != first {
                        assert_ne!(geo.proj[kind][g], geo.proj[kind][h], "kind {kind}, Gauss points {g} and {h}");
                    }
                }
            }
        }
    }

    /// The element computed the plain way (as first written): dense rows B_g of the assumed strains,
    /// r = sum_g B_g^T w D E_g, K = sum_g B_g^T w D B_g + sum_s mu_s Hess_s (x) I3, and P the same
    /// with D0 = D without `D[E33][in-plane]`; the fast kernel must agree to round-off.
    fn reference(plate: &PlateElements, v: &[f64]) -> (Vec<f64>, Vec<f64>, Vec<f64>, f64) {
        reference_about(plate, v, None)
    }

    /// The same with the geometric stiffness's resultants from the strains linearised about
    /// `about` (Element::evaluate_about): E(about) + dE/dv(about) (v - about), from the samples'
    /// values and gradients at `about`.
    fn reference_about(plate: &PlateElements, v: &[f64], about: Option<&[f64]>) -> (Vec<f64>, Vec<f64>, Vec<f64>, f64) {
        let mut ws = plate.new_workspace();
        plate.compute_samples(0, v, &mut ws);
        let linear: Option<Vec<f64>> = about.map(|a| {
            let mut wa = plate.new_workspace();
            plate.compute_samples(0, a, &mut wa);
            wa.samples.iter().map(|s| s.val + (0..NDOF).map(|i| s.grad[i] * (v[i] - a[i])).sum::<f64>()).collect()
        });
        let (geo, d, smp) = (&plate.geometry[0], &plate.d, &ws.samples);
        let (mut r, mut k, mut p, mut energy) = (vec![0.0; NDOF], vec![0.0; NDOF * NDOF], vec![0.0; NDOF * NDOF], 0.0);
        let mut mu = [0.0; NSAMPLE];
        for g in 0..4 {
            let w = geo.wdet[g];
            let mut terms = [([(0, 0.0); 4], 0); NSTRAIN];
            let (mut b, mut strain) = ([[0.0; NDOF]; NSTRAIN], [0.0; NSTRAIN]);
            for c in 0..NSTRAIN {
                PlateElements::terms(geo, g, c, &mut terms[c]);
                for &(s, coef) in &terms[c].0[..terms[c].1] {
                    strain[c] += coef * smp[s].val;
                    for i in 0..NDOF {
                        b[c][i] += coef * smp[s].grad[i];
                    }
                }
            }
            let stress: Vec<f64> = (0..NSTRAIN).map(|rr| (0..NSTRAIN).map(|c| d[rr][c] * strain[c]).sum()).collect();
            energy += 0.5 * w * (0..NSTRAIN).map(|c| strain[c] * stress[c]).sum::<f64>();
            // the resultants of the geometric stiffness
            let geometric: Vec<f64> = match &linear {
                None => stress.clone(),
                Some(lin) => {
                    let e: Vec<f64> = (0..NSTRAIN).map(|c| terms[c].0[..terms[c].1].iter().map(|&(s, coef)| coef * lin[s]).sum()).collect();
                    (0..NSTRAIN).map(|rr| (0..NSTRAIN).map(|c| d[rr][c] * e[c]).sum()).collect()
                }
            };
            for c in 0..NSTRAIN {
                for i in 0..NDOF {
                    r[i] += w * stress[c] * b[c][i];
                }
                for &(s, coef) in &terms[c].0[..terms[c].1] {
                    mu[s] += w * geometric[c] * coef;
                }
                for rr in 0..NSTRAIN {
                    for i in 0..NDOF {
                        for j in 0..NDOF {
                            let kij = b[rr][i] * w * d[rr][c] * b[c][j];
                            k[i * NDOF + j] += kij;
                            if !(rr == E33_ROW && c != E33_ROW) {
                                p[i * NDOF + j] += kij;
                            }
                        }
                    }
                }
            }
        }
        if plate.kinematics == Kinematics::Nonlinear {
            for s in 0..NSAMPLE {
                for kk in 0..NPAIR {
                    for l in 0..NPAIR {
                        for i in 0..3 {
                            k[(3 * kk + i) * NDOF + 3 * l + i] += mu[s] * smp[s].hessian(kk, l);
                            p[(3 * kk + i) * NDOF + 3 * l + i] += mu[s] * smp[s].hessian(kk, l);
                        }
                    }
                }
            }
        }
        (r, k, p, energy)
    }

    /// The kernel (sample-weighted internal force, shared membrane rows, sparse D, geometric
    /// stiffness over the face pairs; AVX2 and baseline builds) against the plain computation, on a distorted element (tying
    /// shear) and a parallelogram (line shear), both kinematics, at a large-displacement state.
    #[test]
    fn kernel_agrees_with_the_plain_computation() {
        use stamp::mesh::QuadMesh;
        let distorted = [[0.0, 0.0], [2.0, 0.3], [2.6, 1.9], [-0.4, 1.2]];
        let parallelogram = [[0.0, 0.0], [2.0, 0.3], [2.5, 1.5], [0.5, 1.2]];
        let section = Section::homogeneous(0.15, crate::Isotropic::new(2.0e5, 0.3).unwrap()).unwrap();
        let v: Vec<f64> = (0..NDOF).map(|k| 0.6 * ((k * 7919 % 1000) as f64 / 500.0 - 1.0)).collect();
        let rel = |a: &[f64], b: &[f64]| {
            let scale = b.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / scale
        };
        for coords in [distorted, parallelogram] {
            for kin in [Kinematics::Nonlinear, Kinematics::Linear] {
                let mesh = QuadMesh::new(coords.to_vec(), vec![[0, 1, 2, 3]]).unwrap();
                let plate = PlateElements::new(&mesh, section.clone(), kin).unwrap();
                assert_eq!(plate.geometry(0).parallelogram, coords == parallelogram);
                let (r, k, p, energy) = reference(&plate, &v);
                let mut ws = plate.new_workspace();
                let mut out = LocalSystem::with_preconditioner(NDOF);
                plate.evaluate(0, &v, &mut ws, &mut out, true);
                let mut alone = LocalSystem::new(NDOF);
                plate.evaluate(0, &v, &mut ws, &mut alone, true);
                let mut residual = LocalSystem::new(NDOF);
                plate.evaluate(0, &v, &mut ws, &mut residual, false);
                // the kernel compiled for baseline x86-64 (what `evaluate` runs without AVX2)
                let mut baseline = LocalSystem::with_preconditioner(NDOF);
                plate.evaluate_kernel(0, &v, None, &mut ws, &mut baseline, true);
                // linearised about another state: the residual is the same, the tangent that of
                // the plain computation with the linearised resultants
                let about: Vec<f64> = v.iter().enumerate().map(|(k, x)| x - 0.3 * ((k * 104729 % 1000) as f64 / 500.0 - 1.0)).collect();
                let (_, k_about, p_about, _) = reference_about(&plate, &v, Some(&about));
                let mut mixed = LocalSystem::with_preconditioner(NDOF);
                plate.evaluate_about(0, &v, &about, &mut ws, &mut mixed, true);
                let mut same = LocalSystem::with_preconditioner(NDOF);
                plate.evaluate_about(0, &v, &v, &mut ws, &mut same, true);
                if kin == Kinematics::Nonlinear {
                    assert!(rel(&k_about, &k) > 1e-3, "the linearised resultants change the tangent");
                }
                for (what, err) in [
                    ("residual about", rel(&mixed.residual, &r)),
                    ("tangent about", rel(&mixed.tangent, &k_about)),
                    ("P about", rel(&mixed.preconditioner, &p_about)),
                    ("tangent about itself", rel(&same.tangent, &k)),
                    ("residual", rel(&out.residual, &r)),
                    ("residual alone", rel(&residual.residual, &r)),
                    ("tangent", rel(&out.tangent, &k)),
                    ("tangent alone", rel(&alone.tangent, &k)),
                    ("P", rel(&out.preconditioner, &p)),
                    ("baseline residual", rel(&baseline.residual, &r)),
                    ("baseline tangent", rel(&baseline.tangent, &k)),
                    ("baseline P", rel(&baseline.preconditioner, &p)),
                    ("energy", rel(&[out.energy, residual.energy], &[energy, energy])),
                ] {
                    assert!(err < 1e-12, "{kin:?}, parallelogram {}: {what} differs by {err:e}", coords == parallelogram);
                }
            }
        }
    }
}

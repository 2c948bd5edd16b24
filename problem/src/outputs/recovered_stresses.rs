//! The recovered stresses of a thickness probe (`stresses = "recovered"`): all six stresses at
//! any point of the plate (a node, an edge, inside a cell), through the thickness.
//!
//! In-plane stresses s11, s22, s12: at each height, a least-squares cubic in (x1, x2) through
//! the cell-centre values (each layer's 3D law at the mean of the cell's four Gauss points) of
//! the cells around the point (outputs/patch.rs: those that hold it and two rings of neighbours,
//! unfolded across the symmetry planes, s12 odd under a mirror; three or four rings where two do
//! not determine the cubic), evaluated at the point: superconvergent patch recovery (Zienkiewicz
//! and Zhu 1992) with a cubic. A quadratic was measured first and is not enough: its constant
//! second derivative cannot follow s11,11 where it varies linearly (one cell from a supported
//! edge, where sin(pi x1/a) ~ x1: s33 9 % off there at 16 x 16 quarter cells), and its first
//! derivatives carry the cubic term's bias (s13 2.3 % off at an inner node); the cubic's are
//! within 0.25 % on the same runs (docs/verification/laminates.md). The cubic's first and second
//! derivatives at the point give
//!
//!   D1 = s11,1 + s12,2,   D2 = s12,1 + s22,2,   Q = s11,11 + 2 s12,12 + s22,22,
//!
//! and the transverse stresses follow from 3D equilibrium (s_ij,j = 0, linear) integrated through
//! the thickness from the bottom face, where the traction is known (t = -s_i3: a pressure or a
//! contact pressure p gives s33 = -p; frictionless contact and pressures no shear):
//!
//!   s13(x3) = s13(b) - int_b^x3 D1 dz,   s23(x3) = s23(b) - int_b^x3 D2 dz,
//!   s33(x3) = s33(b) - (x3 - b) G(b) + int_b^x3 (x3 - z) Q(z) dz,
//!
//! G = s13,1 + s23,2 (0 at the bottom: its shear traction taken uniform around the point), since
//! s33,3 = -G and G,3 = -Q. Each layer is integrated by 5 Gauss points (exact for linear
//! kinematics: the in-plane stresses are polynomials of degree N - 1 <= 4 in x3) and the stresses
//! at its top start the next layer: s13, s23, s33 are continuous at every interface, as in 3D.
//!
//! The top face's known traction (s_i3 = t_i there) is the check: the integrals reach it only as
//! far as the fit is right. The difference at the top (`mismatch`) is reported, and removed by a
//! correction linear in x3 from 0 at the bottom to the whole difference at the top, so that both
//! faces carry exactly what acts on them.

use crate::model::plate_model::Plate;
use crate::outputs::patch::Patch;
use stamp::element::Element;
use stamp::mesh::QuadMesh;
use stamp_elements::Laminate;

use crate::outputs::equilibrium_shear::GAUSS5;

/// The tractions acting on the plate's faces at the point, force per unit area in the plate's
/// axes: s_i3 = -bottom\[i\] on the bottom face, s_i3 = top\[i\] on the top face (a pressure p on
/// either face: s33 = -p).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FaceTractions {
    pub bottom: [f64; 3],
    pub top: [f64; 3],
}

/// The recovered stresses through the thickness at one point.
#[derive(Debug, Clone)]
pub struct Column {
    /// Per asked height: [s11, s22, s33, s12, s13, s23].
    pub rows: Vec<[f64; 6]>,
    /// [s13, s23, s33] integrated to the top face minus the values its traction gives (before
    /// the correction).
    pub mismatch: [f64; 3],
}

/// The fit of one probe's point: the patch's cells and, per sample, the weights of the value
/// and the derivatives [f, f,1, f,2, f,11, f,12, f,22] at the point (the cubic's first six
/// coefficients), and the sign of s12 at the sample.
pub struct StressRecovery {
    cells: Vec<usize>,
    points: Vec<(usize, [f64; 6], f64)>,
}

/// The layers' state at a height: s13, s23, s33 and G = s13,1 + s23,2.
#[derive(Debug, Clone, Copy)]
struct Transverse {
    s13: f64,
    s23: f64,
    s33: f64,
    g: f64,
}

impl StressRecovery {
    /// The patch around `at` (`holding`: the cells that hold it; `planes`: the symmetry planes,
    /// as for outputs/patch.rs). None when the centres do not determine a cubic within four rings.
    pub fn new(mesh: &QuadMesh, holding: &[usize], at: [f64; 2], planes: &[Vec<f64>; 2]) -> Option<StressRecovery> {
        // two rings, or more where they do not determine the cubic (a point on an edge that is
        // not a symmetry plane: three cells deep)
        let (patch, weights) = (2..=4).find_map(|rings| {
            let patch = Patch::with_rings(mesh, holding, at, planes, rings);
            let w = patch.polynomial_weights(3)?;
            Some((patch, w))
        })?;
        let h = mesh.element_size();
        let points = patch
            .samples
            .iter()
            .zip(&weights)
            .map(|(s, w)| (s.cell, [w[0], w[1] / h, w[2] / h, 2.0 * w[3] / (h * h), w[4] / (h * h), 2.0 * w[5] / (h * h)], s.s12_sign))
            .collect();
        Some(StressRecovery { cells: patch.cells, points })
    }

    /// The fitted [s11, s22, s12] at height x3 of layer k: value, d/dx1, d/dx2, d2/dx1^2,
    /// d2/dx1dx2, d2/dx2^2 at the point.
    fn fit(&self, plate: &Plate, locals: &[Vec<f64>], k: usize, x3: f64, ws: &mut <Plate as Element>::Workspace) -> Option<[[f64; 3]; 6]> {
        let centres: Vec<[f64; 6]> = self
            .cells
            .iter()
            .zip(locals)
            .map(|(&c, v)| plate.layer_stresses(c, k, x3, v, ws).map(|g| std::array::from_fn(|i| 0.25 * g.iter().map(|s| s[i]).sum::<f64>())))
            .collect::<Option<_>>()?;
        let mut f = [[0.0; 3]; 6];
        for &(i, w, sign) in &self.points {
            let s = centres[i];
            for j in 0..6 {
                f[j][0] += w[j] * s[0];
                f[j][1] += w[j] * s[1];
                f[j][2] += sign * w[j] * s[5];
            }
        }
        Some(f)
    }

    /// The transverse stresses at x3 in layer k from their values `start` at the layer's bottom b.
    fn integrate(&self, plate: &Plate, locals: &[Vec<f64>], k: usize, b: f64, x3: f64, start: Transverse, ws: &mut <Plate as Element>::Workspace) -> Option<Transverse> {
        let mut t = Transverse { s33: start.s33 - (x3 - b) * start.g, ..start };
        for &(xi, w) in &GAUSS5 {
            let z = 0.5 * (b + x3) + 0.5 * (x3 - b) * xi;
            let jw = 0.5 * (x3 - b) * w;
            let f = self.fit(plate, locals, k, z, ws)?;
            let d1 = f[1][0] + f[2][2];
            let d2 = f[1][2] + f[2][1];
            let q = f[3][0] + 2.0 * f[4][2] + f[5][1];
            t.s13 -= jw * d1;
            t.s23 -= jw * d2;
            t.g -= jw * q;
            t.s33 += jw * (x3 - z) * q;
        }
        Some(t)
    }

    /// The stresses at the heights `at` ((layer, x3), x3 from the stack's mid-plane) of the stack
    /// `lam` for the displacement `u`, with the faces' tractions `faces`.
    pub fn column(&self, plate: &Plate, lam: &Laminate, u: &[f64], at: &[(usize, f64)], faces: &FaceTractions) -> Option<Column> {
        let dpn = plate.dofs_per_node();
        let locals: Vec<Vec<f64>> = self.cells.iter().map(|&c| plate.element_nodes(c).iter().flat_map(|&n| u[dpn * n..dpn * (n + 1)].iter().copied()).collect()).collect();
        let mut ws = plate.new_workspace();
        let b = lam.boundaries();
        let layers = lam.plies.len();
        // the transverse stresses at the bottom of each layer, and at the top face
        let mut starts = vec![Transverse { s13: -faces.bottom[0], s23: -faces.bottom[1], s33: -faces.bottom[2], g: 0.0 }];
        for k in 0..layers {
            let next = self.integrate(plate, &locals, k, b[k], b[k + 1], starts[k], &mut ws)?;
            starts.push(next);
        }
        let top = starts[layers];
        let mismatch = [top.s13 - faces.top[0], top.s23 - faces.top[1], top.s33 - faces.top[2]];
        let h = b[layers] - b[0];
        let mut rows = Vec::with_capacity(at.len());
        for &(k, x3) in at {
            let f = self.fit(plate, &locals, k, x3, &mut ws)?;
            let t = self.integrate(plate, &locals, k, b[k], x3, starts[k], &mut ws)?;
            let r = (x3 - b[0]) / h;
            rows.push([f[0][0], f[0][1], t.s33 - r * mismatch[2], f[0][2], t.s13 - r * mismatch[0], t.s23 - r * mismatch[1]]);
        }
        Some(Column { rows, mismatch })
    }
}

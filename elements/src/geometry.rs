//! Geometry of one four-node element, computed once: the local Cartesian frame, the 2 x 2 Gauss
//! points with the Cartesian shape-function derivatives, the points where the transverse shear is
//! sampled, and the weights of the strain projections (paper eqs. 4.4-4.5).
//!
//! The assumed strain of component c is the L2 projection (weighted by det J, computed with the 2 x 2
//! Gauss rule) of the displacement-based strain onto the monomials the paper gives c:
//! E11 on {1, xi2}, E22 on {1, xi1}, E12 on {1}, E33 on {1, xi1, xi2, xi1 xi2}. On the Gauss points
//! such a projection is a weighted average over the points of one row (E11), one column (E22) or all
//! four (E12). On a rectangle or parallelogram the weights are equal and this is exactly the paper's
//! element (eq. 4.12 with its 3^-(r1+r2) weights); on a general quadrilateral it still reproduces any
//! constant strain, so the membrane patch test is passed.
//!
//! The transverse shear E13 on {1, xi2} and E23 on {1, xi1}: on a parallelogram (every rectangle)
//! it is projected in covariant components along the lines xi1 = 0 and xi2 = 0, exactly the
//! paper's projection. On any other quadrilateral the line samples would fail the bending patch
//! test, so the covariant shear is instead interpolated between the edge midpoints (the tying
//! points of Bathe and Dvorkin's MITC4), with the full Green-Lagrange strain there: the two agree
//! in the linear part on parallelograms, the tying form passes the bending patch test on distorted
//! meshes and, being built from full strains only, stays objective (a rigid rotation superposed on
//! any deformed state leaves it unchanged). This is what keeps the element free of shear locking.

use stamp::mesh::bilinear;
use stamp::{Result, StampError};

/// Abscissa of the two-point Gauss rule.
pub const GAUSS: f64 = 0.577_350_269_189_625_8;

/// Natural coordinates of the four Gauss points: row-major in xi2, (-,-), (+,-), (+,+), (-,+).
pub const GAUSS_POINTS: [[f64; 2]; 4] = [[-GAUSS, -GAUSS], [GAUSS, -GAUSS], [GAUSS, GAUSS], [-GAUSS, GAUSS]];

/// Shear sampling points: 0, 1 on the line xi1 = 0 at xi2 = -g, +g (for the covariant gamma_xi1),
/// 2, 3 on the line xi2 = 0 at xi1 = -g, +g (for gamma_xi2).
pub const LINE_POINTS: [[f64; 2]; 4] = [[0.0, -GAUSS], [0.0, GAUSS], [-GAUSS, 0.0], [GAUSS, 0.0]];

/// Tying points, the edge midpoints: 0, 1 at (0, -1), (0, 1) for gamma_xi1; 2, 3 at (-1, 0), (1, 0)
/// for gamma_xi2.
pub const TYING_POINTS: [[f64; 2]; 4] = [[0.0, -1.0], [0.0, 1.0], [-1.0, 0.0], [1.0, 0.0]];

/// Shape functions at a point and the derivative along one natural direction.
#[derive(Debug, Clone, Copy, Default)]
pub struct ShearPoint {
    pub n: [f64; 4],
    /// dN/dxi_a along the direction of this point's shear component.
    pub dn: [f64; 4],
    /// dX/dxi_a in global coordinates (the reference covariant base vector).
    pub base: [f64; 2],
}

/// Everything about one element that depends only on its reference geometry.
#[derive(Debug, Clone, Copy, Default)]
pub struct ElementGeometry {
    /// Unit vectors of the local frame, in global (x1, x2) components: t1 along dX/dxi1 at the
    /// centre, t2 = e3 x t1.
    pub frame: [[f64; 2]; 2],
    /// Shape functions at the Gauss points.
    pub n: [[f64; 4]; 4],
    /// dN/dy_i (local Cartesian) at the Gauss points: `dndy[g][node][i]`.
    pub dndy: [[[f64; 2]; 4]; 4],
    /// Gauss weight times det J.
    pub wdet: [f64; 4],
    /// J^-T at the Gauss points (maps covariant shear to local Cartesian): `jit[g][i][a]`.
    pub jit: [[[f64; 2]; 2]; 4],
    pub line: [ShearPoint; 4],
    pub tying: [ShearPoint; 4],
    /// Projection weights of E11 (row average), E22 (column average), E12 (all four):
    /// `proj[kind][g][g']`.
    pub proj: [[[f64; 4]; 4]; 3],
    /// Area of the element.
    pub area: f64,
    /// Opposite sides parallel (x1 - x0 = x2 - x3 to round-off): the paper's line sampling of the
    /// transverse shear is used; otherwise its tying interpolation (see the module doc).
    pub parallelogram: bool,
}

fn jacobian(x: &[[f64; 2]; 4], dn: &[[f64; 2]; 4]) -> [[f64; 2]; 2] {
    let mut j = [[0.0; 2]; 2];
    for a in 0..4 {
        for i in 0..2 {
            for k in 0..2 {
                j[i][k] += x[a][i] * dn[a][k];
            }
        }
    }
    j
}

impl ElementGeometry {
    /// Compute the geometry of the element with corner coordinates `x` (counter-clockwise).
    /// Fails for a degenerate or inverted element, naming it by `label`.
    pub fn new(x: &[[f64; 2]; 4], label: usize) -> Result<Self> {
        let mut geo = ElementGeometry::default();
        // local frame from the centre Jacobian
        let (_, dn0) = bilinear(0.0, 0.0);
        let j0 = jacobian(x, &dn0);
        let len = (j0[0][0] * j0[0][0] + j0[1][0] * j0[1][0]).sqrt();
        let det0 = j0[0][0] * j0[1][1] - j0[0][1] * j0[1][0];
        let size = (0..4).map(|a| (x[a][0] - x[0][0]).abs().max((x[a][1] - x[0][1]).abs())).fold(0.0, f64::max);
        if !(len > 0.0) || !(det0 > 1e-12 * size * size) {
            return Err(StampError::Mesh(format!("element {label} is degenerate or inverted (centre Jacobian {det0:.3e})")));
        }
        let t1 = [j0[0][0] / len, j0[1][0] / len];
        let t2 = [-t1[1], t1[0]];
        geo.frame = [t1, t2];
        // local coordinates of the nodes
        let xc = [0.25 * (x[0][0] + x[1][0] + x[2][0] + x[3][0]), 0.25 * (x[0][1] + x[1][1] + x[2][1] + x[3][1])];
        let mut y = [[0.0; 2]; 4];
        for a in 0..4 {
            let d = [x[a][0] - xc[0], x[a][1] - xc[1]];
            y[a] = [d[0] * t1[0] + d[1] * t1[1], d[0] * t2[0] + d[1] * t2[1]];
        }
        for (g, p) in GAUSS_POINTS.iter().enumerate() {
            let (n, dn) = bilinear(p[0], p[1]);
            let j = jacobian(&y, &dn);
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            if !(det > 1e-12 * size * size) {
                return Err(StampError::Mesh(format!(
                    "element {label} is inverted or too distorted: det J = {det:.3e} at Gauss point {g}"
                )));
            }
            let inv = [[j[1][1] / det, -j[0][1] / det], [-j[1][0] / det, j[0][0] / det]];
            geo.n[g] = n;
            for a in 0..4 {
                for i in 0..2 {
                    geo.dndy[g][a][i] = dn[a][0] * inv[0][i] + dn[a][1] * inv[1][i];
                }
            }
            geo.wdet[g] = det;
            for i in 0..2 {
                for k in 0..2 {
                    geo.jit[g][i][k] = inv[k][i];
                }
            }
        }
        geo.area = geo.wdet.iter().sum();
        geo.parallelogram = (0..2).all(|i| ((x[1][i] - x[0][i]) - (x[2][i] - x[3][i])).abs() <= 1e-12 * size);
        let shear_point = |p: &[f64; 2], dir: usize| {
            let (n, dn) = bilinear(p[0], p[1]);
            let mut sp = ShearPoint { n, ..Default::default() };
            for a in 0..4 {
                sp.dn[a] = dn[a][dir];
                sp.base[0] += x[a][0] * dn[a][dir];
                sp.base[1] += x[a][1] * dn[a][dir];
            }
            sp
        };
        for k in 0..4 {
            let dir = if k < 2 { 0 } else { 1 };
            geo.line[k] = shear_point(&LINE_POINTS[k], dir);
            geo.tying[k] = shear_point(&TYING_POINTS[k], dir);
        }
        // projection weights: rows (same xi2) for E11, columns (same xi1) for E22, all for E12
        let same_row = |g: usize, h: usize| GAUSS_POINTS[g][1] == GAUSS_POINTS[h][1];
        let same_col = |g: usize, h: usize| GAUSS_POINTS[g][0] == GAUSS_POINTS[h][0];
        for g in 0..4 {
            let groups: [&dyn Fn(usize) -> bool; 3] = [&|h| same_row(g, h), &|h| same_col(g, h), &|_| true];
            for (kind, member) in groups.iter().enumerate() {
                let total: f64 = (0..4).filter(|&h| member(h)).map(|h| geo.wdet[h]).sum();
                for h in 0..4 {
                    geo.proj[kind][g][h] = if member(h) { geo.wdet[h] / total } else { 0.0 };
                }
            }
        }
        Ok(geo)
    }
}

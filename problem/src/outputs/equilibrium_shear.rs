//! The transverse shear stresses of a thickness probe by integrating 3D equilibrium through the
//! thickness (the alternative to the layers' 3D law, `transverse_shear = "equilibrium"`):
//!
//!   s13(x3) = -int_{bottom}^{x3} (s11,1 + s12,2) dz,   s23(x3) = -int_{bottom}^{x3} (s12,1 + s22,2) dz,
//!
//! from the free bottom face (no shear traction there: pressures and frictionless contact are
//! normal; linear equilibrium, so for small strains). The in-plane derivatives come from a
//! recovery: at each height, a least-squares quadratic in (x1, x2) through the in-plane stresses
//! at the centres of the cells around the point (those that hold it and two rings of neighbours on
//! the plate unfolded across its symmetry planes, s12 odd under a mirror); its
//! linear terms are the derivatives at the point. Centres, not Gauss points: the element's
//! membrane strain E11 is constant along x1 in a cell (and E22 along x2), so its Gauss points
//! form a staircase whose fitted slope is biased low (by a quarter on two cells); the centre
//! values lie on the field to O(l^2). Each ply is integrated by 5 Gauss points (exact
//! for the in-plane stresses of linear kinematics, polynomials of degree N - 1 <= 4 in x3).

use crate::model::plate_model::Plate;
use stamp::element::Element;
use crate::outputs::patch::Patch;
use stamp::mesh::QuadMesh;
use stamp_elements::Laminate;

/// The 5-point Gauss rule on [-1, 1] (abscissa, weight), for integrals through a layer.
pub(crate) const GAUSS5: [(f64, f64); 5] = [
    (-0.906_179_845_938_664, 0.236_926_885_056_189_1),
    (-0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.0, 0.568_888_888_888_888_9),
    (0.538_469_310_105_683, 0.478_628_670_499_366_5),
    (0.906_179_845_938_664, 0.236_926_885_056_189_1),
];

/// The recovery of one probe: the Gauss points used, with the weights that give d/dx1 and d/dx2.
pub struct ShearRecovery {
    cells: Vec<usize>,
    /// (index into `cells`, weights d/dx1, d/dx2 of its centre's s11 and s22, and of its s12 (a
    /// mirror image's s12 changes sign)).
    points: Vec<(usize, [f64; 2], [f64; 2])>,
}

impl ShearRecovery {
    /// The patch around `at`: the cells that hold it and two rings of neighbours, on the plate
    /// unfolded across its symmetry planes (`planes[d]`: the coordinates x_(d+1) of the planes of
    /// normal x_(d+1)): a cell that touches a plane has its mirror image as a neighbour, so that a
    /// point near a symmetry plane (not only on it) is fitted from the cells the whole plate would
    /// give (a probe two cells from the plane read s13 9 % apart on a quarter and a half model).
    /// `holding` are the cells that hold `at`; their images that hold it too (a point on a plane)
    /// start the patch with them.
    /// None when the cells' centres do not determine a quadratic (too few, or in a line: a strip
    /// one cell wide).
    pub fn new(mesh: &QuadMesh, holding: &[usize], at: [f64; 2], planes: &[Vec<f64>; 2]) -> Option<ShearRecovery> {
        let patch = Patch::around(mesh, holding, at, planes);
        let size = mesh.element_size();
        let weights = patch.quadratic_weights()?;
        let points = patch
            .samples
            .iter()
            .zip(&weights)
            .map(|(s, w)| (s.cell, [w[1] / size, w[2] / size], [s.s12_sign * w[1] / size, s.s12_sign * w[2] / size]))
            .collect();
        Some(ShearRecovery { cells: patch.cells, points })
    }

    /// [s11,1 + s12,2, s12,1 + s22,2] at height x3 of layer k.
    fn divergence(&self, plate: &Plate, locals: &[Vec<f64>], k: usize, x3: f64, ws: &mut <Plate as Element>::Workspace) -> Option<[f64; 2]> {
        let stresses: Vec<[[f64; 6]; 4]> = self.cells.iter().zip(locals).map(|(&c, v)| plate.layer_stresses(c, k, x3, v, ws)).collect::<Option<_>>()?;
        let mut d = [0.0; 2];
        for &(i, w, w12) in &self.points {
            // the centre's value: the mean over the Gauss points
            let s: [f64; 6] = std::array::from_fn(|c| 0.25 * stresses[i].iter().map(|g| g[c]).sum::<f64>());
            d[0] += w[0] * s[0] + w12[1] * s[5];
            d[1] += w12[0] * s[5] + w[1] * s[1];
        }
        Some(d)
    }

    /// [s13, s23] at height x3 of layer k of the stack `lam` (mid-plane at x3 = 0), displacement `u`.
    pub fn shear(&self, plate: &Plate, lam: &Laminate, u: &[f64], k: usize, x3: f64) -> Option<[f64; 2]> {
        let dpn = plate.dofs_per_node();
        let locals: Vec<Vec<f64>> = self.cells.iter().map(|&c| plate.element_nodes(c).iter().flat_map(|&n| u[dpn * n..dpn * (n + 1)].iter().copied()).collect()).collect();
        let mut ws = plate.new_workspace();
        let b = lam.boundaries();
        let mut total = [0.0; 2];
        for j in 0..=k {
            let (lo, hi) = (b[j], if j == k { x3 } else { b[j + 1] });
            for &(xi, w) in &GAUSS5 {
                let z = 0.5 * (lo + hi) + 0.5 * (hi - lo) * xi;
                let d = self.divergence(plate, &locals, j, z, &mut ws)?;
                for i in 0..2 {
                    total[i] -= 0.5 * (hi - lo) * w * d[i];
                }
            }
        }
        Some(total)
    }
}

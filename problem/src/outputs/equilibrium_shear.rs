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
use stamp::mesh::QuadMesh;
use stamp_elements::Laminate;

const GAUSS5: [(f64, f64); 5] = [
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
        let tol = 1e-9 * mesh.element_size();
        // for each axis, the plane nearest the point (a patch two rings wide reaches one)
        let plane: [Option<f64>; 2] = std::array::from_fn(|d| planes[d].iter().copied().min_by(|a, b| (a - at[d]).abs().total_cmp(&(b - at[d]).abs())));
        // (cell, image: mirrored across x1's plane, across x2's)
        let mut patch: Vec<(usize, [bool; 2])> = Vec::new();
        for &c in holding {
            for img in [[false, false], [true, false], [false, true], [true, true]] {
                // an image holds the point when the point is on the planes it mirrors across
                if (0..2).all(|d| !img[d] || plane[d].is_some_and(|p| (at[d] - p).abs() <= tol)) && !patch.contains(&(c, img)) {
                    patch.push((c, img));
                }
            }
        }
        let mut node_cells: std::collections::HashMap<usize, Vec<usize>> = std::collections::HashMap::new();
        for (c, cell) in mesh.cells.iter().enumerate() {
            for &n in cell {
                node_cells.entry(n).or_default().push(c);
            }
        }
        for _ring in 0..2 {
            let mut next = patch.clone();
            for &(c, img) in &patch {
                let mut add = |x: (usize, [bool; 2])| {
                    if !next.contains(&x) {
                        next.push(x);
                    }
                };
                for &n in &mesh.cells[c] {
                    for &c2 in &node_cells[&n] {
                        add((c2, img));
                    }
                }
                // across a plane: the images of the cells that share a node on it (a node on
                // the plane is its own image, so the images around it are neighbours too)
                for d in 0..2 {
                    let Some(p) = plane[d] else { continue };
                    let mut flipped = img;
                    flipped[d] = !flipped[d];
                    for &n in mesh.cells[c].iter().filter(|&&n| (mesh.coords[n][d] - p).abs() <= tol) {
                        for &c2 in &node_cells[&n] {
                            add((c2, flipped));
                        }
                    }
                }
            }
            patch = next;
        }
        let mut cells: Vec<usize> = Vec::new();
        for &(c, _) in &patch {
            if !cells.contains(&c) {
                cells.push(c);
            }
        }
        let size = mesh.element_size();
        // (cell index, centre of the cell or its image relative to `at` / size, sign of s12 by
        // image: odd under each mirror)
        let mut samples = Vec::new();
        for &(c, img) in &patch {
            let i = cells.iter().position(|&x| x == c).expect("listed");
            let x = mesh.cell_coords(c);
            let pos: [f64; 2] = std::array::from_fn(|d| {
                let centre = 0.25 * (0..4).map(|a| x[a][d]).sum::<f64>();
                let centre = match (img[d], plane[d]) {
                    (true, Some(p)) => 2.0 * p - centre,
                    _ => centre,
                };
                (centre - at[d]) / size
            });
            samples.push((i, pos, if img[0] != img[1] { -1.0 } else { 1.0 }));
        }
        // least squares on [1, x, y, x^2, xy, y^2]: the rows of (A^T A)^-1 A^T for x and y
        let basis = |p: [f64; 2]| [1.0, p[0], p[1], p[0] * p[0], p[0] * p[1], p[1] * p[1]];
        let mut m = nalgebra::Matrix6::<f64>::zeros();
        for s in &samples {
            let b = basis(s.1);
            for r in 0..6 {
                for c in 0..6 {
                    m[(r, c)] += b[r] * b[c];
                }
            }
        }
        let sv = m.singular_values();
        if !(sv.min() > 1e-10 * sv.max()) {
            return None;
        }
        let inv = m.try_inverse()?;
        let points = samples
            .iter()
            .map(|&(i, p, sign)| {
                let w = inv * nalgebra::Vector6::from(basis(p));
                (i, [w[1] / size, w[2] / size], [sign * w[1] / size, sign * w[2] / size])
            })
            .collect();
        Some(ShearRecovery { cells, points })
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

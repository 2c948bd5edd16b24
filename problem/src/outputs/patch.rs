//! The patch of cells around a point on which stresses are recovered by a least-squares fit
//! (superconvergent patch recovery, Zienkiewicz and Zhu, Int. J. Numer. Meth. Eng. 33 (1992)
//! 1331): the cells that hold the point and two rings of neighbours, on the plate unfolded across
//! its symmetry planes, each sampled at its centre; and the weights of a quadratic in (x1, x2)
//! fitted through those samples.

use stamp::mesh::QuadMesh;

/// One sample of the fit: a cell's centre, or the centre of its mirror image.
#[derive(Debug, Clone, Copy)]
pub struct Sample {
    /// Index into [`Patch::cells`].
    pub cell: usize,
    /// The centre relative to the point, divided by the mesh's element size.
    pub pos: [f64; 2],
    /// The sign of s12 (and of any component odd under one mirror) at the image: -1 when it is
    /// mirrored across one plane only.
    pub s12_sign: f64,
}

/// The cells around a point and their samples.
pub struct Patch {
    /// The distinct cells of the patch.
    pub cells: Vec<usize>,
    pub samples: Vec<Sample>,
}

impl Patch {
    /// The cells that hold `at` (`holding`) and two rings of neighbours, on the plate unfolded
    /// across its symmetry planes (`planes[d]`: the coordinates x_(d+1) of the planes of normal
    /// x_(d+1)): a cell that touches a plane has its mirror image as a neighbour, so that a point
    /// near a symmetry plane (not only on it) is fitted from the cells the whole plate would
    /// give. The images of `holding` that hold the point too (a point on a plane) start the patch.
    pub fn around(mesh: &QuadMesh, holding: &[usize], at: [f64; 2], planes: &[Vec<f64>; 2]) -> Patch {
        Patch::with_rings(mesh, holding, at, planes, 2)
    }

    /// As [`Patch::around`] with `rings` rings of neighbours.
    pub fn with_rings(mesh: &QuadMesh, holding: &[usize], at: [f64; 2], planes: &[Vec<f64>; 2], rings: usize) -> Patch {
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
        for _ring in 0..rings {
            let mut next = patch.clone();
            for &(c, img) in &patch {
                let mut add = |x: (usize, [bool; 2])| {
                    if !next.contains(&x) {
                        next.push(x);
                    }
                };
                // the cells around each node, and across a plane the images of the cells that
                // share a node on it (a node on the plane is its own image, so the images around
                // it are neighbours too; a node on both planes has all three images around it)
                for &n in &mesh.cells[c] {
                    let on: [bool; 2] = std::array::from_fn(|d| plane[d].is_some_and(|p| (mesh.coords[n][d] - p).abs() <= tol));
                    for flip in [[false, false], [true, false], [false, true], [true, true]] {
                        if (0..2).any(|d| flip[d] && !on[d]) {
                            continue;
                        }
                        for &c2 in &node_cells[&n] {
                            add((c2, [img[0] != flip[0], img[1] != flip[1]]));
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
            samples.push(Sample { cell: i, pos, s12_sign: if img[0] != img[1] { -1.0 } else { 1.0 } });
        }
        Patch { cells, samples }
    }

    /// The least-squares quadratic c0 + c1 x + c2 y + c3 x^2 + c4 x y + c5 y^2 (x, y the sample
    /// positions, in element sizes from the point) through the samples: for each sample the
    /// weights w with c = sum_samples w f. None when the centres do not determine a quadratic (too
    /// few, or in a line: a strip one cell wide).
    pub fn quadratic_weights(&self) -> Option<Vec<[f64; 6]>> {
        let basis = |p: [f64; 2]| [1.0, p[0], p[1], p[0] * p[0], p[0] * p[1], p[1] * p[1]];
        let mut m = nalgebra::Matrix6::<f64>::zeros();
        for s in &self.samples {
            let b = basis(s.pos);
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
        Some(
            self.samples
                .iter()
                .map(|s| {
                    let w = inv * nalgebra::Vector6::from(basis(s.pos));
                    std::array::from_fn(|i| w[i])
                })
                .collect(),
        )
    }

    /// The least-squares polynomial of degree `degree` in (x, y) (the sample positions, in element
    /// sizes from the point), its monomials ordered by degree, x's power falling within one (1;
    /// x, y; x^2, xy, y^2; x^3, x^2 y, ...): for each sample the weights w of the coefficients,
    /// c = sum_samples w f. None when the samples do not determine it.
    pub fn polynomial_weights(&self, degree: usize) -> Option<Vec<Vec<f64>>> {
        let powers: Vec<(i32, i32)> = (0..=degree as i32).flat_map(|d| (0..=d).map(move |j| (d - j, j))).collect();
        let m = powers.len();
        let basis = |p: [f64; 2]| nalgebra::DVector::from_iterator(m, powers.iter().map(|&(i, j)| p[0].powi(i) * p[1].powi(j)));
        let mut a = nalgebra::DMatrix::<f64>::zeros(m, m);
        for s in &self.samples {
            let b = basis(s.pos);
            a += &b * b.transpose();
        }
        let sv = a.singular_values();
        if !(sv.min() > 1e-10 * sv.max()) {
            return None;
        }
        let inv = a.try_inverse()?;
        Some(self.samples.iter().map(|s| (&inv * basis(s.pos)).iter().copied().collect()).collect())
    }
}

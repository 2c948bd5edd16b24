//! A recovered contact pressure: a continuous bilinear field on the contact face made from the
//! nodal contact forces, written beside the nodal pressure (docs/design.md, "The recovered
//! contact pressure").
//!
//! The nodal pressure q_i = f_i / w_i (f_i the normal contact force on node i, w_i its tributary
//! area) is exact for a uniform pressure, but on gmsh triangles cut into quadrilaterals the nodes'
//! tributary areas and the plate's stiffness around them differ from node to node, and so does q.
//! Two recoveries of a field p_h = sum_i N_i p_i from the forces f, both on the reference face
//! (the multiplier is a force per unit reference area and the nodal weights are reference areas:
//! the recovered field is a pressure per unit reference area like the nodal one, and its mass
//! matrix is fixed):
//!
//! * [`Recovery::Projection`]: the L2 projection, M p = f, M the consistent mass matrix
//!   M_ij = int N_i N_j dA of the zone's cells (the face's cells with a loaded node). Its integral
//!   over those cells is 1^T M p = sum f. M^-1 undoes a smoothing (the consistent mass of a regular
//!   mesh is the stencil [1/6, 2/3, 1/6]^2 times A_i), so it amplifies node-to-node differences of
//!   the forces (a checkerboard up to 9 times) and undershoots below zero around the zone.
//! * [`Recovery::Smoothing`]: the lumped-mass-weighted patch average p_i = sum_j M_ij q_j / A_i,
//!   q_j = f_j / A_j, A_i = sum_j M_ij = int N_i dA over the face: the consistent mass's stencil
//!   applied to the nodal pressure (a checkerboard is damped 9 times), repeated `passes` times.
//!   Conservative exactly: int p_h dA = sum_i A_i p_i = sum_j A_j q_j = sum f, over the whole face
//!   (the field p_h spreads by one ring of cells per pass, and 1^T M = A^T). A uniform pressure is
//!   kept where the patch is inside the zone.
//!
//! The default, [`RECOVERY`], is one smoothing pass: the measurements in
//! docs/verification/contact-pressure.md. One call allocates a few vectors over the pair's points
//! and the zone's cells, nothing per cell.

use super::ContactPair;
use crate::mesh::{bilinear, bilinear_jacobian};

/// How the recovered pressure is made from the nodal forces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Recovery {
    /// The consistent L2 projection M p = f over the cells with a loaded node.
    Projection,
    /// The lumped-mass-weighted patch average of the nodal pressure, `passes` times.
    Smoothing { passes: usize },
}

/// The recovery written as `contact_pressure_recovered` and `<punch>_pressure_recovered`.
pub const RECOVERY: Recovery = Recovery::Smoothing { passes: 1 };

/// The recovered pressure of a pair, at each of its points, and what the checks read off it.
#[derive(Debug, Clone)]
pub struct RecoveredPressure {
    /// p_i at every contact point of the pair (0 outside the recovered field's support).
    pub pressure: Vec<f64>,
    /// The integral of the recovered field over its cells: 1^T M p (projection) or sum A_i p_i
    /// (smoothing); equal to `force` to round-off.
    pub integral: f64,
    /// sum f_i, the punch's normal force (sum of w_i q_i over the points).
    pub force: f64,
    /// Conjugate-gradient iterations of the projection (0 for the smoothing).
    pub iterations: usize,
}

/// The element mass matrix of a bilinear cell (2 x 2 Gauss points: exact, N_a N_b det J being at
/// most cubic in each cell coordinate) into `m`; false for a degenerate or inverted cell.
fn cell_mass(x: &[[f64; 2]; 4], m: &mut [[f64; 4]; 4]) -> bool {
    let g = 1.0 / 3f64.sqrt();
    *m = [[0.0; 4]; 4];
    for &(s, t) in &[(-g, -g), (g, -g), (g, g), (-g, g)] {
        let (n, dn) = bilinear(s, t);
        let det = bilinear_jacobian(x, &dn);
        if !(det > 0.0 && det.is_finite()) {
            return false;
        }
        for a in 0..4 {
            for b in 0..4 {
                m[a][b] += n[a] * n[b] * det;
            }
        }
    }
    true
}

/// The recovered pressure of `pair` on the face made of `cells` (four node indices each,
/// counter-clockwise in the reference plane; a cell counts when its four nodes are points of the
/// pair), with the in-plane reference coordinates of the points (their `x_ref`).
pub fn recovered_pressure(pair: &ContactPair, cells: &[[usize; 4]], method: Recovery) -> RecoveredPressure {
    let np = pair.points.len();
    let q = pair.pressures();
    let f: Vec<f64> = pair.points.iter().zip(&q).map(|(p, q)| p.weight * q).collect();
    let force: f64 = f.iter().sum();
    // the pair's point at each node
    let max_node = pair.points.iter().map(|p| p.node).max().map_or(0, |n| n + 1);
    let mut point_of = vec![u32::MAX; max_node];
    for (k, p) in pair.points.iter().enumerate() {
        point_of[p.node] = k as u32;
    }
    // the face's cells by point index, with their mass matrices, and A_i over the whole face
    let mut face: Vec<[u32; 4]> = Vec::new();
    let mut mass: Vec<[[f64; 4]; 4]> = Vec::new();
    let mut area = vec![0.0; np];
    let mut m = [[0.0; 4]; 4];
    for cell in cells {
        let Some(pts) = cell.iter().map(|&n| point_of.get(n).copied().filter(|&k| k != u32::MAX)).collect::<Option<Vec<u32>>>() else { continue };
        let pts = [pts[0], pts[1], pts[2], pts[3]];
        let x = pts.map(|k| [pair.points[k as usize].x_ref[0], pair.points[k as usize].x_ref[1]]);
        if !cell_mass(&x, &mut m) {
            continue;
        }
        for a in 0..4 {
            area[pts[a] as usize] += m[a].iter().sum::<f64>();
        }
        face.push(pts);
        mass.push(m);
    }
    match method {
        Recovery::Smoothing { passes } => {
            // q_j = f_j / A_j: the nodal pressure with the face's own lumped mass
            let mut p: Vec<f64> = f.iter().zip(&area).map(|(f, a)| if *a > 0.0 { f / a } else { 0.0 }).collect();
            let mut next = vec![0.0; np];
            for _ in 0..passes {
                next.iter_mut().for_each(|v| *v = 0.0);
                for (pts, m) in face.iter().zip(&mass) {
                    let v = pts.map(|k| p[k as usize]);
                    if v.iter().all(|&v| v == 0.0) {
                        continue;
                    }
                    for a in 0..4 {
                        next[pts[a] as usize] += (0..4).map(|b| m[a][b] * v[b]).sum::<f64>();
                    }
                }
                for (n, a) in next.iter_mut().zip(&area) {
                    *n = if *a > 0.0 { *n / a } else { 0.0 };
                }
                std::mem::swap(&mut p, &mut next);
            }
            let integral = p.iter().zip(&area).map(|(p, a)| p * a).sum();
            RecoveredPressure { pressure: p, integral, force, iterations: 0 }
        }
        Recovery::Projection => {
            // the zone: the face's cells with a loaded node; its unknowns: their nodes
            let zone: Vec<usize> = (0..face.len()).filter(|&c| face[c].iter().any(|&k| f[k as usize] != 0.0)).collect();
            let mut local = vec![u32::MAX; np];
            let mut nodes: Vec<usize> = Vec::new();
            for &c in &zone {
                for &k in &face[c] {
                    if local[k as usize] == u32::MAX {
                        local[k as usize] = nodes.len() as u32;
                        nodes.push(k as usize);
                    }
                }
            }
            let n = nodes.len();
            let cells: Vec<[usize; 4]> = zone.iter().map(|&c| face[c].map(|k| local[k as usize] as usize)).collect();
            let masses: Vec<&[[f64; 4]; 4]> = zone.iter().map(|&c| &mass[c]).collect();
            let apply = |x: &[f64], y: &mut [f64]| {
                y.iter_mut().for_each(|v| *v = 0.0);
                for (c, m) in cells.iter().zip(&masses) {
                    for a in 0..4 {
                        y[c[a]] += (0..4).map(|b| m[a][b] * x[c[b]]).sum::<f64>();
                    }
                }
            };
            let mut diag = vec![0.0; n];
            for (c, m) in cells.iter().zip(&masses) {
                for a in 0..4 {
                    diag[c[a]] += m[a][a];
                }
            }
            let b: Vec<f64> = nodes.iter().map(|&k| f[k]).collect();
            let (x, iterations) = pcg(&apply, &diag, &b);
            let mut y = vec![0.0; n];
            apply(&x, &mut y);
            let integral = y.iter().sum();
            let mut pressure = vec![0.0; np];
            for (i, &k) in nodes.iter().enumerate() {
                pressure[k] = x[i];
            }
            RecoveredPressure { pressure, integral, force, iterations }
        }
    }
}

/// Jacobi-preconditioned conjugate gradients for the SPD mass matrix (its condition number is
/// bounded independently of the mesh size: a few tens of iterations), to a relative residual of
/// 1e-14.
fn pcg(apply: &dyn Fn(&[f64], &mut [f64]), diag: &[f64], b: &[f64]) -> (Vec<f64>, usize) {
    let n = b.len();
    let mut x = vec![0.0; n];
    let mut r = b.to_vec();
    let norm_b = b.iter().map(|v| v * v).sum::<f64>().sqrt();
    if norm_b == 0.0 {
        return (x, 0);
    }
    let mut z: Vec<f64> = r.iter().zip(diag).map(|(r, d)| r / d).collect();
    let mut d = z.clone();
    let mut q = vec![0.0; n];
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
    for it in 1..=1000 {
        apply(&d, &mut q);
        let alpha = rz / d.iter().zip(&q).map(|(a, b)| a * b).sum::<f64>();
        for i in 0..n {
            x[i] += alpha * d[i];
            r[i] -= alpha * q[i];
        }
        if r.iter().map(|v| v * v).sum::<f64>().sqrt() <= 1e-14 * norm_b {
            return (x, it);
        }
        for i in 0..n {
            z[i] = r[i] / diag[i];
        }
        let rz_new: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
        let beta = rz_new / rz;
        rz = rz_new;
        for i in 0..n {
            d[i] = z[i] + beta * d[i];
        }
    }
    (x, 1000)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::{ContactKinematics, ContactPoint};
    use crate::surface::ContactSurface;
    use nalgebra::Vector3;
    use std::sync::Arc;

    struct Plane;
    impl ContactSurface for Plane {
        fn psi(&self, x: &Vector3<f64>) -> f64 {
            -x[2]
        }
        fn gradient(&self, _x: &Vector3<f64>) -> Vector3<f64> {
            Vector3::new(0.0, 0.0, -1.0)
        }
    }

    /// An n x n mesh of the unit square with its interior nodes moved by up to a quarter of a cell
    /// (a deterministic pseudo-random pattern), every node a point with its tributary area, and
    /// the pressure q(x, y) at the nodes.
    fn pair(n: usize, q: impl Fn(usize, f64, f64) -> f64) -> (ContactPair, Vec<[usize; 4]>) {
        let h = 1.0 / n as f64;
        let mut coords = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let inner = i > 0 && i < n && j > 0 && j < n;
                let s = ((i * 7 + j * 13) % 11) as f64 / 11.0 - 0.5;
                let t = ((i * 5 + j * 3) % 9) as f64 / 9.0 - 0.5;
                let (dx, dy) = if inner { (0.5 * h * s, 0.5 * h * t) } else { (0.0, 0.0) };
                coords.push([i as f64 * h + dx, j as f64 * h + dy]);
            }
        }
        let cells: Vec<[usize; 4]> = (0..n).flat_map(|j| (0..n).map(move |i| [j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i])).collect();
        let mesh = crate::mesh::QuadMesh { coords: coords.clone(), cells: cells.clone(), ..Default::default() };
        let w = mesh.nodal_areas();
        let points = coords.iter().enumerate().map(|(k, x)| ContactPoint { node: k, x_ref: [x[0], x[1], 0.0], dofs: [3 * k, 3 * k + 1, 3 * k + 2], weight: w[k] }).collect();
        let mut pair = ContactPair::new("plane", Arc::new(Plane), points, 1.0, ContactKinematics::Exact);
        for (k, x) in coords.iter().enumerate() {
            pair.state[k].grad = [0.0, 0.0, -1.0];
            pair.state[k].lambda = -q(k, x[0], x[1]);
        }
        (pair, cells)
    }

    #[test]
    fn both_recoveries_carry_the_force_and_keep_a_uniform_pressure() {
        // a disk of noisy pressure: loaded nodes with unloaded ones around them
        let noisy = |k: usize, x: f64, y: f64| if (x - 0.5).hypot(y - 0.5) < 0.3 { 1.0 + 0.5 * ((k * 37 % 17) as f64 / 17.0 - 0.5) } else { 0.0 };
        let (p, cells) = pair(16, noisy);
        for method in [Recovery::Projection, Recovery::Smoothing { passes: 1 }, Recovery::Smoothing { passes: 3 }] {
            let r = recovered_pressure(&p, &cells, method);
            assert!(r.force > 0.2, "{method:?}: the disk carries a force: {}", r.force);
            assert!((r.integral - r.force).abs() <= 1e-13 * r.force, "{method:?}: integral {} against force {}", r.integral, r.force);
            if method == Recovery::Projection {
                assert!(r.iterations > 0 && r.iterations < 200, "CG iterations {}", r.iterations);
            }
        }
        // uniform 2.5 over the whole square: both give it back at every node
        let (p, cells) = pair(8, |_, _, _| 2.5);
        for method in [Recovery::Projection, Recovery::Smoothing { passes: 1 }] {
            let r = recovered_pressure(&p, &cells, method);
            let worst = r.pressure.iter().map(|v| (v - 2.5).abs()).fold(0.0, f64::max);
            assert!(worst < 1e-12, "{method:?}: largest deviation {worst:e}");
        }
    }

    #[test]
    fn the_smoothing_damps_a_checkerboard_and_the_projection_amplifies_it() {
        let n = 12;
        let board = move |k: usize, _: f64, _: f64| 1.0 + 0.1 * if (k % (n + 1) + k / (n + 1)).is_multiple_of(2) { 1.0 } else { -1.0 };
        let (p, cells) = pair(n, board);
        let q = p.pressures();
        // the amplitude of the checkerboard at the nodes away from the edge
        let inner: Vec<usize> = (0..q.len()).filter(|&k| (3..n - 2).contains(&(k % (n + 1))) && (3..n - 2).contains(&(k / (n + 1)))).collect();
        let spread = |v: &[f64]| {
            let (lo, hi) = inner.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &k| (lo.min(v[k]), hi.max(v[k])));
            hi - lo
        };
        let s = spread(&recovered_pressure(&p, &cells, Recovery::Smoothing { passes: 1 }).pressure) / spread(&q);
        let pr = spread(&recovered_pressure(&p, &cells, Recovery::Projection).pressure) / spread(&q);
        assert!(s < 0.5, "smoothing: the checkerboard keeps {s} of its amplitude");
        assert!(pr > 2.0, "projection: the checkerboard grows {pr} times");
    }
}

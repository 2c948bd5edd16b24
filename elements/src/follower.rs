//! Follower loads on the plate: a pressure that acts normal to the deformed face on its deformed
//! area, and a couple on an edge carried by the two face planes. Both are
//! [`DeformationDependentLoad`]s: the model subtracts them (times the load factor) from the
//! residual and their derivative from the tangent, so Newton keeps its quadratic convergence.
//!
//! # Follower pressure
//!
//! The face S+ (x3 = delta+) or S- (x3 = delta-) of a cell is the bilinear surface
//! x(xi) = sum_a N_a(xi) (X_a + v_a), X_a = (x1_a, x2_a, delta±) and v_a the face displacements.
//! A pressure p (positive pushing on the face towards the plate) gives the force density
//! -p n da = -s p (x,1 x x,2) dxi1 dxi2, with s = +1 on S+ and -1 on S- (the outward normal of S- is
//! -e3 in the reference) times the sign of the cell's orientation. The nodal forces
//! F_a = -s p int N_a (x,1 x x,2) dxi are integrated with 2 x 2 Gauss points (exact: the integrand
//! is at most quadratic in each xi). With \[a\]x b = a x b, d(x,1 x x,2)/dx_b = N_b,1 (-\[x,2\]x) +
//! N_b,2 \[x,1\]x, so dF_a/dx_b = -s p int N_a (N_b,2 \[x,1\]x - N_b,1 \[x,2\]x) dxi: not symmetric per
//! cell (it is globally for a closed surface with fixed boundary).
//!
//! # Couple on an edge
//!
//! The plate has no rotation unknowns: a couple m per unit length along an edge acts through the
//! two face planes. At an edge node, with the couple M = m L_n (L_n the node's share of the edge
//! length, half of each adjacent segment), equal and opposite forces f+ on the node's S+ point and
//! f- = -f+ on its S- point form a pair whose resultant is zero and whose moment (about any point)
//! is x+ x f+ + x- x f- = d x f+, d = x+ - x- the fibre through the node. The choice
//! f+ = (M x d) / |d|^2 (perpendicular to the fibre) gives
//! d x f+ = (M (d.d) - d (d.M)) / |d|^2 = M - (M.d) d / |d|^2:
//! the part of M perpendicular to the fibre, exactly. A component of M along the fibre (a twist
//! about the fibre) cannot be carried by forces on the fibre's two ends and is dropped.
//!
//! * `follower = true` ([`FollowerCouple`]): d is the current fibre, d = h e3 + v+ - v-. The force
//!   pair turns with the fibre and stays perpendicular to it; its moment is M minus its part along
//!   the current fibre. For an edge that turns about M's own axis (a strip rolled up by an end
//!   moment about the axis of the edge) M stays perpendicular to the fibre and the full M acts at
//!   any rotation. The load stiffness: with q = d.d,
//!   df+/dd = \[M\]x / q - 2 (M x d) d^T / q^2, and dd/dv+ = I, dd/dv- = -I, so
//!   dF/dv = [[A, -A], [-A, A]] on (v+, v-) with A = df+/dd.
//! * `follower = false` ([`fixed_couple_force`]): d is the reference fibre h e3, the pair of
//!   dead forces f+ = (M x e3) / h, f- = -f+. Its moment is M at the reference state (M3, a twist
//!   about the normal, must be zero: it would be dropped) and d x f+ = M cos(theta) after the fibre
//!   turned by theta about M's axis: it does not follow the edge (it vanishes at a quarter turn).

use crate::plate::Face;
use stamp::follower::DeformationDependentLoad;
use stamp::mesh::{bilinear, quad_signed_area};
use crate::geometry::GAUSS_POINTS;

#[inline(always)]
fn cross(a: &[f64; 3], b: &[f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

/// The matrix [a]x of the cross product: [a]x b = a x b.
#[inline(always)]
fn skew(a: &[f64; 3]) -> [[f64; 3]; 3] {
    [[0.0, -a[2], a[1]], [a[2], 0.0, -a[0]], [-a[1], a[0], 0.0]]
}

/// A pressure on one face of a set of cells that acts normal to the deformed face on its deformed
/// area (see the module doc).
pub struct FollowerPressure {
    name: String,
    face: Face,
    cells: Vec<[usize; 4]>,
    /// Reference positions of the cell's face nodes.
    x: Vec<[[f64; 3]; 4]>,
    /// -s p per cell and Gauss point (the pressure at load factor 1 there, the face's and the cell
    /// orientation's sign).
    scale: Vec<[f64; 4]>,
    /// Shape functions and their xi-derivatives at the 2 x 2 Gauss points (weight 1).
    gauss: [([f64; 4], [[f64; 2]; 4]); 4],
    /// Unknowns per node of the plate (see [`Face::dof_in`]).
    dofs_per_node: usize,
    /// The cells evaluated (a process's share, see `share_nodes`); None: all.
    taken: Option<Vec<bool>>,
}

impl FollowerPressure {
    /// Pressure `p` (at load factor 1, positive towards the plate) on `face` (at x3 = `z`) of
    /// `cells` of a mesh with nodal `coords`.
    pub fn new(name: impl Into<String>, coords: &[[f64; 2]], cells: &[[usize; 4]], face: Face, z: f64, p: f64) -> Self {
        Self::varying(name, coords, cells, face, z, &|_, _| p)
    }

    /// The same with a pressure p(x1, x2) that varies over the face, taken at the reference
    /// position of each Gauss point (the pressure stays with the material point it acts on).
    pub fn varying(name: impl Into<String>, coords: &[[f64; 2]], cells: &[[usize; 4]], face: Face, z: f64, p: &dyn Fn(f64, f64) -> f64) -> Self {
        let s_face = match face {
            Face::Top => 1.0,
            Face::Bottom => -1.0,
        };
        let gauss = GAUSS_POINTS.map(|[s, t]| bilinear(s, t));
        let mut x = Vec::with_capacity(cells.len());
        let mut scale = Vec::with_capacity(cells.len());
        for c in cells {
            let xy = c.map(|n| coords[n]);
            let orient = if quad_signed_area(&xy) >= 0.0 { 1.0 } else { -1.0 };
            x.push(xy.map(|q| [q[0], q[1], z]));
            scale.push(gauss.map(|(n, _)| {
                let at = |i: usize| (0..4).map(|a| n[a] * xy[a][i]).sum::<f64>();
                -s_face * orient * p(at(0), at(1))
            }));
        }
        FollowerPressure { name: name.into(), face, cells: cells.to_vec(), x, scale, gauss, dofs_per_node: crate::DOFS_PER_NODE, taken: None }
    }
    /// The same on a plate with `n` unknowns per node (default: the paper's six).
    pub fn with_dofs_per_node(mut self, n: usize) -> Self {
        self.dofs_per_node = n;
        self
    }
}

impl DeformationDependentLoad for FollowerPressure {
    fn name(&self) -> &str {
        &self.name
    }

    /// The cells with a node of `own`.
    fn share_nodes(&mut self, own: Option<&[bool]>) {
        self.taken = own.map(|own| self.cells.iter().map(|c| c.iter().any(|&n| own.get(n).copied().unwrap_or(false))).collect());
    }

    fn add_force_and_stiffness(&self, u: &[f64], force: &mut [f64], mut tangent: Option<&mut dyn FnMut(usize, usize, f64)>) {
        for (k, ((cell, x0), scales)) in self.cells.iter().zip(&self.x).zip(&self.scale).enumerate() {
            if self.taken.as_ref().is_some_and(|t| !t[k]) {
                continue;
            }
            let mut dof = [[0usize; 3]; 4];
            let mut x = *x0;
            for a in 0..4 {
                for i in 0..3 {
                    dof[a][i] = self.face.dof_in(self.dofs_per_node, cell[a], i);
                    x[a][i] += u[dof[a][i]];
                }
            }
            let mut f = [[0.0; 3]; 4];
            let mut k = [[[[0.0; 3]; 3]; 4]; 4];
            for ((n, dn), &scale) in self.gauss.iter().zip(scales) {
                let mut g1 = [0.0; 3];
                let mut g2 = [0.0; 3];
                for a in 0..4 {
                    for i in 0..3 {
                        g1[i] += dn[a][0] * x[a][i];
                        g2[i] += dn[a][1] * x[a][i];
                    }
                }
                let nv = cross(&g1, &g2);
                for a in 0..4 {
                    for i in 0..3 {
                        f[a][i] += scale * n[a] * nv[i];
                    }
                }
                if tangent.is_some() {
                    let (s1, s2) = (skew(&g1), skew(&g2));
                    for a in 0..4 {
                        for b in 0..4 {
                            let (c1, c2) = (scale * n[a] * dn[b][1], scale * n[a] * dn[b][0]);
                            for i in 0..3 {
                                for j in 0..3 {
                                    k[a][b][i][j] += c1 * s1[i][j] - c2 * s2[i][j];
                                }
                            }
                        }
                    }
                }
            }
            for a in 0..4 {
                for i in 0..3 {
                    force[dof[a][i]] += f[a][i];
                }
            }
            if let Some(add) = tangent.as_mut() {
                for a in 0..4 {
                    for b in 0..4 {
                        for i in 0..3 {
                            for j in 0..3 {
                                add(dof[a][i], dof[b][j], k[a][b][i][j]);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// A couple on the nodes of an edge carried by a force pair perpendicular to the current fibre
/// (`follower = true`; see the module doc).
pub struct FollowerCouple {
    name: String,
    /// (node, the couple M = m L_n at load factor 1).
    nodes: Vec<(usize, [f64; 3])>,
    /// The reference fibre h e3.
    h: f64,
    /// Unknowns per node of the plate (see [`Face::dof_in`]).
    dofs_per_node: usize,
    /// The nodes evaluated (a process's share, see `share_nodes`); None: all.
    taken: Option<Vec<bool>>,
}

impl FollowerCouple {
    /// Couples `nodes` = (node, m L_n) on a plate of thickness `h`.
    pub fn new(name: impl Into<String>, nodes: Vec<(usize, [f64; 3])>, h: f64) -> Self {
        FollowerCouple { name: name.into(), nodes, h, dofs_per_node: crate::DOFS_PER_NODE, taken: None }
    }
    /// The same on a plate with `n` unknowns per node (default: the paper's six).
    pub fn with_dofs_per_node(mut self, n: usize) -> Self {
        self.dofs_per_node = n;
        self
    }
}

impl DeformationDependentLoad for FollowerCouple {
    fn name(&self) -> &str {
        &self.name
    }

    /// The own nodes.
    fn share_nodes(&mut self, own: Option<&[bool]>) {
        self.taken = own.map(|own| self.nodes.iter().map(|&(n, _)| own.get(n).copied().unwrap_or(false)).collect());
    }

    fn add_force_and_stiffness(&self, u: &[f64], force: &mut [f64], mut tangent: Option<&mut dyn FnMut(usize, usize, f64)>) {
        for (k, &(node, m)) in self.nodes.iter().enumerate() {
            if self.taken.as_ref().is_some_and(|t| !t[k]) {
                continue;
            }
            let top = [0, 1, 2].map(|i| Face::Top.dof_in(self.dofs_per_node, node, i));
            let bottom = [0, 1, 2].map(|i| Face::Bottom.dof_in(self.dofs_per_node, node, i));
            let mut d = [0.0, 0.0, self.h];
            for i in 0..3 {
                d[i] += u[top[i]] - u[bottom[i]];
            }
            let q = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            let md = cross(&m, &d);
            for i in 0..3 {
                force[top[i]] += md[i] / q;
                force[bottom[i]] -= md[i] / q;
            }
            if let Some(add) = tangent.as_mut() {
                let s = skew(&m);
                for i in 0..3 {
                    for j in 0..3 {
                        let a = s[i][j] / q - 2.0 * md[i] * d[j] / (q * q);
                        add(top[i], top[j], a);
                        add(top[i], bottom[j], -a);
                        add(bottom[i], top[j], -a);
                        add(bottom[i], bottom[j], a);
                    }
                }
            }
        }
    }
}

/// The dead force f+ = (M x e3) / h on the S+ point of a node for a fixed-direction couple M
/// (`follower = false`; f- = -f+ on its S- point; see the module doc). M3 must be zero.
pub fn fixed_couple_force(m: [f64; 3], h: f64) -> [f64; 3] {
    let f = cross(&m, &[0.0, 0.0, 1.0]);
    f.map(|x| x / h)
}

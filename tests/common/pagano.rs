//! Pagano's exact 3D elasticity solution of a simply supported rectangular cross-ply plate under a
//! sinusoidal load (N. J. Pagano, "Exact solutions for rectangular bidirectional composites and
//! sandwich plates", J. Compos. Mater. 4 (1970) 20-34), by the state-space (transfer-matrix) form:
//! with p = pi/a, q = pi/b and
//!
//!   u = U(z) cos px sin qy,  v = V(z) sin px cos qy,  w = W(z) sin px sin qy,
//!   s_xz = X(z) cos px sin qy,  s_yz = Y(z) sin px cos qy,  s_zz = Z(z) sin px sin qy,
//!
//! the diaphragm supports (w = 0, tangential displacement 0, s_nn = 0 on the edges) hold
//! identically, and the 3D equilibrium and law of each orthotropic layer (axes along x, y: C16 =
//! C26 = C36 = C45 = 0) become the constant-coefficient system S' = A S for S = [U, V, W, X, Y, Z]:
//!
//!   U' = X / C55 - p W,   V' = Y / C44 - q W,   W' = (Z + C13 p U + C23 q V) / C33,
//!   X' = -p s_xx + q s_xy,  Y' = p s_xy - q s_yy,  Z' = p X + q Y,
//!
//! with s_xx = -C11 p U - C12 q V + C13 W', s_yy = -C12 p U - C22 q V + C23 W', s_xy = C66 (q U + p V)
//! (the amplitudes of sin sin, sin sin, cos cos). S is continuous at the interfaces (perfect
//! bonding), so S(top) = prod_k exp(A_k h_k) S(bottom); the free bottom face (X = Y = Z = 0) and the
//! loaded top face (X = Y = 0, Z = q0) fix U, V, W at the bottom.
//!
//! Also here: the continuum limit of stamp's layerwise model for the same problem (the Navier
//! solution of the model: the same trigonometric factors times the Lagrange polynomials of N
//! equally spaced surfaces in each layer, its energy integrated exactly through the thickness),
//! which separates the model's error from the mesh's.

use nalgebra::{DMatrix, DVector, Matrix6, Vector6};

/// C in the plate's axes (Voigt [11, 22, 33, 23, 13, 12], engineering shear), of a layer whose
/// axes are along x and y.
pub type Stiffness = [[f64; 6]; 6];

/// One layer: thickness and stiffness.
#[derive(Debug, Clone)]
pub struct Layer {
    pub thickness: f64,
    pub c: Stiffness,
}

/// The exact solution for the load s_zz = q0 sin px sin qy on the top face (upwards for q0 > 0),
/// layers from the bottom up, the mid-plane at z = 0.
pub struct Pagano {
    pub layers: Vec<Layer>,
    pub a: f64,
    pub b: f64,
    pub q0: f64,
    /// The state through the layers.
    pub stack: ThroughThickness,
}

/// The state S(z) = [U, V, W, X, Y, Z] through a stack of layers whose equations are S' = A_k S
/// in layer k (constant A_k: S = exp(A_k (z - z_k)) S(z_k)), continuous at the interfaces, with
/// a traction-free bottom face (X = Y = Z = 0) and the top face loaded by X = Y = 0, Z = q0:
/// S(top) = T S(bottom), T the product of the layers' exponentials, whose lower-left 3 x 3 block
/// fixes U, V, W at the bottom. The mid-plane of the stack is at z = 0.
pub struct ThroughThickness {
    /// z of the layer boundaries.
    pub z: Vec<f64>,
    /// The state at the bottom of each layer.
    start: Vec<Vector6<f64>>,
    system: Vec<Matrix6<f64>>,
    /// A length of the plate: the round-off scale of z.
    length: f64,
}

impl ThroughThickness {
    pub fn new(layers: &[Layer], system: Vec<Matrix6<f64>>, q0: f64, length: f64) -> ThroughThickness {
        let h: f64 = layers.iter().map(|l| l.thickness).sum();
        let mut z = vec![-0.5 * h];
        for l in layers {
            z.push(z.last().unwrap() + l.thickness);
        }
        let mut t = Matrix6::identity();
        for (l, m) in layers.iter().zip(&system) {
            t = (m * l.thickness).exp() * t;
        }
        let k = t.fixed_view::<3, 3>(3, 0).into_owned();
        let u0 = k.lu().solve(&nalgebra::Vector3::new(0.0, 0.0, q0)).expect("a regular plate");
        let mut s = Vector6::new(u0[0], u0[1], u0[2], 0.0, 0.0, 0.0);
        let mut start = Vec::new();
        for (l, m) in layers.iter().zip(&system) {
            start.push(s);
            s = (m * l.thickness).exp() * s;
        }
        ThroughThickness { z, start, system, length }
    }

    /// The state [U, V, W, X, Y, Z] at z in layer k.
    pub fn state(&self, k: usize, z: f64) -> Vector6<f64> {
        (self.system[k] * (z - self.z[k])).exp() * self.start[k]
    }

    /// The layer that holds z (the lower one at an interface).
    pub fn layer_at(&self, z: f64) -> usize {
        let n = self.start.len();
        (0..n).find(|&k| z <= self.z[k + 1] + 1e-12 * self.length).unwrap_or(n - 1)
    }
}

fn system(c: &Stiffness, p: f64, q: f64) -> Matrix6<f64> {
    let (c11, c12, c13, c22, c23, c33) = (c[0][0], c[0][1], c[0][2], c[1][1], c[1][2], c[2][2]);
    let (c44, c55, c66) = (c[3][3], c[4][4], c[5][5]);
    let mut m = Matrix6::zeros();
    // W' row: (Z + C13 p U + C23 q V) / C33
    let wp = [c13 * p / c33, c23 * q / c33, 0.0, 0.0, 0.0, 1.0 / c33];
    // U', V'
    m[(0, 3)] = 1.0 / c55;
    m[(0, 2)] = -p;
    m[(1, 4)] = 1.0 / c44;
    m[(1, 2)] = -q;
    for j in 0..6 {
        m[(2, j)] = wp[j];
    }
    // s_xx, s_yy, s_xy as rows over S
    let mut sxx = [-c11 * p, -c12 * q, 0.0, 0.0, 0.0, 0.0];
    let mut syy = [-c12 * p, -c22 * q, 0.0, 0.0, 0.0, 0.0];
    for j in 0..6 {
        sxx[j] += c13 * wp[j];
        syy[j] += c23 * wp[j];
    }
    let sxy = [c66 * q, c66 * p, 0.0, 0.0, 0.0, 0.0];
    for j in 0..6 {
        m[(3, j)] = -p * sxx[j] + q * sxy[j];
        m[(4, j)] = p * sxy[j] - q * syy[j];
    }
    m[(5, 3)] = p;
    m[(5, 4)] = q;
    m
}

impl Pagano {
    pub fn new(layers: Vec<Layer>, a: f64, b: f64, q0: f64) -> Pagano {
        let (p, q) = (std::f64::consts::PI / a, std::f64::consts::PI / b);
        // S(top) = T S(bottom), S(bottom) = [U, V, W, 0, 0, 0]
        let stack = ThroughThickness::new(&layers, layers.iter().map(|l| system(&l.c, p, q)).collect(), q0, a);
        Pagano { layers, a, b, q0, stack }
    }

    /// The displacement [u, v, w] at (x, y, z).
    pub fn displacement(&self, x: f64, y: f64, z: f64) -> [f64; 3] {
        let s = self.stack.state(self.stack.layer_at(z), z);
        let (px, qy) = (std::f64::consts::PI * x / self.a, std::f64::consts::PI * y / self.b);
        [s[0] * px.cos() * qy.sin(), s[1] * px.sin() * qy.cos(), s[2] * px.sin() * qy.sin()]
    }

    /// The stresses [s_xx, s_yy, s_zz, s_yz, s_xz, s_xy] at (x, y, z) in layer k.
    pub fn stress(&self, k: usize, x: f64, y: f64, z: f64) -> [f64; 6] {
        let (p, q) = (std::f64::consts::PI / self.a, std::f64::consts::PI / self.b);
        let s = self.stack.state(k, z);
        let c = &self.layers[k].c;
        let wp = (s[5] + c[0][2] * p * s[0] + c[1][2] * q * s[1]) / c[2][2];
        let sxx = -c[0][0] * p * s[0] - c[0][1] * q * s[1] + c[0][2] * wp;
        let syy = -c[0][1] * p * s[0] - c[1][1] * q * s[1] + c[1][2] * wp;
        let sxy = c[5][5] * (q * s[0] + p * s[1]);
        let (sx, cx, sy, cy) = ((p * x).sin(), (p * x).cos(), (q * y).sin(), (q * y).cos());
        [sxx * sx * sy, syy * sx * sy, s[5] * sx * sy, s[4] * sx * cy, s[3] * cx * sy, sxy * cx * cy]
    }
}

/// The continuum limit of the layerwise model with `n` equally spaced surfaces per layer (the
/// faces of each layer among them) for the same plate and load: the amplitudes [U_s, V_s, W_s] of
/// every surface s from the bottom up, from K x = f with K = int B^T C B dz (exact: n + 1 Gauss
/// points per layer) and the load on W of the top surface. B maps the amplitudes to those of the
/// strains [e_xx, e_yy, e_zz, g_yz, g_xz, g_xy] (factors sin sin, sin sin, sin sin, sin cos, cos sin,
/// cos cos, whose squares all integrate to ab/4 over the plate, which cancels).
pub struct Layerwise {
    pub z: Vec<f64>,
    pub x: DVector<f64>,
    pub n: usize,
    pub layers: Vec<Layer>,
    pub a: f64,
    pub b: f64,
    bounds: Vec<f64>,
}

// Lagrange functions of the nodes `zs` and their derivatives at `z`: the element's own
use stamp_elements::multi_surface::lagrange;

/// The n-point Gauss rule on [-1, 1] (Golub-Welsch: the eigenvalues of the Jacobi matrix).
fn gauss(n: usize) -> Vec<(f64, f64)> {
    let mut j = DMatrix::zeros(n, n);
    for i in 1..n {
        let b = i as f64 / ((4 * i * i - 1) as f64).sqrt();
        j[(i, i - 1)] = b;
        j[(i - 1, i)] = b;
    }
    let e = j.symmetric_eigen();
    let mut r: Vec<(f64, f64)> = (0..n).map(|k| (e.eigenvalues[k], 2.0 * e.eigenvectors[(0, k)].powi(2))).collect();
    r.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap());
    r
}

impl Layerwise {
    pub fn new(layers: Vec<Layer>, n: usize, a: f64, b: f64, q0: f64) -> Layerwise {
        let (p, q) = (std::f64::consts::PI / a, std::f64::consts::PI / b);
        let h: f64 = layers.iter().map(|l| l.thickness).sum();
        let mut bounds = vec![-0.5 * h];
        for l in &layers {
            bounds.push(bounds.last().unwrap() + l.thickness);
        }
        let m = layers.len() * (n - 1) + 1;
        let mut z = Vec::new();
        for k in 0..layers.len() {
            for s in 0..n - usize::from(k + 1 < layers.len()) {
                z.push(bounds[k] + (bounds[k + 1] - bounds[k]) * s as f64 / (n - 1) as f64);
            }
        }
        assert_eq!(z.len(), m);
        let mut lw = Layerwise { z: z.clone(), x: DVector::zeros(3 * m), n, layers: layers.clone(), a, b, bounds: bounds.clone() };
        let mut kk = DMatrix::zeros(3 * m, 3 * m);
        for (k, layer) in layers.iter().enumerate() {
            let zs: Vec<f64> = (0..n).map(|s| z[k * (n - 1) + s]).collect();
            for (xi, w) in gauss(n + 1) {
                let zz = bounds[k] + 0.5 * (xi + 1.0) * layer.thickness;
                let (l, dl) = lagrange(&zs, zz);
                // B: 6 x 3n over the layer's amplitudes [U_s, V_s, W_s]
                let mut bm = DMatrix::zeros(6, 3 * n);
                for s in 0..n {
                    bm[(0, 3 * s)] = -p * l[s];
                    bm[(1, 3 * s + 1)] = -q * l[s];
                    bm[(2, 3 * s + 2)] = dl[s];
                    bm[(3, 3 * s + 1)] = dl[s];
                    bm[(3, 3 * s + 2)] = q * l[s];
                    bm[(4, 3 * s)] = dl[s];
                    bm[(4, 3 * s + 2)] = p * l[s];
                    bm[(5, 3 * s)] = q * l[s];
                    bm[(5, 3 * s + 1)] = p * l[s];
                }
                let c = DMatrix::from_fn(6, 6, |i, j| layer.c[i][j]);
                let kl = bm.transpose() * c * &bm * (0.5 * w * layer.thickness);
                let off = 3 * k * (n - 1);
                for i in 0..3 * n {
                    for j in 0..3 * n {
                        kk[(off + i, off + j)] += kl[(i, j)];
                    }
                }
            }
        }
        let mut f = DVector::zeros(3 * m);
        f[3 * (m - 1) + 2] = q0;
        lw.x = kk.lu().solve(&f).expect("a regular system");
        lw
    }


    /// The amplitudes [U, V, W] at z.
    pub fn amplitudes(&self, z: f64) -> [f64; 3] {
        let k = (0..self.layers.len()).find(|&k| z <= self.bounds[k + 1] + 1e-12).unwrap_or(self.layers.len() - 1);
        let zs: Vec<f64> = (0..self.n).map(|s| self.z[k * (self.n - 1) + s]).collect();
        let (l, _) = lagrange(&zs, z);
        let mut u = [0.0; 3];
        for s in 0..self.n {
            for i in 0..3 {
                u[i] += l[s] * self.x[3 * (k * (self.n - 1) + s) + i];
            }
        }
        u
    }

    /// The stresses [s_xx, s_yy, s_zz, s_yz, s_xz, s_xy] at (x, y, z) in layer k by the 3D law.
    pub fn stress(&self, k: usize, x: f64, y: f64, z: f64) -> [f64; 6] {
        let (p, q) = (std::f64::consts::PI / self.a, std::f64::consts::PI / self.b);
        let zs: Vec<f64> = (0..self.n).map(|s| self.z[k * (self.n - 1) + s]).collect();
        let (l, dl) = lagrange(&zs, z);
        let amp = |s: usize, i: usize| self.x[3 * (k * (self.n - 1) + s) + i];
        let mut e = [0.0; 6];
        for s in 0..self.n {
            e[0] += -p * l[s] * amp(s, 0);
            e[1] += -q * l[s] * amp(s, 1);
            e[2] += dl[s] * amp(s, 2);
            e[3] += dl[s] * amp(s, 1) + q * l[s] * amp(s, 2);
            e[4] += dl[s] * amp(s, 0) + p * l[s] * amp(s, 2);
            e[5] += q * l[s] * amp(s, 0) + p * l[s] * amp(s, 1);
        }
        let c = &self.layers[k].c;
        let sa: Vec<f64> = (0..6).map(|i| (0..6).map(|j| c[i][j] * e[j]).sum()).collect();
        let (sx, cx, sy, cy) = ((p * x).sin(), (p * x).cos(), (q * y).sin(), (q * y).cos());
        [sa[0] * sx * sy, sa[1] * sx * sy, sa[2] * sx * sy, sa[3] * sx * cy, sa[4] * cx * sy, sa[5] * cx * cy]
    }
}


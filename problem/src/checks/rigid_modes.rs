//! The six rigid-body motions of a body and which of them a set of constraints leaves free.
//!
//! A rigid motion is u(X) = a + w x (X - O) with a translation a and a rotation w about a reference
//! point O (the centre of the model). With the rotation scaled by the model size s (w = w^ / s) the
//! six coordinates c = (a, w^) move the body by amounts of the same order, so the constraint matrix
//! is well scaled whatever the units.
//!
//! Every constraint is one row: the displacement along a direction `d` at a point X,
//! d . u(X) = d . a + (X - O) x d . w^ / s. A combination c of the modes is held by nothing when
//! every row gives zero: c is in the null space of the (rows x 6) matrix A. Only the 6 x 6 Gram
//! matrix G = A^T A is kept (rows are added one by one); its null space is A's. G is scaled to unit
//! diagonal (a correlation matrix, so that a mode held only by a short lever arm still counts as
//! held) and its eigenvectors with eigenvalues below [`NULL_TOLERANCE`] span the free motions.

use nalgebra::{DMatrix, DVector, Matrix6, SymmetricEigen, Vector3, Vector6};

/// Eigenvalue of the unit-diagonal Gram matrix below which a combination of modes counts as free:
/// the squared sine of the angle between a constraint column and the span of the others.
pub const NULL_TOLERANCE: f64 = 1e-9;

/// Accumulates constraint rows against the six rigid motions.
#[derive(Debug, Clone)]
pub struct RigidModes {
    origin: Vector3<f64>,
    scale: f64,
    gram: Matrix6<f64>,
    rows: usize,
}

/// A free rigid motion in physical terms: u(X) = translation + rotation x (X - origin).
#[derive(Debug, Clone, Copy)]
pub struct FreeMotion {
    pub translation: Vector3<f64>,
    pub rotation: Vector3<f64>,
}

const AXES: [&str; 3] = ["x1", "x2", "x3"];

impl RigidModes {
    /// Modes about `origin`, rotations scaled by the model size `scale` (> 0).
    pub fn new(origin: [f64; 3], scale: f64) -> RigidModes {
        let scale = if scale.is_finite() && scale > 0.0 { scale } else { 1.0 };
        RigidModes { origin: Vector3::from(origin), scale, gram: Matrix6::zeros(), rows: 0 }
    }

    /// The six modes' displacement along `dir` at `x` (scaled coordinates).
    pub fn row(&self, x: [f64; 3], dir: [f64; 3]) -> Vector6<f64> {
        let d = Vector3::from(dir);
        let r = (Vector3::from(x) - self.origin) / self.scale;
        let m = r.cross(&d);
        Vector6::new(d[0], d[1], d[2], m[0], m[1], m[2])
    }

    /// Hold the displacement along `dir` at `x`.
    pub fn hold(&mut self, x: [f64; 3], dir: [f64; 3]) {
        let r = self.row(x, dir);
        self.gram += r * r.transpose();
        self.rows += 1;
    }

    /// Hold displacement component `component` (0, 1, 2) at `x`.
    pub fn hold_component(&mut self, x: [f64; 3], component: usize) {
        let mut d = [0.0; 3];
        d[component] = 1.0;
        self.hold(x, d);
    }

    /// The Gram matrix of the rows added, A^T A.
    pub fn gram(&self) -> &Matrix6<f64> {
        &self.gram
    }

    /// Number of rows added.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// An orthonormal basis (in the scaled coordinates) of the combinations held by nothing.
    pub fn free_basis(&self) -> Vec<Vector6<f64>> {
        let g = DMatrix::from_fn(6, 6, |i, j| self.gram[(i, j)]);
        null_basis(&g).into_iter().map(|v| Vector6::from_column_slice(v.as_slice())).collect()
    }

    /// The free motions in physical terms (translation, rotation about the origin).
    pub fn physical(&self, c: &Vector6<f64>) -> FreeMotion {
        FreeMotion { translation: Vector3::new(c[0], c[1], c[2]), rotation: Vector3::new(c[3], c[4], c[5]) / self.scale }
    }

    /// The free motions named in words ("the translations along x1 and x2 and the rotation about
    /// x3"), or None when every rigid motion is held.
    pub fn describe_free(&self) -> Option<String> {
        let basis = self.free_basis();
        if basis.is_empty() {
            return None;
        }
        let k = basis.len();
        let n = DMatrix::from_fn(6, k, |i, j| basis[j][i]);
        let in_span = |v: &Vector6<f64>| -> bool {
            let dv = DVector::from_column_slice(v.as_slice());
            let proj = &n * (n.transpose() * &dv);
            (dv - proj).norm() < 1e-6 * v.norm()
        };
        // free translations
        let mut named: Vec<Vector6<f64>> = Vec::new();
        let mut translations = Vec::new();
        for i in 0..3 {
            let mut e = Vector6::zeros();
            e[i] = 1.0;
            if in_span(&e) {
                translations.push(i);
                named.push(e);
            }
        }
        // free rotations about a coordinate axis (through some point): a combination of the basis
        // whose rotation part is e_i
        let mut rotations: Vec<(usize, Option<String>)> = Vec::new();
        let nw = n.rows(3, 3).into_owned();
        let svd = nw.clone().svd(true, true);
        for i in 0..3 {
            let mut e = DVector::zeros(3);
            e[i] = 1.0;
            let Ok(c) = svd.solve(&e, 1e-9) else { continue };
            if (&nw * &c - &e).norm() > 1e-6 {
                continue;
            }
            let v = &n * &c;
            let v6 = Vector6::from_column_slice(v.as_slice());
            named.push(v6);
            let m = self.physical(&v6);
            // the axis passes through O + w x a / |w|^2; say where unless both translations across
            // the axis are free (then any axis parallel to it is free); with one of them free, the
            // axis may slide across it
            let across: Vec<usize> = (0..3).filter(|&j| j != i).collect();
            let free_across: Vec<usize> = across.iter().copied().filter(|j| translations.contains(j)).collect();
            let p = self.clean(self.origin + m.rotation.cross(&m.translation) / m.rotation.norm_squared());
            let point = match free_across.len() {
                2 => None,
                // moving the axis along x_b adds a translation along x_a (free), along x_a one along
                // x_b (held): x_a of the axis is fixed, x_b is any
                1 => Some(format!("any axis in the plane {} = {}", AXES[free_across[0]], num(p[free_across[0]]))),
                _ => Some(format!("the axis through ({}, {}) = ({}, {})", AXES[across[0]], AXES[across[1]], num(p[across[0]]), num(p[across[1]]))),
            };
            rotations.push((i, point));
        }
        let mut parts = Vec::new();
        if !translations.is_empty() {
            let axes: Vec<&str> = translations.iter().map(|&i| AXES[i]).collect();
            parts.push(if axes.len() == 1 { format!("the translation along {}", axes[0]) } else { format!("the translations along {}", join_and(&axes)) });
        }
        let plain: Vec<&str> = rotations.iter().filter(|r| r.1.is_none()).map(|r| AXES[r.0]).collect();
        if !plain.is_empty() {
            parts.push(if plain.len() == 1 { format!("the rotation about {}", plain[0]) } else { format!("the rotations about {}", join_and(&plain)) });
        }
        for (i, point) in &rotations {
            if let Some(pt) = point {
                parts.push(format!("the rotation about {} (about {pt})", AXES[*i]));
            }
        }
        // whatever the names above do not cover: generic combinations
        let mut covered: Vec<Vector6<f64>> = Vec::new();
        for v in &named {
            push_orthonormal(&mut covered, *v);
        }
        let mut count = translations.len() + rotations.len();
        for b in &basis {
            let before = covered.len();
            push_orthonormal(&mut covered, *b);
            if covered.len() > before {
                let m = self.physical(covered.last().unwrap());
                parts.push(self.describe_motion(&m));
                count += 1;
            }
        }
        let verb = if count == 1 { "is" } else { "are" };
        Some(format!("{} {verb} held by nothing", join_and(&parts.iter().map(|s| s.as_str()).collect::<Vec<_>>())))
    }

    /// A point with round-off (below 1e-9 of the model's size and position) set to zero.
    fn clean(&self, p: Vector3<f64>) -> Vector3<f64> {
        let tiny = 1e-9 * (self.scale + self.origin.norm());
        p.map(|x| if x.abs() < tiny { 0.0 } else { x })
    }

    /// A rigid motion in words: "the translation along x1" or "... along (0.6, 0.8, 0)", "the
    /// rotation about x3 (about the axis through (x1, x2) = (5, 3))" or "the rotation about the axis
    /// along (0.6, 0.8, 0) through (5, 3, 0)". Components below [`ROUND_OFF`] of the largest are
    /// round-off and set to zero, so that a coordinate axis is named by its name.
    pub fn describe_motion(&self, m: &FreeMotion) -> String {
        let w = m.rotation.norm() * self.scale;
        if w < 1e-6 * m.translation.norm() {
            return format!("the translation along {}", direction_words(&m.translation));
        }
        let axis = snap(&m.rotation);
        let p = self.clean(self.origin + m.rotation.cross(&m.translation) / m.rotation.norm_squared());
        match coordinate_axis(&axis) {
            Some(i) => {
                let across: Vec<usize> = (0..3).filter(|&j| j != i).collect();
                format!("the rotation about {} (about the axis through ({}, {}) = ({}, {}))", AXES[i], AXES[across[0]], AXES[across[1]], num(p[across[0]]), num(p[across[1]]))
            }
            None => format!("the rotation about the axis along {} through ({}, {}, {})", direction_words(&axis), num(p[0]), num(p[1]), num(p[2])),
        }
    }
}

/// Relative size below which a component of a direction is round-off.
pub const ROUND_OFF: f64 = 1e-9;

/// `v` scaled to unit length with the components below [`ROUND_OFF`] of the largest set to zero.
pub fn snap(v: &Vector3<f64>) -> Vector3<f64> {
    let big = v.amax();
    if !(big > 0.0 && big.is_finite()) {
        return *v;
    }
    v.map(|c| if c.abs() < ROUND_OFF * big { 0.0 } else { c }).normalize()
}

/// The coordinate axis (0, 1, 2) a snapped direction lies along, if any.
pub fn coordinate_axis(d: &Vector3<f64>) -> Option<usize> {
    let nonzero: Vec<usize> = (0..3).filter(|&i| d[i] != 0.0).collect();
    (nonzero.len() == 1).then(|| nonzero[0])
}

/// A direction in words: "x1" for a coordinate axis (either sense) up to round-off, else the unit
/// vector "(0.6, -0.8, 0)".
pub fn direction_words(v: &Vector3<f64>) -> String {
    let d = snap(v);
    match coordinate_axis(&d) {
        Some(i) => AXES[i].to_string(),
        None => format!("({}, {}, {})", num(d[0]), num(d[1]), num(d[2])),
    }
}

/// An orthonormal basis of the null space of the Gram matrix `gram` (A^T A of the constraint rows
/// A): `gram` is scaled to unit diagonal first (a correlation matrix, so that a column held only by
/// small entries still counts as held) and its eigenvectors with eigenvalues below
/// [`NULL_TOLERANCE`] are taken back to the unscaled coordinates. A column with (next to) nothing
/// in it is free on its own.
pub fn null_basis(gram: &DMatrix<f64>) -> Vec<DVector<f64>> {
    let n = gram.nrows();
    let diag = gram.diagonal();
    let dmax = diag.max();
    let inv: DVector<f64> = diag.map(|g| if g > 0.0 && g > 1e-20 * dmax { 1.0 / g.sqrt() } else { 0.0 });
    let c = DMatrix::from_fn(n, n, |i, j| gram[(i, j)] * inv[i] * inv[j]);
    let eig = SymmetricEigen::new(c);
    let mut basis: Vec<DVector<f64>> = Vec::new();
    for k in 0..n {
        if eig.eigenvalues[k] < NULL_TOLERANCE {
            // back to unscaled coordinates: columns scaled to zero keep their own direction
            let y = eig.eigenvectors.column(k).into_owned();
            let v = DVector::from_fn(n, |i, _| if inv[i] > 0.0 { y[i] * inv[i] } else { y[i] });
            push_orthonormal_d(&mut basis, v);
        }
    }
    basis
}

/// Add `v` to an orthonormal list when it is not (nearly) in its span.
fn push_orthonormal_d(basis: &mut Vec<DVector<f64>>, v: DVector<f64>) {
    let norm0 = v.norm();
    if norm0 == 0.0 {
        return;
    }
    let mut r = v;
    for b in basis.iter() {
        let d = b.dot(&r);
        r -= b * d;
    }
    if r.norm() > 1e-6 * norm0 {
        basis.push(r.normalize());
    }
}

/// Add `v` to an orthonormal list when it is not (nearly) in its span.
fn push_orthonormal(basis: &mut Vec<Vector6<f64>>, v: Vector6<f64>) {
    let norm0 = v.norm();
    if norm0 == 0.0 {
        return;
    }
    let mut r = v;
    for b in basis.iter() {
        r -= b * b.dot(&r);
    }
    if r.norm() > 1e-6 * norm0 {
        basis.push(r.normalize());
    }
}

/// "a", "a and b", "a, b and c".
pub fn join_and(items: &[&str]) -> String {
    match items.len() {
        0 => String::new(),
        1 => items[0].to_string(),
        n => format!("{} and {}", items[..n - 1].join(", "), items[n - 1]),
    }
}

/// A number for a message: short, no round-off tails.
pub fn num(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return if x == 0.0 { "0".into() } else { format!("{x}") };
    }
    let a = x.abs();
    if (1e-3..1e6).contains(&a) {
        let s = format!("{x:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" { "0".into() } else { s.to_string() }
    } else {
        let s = format!("{x:.4e}");
        match s.split_once('e') {
            Some((m, e)) => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
            None => s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 4 x 4 grid of nodes on a 10 x 6 plate, faces at x3 = -0.5 and 0.5.
    fn grid() -> Vec<[f64; 2]> {
        let mut v = Vec::new();
        for j in 0..4 {
            for i in 0..4 {
                v.push([10.0 * i as f64 / 3.0, 6.0 * j as f64 / 3.0]);
            }
        }
        v
    }

    fn modes() -> RigidModes {
        RigidModes::new([5.0, 3.0, 0.0], 6.0)
    }

    #[test]
    fn nothing_held_leaves_all_six_free() {
        let m = modes();
        assert_eq!(m.free_basis().len(), 6);
        let d = m.describe_free().unwrap();
        assert_eq!(d, "the translations along x1, x2 and x3 and the rotations about x1, x2 and x3 are held by nothing");
    }

    #[test]
    fn simply_supported_edges_leave_the_in_plane_motions_free() {
        let mut m = modes();
        for x in grid() {
            let edge = x[0] == 0.0 || x[1] == 0.0 || (x[0] - 10.0).abs() < 1e-12 || (x[1] - 6.0).abs() < 1e-12;
            if edge {
                for z in [-0.5, 0.5] {
                    m.hold_component([x[0], x[1], z], 2);
                }
            }
        }
        assert_eq!(m.free_basis().len(), 3);
        assert_eq!(m.describe_free().unwrap(), "the translations along x1 and x2 and the rotation about x3 are held by nothing");
        // a pin (v1, v2 on both faces) at one corner leaves the rotation about x3 about that corner
        for z in [-0.5, 0.5] {
            m.hold_component([0.0, 0.0, z], 0);
            m.hold_component([0.0, 0.0, z], 1);
        }
        assert_eq!(m.describe_free().unwrap(), "the rotation about x3 (about the axis through (x1, x2) = (0, 0)) is held by nothing");
        // a roller (v2) at a second corner holds it
        m.hold_component([10.0, 0.0, 0.5], 1);
        assert!(m.describe_free().is_none(), "{:?}", m.describe_free());
    }

    #[test]
    fn a_short_lever_arm_still_holds() {
        // on a plate 1e3 long and 1e-4 thick: v3 held along x1 = 0 (the translation along x3 and
        // the rotation about x1), v2 at two points along x1 (x2 and the rotation about x3), v1 on
        // the bottom face of one node: the rotation about x2 about that point is free until v1 is
        // held on its top face too, 1e-4 above
        let mut m = RigidModes::new([0.0, 0.0, 0.0], 1e3);
        for x in [[0.0, 0.0], [0.0, 1e3]] {
            m.hold_component([x[0], x[1], 0.0], 2);
        }
        m.hold_component([0.0, 0.0, 0.0], 1);
        m.hold_component([1e3, 0.0, 0.0], 1);
        m.hold_component([0.0, 0.0, -5e-5], 0);
        assert_eq!(m.describe_free().unwrap(), "the rotation about x2 (about the axis through (x1, x3) = (0, -5e-5)) is held by nothing");
        m.hold_component([0.0, 0.0, 5e-5], 0);
        assert!(m.describe_free().is_none(), "{:?}", m.describe_free());
    }

    #[test]
    fn round_off_in_a_direction_is_dropped_and_coordinate_axes_are_named() {
        assert_eq!(direction_words(&Vector3::new(-0.477886, 0.878422, 2.8206e-22)), "(-0.477886, 0.878422, 0)");
        assert_eq!(direction_words(&Vector3::new(2.0, 3e-12, -1e-20)), "x1");
        assert_eq!(direction_words(&Vector3::new(1e-15, -0.5, 0.0)), "x2", "either sense");
        assert_eq!(direction_words(&Vector3::new(0.0, 0.0, 7.0)), "x3");
        // 1e-6 of the largest is a real component
        assert_eq!(direction_words(&Vector3::new(1.0, 1e-6, 0.0)), "(1, 1e-6, 0)");
        let m = modes();
        let along = |t: [f64; 3]| m.describe_motion(&FreeMotion { translation: Vector3::from(t), rotation: Vector3::zeros() });
        assert_eq!(along([-3.0, 1e-14, 2.8e-22]), "the translation along x1");
        assert_eq!(along([0.6, -0.8, 1e-17]), "the translation along (0.6, -0.8, 0)");
        // a rotation about x3 up to round-off through (2, 7): u = w x (X - P) = w x (X - O) + w x (O - P)
        let w = Vector3::new(1e-13, -2e-12, 0.25);
        let about = |w: Vector3<f64>, p: [f64; 3]| m.describe_motion(&FreeMotion { translation: w.cross(&(Vector3::new(5.0, 3.0, 0.0) - Vector3::from(p))), rotation: w });
        assert_eq!(about(w, [2.0, 7.0, 0.0]), "the rotation about x3 (about the axis through (x1, x2) = (2, 7))");
        assert_eq!(about(Vector3::new(0.0, -1.0, 1e-12), [2.0, 7.0, -0.5]), "the rotation about x2 (about the axis through (x1, x3) = (2, -0.5))");
        assert_eq!(about(Vector3::new(0.6, 0.0, 0.8), [5.0, 3.0, 0.0]), "the rotation about the axis along (0.6, 0, 0.8) through (5, 3, 0)");
    }

    #[test]
    fn a_rotation_whose_axis_may_slide_names_the_plane_of_its_axes() {
        // v3 held on the faces along x1 = 0 and x1 = 10, v2 at (0, 0): the translation along x1
        // and the rotation about x3 about any axis through x1 = 0 (moving the axis along x2 adds a
        // translation along x1, which is free)
        let mut m = modes();
        for x in grid() {
            if x[0] == 0.0 || (x[0] - 10.0).abs() < 1e-12 {
                for z in [-0.5, 0.5] {
                    m.hold_component([x[0], x[1], z], 2);
                }
            }
        }
        m.hold_component([0.0, 0.0, 0.5], 1);
        m.hold_component([0.0, 0.0, -0.5], 1);
        assert_eq!(m.describe_free().unwrap(), "the translation along x1 and the rotation about x3 (about any axis in the plane x1 = 0) are held by nothing");
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(num(0.30000000000000004), "0.3");
        assert_eq!(num(-2.5), "-2.5");
        assert_eq!(num(1e-7), "1e-7");
        assert_eq!(num(-5.12345e-9), "-5.1235e-9");
        assert_eq!(num(2.5e7), "2.5e7");
        assert_eq!(num(0.0), "0");
    }
}

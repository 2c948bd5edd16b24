//! Where a punch is at the start (load factor 0): the gap between it and every candidate point of
//! its contact face, the first gap (the smallest) and the points it touches.
//!
//! The gap of a point is its distance to the punch surface measured along the gradient of Psi:
//! the point is moved by Newton steps x <- x - Psi grad Psi / |grad Psi|^2 onto Psi = 0 and the gap
//! is the length of that path, negative inside the punch. For the sphere, the cylinder and the
//! plane (whose gradients point along the normal through the point) this is the exact distance;
//! near the surface it equals Psi / |grad Psi|, the gap of the .vtu output.

use nalgebra::Vector3;
use stamp::contact::ContactPair;
use stamp::surface::ContactSurface;

/// The gap of one candidate point at the start.
#[derive(Debug, Clone, Copy)]
pub struct PointGap {
    /// Index in the pair's points.
    pub index: usize,
    pub node: usize,
    /// Reference position on the contact face.
    pub x: [f64; 3],
    /// Distance to the punch, negative inside it.
    pub gap: f64,
    /// Unit normal of the punch surface there (grad Psi / |grad Psi|, pointing away from the punch).
    pub normal: [f64; 3],
    /// Where the gradient flow from `x` meets the punch's surface (Psi = 0): the punch's point
    /// nearest to `x` for the sphere, the cylinder and the plane. None when the flow did not end
    /// on the surface.
    pub foot: Option<[f64; 3]>,
}

/// Distance from `x` to the surface along the gradient flow (negative inside) and the unit normal
/// grad Psi / |grad Psi| at `x`; None where the gradient vanishes (the centre of a sphere).
pub fn gap_at(surface: &dyn ContactSurface, x: &Vector3<f64>) -> Option<(f64, Vector3<f64>)> {
    gap_and_foot(surface, x).map(|(g, n, _)| (g, n))
}

/// [`gap_at`] and the end of the flow on the surface (None if the flow did not reach Psi = 0).
pub fn gap_and_foot(surface: &dyn ContactSurface, x: &Vector3<f64>) -> Option<(f64, Vector3<f64>, Option<Vector3<f64>>)> {
    let g0 = surface.gradient(x);
    let psi0 = surface.psi(x);
    let n0 = g0.norm();
    if !(n0 > 0.0 && n0.is_finite() && psi0.is_finite()) {
        return None;
    }
    let scale = surface.length_scale().abs().max(x.amax()).max(1e-300);
    let mut y = *x;
    for _ in 0..60 {
        let g = surface.gradient(&y);
        let gg = g.norm_squared();
        if !(gg > 0.0 && gg.is_finite()) {
            break;
        }
        let step = g * (surface.psi(&y) / gg);
        y -= step;
        if step.norm() <= 1e-14 * scale {
            break;
        }
    }
    let dist = (y - x).norm();
    if !dist.is_finite() {
        return Some((psi0 / n0, g0 / n0, None));
    }
    // the flow ended on the surface: Psi there is round-off against Psi at the start
    let on_surface = surface.psi(&y).abs() <= 1e-6 * psi0.abs().max(n0 * 1e-9 * scale);
    Some((if psi0 < 0.0 { -dist } else { dist }, g0 / n0, on_surface.then_some(y)))
}

/// The gap of every candidate point of `pair` with the punch where it starts (no motion yet).
pub fn start_gaps(pair: &ContactPair) -> Vec<PointGap> {
    pair.points
        .iter()
        .enumerate()
        .filter_map(|(k, p)| {
            let x = Vector3::from(p.x_ref);
            let (gap, n, foot) = gap_and_foot(&*pair.surface, &x)?;
            // round-off in the normal must not hold a motion the punch cannot hold
            let n = n.map(|c| if c.abs() < 1e-9 { 0.0 } else { c });
            Some(PointGap { index: k, node: p.node, x: p.x_ref, gap, normal: n.into(), foot: foot.map(Into::into) })
        })
        .collect()
}

/// The point with the smallest gap.
pub fn first_gap(gaps: &[PointGap]) -> Option<PointGap> {
    gaps.iter().copied().min_by(|a, b| a.gap.total_cmp(&b.gap))
}

#[cfg(test)]
mod tests {
    use super::*;
    use stamp_contact::{Cylinder, Plane, Sphere};

    #[test]
    fn the_gap_is_the_distance_for_the_three_shapes() {
        let s = Sphere::new(Vector3::new(0.0, 0.0, 10.0), 4.0).unwrap();
        let (g, n) = gap_at(&s, &Vector3::new(0.0, 3.0, 0.0)).unwrap();
        assert!((g - (109f64.sqrt() - 4.0)).abs() < 1e-12, "{g}");
        assert!((n - Vector3::new(0.0, 3.0, -10.0) / 109f64.sqrt()).norm() < 1e-12);
        // deep inside: 3.5 from the surface
        let (g, _) = gap_at(&s, &Vector3::new(0.0, 0.0, 9.5)).unwrap();
        assert!((g + 3.5).abs() < 1e-12, "{g}");
        assert!(gap_at(&s, &Vector3::new(0.0, 0.0, 10.0)).is_none());
        let c = Cylinder::new(Vector3::new(0.0, 0.0, 101.0), Vector3::new(1.0, 0.0, 0.0), 100.0).unwrap();
        let (g, _) = gap_at(&c, &Vector3::new(7.0, 0.0, 1.0)).unwrap();
        assert!(g.abs() < 1e-12, "{g}");
        let (g, _) = gap_at(&c, &Vector3::new(7.0, 30.0, 1.0)).unwrap();
        assert!((g - (30f64.hypot(100.0) - 100.0)).abs() < 1e-9, "{g}");
        let p = Plane::new(Vector3::new(0.0, 0.0, -2.5), Vector3::new(0.0, 0.0, 1.0)).unwrap();
        let (g, n) = gap_at(&p, &Vector3::new(3.0, 1.0, -0.5)).unwrap();
        assert!((g - 2.0).abs() < 1e-12 && n == Vector3::new(0.0, 0.0, 1.0));
    }
}

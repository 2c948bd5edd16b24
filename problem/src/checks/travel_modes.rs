//! The travels of force-driven punches: unknowns that only the plate holds.
//!
//! A force-driven punch moves by s along its direction D on top of its motion; s is an unknown of
//! the model, held only by the points where the punch presses the plate: a point at X with normal
//! n holds n . (u(X) - s D). Together with the six rigid motions of the plate (see
//! [`crate::checks::rigid_modes`]) the rows are (rigid-mode row, -n . D in the punch's column). A
//! combination held by nothing has a travel in it when the plate holds every rigid motion: either
//! the punch's direction is across every normal where it presses (it slides past the plate), or
//! the plate's motion the punch holds is held by nothing else (plate and punch move away together
//! and nothing takes the force).

use crate::checks::rigid_modes::{null_basis, FreeMotion, RigidModes};
use nalgebra::{DMatrix, DVector, Vector3, Vector6};

/// Rows against the six rigid motions and the travels of `travels` force-driven punches.
#[derive(Debug, Clone)]
pub struct TravelModes {
    modes: RigidModes,
    gram: DMatrix<f64>,
}

/// A combination held by nothing: the plate's rigid motion when the punch with the largest share
/// travels by 1 along its direction, and each punch's travel.
#[derive(Debug, Clone)]
pub struct FreeTravel {
    pub plate: FreeMotion,
    /// The plate does not move (below 1e-6 of the travel).
    pub plate_still: bool,
    pub travels: Vec<f64>,
}

impl TravelModes {
    /// The rows of `modes` (their travel columns zero: supports) and `travels` punch travels.
    pub fn new(modes: &RigidModes, travels: usize) -> TravelModes {
        let mut gram = DMatrix::zeros(6 + travels, 6 + travels);
        gram.view_mut((0, 0), (6, 6)).copy_from(modes.gram());
        TravelModes { modes: modes.clone(), gram }
    }

    /// Hold the displacement along `dir` at `x` relative to the punch: `travel` is the punch's
    /// index and direction when it is force-driven.
    pub fn hold(&mut self, x: [f64; 3], dir: [f64; 3], travel: Option<(usize, [f64; 3])>) {
        let n = self.gram.nrows();
        let r6: Vector6<f64> = self.modes.row(x, dir);
        let mut r = DVector::zeros(n);
        r.rows_mut(0, 6).copy_from(&r6);
        if let Some((k, d)) = travel {
            r[6 + k] = -Vector3::from(dir).dot(&Vector3::from(d));
        }
        self.gram += &r * r.transpose();
    }

    /// The combinations with a travel in them that nothing holds.
    pub fn free(&self) -> Vec<FreeTravel> {
        let mut out = Vec::new();
        for v in null_basis(&self.gram) {
            let travels: Vec<f64> = v.rows(6, v.len() - 6).iter().copied().collect();
            let big = travels.iter().copied().fold(0.0_f64, |a, b| if b.abs() > a.abs() { b } else { a });
            if big.abs() < 1e-6 * v.norm() {
                continue;
            }
            let c = Vector6::from_fn(|i, _| v[i] / big);
            out.push(FreeTravel { plate: self.modes.physical(&c), plate_still: c.norm() < 1e-6, travels: travels.iter().map(|t| t / big).collect() });
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plate of the rigid_modes tests (10 x 6, faces at x3 = -0.5 and 0.5) with its six rigid
    /// motions held, or, with `free_x3`, all but the translation along x3 and the rotation about x1
    /// (no support holds v3; v1 on two heights holds the rotation about x2).
    fn held(free_x3: bool) -> RigidModes {
        let mut m = RigidModes::new([5.0, 3.0, 0.0], 6.0);
        let mut rows = vec![([0.0, 0.0, 0.0], [1.0, 0.0, 0.0]), ([0.0, 0.0, 0.0], [0.0, 1.0, 0.0]), ([10.0, 0.0, 0.0], [0.0, 1.0, 0.0])];
        rows.extend([([0.0, 0.0, 0.5], [1.0, 0.0, 0.0]), ([0.0, 6.0, 0.5], [1.0, 0.0, 0.0])]);
        if !free_x3 {
            rows.extend([([0.0, 0.0, 0.0], [0.0, 0.0, 1.0]), ([10.0, 0.0, 0.0], [0.0, 0.0, 1.0]), ([0.0, 6.0, 0.0], [0.0, 0.0, 1.0])]);
        }
        for (x, d) in rows {
            m.hold(x, d);
        }
        m
    }

    #[test]
    fn a_punch_pressing_along_x3_on_a_held_plate_is_held() {
        let m = held(false);
        let mut t = TravelModes::new(&m, 1);
        assert_eq!(t.free().len(), 1, "no contact: the travel is free");
        t.hold([5.0, 3.0, 0.5], [0.0, 0.0, 1.0], Some((0, [0.0, 0.0, -1.0])));
        assert!(t.free().is_empty());
    }

    #[test]
    fn a_punch_sliding_across_its_contact_normal_is_free() {
        let m = held(false);
        let mut t = TravelModes::new(&m, 1);
        t.hold([5.0, 3.0, 0.5], [0.0, 0.0, 1.0], Some((0, [1.0, 0.0, 0.0])));
        let f = t.free();
        assert_eq!(f.len(), 1);
        assert!(f[0].plate_still && f[0].travels == vec![1.0], "{f:?}");
    }

    #[test]
    fn a_plate_held_only_by_the_force_driven_punch_moves_with_it() {
        let m = held(true);
        let mut t = TravelModes::new(&m, 1);
        // the punch touches at three points not in a line, and it alone holds the plate's x3 motions
        for x in [[2.0, 1.0, 0.5], [8.0, 1.0, 0.5], [5.0, 5.0, 0.5]] {
            t.hold(x, [0.0, 0.0, 1.0], Some((0, [0.0, 0.0, -1.0])));
        }
        let f = t.free();
        assert_eq!(f.len(), 1, "{f:?}");
        assert!(!f[0].plate_still);
        // the plate goes down with the punch: its translation along x3 is the punch's travel
        assert!((f[0].plate.translation - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-9, "{:?}", f[0].plate);
        assert!(f[0].plate.rotation.norm() < 1e-9);
        assert_eq!(m.describe_motion(&f[0].plate), "the translation along x3");
    }
}

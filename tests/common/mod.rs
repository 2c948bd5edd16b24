//! Helpers shared by the integration tests.
#![allow(dead_code)]

use stamp::element::{Element, LocalSystem};
use stamp::mesh::QuadMesh;
use stamp_elements::{Isotropic, Kinematics, PlateElements, Section};

/// A tiny deterministic random generator (no external crates in tests).
pub struct Lcg(pub u64);
impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64) / ((1u64 << 53) as f64)
    }
    /// Uniform in [a, b).
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }
}

/// The rotation matrix of the paper's eq. 1.7 from the Euler-Krylov angles (phi, theta, psi).
pub fn euler_krylov(phi: f64, theta: f64, psi: f64) -> [[f64; 3]; 3] {
    let (sf, cf) = phi.sin_cos();
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = psi.sin_cos();
    [
        [ct * cp, ct * sp, -st],
        [-cf * sp + sf * st * cp, cf * cp + sf * st * sp, sf * ct],
        [sf * sp + cf * st * cp, -sf * cp + cf * st * sp, cf * ct],
    ]
}

/// A strongly distorted single element (corner angles far from 90 degrees).
pub fn distorted_element() -> QuadMesh {
    QuadMesh::new(vec![[0.0, 0.0], [2.0, 0.3], [2.6, 1.9], [-0.4, 1.2]], vec![[0, 1, 2, 3]]).unwrap()
}

pub fn steel_section(h: f64) -> Section {
    Section::homogeneous(h, Isotropic::new(2.0e5, 0.3).unwrap()).unwrap()
}

/// Evaluate element 0 of a plate at local dofs v.
pub fn eval(plate: &PlateElements, v: &[f64], tangent: bool) -> LocalSystem {
    let mut ws = plate.new_workspace();
    let mut out = LocalSystem::new(24);
    plate.evaluate(0, v, &mut ws, &mut out, tangent);
    out
}

pub fn plate(mesh: &QuadMesh, h: f64, kin: Kinematics) -> PlateElements {
    PlateElements::new(mesh, steel_section(h), kin).unwrap()
}

pub fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |m, x| m.max(x.abs()))
}

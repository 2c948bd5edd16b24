//! Exact rigid-body motions (paper eqs. 1.6-1.8): on a distorted element, translations plus
//! rotations by arbitrary Euler-Krylov angles up to 180 degrees give zero strain, internal force and
//! energy to round-off, relative to the element's stiffness scale.

mod common;
use common::*;
use stamp_elements::Kinematics;

fn rigid_dofs(mesh: &stamp::mesh::QuadMesh, h: f64, rot: [[f64; 3]; 3], shift: [f64; 3]) -> Vec<f64> {
    let mut v = vec![0.0; 24];
    for a in 0..4 {
        let x = mesh.coords[mesh.cells[0][a]];
        for (face, z) in [(0usize, -0.5 * h), (1, 0.5 * h)] {
            let r = [x[0], x[1], z];
            for i in 0..3 {
                let phir: f64 = (0..3).map(|j| rot[i][j] * r[j]).sum();
                v[a * 6 + face * 3 + i] = shift[i] + phir - r[i];
            }
        }
    }
    v
}

#[test]
fn rigid_body_motions_are_strain_free_on_a_distorted_element() {
    let mesh = distorted_element();
    let h = 0.1;
    let plate = plate(&mesh, h, Kinematics::Nonlinear);
    let k0 = eval(&plate, &vec![0.0; 24], true);
    let k_scale = max_abs(&k0.tangent);
    let mut rng = Lcg(7);
    let pi = std::f64::consts::PI;
    let mut angles = vec![(pi / 2.0, 0.0, 0.0), (0.0, pi / 2.0, 0.0), (0.0, 0.0, pi), (pi, 0.0, 0.0), (0.0, pi, 0.0), (pi, pi, pi)];
    for _ in 0..20 {
        angles.push((rng.range(-pi, pi), rng.range(-pi, pi), rng.range(-pi, pi)));
    }
    let mut ws = stamp::element::Element::new_workspace(&plate);
    for (phi, theta, psi) in angles {
        let rot = euler_krylov(phi, theta, psi);
        let shift = [rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), rng.range(-5.0, 5.0)];
        let v = rigid_dofs(&mesh, h, rot, shift);
        let v_scale = max_abs(&v);
        let out = eval(&plate, &v, false);
        let force = max_abs(&out.residual);
        assert!(force <= 1e-12 * k_scale * v_scale, "angles ({phi}, {theta}, {psi}): internal force {force:e} vs scale {:e}", k_scale * v_scale);
        assert!(out.energy.abs() <= 1e-24 * k_scale * v_scale * v_scale, "energy {:e}", out.energy);
        let state = plate.gauss_state(0, &v, &mut ws);
        for g in 0..4 {
            let e = max_abs(&state.strain[g]);
            assert!(e <= 1e-13 * v_scale.max(1.0), "angles ({phi}, {theta}, {psi}): strain {e:e} at Gauss point {g}");
        }
    }
}

#[test]
fn the_linear_variant_is_not_rigid_body_exact_for_large_rotations() {
    // Guard that the test above can fail: the geometrically linear element strains under a
    // 90-degree rotation.
    let mesh = distorted_element();
    let plate = plate(&mesh, 0.1, Kinematics::Linear);
    let v = rigid_dofs(&mesh, 0.1, euler_krylov(0.0, 0.0, std::f64::consts::FRAC_PI_2), [0.0; 3]);
    let out = eval(&plate, &v, false);
    assert!(max_abs(&out.residual) > 1.0);
}

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

/// Rigid motions keep the volume ratio det[g1, g2, g3] / det[G1, G2, G3] at 1; mirror images have
/// the same (zero) Green-Lagrange strains but a volume ratio of -1, and the nonlinear element
/// refuses them (the assembler then refuses the state, Newton backs off).
#[test]
fn mirror_images_are_strain_free_but_refused() {
    let mesh = distorted_element();
    let h = 0.1;
    let plate = plate(&mesh, h, Kinematics::Nonlinear);
    let mut ws = stamp::element::Element::new_workspace(&plate);
    let mut rng = Lcg(11);
    let pi = std::f64::consts::PI;
    let mirrors = [[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]], [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]];
    for _ in 0..10 {
        let rot = euler_krylov(rng.range(-pi, pi), rng.range(-pi, pi), rng.range(-pi, pi));
        let shift = [rng.range(-5.0, 5.0), rng.range(-5.0, 5.0), rng.range(-5.0, 5.0)];
        let v = rigid_dofs(&mesh, h, rot, shift);
        let j = plate.smallest_volume_ratio(0, &v, &mut ws);
        assert!((j - 1.0).abs() <= 1e-12, "rotation: volume ratio {j}");
        assert!(eval(&plate, &v, true).inadmissible.is_none());
        for m in mirrors {
            // the rotation after the mirror: still an improper orthogonal map
            let mut q = [[0.0; 3]; 3];
            for i in 0..3 {
                for k in 0..3 {
                    q[i][k] = (0..3).map(|l| rot[i][l] * m[l][k]).sum();
                }
            }
            let v = rigid_dofs(&mesh, h, q, shift);
            let state = plate.gauss_state(0, &v, &mut ws);
            for g in 0..4 {
                assert!(max_abs(&state.strain[g]) <= 1e-12, "a mirror image strains: {:?}", state.strain[g]);
            }
            let j = plate.smallest_volume_ratio(0, &v, &mut ws);
            assert!((j + 1.0).abs() <= 1e-12, "mirror: volume ratio {j}");
            let out = eval(&plate, &v, true);
            let reason = out.inadmissible.expect("a mirror image must be refused");
            assert!(reason.contains("inside out"), "{reason}");
        }
    }
    // the linear theory has no such limit
    let linear = common::plate(&mesh, h, Kinematics::Linear);
    let v = rigid_dofs(&mesh, h, mirrors[0], [0.0; 3]);
    assert!(eval(&linear, &v, true).inadmissible.is_none());
}

/// One fibre pushed through the plate (the top face of a corner node below its bottom face): the
/// model's evaluation fails with an error naming the one element that holds that node, and the
/// same state with the fibre only shortened is evaluated.
#[test]
fn a_fibre_pushed_through_the_plate_is_refused_naming_its_element() {
    use stamp::nonlinear::NonlinearProblem;
    use stamp_elements::Face;
    let mesh = stamp::mesh::QuadMesh::rectangle(0.0, 3.0, 0.0, 2.0, 3, 2).unwrap();
    let h = 0.1;
    let plate = plate(&mesh, h, Kinematics::Nonlinear);
    let dofs = stamp::dofs::DofMap::new(mesh.num_nodes(), 6).unwrap();
    let mut model = stamp::model::Model::new(plate, dofs).unwrap();
    // the last node: a corner, in the last cell only
    let node = mesh.num_nodes() - 1;
    let cell = mesh.cells.iter().position(|c| c.contains(&node)).unwrap();
    assert_eq!(mesh.cells.iter().filter(|c| c.contains(&node)).count(), 1);
    let mut u = vec![0.0; model.num_dofs()];
    for (factor, refused) in [(0.5, false), (1.5, false), (3.0, true)] {
        // the node's fibre e3 (1 - factor): flipped when factor > 1, but the element samples its
        // fibres at the Gauss points: at the one nearest the node the fibre is e3 (1 - 0.622 factor)
        // (0.622 the node's shape function there), flipped once factor > 1.61
        u[Face::Top.dof(node, 2)] = -0.5 * h * factor;
        u[Face::Bottom.dof(node, 2)] = 0.5 * h * factor;
        match model.evaluate(&u, 0.0, true) {
            Ok(ev) => assert!(!refused && ev.residual_norm.is_finite() && ev.residual_norm > 0.0),
            Err(stamp::StampError::Inadmissible { element, reason }) => {
                assert!(refused, "refused a shortened fibre: {reason}");
                assert_eq!(element, cell);
                let message = stamp::StampError::Inadmissible { element, reason }.to_string();
                assert!(message.contains(&format!("element {cell}")) && message.contains("inside out"), "{message}");
            }
            Err(e) => panic!("unexpected error {e}"),
        }
    }
}

//! Bad input gets a typed error, never a panic; a Newton failure says where it stopped.

mod common;
use common::*;
use stamp::dofs::DofMap;
use stamp::mesh::QuadMesh;
use stamp::linalg::linear_solver::SparseLu;
use stamp::model::Model;
use stamp::nonlinear::{NewtonRaphson, NewtonSettings, NonlinearSolver};
use stamp::StampError;
use stamp_elements::{Face, Isotropic, Kinematics, PlateElements, Section};

#[test]
fn materials_and_sections_out_of_range() {
    for nu in [0.5, 0.7, -1.0, -1.5, f64::NAN] {
        assert!(matches!(Isotropic::new(1.0, nu), Err(StampError::Material(_))), "nu = {nu}");
    }
    assert!(matches!(Isotropic::new(0.0, 0.3), Err(StampError::Material(_))));
    assert!(matches!(Isotropic::new(-5.0, 0.3), Err(StampError::Material(_))));
    let m = Isotropic::new(1.0, 0.3).unwrap();
    for h in [0.0, -1.0, f64::NAN] {
        let e = Section::homogeneous(h, m).unwrap_err();
        assert!(e.to_string().contains("thickness"), "{e}");
    }
    assert!(Section::homogeneous_offset(1.0, 0.5, m).is_err());
}

#[test]
fn empty_degenerate_and_inverted_meshes() {
    let e = QuadMesh::new(vec![], vec![]).unwrap_err();
    assert!(e.to_string().contains("empty"), "{e}");
    let square = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let e = QuadMesh::new(square.clone(), vec![[0, 3, 2, 1]]).unwrap_err();
    assert!(e.to_string().contains("inverted"), "{e}");
    let e = QuadMesh::new(square.clone(), vec![[0, 1, 1, 3]]).unwrap_err();
    assert!(e.to_string().contains("degenerate"), "{e}");
    let e = QuadMesh::new(vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0]], vec![[0, 1, 2, 3]]).unwrap_err();
    assert!(matches!(e, StampError::Mesh(_)), "{e}");
    let e = QuadMesh::new(square.clone(), vec![[0, 1, 2, 7]]).unwrap_err();
    assert!(e.to_string().contains("node 7"), "{e}");
    // a mesh edited after validation is checked again by the element
    let mut mesh = QuadMesh::new(square, vec![[0, 1, 2, 3]]).unwrap();
    mesh.cells[0] = [0, 3, 2, 1];
    assert!(PlateElements::new(&mesh, steel_section(0.1), Kinematics::Nonlinear).is_err());
}

#[test]
fn newton_failure_names_the_step_and_the_residual() {
    let mesh = QuadMesh::rectangle(0.0, 1.0, 0.0, 1.0, 1, 4).unwrap();
    let plate = PlateElements::new(&mesh, steel_section(0.01), Kinematics::Nonlinear).unwrap();
    let mut dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    dofs.fix(mesh.group_nodes("bottom").unwrap(), &[0, 1, 2, 3, 4, 5]).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    for &n in mesh.group_nodes("top").unwrap() {
        model.add_load(Face::Top.dof(n, 2), 1e3).unwrap();
    }
    let mut settings = NewtonSettings::default();
    settings.max_iterations = 2;
    settings.max_cutbacks = 1;
    let mut newton = NewtonRaphson::new(SparseLu::new(), settings);
    let mut u = vec![0.0; model.dofs.num_dofs()];
    let err = newton.solve_path(&mut model, &mut u, 0.0, &[1.0], &mut |_, _, _| {}).unwrap_err();
    let text = err.to_string();
    assert!(matches!(err, StampError::NoConvergence { step: 1, .. }), "{text}");
    assert!(text.contains("load step 1") && text.contains("residual"), "{text}");
    assert!(u.iter().all(|x| *x == 0.0), "u keeps the last converged state");
}

#[test]
fn a_node_outside_every_element_is_named() {
    let coords = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]];
    let mesh = QuadMesh::new(coords, vec![[0, 1, 2, 3]]).unwrap();
    let plate = PlateElements::new(&mesh, steel_section(0.1), Kinematics::Linear).unwrap();
    let dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    let err = Model::new(plate, dofs).err().expect("an orphan node is an error");
    assert!(err.to_string().contains("node 4 belongs to no element"), "{err}");
}

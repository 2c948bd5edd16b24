//! The parallel assembly (blocks of consecutive elements, coloured so that the blocks of one colour
//! share no node) gives the serial one's residual, tangent, preconditioner and energy to round-off,
//! on a mesh in grid order and on the same mesh with its elements shuffled (blocks scattered over
//! the mesh), at a random large-displacement state, also when the parallel one assembled at
//! another state before (it zeroes the value arrays block by block).

mod common;

use common::{steel_section, Lcg};
use stamp::dofs::DofMap;
use stamp::mesh::QuadMesh;
use stamp::model::Model;
use stamp::nonlinear::NonlinearProblem;
use stamp_elements::{Kinematics, PlateElements};

/// Residual, tangent, preconditioner and energy of the plate on `mesh` at `u`, with `threads`
/// (after an assembly at each state of `before`: each one overwrites the last), and the number of
/// colours of the assembly's blocks.
fn assemble(mesh: &QuadMesh, before: &[&[f64]], u: &[f64], threads: usize) -> ((Vec<f64>, Vec<f64>, Vec<f64>, f64), usize) {
    let plate = PlateElements::new(mesh, steel_section(0.1), Kinematics::Nonlinear).unwrap();
    let mut dofs = DofMap::new(mesh.num_nodes(), 6).unwrap();
    dofs.fix(&mesh.nodes_where(|x| x[0] == 0.0), &[0, 1, 2, 3, 4, 5]).unwrap();
    let mut model = Model::new(plate, dofs).unwrap();
    model.want_preconditioner(true);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        for v in before {
            model.evaluate(v, 1.0, true).unwrap();
        }
        model.evaluate(u, 1.0, true).unwrap()
    });
    let p = model.preconditioner().unwrap().val().to_vec();
    ((model.residual().to_vec(), model.matrix().val().to_vec(), p, model.energy()), model.num_colors())
}

fn relative_difference(a: &[f64], b: &[f64]) -> f64 {
    let size = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    a.iter().zip(b).fold(0.0f64, |m, (x, y)| m.max((x - y).abs())) / size
}

#[test]
fn parallel_assembly_equals_serial() {
    // 60 x 60 = 3600 elements: above the assembler's parallel threshold
    let grid = QuadMesh::rectangle(0.0, 6.0, 0.0, 6.0, 60, 60).unwrap();
    assert!(grid.num_cells() >= stamp::assembly::PARALLEL_MIN_ELEMENTS);
    let mut shuffled = grid.clone();
    shuffled.cells.sort_by_key(|c| (c[0] * 7919) % grid.num_nodes());
    let mut rng = Lcg(7);
    let u: Vec<f64> = (0..6 * grid.num_nodes()).map(|_| rng.range(-0.02, 0.02)).collect();
    let earlier: Vec<f64> = (0..6 * grid.num_nodes()).map(|_| rng.range(-0.015, 0.015)).collect();
    for (name, mesh) in [("grid order", &grid), ("shuffled", &shuffled)] {
        let (serial, colors) = assemble(mesh, &[], &u, 1);
        // in parallel after two assemblies at another state: the arrays are overwritten
        let (parallel, _) = assemble(mesh, &[&earlier, &earlier], &u, 2);
        // a shuffled mesh is put in breadth-first order: its blocks need few colours too
        assert!(colors <= 8, "{name}: {colors} colours");
        assert!(serial.1.iter().any(|&x| x != 0.0) && serial.3 > 0.0);
        for (what, a, b) in [("residual", &serial.0, &parallel.0), ("tangent", &serial.1, &parallel.1), ("preconditioner", &serial.2, &parallel.2)] {
            let d = relative_difference(a, b);
            assert!(d <= 1e-13, "{name}: {what} differs by {d:e}");
        }
        assert!((serial.3 - parallel.3).abs() <= 1e-12 * serial.3, "{name}: energy {} against {}", serial.3, parallel.3);
    }
}

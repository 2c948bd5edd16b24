//! The whole-mesh checks (stamp::mesh::check) on small meshes with one defect each, the messages
//! the gmsh reader makes of them (gmsh tags), and the cost on a 400 x 400 mesh (ignored test).

use stamp::io::gmsh::parse_msh_bytes;
use stamp::mesh::QuadMesh;
use stamp::mesh::check::{check_mesh, Defect};
use std::path::Path;

fn mesh(coords: Vec<[f64; 2]>, cells: Vec<[usize; 4]>) -> QuadMesh {
    QuadMesh { coords, cells, ..Default::default() }
}

/// Two unit squares side by side: nodes 0..5 (bottom row 0, 1, 2; top row 3, 4, 5).
fn two_squares() -> QuadMesh {
    mesh(
        vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0], [2.0, 1.0]],
        vec![[0, 1, 4, 3], [1, 2, 5, 4]],
    )
}

#[test]
fn good_meshes_pass() {
    check_mesh(&two_squares()).unwrap();
    check_mesh(&QuadMesh::rectangle(0.0, 3.0, -1.0, 1.0, 30, 20).unwrap()).unwrap();
}

#[test]
fn each_defect_is_found() {
    let mut m = two_squares();
    m.cells.push([4, 3, 0, 1]);
    assert_eq!(check_mesh(&m), Err(Defect::DuplicateCells { first: 0, second: 2 }));

    // A third square on the edge 1-4, folded back over the first one.
    let mut m = two_squares();
    m.coords.push([0.5, 0.0]);
    m.coords.push([0.5, 1.0]);
    m.cells.push([6, 1, 4, 7]);
    match check_mesh(&m) {
        Err(Defect::EdgeSharedByMore { edge: [1, 4], cells }) => assert_eq!(cells.len(), 3),
        other => panic!("{other:?}"),
    }

    // Cell 1 mirrored onto cell 0 across edge 1-4 (the same side): a fold.
    let mut m = two_squares();
    m.coords[2] = [0.2, 0.0];
    m.coords[5] = [0.2, 1.0];
    m.cells[1] = [2, 1, 4, 5];
    assert_eq!(check_mesh(&m), Err(Defect::Folded { first: 0, second: 1, edge: [1, 4] }));

    // Two squares overlapping without sharing anything.
    let m = mesh(
        vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]],
        vec![[0, 1, 2, 3], [4, 5, 6, 7]],
    );
    assert_eq!(check_mesh(&m), Err(Defect::Overlap { first: 0, second: 1 }));

    // A big cell next to two small ones: node 7 hangs on the big cell's edge 1-4... here (1, 0.5).
    let m = mesh(
        vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0], [2.0, 1.0], [2.0, 0.5], [1.0, 0.5]],
        vec![[0, 1, 4, 3], [1, 2, 6, 7], [7, 6, 5, 4]],
    );
    assert_eq!(check_mesh(&m), Err(Defect::HangingNode { node: 7, cell: 0, edge: [1, 4] }));

    // Two cells that touch along x = 1 through different nodes at the same points: a crack.
    let m = mesh(
        vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [1.0, 0.0], [2.0, 0.0], [2.0, 1.0], [1.0, 1.0]],
        vec![[0, 1, 2, 3], [4, 5, 6, 7]],
    );
    assert!(matches!(check_mesh(&m), Err(Defect::CoincidentNodes { .. })), "{:?}", check_mesh(&m));

    // Alone: an inverted cell.
    let m = mesh(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]], vec![[0, 3, 2, 1]]);
    assert!(matches!(check_mesh(&m), Err(Defect::BadCell { cell: 0, inverted: true, .. })));
}

/// An ASCII MSH 4.1 file of quadrilaterals (one surface, no entities) with the given node
/// coordinates and element node tags (nodes tagged 1..).
fn msh(coords: &[[f64; 2]], elements: &[(u64, [u64; 4])]) -> String {
    let mut s = String::from("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n");
    s += &format!("1 {n} 1 {n}\n2 1 0 {n}\n", n = coords.len());
    for i in 0..coords.len() {
        s += &format!("{}\n", i + 1);
    }
    for c in coords {
        s += &format!("{} {} 0\n", c[0], c[1]);
    }
    let (lo, hi) = (elements.iter().map(|e| e.0).min().unwrap(), elements.iter().map(|e| e.0).max().unwrap());
    s += &format!("$EndNodes\n$Elements\n1 {} {lo} {hi}\n2 1 3 {}\n", elements.len(), elements.len());
    for (t, n) in elements {
        s += &format!("{t} {} {} {} {}\n", n[0], n[1], n[2], n[3]);
    }
    s + "$EndElements\n"
}

fn error_of(text: &str) -> String {
    match parse_msh_bytes(Path::new("defect.msh"), text.as_bytes()) {
        Ok(_) => panic!("accepted:\n{text}"),
        Err(e) => e.to_string(),
    }
}

fn assert_contains(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(message.contains(p), "error message lacks {p:?}: {message}");
    }
    assert!(message.len() < 400, "{message}");
}

#[test]
fn the_reader_names_gmsh_tags() {
    let sq = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0], [2.0, 1.0]];
    let e = error_of(&msh(&sq, &[(10, [1, 2, 5, 4]), (20, [2, 3, 6, 5]), (30, [5, 4, 1, 2])]));
    assert_contains(&e, &["defect.msh", "elements 10 and 30", "duplicates"]);

    let hang = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [0.0, 1.0], [1.0, 1.0], [2.0, 1.0], [2.0, 0.5], [1.0, 0.5]];
    let e = error_of(&msh(&hang, &[(7, [1, 2, 5, 4]), (8, [2, 3, 7, 8]), (9, [8, 7, 6, 5])]));
    assert_contains(&e, &["node 8 lies on the edge from node 2 to node 5 of element 7", "hanging"]);

    let e = error_of(&msh(&sq, &[(10, [1, 2, 5, 4]), (10, [2, 3, 6, 5])]));
    assert_contains(&e, &["element tag 10 appears more than once"]);

    let over = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5], [1.5, 0.5], [1.5, 1.5], [0.5, 1.5]];
    let e = error_of(&msh(&over, &[(3, [1, 2, 3, 4]), (4, [5, 6, 7, 8])]));
    assert_contains(&e, &["elements 3 and 4 overlap"]);
}

#[test]
#[ignore = "a measurement: prints the time of the checks on a 400 x 400 mesh"]
fn mesh_check_cost() {
    let m = QuadMesh::rectangle(0.0, 4.0, 0.0, 4.0, 400, 400).unwrap();
    for _ in 0..3 {
        let t = std::time::Instant::now();
        check_mesh(&m).unwrap();
        println!("check_mesh on {} cells: {:.3} s", m.num_cells(), t.elapsed().as_secs_f64());
    }
    // The whole reader on the same mesh as an ASCII file (parse, convert, check).
    let tags: Vec<(u64, [u64; 4])> =
        m.cells.iter().enumerate().map(|(c, n)| (c as u64 + 1, n.map(|i| i as u64 + 1))).collect();
    let text = msh(&m.coords, &tags);
    let t = std::time::Instant::now();
    let g = parse_msh_bytes(Path::new("big.msh"), text.as_bytes()).unwrap();
    println!("parse_msh_bytes of {} bytes, {} cells: {:.3} s", text.len(), g.mesh.num_cells(), t.elapsed().as_secs_f64());
}

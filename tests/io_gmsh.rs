//! Reading gmsh meshes: the committed fixtures in tests/data (made by gmsh 4.8 from the .geo files
//! there, some edited by hand; see tests/data/README.md).

use stamp::io::gmsh::{read_msh, GmshMesh};
use stamp::mesh::{quad_corner_jacobians, quad_signed_area};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data").join(name)
}

fn read(name: &str) -> GmshMesh {
    read_msh(&data(name)).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The error message of reading a file that must be refused.
fn error_of(path: &Path) -> String {
    match read_msh(path) {
        Ok(m) => panic!("{} was accepted ({} nodes, {} cells)", path.display(), m.mesh.num_nodes(), m.mesh.num_cells()),
        Err(e) => e.to_string(),
    }
}

fn assert_contains(message: &str, parts: &[&str]) {
    for p in parts {
        assert!(message.contains(p), "error message lacks {p:?}: {message}");
    }
}

/// A scratch directory for files made by editing the fixtures.
fn scratch(test: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("io_gmsh-{test}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn edited(test: &str, fixture: &str, edits: &[(&str, &str)]) -> PathBuf {
    let mut text = std::fs::read_to_string(data(fixture)).unwrap();
    for (old, new) in edits {
        assert!(text.contains(old), "{fixture} does not contain {old:?}");
        text = text.replacen(old, new, 1);
    }
    let p = scratch(test).join(fixture);
    std::fs::write(&p, text).unwrap();
    p
}

fn total_area(m: &GmshMesh) -> f64 {
    (0..m.mesh.num_cells()).map(|c| quad_signed_area(&m.mesh.cell_coords(c))).sum()
}

fn node_by_tag(m: &GmshMesh, tag: u64) -> usize {
    m.node_tags.iter().position(|&t| t == tag).unwrap_or_else(|| panic!("no node tag {tag}"))
}

fn sizes<T>(map: &BTreeMap<String, Vec<T>>) -> BTreeMap<String, usize> {
    map.iter().map(|(k, v)| (k.clone(), v.len())).collect()
}

fn owned(pairs: &[(&str, usize)]) -> BTreeMap<String, usize> {
    pairs.iter().map(|(k, v)| (k.to_string(), *v)).collect()
}

#[test]
fn rect_ascii_counts_coordinates_and_groups() {
    let m = read("rect.msh");
    assert_eq!(m.mesh.num_nodes(), 15);
    assert_eq!(m.mesh.num_cells(), 8);
    assert!(!m.reoriented);
    m.mesh.validate().unwrap();
    assert!((total_area(&m) - 2.0).abs() < 1e-12);
    assert_eq!(m.cell_tags, (15..=22).collect::<Vec<u64>>());
    let mut tags = m.node_tags.clone();
    tags.sort();
    assert_eq!(tags, (1..=15).collect::<Vec<u64>>());

    // Node 8 is the middle of the right edge, node 3 the corner (2, 1).
    let n8 = node_by_tag(&m, 8);
    assert!((m.mesh.coords[n8][0] - 2.0).abs() < 1e-12 && (m.mesh.coords[n8][1] - 0.5).abs() < 1e-9);
    assert_eq!(m.mesh.coords[node_by_tag(&m, 3)], [2.0, 1.0]);
    // Element 15 is (1, 5, 13, 12), counter-clockwise as in the file.
    assert_eq!(m.mesh.cells[0], [1, 5, 13, 12].map(|t| node_by_tag(&m, t)));

    let names: Vec<(usize, i32, &str)> = m.physical_names.iter().map(|p| (p.dim, p.tag, p.name.as_str())).collect();
    assert_eq!(names, vec![(0, 1, "origin"), (1, 3, "bottom"), (1, 4, "right"), (1, 5, "load"), (2, 7, "plate")]);
    assert_eq!(m.physical_groups.len(), 7);

    assert_eq!(
        sizes(&m.mesh.node_groups),
        owned(&[
            ("#1", 1),
            ("#2", 1),
            ("#3", 5),
            ("#4", 3),
            ("#5", 5),
            ("#6", 3),
            ("#7", 15),
            ("bottom", 5),
            ("load", 5),
            ("origin", 1),
            ("plate", 15),
            ("right", 3),
        ])
    );
    assert_eq!(sizes(&m.point_groups), owned(&[("#1", 1), ("#2", 1), ("origin", 1)]));
    assert_eq!(
        sizes(&m.curve_groups),
        owned(&[("#3", 4), ("#4", 2), ("#5", 4), ("#6", 2), ("bottom", 4), ("load", 4), ("right", 2)])
    );
    assert_eq!(sizes(&m.mesh.cell_groups), owned(&[("#7", 8), ("plate", 8)]));

    // Group contents.
    assert_eq!(m.point_group("origin").unwrap(), &[node_by_tag(&m, 1)]);
    assert_eq!(m.mesh.coords[m.point_group("#2").unwrap()[0]], [2.0, 1.0]);
    for &n in m.node_group("bottom").unwrap() {
        assert_eq!(m.mesh.coords[n][1], 0.0);
    }
    for &n in m.group("#6").unwrap() {
        assert_eq!(m.mesh.coords[n][0], 0.0);
    }
    let load = m.curve_group("load").unwrap();
    let len: f64 = load
        .iter()
        .map(|s| {
            let (a, b) = (m.mesh.coords[s[0]], m.mesh.coords[s[1]]);
            ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
        })
        .sum();
    assert!((len - 2.0).abs() < 1e-12);
    assert!(load.iter().flatten().all(|&n| (m.mesh.coords[n][1] - 1.0).abs() < 1e-12));
    assert_eq!(m.cell_group("plate").unwrap(), &(0..8).collect::<Vec<_>>()[..]);
    assert_eq!(m.mesh.group_nodes("load").unwrap(), m.node_group("load").unwrap());
}

/// Same mesh and groups; coordinates to 1e-15 (ASCII files hold 16 significant digits, binary files
/// the full double).
fn assert_same_mesh(a: &GmshMesh, b: &GmshMesh) {
    assert_eq!(a.mesh.num_nodes(), b.mesh.num_nodes());
    for (i, (x, y)) in a.mesh.coords.iter().zip(&b.mesh.coords).enumerate() {
        for d in 0..2 {
            assert!((x[d] - y[d]).abs() <= 1e-15 * x[d].abs().max(1.0), "node {i}: {x:?} vs {y:?}");
        }
    }
    assert_eq!(a.mesh.cells, b.mesh.cells);
    assert_eq!(a.mesh.node_groups, b.mesh.node_groups);
    assert_eq!(a.mesh.cell_groups, b.mesh.cell_groups);
    assert_eq!(a.point_groups, b.point_groups);
    assert_eq!(a.curve_groups, b.curve_groups);
    assert_eq!(a.node_tags, b.node_tags);
    assert_eq!(a.cell_tags, b.cell_tags);
    assert_eq!(a.physical_names, b.physical_names);
    assert_eq!(a.physical_groups, b.physical_groups);
}

#[test]
fn rect_binary_gives_the_same_mesh_as_ascii() {
    assert_same_mesh(&read("rect.msh"), &read("rect_bin.msh"));
}

#[test]
fn holed_plate_unstructured_ascii_and_binary() {
    let m = read("holed.msh");
    assert_same_mesh(&m, &read("holed_bin.msh"));
    assert_eq!(m.mesh.num_nodes(), 224);
    assert!(m.mesh.num_cells() > 150, "{} cells", m.mesh.num_cells());
    m.mesh.validate().unwrap();
    // Area = square minus the polygon the hole's segments make (fan of triangles from the centre).
    let hole = m.curve_group("hole").unwrap();
    let polygon: f64 = hole
        .iter()
        .map(|s| {
            let (a, b) = (m.mesh.coords[s[0]], m.mesh.coords[s[1]]);
            0.5 * ((a[0] - 2.0) * (b[1] - 2.0) - (a[1] - 2.0) * (b[0] - 2.0)).abs()
        })
        .sum();
    let area = total_area(&m);
    assert!((area - (16.0 - polygon)).abs() < 1e-10, "area {area}, expected {}", 16.0 - polygon);
    assert!(polygon < std::f64::consts::PI * 0.64 && polygon > 0.95 * std::f64::consts::PI * 0.64);
    for c in 0..m.mesh.num_cells() {
        assert!(quad_corner_jacobians(&m.mesh.cell_coords(c)).iter().all(|&j| j > 0.0), "cell {c}");
    }
    // The hole is a closed loop of segments: every node on it ends exactly two segments, and all
    // lie on the circle.
    let mut ends: BTreeMap<usize, usize> = BTreeMap::new();
    for s in hole {
        *ends.entry(s[0]).or_default() += 1;
        *ends.entry(s[1]).or_default() += 1;
    }
    assert_eq!(ends.len(), hole.len());
    assert!(ends.values().all(|&k| k == 2));
    for &n in ends.keys() {
        let [x, y] = m.mesh.coords[n];
        assert!((((x - 2.0).powi(2) + (y - 2.0).powi(2)).sqrt() - 0.8).abs() < 1e-9);
    }
    assert_eq!(m.node_group("hole").unwrap().len(), hole.len());
    assert_eq!(m.node_group("plate").unwrap().len(), 224);
    assert_eq!(m.cell_group("plate").unwrap().len(), m.mesh.num_cells());
    assert!(m.node_group("outer").unwrap().len() >= 16);
}

#[test]
fn clockwise_mesh_is_reoriented() {
    let m = read("rect_cw.msh");
    assert!(m.reoriented);
    assert_eq!(m.mesh.num_cells(), 8);
    assert_eq!(m.mesh.num_nodes(), 15);
    m.mesh.validate().unwrap();
    assert!((total_area(&m) - 2.0).abs() < 1e-12);
    // The file's first quad (element 5) is (4, 11, 13, 12), clockwise: reversed to (4, 12, 13, 11).
    assert_eq!(m.cell_tags[0], 5);
    assert_eq!(m.mesh.cells[0], [4, 12, 13, 11].map(|t| node_by_tag(&m, t)));
    assert_eq!(m.node_group("bottom").unwrap().len(), 5);
}

#[test]
fn permuted_dense_node_tags_are_read_by_tag() {
    // rect_permuted.msh lists the nodes of one block in the order 15, 13, 14 (tags and coordinates
    // together): the same mesh as rect.msh.
    let a = read("rect.msh");
    let b = read("rect_permuted.msh");
    assert_eq!(a.mesh.num_cells(), b.mesh.num_cells());
    for c in 0..a.mesh.num_cells() {
        assert_eq!(a.cell_tags[c], b.cell_tags[c]);
        assert_eq!(a.mesh.cell_coords(c), b.mesh.cell_coords(c), "cell with gmsh tag {}", a.cell_tags[c]);
    }
    for tag in 1..=15 {
        assert_eq!(a.mesh.coords[node_by_tag(&a, tag)], b.mesh.coords[node_by_tag(&b, tag)], "node {tag}");
    }

}

#[test]
fn msh22_is_refused_with_a_conversion_hint() {
    let e = error_of(&data("rect_msh22.msh"));
    assert_contains(&e, &["rect_msh22.msh", "version 2.2", "-format msh41"]);
}

#[test]
fn msh40_is_refused_with_a_conversion_hint() {
    let p = edited("msh40", "rect.msh", &[("4.1 0 8", "4 0 8")]);
    assert_contains(&error_of(&p), &["rect.msh", "version 4 ", "-format msh41"]);
}

#[test]
fn triangles_are_accepted_and_cut_into_quadrilaterals() {
    let m = read("tri.msh");
    assert_eq!(m.source_cells.len(), 1);
    assert_eq!((m.source_cells[0].elements, m.source_cells[0].cells), (4, 12));
    assert_eq!(m.mesh.num_cells(), 12);
    assert!((total_area(&m) - 2.0).abs() < 1e-12);
    assert_eq!(m.curve_group("bottom").unwrap().len(), 4);
}

#[test]
fn unsupported_element_types_are_named_in_words_with_their_tag() {
    // The quadrilateral block of rect.msh relabelled as 8-node hexahedra (type 5).
    let p = edited("hex", "rect.msh", &[("2 1 3 8\n", "2 1 5 8\n")]);
    let e = error_of(&p);
    assert_contains(&e, &["rect.msh", "element 15", "type 5", "8-node hexahedron", "stamp accepts"]);
    let p = edited("cubic", "rect.msh", &[("2 1 3 8\n", "2 1 21 8\n")]);
    assert_contains(&error_of(&p), &["element 15", "10-node triangle (third order)"]);
}

#[test]
fn truncated_files_are_refused() {
    for name in ["rect_truncated.msh", "rect_bin_truncated.msh"] {
        assert_contains(&error_of(&data(name)), &[name, "truncated"]);
    }
    // Cut at every 7th byte of both files: always an error, never a panic.
    let dir = scratch("truncated");
    for name in ["rect.msh", "rect_bin.msh"] {
        let bytes = std::fs::read(data(name)).unwrap();
        for cut in (0..bytes.len() - 20).step_by(7) {
            let p = dir.join(format!("cut{cut}-{name}"));
            std::fs::write(&p, &bytes[..cut]).unwrap();
            assert_contains(&error_of(&p), &[&format!("cut{cut}-{name}")]);
        }
    }
}

#[test]
fn an_inverted_element_is_named() {
    let e = error_of(&data("rect_inverted.msh"));
    assert_contains(&e, &["rect_inverted.msh", "element 17 ", "inverted", "clockwise"]);
}

#[test]
fn a_degenerate_element_is_named() {
    // Element 20 = (14, 15, 9, 10) with node 9 moved onto node 15: zero corner Jacobian.
    let p = edited("degenerate", "rect.msh", &[("1.500000000000694 1 0\n", "1.499999999999688 0.499999999999534 0\n")]);
    let e = error_of(&p);
    assert_contains(&e, &["rect.msh", "element 20 (", "degenerate"]);
}

#[test]
fn non_planar_node_is_refused() {
    let e = error_of(&data("rect_z.msh"));
    assert_contains(&e, &["rect_z.msh", "node 14", "z = 0.25"]);
}

#[test]
fn missing_node_is_refused() {
    let e = error_of(&data("rect_badnode.msh"));
    assert_contains(&e, &["rect_badnode.msh", "element 22", "node tag 99"]);
}

#[test]
fn missing_empty_and_foreign_files_are_refused() {
    let e = error_of(&data("no_such_file.msh"));
    assert_contains(&e, &["no_such_file.msh", "cannot read"]);
    let dir = scratch("foreign");
    let empty = dir.join("empty.msh");
    std::fs::write(&empty, "").unwrap();
    assert_contains(&error_of(&empty), &["empty.msh", "empty"]);
    let stl = dir.join("part.stl");
    std::fs::write(&stl, "solid part\nendsolid part\n").unwrap();
    assert_contains(&error_of(&stl), &["part.stl", "$MeshFormat"]);
}

#[test]
fn unknown_group_names_list_what_the_file_has() {
    let m = read("rect.msh");
    let e = m.node_group("clamped").unwrap_err().to_string();
    assert_contains(&e, &["rect.msh", "'clamped'", "bottom", "load", "origin", "plate", "right", "#6"]);
    let e = m.curve_group("plate").unwrap_err().to_string();
    assert_contains(&e, &["rect.msh", "bottom, load", "'plate' is a physical surface"]);
    let e = m.cell_group("bottom").unwrap_err().to_string();
    assert_contains(&e, &["plate", "'bottom' is a physical curve"]);
    let e = m.point_group("top").unwrap_err().to_string();
    assert_contains(&e, &["#1, #2, origin"]);
}

#[test]
fn group_number_used_by_two_dimensions() {
    // Give the surface the number of the curve "load" (5): "#5" is ambiguous in node_groups, but
    // the per-dimension lookups and the names still work.
    let p = edited(
        "ambiguous",
        "rect.msh",
        &[("2 7 \"plate\"", "2 5 \"plate\""), ("1 0 0 0 2 1 0 1 7 4 1 2 3 4", "1 0 0 0 2 1 0 1 5 4 1 2 3 4")],
    );
    let m = read_msh(&p).unwrap();
    assert!(!m.mesh.node_groups.contains_key("#5"));
    assert_contains(&m.node_group("#5").unwrap_err().to_string(), &["ambiguous", "curve", "surface"]);
    assert_eq!(m.curve_group("#5").unwrap().len(), 4);
    assert_eq!(m.cell_group("#5").unwrap().len(), 8);
    assert_eq!(m.node_group("plate").unwrap().len(), 15);
    assert_eq!(m.node_group("load").unwrap().len(), 5);
}

#[test]
fn names_with_spaces_and_shared_names() {
    // A name with spaces, and the name "edge" used by a point and a curve: the node group is the
    // union.
    let p = edited(
        "names",
        "rect.msh",
        &[("0 1 \"origin\"", "0 1 \"edge\""), ("1 3 \"bottom\"", "1 3 \"edge\""), ("1 5 \"load\"", "1 5 \"top load\"")],
    );
    let m = read_msh(&p).unwrap();
    assert_eq!(m.curve_group("top load").unwrap().len(), 4);
    assert_eq!(m.point_group("edge").unwrap().len(), 1);
    assert_eq!(m.curve_group("edge").unwrap().len(), 4);
    assert_eq!(m.node_group("edge").unwrap().len(), 5);
}

/// The message of parsing edited bytes of a fixture (no file written).
fn bytes_error(fixture: &str, edit: impl Fn(Vec<u8>) -> Vec<u8>) -> String {
    let bytes = edit(std::fs::read(data(fixture)).unwrap());
    match stamp::io::parse_msh_bytes(Path::new(fixture), &bytes) {
        Ok(_) => panic!("{fixture} edited was accepted"),
        Err(e) => {
            let m = e.to_string();
            assert!(m.len() < 400, "message of {} characters: {m}", m.len());
            m
        }
    }
}

fn replace(old: &str, new: &str) -> impl Fn(Vec<u8>) -> Vec<u8> {
    let (old, new) = (old.as_bytes().to_vec(), new.as_bytes().to_vec());
    move |b: Vec<u8>| {
        let p = b.windows(old.len()).position(|w| w == old.as_slice()).expect("fixture lacks the text");
        [&b[..p], new.as_slice(), &b[p + old.len()..]].concat()
    }
}

#[test]
fn huge_counts_are_refused_without_allocating() {
    for count in ["1000000000000", "18446744073709551615", "9223372036854775808"] {
        let e = bytes_error("rect.msh", replace("$PhysicalNames\n5\n", &format!("$PhysicalNames\n{count}\n")));
        assert_contains(&e, &["rect.msh", "$PhysicalNames", count, "bytes left"]);
        let e = bytes_error("rect.msh", replace("$Nodes\n9 15 1 15\n", &format!("$Nodes\n9 {count} 1 15\n")));
        assert_contains(&e, &["$Nodes", "number of nodes", count]);
        let e = bytes_error("rect.msh", replace("$Elements\n7 22 1 22\n", &format!("$Elements\n{count} 22 1 22\n")));
        assert_contains(&e, &["$Elements", "element blocks", count]);
        let e = bytes_error("rect.msh", replace("$Entities\n4 4 1 0\n", &format!("$Entities\n4 {count} 1 0\n")));
        assert_contains(&e, &["$Entities", "curve entities", count]);
        let e = bytes_error("rect.msh", replace("2 1 3 8\n", &format!("2 1 3 {count}\n")));
        assert_contains(&e, &["$Elements", "block 7", count]);
    }
    let e = bytes_error("rect.msh", replace("$PhysicalNames\n5\n", "$PhysicalNames\n-1\n"));
    assert_contains(&e, &["$PhysicalNames", "number of physical names", "'-1'"]);
    // binary: the node count of the first block set to 2^64 - 1
    let e = bytes_error("rect_bin.msh", |mut b| {
        let p = b.windows(7).position(|w| w == b"$Nodes\n").unwrap() + 7;
        // header: 4 size_t; block: 3 ints then the count
        b[p + 32 + 12..p + 32 + 20].copy_from_slice(&u64::MAX.to_le_bytes());
        b
    });
    assert_contains(&e, &["rect_bin.msh", "$Nodes", "18446744073709551615", "bytes left"]);
}

#[test]
fn header_counts_and_tags_must_match_the_blocks() {
    let e = bytes_error("rect.msh", replace("$Nodes\n9 15 1 15\n", "$Nodes\n9 14 1 15\n"));
    assert_contains(&e, &["$Nodes", "more nodes than the 14"]);
    let e = bytes_error("rect.msh", replace("$Nodes\n9 15 1 15\n", "$Nodes\n9 15 1 16\n"));
    assert_contains(&e, &["$Nodes", "1 to 16", "1 to 15"]);
    let e = bytes_error("rect.msh", replace("$Elements\n7 22 1 22\n", "$Elements\n7 23 1 22\n"));
    assert_contains(&e, &["$Elements", "announces 23 elements", "hold 22"]);
    let e = bytes_error("rect.msh", replace("$Elements\n7 22 1 22\n", "$Elements\n7 22 2 22\n"));
    assert_contains(&e, &["$Elements", "element tags 2 to 22", "from 1 to 22"]);
    let e = bytes_error("rect.msh", replace("\n5\n6\n7\n", "\n5\n0\n7\n"));
    assert_contains(&e, &["node tag 0 is invalid"]);
    let e = bytes_error("rect.msh", replace("\n5\n6\n7\n", "\n5\n5\n7\n"));
    assert_contains(&e, &["node tag 5 appears more than once"]);
    let e = bytes_error("rect.msh", replace("\n15 1 5 13 12 \n", "\n0 1 5 13 12 \n"));
    assert_contains(&e, &["element tag 0 is invalid"]);
    let e = bytes_error("rect.msh", replace("\n15 1 5 13 12 \n", "\n16 1 5 13 12 \n"));
    assert_contains(&e, &["element tag 16 appears more than once"]);
    let e = bytes_error("rect.msh", replace("\n22 15 8 3 9 \n", "\n22 5 13 12 1 \n"));
    assert_contains(&e, &["elements 15 and 22 are duplicates"]);
}

#[test]
fn unterminated_sections_are_named() {
    for section in ["PhysicalNames", "Entities", "Nodes", "Elements"] {
        let end = format!("$End{section}\n");
        let e = bytes_error("rect.msh", replace(&end, ""));
        assert_contains(&e, &["rect.msh", &format!("${section} section"), &format!("$End{section}")]);
        let e = bytes_error("rect_bin.msh", replace(&end, ""));
        assert_contains(&e, &["rect_bin.msh", &format!("${section} section"), &format!("$End{section}")]);
    }
    // A block count one too small leaves data where $EndNodes should be.
    let e = bytes_error("rect.msh", replace("$Nodes\n9 15 1 15\n", "$Nodes\n8 15 1 15\n"));
    assert_contains(&e, &["$Nodes", "hold"]);
}

#[test]
fn binary_garbage_is_not_echoed() {
    // The binary node section's coordinates overwritten with text-like and control bytes after
    // breaking the counts: the message stays short and printable.
    let e = bytes_error("rect_bin.msh", |mut b| {
        let p = b.windows(7).position(|w| w == b"$Nodes\n").unwrap() + 7;
        for (k, x) in b[p..p + 400].iter_mut().enumerate() {
            *x = if k % 3 == 0 { 0 } else { 0x41 + (k % 26) as u8 };
        }
        b
    });
    assert!(e.chars().all(|c| !c.is_control()), "{e}");
    let e = bytes_error("rect.msh", replace("$Nodes\n", &format!("$Garbage\n{}\n$Nodes\n", "\u{1}x".repeat(500))));
    assert!(e.chars().all(|c| !c.is_control()), "{e}");
}

#[test]
fn only_regular_files_are_read() {
    let dir = scratch("kinds");
    assert_contains(&error_of(&dir), &["io_gmsh-kinds", "directory"]);
    #[cfg(unix)]
    {
        let fifo = dir.join("pipe.msh");
        let status = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(status.success());
        // Would block forever if the reader opened it.
        assert_contains(&error_of(&fifo), &["pipe.msh", "not a regular file"]);
        assert_contains(&error_of(Path::new("/dev/null")), &["/dev/null", "not a regular file"]);
    }
}

#[test]
fn the_shipped_meshes_pass_the_whole_mesh_checks() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("meshes");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let p = entry.unwrap().path();
        if p.extension().is_some_and(|e| e == "msh") {
            let m = read_msh(&p).unwrap_or_else(|e| panic!("{e}"));
            stamp::mesh::check::check_mesh(&m.mesh).unwrap();
            // quadrilateral meshes are read as they are; the disk (at lc = 2 and 1), the README
            // tutorial's plate and the friction example's half plate are gmsh's default triangles
            let triangles = p.file_name().is_some_and(|f| f == "disk-clamped.msh" || f == "disk-clamped-lc1.msh" || f == "plate.msh" || f == "sphere-slide-tri.msh");
            assert_eq!(m.split_summary().is_some(), triangles, "{}: {:?}", p.display(), m.split_summary());
            n += 1;
        }
    }
    assert!(n >= 3);
}

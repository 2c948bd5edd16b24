//! Writing ParaView files (.vtu, .pvd) and atomic writes.

#[path = "common/python.rs"]
mod python;
use python::python_with;
use stamp::io::atomic::{write_atomically, write_string_atomically};
use stamp::io::vtk::{write_pvd, write_vtu, Field};
use stamp::mesh::QuadMesh;
use std::path::{Path, PathBuf};
use std::process::Command;
use vtkio::model::{Attribute, CellType, DataSet, IOBuffer, Piece, VertexNumbers, Vtk};

fn scratch(test: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("io_vtk-{test}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn dir_listing(d: &Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

/// A 3 x 2 mesh on [0, 3] x [0, 1] with nodes moved a little so that no coordinate is trivial,
/// and fields: displacement (3 components) and w at the nodes, thickness and a 2-component
/// "stress" at the cells.
fn sample() -> (QuadMesh, Vec<Field>, Vec<Field>) {
    let mut mesh = QuadMesh::rectangle(0.0, 3.0, 0.0, 1.0, 3, 2).unwrap();
    for (i, x) in mesh.coords.iter_mut().enumerate() {
        x[0] += 0.01 * (i as f64).sin();
        x[1] += 0.01 * (i as f64).cos();
    }
    mesh.validate().unwrap();
    let n = mesh.num_nodes();
    let c = mesh.num_cells();
    let u: Vec<f64> = (0..3 * n).map(|k| 1e-3 * (k as f64 + 1.0) / 7.0).collect();
    let w: Vec<f64> = (0..n).map(|k| -0.5 + (k as f64).powi(2) / 13.0).collect();
    let t: Vec<f64> = (0..c).map(|k| 0.1 + 0.01 * k as f64).collect();
    let s: Vec<f64> = (0..2 * c).map(|k| 1e6 * (k as f64 - 3.3)).collect();
    (
        mesh,
        vec![Field::new("displacement", 3, u), Field::scalar("w", w)],
        vec![Field::scalar("thickness", t), Field::new("stress", 2, s)],
    )
}

fn f64s(buf: &IOBuffer) -> Vec<f64> {
    match buf {
        IOBuffer::F64(v) => v.clone(),
        IOBuffer::F32(v) => v.iter().map(|&x| x as f64).collect(),
        other => panic!("unexpected buffer type {other:?}"),
    }
}

fn check_attributes(read: &[Attribute], written: &[Field]) {
    assert_eq!(read.len(), written.len());
    for (a, f) in read.iter().zip(written) {
        let Attribute::DataArray(d) = a else { panic!("field data {a:?}") };
        assert_eq!(d.name, f.name);
        assert_eq!(d.elem.num_comp() as usize, f.components, "{}", f.name);
        assert_eq!(f64s(&d.data), f.values, "{}", f.name);
    }
}

#[test]
fn vtu_round_trip_through_vtkio() {
    let dir = scratch("roundtrip");
    let path = dir.join("result.vtu");
    let (mesh, pd, cd) = sample();
    write_vtu(&path, &mesh, &pd, &cd).unwrap();
    assert_eq!(dir_listing(&dir), vec!["result.vtu"]);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("UnstructuredGrid") && text.contains("vtkZLibDataCompressor"),
        "{}",
        &text[..300.min(text.len())]
    );

    let vtk = Vtk::import(&path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!("not an unstructured grid") };
    assert_eq!(pieces.len(), 1);
    let Piece::Inline(piece) = &pieces[0] else { panic!("piece not inline") };
    assert_eq!(piece.num_points(), mesh.num_nodes());
    let pts = f64s(&piece.points);
    let expected: Vec<f64> = mesh.coords.iter().flat_map(|x| [x[0], x[1], 0.0]).collect();
    assert_eq!(pts, expected);
    assert_eq!(piece.cells.types, vec![CellType::Quad; mesh.num_cells()]);
    let (conn, offsets) = match &piece.cells.cell_verts {
        VertexNumbers::XML { connectivity, offsets } => (connectivity.clone(), offsets.clone()),
        VertexNumbers::Legacy { .. } => panic!("legacy cells"),
    };
    let expected: Vec<u64> = mesh.cells.iter().flatten().map(|&k| k as u64).collect();
    assert_eq!(conn, expected);
    assert_eq!(offsets, (1..=mesh.num_cells() as u64).map(|k| 4 * k).collect::<Vec<_>>());
    check_attributes(&piece.data.point, &pd);
    check_attributes(&piece.data.cell, &cd);
}

#[test]
fn vtu_without_fields_and_overwrite() {
    let dir = scratch("nofields");
    let path = dir.join("mesh.vtu");
    let mesh = QuadMesh::rectangle(0.0, 1.0, 0.0, 1.0, 1, 1).unwrap();
    write_vtu(&path, &mesh, &[], &[]).unwrap();
    let (big, pd, cd) = sample();
    write_vtu(&path, &big, &pd, &cd).unwrap();
    let vtk = Vtk::import(&path).unwrap();
    let DataSet::UnstructuredGrid { pieces, .. } = vtk.data else { panic!() };
    let Piece::Inline(piece) = &pieces[0] else { panic!() };
    assert_eq!(piece.num_points(), big.num_nodes());
    assert_eq!(dir_listing(&dir), vec!["mesh.vtu"]);
}

#[test]
fn bad_fields_are_refused_naming_the_field_and_keep_the_old_file() {
    let dir = scratch("badfields");
    let path = dir.join("out.vtu");
    let (mesh, pd, cd) = sample();
    write_vtu(&path, &mesh, &pd, &cd).unwrap();
    let before = std::fs::read(&path).unwrap();

    let mut short = pd.clone();
    short[1].values.pop();
    let e = write_vtu(&path, &mesh, &short, &cd).unwrap_err().to_string();
    for part in ["out.vtu", "point field 'w'", "11 values", "12 nodes"] {
        assert!(e.contains(part), "{part:?} not in: {e}");
    }

    let mut nan = cd.clone();
    nan[1].values[5] = f64::NAN;
    let e = write_vtu(&path, &mesh, &pd, &nan).unwrap_err().to_string();
    for part in ["out.vtu", "cell field 'stress'", "NaN", "cell 2, component 1"] {
        assert!(e.contains(part), "{part:?} not in: {e}");
    }

    let mut inf = pd.clone();
    inf[0].values[0] = f64::INFINITY;
    let e = write_vtu(&path, &mesh, &inf, &cd).unwrap_err().to_string();
    assert!(e.contains("'displacement'") && e.contains("inf"), "{e}");

    let dup = vec![pd[1].clone(), pd[1].clone()];
    let e = write_vtu(&path, &mesh, &dup, &[]).unwrap_err().to_string();
    assert!(e.contains("two point fields are named 'w'"), "{e}");

    let zero = vec![Field::new("nothing", 0, vec![])];
    let e = write_vtu(&path, &mesh, &[], &zero).unwrap_err().to_string();
    assert!(e.contains("'nothing'") && e.contains("0 components"), "{e}");

    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(dir_listing(&dir), vec!["out.vtu"]);
}

#[test]
fn vtu_checked_by_python_vtk() {
    if !python_with(&["vtk"], "reading the .vtu back with VTK") {
        return;
    }
    let dir = scratch("python");
    let path = dir.join("check.vtu");
    let (mesh, pd, cd) = sample();
    write_vtu(&path, &mesh, &pd, &cd).unwrap();

    let summary = |fields: &[Field], count: usize| {
        let mut m = serde_json::Map::new();
        for f in fields {
            m.insert(
                f.name.clone(),
                serde_json::json!({
                    "components": f.components,
                    "tuples": count,
                    "sum": f.values.iter().sum::<f64>(),
                    "abs_sum": f.values.iter().map(|v| v.abs()).sum::<f64>(),
                }),
            );
        }
        serde_json::Value::Object(m)
    };
    let xs: Vec<f64> = mesh.coords.iter().map(|x| x[0]).collect();
    let ys: Vec<f64> = mesh.coords.iter().map(|x| x[1]).collect();
    let min = |v: &[f64]| v.iter().cloned().fold(f64::INFINITY, f64::min);
    let max = |v: &[f64]| v.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let expected = serde_json::json!({
        "points": mesh.num_nodes(),
        "cells": mesh.num_cells(),
        "cell_types": [9],
        "bounds": [min(&xs), max(&xs), min(&ys), max(&ys), 0.0, 0.0],
        "points_sum": xs.iter().chain(&ys).sum::<f64>(),
        "connectivity_sum": mesh.cells.iter().flatten().sum::<usize>(),
        "point_arrays": summary(&pd, mesh.num_nodes()),
        "cell_arrays": summary(&cd, mesh.num_cells()),
    });
    let want = dir.join("expected.json");
    std::fs::write(&want, serde_json::to_string_pretty(&expected).unwrap()).unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/check_vtu.py");
    let out = Command::new("python3").arg(&script).arg(&path).arg(&want).output().unwrap();
    assert!(
        out.status.success(),
        "check_vtu.py failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    // The script's own summary must name exactly our arrays.
    let got: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names = |v: &serde_json::Value| v.as_object().unwrap().keys().cloned().collect::<Vec<_>>();
    assert_eq!(names(&got["point_arrays"]), vec!["displacement", "w"]);
    assert_eq!(names(&got["cell_arrays"]), vec!["stress", "thickness"]);
}

#[test]
fn pvd_lists_the_files_in_order() {
    let dir = scratch("pvd");
    let path = dir.join("run.pvd");
    let entries = vec![
        (0.0, "run_0000.vtu".to_string()),
        (0.25, "run_0001.vtu".to_string()),
        (0.5, "steps/run_0002.vtu".to_string()),
        (1.0, "run & <3>.vtu".to_string()),
    ];
    write_pvd(&path, &entries).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.starts_with("<?xml"));
    assert!(text.contains("type=\"Collection\""));
    let mut found = Vec::new();
    for line in text.lines().filter(|l| l.contains("<DataSet")) {
        let attr = |name: &str| {
            let start = line.find(&format!("{name}=\"")).unwrap() + name.len() + 2;
            let end = start + line[start..].find('"').unwrap();
            line[start..end].to_string()
        };
        found.push((attr("timestep").parse::<f64>().unwrap(), attr("file")));
    }
    let expected: Vec<(f64, String)> =
        entries.iter().map(|(t, f)| (*t, f.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;"))).collect();
    assert_eq!(found, expected);
    assert_eq!(dir_listing(&dir), vec!["run.pvd"]);

    // A non-finite time is refused and leaves the old file.
    let e = write_pvd(&path, &[(f64::NAN, "x.vtu".into())]).unwrap_err().to_string();
    assert!(e.contains("run.pvd") && e.contains("x.vtu"), "{e}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
}

#[test]
fn pvd_is_valid_xml_for_python() {
    // Parse with Python's XML parser when python3 is there (no VTK needed).
    let dir = scratch("pvdxml");
    let path = dir.join("a.pvd");
    write_pvd(&path, &[(0.5, "a \"quoted\" & odd.vtu".into()), (1.0, "b.vtu".into())]).unwrap();
    let code = "import sys, xml.etree.ElementTree as E\n\
                r = E.parse(sys.argv[1]).getroot()\n\
                print('|'.join(d.get('timestep') + '=' + d.get('file') for d in r.iter('DataSet')))";
    if !python_with(&[], "parsing the .pvd with Python's XML parser") {
        return;
    }
    let out = Command::new("python3").args(["-c", code]).arg(&path).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "0.5=a \"quoted\" & odd.vtu|1=b.vtu");
}

#[test]
fn atomic_write_creates_replaces_and_leaves_no_temp_file() {
    let dir = scratch("atomic");
    let path = dir.join("out.txt");
    write_string_atomically(&path, "first").unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "first");
    write_atomically(&path, |w| {
        w.write_all(b"second ")?;
        write!(w, "{}", 2)
    })
    .unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "second 2");
    assert_eq!(dir_listing(&dir), vec!["out.txt"]);
}

#[test]
fn failed_atomic_write_keeps_the_old_file() {
    let dir = scratch("atomicfail");
    let path = dir.join("out.txt");
    write_string_atomically(&path, "old content").unwrap();
    let e = write_atomically(&path, |w| {
        w.write_all(&vec![b'x'; 100_000])?;
        Err(std::io::Error::other("solver blew up"))
    })
    .unwrap_err()
    .to_string();
    assert!(e.contains("out.txt") && e.contains("solver blew up"), "{e}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "old content");
    assert_eq!(dir_listing(&dir), vec!["out.txt"]);

    // A panic in the closure also removes the temporary file.
    let p2 = path.clone();
    let r = std::panic::catch_unwind(move || {
        let _ = write_atomically(&p2, |w| {
            w.write_all(b"partial")?;
            panic!("bug in the writer");
        });
    });
    assert!(r.is_err());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "old content");
    assert_eq!(dir_listing(&dir), vec!["out.txt"]);

    // A failed write of a new file leaves nothing.
    let fresh = dir.join("new.txt");
    assert!(write_atomically(&fresh, |_| Err(std::io::Error::other("no"))).is_err());
    assert_eq!(dir_listing(&dir), vec!["out.txt"]);
}

#[test]
fn atomic_write_into_a_missing_directory_names_the_path() {
    let dir = scratch("nodir");
    let path = dir.join("missing").join("out.vtu");
    let e = write_string_atomically(&path, "x").unwrap_err().to_string();
    assert!(e.contains("missing/out.vtu"), "{e}");
    let mesh = QuadMesh::rectangle(0.0, 1.0, 0.0, 1.0, 1, 1).unwrap();
    let e = write_vtu(&path, &mesh, &[], &[]).unwrap_err().to_string();
    assert!(e.contains("missing/out.vtu"), "{e}");
}

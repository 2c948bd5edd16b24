//! Output for ParaView: one XML unstructured grid (`.vtu`) per result, and a `.pvd` collection that
//! lists them with their time (the load factor).
//!
//! The `.vtu` files are written with vtkio as inline binary, zlib-compressed (read by VTK 9.x /
//! ParaView and meshio). Points are (x1, x2, 0), cells VTK_QUAD (type 9). Every file is written
//! atomically (see [`crate::io::atomic`]).

use crate::error::{Result, StampError};
use crate::io::atomic::{write_atomically, write_string_atomically};
use crate::mesh::QuadMesh;
use std::collections::BTreeSet;
use std::path::Path;
use vtkio::model::{
    Attribute, Attributes, ByteOrder, CellType, Cells, DataArray, DataSet, ElementType, IOBuffer,
    UnstructuredGridPiece, Version, VertexNumbers, Vtk,
};

/// zlib level of the `.vtu` data arrays (fast, and still about 3-5x smaller than raw base64).
const ZLIB_LEVEL: u32 = 5;

/// A named array of values at the nodes (point data) or cells (cell data).
#[derive(Debug, Clone, PartialEq)]
pub struct Field {
    /// Array name shown in ParaView.
    pub name: String,
    /// Number of components per node or cell (1 scalar, 3 vector, ...). ParaView's "Warp By
    /// Vector" wants 3 components: write in-plane vectors as (v1, v2, 0) or with a w component.
    pub components: usize,
    /// Values, node-major (cell-major): all components of node 0, then node 1, ...
    pub values: Vec<f64>,
}

impl Field {
    /// A field of `components` values per node or cell.
    pub fn new(name: impl Into<String>, components: usize, values: Vec<f64>) -> Self {
        Field { name: name.into(), components, values }
    }

    /// A scalar field.
    pub fn scalar(name: impl Into<String>, values: Vec<f64>) -> Self {
        Field::new(name, 1, values)
    }
}

fn check_fields(path: &Path, kind: &str, count: usize, fields: &[Field]) -> Result<()> {
    let file = path.display().to_string();
    let mut names = BTreeSet::new();
    for f in fields {
        if f.name.trim().is_empty() || f.name.chars().any(|c| c.is_control()) {
            return Err(StampError::Input {
                file,
                message: format!("{kind} field name {:?} is empty or has control characters", f.name),
            });
        }
        if !names.insert(f.name.as_str()) {
            return Err(StampError::Input { file, message: format!("two {kind} fields are named '{}'", f.name) });
        }
        if f.components == 0 {
            return Err(StampError::Input { file, message: format!("{kind} field '{}' has 0 components", f.name) });
        }
        let expected = f.components.checked_mul(count);
        if expected != Some(f.values.len()) {
            return Err(StampError::Input {
                file,
                message: format!(
                    "{kind} field '{}' has {} values; {} components x {count} {}s needs {}",
                    f.name,
                    f.values.len(),
                    f.components,
                    if kind == "point" { "node" } else { "cell" },
                    expected.map(|e| e.to_string()).unwrap_or_else(|| "too many".into())
                ),
            });
        }
        if let Some(i) = f.values.iter().position(|v| !v.is_finite()) {
            return Err(StampError::NonFinite(format!(
                "{file}: {kind} field '{}' has the value {} at {} {}, component {}",
                f.name,
                f.values[i],
                if kind == "point" { "node" } else { "cell" },
                i / f.components,
                i % f.components
            )));
        }
    }
    Ok(())
}

fn attributes(fields: &[Field]) -> Vec<Attribute> {
    fields
        .iter()
        .map(|f| {
            Attribute::DataArray(DataArray {
                name: f.name.clone(),
                elem: ElementType::Generic(f.components as u32),
                data: IOBuffer::F64(f.values.clone()),
            })
        })
        .collect()
}

/// Writes the mesh and its fields as an XML unstructured grid (`.vtu`), atomically.
///
/// `point_data` fields have `components * num_nodes` values, `cell_data` fields
/// `components * num_cells`; every value must be finite and names unique within each list. Errors
/// name the file and the field.
pub fn write_vtu(path: &Path, mesh: &QuadMesh, point_data: &[Field], cell_data: &[Field]) -> Result<()> {
    let file = path.display().to_string();
    let n = mesh.num_nodes();
    if let Some((c, cell)) = mesh.cells.iter().enumerate().find(|(_, cell)| cell.iter().any(|&k| k >= n)) {
        return Err(StampError::Mesh(format!("{file}: cell {c} refers to node {cell:?}, but the mesh has {n} nodes")));
    }
    if let Some(i) = mesh.coords.iter().position(|x| !x[0].is_finite() || !x[1].is_finite()) {
        return Err(StampError::NonFinite(format!("{file}: node {i} has coordinates {:?}", mesh.coords[i])));
    }
    check_fields(path, "point", n, point_data)?;
    check_fields(path, "cell", mesh.num_cells(), cell_data)?;

    let points: Vec<f64> = mesh.coords.iter().flat_map(|x| [x[0], x[1], 0.0]).collect();
    let connectivity: Vec<u64> = mesh.cells.iter().flat_map(|c| c.iter().map(|&k| k as u64)).collect();
    let offsets: Vec<u64> = (1..=mesh.num_cells() as u64).map(|k| 4 * k).collect();
    let vtk = Vtk {
        version: Version::new_xml(1, 0),
        title: String::new(),
        byte_order: ByteOrder::LittleEndian,
        file_path: None,
        data: DataSet::inline(UnstructuredGridPiece {
            points: IOBuffer::F64(points),
            cells: Cells {
                cell_verts: VertexNumbers::XML { connectivity, offsets },
                types: vec![CellType::Quad; mesh.num_cells()],
            },
            data: Attributes { point: attributes(point_data), cell: attributes(cell_data) },
        }),
    };
    let xml = vtk
        .try_into_xml_format(vtkio::xml::Compressor::ZLib, ZLIB_LEVEL)
        .map_err(|e| StampError::Input { file: file.clone(), message: format!("cannot encode the VTK file: {e}") })?;
    write_atomically(path, |w| xml.write(w).map_err(|e| std::io::Error::other(e.to_string())))
}

fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

/// Writes a ParaView collection (`.pvd`) listing `entries` = (time, file) in the given order,
/// atomically. The time is the load factor; the file names are relative to the `.pvd`'s directory.
/// ParaView orders the data sets by time, so times should increase (with arc-length control the
/// load factor may not: write the step number as the time then).
pub fn write_pvd(path: &Path, entries: &[(f64, String)]) -> Result<()> {
    let file = path.display().to_string();
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n",
    );
    for (k, (t, name)) in entries.iter().enumerate() {
        if !t.is_finite() {
            return Err(StampError::NonFinite(format!("{file}: entry {k} ('{name}') has the time {t}")));
        }
        if name.trim().is_empty() || name.chars().any(|c| c.is_control()) {
            return Err(StampError::Input {
                file,
                message: format!("entry {k} has the file name {name:?} (empty or with control characters)"),
            });
        }
        // Shortest text that reads back to the same double; exponent form for extreme magnitudes.
        let time = if *t == 0.0 || (1e-4..1e15).contains(&t.abs()) { format!("{t}") } else { format!("{t:e}") };
        s.push_str(&format!(
            "    <DataSet timestep=\"{time}\" group=\"\" part=\"0\" file=\"{}\"/>\n",
            xml_escape(name)
        ));
    }
    s.push_str("  </Collection>\n</VTKFile>\n");
    write_string_atomically(path, &s)
}

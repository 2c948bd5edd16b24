//! A mesh given as arrays (nodes, cells of 3 or 4 node indices, groups by node, segment or cell
//! indices), put together by the code that reads a gmsh file, so that it is cut, oriented, checked
//! and grouped exactly as the same mesh read from a .msh: the arrays become the sections of a file
//! (node tag = row + 1, element tag = cell row + 1) and go through the same conversion.
//!
//! A cell in several surface groups lies on one entity that carries all of their physical tags (as
//! gmsh writes it); node and segment groups get an entity each.

use super::elements::{LINE2, POINT, QUAD4, TRI3};
use super::sections::{input_err, ElementBlock, RawMsh};
use super::{convert, GmshMesh, PhysicalName};
use crate::error::{Result, StampError};
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

/// The members of a group given as indices (0-based rows of the node and cell arrays).
#[derive(Debug, Clone, PartialEq)]
pub enum GroupItems {
    /// A point group: these nodes.
    Nodes(Vec<usize>),
    /// A curve group: 2-node segments (their direction orders the curve, as a gmsh line's does).
    Segments(Vec<[usize; 2]>),
    /// A surface group: these cells.
    Cells(Vec<usize>),
}

/// A named group of an array mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct ArrayGroup {
    pub name: String,
    pub items: GroupItems,
}

/// The mesh of `nodes` (x1, x2), `cells` (rows of 3 node indices, triangles, or 4, quadrilaterals,
/// counter-clockwise or all clockwise) and `groups`, as [`super::parse_msh_bytes`] would give it
/// for the same mesh written as a gmsh file. Errors are [`StampError::Input`] naming `label` and
/// the array and row concerned; those of the conversion name node and element tags, which are the
/// rows plus one (a note at the end says so).
pub fn mesh_from_arrays(label: &Path, nodes: &[[f64; 2]], cells: &[Vec<usize>], groups: &[ArrayGroup]) -> Result<GmshMesh> {
    let err = |m: String| input_err(label, m);
    let n = nodes.len();
    let node_index = |what: &str, row: usize, i: usize| -> Result<u64> {
        if i < n {
            Ok(i as u64 + 1)
        } else {
            Err(err(format!("{what} row {row}: node index {i} is out of range (mesh.nodes has {n} rows; indices are 0-based)")))
        }
    };
    if cells.is_empty() {
        return Err(err("mesh.cells: no cells (give an (m, 3) or (m, 4) array of node indices)".into()));
    }
    let mut raw = RawMsh { has_nodes: true, has_elements: true, ..Default::default() };
    raw.node_tags = (1..=n as u64).collect();
    raw.node_coords = nodes.iter().map(|x| [x[0], x[1], 0.0]).collect();

    // the surface groups of each cell
    let mut cell_groups: Vec<Vec<i32>> = vec![Vec::new(); cells.len()];
    let mut entities: HashMap<(usize, i32), Vec<i32>> = HashMap::new();
    for (g, group) in groups.iter().enumerate() {
        let tag = g as i32 + 1;
        if group.name.is_empty() {
            return Err(err("mesh.groups: a group has an empty name".into()));
        }
        // "#<tag>" is the key of a gmsh group by number, which the arrays' groups do not keep (the
        // numbers would only repeat the names) and which outputs leave out as unnamed
        if group.name.starts_with('#') {
            return Err(err(format!("mesh.groups.{}: a group's name cannot start with '#' (\"#<number>\" names a gmsh group by its number; a mesh given as arrays has named groups only)", group.name)));
        }
        raw.physical_names.push(PhysicalName { dim: dim_of(&group.items), tag, name: group.name.clone() });
        if let GroupItems::Cells(list) = &group.items {
            for (row, &c) in list.iter().enumerate() {
                let Some(of) = cell_groups.get_mut(c) else {
                    return Err(err(format!("mesh.groups.{}.cells row {row}: cell index {c} is out of range (mesh.cells has {} rows; indices are 0-based)", group.name, cells.len())));
                };
                if !of.contains(&tag) {
                    of.push(tag);
                }
            }
        }
    }
    // cells: one entity per set of surface groups, one block per entity and type
    let mut entity_of: BTreeMap<Vec<i32>, i32> = BTreeMap::new();
    let mut blocks: BTreeMap<(i32, i32), ElementBlock> = BTreeMap::new();
    for (row, cell) in cells.iter().enumerate() {
        let ty = match cell.len() {
            3 => TRI3,
            4 => QUAD4,
            k => return Err(err(format!("mesh.cells row {row}: a cell has 3 or 4 nodes, got {k}"))),
        };
        let next = entity_of.len() as i32 + 1;
        let entity = *entity_of.entry(cell_groups[row].clone()).or_insert(next);
        let block = blocks.entry((entity, ty)).or_insert_with(|| ElementBlock {
            entity_dim: 2,
            entity_tag: entity,
            element_type: ty,
            nodes_per_element: cell.len(),
            tags: Vec::new(),
            nodes: Vec::new(),
        });
        block.tags.push(row as u64 + 1);
        for &i in cell {
            block.nodes.push(node_index("mesh.cells", row, i)?);
        }
    }
    for (phys, entity) in &entity_of {
        entities.insert((2, *entity), phys.clone());
    }
    raw.element_blocks = blocks.into_values().collect();
    // node and segment groups: an entity each, elements tagged after the cells
    let mut next_tag = cells.len() as u64;
    for (g, group) in groups.iter().enumerate() {
        let tag = g as i32 + 1;
        let key = format!("mesh.groups.{}", group.name);
        let (dim, ty, per, list): (usize, i32, usize, Vec<u64>) = match &group.items {
            GroupItems::Cells(_) => continue,
            GroupItems::Nodes(v) => (0, POINT, 1, v.iter().enumerate().map(|(r, &i)| node_index(&format!("{key}.nodes"), r, i)).collect::<Result<_>>()?),
            GroupItems::Segments(v) => {
                let mut list = Vec::with_capacity(2 * v.len());
                for (r, s) in v.iter().enumerate() {
                    if s[0] == s[1] {
                        return Err(err(format!("{key}.segments row {r}: a segment joins two different nodes, got [{}, {}]", s[0], s[1])));
                    }
                    list.push(node_index(&format!("{key}.segments"), r, s[0])?);
                    list.push(node_index(&format!("{key}.segments"), r, s[1])?);
                }
                (1, LINE2, 2, list)
            }
        };
        let count = (list.len() / per) as u64;
        entities.insert((dim, tag), vec![tag]);
        raw.element_blocks.push(ElementBlock {
            entity_dim: dim as i32,
            entity_tag: tag,
            element_type: ty,
            nodes_per_element: per,
            tags: (next_tag + 1..=next_tag + count).collect(),
            nodes: list,
        });
        next_tag += count;
    }
    raw.entities = Some(entities);
    let mut mesh = convert(label, raw).map_err(|e| match e {
        StampError::Input { file, message } => StampError::Input {
            file,
            message: format!("{message} (the mesh given as arrays: node N is row N-1 of mesh.nodes, element N is row N-1 of mesh.cells)"),
        },
        e => e,
    })?;
    // every group has a name: the numbered keys ("#1") would only repeat them
    mesh.point_groups.retain(|k, _| !k.starts_with('#'));
    mesh.curve_groups.retain(|k, _| !k.starts_with('#'));
    mesh.mesh.cell_groups.retain(|k, _| !k.starts_with('#'));
    mesh.mesh.node_groups.retain(|k, _| !k.starts_with('#'));
    Ok(mesh)
}

fn dim_of(items: &GroupItems) -> usize {
    match items {
        GroupItems::Nodes(_) => 0,
        GroupItems::Segments(_) => 1,
        GroupItems::Cells(_) => 2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit square as two quadrilaterals, or as four triangles around its centre.
    fn square() -> Vec<[f64; 2]> {
        vec![[0.0, 0.0], [0.5, 0.0], [1.0, 0.0], [0.0, 1.0], [0.5, 1.0], [1.0, 1.0]]
    }

    #[test]
    fn quadrilaterals_keep_their_rows_and_groups_their_members() {
        let cells = vec![vec![0, 1, 4, 3], vec![1, 2, 5, 4]];
        let groups = vec![
            ArrayGroup { name: "left".into(), items: GroupItems::Nodes(vec![0, 3]) },
            ArrayGroup { name: "bottom".into(), items: GroupItems::Segments(vec![[0, 1], [1, 2]]) },
            ArrayGroup { name: "plate".into(), items: GroupItems::Cells(vec![0, 1]) },
            ArrayGroup { name: "right_half".into(), items: GroupItems::Cells(vec![1]) },
        ];
        let m = mesh_from_arrays(Path::new("mesh"), &square(), &cells, &groups).unwrap();
        assert_eq!(m.mesh.coords, square());
        assert_eq!(m.mesh.cells, vec![[0, 1, 4, 3], [1, 2, 5, 4]]);
        assert_eq!(m.point_groups["left"], vec![0, 3]);
        assert_eq!(m.curve_groups["bottom"], vec![[0, 1], [1, 2]]);
        assert_eq!(m.mesh.cell_groups["plate"], vec![0, 1]);
        assert_eq!(m.mesh.cell_groups["right_half"], vec![1]);
        assert_eq!(m.mesh.node_groups["right_half"], vec![1, 2, 4, 5]);
        assert!(m.split_summary().is_none());
        assert!(m.point_groups.keys().chain(m.mesh.node_groups.keys()).all(|k| !k.starts_with('#')));
    }

    #[test]
    fn a_group_named_like_a_gmsh_number_is_refused() {
        let cells = vec![vec![0, 1, 4, 3], vec![1, 2, 5, 4]];
        let groups = vec![ArrayGroup { name: "#1".into(), items: GroupItems::Nodes(vec![0]) }];
        let e = mesh_from_arrays(Path::new("mesh"), &square(), &cells, &groups).unwrap_err().to_string();
        assert!(e.contains("mesh.groups.#1: a group's name cannot start with '#'"), "{e}");
    }

    #[test]
    fn triangles_are_cut_as_the_reader_cuts_them() {
        let nodes = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let cells = vec![vec![0, 1, 2], vec![0, 2, 3]];
        let groups = vec![ArrayGroup { name: "bottom".into(), items: GroupItems::Segments(vec![[0, 1]]) }];
        let m = mesh_from_arrays(Path::new("mesh"), &nodes, &cells, &groups).unwrap();
        // three quadrilaterals per triangle; 5 edge midpoints and 2 centroids added after the nodes
        assert_eq!((m.mesh.num_cells(), m.mesh.num_nodes()), (6, 11));
        assert_eq!(&m.mesh.coords[..4], &nodes[..]);
        assert_eq!(m.cell_tags, vec![1, 1, 1, 2, 2, 2]);
        // the boundary segment is cut at its midpoint
        let bottom = &m.curve_groups["bottom"];
        assert_eq!(bottom.len(), 2);
        assert_eq!(m.mesh.coords[bottom[0][1]], [0.5, 0.0]);
        assert!(m.split_summary().unwrap().contains("2 3-node triangles split into 6 quadrilaterals"));
        let area: f64 = (0..6).map(|c| crate::mesh::quad_signed_area(&m.mesh.cell_coords(c))).sum();
        assert!((area - 1.0).abs() < 1e-14);
    }

    #[test]
    fn bad_indices_and_bad_cells_are_named() {
        let e = |cells: Vec<Vec<usize>>, groups: Vec<ArrayGroup>| mesh_from_arrays(Path::new("mesh"), &square(), &cells, &groups).unwrap_err().to_string();
        assert!(e(vec![vec![0, 1, 4, 9]], vec![]).contains("mesh.cells row 0: node index 9 is out of range (mesh.nodes has 6 rows"));
        assert!(e(vec![vec![0, 1]], vec![]).contains("mesh.cells row 0: a cell has 3 or 4 nodes, got 2"));
        let g = vec![ArrayGroup { name: "p".into(), items: GroupItems::Cells(vec![5]) }];
        assert!(e(vec![vec![0, 1, 4, 3]], g).contains("mesh.groups.p.cells row 0: cell index 5 is out of range"));
        let g = vec![ArrayGroup { name: "s".into(), items: GroupItems::Segments(vec![[0, 1], [2, 2]]) }];
        assert!(e(vec![vec![0, 1, 4, 3]], g).contains("mesh.groups.s.segments row 1: a segment joins two different nodes"));
        // a cell listed clockwise among counter-clockwise ones: the reader's message, with the rows
        let m = e(vec![vec![0, 1, 4, 3], vec![1, 4, 5, 2], vec![0, 1, 4, 3]], vec![]);
        assert!(m.contains("inverted") && m.contains("element N is row N-1 of mesh.cells"), "{m}");
    }
}

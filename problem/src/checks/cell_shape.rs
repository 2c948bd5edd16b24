//! A warning for cells of extreme aspect ratio: Newton converges poorly on a mesh whose cells are
//! thousands of times longer than wide (a 20 x 1e6 rectangle of 20 x 20 cells crawled on in
//! increments of 1e-4 of the load), so `stamp check` and `stamp run` say so before the solve.

use crate::model::mesh::MeshData;
use crate::model::mesh::where_node;
use crate::schema::Problem;

/// Aspect ratios above this are warned about.
pub const MAX_ASPECT_RATIO: f64 = 1000.0;

/// The aspect ratio of the quadrilateral `nodes`: its longest edge squared over its area (a/b for
/// an a x b rectangle, a >= b; the longest edge over the height onto it, for a triangle with a
/// repeated node, twice that). Infinite for a cell without area.
pub fn aspect_ratio(coords: &[[f64; 2]], nodes: &[usize; 4]) -> f64 {
    let p = nodes.map(|n| coords[n]);
    let longest = (0..4).map(|k| {
        let (a, b) = (p[k], p[(k + 1) % 4]);
        (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)
    });
    let longest = longest.fold(0.0, f64::max);
    // shoelace
    let area = 0.5 * (0..4).map(|k| p[k][0] * p[(k + 1) % 4][1] - p[(k + 1) % 4][0] * p[k][1]).sum::<f64>().abs();
    if area > 0.0 {
        longest / area
    } else {
        f64::INFINITY
    }
}

/// The warning for the cells of `mesh` whose aspect ratio exceeds [`MAX_ASPECT_RATIO`], if any.
pub fn aspect_warning(p: &Problem, mesh: &MeshData) -> Option<String> {
    let m = &mesh.mesh;
    let ratios: Vec<f64> = m.cells.iter().map(|c| aspect_ratio(&m.coords, c)).collect();
    let over = ratios.iter().filter(|&&r| r > MAX_ASPECT_RATIO).count();
    let (worst, cell) = ratios.iter().enumerate().fold((0.0, 0), |(w, i), (k, &r)| if r > w { (r, k) } else { (w, i) });
    if over == 0 {
        return None;
    }
    let key = if p.spec.mesh.get_ref().file.is_some() { "mesh.file" } else { "mesh.rectangle" };
    Some(format!(
        "{}: {key}: {over} of {} cells have an aspect ratio above {MAX_ASPECT_RATIO} (the worst {worst:.3e}, the cell at {}): Newton converges poorly on such cells and the load path may crawl \
         until [solver] max_steps stops it; mesh the plate with cells closer to square",
        p.path.display(),
        m.num_cells(),
        where_node(mesh, m.cells[cell][0]).trim_start_matches("the node at ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_aspect_ratio_of_a_rectangle_is_its_sides_ratio() {
        let coords = [[0.0, 0.0], [1.0, 0.0], [1.0, 50_000.0], [0.0, 50_000.0], [0.5, 0.5]];
        assert!((aspect_ratio(&coords, &[0, 1, 2, 3]) - 50_000.0).abs() < 1e-6);
        let square = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]];
        assert!((aspect_ratio(&square, &[0, 1, 2, 3]) - 1.0).abs() < 1e-12);
        // a right triangle (a repeated node): longest edge^2 / area = 2 / 0.5
        let tri = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        assert!((aspect_ratio(&tri, &[0, 1, 2, 2]) - 4.0).abs() < 1e-12);
        assert!(aspect_ratio(&coords, &[0, 0, 0, 0]).is_infinite());
    }
}

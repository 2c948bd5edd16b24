//! A rigid die given as a triangulated surface (closed or open), with a smooth signed distance.
//!
//! Psi(x) = (x - p) . n(p), p the closest point of the surface to x and n(p) the normal
//! interpolated linearly (barycentric weights) between the facet's vertex normals, normalised
//! (Phong normals; vertex normals weighted by the facets' angles at the vertex). Psi is positive on
//! the side the facet normals point to. Because neighbouring facets share vertex normals, n(p) is
//! continuous across facet edges and so are Psi and its gradient, which is taken as n(p) (exact
//! for a flat region, and the normal of the smooth surface the facets approximate otherwise).
//!
//! The Hessian is the derivative of that gradient: dn/dx = (I - n n^T)/|m| sum_i n_i (grad b_i)^T J,
//! m = sum_i b_i n_i, b_i the barycentric weights, J = dp/dx (the projector on the facet's plane
//! when p is inside a facet, t t^T on an edge of tangent t, 0 at a vertex), symmetrised. On a
//! triangulated sphere of radius R it tends to (I - n n^T)/R, the curvature the analytic sphere's
//! normalised distance has on its surface.
//!
//! The closest facet is found with an R*-tree (crate `rstar`) built once over the facets' boxes:
//! a query costs O(log N).

use super::reader::{read_stl, TriangleMesh, DEFAULT_MAX_FACETS};
use nalgebra::{Matrix3, Vector3};
use rstar::{PointDistance, RTree, RTreeObject, AABB};
use stamp::surface::ContactSurface;
use stamp::{Result, StampError};
use std::path::Path;

/// One facet in the search tree: its index and corners.
#[derive(Debug, Clone)]
struct Facet {
    index: u32,
    corners: [[f64; 3]; 3],
    /// The corners' bounding box, kept: the search asks for it at every facet it meets.
    bounds: AABB<[f64; 3]>,
}

impl Facet {
    fn new(index: u32, corners: [[f64; 3]; 3]) -> Self {
        let [a, b, c] = corners;
        let lo = [0, 1, 2].map(|i| a[i].min(b[i]).min(c[i]));
        let hi = [0, 1, 2].map(|i| a[i].max(b[i]).max(c[i]));
        Facet { index, corners, bounds: AABB::from_corners(lo, hi) }
    }
}

impl RTreeObject for Facet {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        self.bounds
    }
}

impl PointDistance for Facet {
    fn distance_2(&self, point: &[f64; 3]) -> f64 {
        let [a, b, c] = self.corners.map(Vector3::from);
        let q = closest_on_triangle(&Vector3::from(*point), &a, &b, &c);
        (q.point - Vector3::from(*point)).norm_squared()
    }

    /// The facet's box first (a few comparisons): most facets the search meets are farther than
    /// the best so far, and the exact distance is only computed for the others.
    fn distance_2_if_less_or_equal(&self, point: &[f64; 3], max_distance_2: f64) -> Option<f64> {
        if self.bounds.distance_2(point) > max_distance_2 {
            return None;
        }
        let d = self.distance_2(point);
        (d <= max_distance_2).then_some(d)
    }
}

/// Where on a facet the closest point lies.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Region {
    Inside,
    /// On the edge from corner `i` to corner `j`.
    Edge(usize, usize),
    Vertex,
}

#[derive(Debug, Clone, Copy)]
struct Closest {
    point: Vector3<f64>,
    /// Barycentric weights of the corners.
    bary: [f64; 3],
    region: Region,
}

/// The closest point of triangle (a, b, c) to x (Ericson, Real-Time Collision Detection, 5.1.5).
fn closest_on_triangle(x: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>, c: &Vector3<f64>) -> Closest {
    let ab = b - a;
    let ac = c - a;
    let ap = x - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return Closest { point: *a, bary: [1.0, 0.0, 0.0], region: Region::Vertex };
    }
    let bp = x - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    if d3 >= 0.0 && d4 <= d3 {
        return Closest { point: *b, bary: [0.0, 1.0, 0.0], region: Region::Vertex };
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return Closest { point: a + ab * v, bary: [1.0 - v, v, 0.0], region: Region::Edge(0, 1) };
    }
    let cp = x - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    if d6 >= 0.0 && d5 <= d6 {
        return Closest { point: *c, bary: [0.0, 0.0, 1.0], region: Region::Vertex };
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return Closest { point: a + ac * w, bary: [1.0 - w, 0.0, w], region: Region::Edge(0, 2) };
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return Closest { point: b + (c - b) * w, bary: [0.0, 1.0 - w, w], region: Region::Edge(1, 2) };
    }
    let denom = 1.0 / (va + vb + vc);
    let v = vb * denom;
    let w = vc * denom;
    Closest { point: a + ab * v + ac * w, bary: [1.0 - v - w, v, w], region: Region::Inside }
}

thread_local! {
    /// This thread's last query: (surface id, x's bits) and what it found.
    static LAST_QUERY: std::cell::Cell<Option<((u64, [u64; 3]), Query)>> = const { std::cell::Cell::new(None) };
}

/// A rigid die bounded by a triangulated surface read from an STL file.
pub struct StlSurface {
    /// Unique among all surfaces made in this process: the key of the per-thread query cache
    /// (an address could be reused by a surface made after this one is dropped).
    id: u64,
    /// Squared distance up to which a hint bounds a search (beyond it the box about the point
    /// would hold too many facets and the tree's nearest-neighbour search is cheaper): four times
    /// the longest facet edge.
    hint_reach_2: f64,
    name: String,
    vertices: Vec<Vector3<f64>>,
    facets: Vec<[u32; 3]>,
    vertex_normals: Vec<Vector3<f64>>,
    tree: RTree<Facet>,
    length_scale: f64,
    lo: Vector3<f64>,
    hi: Vector3<f64>,
}

/// What a query finds: the closest point, its facet, and the interpolated normal.
#[derive(Clone, Copy)]
struct Query {
    closest: Closest,
    facet: usize,
    /// m = sum_i b_i n_i (not normalised).
    m: Vector3<f64>,
}

impl StlSurface {
    /// Reads `path` (ASCII or binary STL, at most [`DEFAULT_MAX_FACETS`] facets) and builds the
    /// surface. Errors name the file and what is wrong (with the facet number, 1-based).
    pub fn from_file(path: &Path) -> Result<Self> {
        Self::from_file_with_limit(path, DEFAULT_MAX_FACETS)
    }

    /// [`from_file`](Self::from_file) with another facet limit.
    pub fn from_file_with_limit(path: &Path, max_facets: usize) -> Result<Self> {
        let mesh = read_stl(path, max_facets)?;
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        Self::from_mesh(&stamp::quote(&name), mesh)
    }

    /// Builds the surface of a checked mesh (see [`read_stl`]); `name` appears in
    /// [`describe`](ContactSurface::describe).
    pub fn from_mesh(name: &str, mesh: TriangleMesh) -> Result<Self> {
        let vertices: Vec<Vector3<f64>> = mesh.vertices.iter().map(|v| Vector3::from(*v)).collect();
        if mesh.facets.is_empty() {
            return Err(StampError::Problem(format!("STL die {name}: no facets")));
        }
        // angle-weighted vertex normals (Thuermer and Wuethrich)
        let mut normals = vec![Vector3::zeros(); vertices.len()];
        for t in &mesh.facets {
            let p = t.map(|i| vertices[i as usize]);
            let n = (p[1] - p[0]).cross(&(p[2] - p[0])).normalize();
            for k in 0..3 {
                let e1 = p[(k + 1) % 3] - p[k];
                let e2 = p[(k + 2) % 3] - p[k];
                let angle = e1.cross(&e2).norm().atan2(e1.dot(&e2));
                normals[t[k] as usize] += angle * n;
            }
        }
        for n in normals.iter_mut() {
            let l = n.norm();
            if l > 0.0 {
                *n /= l;
            }
        }
        let items: Vec<Facet> = mesh
            .facets
            .iter()
            .enumerate()
            .map(|(k, t)| Facet::new(k as u32, t.map(|i| mesh.vertices[i as usize])))
            .collect();
        let tree = RTree::bulk_load(items);
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for v in &vertices {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        let length_scale = (hi - lo).norm().max(f64::MIN_POSITIVE);
        static NEXT_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let id = NEXT_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let longest_edge_2 = mesh
            .facets
            .iter()
            .flat_map(|t| {
                let v = &vertices;
                (0..3).map(move |k| (v[t[k] as usize] - v[t[(k + 1) % 3] as usize]).norm_squared())
            })
            .fold(0.0, f64::max);
        let hint_reach_2 = 16.0 * longest_edge_2;
        Ok(Self { id, hint_reach_2, name: name.to_string(), vertices, facets: mesh.facets, vertex_normals: normals, tree, length_scale, lo, hi })
    }

    /// Number of facets.
    pub fn num_facets(&self) -> usize {
        self.facets.len()
    }

    /// Number of distinct vertices.
    pub fn num_vertices(&self) -> usize {
        self.vertices.len()
    }

    /// The query at x, reusing this thread's last one when it was at the same x on this surface:
    /// the contact constraint asks for the gradient and Psi (and the Hessian) at one point in turn.
    fn query(&self, x: &Vector3<f64>) -> Query {
        let key = (self.id, [x.x.to_bits(), x.y.to_bits(), x.z.to_bits()]);
        let last = LAST_QUERY.with(|c| c.get());
        if let Some((k, q)) = last {
            if k == key {
                return q;
            }
        }
        let hint = last.filter(|((id, _), _)| *id == self.id).map(|(_, q)| q.facet);
        let q = self.search(x, hint);
        LAST_QUERY.with(|c| c.set(Some((key, q))));
        q
    }

    /// The closest point of the surface to x. `hint`, a facet close to x (the last query's: the
    /// contact points are visited in the mesh's order, neighbours after neighbours), bounds the
    /// search: every facet closer than it meets the box of half-width |x - hint| about x.
    fn search(&self, x: &Vector3<f64>, hint: Option<usize>) -> Query {
        let p = [x.x, x.y, x.z];
        let facet = |k: usize| {
            let t = self.facets[k];
            let [a, b, c] = t.map(|i| self.vertices[i as usize]);
            closest_on_triangle(x, &a, &b, &c)
        };
        let mut best = None;
        if let Some(h) = hint {
            let c = facet(h);
            let d2 = (c.point - x).norm_squared();
            if d2 <= self.hint_reach_2 {
                let r = d2.sqrt() * (1.0 + 1e-9) + 1e-12 * self.length_scale;
                let envelope = AABB::from_corners([x.x - r, x.y - r, x.z - r], [x.x + r, x.y + r, x.z + r]);
                let mut found = (h, c, d2);
                for f in self.tree.locate_in_envelope_intersecting(&envelope) {
                    let k = f.index as usize;
                    if k != found.0 && f.bounds.distance_2(&p) < found.2 {
                        let c = facet(k);
                        let d2 = (c.point - x).norm_squared();
                        if d2 < found.2 {
                            found = (k, c, d2);
                        }
                    }
                }
                best = Some((found.0, found.1));
            }
        }
        let (k, closest) = best.unwrap_or_else(|| {
            let k = self.tree.nearest_neighbor(&p).expect("the tree has facets").index as usize;
            (k, facet(k))
        });
        let t = self.facets[k];
        let m = (0..3).fold(Vector3::zeros(), |s, i| s + closest.bary[i] * self.vertex_normals[t[i] as usize]);
        Query { closest, facet: k, m }
    }

    /// The normal at the query's point (the facet's normal if the vertex normals cancel).
    fn normal(&self, q: &Query) -> Vector3<f64> {
        let l = q.m.norm();
        if l > 1e-12 {
            q.m / l
        } else {
            let t = self.facets[q.facet].map(|i| self.vertices[i as usize]);
            (t[1] - t[0]).cross(&(t[2] - t[0])).normalize()
        }
    }
}

impl ContactSurface for StlSurface {
    fn psi(&self, x: &Vector3<f64>) -> f64 {
        self.psi_and_gradient(x).0
    }

    fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64> {
        let q = self.query(x);
        self.normal(&q)
    }

    fn psi_and_gradient(&self, x: &Vector3<f64>) -> (f64, Vector3<f64>) {
        let q = self.query(x);
        let n = self.normal(&q);
        ((x - q.closest.point).dot(&n), n)
    }

    fn hessian(&self, x: &Vector3<f64>) -> Matrix3<f64> {
        let q = self.query(x);
        let l = q.m.norm();
        if l <= 1e-12 {
            return Matrix3::zeros();
        }
        let n = q.m / l;
        let t = self.facets[q.facet];
        let p = t.map(|i| self.vertices[i as usize]);
        let big_n = (p[1] - p[0]).cross(&(p[2] - p[0]));
        let nn = big_n.norm_squared();
        let nf = big_n / nn.sqrt();
        // dp/dx
        let j = match q.closest.region {
            Region::Inside => Matrix3::identity() - nf * nf.transpose(),
            Region::Edge(a, b) => {
                let e = (p[b] - p[a]).normalize();
                e * e.transpose()
            }
            Region::Vertex => return Matrix3::zeros(),
        };
        // grad b_i = N x e_i / |N|^2, e_i the edge opposite corner i (from i+1 to i+2)
        let mut dm = Matrix3::zeros();
        for i in 0..3 {
            let e = p[(i + 2) % 3] - p[(i + 1) % 3];
            let gb = big_n.cross(&e) / nn;
            dm += self.vertex_normals[t[i] as usize] * (j * gb).transpose();
        }
        let h = (Matrix3::identity() - n * n.transpose()) * dm / l;
        0.5 * (h + h.transpose())
    }

    fn length_scale(&self) -> f64 {
        self.length_scale
    }

    fn describe(&self) -> String {
        format!(
            "STL die '{}': {} facets, {} vertices, box ({:.4}, {:.4}, {:.4}) to ({:.4}, {:.4}, {:.4})",
            self.name,
            self.facets.len(),
            self.vertices.len(),
            self.lo.x,
            self.lo.y,
            self.lo.z,
            self.hi.x,
            self.hi.y,
            self.hi.z
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A wavy height field z = 0.3 sin(x) cos(y) over [-5, 5]^2, 40 x 40 squares cut in two.
    fn wavy() -> StlSurface {
        let n = 40;
        let z = |x: f64, y: f64| 0.3 * x.sin() * y.cos();
        let mut vertices = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (-5.0 + 10.0 * i as f64 / n as f64, -5.0 + 10.0 * j as f64 / n as f64);
                vertices.push([x, y, z(x, y)]);
            }
        }
        let id = |i: u32, j: u32| j * (n + 1) + i;
        let mut facets = Vec::new();
        for j in 0..n {
            for i in 0..n {
                facets.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                facets.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
        StlSurface::from_mesh("wavy", TriangleMesh { vertices, facets }).unwrap()
    }

    #[test]
    fn a_hinted_search_finds_the_closest_facet() {
        let s = wavy();
        let brute = |x: &Vector3<f64>| {
            (0..s.facets.len())
                .map(|k| {
                    let [a, b, c] = s.facets[k].map(|i| s.vertices[i as usize]);
                    (closest_on_triangle(x, &a, &b, &c).point - x).norm_squared()
                })
                .fold(f64::INFINITY, f64::min)
        };
        // a scrambled sequence of points up to 2 from the surface, some beyond its edges, with
        // hints from the last point (near or far from the new one) and from a fixed far facet
        let mut last = None;
        for k in 0..2000 {
            let f = |a: f64| (k as f64 * a).fract();
            let x = Vector3::new(-6.0 + 12.0 * f(0.6180339887), -6.0 + 12.0 * f(0.4142135623), -2.0 + 4.0 * f(0.7320508075));
            let want = brute(&x);
            for hint in [None, last, Some(0), Some(s.facets.len() - 1)] {
                let q = s.search(&x, hint);
                let got = (q.closest.point - x).norm_squared();
                assert!((got - want).abs() <= 1e-12 * want.max(1.0), "point {x:?}, hint {hint:?}: {got} against {want}");
            }
            last = Some(s.search(&x, last).facet);
            // psi and the gradient asked together are those asked one by one
            assert_eq!(s.psi_and_gradient(&x), (s.psi(&x), s.gradient(&x)));
        }
    }
}

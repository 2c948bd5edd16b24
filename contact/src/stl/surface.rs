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
}

impl RTreeObject for Facet {
    type Envelope = AABB<[f64; 3]>;
    fn envelope(&self) -> Self::Envelope {
        let [a, b, c] = self.corners;
        let lo = [0, 1, 2].map(|i| a[i].min(b[i]).min(c[i]));
        let hi = [0, 1, 2].map(|i| a[i].max(b[i]).max(c[i]));
        AABB::from_corners(lo, hi)
    }
}

impl PointDistance for Facet {
    fn distance_2(&self, point: &[f64; 3]) -> f64 {
        let [a, b, c] = self.corners.map(Vector3::from);
        let q = closest_on_triangle(&Vector3::from(*point), &a, &b, &c);
        (q.point - Vector3::from(*point)).norm_squared()
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
            .map(|(k, t)| Facet { index: k as u32, corners: t.map(|i| mesh.vertices[i as usize]) })
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
        Ok(Self { id, name: name.to_string(), vertices, facets: mesh.facets, vertex_normals: normals, tree, length_scale, lo, hi })
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
        if let Some((k, q)) = LAST_QUERY.with(|c| c.get()) {
            if k == key {
                return q;
            }
        }
        let q = self.search(x);
        LAST_QUERY.with(|c| c.set(Some((key, q))));
        q
    }

    fn search(&self, x: &Vector3<f64>) -> Query {
        let f = self.tree.nearest_neighbor(&[x.x, x.y, x.z]).expect("the tree has facets");
        let t = self.facets[f.index as usize];
        let [a, b, c] = t.map(|i| self.vertices[i as usize]);
        let closest = closest_on_triangle(x, &a, &b, &c);
        let m = (0..3).fold(Vector3::zeros(), |s, k| s + closest.bary[k] * self.vertex_normals[t[k] as usize]);
        Query { closest, facet: f.index as usize, m }
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
        let q = self.query(x);
        (x - q.closest.point).dot(&self.normal(&q))
    }

    fn gradient(&self, x: &Vector3<f64>) -> Vector3<f64> {
        let q = self.query(x);
        self.normal(&q)
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

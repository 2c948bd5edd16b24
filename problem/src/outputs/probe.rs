//! Fields along a straight line of the reference plane: `[[output.probe]]`.
//!
//! ```toml
//! [[output.probe]]
//! name = "axis"          # names the files: probe_axis_<step>.csv, probe_axis.png/.svg
//! from = [0.0, 0.0]      # reference x1, x2
//! to = [20.0, 0.0]
//! points = 200           # equally spaced points from `from` to `to` (2..=100000, default 200)
//! ```
//!
//! Each point is located in the quadrilateral that contains it (a uniform grid of cell bounding
//! boxes gives the candidates; [`inverse_bilinear`] inverts the isoparametric map by Newton) and the
//! nodal fields are interpolated with the bilinear shape functions there. The mesh nodes that lie on
//! the line are added to the equally spaced points (so curves pass through the nodal values, drawn
//! as markers); points outside the mesh are left out of the CSV and the plot. Per written step `probe_<name>_<step>.csv` has the columns
//! `distance` (from `from`), `x1`, `x2` (reference), `u1`, `u2`, `u3` (mid-surface displacement)
//! and, for each punch, `<punch>_pressure` (the contact pressure, the paper's q_n),
//! `<punch>_pressure_recovered` (the recovered pressure of the .vtu's
//! `contact_pressure_recovered`, a continuous field made from the nodal forces, smoother than
//! q_n node to node on cut triangles: [`stamp::contact::recovered_pressure`]),
//! `<punch>_integral` (the integral of the pressure along the line from `from` to the point, by
//! the trapezoidal rule over the points) and `<punch>_line_load` (the same integral of the
//! pressure averaged across a band of [`BAND_CELLS`] cell sizes centred on the line). Across a
//! roller the last row's integral is the load per unit length; where the contact is a line
//! narrower than the cells, the nodes next to the line carry it in turn and the integral along
//! one line of an unstructured mesh varies from line to line, while the band's converges (the
//! force in the band divided by its width). After those, for each punch with friction,
//! `<punch>_traction_x1`, `_x2`, `_x3`: its tangential traction (the .vtu's `<punch>_traction`). `probe_<name>.png/.svg` draws the contact pressure
//! (summed over the punches) of up to [`MAX_CURVES`] written steps spread evenly over the load
//! path, labelled by the first punch's force (force driven) or travel; markers show the points
//! that are nodes; its title gives the last step's integrals.
//!
//! With no probe, a punch and `plot = true`, a default probe named `<punch>` crosses the whole mesh
//! along x1 (or along `plot_axis` when the file gives it; "arc" means x1) through the first contact
//! point: the active node of the first written step closest to the pressure-weighted centre of its
//! active nodes, or, when nothing touches yet, the node closest to the punch.

use crate::model::mesh::MeshData;
use crate::model::plate_model::Layout;
use crate::outputs::history::{sig4, History, HistoryRow};
use crate::outputs::plot::{write_plot, Plot, Series};
use crate::schema::units::Units;
use crate::schema::{Problem, ProbeSpec};
use stamp::Result;
use stamp::contact::ContactPair;
use stamp::io::write_string_atomically;
use stamp::mesh::{bilinear, inverse_bilinear, QuadMesh};
use std::path::{Path, PathBuf};
use toml::Spanned;

/// At most this many curves in a probe plot.
pub const MAX_CURVES: usize = 8;
/// Default number of points of a probe.
pub const DEFAULT_POINTS: usize = 200;
/// The width of the band of `<punch>_line_load`, in cell sizes (the square root of the mean cell
/// area), and the number of lines across it that sample it.
pub const BAND_CELLS: f64 = 8.0;
const BAND_LINES: usize = 17;

// ---------------------------------------------------------------------------------------------
// point location

/// Tolerance on |xi| - 1 for a point to count as inside a cell (points on edges and nodes).
const INSIDE_TOL: f64 = 1e-9;

/// A uniform grid over the mesh's bounding box; each grid cell lists the mesh cells whose bounding
/// box overlaps it. About one mesh cell per grid cell, so a query tries a handful of cells.
pub struct CellLocator<'a> {
    mesh: &'a QuadMesh,
    lo: [f64; 2],
    step: [f64; 2],
    n: [usize; 2],
    bins: Vec<Vec<u32>>,
}

impl<'a> CellLocator<'a> {
    pub fn new(mesh: &'a QuadMesh) -> CellLocator<'a> {
        let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
        for c in &mesh.coords {
            for i in 0..2 {
                lo[i] = lo[i].min(c[i]);
                hi[i] = hi[i].max(c[i]);
            }
        }
        let ext = [(hi[0] - lo[0]).max(1e-300), (hi[1] - lo[1]).max(1e-300)];
        let cells = mesh.num_cells().max(1) as f64;
        // grid cells about as many as mesh cells, shaped like the box
        let aspect = ext[0] / ext[1];
        let nx = ((cells * aspect).sqrt().ceil() as usize).clamp(1, 4096);
        let ny = ((cells / aspect).sqrt().ceil() as usize).clamp(1, 4096);
        let n = [nx, ny];
        let step = [ext[0] / nx as f64, ext[1] / ny as f64];
        let mut bins = vec![Vec::new(); nx * ny];
        let mut loc = CellLocator { mesh, lo, step, n, bins: Vec::new() };
        for c in 0..mesh.num_cells() {
            let x = mesh.cell_coords(c);
            let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for q in &x {
                for i in 0..2 {
                    a[i] = a[i].min(q[i]);
                    b[i] = b[i].max(q[i]);
                }
            }
            let (i0, j0) = loc.bin(a);
            let (i1, j1) = loc.bin(b);
            for j in j0..=j1 {
                for i in i0..=i1 {
                    bins[j * nx + i].push(c as u32);
                }
            }
        }
        loc.bins = bins;
        loc
    }

    /// The grid cell of `p`, clamped to the grid.
    fn bin(&self, p: [f64; 2]) -> (usize, usize) {
        let f = |i: usize| (((p[i] - self.lo[i]) / self.step[i]).floor().max(0.0) as usize).min(self.n[i] - 1);
        (f(0), f(1))
    }

    /// Every cell that holds `p` (one inside a cell, two on an edge, all of a node's cells at a
    /// node) with the local coordinates there; empty outside the mesh.
    pub fn locate_all(&self, p: [f64; 2]) -> Vec<(usize, [f64; 2])> {
        if self.locate(p).is_none() {
            return Vec::new();
        }
        let (i, j) = self.bin(p);
        self.bins[j * self.n[0] + i]
            .iter()
            .filter_map(|&c| {
                let c = c as usize;
                let xi = inverse_bilinear(&self.mesh.cell_coords(c), p)?;
                (xi[0].abs().max(xi[1].abs()) - 1.0 <= INSIDE_TOL).then_some((c, xi))
            })
            .collect()
    }

    /// The cell containing `p` and the local coordinates there; None outside the mesh.
    pub fn locate(&self, p: [f64; 2]) -> Option<(usize, [f64; 2])> {
        let tol = 1e-9 * (self.step[0] + self.step[1]);
        if p[0] < self.lo[0] - tol || p[1] < self.lo[1] - tol || p[0] > self.lo[0] + self.step[0] * self.n[0] as f64 + tol || p[1] > self.lo[1] + self.step[1] * self.n[1] as f64 + tol {
            return None;
        }
        let (i, j) = self.bin(p);
        let mut best: Option<(usize, [f64; 2], f64)> = None;
        for &c in &self.bins[j * self.n[0] + i] {
            let c = c as usize;
            if let Some(xi) = inverse_bilinear(&self.mesh.cell_coords(c), p) {
                let out = xi[0].abs().max(xi[1].abs()) - 1.0;
                if out <= INSIDE_TOL && best.as_ref().is_none_or(|b| out < b.2) {
                    best = Some((c, xi, out));
                }
            }
        }
        best.map(|b| (b.0, b.1))
    }
}

// ---------------------------------------------------------------------------------------------
// probes

/// A probe point inside the mesh.
#[derive(Debug, Clone, PartialEq)]
pub struct Sample {
    /// Distance from the start of the line.
    pub distance: f64,
    pub x: [f64; 2],
    /// The nodes of the containing cell and their shape-function values there.
    pub nodes: [usize; 4],
    pub weights: [f64; 4],
    /// Whether the point is a node (a shape function is 1 to round-off).
    pub at_node: bool,
    /// The points across the band at this distance that lie in the mesh (nodes and shape
    /// functions), see [`BAND_CELLS`].
    pub band: Vec<([usize; 4], [f64; 4])>,
}

/// The points of one probe line that lie in the mesh: the equally spaced points and the mesh nodes
/// on the line (a node replaces an equally spaced point within 1e-9 of the line's length of it).
#[derive(Debug, Clone)]
pub struct ProbeLine {
    pub name: String,
    pub from: [f64; 2],
    pub to: [f64; 2],
    /// Points asked for (those outside the mesh are not in `samples`).
    pub points: usize,
    pub samples: Vec<Sample>,
}

impl ProbeLine {
    /// `points` equally spaced points from `from` to `to` and the nodes on the line, located in
/// `mesh`, in order of distance from `from`; points outside the mesh are left out.
    pub fn new(name: &str, from: [f64; 2], to: [f64; 2], points: usize, mesh: &QuadMesh, locator: &CellLocator) -> ProbeLine {
        let len = (to[0] - from[0]).hypot(to[1] - from[1]);
        let dir = [(to[0] - from[0]) / len, (to[1] - from[1]) / len];
        let tol = 1e-9 * len;
        let width = BAND_CELLS * mesh.element_size();
        let mut samples: Vec<Sample> = Vec::new();
        let mut add = |distance: f64, x: [f64; 2]| {
            if let Some((c, xi)) = locator.locate(x) {
                let (w, _) = bilinear(xi[0].clamp(-1.0, 1.0), xi[1].clamp(-1.0, 1.0));
                let band = (0..BAND_LINES)
                    .filter_map(|k| {
                        let t = width * (k as f64 / (BAND_LINES - 1) as f64 - 0.5);
                        let (c, xi) = locator.locate([x[0] + t * dir[1], x[1] - t * dir[0]])?;
                        Some((mesh.cells[c], bilinear(xi[0].clamp(-1.0, 1.0), xi[1].clamp(-1.0, 1.0)).0))
                    })
                    .collect();
                samples.push(Sample { distance, x, nodes: mesh.cells[c], weights: w, at_node: w.iter().any(|&v| v > 1.0 - 1e-9), band });
            }
        };
        let mut wanted: Vec<(f64, [f64; 2])> = (0..points)
            .map(|k| {
                let s = k as f64 / (points - 1).max(1) as f64;
                (s * len, [from[0] + s * (to[0] - from[0]), from[1] + s * (to[1] - from[1])])
            })
            .collect();
        // the nodes on the line, so that the curve passes through the nodal values
        for x in &mesh.coords {
            let r = [x[0] - from[0], x[1] - from[1]];
            let along = r[0] * dir[0] + r[1] * dir[1];
            let across = r[0] * dir[1] - r[1] * dir[0];
            if across.abs() <= tol && (-tol..=len + tol).contains(&along) {
                wanted.push((along.clamp(0.0, len), *x));
            }
        }
        wanted.sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(std::cmp::Ordering::Equal));
        // a node replaces an equally spaced point that coincides with it
        let mut kept: Vec<(f64, [f64; 2])> = Vec::with_capacity(wanted.len());
        for w in wanted {
            match kept.last_mut() {
                Some(last) if (w.0 - last.0).abs() <= tol => {
                    if mesh.coords.contains(&w.1) {
                        *last = w;
                    }
                }
                _ => kept.push(w),
            }
        }
        for (d, x) in kept {
            add(d, x);
        }
        ProbeLine { name: name.to_string(), from, to, points, samples }
    }

    /// Interpolate the nodal values `f` at every sample.
    pub fn interpolate(&self, f: impl Fn(usize) -> f64) -> Vec<f64> {
        self.samples.iter().map(|s| (0..4).map(|a| s.weights[a] * f(s.nodes[a])).sum()).collect()
    }

    /// The mean of the nodal field `f` across the band at every sample (see [`BAND_CELLS`]; over
    /// the band's points in the mesh).
    pub fn band_mean(&self, f: impl Fn(usize) -> f64) -> Vec<f64> {
        self.samples
            .iter()
            .map(|s| {
                let sum: f64 = s.band.iter().map(|(nodes, w)| (0..4).map(|a| w[a] * f(nodes[a])).sum::<f64>()).sum();
                sum / s.band.len().max(1) as f64
            })
            .collect()
    }

    /// The running integral of `values` (one per sample) along the line, by the trapezoidal rule;
    /// a gap in the samples (a hole of the mesh) adds nothing.
    pub fn running_integral(&self, values: &[f64]) -> Vec<f64> {
        let spacing = (self.to[0] - self.from[0]).hypot(self.to[1] - self.from[1]) / (self.points - 1).max(1) as f64;
        let mut out = Vec::with_capacity(values.len());
        let mut sum = 0.0;
        for k in 0..values.len() {
            if k > 0 {
                let dd = self.samples[k].distance - self.samples[k - 1].distance;
                // consecutive samples are at most one spacing apart; farther: the line left the mesh
                if dd <= spacing * (1.0 + 1e-6) {
                    sum += 0.5 * dd * (values[k] + values[k - 1]);
                }
            }
            out.push(sum);
        }
        out
    }
}

/// Values given per contact point of `pair`, at every node (0 at nodes that are not its
/// candidates).
fn at_nodes(pair: &ContactPair, num_nodes: usize, values: impl IntoIterator<Item = f64>) -> Vec<f64> {
    let mut q = vec![0.0; num_nodes];
    for (pt, v) in pair.points.iter().zip(values) {
        q[pt.node] += v;
    }
    q
}

/// Nodal contact pressure q_n of one punch (0 at nodes that are not its candidates).
pub fn nodal_pressure(pair: &ContactPair, num_nodes: usize) -> Vec<f64> {
    at_nodes(pair, num_nodes, pair.pressures())
}

/// The tangential traction of one punch with friction (the .vtu's `<punch>_traction`, force per
/// unit area of the plate on the punch, global axes) at every node, per component; None without
/// friction.
pub fn nodal_traction(pair: &ContactPair, num_nodes: usize) -> Option<[Vec<f64>; 3]> {
    let f = pair.friction_at_points()?;
    Some(std::array::from_fn(|c| at_nodes(pair, num_nodes, f.traction.iter().map(|t| t[c]))))
}

/// The recovered contact pressure of one punch ([`stamp::contact::RECOVERY`]) at every node (0
/// at nodes that are not its candidates).
pub fn recovered_nodal_pressure(pair: &ContactPair, cells: &[[usize; 4]], num_nodes: usize) -> Vec<f64> {
    at_nodes(pair, num_nodes, stamp::contact::recovered_pressure(pair, cells, stamp::contact::RECOVERY).pressure)
}

/// One written step of a probe, kept for the plot.
struct Curve {
    row: HistoryRow,
    points: Vec<(f64, f64)>,
    markers: Vec<(f64, f64)>,
    /// The integral of the pressure along the line, and across the band (all punches).
    integral: f64,
    line_load: f64,
}

/// The default probe, decided at the first written step.
struct DefaultProbe {
    name: String,
    /// 0: along x1, 1: along x2.
    axis: usize,
}

/// The probes of a run and the curves of their plots.
pub struct Probes<'a> {
    mesh: &'a QuadMesh,
    locator: CellLocator<'a>,
    pub lines: Vec<ProbeLine>,
    pending: Option<DefaultProbe>,
    curves: Vec<Vec<Curve>>,
}

/// Whether the problem file itself sets `output.plot_axis`.
fn plot_axis_given(p: &Problem) -> bool {
    toml::from_str::<toml::Table>(&p.source).ok().and_then(|t| t.get("output").and_then(|o| o.get("plot_axis")).cloned()).is_some()
}

impl<'a> Probes<'a> {
    /// The probes the problem names, or the default probe (see the module notes).
    pub fn new(p: &Problem, mesh: &'a MeshData, probes: &[Spanned<ProbeSpec>], punch_names: &[String]) -> Result<Probes<'a>> {
        let locator = CellLocator::new(&mesh.mesh);
        let mut lines: Vec<ProbeLine> = Vec::with_capacity(probes.len());
        for (i, spanned) in probes.iter().enumerate() {
            let s = spanned.get_ref();
            let line = ProbeLine::new(&s.name, s.from, s.to, s.points.unwrap_or(DEFAULT_POINTS), &mesh.mesh, &locator);
            if line.samples.is_empty() {
                return Err(p.error_at(spanned.span(), &format!("output.probe[{i}]"), format!("the line from {:?} to {:?} does not cross the mesh", s.from, s.to)));
            }
            lines.push(line);
        }
        let pending = (lines.is_empty() && p.spec.output.plot && !punch_names.is_empty()).then(|| DefaultProbe {
            name: punch_names[0].clone(),
            axis: if plot_axis_given(p) && p.spec.output.plot_axis == crate::schema::PlotAxis::X2 { 1 } else { 0 },
        });
        let curves = lines.iter().map(|_| Vec::new()).collect();
        Ok(Probes { mesh: &mesh.mesh, locator, lines, pending, curves })
    }

    /// Whether there is nothing to write.
    pub fn is_empty(&self) -> bool {
        self.lines.is_empty() && self.pending.is_none()
    }

    /// Place the default probe through the first contact point of `contacts[0]`.
    fn place_default(&mut self, contacts: &[ContactPair]) {
        let Some(d) = self.pending.take() else { return };
        let Some(pair) = contacts.first() else { return };
        let q = pair.pressures();
        let pick = |key: &dyn Fn(usize) -> f64| (0..pair.points.len()).min_by(|&a, &b| key(a).partial_cmp(&key(b)).unwrap_or(std::cmp::Ordering::Equal));
        let any_active = pair.state.iter().any(|s| s.active);
        let k = if any_active {
            // the active node closest to the pressure-weighted centre of the active nodes
            let (mut c, mut wsum) = ([0.0; 2], 0.0);
            for (pt, (st, &qk)) in pair.points.iter().zip(pair.state.iter().zip(&q)) {
                if st.active {
                    let w = qk.max(0.0) + 1e-300;
                    c = [c[0] + w * pt.x_ref[0], c[1] + w * pt.x_ref[1]];
                    wsum += w;
                }
            }
            let c = [c[0] / wsum, c[1] / wsum];
            pick(&|k| if pair.state[k].active { (pair.points[k].x_ref[0] - c[0]).hypot(pair.points[k].x_ref[1] - c[1]) } else { f64::INFINITY })
        } else {
            pick(&|k| {
                let s = &pair.state[k];
                let g = s.grad.iter().map(|v| v * v).sum::<f64>().sqrt();
                if g > 0.0 { s.psi / g } else { f64::INFINITY }
            })
        };
        let Some(k) = k else { return };
        let c = self.mesh.coords[pair.points[k].node];
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for x in &self.mesh.coords {
            lo = lo.min(x[d.axis]);
            hi = hi.max(x[d.axis]);
        }
        let (mut from, mut to) = (c, c);
        from[d.axis] = lo;
        to[d.axis] = hi;
        self.lines.push(ProbeLine::new(&d.name, from, to, DEFAULT_POINTS, self.mesh, &self.locator));
        self.curves.push(Vec::new());
    }

    /// Write `probe_<name>_<step>.csv` of every probe for the state `u` and keep the curves.
    pub fn write_step(&mut self, dir: &Path, step: usize, row: &HistoryRow, punch_names: &[String], contacts: &[ContactPair], layout: &Layout, u: &[f64]) -> Result<Vec<PathBuf>> {
        self.place_default(contacts);
        let nn = self.mesh.num_nodes();
        let q: Vec<Vec<f64>> = contacts.iter().map(|c| nodal_pressure(c, nn)).collect();
        let rec: Vec<Vec<f64>> = contacts.iter().map(|c| recovered_nodal_pressure(c, &self.mesh.cells, nn)).collect();
        // the tangential traction of each punch with friction, per component, at every node
        let traction: Vec<(&String, [Vec<f64>; 3])> = punch_names.iter().zip(contacts).filter_map(|(n, c)| nodal_traction(c, nn).map(|t| (n, t))).collect();
        let mut files = Vec::new();
        for (line, curves) in self.lines.iter().zip(&mut self.curves) {
            let disp: Vec<Vec<f64>> = (0..3).map(|i| line.interpolate(|n| layout.mid_displacement(u, n)[i])).collect();
            let qs: Vec<Vec<f64>> = q.iter().map(|qk| line.interpolate(|n| qk[n])).collect();
            let recs: Vec<Vec<f64>> = rec.iter().map(|rk| line.interpolate(|n| rk[n])).collect();
            let integrals: Vec<Vec<f64>> = qs.iter().map(|v| line.running_integral(v)).collect();
            let loads: Vec<Vec<f64>> = q.iter().map(|qk| line.running_integral(&line.band_mean(|n| qk[n]))).collect();
            let tractions: Vec<Vec<f64>> = traction.iter().flat_map(|(_, t)| t.iter().map(|tc| line.interpolate(|n| tc[n]))).collect();
            let mut csv = String::from("distance,x1,x2,u1,u2,u3");
            for n in punch_names {
                csv.push_str(&format!(",{n}_pressure,{n}_pressure_recovered,{n}_integral,{n}_line_load"));
            }
            for (n, _) in &traction {
                csv.push_str(&format!(",{n}_traction_x1,{n}_traction_x2,{n}_traction_x3"));
            }
            csv.push('\n');
            let mut points = Vec::with_capacity(line.samples.len());
            let mut markers = Vec::new();
            for (k, s) in line.samples.iter().enumerate() {
                csv.push_str(&format!("{:e},{:e},{:e},{:e},{:e},{:e}", s.distance, s.x[0], s.x[1], disp[0][k], disp[1][k], disp[2][k]));
                let mut total = 0.0;
                for (((qk, rk), ik), lk) in qs.iter().zip(&recs).zip(&integrals).zip(&loads) {
                    csv.push_str(&format!(",{:e},{:e},{:e},{:e}", qk[k], rk[k], ik[k], lk[k]));
                    total += qk[k];
                }
                for t in &tractions {
                    csv.push_str(&format!(",{:e}", t[k]));
                }
                csv.push('\n');
                points.push((s.distance, total));
                if s.at_node {
                    markers.push((s.distance, total));
                }
            }
            let path = dir.join(format!("probe_{}_{step:04}.csv", line.name));
            write_string_atomically(&path, &csv)?;
            files.push(path);
            let last = |v: &Vec<Vec<f64>>| v.iter().map(|x| x.last().copied().unwrap_or(0.0)).sum::<f64>();
            curves.push(Curve { row: row.clone(), points, markers, integral: last(&integrals), line_load: last(&loads) });
        }
        Ok(files)
    }

    /// Draw `probe_<name>.png/.svg`: the contact pressure of up to [`MAX_CURVES`] written steps.
    pub fn plot(&self, dir: &Path, history: &History, units: &Units) -> Result<Vec<PathBuf>> {
        let mut files = Vec::new();
        for (line, curves) in self.lines.iter().zip(&self.curves) {
            if curves.is_empty() {
                continue;
            }
            let paths: Vec<f64> = curves.iter().map(|c| c.row.path).collect();
            let series: Vec<Series> = choose_evenly(&paths, MAX_CURVES)
                .into_iter()
                .map(|i| {
                    let c = &curves[i];
                    Series { label: history.step_label(&c.row, units), points: c.points.clone(), markers: c.markers.clone() }
                })
                .collect();
            let [a, b] = [line.from, line.to].map(|p| format!("({}, {})", sig4(p[0]), sig4(p[1])));
            let end = curves.last().expect("not empty");
            let title = format!(
                "contact pressure along probe '{}' from {a} to {b}\nat the last step its integral is {} ({} across a band of {} cells)",
                line.name,
                sig4(end.integral),
                sig4(end.line_load),
                BAND_CELLS
            );
            let x = Units::label("distance along the line", &units.length);
            let y = Units::label("contact pressure q_n", &units.pressure);
            let plot = Plot { title: &title, x_label: &x, y_label: &y, series: &series };
            files.extend(write_plot(&dir.join(format!("probe_{}", line.name)), &plot)?);
        }
        Ok(files)
    }
}

/// Indices of at most `n` of the increasing values `path`, spread evenly over [0, last], always the
/// last, in increasing order.
pub fn choose_evenly(path: &[f64], n: usize) -> Vec<usize> {
    if path.len() <= n {
        return (0..path.len()).collect();
    }
    let last = path.len() - 1;
    let end = path[last];
    let mut picked: Vec<usize> = Vec::new();
    for k in 1..=n {
        let target = end * k as f64 / n as f64;
        let best = (0..=last).filter(|i| !picked.contains(i)).min_by(|&a, &b| (path[a] - target).abs().partial_cmp(&(path[b] - target).abs()).unwrap_or(std::cmp::Ordering::Equal));
        if let Some(i) = best {
            picked.push(i);
        }
    }
    picked.sort_unstable();
    picked
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn locator_finds_the_cell_and_refuses_points_outside() {
        // a 7 x 5 rectangle with its interior nodes moved, so cells are distorted
        let mut mesh = QuadMesh::rectangle(0.0, 7.0, 0.0, 5.0, 7, 5).unwrap();
        for (k, c) in mesh.coords.iter_mut().enumerate() {
            if c[0] > 0.0 && c[0] < 7.0 && c[1] > 0.0 && c[1] < 5.0 {
                c[0] += 0.3 * ((k as f64) * 1.7).sin();
                c[1] += 0.3 * ((k as f64) * 2.3).cos();
            }
        }
        let loc = CellLocator::new(&mesh);
        for c in 0..mesh.num_cells() {
            let x = mesh.cell_coords(c);
            for xi in [[0.1, 0.2], [-0.8, 0.6], [0.5, -0.9]] {
                let p = stamp::mesh::bilinear_point(&x, xi);
                let (found, back) = loc.locate(p).unwrap_or_else(|| panic!("{p:?} in cell {c} not found"));
                assert_eq!(found, c, "{p:?}");
                assert!((back[0] - xi[0]).abs() < 1e-10 && (back[1] - xi[1]).abs() < 1e-10);
            }
        }
        // every node is found (on an edge or corner of some cell), with a shape function 1 there
        for (k, &p) in mesh.coords.iter().enumerate() {
            let (c, xi) = loc.locate(p).unwrap_or_else(|| panic!("node {k} not found"));
            let (w, _) = bilinear(xi[0], xi[1]);
            let a = mesh.cells[c].iter().position(|&n| n == k).expect("node of the cell");
            assert!((w[a] - 1.0).abs() < 1e-9, "node {k}: {w:?}");
        }
        for p in [[-0.1, 2.0], [7.2, 1.0], [3.0, 5.5], [-1.0, -1.0]] {
            assert!(loc.locate(p).is_none(), "{p:?} outside was located");
        }
    }

    #[test]
    fn locator_on_a_mesh_with_a_hole_leaves_the_hole_out() {
        // a 3 x 3 rectangle without its middle cell
        let full = QuadMesh::rectangle(0.0, 3.0, 0.0, 3.0, 3, 3).unwrap();
        let cells: Vec<[usize; 4]> = full.cells.iter().enumerate().filter(|(c, _)| *c != 4).map(|(_, c)| *c).collect();
        let mesh = QuadMesh::new(full.coords.clone(), cells).unwrap();
        let loc = CellLocator::new(&mesh);
        assert!(loc.locate([1.5, 1.5]).is_none());
        assert!(loc.locate([0.5, 1.5]).is_some());
        let line = ProbeLine::new("l", [0.0, 1.5], [3.0, 1.5], 7, &mesh, &loc);
        let d: Vec<f64> = line.samples.iter().map(|s| s.distance).collect();
        assert_eq!(d, [0.0, 0.5, 1.0, 2.0, 2.5, 3.0], "1.5 lies in the hole");
    }

    #[test]
    fn interpolation_is_exact_for_bilinear_fields() {
        let mut mesh = QuadMesh::rectangle(-2.0, 2.0, -1.0, 1.0, 8, 4).unwrap();
        for (k, c) in mesh.coords.iter_mut().enumerate() {
            if c[0].abs() < 2.0 && c[1].abs() < 1.0 {
                c[0] += 0.1 * ((k as f64) * 0.9).sin();
            }
        }
        let loc = CellLocator::new(&mesh);
        let line = ProbeLine::new("l", [-2.0, -1.0], [2.0, 1.0], 41, &mesh, &loc);
        assert_eq!(line.samples.len(), 41);
        // an affine field is reproduced exactly by bilinear elements of any shape
        let f = |x: [f64; 2]| 3.0 + 2.0 * x[0] - 5.0 * x[1];
        let vals = line.interpolate(|n| f(mesh.coords[n]));
        for (s, v) in line.samples.iter().zip(vals) {
            assert!((v - f(s.x)).abs() < 1e-10, "{:?}: {v} against {}", s.x, f(s.x));
        }
        assert!(line.samples[0].at_node && line.samples[40].at_node);
    }

    #[test]
    fn the_band_mean_of_an_affine_field_is_its_value_and_integrals_are_exact_for_it() {
        // a distorted 8 x 8 mesh on [0, 8]^2, a line across its middle: the band (8 cells wide)
        // stays inside, so its mean of an affine field is the field on the line
        let mut mesh = QuadMesh::rectangle(0.0, 8.0, 0.0, 8.0, 8, 8).unwrap();
        for (k, c) in mesh.coords.iter_mut().enumerate() {
            if c[0] > 0.0 && c[0] < 8.0 && c[1] > 0.0 && c[1] < 8.0 {
                c[0] += 0.2 * ((k as f64) * 1.3).sin();
                c[1] += 0.2 * ((k as f64) * 0.7).cos();
            }
        }
        let loc = CellLocator::new(&mesh);
        let line = ProbeLine::new("l", [1.0, 4.0], [7.0, 4.0], 61, &mesh, &loc);
        let f = |x: [f64; 2]| 2.0 + 0.5 * x[0] + 3.0 * x[1];
        let on_line = line.interpolate(|n| f(mesh.coords[n]));
        let band = line.band_mean(|n| f(mesh.coords[n]));
        for ((s, a), b) in line.samples.iter().zip(&on_line).zip(&band) {
            assert_eq!(s.band.len(), BAND_LINES, "the whole band lies in the mesh");
            assert!((a - b).abs() < 1e-10, "at {:?}: {a} on the line, {b} across the band", s.x);
        }
        // int_1^7 (2 + 0.5 x + 12) dx = 14 * 6 + 0.25 * (49 - 1) = 96, exact for a linear integrand
        let integral = line.running_integral(&on_line);
        assert!((integral.last().unwrap() - 96.0).abs() < 1e-9, "{}", integral.last().unwrap());
        assert_eq!(integral[0], 0.0);
        // a band that leaves the mesh averages over its points inside
        let edge = ProbeLine::new("e", [1.0, 0.5], [7.0, 0.5], 7, &mesh, &loc);
        assert!(edge.samples.iter().all(|s| s.band.len() < BAND_LINES && !s.band.is_empty()));
    }

    #[test]
    fn curves_are_spread_over_the_path_with_the_last() {
        let path: Vec<f64> = (1..=20).map(|k| k as f64).collect();
        let c = choose_evenly(&path, 8);
        assert_eq!(c.len(), 8);
        assert_eq!(*c.last().unwrap(), 19);
        assert_eq!(choose_evenly(&path[..5], 8), vec![0, 1, 2, 3, 4]);
        // steps crowded at the start: the picks follow the path, not the step count
        let crowded = [0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.5, 1.0];
        let c = choose_evenly(&crowded, 3);
        assert_eq!(c, vec![8, 9, 10]);
    }

    /// Cost on a large mesh (run with --ignored): a 1000 x 1000 rectangle, a probe of 100000 points.
    #[test]
    #[ignore]
    fn probe_on_a_million_cells() {
        let mesh = QuadMesh::rectangle(0.0, 1.0, 0.0, 1.0, 1000, 1000).unwrap();
        let t = std::time::Instant::now();
        let loc = CellLocator::new(&mesh);
        let built = t.elapsed();
        let line = ProbeLine::new("l", [0.0, 0.123], [1.0, 0.987], 100_000, &mesh, &loc);
        eprintln!("locator {:.3} s, 100000-point probe {:.3} s", built.as_secs_f64(), (t.elapsed() - built).as_secs_f64());
        // the line meets 9 nodes, (i, j) / 1000 with i = 0, 125, ..., 1000: 7 between the ends
        assert_eq!(line.samples.len(), 100_007);
    }
}

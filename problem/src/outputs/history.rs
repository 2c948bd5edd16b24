//! The load history of a run: one row per converged step with each punch's travel, force, contact
//! area and peak pressure and the displacement of each named point; written as `history.csv` after
//! every converged step and drawn as `force_travel_<punch>.png/.svg` at the end.
//!
//! Per punch, along its direction d (the unit motion of a displacement-driven punch, the drive
//! direction of a force-driven one, or towards the plate, -x3 on the top face and +x3 on the bottom
//! face, for a punch that does not move):
//! * travel: the prescribed displacement t motion . d, or the drive displacement s of a force-driven
//!   punch;
//! * force: the reaction of the punch on the plate along d, so pressing is positive;
//! * contact area: the sum of the tributary areas (contact weights) of the active nodes;
//! * max pressure: the largest q_n; max penetration: the largest max(0, -Psi / |grad Psi|).
//!
//! Per `[[boundary]]` group, the reaction of its supports on the plate in global axes (see
//! [`crate::outputs::supports`]), in the last columns.

use crate::model::plate_model::Layout;
use crate::outputs::plot::{write_plot, Plot, Series};
use crate::schema::units::Units;
use stamp::Result;
use stamp::contact::ContactPair;
use stamp::io::write_string_atomically;
use stamp_elements::Face;
use std::path::{Path, PathBuf};

/// What one punch did in one converged step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PunchRow {
    pub travel: f64,
    pub force: f64,
    pub contact_area: f64,
    pub max_pressure: f64,
    pub max_penetration: f64,
    /// The force of the plate on the punch in global axes (normal and friction forces).
    pub force_on_punch: [f64; 3],
    /// The energy friction dissipated so far (None: a punch without friction).
    pub dissipation: Option<f64>,
}

/// One converged step.
#[derive(Debug, Clone, PartialEq)]
pub struct HistoryRow {
    pub step: usize,
    pub load_factor: f64,
    pub path: f64,
    pub newton_iterations: usize,
    pub punches: Vec<PunchRow>,
    /// Mid-surface displacement of each named point group (mean over its nodes).
    pub points: Vec<[f64; 3]>,
    /// The mid-surface deflection u3 of largest magnitude over all nodes (with its sign).
    pub max_deflection: f64,
    /// The reaction [f1, f2, f3] of each support group ([`History::support_names`]) on the plate.
    pub supports: Vec<[f64; 3]>,
    /// An elastic-plastic plate: the largest equivalent plastic strain and the least thickness.
    pub plastic: Option<(f64, f64)>,
}

/// The direction along which a punch's travel and force are measured.
pub fn punch_direction(pair: &ContactPair, face: Face) -> [f64; 3] {
    if let Some(d) = &pair.drive {
        return d.direction;
    }
    let m = pair.motion.approach();
    let norm = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    if norm > 0.0 {
        return m.map(|x| x / norm);
    }
    match face {
        Face::Top => [0.0, 0.0, -1.0],
        Face::Bottom => [0.0, 0.0, 1.0],
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The row of one punch for the unknowns `u` at load factor `t`.
pub fn punch_row(pair: &ContactPair, face: Face, u: &[f64], t: f64) -> PunchRow {
    let d = punch_direction(pair, face);
    let travel = pair.drive_displacement(u).unwrap_or_else(|| dot(pair.punch_displacement(u, t), d));
    let q = pair.pressures();
    let contact_area = pair.points.iter().zip(&pair.state).filter(|(_, s)| s.active).fold(0.0, |a, (p, _)| a + p.weight);
    PunchRow {
        travel,
        force: dot(pair.reaction(), d),
        force_on_punch: pair.reaction().map(|x| -x),
        dissipation: pair.friction_dissipation(),
        contact_area,
        max_pressure: q.iter().cloned().fold(0.0, f64::max),
        max_penetration: pair.max_penetration(),
    }
}


/// The rows of a run so far and what names its columns.
#[derive(Debug, Clone)]
pub struct History {
    pub punch_names: Vec<String>,
    pub punch_faces: Vec<Face>,
    /// Whether a punch's steps are labelled by force (force driven, or not moving) rather than by
    /// travel in the probe plots.
    pub label_by_force: Vec<bool>,
    /// Named point groups (name, nodes).
    pub points: Vec<(String, Vec<usize>)>,
    /// The `[[boundary]]` groups whose reactions the rows hold.
    pub support_names: Vec<String>,
    pub rows: Vec<HistoryRow>,
    /// Where the plate keeps its surfaces' displacements among the unknowns.
    pub layout: Layout,
}

impl History {
    /// An empty history for the punches (name, face, label by force); point groups whose name starts
    /// with '#' (unnamed gmsh groups) are left out.
    pub fn new(punches: &[(String, Face, bool)], point_groups: &[(String, Vec<usize>)]) -> History {
        History {
            punch_names: punches.iter().map(|p| p.0.clone()).collect(),
            punch_faces: punches.iter().map(|p| p.1).collect(),
            label_by_force: punches.iter().map(|p| p.2).collect(),
            points: point_groups.iter().filter(|(k, _)| !k.starts_with('#')).cloned().collect(),
            support_names: Vec::new(),
            rows: Vec::new(),
            layout: Layout::two_surface(),
        }
    }

    /// The same for a plate with another layout of its unknowns (a plate of more than two surfaces).
    pub fn with_layout(mut self, layout: Layout) -> History {
        self.layout = layout;
        self
    }

    /// The same with the reactions of these support groups in its rows.
    pub fn with_supports(mut self, names: Vec<String>) -> History {
        self.support_names = names;
        self
    }

    /// Add the converged step `step` (unknowns `u`, load factor `t`, path length `path`, the
    /// reactions of the support groups `supports`).
    #[allow(clippy::too_many_arguments)]
    pub fn record(&mut self, step: usize, t: f64, path: f64, newton_iterations: usize, contacts: &[ContactPair], u: &[f64], supports: Vec<[f64; 3]>, plastic: Option<(f64, f64)>) -> &HistoryRow {
        let punches = contacts.iter().zip(&self.punch_faces).map(|(c, &f)| punch_row(c, f, u, t)).collect();
        let points = self
            .points
            .iter()
            .map(|(_, nodes)| {
                let mut s = [0.0; 3];
                for &k in nodes {
                    let v = self.layout.mid_displacement(u, k);
                    for i in 0..3 {
                        s[i] += v[i] / nodes.len() as f64;
                    }
                }
                s
            })
            .collect();
        // u holds the surfaces' displacements node by node, then one unknown per force-driven punch
        let nodes = (u.len() - contacts.iter().filter(|c| c.drive.is_some()).count()) / self.layout.dofs_per_node;
        let max_deflection = (0..nodes).map(|n| self.layout.mid_displacement(u, n)[2]).fold(0.0f64, |m, w| if w.abs() > m.abs() { w } else { m });
        self.rows.push(HistoryRow { step, load_factor: t, path, newton_iterations, punches, points, max_deflection, supports, plastic });
        self.rows.last().expect("just pushed")
    }

    /// The text of history.csv.
    pub fn csv(&self) -> String {
        let mut s = String::from("step,load_factor,path");
        for n in &self.punch_names {
            s.push_str(&format!(",{n}_travel,{n}_force,{n}_contact_area,{n}_max_pressure"));
        }
        for (n, _) in &self.points {
            s.push_str(&format!(",{n}_u1,{n}_u2,{n}_u3"));
        }
        // after the columns above: the force on each punch in global axes, and the friction's
        // dissipation of the punches with friction
        let friction: Vec<bool> = (0..self.punch_names.len()).map(|k| self.rows.first().is_some_and(|r| r.punches[k].dissipation.is_some())).collect();
        for (k, n) in self.punch_names.iter().enumerate() {
            s.push_str(&format!(",{n}_force_x1,{n}_force_x2,{n}_force_x3"));
            if friction[k] {
                s.push_str(&format!(",{n}_dissipation"));
            }
        }
        // last: the reaction of each support group in global axes
        for g in &self.support_names {
            s.push_str(&format!(",{g}_reaction_x1,{g}_reaction_x2,{g}_reaction_x3"));
        }
        // an elastic-plastic plate: the largest plastic strain and the least thickness
        if self.rows.first().is_some_and(|r| r.plastic.is_some()) {
            s.push_str(",max_plastic_strain,min_thickness");
        }
        s.push('\n');
        for r in &self.rows {
            s.push_str(&format!("{},{:e},{:e}", r.step, r.load_factor, r.path));
            for p in &r.punches {
                s.push_str(&format!(",{:e},{:e},{:e},{:e}", p.travel, p.force, p.contact_area, p.max_pressure));
            }
            for v in &r.points {
                s.push_str(&format!(",{:e},{:e},{:e}", v[0], v[1], v[2]));
            }
            for p in &r.punches {
                let f = p.force_on_punch;
                s.push_str(&format!(",{:e},{:e},{:e}", f[0], f[1], f[2]));
                if let Some(d) = p.dissipation {
                    s.push_str(&format!(",{d:e}"));
                }
            }
            for f in &r.supports {
                s.push_str(&format!(",{:e},{:e},{:e}", f[0], f[1], f[2]));
            }
            if let Some((ep, h)) = r.plastic {
                s.push_str(&format!(",{ep:e},{h:e}"));
            }
            s.push('\n');
        }
        s
    }

    /// Write history.csv into `dir` (atomically).
    pub fn write_csv(&self, dir: &Path) -> Result<PathBuf> {
        let path = dir.join("history.csv");
        write_string_atomically(&path, &self.csv())?;
        Ok(path)
    }

    /// " sphere force 1.234e3" for each punch: the tail of the terse progress line.
    pub fn terse_forces(&self) -> String {
        let Some(r) = self.rows.last() else { return String::new() };
        self.punch_names.iter().zip(&r.punches).map(|(n, p)| format!(", {n} force {} travel {}", sig(p.force), sig(p.travel))).collect()
    }

    /// The label of a step in the probe plots: the force of the first punch when it is force
    /// driven or does not move, else its travel; the load factor without punches.
    pub fn step_label(&self, row: &HistoryRow, units: &Units) -> String {
        match (row.punches.first(), self.label_by_force.first()) {
            (Some(p), Some(true)) => format!("force {}", units.force_value(&sig4(p.force))),
            (Some(p), _) => format!("travel {}", units.length_value(&sig4(p.travel))),
            _ => format!("load factor {}", sig4(row.load_factor)),
        }
    }

    /// Draw force against travel for every punch: `force_travel_<punch>.png` and `.svg` (against the
    /// load factor for a punch whose travel stays 0, a fixed punch, and for one whose travel stays
    /// the same over a step while it moves on: a die sliding along a path).
    pub fn plot_force_travel(&self, dir: &Path, units: &Units) -> Result<Vec<PathBuf>> {
        let mut files = Vec::new();
        for (k, name) in self.punch_names.iter().enumerate() {
            // a punch that does not move: force against the load factor
            let fixed = self.rows.iter().all(|r| r.punches[k].travel == 0.0);
            let scale = self.rows.iter().map(|r| r.punches[k].travel.abs()).fold(0.0, f64::max);
            let slides = !fixed
                && self.rows.windows(2).any(|w| (w[1].punches[k].travel - w[0].punches[k].travel).abs() <= 1e-12 * scale && w[1].load_factor != w[0].load_factor);
            let against_load_factor = fixed || slides;
            let mut points = vec![(0.0, 0.0)];
            points.extend(self.rows.iter().map(|r| (if against_load_factor { r.load_factor } else { r.punches[k].travel }, r.punches[k].force)));
            let series = [Series { label: String::new(), points: points.clone(), markers: points }];
            let (title, x) = if fixed {
                (format!("punch '{name}' (fixed): force against load factor"), "load factor".to_string())
            } else if slides {
                (format!("punch '{name}' (moved along a path): force against load factor"), "load factor".to_string())
            } else {
                (format!("punch '{name}': force against travel"), Units::label("travel", &units.length))
            };
            let y = Units::label("force", &units.force);
            let plot = Plot { title: &title, x_label: &x, y_label: &y, series: &series };
            files.extend(write_plot(&dir.join(format!("force_travel_{name}")), &plot)?);
        }
        Ok(files)
    }
}

/// `x` with 6 significant digits: fixed notation for magnitudes in [1e-3, 1e6), else scientific.
pub fn sig(x: f64) -> String {
    sig_n(x, 6)
}

/// `x` with 4 significant digits (plot labels).
pub fn sig4(x: f64) -> String {
    sig_n(x, 4)
}

fn sig_n(x: f64, digits: i32) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    // the exponent of x rounded to `digits` significant digits (99.99999 -> 100.000)
    let rounded: f64 = format!("{x:.*e}", (digits - 1) as usize).parse().unwrap_or(x);
    let e = rounded.abs().log10().floor() as i32;
    if (-3..6).contains(&e) {
        let decimals = (digits - 1 - e).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        format!("{x:.*e}", (digits - 1) as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(1234.5678), "1234.57");
        assert_eq!(sig(-0.012345678), "-0.0123457");
        assert_eq!(sig(2.0e-7), "2.00000e-7");
        assert_eq!(sig(0.0), "0");
        assert_eq!(sig4(0.45), "0.4500");
        assert_eq!(sig(123456789.0), "1.23457e8");
        assert_eq!(sig(99.9999999873), "100.000");
        assert_eq!(sig(999999.9), "1.00000e6");
    }

    /// The force-travel plot's title for a punch with these (load factor, travel) steps.
    fn plot_title(name: &str, steps: &[(f64, f64)]) -> String {
        let mut h = History::new(&[(name.into(), Face::Top, false)], &[]);
        for (k, &(t, travel)) in steps.iter().enumerate() {
            let punches = vec![PunchRow { travel, force: 10.0 * t, contact_area: 1.0, max_pressure: 1.0, max_penetration: 0.0, force_on_punch: [0.0; 3], dissipation: None }];
            h.rows.push(HistoryRow { step: k + 1, load_factor: t, path: t, newton_iterations: 2, punches, points: vec![], max_deflection: 0.0, supports: vec![], plastic: None });
        }
        let dir = std::env::temp_dir().join(format!("stamp-history-plot-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        h.plot_force_travel(&dir, &Units::new(None)).unwrap();
        let svg = std::fs::read_to_string(dir.join(format!("force_travel_{name}.svg"))).unwrap();
        let _ = std::fs::remove_dir_all(&dir);
        svg
    }

    #[test]
    fn a_sliding_punch_is_plotted_against_the_load_factor() {
        // pressed, then slid at the same depth: its travel stands still while the load factor goes on
        let svg = plot_title("slide", &[(0.25, 0.1), (0.5, 0.2), (0.75, 0.2), (1.0, 0.2)]);
        assert!(svg.contains("moved along a path): force against load factor"), "{svg}");
        // pressed and released: force against travel (a loop is what the user wants to see)
        let svg = plot_title("press", &[(0.5, 0.1), (1.0, 0.2), (1.5, 0.1), (2.0, 0.0)]);
        assert!(svg.contains("force against travel"), "{svg}");
        let svg = plot_title("fixed", &[(0.5, 0.0), (1.0, 0.0)]);
        assert!(svg.contains("(fixed): force against load factor"), "{svg}");
    }
}

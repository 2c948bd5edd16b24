//! What `stamp run --refine` reports: the key results of the run on the problem's mesh and on its
//! refinements at the same load steps, their Richardson estimate ([`crate::refine::richardson`]) and each
//! run's estimated error, as tables under the run's table (one per key result), as extra columns
//! of history.csv and as summary.json's `refinement.steps`.
//!
//! The key results ([`quantities`]): the force of every displacement-driven (or fixed) punch
//! (`<punch>_force`), the travel of every force-driven punch (`<punch>_travel`; its force is given), the mid-surface deflection of largest magnitude over the
//! plate (`max_deflection`) and the deflection of every named point (`<point>_u3`).
//!
//! history.csv keeps its columns and gains, at the end: `max_deflection` (this run's), then per key
//! result q: `q_refined` (`q_refined2`, ... for further levels), `q_estimate`, `q_error_pct` (this
//! run's estimated error, 100 (q - q_estimate) / |q_estimate|), `q_refined_error_pct` (...), and
//! with two levels or more `q_order` (the order used).

use crate::outputs::history::{sig, History, HistoryRow};
use crate::outputs::table::{column, render_columns, step_columns};
use crate::refine::richardson::{extrapolate, Estimate, ASSUMED_ORDER};
use crate::schema::units::Units;
use serde_json::{json, Map, Value};

/// Which number of a history row a key result is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    Force(usize),
    Travel(usize),
    MaxDeflection,
    PointU3(usize),
}

/// One key result.
#[derive(Debug, Clone)]
pub struct Quantity {
    /// Its name in history.csv and summary.json, e.g. "sphere_force".
    pub key: String,
    /// Its name in the table, e.g. "sphere force".
    pub label: String,
    pub unit: String,
    pub kind: Kind,
}

impl Quantity {
    /// Its value in a row.
    pub fn value(&self, r: &HistoryRow) -> f64 {
        match self.kind {
            Kind::Force(k) => r.punches[k].force,
            Kind::Travel(k) => r.punches[k].travel,
            Kind::MaxDeflection => r.max_deflection,
            Kind::PointU3(k) => r.points[k][2],
        }
    }

    /// Shown in the end-of-run table (the named points are in history.csv and summary.json only).
    fn in_table(&self) -> bool {
        !matches!(self.kind, Kind::PointU3(_))
    }
}

/// The key results of a history; `force_driven[k]`: punch k is pressed with a force (its travel
/// is then the result, its force is given).
pub fn quantities(h: &History, force_driven: &[bool], units: &Units) -> Vec<Quantity> {
    let mut q = Vec::new();
    for (k, name) in h.punch_names.iter().enumerate() {
        if force_driven.get(k).copied().unwrap_or(false) {
            q.push(Quantity { key: format!("{name}_travel"), label: format!("{name} travel"), unit: units.length.clone(), kind: Kind::Travel(k) });
        } else {
            q.push(Quantity { key: format!("{name}_force"), label: format!("{name} force"), unit: units.force.clone(), kind: Kind::Force(k) });
        }
    }
    q.push(Quantity { key: "max_deflection".into(), label: "max deflection".into(), unit: units.length.clone(), kind: Kind::MaxDeflection });
    for (k, (name, _)) in h.points.iter().enumerate() {
        q.push(Quantity { key: format!("{name}_u3"), label: format!("{name} u3"), unit: units.length.clone(), kind: Kind::PointU3(k) });
    }
    q
}

/// For each row of `coarse`, the row of `fine` at the same load factor, matched in order (the
/// finer run passes through the coarse run's load factors; between them it may cut back).
pub fn match_rows(coarse: &History, fine: &History) -> Vec<Option<usize>> {
    let mut j = 0;
    coarse
        .rows
        .iter()
        .map(|r| {
            let k = (j..fine.rows.len()).find(|&k| fine.rows[k].load_factor == r.load_factor)?;
            j = k + 1;
            Some(k)
        })
        .collect()
}

/// The name of refinement level `level` (1-based): "refined", "refined2", ..., in column names and
/// as the level's folder inside the output folder ([`crate::refine::level_folder`]).
pub fn level_name(level: usize) -> String {
    if level == 1 {
        "refined".into()
    } else {
        format!("refined{level}")
    }
}

/// The estimates of every key result at every step of the coarse run.
#[derive(Debug, Clone)]
pub struct Report {
    /// Refinements (meshes - 1).
    pub levels: usize,
    pub quantities: Vec<Quantity>,
    /// Per coarse row: the row number of each finer run, and per quantity its estimate.
    pub steps: Vec<(Vec<usize>, Vec<Estimate>)>,
}

impl Report {
    /// Compare `coarse` with the finer runs `fines` (each refined once more). A coarse step that a
    /// finer run did not reach is an error that names its load factor.
    pub fn new(coarse: &History, fines: &[History], quantities: Vec<Quantity>) -> Result<Report, String> {
        let matches: Vec<Vec<Option<usize>>> = fines.iter().map(|f| match_rows(coarse, f)).collect();
        let mut steps = Vec::with_capacity(coarse.rows.len());
        for (i, r) in coarse.rows.iter().enumerate() {
            let mut rows = Vec::with_capacity(fines.len());
            for (l, m) in matches.iter().enumerate() {
                rows.push(m[i].ok_or_else(|| format!("the mesh refined {} did not reach load factor {} (step {} of the run on the problem's mesh)", times(l + 1), sig(r.load_factor), r.step))?);
            }
            let estimates = quantities
                .iter()
                .map(|q| {
                    let mut values = vec![q.value(r)];
                    values.extend(rows.iter().zip(fines).map(|(&k, f)| q.value(&f.rows[k])));
                    extrapolate(&values)
                })
                .collect();
            steps.push((rows.iter().zip(fines).map(|(&k, f)| f.rows[k].step).collect(), estimates));
        }
        Ok(Report { levels: fines.len(), quantities, steps })
    }

    /// history.csv of the coarse run with the columns of the module notes appended.
    pub fn csv(&self, coarse: &History) -> String {
        let base = coarse.csv();
        let mut lines = base.lines();
        let mut header = lines.next().unwrap_or_default().to_string();
        header.push_str(",max_deflection");
        for q in &self.quantities {
            for l in 1..=self.levels {
                header.push_str(&format!(",{}_{}", q.key, level_name(l)));
            }
            header.push_str(&format!(",{0}_estimate,{0}_error_pct", q.key));
            for l in 1..=self.levels {
                header.push_str(&format!(",{}_{}_error_pct", q.key, level_name(l)));
            }
            if self.levels >= 2 {
                header.push_str(&format!(",{}_order", q.key));
            }
        }
        let mut out = header + "\n";
        for ((line, r), (_, estimates)) in lines.zip(&coarse.rows).zip(&self.steps) {
            out.push_str(line);
            out.push_str(&format!(",{:e}", r.max_deflection));
            for e in estimates {
                for v in &e.values[1..] {
                    out.push_str(&format!(",{v:e}"));
                }
                out.push_str(&format!(",{:e}", e.value));
                for k in 0..e.values.len() {
                    out.push_str(&format!(",{:e}", e.percent(k).unwrap_or(f64::NAN)));
                }
                if self.levels >= 2 {
                    out.push_str(&format!(",{:e}", e.order));
                }
            }
            out.push('\n');
        }
        out
    }

    /// The tables under the run's table: one per key result (but the named points), a row per
    /// step with this run's value, the refined values, the estimate and each run's estimated error
    /// in percent (and the order used, with two levels or more).
    pub fn tables(&self, coarse: &History) -> String {
        let mut out = String::new();
        for (i, q) in self.quantities.iter().enumerate() {
            if !q.in_table() {
                continue;
            }
            let mut cols = step_columns(coarse);
            let mut group = format!("{}:", q.label);
            let mut take = |header: String, values: Vec<String>| {
                cols.push(column(std::mem::take(&mut group), header, values));
            };
            let est = |f: &dyn Fn(&Estimate) -> String| self.steps.iter().map(|(_, e)| f(&e[i])).collect::<Vec<String>>();
            take(Units::label("this mesh", &q.unit), est(&|e| sig(e.values[0])));
            for l in 1..=self.levels {
                let name = if l == 1 { "refined".to_string() } else { format!("refined {l}") };
                take(Units::label(&name, &q.unit), est(&|e| sig(e.values[l])));
            }
            take(Units::label("estimate", &q.unit), est(&|e| sig(e.value)));
            take("error %".into(), est(&|e| percent(e.percent(0))));
            for l in 1..=self.levels {
                let name = if l == 1 { "refined error %".to_string() } else { format!("refined {l} error %") };
                take(name, est(&|e| percent(e.percent(l))));
            }
            if self.levels >= 2 {
                take("order".into(), est(&|e| format!("{:.2}", e.order)));
            }
            out.push('\n');
            out.push_str(&render_columns(&cols));
        }
        out
    }

    /// summary.json's `refinement.steps`: per coarse step its load factor, the finer runs' step
    /// numbers and per key result the values, estimate, order and errors.
    pub fn json_steps(&self, coarse: &History) -> Value {
        let steps: Vec<Value> = coarse
            .rows
            .iter()
            .zip(&self.steps)
            .map(|(r, (rows, estimates))| {
                let mut results = Map::new();
                for (q, e) in self.quantities.iter().zip(estimates) {
                    results.insert(
                        q.key.clone(),
                        json!({
                            "values": e.values,
                            "estimate": e.value,
                            "order": e.order,
                            "observed_order": e.observed_order,
                            "errors": e.errors,
                            "errors_percent": (0..e.values.len()).map(|k| e.percent(k)).collect::<Vec<_>>(),
                        }),
                    );
                }
                json!({ "step": r.step, "load_factor": r.load_factor, "refined_steps": rows, "results": results })
            })
            .collect();
        Value::Array(steps)
    }

    /// The order summary.json states: the assumed one with a single refinement.
    pub fn assumed_order(&self) -> f64 {
        ASSUMED_ORDER
    }
}

/// "once", "twice", "3 times".
pub fn times(level: usize) -> String {
    match level {
        1 => "once".into(),
        2 => "twice".into(),
        n => format!("{n} times"),
    }
}

/// A percentage in the table: three decimals ("+1.234"), tiny ones in exponent form ("+4.5e-4"),
/// "-" when there is none (the estimate is 0 and the value is not).
pub fn percent(p: Option<f64>) -> String {
    match p {
        Some(x) if x == 0.0 => "0".into(),
        Some(x) if x.is_finite() && x.abs() < 0.01 => format!("{x:+.1e}"),
        Some(x) if x.is_finite() => format!("{x:+.3}"),
        _ => "-".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outputs::history::PunchRow;
    use stamp_elements::Face;

    fn history(rows: &[(f64, f64, f64)]) -> History {
        let mut h = History::new(&[("ball".into(), Face::Top, false)], &[("center".into(), vec![0])]);
        for (k, &(t, force, w)) in rows.iter().enumerate() {
            h.rows.push(HistoryRow {
                step: k + 1,
                load_factor: t,
                path: t,
                newton_iterations: 3,
                punches: vec![PunchRow { travel: t, force, contact_area: 1.0, max_pressure: 2.0, max_penetration: 0.0, force_on_punch: [0.0; 3], dissipation: None }],
                points: vec![[0.0, 0.0, w]],
                max_deflection: w,
                supports: vec![],
                plastic: None,
            });
        }
        h
    }

    fn units() -> Units {
        Units { length: "mm".into(), force: "N".into(), pressure: "MPa".into(), area: "mm^2".into(), length_given: true, force_given: true }
    }

    #[test]
    fn fine_rows_are_matched_by_load_factor_in_order() {
        let coarse = history(&[(0.5, 10.0, -1.0), (1.0, 20.0, -2.0), (0.5, 11.0, -1.1)]);
        // the fine run cut back once (0.75) and passes 0.5 twice
        let fine = history(&[(0.5, 9.0, -0.9), (0.75, 14.0, -1.4), (1.0, 18.0, -1.8), (0.5, 10.0, -1.0)]);
        assert_eq!(match_rows(&coarse, &fine), vec![Some(0), Some(2), Some(3)]);
        let short = history(&[(0.5, 9.0, -0.9)]);
        assert_eq!(match_rows(&coarse, &short), vec![Some(0), None, None]);
        let q = quantities(&coarse, &[false], &units());
        let e = Report::new(&coarse, &[short], q).unwrap_err();
        assert!(e.contains("load factor 1.00000") && e.contains("refined once"), "{e}");
    }

    #[test]
    fn columns_csv_and_json_say_the_same() {
        let coarse = history(&[(0.5, 10.0, -1.0), (1.0, 20.0, -2.0)]);
        let fine = history(&[(0.5, 9.0, -0.9), (0.75, 14.0, -1.4), (1.0, 18.0, -1.8)]);
        let q = quantities(&coarse, &[false], &units());
        assert_eq!(q.iter().map(|q| q.key.as_str()).collect::<Vec<_>>(), ["ball_force", "max_deflection", "center_u3"]);
        let r = Report::new(&coarse, &[fine], q).unwrap();
        // step 2: 20 -> 18, p = 2: estimate 18 - 2/3 = 17.3333; errors 15.38 % and 3.846 %
        let e = &r.steps[1].1[0];
        assert!((e.value - (18.0 - 2.0 / 3.0)).abs() < 1e-12);
        assert_eq!(r.steps[1].0, vec![3], "the fine run's step number");
        let csv = r.csv(&coarse);
        let lines: Vec<&str> = csv.lines().collect();
        let header: Vec<&str> = lines[0].split(',').collect();
        assert_eq!(header[..7], ["step", "load_factor", "path", "ball_travel", "ball_force", "ball_contact_area", "ball_max_pressure"], "the columns of plain history.csv come first");
        let at = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("{name} in {header:?}"));
        let row: Vec<f64> = lines[2].split(',').map(|v| v.parse().unwrap()).collect();
        assert_eq!(row[at("ball_force_refined")], 18.0);
        assert!((row[at("ball_force_estimate")] - e.value).abs() < 1e-12);
        assert!((row[at("ball_force_error_pct")] - 100.0 * (2.0 + 2.0 / 3.0) / e.value).abs() < 1e-9);
        assert!((row[at("ball_force_refined_error_pct")] - 100.0 * (2.0 / 3.0) / e.value).abs() < 1e-9);
        assert_eq!(row[at("max_deflection")], -2.0);
        assert_eq!(row[at("center_u3_refined")], -1.8);
        let tables = r.tables(&coarse);
        let lines: Vec<&str> = tables.lines().collect();
        // a blank line, then per key result its name, the header and one row per step
        assert_eq!(lines.len(), 2 * 5, "{tables}");
        assert!(lines[1].contains("ball force:") && lines[6].contains("max deflection:") && !tables.contains("center u3"), "{tables}");
        for head in ["step", "load factor", "this mesh (N)", "refined (N)", "estimate (N)", "error %", "refined error %"] {
            assert!(lines[2].contains(head), "{head}: {tables}");
        }
        let last: Vec<&str> = lines[4].split_whitespace().collect();
        assert_eq!(last, ["2", "1.00000", "20.0000", "18.0000", "17.3333", "+15.385", "+3.846"], "{tables}");
        assert!(lines[9].contains("-2.00000") && lines[9].contains("-1.80000"), "{tables}");
        let j = r.json_steps(&coarse);
        assert_eq!(j[1]["results"]["ball_force"]["values"], json!([20.0, 18.0]));
        assert!((j[1]["results"]["ball_force"]["errors_percent"][0].as_f64().unwrap() - 15.384615).abs() < 1e-5);
        assert_eq!(j[1]["results"]["ball_force"]["observed_order"], Value::Null);
        assert_eq!(j[1]["refined_steps"], json!([3]));
    }
}

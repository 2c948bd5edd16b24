//! The table `stamp run` prints on stdout at the end: one row per converged step with the load
//! factor, each punch's travel, force, contact area, peak pressure and largest penetration, and the
//! Newton iterations. Numbers have 6 significant digits ([`sig`]); columns are right-aligned under a
//! two-line header (the punch's name over its columns, then quantity and unit).

use crate::outputs::history::{sig, History};
use crate::schema::units::Units;

/// One number of a punch's row.
type Quantity = fn(&crate::outputs::history::PunchRow) -> f64;

/// One column: the punch's name over its first column (else empty), the header, the values (one
/// per row of the history).
pub struct Column {
    pub group: String,
    pub header: String,
    pub values: Vec<String>,
}

/// A column of the table.
pub fn column(group: String, header: impl Into<String>, values: Vec<String>) -> Column {
    Column { group, header: header.into(), values }
}

/// The table text (ends with a newline; empty when no step converged).
pub fn render(h: &History, units: &Units) -> String {
    if h.rows.is_empty() {
        return String::new();
    }
    let mut cols = step_columns(h);
    for (k, name) in h.punch_names.iter().enumerate() {
        let quantities: [(String, Quantity); 5] = [
            (Units::label("travel", &units.length), |p| p.travel),
            (Units::label("force", &units.force), |p| p.force),
            (Units::label("contact area", &units.area), |p| p.contact_area),
            (Units::label("peak pressure", &units.pressure), |p| p.max_pressure),
            (Units::label("penetration", &units.length), |p| p.max_penetration),
        ];
        for (i, (header, get)) in quantities.into_iter().enumerate() {
            let group = if i == 0 { format!("{name}:") } else { String::new() };
            cols.push(column(group, header, h.rows.iter().map(|r| sig(get(&r.punches[k]))).collect()));
        }
    }
    cols.push(column(String::new(), "Newton", h.rows.iter().map(|r| r.newton_iterations.to_string()).collect()));
    render_columns(&cols)
}

/// The step and load-factor columns of a history (the first two of every table).
pub fn step_columns(h: &History) -> Vec<Column> {
    vec![
        column(String::new(), "step", h.rows.iter().map(|r| r.step.to_string()).collect()),
        column(String::new(), "load factor", h.rows.iter().map(|r| sig(r.load_factor)).collect()),
    ]
}

/// Columns as a table: right-aligned under the header, the groups' line above it when any column
/// has a group; one row per value.
pub fn render_columns(cols: &[Column]) -> String {
    let rows = cols.first().map(|c| c.values.len()).unwrap_or(0);
    let widths: Vec<usize> = cols.iter().map(|c| c.values.iter().map(|s| s.len()).chain([c.header.chars().count(), c.group.chars().count()]).max().unwrap_or(0)).collect();
    let mut out = String::new();
    if cols.iter().any(|c| !c.group.is_empty()) {
        let line: Vec<String> = cols.iter().zip(&widths).map(|(c, &w)| format!("{:<w$}", c.group)).collect();
        out.push_str(line.join("  ").trim_end());
        out.push('\n');
    }
    let line: Vec<String> = cols.iter().zip(&widths).map(|(c, &w)| format!("{:>w$}", c.header)).collect();
    out.push_str(&line.join("  "));
    out.push('\n');
    for i in 0..rows {
        let line: Vec<String> = cols.iter().zip(&widths).map(|(c, &w)| format!("{:>w$}", c.values[i])).collect();
        out.push_str(&line.join("  "));
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::outputs::history::{HistoryRow, PunchRow};
    use stamp_elements::Face;

    #[test]
    fn one_row_per_step_with_units_in_the_header() {
        let mut h = History::new(&[("sphere".into(), Face::Top, true)], &[]);
        for (k, t) in [0.5, 1.0].iter().enumerate() {
            h.rows.push(HistoryRow {
                step: k + 1,
                load_factor: *t,
                path: *t,
                newton_iterations: 4 + k,
                punches: vec![PunchRow { travel: 0.5 * t, force: 500.0 * t, contact_area: 3.0, max_pressure: 12.5, max_penetration: 1e-7, force_on_punch: [0.0; 3], dissipation: None }],
                points: vec![],
                max_deflection: -0.1 * t,
                supports: vec![],
                plastic: None,
            });
        }
        let units = Units { length: "mm".into(), force: "N".into(), pressure: "MPa".into(), area: "mm^2".into(), length_given: true, force_given: true };
        let text = render(&h, &units);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 4, "{text}");
        assert!(lines[0].starts_with("  ") && lines[0].contains("sphere:"), "{text}");
        for head in ["step", "load factor", "travel (mm)", "force (N)", "contact area (mm^2)", "peak pressure (MPa)", "penetration (mm)", "Newton"] {
            assert!(lines[1].contains(head), "{head} missing: {text}");
        }
        let last: Vec<&str> = lines[3].split_whitespace().collect();
        assert_eq!(last, ["2", "1.00000", "0.500000", "500.000", "3.00000", "12.5000", "1.00000e-7", "5"], "{text}");
    }
}

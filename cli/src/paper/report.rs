//! The text report of the paper's benchmark: Tables 1 and 2 in the paper's layout, ours beside the paper's.

use super::tables::{PaperReport, Table2Row, ZoneRow};

fn pct(x: f64) -> String {
    format!("{:+.3}%", 100.0 * x)
}

/// "one", "two", ... nodes.
fn nodes(k: i64) -> String {
    let word = ["no", "one", "two", "three", "four", "five"].get(k.unsigned_abs() as usize).map(|w| w.to_string()).unwrap_or(k.abs().to_string());
    format!("{word} node{}", if k.abs() == 1 { "" } else { "s" })
}

/// Where Table 2's b_ext lies against the paper's, in nodes of `spacing` mm, from the rows
/// themselves: "Table 2's b_ext lies one node inside the paper's (two at P = 2.50)".
fn b_ext_note(rows: &[Table2Row], spacing: f64) -> String {
    let ks: Vec<i64> = rows.iter().map(|r| ((r.paper[1] - r.b_ext) / spacing).round() as i64).collect();
    // the most frequent count first, the others by their loads
    let mut counts: Vec<(i64, usize)> = Vec::new();
    for &k in &ks {
        match counts.iter_mut().find(|(c, _)| *c == k) {
            Some(e) => e.1 += 1,
            None => counts.push((k, 1)),
        }
    }
    counts.sort_by(|a, b| b.1.cmp(&a.1));
    let side = |k: i64| if k >= 0 { "inside" } else { "outside" };
    let Some(&(main, _)) = counts.first() else { return String::new() };
    let mut note = if main == 0 { "Table 2's b_ext is the paper's".to_string() } else { format!("Table 2's b_ext lies {} {} the paper's", nodes(main), side(main)) };
    let others: Vec<String> = rows
        .iter()
        .zip(&ks)
        .filter(|(_, &k)| k != main)
        .map(|(r, &k)| if k == 0 { format!("equal at P = {:.2}", r.p) } else { format!("{} {} at P = {:.2}", nodes(k), side(k), r.p) })
        .collect();
    if !others.is_empty() {
        note.push_str(&format!(" ({})", others.join(", ")));
    }
    note
}

/// Format the report as text tables.
pub fn format_report(r: &PaperReport) -> String {
    let mut s = String::new();
    s.push_str("stamp: the paper's section-5 benchmark (half plate, 40 elements, plane strain)\n\n");
    s.push_str("Table 1. R = 1000 mm (shallow), P/2 on each end. Zones [b_int, b_ext] in mm: ours (paper); v3(l) in mm: ours, paper, difference\n");
    s.push_str(&format!("{:>5} | {:^25} {:>8} {:>7} {:>9} | {:^25} {:>8} {:>7} {:>9}\n", "P", "linear zone", "v3", "paper", "diff", "nonlinear zone", "v3", "paper", "diff"));
    for row in &r.table1 {
        let zone = |z: &ZoneRow| format!("[{:>4.1}, {:>4.1}] ({:>4.1}, {:>4.1})", z.b_int, z.b_ext, z.paper[0], z.paper[1]);
        s.push_str(&format!(
            "{:>5.1} | {:<25} {:>8.4} {:>7.3} {:>9} | {:<25} {:>8.4} {:>7.3} {:>9}\n",
            row.p,
            zone(&row.linear),
            row.linear.v3,
            row.linear.paper[2],
            pct(row.linear.v3_rel_diff),
            zone(&row.nonlinear),
            row.nonlinear.v3,
            row.nonlinear.paper[2],
            pct(row.nonlinear.v3_rel_diff)
        ));
    }
    s.push_str("\nTable 2. R = 100 mm (non-shallow, nonlinear), P on each end\n");
    s.push_str(&format!("{:>6} | {:>6} {:>6} | {:>6} {:>6} | {:>8} {:>7} {:>9} | {:>14} | {:>6}\n", "P", "b_int", "paper", "b_ext", "paper", "v3", "paper", "diff", "reaction", "Newton"));
    for row in &r.table2 {
        s.push_str(&format!(
            "{:>6.2} | {:>6.1} {:>6.1} | {:>6.1} {:>6.1} | {:>8.4} {:>7.2} {:>9} | {:>14.10} | {:>6}\n",
            row.p, row.b_int, row.paper[0], row.b_ext, row.paper[1], row.v3, row.paper[2], pct(row.v3_rel_diff), row.reaction, row.newton_iterations
        ));
    }
    s.push_str(&format!(
        "\nReaction check (P = 20): contact reaction of the half plate {:.11} N/mm for an end force of {} N/mm (relative difference {:.1e}; the paper: 20.00000002)\n",
        r.reaction_check.ours, r.reaction_check.paper, r.reaction_check.rel_diff
    ));
    let spacing = {
        let p = super::strip::StripProblem::paper(100.0, stamp_elements::Kinematics::Nonlinear);
        p.half_length / p.elements as f64
    };
    s.push_str(&format!("Zones: nodes whose |lambda| exceeds 0.5 % of the largest. {}; docs/verification/paper.md\n", b_ext_note(&r.table2, spacing)));
    s.push_str("says why we do not tune to it. The geometric active sets are in `stamp paper --json`.\n");
    let iters: usize = r.table1.iter().map(|x| x.linear.newton_iterations + x.nonlinear.newton_iterations).sum::<usize>() + r.table2.iter().map(|x| x.newton_iterations).sum::<usize>();
    s.push_str(&format!("Newton iterations: {iters} in all; wall time {:.3} s\n", r.seconds));
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(p: f64, b_ext: f64, paper: f64) -> Table2Row {
        Table2Row { p, b_int: 0.0, b_ext, v3: 0.0, reaction: 0.0, load_per_end: p, paper: [0.0, paper, 0.0], v3_rel_diff: 0.0, active_set: Vec::new(), newton_iterations: 0, max_penetration: 0.0 }
    }

    #[test]
    fn the_b_ext_note_counts_the_nodes_of_every_row() {
        let rows = [row(1.25, 0.0, 2.5), row(2.5, 32.5, 37.5), row(5.0, 62.5, 65.0)];
        assert_eq!(b_ext_note(&rows, 2.5), "Table 2's b_ext lies one node inside the paper's (two nodes inside at P = 2.50)");
        assert_eq!(b_ext_note(&rows[..1], 2.5), "Table 2's b_ext lies one node inside the paper's");
        assert_eq!(b_ext_note(&[row(1.0, 5.0, 5.0)], 2.5), "Table 2's b_ext is the paper's");
    }
}

//! The text report of the paper's benchmark: Tables 1 and 2 in the paper's layout, ours beside the paper's.

use super::tables::{PaperReport, ZoneRow};

fn pct(x: f64) -> String {
    format!("{:+.3}%", 100.0 * x)
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
    s.push_str("Zones: nodes whose |lambda| exceeds 0.5 % of the largest. Table 2's b_ext lies one node inside the paper's; docs/verification.md\n");
    s.push_str("(\"The paper's benchmark\") says why we do not tune to it. The geometric active sets are in `stamp paper --json`.\n");
    let iters: usize = r.table1.iter().map(|x| x.linear.newton_iterations + x.nonlinear.newton_iterations).sum::<usize>() + r.table2.iter().map(|x| x.newton_iterations).sum::<usize>();
    s.push_str(&format!("Newton iterations: {iters} in all; wall time {:.3} s\n", r.seconds));
    s
}

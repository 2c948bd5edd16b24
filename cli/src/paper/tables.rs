//! Tables 1 and 2 of the paper (its section 5): the paper's values, ours beside them, and the
//! reaction check. Table 1: R = 1000 mm, each end carries P/2, linear and nonlinear; Table 2:
//! R = 100 mm, each end carries P, nonlinear.

use super::strip::{solve_strip, StripProblem, StripResult};
use serde::Serialize;
use stamp::Result;
use stamp_elements::Kinematics;
use std::time::Instant;

/// One row of the paper's Table 1 or 2 with our value beside it.
#[derive(Debug, Clone, Serialize)]
pub struct Compared {
    pub paper: f64,
    pub ours: f64,
    pub rel_diff: f64,
}

fn cmp(paper: f64, ours: f64) -> Compared {
    Compared { paper, ours, rel_diff: if paper != 0.0 { (ours - paper) / paper } else { ours - paper } }
}

/// Table 1 and 2 of the paper (its section 5).
pub const TABLE1: [(f64, [f64; 3], [f64; 3]); 6] = [
    (0.1, [0.0, 0.0, 1.138], [0.0, 0.0, 1.138]),
    (0.3, [0.0, 2.5, 3.410], [0.0, 2.5, 3.407]),
    (0.5, [40.0, 42.5, 4.427], [40.0, 42.5, 4.419]),
    (1.0, [70.0, 72.5, 4.857], [70.0, 72.5, 4.846]),
    (2.0, [85.0, 87.5, 4.965], [85.0, 87.5, 4.952]),
    (3.0, [90.0, 92.5, 4.985], [90.0, 92.5, 4.971]),
];
pub const TABLE2: [(f64, [f64; 3]); 5] = [
    (1.25, [0.0, 2.5, 26.39]),
    (2.5, [0.0, 37.5, 39.62]),
    (5.0, [0.0, 65.0, 43.85]),
    (10.0, [0.0, 82.5, 45.11]),
    (20.0, [0.0, 92.5, 45.50]),
];

#[derive(Debug, Clone, Serialize)]
pub struct ZoneRow {
    pub b_int: f64,
    pub b_ext: f64,
    pub v3: f64,
    pub paper: [f64; 3],
    pub v3_rel_diff: f64,
    pub active_set: Vec<f64>,
    pub newton_iterations: usize,
}

#[derive(Debug, Clone, Serialize)]
pub struct Table1Row {
    #[serde(rename = "P")]
    pub p: f64,
    pub linear: ZoneRow,
    pub nonlinear: ZoneRow,
}

#[derive(Debug, Clone, Serialize)]
pub struct Table2Row {
    #[serde(rename = "P")]
    pub p: f64,
    pub b_int: f64,
    pub b_ext: f64,
    pub v3: f64,
    pub reaction: f64,
    pub load_per_end: f64,
    pub paper: [f64; 3],
    pub v3_rel_diff: f64,
    pub active_set: Vec<f64>,
    pub newton_iterations: usize,
    pub max_penetration: f64,
}

/// The whole benchmark.
#[derive(Debug, Clone, Serialize)]
pub struct PaperReport {
    pub table1: Vec<Table1Row>,
    pub table2: Vec<Table2Row>,
    pub seconds: f64,
    /// The reaction check at P = 20 (Table 2): contact reaction and end force.
    pub reaction_check: Compared,
}

fn zone_row(r: &StripResult, paper: [f64; 3]) -> ZoneRow {
    ZoneRow {
        b_int: r.b_int,
        b_ext: r.b_ext,
        v3: r.v3,
        paper,
        v3_rel_diff: cmp(paper[2], r.v3).rel_diff,
        active_set: r.active_x2.clone(),
        newton_iterations: r.newton_iterations,
    }
}

/// Run Table 1 (linear and nonlinear, R = 1000, P/2 per end) and Table 2 (R = 100, P per end).
pub fn run_paper() -> Result<PaperReport> {
    let start = Instant::now();
    let t1_loads: Vec<f64> = TABLE1.iter().map(|r| 0.5 * r.0).collect();
    let t2_loads: Vec<f64> = TABLE2.iter().map(|r| r.0).collect();
    // the three load paths are independent: solve them side by side (each is too small to use
    // more than one thread by itself)
    let (nl, (lin, t2)) = rayon::join(
        || solve_strip(&StripProblem::paper(1000.0, Kinematics::Nonlinear), &t1_loads),
        || {
            rayon::join(
                || solve_strip(&StripProblem::paper(1000.0, Kinematics::Linear), &t1_loads),
                || solve_strip(&StripProblem::paper(100.0, Kinematics::Nonlinear), &t2_loads),
            )
        },
    );
    let (lin, nl, t2) = (lin?, nl?, t2?);
    let table1 = TABLE1
        .iter()
        .zip(lin.iter().zip(&nl))
        .map(|(row, (a, b))| Table1Row { p: row.0, linear: zone_row(a, row.1), nonlinear: zone_row(b, row.2) })
        .collect();
    let table2: Vec<Table2Row> = TABLE2
        .iter()
        .zip(&t2)
        .map(|(row, r)| Table2Row {
            p: row.0,
            b_int: r.b_int,
            b_ext: r.b_ext,
            v3: r.v3,
            reaction: r.reaction,
            load_per_end: r.load_per_end,
            paper: row.1,
            v3_rel_diff: cmp(row.1[2], r.v3).rel_diff,
            active_set: r.active_x2.clone(),
            newton_iterations: r.newton_iterations,
            max_penetration: r.max_penetration,
        })
        .collect();
    let last = t2.last().expect("five loads");
    Ok(PaperReport {
        table1,
        reaction_check: cmp(last.load_per_end, last.reaction),
        table2,
        seconds: start.elapsed().as_secs_f64(),
    })
}

//! The paper's Figure 4 redrawn: the dimensionless contact pressure along the deformed plate for
//! several loads (R = 100, nonlinear), as PNG, SVG and the CSV of the plotted points.

use super::strip::{solve_strip, StripProblem};
use stamp_problem::plot::{write_plot, Plot, Series};
use stamp::io::write_string_atomically;
use stamp::StampError;
use stamp_elements::Kinematics;
use std::path::{Path, PathBuf};

/// The load parameters P~ = 16 P R^2 / (E h) of the redrawn Figure 4.
pub const FIGURE4_LOADS: [f64; 7] = [1.0, 2.0, 5.0, 10.0, 20.0, 40.0, 80.0];

/// Redraw the paper's Figure 4 into `dir`: the dimensionless contact pressure
/// q~ = 16 q_n R^2 l / (E h^3) along the deformed plate against the deformed x2, for the load
/// parameters [`FIGURE4_LOADS`] (R = 100, nonlinear), as figure4.png, figure4.svg and figure4.csv.
/// Returns the paths written: PNG, SVG, CSV.
pub fn write_figure4(dir: &Path) -> stamp::Result<[PathBuf; 3]> {
    std::fs::create_dir_all(dir).map_err(|e| StampError::io(dir, e))?;
    let problem = StripProblem::paper(100.0, Kinematics::Nonlinear);
    let (e, h, r, l) = (problem.young, problem.thickness, problem.radius, problem.half_length);
    let loads: Vec<f64> = FIGURE4_LOADS.iter().map(|pt| pt * e * h / (16.0 * r * r)).collect();
    let results = solve_strip(&problem, &loads)?;
    let scale = 16.0 * r * r * l / (e * h * h * h);
    let mut csv = String::from("P_tilde,P_per_end,x2,x2_deformed,x3_deformed,q_n,q_tilde\n");
    let mut series = Vec::new();
    for (pt, res) in FIGURE4_LOADS.iter().zip(&results) {
        let mut pts = Vec::new();
        for k in 0..res.x2.len() {
            let q = res.pressure[k];
            csv.push_str(&format!("{pt},{:e},{:e},{:e},{:e},{:e},{:e}\n", res.load_per_end, res.x2[k], res.deformed[k][0], res.deformed[k][1], q, scale * q));
            pts.push((res.deformed[k][0], scale * q));
        }
        series.push(Series { label: format!("P~ = {pt}"), points: pts, markers: Vec::new() });
    }
    let csv_path = dir.join("figure4.csv");
    write_string_atomically(&csv_path, &csv)?;
    let plot = Plot {
        title: "Figure 4: contact pressure along the deformed plate (R = 100)",
        x_label: "deformed x2 (mm)",
        y_label: "q~ = 16 q_n R^2 l / (E h^3)",
        series: &series,
    };
    let [png, svg] = write_plot(&dir.join("figure4"), &plot)?;
    Ok([png, svg, csv_path])
}

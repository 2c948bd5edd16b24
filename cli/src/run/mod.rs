//! `stamp run`: problem files, the generic solve pipeline and its outputs.

use std::path::Path;

/// Run the problem file `problem`, writing into `out`.
pub fn run_command(problem: &Path, _out: Option<&Path>, _quiet: bool) -> stamp::Result<()> {
    Err(stamp::StampError::Problem(format!("{}: `stamp run` is not available yet", problem.display())))
}

/// Redraw the paper's Figure 4 into `dir`.
pub fn plot_paper_figure4(dir: &Path) -> stamp::Result<()> {
    Err(stamp::StampError::Problem(format!("{}: plots are not available yet", dir.display())))
}

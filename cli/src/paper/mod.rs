//! `stamp paper`: the paper's section-5 benchmark. An infinitely long plate
//! (plane strain) of length 2l is bent around a fixed rigid cylinder by equal end forces towards
//! the punch; the program reproduces the paper's Tables 1 and 2, the reaction check and Figure 4.
//!
//! * [`strip`]: the strip's model and its solve along a list of end forces;
//! * [`tables`]: the paper's Tables 1 and 2, ours beside them ([`tables::run_paper`]);
//! * [`report`]: the tables printed as text in the paper's layout;
//! * [`figure4`]: the contact pressure along the plate redrawn (PNG, SVG, CSV).

pub mod figure4;
pub mod report;
pub mod strip;
pub mod tables;

use std::path::Path;

/// The line `stamp paper --plot DIR` prints once Figure 4 is written: where its files are.
pub fn figure4_written_message(dir: &Path) -> String {
    format!("stamp paper: Figure 4 written to {}, .svg, .csv", dir.join("figure4.png").display())
}

/// `stamp paper [--json] [--plot DIR]`: the tables as text (or JSON), then Figure 4 into `DIR`
/// when asked, saying where it was written (on stderr with `--json`, so stdout stays JSON).
pub fn paper_command(json: bool, plot: Option<&Path>) -> stamp::Result<()> {
    let report = tables::run_paper()?;
    if json {
        crate::outln!("{}", serde_json::to_string_pretty(&report).map_err(|e| stamp::StampError::Problem(e.to_string()))?);
    } else {
        crate::out!("{}", report::format_report(&report));
    }
    if let Some(dir) = plot {
        figure4::write_figure4(dir)?;
        let message = figure4_written_message(dir);
        if json {
            eprintln!("{message}");
        } else {
            crate::outln!("\n{message}");
        }
    }
    Ok(())
}

//! `stamp`: elastic plates pressed by rigid punches. With no arguments it runs the paper's benchmark.

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(name = "stamp", version, about = "Finite elements for elastic plates in contact with rigid punches (Kulikov & Plotnikova's mixed plate)")]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Reproduce the paper's section-5 benchmark: Tables 1 and 2 and the reaction check.
    Paper {
        /// Print the results as JSON.
        #[arg(long)]
        json: bool,
        /// Redraw the paper's Figure 4 (contact pressure along the plate, R = 100) into this folder.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Solve the problem a TOML problem file describes; write VTK, summary.json and CSV files.
    Run {
        /// The problem file (see meshes/*.toml).
        problem: PathBuf,
        /// Output folder (default: next to the problem file, named after it).
        #[arg(long)]
        out: Option<PathBuf>,
        /// No progress bar.
        #[arg(long, short)]
        quiet: bool,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => stamp_cli::report::paper_command(false, None),
        Some(Command::Paper { json, plot }) => stamp_cli::report::paper_command(json, plot.as_deref()),
        Some(Command::Run { problem, out, quiet }) => stamp_cli::run::run_command(&problem, out.as_deref(), quiet),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

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
        /// Print nothing but warnings and errors: no progress, no table (the outputs are written
        /// all the same).
        #[arg(long, short)]
        quiet: bool,
        /// Also solve on the mesh refined LEVELS times (default 1; each cell into 4 every time) at
        /// the same load steps, and report the Richardson estimate of the mesh-converged results
        /// and each run's estimated error (the refined runs' outputs go to OUT/refined/, ...).
        #[arg(long, value_name = "LEVELS", num_args = 0..=1, require_equals = true, default_missing_value = "1", value_parser = clap::value_parser!(u8).range(1..=3))]
        refine: Option<u8>,
    },
    /// Read and build a problem file, say what is wrong with it (rigid motions held by nothing,
    /// a punch starting inside the plate, empty groups; warnings for punches that move away or sit
    /// on the other side) and print a summary of the model, without solving.
    Check {
        /// The problem file (see meshes/*.toml).
        problem: PathBuf,
    },
    /// Time the solve of the simply supported plate under a sphere (quarter model) on n x n meshes.
    Bench {
        /// Mesh sizes n (n x n elements on the quarter), comma separated (default 25,50,100,200,400;
        /// with --problem sphere-displacement 10,20,40,80,160).
        #[arg(long, value_delimiter = ',')]
        sizes: Option<Vec<usize>>,
        /// Print the results as JSON: {"runs": [...]}.
        #[arg(long)]
        json: bool,
        /// Reuse a factorisation across Newton iterations as GMRES's preconditioner while that is
        /// cheaper than factorising again (default: factorise every iteration's matrix).
        #[arg(long)]
        reuse: bool,
        /// Precondition GMRES with the LDL^T of the tangent's symmetric part instead of the
        /// plate's P (its tangent without the one-way thickness coupling; the default, about half
        /// the GMRES iterations): for comparison.
        #[arg(long)]
        symmetric_part: bool,
        /// The problem: `sphere` (the default: R = 50 moved down 2 onto the plate of side 100),
        /// `sphere-displacement` (meshes/sphere-ss-displacement.toml on n x n meshes) or
        /// `sphere-slide` (meshes/sphere-slide.toml on 4n x n meshes).
        #[arg(long, value_enum, default_value = "sphere")]
        problem: stamp_cli::bench::BenchProblem,
        /// With --problem sphere-displacement: start every load step from the solution on the
        /// mesh with half the n (`[solver] predictor = "coarse"`) instead of the secant predictor.
        #[arg(long, value_enum, default_value = "secant")]
        predictor: stamp_cli::bench::BenchPredictor,
        /// Coulomb friction coefficient between the punch and the plate (default 0: frictionless).
        #[arg(long, default_value_t = 0.0)]
        friction: f64,
        /// Run one size in this process and print its JSON (used by `stamp bench` for each size).
        #[arg(long, hide = true)]
        one: Option<usize>,
    },
}

fn main() -> ExitCode {
    // `--refine 2 P.toml` is read as `--refine=2 P.toml`, `--refine P.toml` as `--refine=1 P.toml`
    let cli = match Cli::try_parse_from(stamp_cli::run::refine::join_refine_value(std::env::args_os())) {
        Ok(cli) => cli,
        // --help and --version: on stdout, through the printer that reports a failed write
        Err(e) if !e.use_stderr() => {
            stamp_cli::out!("{e}");
            return match stamp_cli::stdout::finish() {
                Ok(()) => ExitCode::SUCCESS,
                Err(w) => {
                    eprintln!("error: cannot write to stdout: {w}");
                    ExitCode::FAILURE
                }
            };
        }
        Err(e) => e.exit(),
    };
    // `mpirun -n P stamp ...`: PETSc and MPI for the whole command (see mpi.rs)
    #[cfg(feature = "petsc")]
    let mut ranks = match stamp_cli::mpi::Ranks::start() {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::FAILURE;
        }
    };
    // under MPI only rank 0 writes files (the paper's figure too)
    let writes = stamp_problem::parallel::writes_outputs();
    let result = match cli.command {
        None => stamp_cli::paper::paper_command(false, None),
        Some(Command::Paper { json, plot }) => stamp_cli::paper::paper_command(json, plot.as_deref().filter(|_| writes)),
        Some(Command::Run { problem, out, quiet, refine }) => stamp_cli::commands::run_command(&problem, out.as_deref(), quiet, refine.map(usize::from)),
        Some(Command::Check { problem }) => stamp_cli::commands::check_command(&problem),
        Some(Command::Bench { one: Some(n), reuse, symmetric_part, problem, predictor, friction, .. }) => stamp_cli::bench::one_command(n, stamp_cli::bench::SolverOptions { reuse, symmetric_part, problem, predictor, friction }),
        Some(Command::Bench { sizes, json, reuse, symmetric_part, problem, predictor, friction, one: None }) => {
            let sizes = sizes.unwrap_or_else(|| problem.default_sizes().to_vec());
            stamp_cli::bench::bench_command(&sizes, json, stamp_cli::bench::SolverOptions { reuse, symmetric_part, problem, predictor, friction })
        }
    };
    // a reader that closed stdout early is no error; a stdout that cannot be written (a full disk,
    // /dev/full) is, once the command has done the rest of its work
    let stdout = stamp_cli::stdout::finish();
    let result = result.map_err(|e| e.to_string());
    // every rank ends with the same outcome
    #[cfg(feature = "petsc")]
    let result = ranks.finish(result);
    let code = match (result, stdout) {
        (Ok(()), Ok(())) => ExitCode::SUCCESS,
        (Ok(()), Err(e)) => {
            eprintln!("error: cannot write to stdout: {e}");
            ExitCode::FAILURE
        }
        (Err(e), _) => {
            eprintln!("error: {e}");
            // ended by Ctrl-C or SIGTERM: the status a shell gives a process the signal ended
            match stamp_cli::run::interrupt::received() {
                Some(signal) => ExitCode::from(stamp_cli::run::interrupt::exit_status(signal)),
                None => ExitCode::FAILURE,
            }
        }
    };
    #[cfg(feature = "petsc")]
    ranks.end();
    code
}

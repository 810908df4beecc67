//! `wingman-planner`: the planner service binary and its offline commands. `main` only
//! parses arguments, sets up logging and calls into the library.

use std::process::ExitCode;

use clap::{Parser, Subcommand};
use wingman_planner::scenario::load_by_path_or_name;

/// Onboard route planner of the loyal wingman.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Checks a scenario file (or a bundled scenario's name) and prints its summary.
    Check {
        /// A scenario file in the format of scenarios/FORMAT.md, or a bundled name.
        scenario: String,
    },
}

fn main() -> ExitCode {
    wingman_planner::logging::init();
    match Cli::parse().command {
        Command::Check { scenario } => match load_by_path_or_name(&scenario) {
            Ok(sc) => {
                println!("{sc}");
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        },
    }
}

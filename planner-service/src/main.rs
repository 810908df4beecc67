//! `wingman-planner`: the planner service binary and its offline commands. `main` only
//! parses arguments, sets up logging and calls into the library.

use std::process::ExitCode;

use std::path::PathBuf;
use std::time::Duration;

use clap::{Parser, Subcommand};
use wingman_planner::clock::MonotonicClock;
use wingman_planner::offline::{PlanRequest, plan_scenario, summary};
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
    /// Plans a scenario's take-off plan (threats known at t0; moving threats from their
    /// initial estimate) and writes plan.csv (the judge's format) and plan.json.
    Plan {
        /// A scenario file in the format of scenarios/FORMAT.md, or a bundled name.
        scenario: String,
        /// Seed of the particle swarm.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Compute budget in milliseconds (default: 2000 for 2-D, 5000 for 3-D).
        #[arg(long)]
        deadline_ms: Option<u64>,
        /// Output folder (default: runs/<scenario>/plan).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    wingman_planner::logging::init();
    match Cli::parse().command {
        Command::Plan {
            scenario,
            seed,
            deadline_ms,
            out,
        } => {
            let sc = match load_by_path_or_name(&scenario) {
                Ok(sc) => sc,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
            let out_dir = out.unwrap_or_else(|| PathBuf::from("runs").join(&sc.name).join("plan"));
            let request = PlanRequest {
                scenario: sc,
                seed,
                deadline: deadline_ms.map(Duration::from_millis),
                out_dir,
            };
            let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
            match plan_scenario(&request, clock) {
                Ok(outcome) => {
                    println!("{}", summary(&request.scenario, &outcome));
                    println!("wrote {}/plan.csv and plan.json", request.out_dir.display());
                    ExitCode::SUCCESS
                }
                Err(e) => {
                    eprintln!("error: {e:#}");
                    ExitCode::from(1)
                }
            }
        }
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

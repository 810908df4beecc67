//! `wingman-planner`: the planner service binary and its offline commands. `main` only
//! parses arguments, sets up logging, wires the configuration, the clock and signal
//! handling, and calls into the library (`service::run` for `serve`).

use std::process::ExitCode;

use std::path::PathBuf;
use std::time::Duration;

use clap::{Parser, Subcommand};
use wingman_planner::offline::{PlanRequest, plan_scenario, summary};
use wingman_planner::service::{RunOptions, ServiceConfig, Shutdown};
use wingman_planning::clock::MonotonicClock;
use wingman_planning::cuts::ReplayCuts;
use wingman_planning::scenario::load_by_path_or_name;

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
        /// Plan with the yardstick of global optimality (a far wider global search, each
        /// run from its own seed, 60 s per run unless --deadline-ms says otherwise) instead
        /// of the deployment settings. Not for flight: it judges the default plan.
        #[arg(long)]
        exhaustive: bool,
        /// Runs of the yardstick (with --exhaustive).
        #[arg(long, default_value_t = 3, requires = "exhaustive")]
        runs: usize,
    },
    /// Runs the planner service (iceoryx2 node of one vehicle; stops on SIGTERM/SIGINT).
    ///
    /// Subscribes to tasking, lead route and state, threats, track fixes and ownship over
    /// iceoryx2; plans only when triggered; publishes plans and a heartbeat status. Stops
    /// on SIGTERM or SIGINT with exit code 0 (2: bad configuration, 1: cannot start).
    /// Logs go to stderr: RUST_LOG sets the level, WINGMAN_LOG_FORMAT=json gives JSON
    /// lines, IOX2_LOG_LEVEL sets iceoryx2's own (default error). See docs/DEPLOYMENT.md.
    Serve {
        /// Configuration file (planner.toml); every setting has a default, so without it
        /// the defaults apply.
        #[arg(long, value_name = "FILE")]
        config: Option<PathBuf>,
        /// Vehicle id (overrides `vehicle_id` of the configuration): the services are
        /// wingman/<ID>/...
        #[arg(long, value_name = "ID")]
        vehicle: Option<String>,
        /// Prints the effective configuration as TOML and exits.
        #[arg(long)]
        print_config: bool,
        /// Replay: plan with no compute deadline, taking instead the deadline cuts logged
        /// with a flight's plans (written by `wingman-harness replay`; see
        /// docs/ARCHITECTURE.md, "Deadline cuts"). Not for flight.
        #[arg(long, value_name = "FILE")]
        replay_cuts: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    wingman_ipc::logging::init();
    match Cli::parse().command {
        Command::Serve {
            config,
            vehicle,
            print_config,
            replay_cuts,
        } => serve(config, vehicle, print_config, replay_cuts),
        Command::Plan {
            scenario,
            seed,
            deadline_ms,
            out,
            exhaustive,
            runs,
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
                exhaustive_runs: exhaustive.then_some(runs),
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

/// `serve`: configuration, clock, signals, then `service::run`.
fn serve(
    config: Option<PathBuf>,
    vehicle: Option<String>,
    print_config: bool,
    replay_cuts: Option<PathBuf>,
) -> ExitCode {
    let mut cfg = match &config {
        Some(path) => match ServiceConfig::load(path) {
            Ok(c) => c,
            Err(e) => {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
        },
        None => ServiceConfig::default(),
    };
    if let Some(id) = vehicle {
        cfg.vehicle_id = id;
    }
    if let Err(e) = cfg.validate() {
        eprintln!("error: {e}");
        return ExitCode::from(2);
    }
    if print_config {
        print!("{}", cfg.to_toml());
        return ExitCode::SUCCESS;
    }
    let replay_cuts = match replay_cuts.as_deref().map(read_replay_cuts).transpose() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    // iceoryx2 logs through its own console logger: errors only unless IOX2_LOG_LEVEL
    // says otherwise (its "no config file, defaults used" warning is expected here).
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Error);
    // Deadlines need a `&'static dyn Clock`: one clock for the process's lifetime.
    let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
    let options = RunOptions {
        config: cfg,
        clock,
        handle_signals: true,
        shutdown: Shutdown::new(),
        replay_cuts,
    };
    match wingman_planner::service::run(options) {
        Ok(summary) => {
            tracing::info!(
                exit = ?summary.exit,
                plans = summary.status.plans_made,
                received = summary.status.messages_received,
                rejected = summary.status.messages_rejected,
                "planner service stopped"
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            tracing::error!(error = %e, "planner service failed");
            eprintln!("error: {e}");
            ExitCode::from(1)
        }
    }
}

/// The deadline cuts of `--replay-cuts FILE`.
fn read_replay_cuts(path: &std::path::Path) -> Result<ReplayCuts, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    ReplayCuts::parse(&text).map_err(|e| format!("{}: {e}", path.display()))
}

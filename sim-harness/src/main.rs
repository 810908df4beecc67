//! `wingman-harness`: flies scenarios against the planner process. `main` only parses
//! arguments, sets up logging and calls into the library.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use wingman_harness::clock::ClockMode;
use wingman_harness::mission::{self, FlyOptions, PlannerMode};
use wingman_ipc::ServiceConfig;
use wingman_planning::scenario::load_by_path_or_name;

/// Simulation harness of the wingman planner.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Flies a scenario end to end against the planner process.
    Fly {
        /// A scenario file in the format of scenarios/FORMAT.md, or a bundled name.
        scenario: String,
        #[command(flatten)]
        fly: FlyArgs,
        /// Output folder (default runs/<scenario>/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Take over the mission a planner is already flying (after its harness died):
        /// start at the planner's mission time on its current plan, with the scenario's
        /// world as it stands then (needs --planner external).
        #[arg(long)]
        resume: bool,
    },
    /// Feeds a flight log's planner inputs to the planner in-process and checks that
    /// every plan comes out byte-identical (exit 1 if not).
    Replay {
        /// A `flight.log` written by `fly`.
        log: PathBuf,
        /// Longest wait for the planner at one step, s.
        #[arg(long, default_value_t = 300)]
        timeout_s: u64,
    },
    /// Flies every canonical scenario (`scenarios/*.toml`, else the bundled ones), replays
    /// each log, and prints the table of outcomes (Markdown); exit 1 if any fails.
    FlyAll {
        #[command(flatten)]
        fly: FlyArgs,
        /// Folder of the scenarios.
        #[arg(long, default_value = "scenarios")]
        scenarios: PathBuf,
        /// Each flight's outputs go to <OUT_ROOT>/<scenario>/.
        #[arg(long, default_value = "runs")]
        out_root: PathBuf,
        /// Skip the replays.
        #[arg(long)]
        no_replay: bool,
    },
    /// Lists the bundled scenarios with their summaries.
    List,
}

#[derive(clap::Args, Clone)]
struct FlyArgs {
    /// Mission clock: `fast` (lock-step, compute time charged), `realtime`, or `x<K>`.
    #[arg(long, default_value = "fast")]
    clock: ClockMode,
    /// `spawn` starts `wingman-planner serve` (next to this binary); `external` uses a
    /// planner already serving `--vehicle`.
    #[arg(long, default_value = "spawn", value_parser = ["spawn", "external"])]
    planner: String,
    /// Vehicle id (default: a fresh one per run with `spawn`, `w1` with `external`).
    #[arg(long)]
    vehicle: Option<String>,
    /// Planner configuration for a spawned planner (default: the deployment defaults of
    /// planner.toml, heartbeat 200 ms; written to <out>/planner.toml).
    #[arg(long, value_name = "FILE")]
    planner_config: Option<PathBuf>,
    /// End the flight at this mission time if the plan has not ended, s.
    #[arg(long)]
    time_limit: Option<f64>,
    /// No progress line.
    #[arg(long)]
    quiet: bool,
    /// Fault injection (tests): SIGKILL the spawned planner at this mission time, fly on
    /// the last plan without it for --restart-after seconds, then start a new planner.
    #[arg(long, value_name = "S")]
    kill_planner_at: Option<f64>,
    /// Mission time without a planner after --kill-planner-at, s.
    #[arg(long, value_name = "S", default_value_t = 10.0)]
    restart_after: f64,
    /// Fault injection (tests): from this mission time, send a burst of
    /// --popup-burst-count pop-ups within one second, on the flown plan ahead.
    #[arg(long, value_name = "S")]
    popup_burst_at: Option<f64>,
    /// Pop-up reports in the burst.
    #[arg(long, value_name = "N", default_value_t = 100)]
    popup_burst_count: u32,
}

fn main() -> ExitCode {
    wingman_ipc::logging::init();
    iceoryx2::prelude::set_log_level_from_env_or(iceoryx2::prelude::LogLevel::Error);
    match Cli::parse().command {
        Command::List => match wingman_harness::list_bundled() {
            Ok(rows) => {
                for (name, summary) in rows {
                    println!("{name:<36} {summary}");
                }
                ExitCode::SUCCESS
            }
            Err(e) => {
                eprintln!("error: {e}");
                ExitCode::from(2)
            }
        },
        Command::FlyAll {
            fly,
            scenarios,
            out_root,
            no_replay,
        } => {
            let all = match wingman_harness::fly_all::canonical(&scenarios) {
                Ok(all) if !all.is_empty() => all,
                Ok(_) => {
                    eprintln!("error: no scenarios in {}", scenarios.display());
                    return ExitCode::from(2);
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
            let mut opts = FlyOptions::new(all[0].clone());
            if let Err(e) = apply(&fly, &mut opts) {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
            let rows = wingman_harness::fly_all::fly_all(&all, &opts, &out_root, !no_replay);
            print!("{}", wingman_harness::fly_all::table(&rows));
            if rows.iter().all(|r| r.passes()) {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(1)
            }
        }
        Command::Replay { log, timeout_s } => {
            match wingman_harness::replay::replay(&log, std::time::Duration::from_secs(timeout_s)) {
                Ok(o) => {
                    println!("{o}");
                    if o.all_identical() {
                        ExitCode::SUCCESS
                    } else {
                        ExitCode::from(1)
                    }
                }
                Err(e) => {
                    eprintln!("error: {e}");
                    ExitCode::from(2)
                }
            }
        }
        Command::Fly {
            scenario,
            fly,
            out,
            resume,
        } => {
            if resume && fly.planner != "external" {
                eprintln!(
                    "error: {}",
                    wingman_harness::resume::ResumeError::NotExternal
                );
                return ExitCode::from(2);
            }
            let sc = match load_by_path_or_name(&scenario) {
                Ok(sc) => sc,
                Err(e) => {
                    eprintln!("error: {e}");
                    return ExitCode::from(2);
                }
            };
            let mut opts = FlyOptions::new(sc);
            if let Some(out) = out {
                opts.out_dir = out;
            }
            if let Err(e) = apply(&fly, &mut opts) {
                eprintln!("error: {e}");
                return ExitCode::from(2);
            }
            opts.resume = resume;
            fly_one(&opts)
        }
    }
}

/// Applies the command-line flags to the options.
fn apply(args: &FlyArgs, opts: &mut FlyOptions) -> Result<(), String> {
    opts.clock = args.clock;
    opts.progress = !args.quiet;
    if let Some(t) = args.time_limit
        && !t.is_finite()
    {
        return Err(format!(
            "--time-limit must be a finite mission time, got {t}"
        ));
    }
    opts.time_limit_s = args.time_limit;
    for (flag, v) in [
        ("--kill-planner-at", args.kill_planner_at),
        ("--restart-after", Some(args.restart_after)),
        ("--popup-burst-at", args.popup_burst_at),
    ] {
        if let Some(v) = v
            && !(v.is_finite() && v >= 0.0)
        {
            return Err(format!(
                "{flag} must be a finite, non-negative time, got {v}"
            ));
        }
    }
    if args.kill_planner_at.is_some() && args.planner == "external" {
        return Err("--kill-planner-at needs a spawned planner (not --planner external)".into());
    }
    opts.faults = mission::Faults {
        kill_planner_at_s: args.kill_planner_at,
        restart_after_s: args.restart_after,
        popup_burst_at_s: args.popup_burst_at,
        popup_burst_count: args.popup_burst_count,
    };
    if let Some(path) = &args.planner_config {
        opts.planner_config = ServiceConfig::load(path).map_err(|e| e.to_string())?;
    }
    match args.planner.as_str() {
        "external" => {
            opts.planner = PlannerMode::External;
            opts.planner_config.vehicle_id = args.vehicle.clone().unwrap_or_else(|| "w1".into());
        }
        _ => {
            opts.planner = PlannerMode::Spawn { binary: None };
            opts.planner_config.vehicle_id = args
                .vehicle
                .clone()
                .unwrap_or_else(|| mission::unique_vehicle_id("fly"));
        }
    }
    opts.planner_config.validate().map_err(|e| e.to_string())
}

fn fly_one(opts: &FlyOptions) -> ExitCode {
    match wingman_harness::run_fly(opts) {
        Ok((_, summary)) => {
            println!("{summary}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

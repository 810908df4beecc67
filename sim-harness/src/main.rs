//! `wingman-harness`: flies scenarios against the planner process. `main` only parses
//! arguments, sets up logging and calls into the library.

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Parser, Subcommand};
use wingman_harness::campaign;
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
    /// Flies a campaign of random well-posed missions (or one shard of it), plans each
    /// take-off again with the yardstick of global optimality, and writes results.json,
    /// report.md, summary.json and charts into --out. `campaign merge` joins shards.
    /// Exit 1 if the campaign misses a bar (docs/CAMPAIGN.md); a shard exits 0 once it
    /// ran (its merge gives the verdict).
    Campaign(CampaignCmd),
}

#[derive(clap::Args)]
#[command(args_conflicts_with_subcommands = true)]
struct CampaignCmd {
    #[command(subcommand)]
    merge: Option<CampaignSub>,
    #[command(flatten)]
    run: CampaignArgs,
}

#[derive(Subcommand)]
enum CampaignSub {
    /// Builds one campaign's results and report from its shards' (results.json files or
    /// their folders); exit 1 if it misses a bar.
    Merge {
        /// The shards' results.
        #[arg(required = true)]
        shards: Vec<PathBuf>,
        /// Folder of the merged results and report.
        #[arg(long)]
        out: PathBuf,
    },
}

#[derive(clap::Args)]
struct CampaignArgs {
    /// Missions in the campaign.
    #[arg(long, default_value_t = 30)]
    count: usize,
    /// Seed of the missions (mission i of seed S is the same in any run or shard).
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Flights at a time, each with its own planner process.
    #[arg(long, default_value_t = 1)]
    jobs: usize,
    /// Run only slice i of n (0 <= i < n): the missions whose index is i modulo n.
    #[arg(long, value_name = "I/N")]
    shard: Option<String>,
    /// Only this model (2d, 3d; repeatable).
    #[arg(long = "model")]
    models: Vec<String>,
    /// Only this objective (fixed-time, min-time, min-time-rendezvous; repeatable).
    #[arg(long = "objective")]
    objectives: Vec<String>,
    /// Every mission has this feature (unavoidable, moving, popups, lead-change;
    /// repeatable; a mission whose layout had no room for it is drawn again).
    #[arg(long = "with")]
    with: Vec<String>,
    /// No mission has this feature (repeatable).
    #[arg(long = "without")]
    without: Vec<String>,
    /// Output folder (default runs/campaign-<seed>, or runs/campaign-<seed>-shard-<i>-of-<n>).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Runs of the yardstick per take-off.
    #[arg(long, default_value_t = 2)]
    yardstick_runs: usize,
    /// Budget of each yardstick run, s.
    #[arg(long, default_value_t = 60.0)]
    yardstick_budget_s: f64,
    /// Do not plan the take-offs with the yardstick (no gap is measured).
    #[arg(long)]
    no_yardstick: bool,
    /// Plan the take-off of every K-th mission (index 0, K, 2K, ...) also with the
    /// independent solver (CasADi + IPOPT, needs python3 with casadi, numpy, scipy); 0:
    /// none.
    #[arg(long, value_name = "K", default_value_t = 0)]
    independent_every: usize,
    /// The independent solver's script.
    #[arg(
        long,
        value_name = "FILE",
        default_value = "tools/yardstick/ipopt_multistart.py"
    )]
    independent_solver: PathBuf,
    /// An argument passed to the independent solver (repeatable), e.g.
    /// `--independent-arg=--bulges=0` for its straight start only.
    #[arg(
        long = "independent-arg",
        value_name = "ARG",
        allow_hyphen_values = true
    )]
    independent_args: Vec<String>,
    /// Planner configuration of the flights (default: the deployment defaults).
    #[arg(long, value_name = "FILE")]
    planner_config: Option<PathBuf>,
    /// Keep every mission's folder (default: only the failed and outlying ones).
    #[arg(long)]
    keep_all: bool,
    /// No progress line.
    #[arg(long)]
    quiet: bool,
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
        Command::Campaign(c) => match c.merge {
            Some(CampaignSub::Merge { shards, out }) => campaign_merge(&shards, &out),
            None => campaign(&c.run),
        },
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

/// The options of a campaign run from its flags.
fn campaign_options(a: &CampaignArgs) -> Result<campaign::run::RunOptions, String> {
    use campaign::kind::{Feature, Filter};
    use campaign::run::{CampaignSpec, RunOptions, Shard, YardstickSpec};
    let features = |names: &[String]| -> Result<Vec<Feature>, String> {
        names.iter().map(|n| Feature::parse(n)).collect()
    };
    let filter = Filter {
        models: a.models.clone(),
        objectives: a.objectives.clone(),
        with: features(&a.with)?,
        without: features(&a.without)?,
    };
    filter.validate()?;
    if a.count == 0 {
        return Err("--count must be at least 1".into());
    }
    if a.jobs == 0 {
        return Err("--jobs must be at least 1".into());
    }
    if !(a.yardstick_budget_s > 0.0
        && std::time::Duration::try_from_secs_f64(a.yardstick_budget_s).is_ok())
    {
        return Err("--yardstick-budget-s must be a positive number of seconds".into());
    }
    if a.yardstick_runs == 0 {
        return Err("--yardstick-runs must be at least 1 (or --no-yardstick)".into());
    }
    if a.independent_every == 0 && !a.independent_args.is_empty() {
        return Err("--independent-arg needs --independent-every K (K >= 1)".into());
    }
    if a.independent_every > 0 {
        independent_solver_ready(&a.independent_solver)?;
    }
    let shard = match &a.shard {
        Some(s) => Shard::parse(s)?,
        None => Shard::WHOLE,
    };
    let out = a.out.clone().unwrap_or_else(|| {
        let name = if shard == Shard::WHOLE {
            format!("campaign-{}", a.seed)
        } else {
            format!("campaign-{}-shard-{}-of-{}", a.seed, shard.index, shard.of)
        };
        PathBuf::from("runs").join(name)
    });
    let mut planner_config = match &a.planner_config {
        Some(path) => ServiceConfig::load(path).map_err(|e| e.to_string())?,
        None => mission::harness_planner_config("campaign"),
    };
    planner_config.status.heartbeat_ms = 200;
    planner_config.validate().map_err(|e| e.to_string())?;
    Ok(RunOptions {
        spec: CampaignSpec {
            seed: a.seed,
            count: a.count,
            filter,
            yardstick: (!a.no_yardstick).then_some(YardstickSpec {
                runs: a.yardstick_runs,
                budget_s: a.yardstick_budget_s,
                seed: 1,
            }),
            planner_config: a.planner_config.as_ref().map(|p| p.display().to_string()),
            independent_every: a.independent_every,
            independent_args: a.independent_args.clone(),
        },
        shard,
        jobs: a.jobs,
        out_dir: out,
        planner_config,
        keep_all: a.keep_all,
        independent_solver: a.independent_solver.clone(),
        progress: !a.quiet,
    })
}

/// Whether the independent solver can run: its script is there, and python3 imports what
/// it needs (else every chosen mission would fail after its flight).
fn independent_solver_ready(script: &std::path::Path) -> Result<(), String> {
    if !script.is_file() {
        return Err(format!(
            "--independent-solver {}: no such file (run from the repository's root, or give \
             its path)",
            script.display()
        ));
    }
    let imports = std::process::Command::new("python3")
        .args(["-c", "import casadi, numpy, scipy"])
        .output();
    match imports {
        Ok(o) if o.status.success() => Ok(()),
        _ => Err(
            "--independent-every needs python3 with casadi, numpy and scipy: \
             python3 -m pip install -r tools/yardstick/requirements.txt"
                .into(),
        ),
    }
}

fn campaign(a: &CampaignArgs) -> ExitCode {
    let opts = match campaign_options(a) {
        Ok(o) => o,
        Err(e) => {
            eprintln!("error: {e}");
            return ExitCode::from(2);
        }
    };
    match campaign::run::run(&opts) {
        // A shard's verdict is the merge's to give: a scheduler must not retry a shard
        // that ran.
        Ok(results) if opts.shard != campaign::run::Shard::WHOLE => {
            let _ = report_campaign(&opts.out_dir, &results);
            ExitCode::SUCCESS
        }
        Ok(results) => report_campaign(&opts.out_dir, &results),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn campaign_merge(shards: &[PathBuf], out: &std::path::Path) -> ExitCode {
    match campaign::merge::merge(shards, out) {
        Ok(results) => report_campaign(out, &results),
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// Writes the report, prints its verdict; exit 1 if the campaign misses a bar.
fn report_campaign(out: &std::path::Path, results: &campaign::run::CampaignResults) -> ExitCode {
    use campaign::summary::{Verdict, write_report};
    if let Err(e) = write_report(out, results) {
        eprintln!("error: {e:#}");
        return ExitCode::from(1);
    }
    let v = Verdict::of(results);
    println!(
        "{} of {} missions meet the criteria; {} of {} take-off plans within 0.5 % of the yardstick; {} missing. Report: {}/report.md",
        v.meeting,
        v.missions,
        v.within,
        v.judged,
        v.missing.len(),
        out.display()
    );
    if v.passes() {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(1)
    }
}

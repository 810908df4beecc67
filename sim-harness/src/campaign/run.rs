//! Running a campaign, or one shard of it: each mission drawn, flown end to end against
//! its own planner process (`jobs` at a time, each on its own vehicle id), its take-off
//! planned again with the yardstick, its outcome added to `results.json` as it lands.
//! A mission that fails or whose take-off plan is outside the yardstick's tolerance keeps
//! its folder (scenario file, `report.json`, `flight.log`, `planner.log`), so it can be
//! flown alone again; the others' folders are removed unless asked to keep them.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};
use wingman_ipc::ServiceConfig;
use wingman_planning::clock::MonotonicClock;
use wingman_planning::hybrid::{Exhaustive, plan_exhaustive};
use wingman_planning::problem::Problem;
use wingman_planning::scenario::Scenario;
use wingman_planning::trajectory::Trajectory;

use super::generate::{Drawn, draw};
use super::independent::{self, IndependentNumbers, PlanJson};
use super::kind::Filter;
use super::outcome::{FlightNumbers, MissionOutcome, YardstickNumbers, finite};
use super::progress::Progress;
use crate::mission::{self, FlyOptions};

/// Version of the results file's layout.
pub const RESULTS_FORMAT: u32 = 1;

/// One slice of a campaign: the missions whose index is `index` modulo `of`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    pub index: usize,
    pub of: usize,
}

impl Shard {
    /// The whole campaign.
    pub const WHOLE: Shard = Shard { index: 0, of: 1 };

    /// Parses `i/n` (`0 <= i < n`).
    pub fn parse(s: &str) -> Result<Shard, String> {
        let bad = || format!("shard `{s}`: expected i/n with 0 <= i < n (e.g. 0/4)");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, of) = (
            i.trim().parse::<usize>().map_err(|_| bad())?,
            n.trim().parse::<usize>().map_err(|_| bad())?,
        );
        if of == 0 || index >= of {
            return Err(bad());
        }
        Ok(Shard { index, of })
    }

    /// The indices of this shard among `count` missions.
    pub fn indices(&self, count: usize) -> Vec<usize> {
        (self.index..count).step_by(self.of).collect()
    }
}

/// The yardstick's settings as the results record them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct YardstickSpec {
    pub runs: usize,
    pub budget_s: f64,
    pub seed: u64,
}

impl YardstickSpec {
    fn exhaustive(&self) -> Exhaustive {
        Exhaustive {
            runs: self.runs,
            budget: Duration::from_secs_f64(self.budget_s),
            seed: self.seed,
        }
    }
}

/// What defines a campaign: two runs with the same spec draw the same missions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignSpec {
    pub seed: u64,
    pub count: usize,
    pub filter: Filter,
    /// `None`: no yardstick (the gap is not measured).
    pub yardstick: Option<YardstickSpec>,
    /// The planner configuration file the flights used (`None`: the deployment defaults).
    #[serde(default)]
    pub planner_config: Option<String>,
    /// The independent solver plans the take-off of every this many missions (0: none).
    #[serde(default)]
    pub independent_every: usize,
    /// Arguments passed to the independent solver.
    #[serde(default)]
    pub independent_args: Vec<String>,
}

/// The results file of a campaign or of some of its shards.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignResults {
    pub format: u32,
    pub spec: CampaignSpec,
    /// The shards these results hold.
    pub shards: Vec<Shard>,
    /// When and where each shard ran: `started` UTC, host, cores.
    pub runs: Vec<RunRecord>,
    /// In index order.
    pub outcomes: Vec<MissionOutcome>,
}

/// When and where one shard ran.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunRecord {
    pub shard: Shard,
    pub started_utc: String,
    pub host: String,
    pub cores: usize,
    pub jobs: usize,
    pub wall_s: f64,
}

/// How to run a campaign.
#[derive(Debug, Clone)]
pub struct RunOptions {
    pub spec: CampaignSpec,
    pub shard: Shard,
    pub jobs: usize,
    pub out_dir: PathBuf,
    /// Planner configuration of every flight (its vehicle id is replaced per flight).
    pub planner_config: ServiceConfig,
    /// Keep every mission's folder, not only the failed and outlying ones.
    pub keep_all: bool,
    /// The independent solver's script (`tools/yardstick/ipopt_multistart.py`).
    pub independent_solver: PathBuf,
    pub progress: bool,
}

/// Runs the options' shard of the campaign and writes `results.json` into the output
/// folder after every mission; returns the results.
pub fn run(opts: &RunOptions) -> anyhow::Result<CampaignResults> {
    use anyhow::Context;
    opts.spec.filter.validate().map_err(anyhow::Error::msg)?;
    let missions_dir = opts.out_dir.join("missions");
    std::fs::create_dir_all(&missions_dir)
        .with_context(|| format!("create {}", missions_dir.display()))?;
    let indices = opts.shard.indices(opts.spec.count);
    let started = Instant::now();
    let mut results = CampaignResults {
        format: RESULTS_FORMAT,
        spec: opts.spec.clone(),
        shards: vec![opts.shard],
        runs: vec![RunRecord {
            shard: opts.shard,
            started_utc: utc_now(),
            host: host_name(),
            cores: std::thread::available_parallelism().map_or(1, |n| n.get()),
            jobs: opts.jobs,
            wall_s: 0.0,
        }],
        outcomes: Vec::new(),
    };
    let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
    let next = AtomicUsize::new(0);
    let shared = Mutex::new((results.clone(), Progress::new(opts.progress, indices.len())));
    std::thread::scope(|scope| {
        for _ in 0..opts.jobs.clamp(1, indices.len().max(1)) {
            scope.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(&index) = indices.get(k) else {
                        break;
                    };
                    let drawn = draw(opts.spec.seed, index, &opts.spec.filter);
                    // A panic in one mission is that mission's error, not the campaign's end.
                    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                        fly_mission(opts, &drawn, &missions_dir, clock)
                    }))
                    .unwrap_or_else(|panic| {
                        let what = panic
                            .downcast_ref::<String>()
                            .cloned()
                            .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                            .unwrap_or_default();
                        let mut o = MissionOutcome::not_flown(
                            drawn.index,
                            &drawn.name,
                            &drawn.kind,
                            format!("panicked: {what}"),
                        );
                        o.kept = Some(format!("missions/{}", drawn.name));
                        o
                    });
                    let mut guard = shared.lock().unwrap_or_else(|p| p.into_inner());
                    let (res, progress) = &mut *guard;
                    progress.done(&outcome);
                    res.outcomes.push(outcome);
                    res.outcomes.sort_by_key(|o| o.index);
                    res.runs[0].wall_s = started.elapsed().as_secs_f64();
                    if let Err(e) = write_results(&opts.out_dir, res) {
                        tracing::error!("writing the results: {e:#}");
                    }
                }
            });
        }
    });
    let (done, progress) = shared.into_inner().unwrap_or_else(|p| p.into_inner());
    progress.finish();
    results.outcomes = done.outcomes;
    results.runs[0].wall_s = started.elapsed().as_secs_f64();
    write_results(&opts.out_dir, &results)?;
    Ok(results)
}

/// Flies one mission in `missions_dir/<name>/`, plans its take-off with the yardstick, and
/// keeps or removes its folder.
fn fly_mission(
    opts: &RunOptions,
    drawn: &Drawn,
    missions_dir: &Path,
    clock: &'static MonotonicClock,
) -> MissionOutcome {
    let started = Instant::now();
    let dir = missions_dir.join(&drawn.name);
    let mut outcome =
        MissionOutcome::not_flown(drawn.index, &drawn.name, &drawn.kind, String::new());
    match fly_and_judge(opts, drawn, &dir, clock) {
        Ok(judged) => {
            outcome.error = None;
            outcome.misses = judged.flight.misses(&drawn.kind);
            outcome.flight = Some(judged.flight);
            match judged.yardstick {
                Some(Ok(y)) => outcome.yardstick = Some(y),
                Some(Err(e)) => outcome.yardstick_error = Some(e),
                None => {}
            }
            match judged.independent {
                Some(Ok(i)) => outcome.independent = Some(i),
                Some(Err(e)) => outcome.independent_error = Some(e),
                None => {}
            }
        }
        Err(e) => outcome.error = Some(format!("{e:#}")),
    }
    // A mission where the independent solver beat the yardstick is kept too.
    let beaten = outcome
        .yardstick_vs_independent()
        .is_some_and(|g| g > super::outcome::GAP_TOL);
    if opts.keep_all || outcome.outlying() || beaten {
        outcome.kept = Some(format!("missions/{}", drawn.name));
    } else if let Err(e) = std::fs::remove_dir_all(&dir) {
        tracing::warn!("removing {}: {e}", dir.display());
    }
    outcome.wall_s = started.elapsed().as_secs_f64();
    outcome
}

/// What one mission measured: the flight, and the take-off by the yardstick and the
/// independent solver (or why they could not plan it: the flight stands either way).
struct Judged {
    flight: FlightNumbers,
    yardstick: Option<Result<YardstickNumbers, String>>,
    independent: Option<Result<IndependentNumbers, String>>,
}

/// Flies one mission and plans its take-off with the yardstick and, if it is one of
/// theirs, the independent solver.
fn fly_and_judge(
    opts: &RunOptions,
    drawn: &Drawn,
    dir: &Path,
    clock: &'static MonotonicClock,
) -> anyhow::Result<Judged> {
    use anyhow::Context;
    std::fs::create_dir_all(dir).with_context(|| format!("create {}", dir.display()))?;
    let file = dir.join(format!("{}.toml", drawn.name));
    std::fs::write(&file, &drawn.text).with_context(|| format!("write {}", file.display()))?;
    let scenario = Scenario::load(&file)?;
    let mut fly = FlyOptions::new(scenario.clone());
    fly.out_dir = dir.to_path_buf();
    fly.progress = false;
    fly.planner_config = opts.planner_config.clone();
    fly.planner_config.vehicle_id = mission::unique_vehicle_id(&format!("cmp{}", drawn.index));
    let flight = mission::fly(&fly)?;
    let report = crate::report::build(&flight).context("report")?;
    let json = serde_json::to_string_pretty(&report).context("report as JSON")?;
    std::fs::write(dir.join("report.json"), json + "\n").context("write report.json")?;
    let numbers = FlightNumbers::of(&report);
    let yardstick = opts
        .spec
        .yardstick
        .as_ref()
        .map(|spec| yardstick(&scenario, spec, clock).map_err(|e| format!("{e:#}")));
    let independent = independent::selected(drawn.index, &drawn.kind, opts.spec.independent_every)
        .then(|| {
            let yardstick_plan = yardstick.as_ref().and_then(|y| y.as_ref().ok());
            independent(
                opts,
                &scenario,
                &file,
                &flight,
                yardstick_plan.map(|(_, tr)| tr),
            )
        });
    Ok(Judged {
        flight: numbers,
        yardstick: yardstick.map(|y| y.map(|(numbers, _)| numbers)),
        independent,
    })
}

/// The yardstick's take-off plan of `scenario`: its numbers and its path.
fn yardstick(
    scenario: &Scenario,
    spec: &YardstickSpec,
    clock: &'static MonotonicClock,
) -> anyhow::Result<(YardstickNumbers, Trajectory)> {
    let problem = Problem::from_scenario(scenario)?;
    let o = plan_exhaustive(&problem, &spec.exhaustive(), clock)?;
    let numbers = YardstickNumbers {
        cost: finite(o.best.cost),
        quality: o.best.quality.name().to_string(),
        run_costs: o.runs.iter().map(|(_, c)| finite(*c)).collect(),
        cuts: o.cuts,
        compute_s: o.elapsed.as_secs_f64(),
    };
    Ok((numbers, o.best.trajectory))
}

/// The independent solver's take-off of the mission in `file`, started also from the
/// flight's take-off plan and the yardstick's path (written beside `file`).
fn independent(
    opts: &RunOptions,
    scenario: &Scenario,
    file: &Path,
    flight: &mission::Flight,
    yardstick: Option<&Trajectory>,
) -> Result<IndependentNumbers, String> {
    let dir = file.parent().unwrap_or(Path::new("."));
    let take_off = flight
        .plans
        .first()
        .filter(|p| p.plan.trigger() == Some(wingman_interfaces::Trigger::Initial))
        .map(|p| {
            (
                "default_plan.json",
                PlanJson::of_plan(&p.plan, scenario.model),
            )
        });
    let yardstick = yardstick.map(|tr| {
        let plan = PlanJson::of_trajectory(tr, scenario.model);
        ("yardstick_plan.json", plan)
    });
    let mut starts = Vec::new();
    for (name, plan) in take_off.into_iter().chain(yardstick) {
        let path = dir.join(name);
        plan.write(&path).map_err(|e| format!("{e:#}"))?;
        starts.push(path);
    }
    independent::solve(
        &opts.independent_solver,
        &opts.spec.independent_args,
        file,
        &starts,
    )
}

/// Writes `results.json` (through a temporary file, so a reader never sees half of it).
pub fn write_results(dir: &Path, results: &CampaignResults) -> anyhow::Result<()> {
    let tmp = dir.join("results.json.tmp");
    std::fs::write(&tmp, serde_json::to_string_pretty(results)? + "\n")?;
    std::fs::rename(&tmp, dir.join("results.json"))?;
    Ok(())
}

/// Reads a `results.json` (or the one in a folder).
pub fn read_results(path: &Path) -> anyhow::Result<CampaignResults> {
    use anyhow::Context;
    let file = if path.is_dir() {
        path.join("results.json")
    } else {
        path.to_path_buf()
    };
    let text =
        std::fs::read_to_string(&file).with_context(|| format!("read {}", file.display()))?;
    let r: CampaignResults =
        serde_json::from_str(&text).with_context(|| format!("parse {}", file.display()))?;
    anyhow::ensure!(
        r.format == RESULTS_FORMAT,
        "{}: results format {} (this harness reads {RESULTS_FORMAT})",
        file.display(),
        r.format
    );
    Ok(r)
}

/// The host's name (`/etc/hostname`, else `HOSTNAME`, else `unknown`).
fn host_name() -> String {
    std::fs::read_to_string("/etc/hostname")
        .ok()
        .map(|s| s.trim().to_string())
        .filter(|s| !s.is_empty())
        .or_else(|| std::env::var("HOSTNAME").ok())
        .unwrap_or_else(|| "unknown".into())
}

/// The time now, UTC, as `YYYY-MM-DD HH:MM`.
pub fn utc_now() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (days, rest) = (secs / 86_400, secs % 86_400);
    let (y, m, d) = civil_from_days(days as i64);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02}",
        rest / 3600,
        (rest % 3600) / 60
    )
}

/// Year, month, day of a day count since 1970-01-01 (Howard Hinnant's algorithm).
fn civil_from_days(z: i64) -> (i64, u32, u32) {
    let z = z + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let m = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    (yoe + era * 400 + i64::from(m <= 2), m, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_split_the_indices_without_overlap() {
        assert_eq!(Shard::parse("1/4"), Ok(Shard { index: 1, of: 4 }));
        for bad in ["4/4", "1", "a/2", "0/0", "-1/2"] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        let mut all: Vec<usize> = (0..4)
            .flat_map(|i| Shard { index: i, of: 4 }.indices(30))
            .collect();
        all.sort_unstable();
        assert_eq!(all, (0..30).collect::<Vec<_>>());
        assert_eq!(Shard::WHOLE.indices(3), vec![0, 1, 2]);
    }

    #[test]
    fn dates_come_out_as_the_calendar_says() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        // 2000-03-01 and 2026-12-06, counted independently (days since the epoch).
        assert_eq!(civil_from_days(11_017), (2000, 3, 1));
        assert_eq!(civil_from_days(20_793), (2026, 12, 6));
    }
}

//! The independent yardstick on a subset of a campaign: the take-off problem of every
//! `every`-th mission (index 0, `every`, `2 every`, ...: the same missions in any shard)
//! solved by a solver that shares nothing with the planner — `tools/yardstick/
//! ipopt_multistart.py`, a Hermite–Simpson transcription in CasADi solved by IPOPT with
//! exact second derivatives, each solution judged by the customer's judge. It starts from
//! its own straight and bulged paths and from the default take-off plan and the
//! yardstick's (written as `default_plan.json` and `yardstick_plan.json` beside the
//! mission's scenario), so it checks both: a better basin it finds from its own starts is
//! one the planner and its yardstick both missed, and from theirs it polishes their basin
//! with another transcription.
//!
//! It runs at test time only (a campaign, or the CI's), never in flight: it needs Python
//! with casadi, numpy and scipy (`tools/yardstick/requirements.txt`).

use std::fmt::Write;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};
use wingman_interfaces::{Model, Plan};
use wingman_planning::trajectory::Trajectory;

use super::kind::MissionKind;
use super::outcome::{COST_FLOOR, GAP_TOL, MissionOutcome, finite};
use super::run::CampaignResults;

/// Longest a mission's independent solve may take before it is stopped (its result is then
/// the mission's `independent_error`).
pub const TIME_LIMIT: Duration = Duration::from_secs(900);

/// What the independent solver found for one mission's take-off.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IndependentNumbers {
    /// The best judged cost over its starts.
    pub cost: f64,
    /// The start it came from (`bulge 0.25`, `.../default_plan.json`, ...).
    pub start: String,
    /// Starts IPOPT solved (`Solve_Succeeded`), and starts tried.
    pub converged: usize,
    pub starts: usize,
    pub compute_s: f64,
}

/// Whether mission `index` (of `kind`) is one the independent solver plans (`every` 0:
/// none). The solver and the customer's judge that judges it model still air: a windy
/// mission is left out.
pub fn selected(index: usize, kind: &MissionKind, every: usize) -> bool {
    every > 0 && index.is_multiple_of(every) && !kind.wind
}

/// A path in the judge's `plan.json` layout (the keys the solver reads).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanJson {
    pub times: Vec<f64>,
    pub states: Vec<Vec<f64>>,
    pub controls: Vec<Vec<f64>>,
    pub phase_ends_s: Vec<f64>,
}

impl PlanJson {
    /// The samples of a `Plan` message (its model's states and controls).
    pub fn of_plan(plan: &Plan, model: Model) -> PlanJson {
        let (nx, nu) = (model.state_dim(), model.control_dim());
        let samples = plan.samples();
        PlanJson {
            times: samples.iter().map(|s| s.t_s).collect(),
            states: samples.iter().map(|s| s.state[..nx].to_vec()).collect(),
            controls: samples.iter().map(|s| s.control[..nu].to_vec()).collect(),
            phase_ends_s: plan.phase_ends().to_vec(),
        }
    }

    /// The samples of a planner's trajectory.
    pub fn of_trajectory(tr: &Trajectory, model: Model) -> PlanJson {
        let (nx, nu) = (model.state_dim(), model.control_dim());
        PlanJson {
            times: tr.times.clone(),
            states: tr.states.iter().map(|s| s[..nx].to_vec()).collect(),
            controls: tr.controls.iter().map(|u| u[..nu].to_vec()).collect(),
            phase_ends_s: tr.phase_ends.clone(),
        }
    }

    pub fn write(&self, path: &Path) -> anyhow::Result<()> {
        std::fs::write(path, serde_json::to_string(self)? + "\n")?;
        Ok(())
    }
}

/// Solves `scenario`'s take-off with the independent solver `script` (given `args`), also
/// from the plans `starts`; its best judged cost.
pub fn solve(
    script: &Path,
    args: &[String],
    scenario: &Path,
    starts: &[PathBuf],
) -> Result<IndependentNumbers, String> {
    let started = Instant::now();
    let mut child = Command::new("python3")
        // One core: flights beside it (`--jobs`) keep theirs.
        .env("OMP_NUM_THREADS", "1")
        .env("OPENBLAS_NUM_THREADS", "1")
        .arg(script)
        .args(args)
        .arg(scenario)
        .args(starts)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| format!("cannot start python3 {}: {e}", script.display()))?;
    // The output is read on threads, so that a full pipe never blocks the solver.
    let read = |mut pipe: Box<dyn Read + Send>| {
        std::thread::spawn(move || {
            let mut text = String::new();
            let _ = pipe.read_to_string(&mut text);
            text
        })
    };
    let stdout = read(Box::new(child.stdout.take().expect("piped")));
    let stderr = read(Box::new(child.stderr.take().expect("piped")));
    let status = loop {
        let stop = match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if started.elapsed() > TIME_LIMIT => {
                format!("stopped after {} s", TIME_LIMIT.as_secs())
            }
            Ok(None) => {
                std::thread::sleep(Duration::from_millis(50));
                continue;
            }
            Err(e) => format!("waiting for the solver: {e}"),
        };
        let _ = child.kill();
        let _ = child.wait();
        return Err(stop);
    };
    let (out, err) = (
        stdout.join().unwrap_or_default(),
        stderr.join().unwrap_or_default(),
    );
    let mut numbers = parse_output(&out).map_err(|e| {
        let lines: Vec<&str> = err.lines().collect();
        let tail = lines[lines.len().saturating_sub(3)..].join(" / ");
        format!("{e} ({status}; stderr: {tail})")
    })?;
    numbers.compute_s = started.elapsed().as_secs_f64();
    Ok(numbers)
}

/// The numbers of the solver's JSON output (`starts`, `best`; compute time left 0).
pub fn parse_output(stdout: &str) -> Result<IndependentNumbers, String> {
    #[derive(Deserialize)]
    struct Start {
        status: Option<String>,
    }
    #[derive(Deserialize)]
    struct Best {
        judged_cost: f64,
        start: String,
    }
    #[derive(Deserialize)]
    struct Output {
        starts: Vec<Start>,
        best: Option<Best>,
    }
    let o: Output =
        serde_json::from_str(stdout).map_err(|e| format!("unreadable solver output: {e}"))?;
    let converged = o
        .starts
        .iter()
        .filter(|s| s.status.as_deref() == Some("Solve_Succeeded"))
        .count();
    let best = o
        .best
        .ok_or_else(|| format!("no start of {} converged", o.starts.len()))?;
    Ok(IndependentNumbers {
        cost: finite(best.judged_cost),
        start: best.start,
        converged,
        starts: o.starts.len(),
        compute_s: 0.0,
    })
}

impl MissionOutcome {
    /// The gap of `cost` over the independent solver's best (as [`MissionOutcome::gap`]).
    pub fn independent_gap(&self, cost: f64) -> Option<f64> {
        let i = self.independent.as_ref()?.cost;
        (cost.is_finite() && i.is_finite()).then(|| (cost - i) / i.abs().max(COST_FLOOR))
    }

    /// The yardstick's gap over the independent solver's best: above [`GAP_TOL`], the
    /// independent solver found a basin the yardstick missed.
    pub fn yardstick_vs_independent(&self) -> Option<f64> {
        self.independent_gap(self.yardstick.as_ref()?.cost)
    }

    /// The default take-off plan's gap over the independent solver's best.
    pub fn default_vs_independent(&self) -> Option<f64> {
        self.independent_gap(self.flight.as_ref()?.take_off()?.cost)
    }
}

/// The report's section on the independent solver.
pub fn write_section(s: &mut String, r: &CampaignResults) {
    let every = r.spec.independent_every;
    let _ = writeln!(s, "## The independent solver\n");
    if every == 0 {
        let _ = writeln!(s, "Not run (`--independent-every 0`).\n");
        return;
    }
    let picked: Vec<&MissionOutcome> = r
        .outcomes
        .iter()
        .filter(|o| selected(o.index, &o.kind, every))
        .collect();
    let beaten = picked
        .iter()
        .filter(|o| o.yardstick_vs_independent().is_some_and(|g| g > GAP_TOL))
        .count();
    let _ = writeln!(
        s,
        "The take-off of every mission in still air whose index is a multiple of {every} \
         (`tools/yardstick/ipopt_multistart.py` by default: Hermite–Simpson in CasADi, IPOPT \
         with exact Hessians, judged by the customer's judge; started from its own paths, \
         the default plan and the yardstick's). Gaps as the yardstick's, against its best \
         judged cost. It beat the yardstick by more than the tolerance on {beaten} of {} \
         mission(s).\n",
        picked.len()
    );
    let _ = writeln!(
        s,
        "| mission | default | yardstick | independent | its start | converged | default vs it | yardstick vs it | time |\n|---|---:|---:|---:|---|---:|---:|---:|---:|"
    );
    let gap = |g: Option<f64>| g.map_or("-".into(), |g| format!("{:+.3} %", 100.0 * g));
    for o in picked {
        let take_off = o
            .flight
            .as_ref()
            .and_then(|f| f.take_off())
            .map_or("-".into(), |t| format!("{:.6}", t.cost));
        let yardstick = o
            .yardstick
            .as_ref()
            .map_or("-".into(), |y| format!("{:.6}", y.cost));
        let Some(i) = &o.independent else {
            let why = o.independent_error.as_deref().unwrap_or("not run");
            let why = why.replace('|', "/");
            let _ = writeln!(
                s,
                "| {} | {take_off} | {yardstick} | {why} | | | | | |",
                o.name
            );
            continue;
        };
        let start = Path::new(&i.start)
            .file_name()
            .map_or(i.start.clone(), |f| f.to_string_lossy().into_owned());
        let _ = writeln!(
            s,
            "| {} | {take_off} | {yardstick} | {:.6} | {start} | {}/{} | {} | {} | {:.0} s |",
            o.name,
            i.cost,
            i.converged,
            i.starts,
            gap(o.default_vs_independent()),
            gap(o.yardstick_vs_independent()),
            i.compute_s,
        );
    }
    let _ = writeln!(s);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_solvers_output_gives_its_best_judged_start() {
        let out = r#"{"scenario": "m", "starts": [
            {"status": "Solve_Succeeded", "judged_cost": 2.5, "start": "bulge 0"},
            {"status": "Infeasible_Problem_Detected", "nlp_objective": null, "start": "bulge 0.25"},
            {"status": "Solve_Succeeded", "judged_cost": 2.4, "start": "d/default_plan.json"}],
            "best": {"status": "Solve_Succeeded", "judged_cost": 2.4, "start": "d/default_plan.json"}}"#;
        let n = parse_output(out).unwrap();
        assert_eq!((n.cost, n.converged, n.starts), (2.4, 2, 3));
        assert_eq!(n.start, "d/default_plan.json");
        let none = r#"{"scenario": "m", "starts": [{"status": "error: x", "start": "bulge 0"}], "best": null}"#;
        assert!(parse_output(none).unwrap_err().contains("no start of 1"));
        assert!(parse_output("Traceback").is_err());
        let still = super::super::generate::draw(3, 0, &Default::default()).kind;
        let windy = MissionKind {
            wind: true,
            ..still.clone()
        };
        assert!(selected(0, &still, 10) && selected(20, &still, 10));
        assert!(!selected(5, &still, 10) && !selected(0, &still, 0));
        assert!(!selected(0, &windy, 10), "the solver is still air");
    }
}

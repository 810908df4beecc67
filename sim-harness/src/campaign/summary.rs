//! A campaign's report from its results: `report.md` (the verdict against the bars,
//! tables by kind and feature, errors, exposure, re-plans and compute time by trigger, the
//! gap to the yardstick with its worst cases, the missions that miss a criterion),
//! `summary.json` (the same numbers for machines) and the CDF charts.

use std::collections::BTreeMap;
use std::fmt::Write;
use std::path::Path;

use serde_json::json;

use super::charts::{Cdf, Series, draw_cdf};
use super::independent;
use super::kind::{Feature, OBJECTIVES};
use super::outcome::{GAP_TOL, MissionOutcome};
use super::progress::clock_time;
use super::run::CampaignResults;

/// Share of missions that must meet the criteria.
pub const CRITERIA_BAR: f64 = 0.99;
/// Share of missions whose take-off plan must be within [`GAP_TOL`] of the yardstick.
pub const GAP_BAR: f64 = 0.98;
/// Where the gap chart's axis ends, %.
const GAP_AXIS: f64 = 10.0;

/// The headline numbers.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    pub missions: usize,
    /// Missions of the campaign with no outcome (shards not merged in).
    pub missing: Vec<usize>,
    pub meeting: usize,
    /// Missions with a gap measured, and those within [`GAP_TOL`].
    pub judged: usize,
    pub within: usize,
}

impl Verdict {
    pub fn of(r: &CampaignResults) -> Verdict {
        let have: std::collections::BTreeSet<usize> = r.outcomes.iter().map(|o| o.index).collect();
        // One shard's own results expect its slice; a whole run or a merge, every mission
        // (a shard left out of a merge shows as missing missions).
        let expected: Vec<usize> = match r.shards.as_slice() {
            [one] => one.indices(r.spec.count),
            _ => (0..r.spec.count).collect(),
        };
        let mut missing: Vec<usize> = expected.into_iter().filter(|i| !have.contains(i)).collect();
        missing.sort_unstable();
        let gaps: Vec<f64> = r.outcomes.iter().filter_map(MissionOutcome::gap).collect();
        Verdict {
            missions: r.outcomes.len(),
            missing,
            meeting: r.outcomes.iter().filter(|o| o.meets_criteria()).count(),
            // With a yardstick every mission is judged: one without a gap (not flown, no
            // take-off plan, the yardstick failed) counts as outside.
            judged: if r.spec.yardstick.is_some() {
                r.outcomes.len()
            } else {
                0
            },
            within: gaps.iter().filter(|g| **g <= GAP_TOL).count(),
        }
    }

    /// Whether the campaign clears both bars (the gap's only when a yardstick ran).
    pub fn passes(&self) -> bool {
        let share = |a: usize, b: usize| if b == 0 { 1.0 } else { a as f64 / b as f64 };
        self.missing.is_empty()
            && share(self.meeting, self.missions) >= CRITERIA_BAR
            && share(self.within, self.judged) >= GAP_BAR
    }
}

/// Writes `report.md`, `summary.json` and the charts into `dir`; returns the Markdown.
pub fn write_report(dir: &Path, r: &CampaignResults) -> anyhow::Result<String> {
    let md = markdown(r);
    std::fs::write(dir.join("report.md"), &md)?;
    std::fs::write(
        dir.join("summary.json"),
        serde_json::to_string_pretty(&summary_json(r))? + "\n",
    )?;
    draw_charts(dir, r).map_err(|e| anyhow::anyhow!("charts: {e}"))?;
    Ok(md)
}

/// The command that runs this campaign again (all shards in one run).
pub fn command(r: &CampaignResults) -> String {
    let s = &r.spec;
    let mut c = format!(
        "wingman-harness campaign --count {} --seed {}",
        s.count, s.seed
    );
    let flags = s.filter.flags();
    if !flags.is_empty() {
        c.push(' ');
        c.push_str(&flags);
    }
    if let Some(config) = &s.planner_config {
        let _ = write!(c, " --planner-config {config}");
    }
    match &s.yardstick {
        None => c.push_str(" --no-yardstick"),
        Some(y) => {
            let _ = write!(
                c,
                " --yardstick-runs {} --yardstick-budget-s {}",
                y.runs, y.budget_s
            );
        }
    }
    if s.independent_every > 0 {
        let _ = write!(c, " --independent-every {}", s.independent_every);
        for arg in &s.independent_args {
            let _ = write!(c, " --independent-arg={arg}");
        }
    }
    c
}

fn pct(a: usize, b: usize) -> String {
    if b == 0 {
        "-".into()
    } else {
        format!("{:.1} %", 100.0 * a as f64 / b as f64)
    }
}

/// The `q` quantile of `v` (nearest rank; `None` when empty).
pub fn quantile(v: &[f64], q: f64) -> Option<f64> {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if s.is_empty() {
        return None;
    }
    s.sort_by(f64::total_cmp);
    let k = ((q * s.len() as f64).ceil() as usize).clamp(1, s.len()) - 1;
    Some(s[k])
}

fn num(v: Option<f64>, digits: usize) -> String {
    v.map_or("-".into(), |x| format!("{x:.digits$}"))
}

fn gap_pct(v: Option<f64>) -> String {
    v.map_or("-".into(), |g| format!("{:+.3} %", 100.0 * g))
}

/// The Markdown report.
pub fn markdown(r: &CampaignResults) -> String {
    let v = Verdict::of(r);
    let mut s = String::new();
    write_header(&mut s, r, &v);
    write_kinds(&mut s, r);
    write_errors(&mut s, r);
    write_plans(&mut s, r);
    write_gaps(&mut s, r);
    independent::write_section(&mut s, r);
    write_failures(&mut s, r);
    s
}

fn write_header(s: &mut String, r: &CampaignResults, v: &Verdict) {
    let _ = writeln!(s, "# Campaign report\n");
    let _ = writeln!(s, "```sh\n{}\n```\n", command(r));
    let y = r.spec.yardstick.map_or("none".to_string(), |y| {
        format!(
            "{} runs of `PlannerSettings::exhaustive`, {} s each, seeds from {}",
            y.runs, y.budget_s, y.seed
        )
    });
    let _ = writeln!(
        s,
        "- Seed {}, {} missions{}; yardstick: {y}.",
        r.spec.seed,
        r.spec.count,
        if r.spec.filter.flags().is_empty() {
            String::new()
        } else {
            format!(" ({})", r.spec.filter.flags())
        }
    );
    for run in &r.runs {
        let _ = writeln!(
            s,
            "- Shard {}/{}: started {} UTC on `{}` ({} cores), {} flight(s) at a time, {} wall.",
            run.shard.index,
            run.shard.of,
            run.started_utc,
            run.host,
            run.cores,
            run.jobs,
            clock_time(run.wall_s)
        );
    }
    let _ = writeln!(
        s,
        "\n| measure | result | bar |\n|---|---:|---:|\n| missions flown that meet the criteria | {} / {} ({}) | ≥ {:.0} % |\n| default take-off plan within {:.1} % of the yardstick | {} / {} ({}) | ≥ {:.0} % |\n| missions without an outcome | {} | 0 |\n",
        v.meeting,
        v.missions,
        pct(v.meeting, v.missions),
        100.0 * CRITERIA_BAR,
        100.0 * GAP_TOL,
        v.within,
        v.judged,
        pct(v.within, v.judged),
        100.0 * GAP_BAR,
        v.missing.len()
    );
    let _ = writeln!(
        s,
        "Criteria: every target and the end (the final point, or the lead at the rendezvous) \
         within 100 m; a fixed final time within 2 s; the flown path never inside a static \
         threat (pop-ups included; min F ≥ 1) but, on an unavoidable layout, the defended one. The gap is the default \
         take-off plan's cost `c` over the yardstick's `y`, `(c − y) / max(|y|, 0.02)` \
         (negative: the default did better; below 0.02 costs compare in absolute terms, \
         within 1e-4). Verdict: **{}**.\n",
        if v.passes() {
            "passes both bars"
        } else {
            "misses a bar"
        }
    );
}

/// Missions, criteria and gaps per group.
fn group_row(s: &mut String, label: &str, group: &[&MissionOutcome]) {
    let gaps: Vec<f64> = group.iter().filter_map(|o| o.gap()).collect();
    let meeting = group.iter().filter(|o| o.meets_criteria()).count();
    let _ = writeln!(
        s,
        "| {label} | {} | {} ({}) | {} | {} | {} |",
        group.len(),
        meeting,
        pct(meeting, group.len()),
        gap_pct(quantile(&gaps, 0.5)),
        gap_pct(quantile(&gaps, 0.95)),
        gap_pct(gaps.iter().copied().fold(None, |m: Option<f64>, g| {
            Some(m.map_or(g, |m| m.max(g)))
        })),
    );
}

fn write_kinds(s: &mut String, r: &CampaignResults) {
    let _ = writeln!(
        s,
        "## By kind\n\n| kind | missions | meet the criteria | gap p50 | gap p95 | worst gap |\n|---|---:|---:|---:|---:|---:|"
    );
    for model in ["2d", "3d"] {
        for objective in OBJECTIVES {
            let g: Vec<&MissionOutcome> = r
                .outcomes
                .iter()
                .filter(|o| o.kind.model == model && o.kind.objective == objective)
                .collect();
            if !g.is_empty() {
                group_row(s, &format!("{model} {objective}"), &g);
            }
        }
    }
    for targets in 1..=4 {
        let g: Vec<&MissionOutcome> = r
            .outcomes
            .iter()
            .filter(|o| o.kind.targets == targets)
            .collect();
        if !g.is_empty() {
            group_row(s, &format!("{targets} target(s)"), &g);
        }
    }
    for (label, lo, hi) in [
        ("3–7 threats", 3, 7),
        ("8–11 threats", 8, 11),
        ("12–16 threats", 12, 16),
    ] {
        let g: Vec<&MissionOutcome> = r
            .outcomes
            .iter()
            .filter(|o| (lo..=hi).contains(&o.kind.threats))
            .collect();
        if !g.is_empty() {
            group_row(s, label, &g);
        }
    }
    let avoidable: Vec<&MissionOutcome> =
        r.outcomes.iter().filter(|o| !o.kind.unavoidable).collect();
    group_row(s, "avoidable", &avoidable);
    for f in Feature::ALL {
        let g: Vec<&MissionOutcome> = r.outcomes.iter().filter(|o| o.kind.has(f)).collect();
        group_row(s, f.name(), &g);
    }
    let _ = writeln!(s);
}

fn write_errors(s: &mut String, r: &CampaignResults) {
    let flights: Vec<_> = r
        .outcomes
        .iter()
        .filter_map(|o| o.flight.as_ref().map(|f| (o, f)))
        .collect();
    let targets: Vec<f64> = flights
        .iter()
        .flat_map(|(_, f)| f.target_miss_m.iter().copied())
        .collect();
    let ends: Vec<f64> = flights.iter().map(|(_, f)| f.final_error_m).collect();
    let times: Vec<f64> = flights
        .iter()
        .filter_map(|(_, f)| f.final_time_error_s.map(f64::abs))
        .collect();
    let _ = writeln!(
        s,
        "## Errors at the targets and the end\n\n| measure | samples | p50 | p95 | max |\n|---|---:|---:|---:|---:|"
    );
    for (label, v) in [
        ("target miss [m]", &targets),
        ("end error [m]", &ends),
        ("fixed final time error [s]", &times),
    ] {
        let _ = writeln!(
            s,
            "| {label} | {} | {} | {} | {} |",
            v.len(),
            num(quantile(v, 0.5), 1),
            num(quantile(v, 0.95), 1),
            num(quantile(v, 1.0), 1)
        );
    }
    let _ = writeln!(
        s,
        "\n## Exposure\n\n| layout | missions | ∫E dt p50 [s] | p95 | max | smallest min F static |\n|---|---:|---:|---:|---:|---:|"
    );
    for (label, unavoidable) in [("avoidable", false), ("unavoidable", true)] {
        let g: Vec<_> = flights
            .iter()
            .filter(|(o, _)| o.kind.unavoidable == unavoidable)
            .collect();
        let e: Vec<f64> = g.iter().map(|(_, f)| f.exposure_s).collect();
        let min_f = g
            .iter()
            .filter_map(|(_, f)| f.min_f_static)
            .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.min(x))));
        let _ = writeln!(
            s,
            "| {label} | {} | {} | {} | {} | {} |",
            g.len(),
            num(quantile(&e, 0.5), 3),
            num(quantile(&e, 0.95), 3),
            num(quantile(&e, 1.0), 3),
            num(min_f, 3)
        );
    }
    let _ = writeln!(s);
}

/// Plans by trigger: how many, their quality, compute time, deadline cuts; and holds.
fn write_plans(s: &mut String, r: &CampaignResults) {
    let mut by: BTreeMap<&str, Vec<&super::outcome::PlanNumbers>> = BTreeMap::new();
    for f in r.outcomes.iter().filter_map(|o| o.flight.as_ref()) {
        for p in &f.plans {
            by.entry(p.trigger.as_str()).or_default().push(p);
        }
    }
    let _ = writeln!(
        s,
        "## Plans and compute time by trigger\n\n| trigger | plans | Optimal | Feasible | SwarmOnly | with a deadline cut | compute p50 [ms] | p95 | max |\n|---|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for (trigger, plans) in &by {
        let q = |name: &str| plans.iter().filter(|p| p.quality == name).count();
        let ms: Vec<f64> = plans.iter().map(|p| p.compute_ms).collect();
        let _ = writeln!(
            s,
            "| {trigger} | {} | {} | {} | {} | {} | {} | {} | {} |",
            plans.len(),
            q("Optimal"),
            q("Feasible"),
            q("SwarmOnly"),
            plans.iter().filter(|p| p.cuts > 0).count(),
            num(quantile(&ms, 0.5), 0),
            num(quantile(&ms, 0.95), 0),
            num(quantile(&ms, 1.0), 0)
        );
    }
    let flights: Vec<_> = r
        .outcomes
        .iter()
        .filter_map(|o| o.flight.as_ref())
        .collect();
    let holds: usize = flights.iter().map(|f| f.holds).sum();
    let lost: u64 = flights.iter().map(|f| f.messages_lost).sum();
    let _ = writeln!(
        s,
        "\nSafe holds: {holds} in {} flight(s). Planner inputs lost: {lost}.\n",
        flights.iter().filter(|f| f.holds > 0).count()
    );
}

fn write_gaps(s: &mut String, r: &CampaignResults) {
    let gaps: Vec<(&MissionOutcome, f64)> = r
        .outcomes
        .iter()
        .filter_map(|o| o.gap().map(|g| (o, g)))
        .collect();
    let _ = writeln!(s, "## The default take-off plan against the yardstick\n");
    if gaps.is_empty() {
        let _ = writeln!(s, "No gap measured (no yardstick).\n");
        return;
    }
    let bins = [
        (
            "the default did better by more than 0.1 %",
            f64::NEG_INFINITY,
            -0.001,
        ),
        ("within ±0.1 %", -0.001, 0.001),
        ("0.1–0.5 % above", 0.001, GAP_TOL),
        ("0.5–2 % above", GAP_TOL, 0.02),
        ("2–10 % above", 0.02, 0.1),
        ("more than 10 % above", 0.1, f64::INFINITY),
    ];
    let _ = writeln!(s, "| gap | missions |\n|---|---:|");
    for (label, lo, hi) in bins {
        let n = gaps.iter().filter(|(_, g)| *g > lo && *g <= hi).count();
        let _ = writeln!(s, "| {label} | {n} |");
    }
    let yardstick_cut = r
        .outcomes
        .iter()
        .filter(|o| o.yardstick.as_ref().is_some_and(|y| y.cuts > 0))
        .count();
    let _ = writeln!(
        s,
        "\nYardstick runs its budget cut: {yardstick_cut} mission(s). Charts: `gap_cdf.png`, \
         `compute_cdf.png`, `errors_cdf.png`.\n"
    );
    let mut worst = gaps.clone();
    worst.sort_by(|a, b| b.1.total_cmp(&a.1));
    let _ = writeln!(
        s,
        "Worst gaps:\n\n| mission | kind | take-off plan | its cost | yardstick's cost | gap | folder |\n|---|---|---|---:|---:|---:|---|"
    );
    for (o, g) in worst.iter().take(10) {
        let Some(f) = &o.flight else { continue };
        let Some(t) = f.take_off() else { continue };
        let _ = writeln!(
            s,
            "| {} | {} | {} {} | {:.6} | {:.6} | {} | {} |",
            o.name,
            o.kind.describe(),
            t.quality,
            t.path,
            t.cost,
            o.yardstick.as_ref().map_or(f64::NAN, |y| y.cost),
            gap_pct(Some(*g)),
            o.kept.as_deref().unwrap_or("-")
        );
    }
    let _ = writeln!(s);
}

fn write_failures(s: &mut String, r: &CampaignResults) {
    let failed: Vec<&MissionOutcome> = r.outcomes.iter().filter(|o| !o.meets_criteria()).collect();
    let _ = writeln!(s, "## Missions that miss a criterion\n");
    if failed.is_empty() {
        let _ = writeln!(s, "None.\n");
        return;
    }
    let _ = writeln!(
        s,
        "| mission | kind | misses | fly it alone |\n|---|---|---|---|"
    );
    for o in failed {
        let _ = writeln!(
            s,
            "| {} | {} | {} | `wingman-harness fly {kept}/{}.toml --planner-config {kept}/planner.toml` |",
            o.name,
            o.kind.describe(),
            o.error
                .as_deref()
                .map_or(o.misses.join("; "), |e| format!("not flown: {e}")),
            o.name,
            kept = o.kept.as_deref().unwrap_or("missions/?"),
        );
    }
    let _ = writeln!(s);
}

/// The report's numbers for machines.
pub fn summary_json(r: &CampaignResults) -> serde_json::Value {
    let v = Verdict::of(r);
    let gaps: Vec<f64> = r.outcomes.iter().filter_map(MissionOutcome::gap).collect();
    json!({
        "command": command(r),
        "seed": r.spec.seed,
        "count": r.spec.count,
        "missions": v.missions,
        "missing": v.missing,
        "meeting_criteria": v.meeting,
        "gap_judged": v.judged,
        "gap_within_tolerance": v.within,
        "gap_tolerance": GAP_TOL,
        "gap_quantiles": {
            "p50": quantile(&gaps, 0.5),
            "p95": quantile(&gaps, 0.95),
            "p99": quantile(&gaps, 0.99),
            "max": quantile(&gaps, 1.0),
        },
        "passes": v.passes(),
        "failed": r.outcomes.iter().filter(|o| !o.meets_criteria()).map(|o| json!({
            "name": o.name, "misses": o.misses, "error": o.error, "kept": o.kept,
        })).collect::<Vec<_>>(),
        "outlying": r.outcomes.iter().filter(|o| o.gap().is_some_and(|g| g > GAP_TOL)).map(|o| json!({
            "name": o.name, "gap": o.gap(), "kept": o.kept,
        })).collect::<Vec<_>>(),
        "independent": r.outcomes.iter().filter(|o| independent::selected(o.index, &o.kind, r.spec.independent_every)).map(|o| json!({
            "name": o.name,
            "cost": o.independent.as_ref().map(|i| i.cost),
            "start": o.independent.as_ref().map(|i| &i.start),
            "error": o.independent_error,
            "default_vs_independent": o.default_vs_independent(),
            "yardstick_vs_independent": o.yardstick_vs_independent(),
        })).collect::<Vec<_>>(),
    })
}

/// `gap_cdf.png` (per model), `compute_cdf.png` (per trigger), `errors_cdf.png`.
fn draw_charts(
    dir: &Path,
    r: &CampaignResults,
) -> Result<(), Box<dyn std::error::Error + Send + Sync>> {
    // A few gaps of thousands of percent would squeeze the rest into one pixel: the axis
    // stops at GAP_AXIS, larger gaps are drawn at its end.
    let per_model = |model: &str| Series {
        label: model.to_string(),
        values: r
            .outcomes
            .iter()
            .filter(|o| o.kind.model == model)
            .filter_map(|o| o.gap().map(|g| (100.0 * g).clamp(-GAP_AXIS, GAP_AXIS)))
            .collect(),
    };
    draw_cdf(
        &dir.join("gap_cdf.png"),
        &Cdf {
            title: "default take-off plan's cost over the yardstick's (gaps beyond ±10 % at the ends)",
            x_label: "gap [%]",
            series: vec![per_model("2d"), per_model("3d")],
            marks: vec![(format!("{:.1} %", 100.0 * GAP_TOL), 100.0 * GAP_TOL)],
            log_x: false,
        },
    )?;
    let mut by: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for f in r.outcomes.iter().filter_map(|o| o.flight.as_ref()) {
        for p in &f.plans {
            by.entry(p.trigger.clone()).or_default().push(p.compute_ms);
        }
    }
    draw_cdf(
        &dir.join("compute_cdf.png"),
        &Cdf {
            title: "compute time of the plans by trigger",
            x_label: "compute time [ms]",
            series: by
                .into_iter()
                .map(|(label, values)| Series { label, values })
                .collect(),
            marks: Vec::new(),
            log_x: true,
        },
    )?;
    let flights: Vec<_> = r
        .outcomes
        .iter()
        .filter_map(|o| o.flight.as_ref())
        .collect();
    draw_cdf(
        &dir.join("errors_cdf.png"),
        &Cdf {
            title: "misses at the targets and the end",
            x_label: "distance [m]",
            series: vec![
                Series {
                    label: "target miss".into(),
                    values: flights
                        .iter()
                        .flat_map(|f| f.target_miss_m.iter().copied())
                        .collect(),
                },
                Series {
                    label: "end error".into(),
                    values: flights.iter().map(|f| f.final_error_m).collect(),
                },
            ],
            marks: vec![("100 m".into(), 100.0)],
            log_x: true,
        },
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_take_the_nearest_rank() {
        let v = [5.0, 1.0, 3.0, 2.0, 4.0];
        assert_eq!(quantile(&v, 0.5), Some(3.0));
        assert_eq!(quantile(&v, 1.0), Some(5.0));
        assert_eq!(quantile(&v, 0.0), Some(1.0));
        assert_eq!(quantile(&[], 0.5), None);
    }
}

//! Latency benchmark of issue 8 (part 2): the raw iceoryx2 round trip between two
//! processes (the baseline) against the planner service's round trip and its trigger to
//! plan time, each with the machine idle and with a CPU hog on both cores.
//!
//! ```sh
//! cargo bench -p wingman-tests --bench latency              # the full run (~10 min)
//! cargo bench -p wingman-tests --bench latency -- --quick   # a smoke run (~1 min)
//! ```
//!
//! Options (after `--`): `--quick`; `--budget-2d-ms N`, `--budget-3d-ms N` (the planner's
//! re-plan budgets, which the pop-ups' re-plans run under; default `planner.toml`'s
//! `replan_2d_ms` / `replan_3d_ms`; the take-off plan keeps `plan_2d_ms` / `plan_3d_ms`); `--out FILE` (default
//! `docs/benchmarks/latency.json`); `--round-trip-only` (the small raw round trip and the
//! service's, both conditions, ~1 min: an A/B of the message path); `--message-slice-us N`
//! (the planner's `scheduling.message_slice_us`, default its own default).
//!
//! What runs, in each condition (`idle`, then `loaded`):
//! - `raw_iceoryx2_small` / `raw_iceoryx2_plan`: this process publishes a message the size
//!   of `OwnshipState` (`Plan`) and notifies; an echo process (this binary re-run with
//!   `--echo`) wakes on its listener (a timed wait, no spinning, like the planner's
//!   WaitSet), copies the sample into a loaned one on a second service and notifies back;
//!   the time is from before the publication to the echo's receipt. Every port comes from
//!   `wingman_ipc`, so QoS and wake-ups are the real system's.
//! - `service_round_trip`: a real `wingman-planner serve` flying the first plan of
//!   `2d-min-time-avoidable` gets an `OwnshipState` and wakes; the time is until the
//!   `PlannerStatus` echoing its sequence is received.
//! - `trigger_to_plan_2d` / `_3d`: a pop-up (one threat id moved onto the current plan,
//!   40 s past the commit time) is published; the time is until the new `Plan` is received.
//!   Pop-ups are paced so the planner's compute gate (duty cycle 1.0 over a 12 s window,
//!   min spacing 50 ms: the bench's own planner.toml) never defers one; a deferred one
//!   would be counted in `deferred`.
//!
//! Every process is pinned to cores 0 and 1 (`taskset`); the hog is one busy-loop process
//! per core (this binary re-run with `--hog`), bounded in time and killed on drop. Each
//! run uses vehicle ids of its own (`bl<pid>...`); every child is killed on drop and the
//! iceoryx2 resources of dead nodes are removed.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use hdrhistogram::Histogram;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use serde_json::{Value, json};
use wingman_interfaces::*;
use wingman_ipc::{self as ipc, Ipc};
use wingman_planner::service::sched;
use wingman_planning::plan_message::state_at;
use wingman_planning::scenario::bundled;
use wingman_planning::scenario::messages::{
    take_off_tasking as tasking_from, take_off_threat_reports as scenario_threats,
};
use wingman_testkit::fake_harness::{FakeHarness, ownship_2d, static_threat};
use wingman_testkit::process::{Proc, TempDir, planner};

/// Cores both processes (and the hog) run on.
const CORES: &str = "0,1";
/// Longest wait for one reply before the bench gives up.
const REPLY_TIMEOUT: Duration = Duration::from_secs(30);
/// Listener wait of both sides (woken at once by a notification; the timeout only bounds
/// a lost wake-up).
const WAIT_SLICE: Duration = Duration::from_millis(100);
/// Pause between two round trips (the ownship state's period is far longer; a pause keeps
/// the samples independent and the same for the baseline and the service).
const PACE: Duration = Duration::from_millis(2);
/// Planner compute gate of the bench's configuration.
const DUTY_WINDOW_MS: u64 = 12_000;
const MIN_SPACING_MS: u64 = 50;
const SOLVER_THREADS: u32 = 2;
/// Id of the pop-up threat the bench moves onto the plan.
const POPUP_ID: u32 = 900;
/// Sequence number that tells an echo process to stop.
const STOP: u64 = u64::MAX;

#[derive(Debug, Clone)]
struct Options {
    quick: bool,
    budget_2d_ms: u64,
    budget_3d_ms: u64,
    out: PathBuf,
    /// Only the small raw round trip and the service's round trip (an A/B of the message
    /// path in ~1 min).
    round_trip_only: bool,
    /// The planner's `scheduling.message_slice_us` (`None`: its default).
    message_slice_us: Option<u64>,
}

impl Options {
    fn raw_samples(&self) -> usize {
        if self.quick { 300 } else { 5000 }
    }
    fn service_samples(&self) -> usize {
        if self.quick { 300 } else { 3000 }
    }
    fn trigger_samples(&self, model: Model) -> usize {
        match (self.quick, model) {
            _ if self.round_trip_only => 0,
            (true, _) => 5,
            (false, Model::TwoD) => 50,
            (false, Model::ThreeD) => 30,
        }
    }
    /// The message threads' scheduler slice, µs (0: the kernel's default).
    fn slice_us(&self) -> u64 {
        self.message_slice_us.unwrap_or(
            wingman_ipc::ServiceConfig::default()
                .scheduling
                .message_slice_us,
        )
    }
    fn budget_ms(&self, model: Model) -> u64 {
        match model {
            Model::TwoD => self.budget_2d_ms,
            Model::ThreeD => self.budget_3d_ms,
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.first().map(String::as_str) {
        Some("--echo") => {
            let (ping, pong, kind) = (arg(&args, 1), arg(&args, 2), arg(&args, 3));
            let _slice = Slice::set(arg(&args, 4).parse().expect("--echo slice µs"));
            match kind {
                "small" => echo::<OwnshipState>(ping, pong),
                "plan" => echo::<Plan>(ping, pong),
                other => panic!("--echo: unknown payload {other}"),
            }
            return;
        }
        Some("--hog") => {
            let secs: u64 = arg(&args, 1).parse().expect("--hog SECONDS");
            hog(Duration::from_secs(secs));
            return;
        }
        _ => {}
    }
    let mut o = Options {
        quick: false,
        budget_2d_ms: wingman_ipc::ServiceConfig::default().budget.replan_2d_ms,
        budget_3d_ms: wingman_ipc::ServiceConfig::default().budget.replan_3d_ms,
        out: Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/benchmarks/latency.json"),
        round_trip_only: false,
        message_slice_us: None,
    };
    let mut k = 0;
    while k < args.len() {
        match args[k].as_str() {
            "--quick" => o.quick = true,
            "--budget-2d-ms" => {
                k += 1;
                o.budget_2d_ms = arg(&args, k).parse().expect("--budget-2d-ms N");
            }
            "--budget-3d-ms" => {
                k += 1;
                o.budget_3d_ms = arg(&args, k).parse().expect("--budget-3d-ms N");
            }
            "--round-trip-only" => o.round_trip_only = true,
            "--message-slice-us" => {
                k += 1;
                o.message_slice_us = Some(arg(&args, k).parse().expect("--message-slice-us N"));
            }
            "--out" => {
                k += 1;
                o.out = PathBuf::from(arg(&args, k));
            }
            // `cargo bench` passes `--bench`.
            "--bench" => {}
            other => panic!("unknown argument {other}"),
        }
        k += 1;
    }
    if o.quick {
        o.budget_2d_ms = o.budget_2d_ms.min(300);
        o.budget_3d_ms = o.budget_3d_ms.min(600);
    }
    run(&o);
}

fn arg(args: &[String], k: usize) -> &str {
    args.get(k)
        .map(String::as_str)
        .unwrap_or_else(|| panic!("missing argument {k} in {args:?}"))
}

// -------------------------------------------------------------------------------------
// The bench
// -------------------------------------------------------------------------------------

/// A latency histogram in nanoseconds.
struct Series {
    h: Histogram<u64>,
    /// Pop-ups the planner deferred (compute gate).
    deferred: u64,
    /// The planner's own compute time of each plan (`Plan::compute_ms`), ms.
    compute_ms: Vec<f64>,
    /// Each sample's time less the planner's compute time (IPC, the message loop, the
    /// wake-ups), ms.
    overhead_ms: Vec<f64>,
}

impl Series {
    fn new() -> Series {
        Series {
            h: Histogram::new_with_bounds(1, 600_000_000_000, 3).expect("histogram bounds"),
            deferred: 0,
            compute_ms: Vec::new(),
            overhead_ms: Vec::new(),
        }
    }

    /// p50, p99 and max of the planner's compute times and of the rest, ms.
    fn compute_json(&self) -> Value {
        let stats = |v: &[f64]| {
            let mut c = v.to_vec();
            c.sort_by(f64::total_cmp);
            let at = |q: f64| {
                let k = ((c.len() as f64 * q).ceil() as usize).clamp(1, c.len().max(1)) - 1;
                c.get(k).map_or(0.0, |v| (v * 100.0).round() / 100.0)
            };
            json!({"p50_ms": at(0.5), "p99_ms": at(0.99), "max_ms": at(1.0)})
        };
        json!({
            "compute": stats(&self.compute_ms),
            "rest": stats(&self.overhead_ms),
        })
    }

    fn record(&mut self, d: Duration) {
        let ns = u64::try_from(d.as_nanos()).unwrap_or(u64::MAX).max(1);
        self.h.saturating_record(ns);
    }

    fn us(&self, q: f64) -> f64 {
        (self.h.value_at_quantile(q) as f64 / 100.0).round() / 10.0
    }

    fn max_us(&self) -> f64 {
        (self.h.max() as f64 / 100.0).round() / 10.0
    }

    fn json(&self) -> Value {
        json!({
            "p50_us": self.us(0.5),
            "p90_us": self.us(0.9),
            "p99_us": self.us(0.99),
            "p999_us": self.us(0.999),
            "max_us": self.max_us(),
            "samples": self.h.len(),
        })
    }
}

const CONDITIONS: [&str; 2] = ["idle", "loaded"];
const SERIES: [&str; 5] = [
    "raw_iceoryx2_small",
    "raw_iceoryx2_plan",
    "service_round_trip",
    "trigger_to_plan_2d",
    "trigger_to_plan_3d",
];

fn run(o: &Options) {
    pin_self();
    let started = Instant::now();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let busy = other_builds();
    println!(
        "latency bench ({}): load average {}; other cargo/rustc processes: {}",
        if o.quick { "quick" } else { "full" },
        load.trim(),
        if busy.is_empty() { "none" } else { &busy }
    );
    // Build (once) the planner binary before anything is timed.
    let planner_bin = wingman_testkit::binary("wingman-planner");
    println!("planner: {}", planner_bin.display());
    let mut results: BTreeMap<(&str, &str), Series> = BTreeMap::new();
    for (c, cond) in CONDITIONS.iter().enumerate() {
        let _hog = (*cond == "loaded").then(|| Hog::start(Duration::from_secs(1800)));
        if _hog.is_some() {
            std::thread::sleep(Duration::from_secs(1));
        }
        let tag = format!("bl{}c{c}", std::process::id());
        println!(
            "[{cond}] raw iceoryx2, small ({} B)",
            size_of::<OwnshipState>()
        );
        results.insert(
            ("raw_iceoryx2_small", cond),
            raw::<OwnshipState>(
                &format!("{tag}s"),
                "small",
                o.slice_us(),
                o.raw_samples(),
                |m, s| {
                    m.header.sequence = s;
                },
            ),
        );
        if !o.round_trip_only {
            println!("[{cond}] raw iceoryx2, plan ({} B)", size_of::<Plan>());
            results.insert(
                ("raw_iceoryx2_plan", cond),
                raw::<Plan>(
                    &format!("{tag}p"),
                    "plan",
                    o.slice_us(),
                    o.raw_samples(),
                    |m, s| {
                        m.header.sequence = s;
                    },
                ),
            );
        }
        let models: &[Model] = if o.round_trip_only {
            &[Model::TwoD]
        } else {
            &[Model::TwoD, Model::ThreeD]
        };
        for &model in models {
            let (rt, trig) = service(o, &format!("{tag}m{}", model as u32), model, cond);
            if let Some(rt) = rt {
                results.insert(("service_round_trip", cond), rt);
            }
            let name = match model {
                Model::TwoD => "trigger_to_plan_2d",
                Model::ThreeD => "trigger_to_plan_3d",
            };
            if !o.round_trip_only {
                results.insert((name, cond), trig);
            }
        }
    }
    let elapsed = started.elapsed();
    report(o, &results, &load, &busy, elapsed);
}

fn report(
    o: &Options,
    results: &BTreeMap<(&str, &str), Series>,
    load: &str,
    busy: &str,
    elapsed: Duration,
) {
    let budget = |name: &str| match name {
        "trigger_to_plan_2d" => Some(o.budget_2d_ms),
        "trigger_to_plan_3d" => Some(o.budget_3d_ms),
        _ => None,
    };
    let mut series = serde_json::Map::new();
    let mut table = String::from(
        "| series | condition | samples | p50 µs | p90 µs | p99 µs | p99.9 µs | max µs |\n\
         |---|---|---:|---:|---:|---:|---:|---:|\n",
    );
    for name in SERIES {
        let mut entry = serde_json::Map::new();
        if let Some(b) = budget(name) {
            entry.insert("budget_ms".into(), json!(b));
        }
        entry.insert(
            "payload_bytes".into(),
            json!(match name {
                "raw_iceoryx2_small" | "service_round_trip" => size_of::<OwnshipState>(),
                _ => size_of::<Plan>(),
            }),
        );
        for cond in CONDITIONS {
            let Some(s) = results.get(&(name, cond)) else {
                continue;
            };
            let mut j = s.json();
            if budget(name).is_some()
                && let Some(m) = j.as_object_mut()
            {
                m.insert("deferred".into(), json!(s.deferred));
                m.insert("planner".into(), s.compute_json());
            }
            entry.insert(cond.into(), j);
            let label = match budget(name) {
                Some(b) => format!("{name} (budget {b} ms)"),
                None => name.to_string(),
            };
            let _ = writeln!(
                table,
                "| {label} | {cond} | {} | {} | {} | {} | {} | {} |",
                s.h.len(),
                s.us(0.5),
                s.us(0.9),
                s.us(0.99),
                s.us(0.999),
                s.max_us()
            );
        }
        series.insert(name.into(), Value::Object(entry));
    }
    let mut verdicts = serde_json::Map::new();
    let mut lines = String::new();
    for cond in CONDITIONS {
        let p99 = |n: &str| results.get(&(n, cond)).map(|s| s.us(0.99));
        if let (Some(svc), Some(raw)) = (p99("service_round_trip"), p99("raw_iceoryx2_small")) {
            let holds = svc <= 2.0 * raw;
            verdicts.insert(
                format!("service_round_trip_within_2x_raw_{cond}"),
                json!(holds),
            );
            let _ = writeln!(
                lines,
                "- {cond}: service round trip p99 {svc} µs vs 2 x raw small p99 {} µs: {}",
                2.0 * raw,
                if holds { "holds" } else { "does NOT hold" }
            );
        }
        for n in ["trigger_to_plan_2d", "trigger_to_plan_3d"] {
            if let (Some(p), Some(b)) = (p99(n), budget(n)) {
                let limit = (b as f64 + 1.0) * 1e3;
                let holds = p <= limit;
                verdicts.insert(format!("{n}_within_budget_plus_1ms_{cond}"), json!(holds));
                let compute = results
                    .get(&(n, cond))
                    .map(Series::compute_json)
                    .unwrap_or_default();
                let _ = writeln!(
                    lines,
                    "- {cond}: {n} p99 {p} µs vs budget + 1 ms = {limit} µs: {} (the \
                     planner's compute and the rest, ms: {compute})",
                    if holds { "holds" } else { "does NOT hold" }
                );
            }
        }
    }
    let doc = json!({
        "command": format!("cargo bench -p wingman-tests --bench latency{}", {
            let mut a = String::new();
            if o.quick {
                a += " --quick";
            }
            if o.round_trip_only {
                a += " --round-trip-only";
            }
            if let Some(us) = o.message_slice_us {
                let _ = write!(a, " --message-slice-us {us}");
            }
            if a.is_empty() { a } else { format!(" --{a}") }
        }),
        "message_slice_us": o.slice_us(),
        "scheduling": "the responder of each round trip runs with the scheduler slice \
                       `message_slice_us`: the planner's message thread (its planner.toml) \
                       and the raw echo alike; the requester (this bench's thread), the hog \
                       and the planner's solve thread keep the kernel's default",
        "mode": if o.quick { "quick" } else { "full" },
        "date": shell(&["date", "-u", "+%Y-%m-%dT%H:%M:%SZ"]),
        "machine": {
            "nproc": std::thread::available_parallelism().map_or(0, |n| n.get()),
            "cpu": cpu_model(),
            "load_average_at_start": load.trim(),
            "other_builds_at_start": busy,
            // The bench is meant for a quiet machine: load < 0.5 and no build running.
            "quiet_at_start": busy.is_empty()
                && load
                    .split_whitespace()
                    .next()
                    .and_then(|l| l.parse::<f64>().ok())
                    .is_some_and(|l| l < 0.5),
        },
        "affinity": format!("taskset -c {CORES} (bench, echo, planner); hog: one busy-loop process per core"),
        "planner": {
            "config": format!(
                "replan_2d_ms = {}, replan_3d_ms = {} (plan_2d_ms, plan_3d_ms: the defaults), \
                 min_spacing_ms = {MIN_SPACING_MS}, duty_cycle = 1.0, \
                 duty_window_ms = {DUTY_WINDOW_MS}, threads = {SOLVER_THREADS}",
                o.budget_2d_ms, o.budget_3d_ms
            ),
            "scenarios": {"2d": "2d-min-time-avoidable", "3d": "3d-min-time-avoidable"},
        },
        "pace_ms": PACE.as_secs_f64() * 1e3,
        "elapsed_s": elapsed.as_secs(),
        "series": Value::Object(series),
        "must_show": Value::Object(verdicts),
    });
    if let Some(dir) = o.out.parent() {
        std::fs::create_dir_all(dir).expect("create the output folder");
    }
    let text = serde_json::to_string_pretty(&doc).expect("JSON") + "\n";
    std::fs::write(&o.out, text).expect("write the results");
    println!("\n{table}\n{lines}\nwritten: {}", o.out.display());
}

// -------------------------------------------------------------------------------------
// Raw iceoryx2 round trip
// -------------------------------------------------------------------------------------

/// The services of one raw round trip: pings on `ping`'s service of `M`, wake-ups on
/// `ping`'s `wake/planner`; echoes on `pong`'s service of `M`, wake-ups on `ping`'s
/// `wake/harness`.
struct Ends<M: Message + 'static> {
    tx: Publisher<Ipc, M, ()>,
    rx: Subscriber<Ipc, M, ()>,
    notify: Notifier<Ipc>,
    listen: Listener<Ipc>,
    _node: iceoryx2::node::Node<Ipc>,
}

impl<M: Message + 'static> Ends<M> {
    /// The bench side (`echo = false`) or the echo side.
    fn open(ping: &str, pong: &str, echo: bool) -> Ends<M> {
        let side = if echo { "echo" } else { "bench" };
        let node = ipc::node(&format!("{side}-{ping}"), false).expect("node");
        let (out_v, in_v) = if echo { (pong, ping) } else { (ping, pong) };
        let tx = ipc::publisher(&ipc::open_publish_subscribe::<M>(&node, out_v).expect("service"))
            .expect("publisher");
        let rx = ipc::subscriber(&ipc::open_publish_subscribe::<M>(&node, in_v).expect("service"))
            .expect("subscriber");
        let planner_wake = ipc::open_event(&node, ping, Service::PlannerWake).expect("event");
        let harness_wake = ipc::open_event(&node, ping, Service::HarnessWake).expect("event");
        let (n, l) = if echo {
            (
                ipc::notifier(&harness_wake, ipc::WAKE_HARNESS),
                ipc::listener(&planner_wake),
            )
        } else {
            (
                ipc::notifier(&planner_wake, ipc::WAKE_INPUT),
                ipc::listener(&harness_wake),
            )
        };
        Ends {
            tx,
            rx,
            notify: n.expect("notifier"),
            listen: l.expect("listener"),
            _node: node,
        }
    }

    /// Publishes a copy of `m` (through a loaned sample: the planner publishes plans so).
    fn send(&self, m: &M) {
        let mut sample = self.tx.loan_uninit().expect("loan");
        // SAFETY: `m` is a valid `M` and the loaned slot holds room for one.
        let sample = unsafe {
            std::ptr::copy_nonoverlapping(m, sample.payload_mut().as_mut_ptr(), 1);
            sample.assume_init()
        };
        sample.send().expect("send");
    }
}

/// The echo process: copies every sample on `ping` to `pong` and notifies, until the stop
/// sequence, its parent's exit, or one hour.
fn echo<M: Message + 'static>(ping: &str, pong: &str) {
    let e = Ends::<M>::open(ping, pong, true);
    let parent = std::os::unix::process::parent_id();
    let end = Instant::now() + Duration::from_secs(3600);
    // Tells the bench the ports exist.
    e.notify.notify().expect("notify");
    loop {
        e.listen.timed_wait(|_| {}, WAIT_SLICE).expect("wait");
        let mut stop = false;
        let mut sent = false;
        while let Some(sample) = e.rx.receive().expect("receive") {
            let mut out = e.tx.loan_uninit().expect("loan");
            // SAFETY: the received payload is a valid `M`; the loaned slot holds room for
            // one.
            let out = unsafe {
                std::ptr::copy_nonoverlapping(sample.payload(), out.payload_mut().as_mut_ptr(), 1);
                out.assume_init()
            };
            stop |= sample.payload().header().sequence == STOP;
            drop(sample);
            out.send().expect("send");
            sent = true;
        }
        if sent {
            e.notify.notify().expect("notify");
        }
        if stop || std::os::unix::process::parent_id() != parent || Instant::now() > end {
            return;
        }
    }
}

/// `samples` raw round trips of `M` with an echo process (after 200 not recorded).
fn raw<M: Message + 'static>(
    tag: &str,
    kind: &str,
    slice_us: u64,
    samples: usize,
    set_sequence: fn(&mut M, u64),
) -> Series {
    let (ping, pong) = (format!("{tag}a"), format!("{tag}b"));
    let ends = Ends::<M>::open(&ping, &pong, false);
    let mut cmd = Command::new(std::env::current_exe().expect("current_exe"));
    cmd.args(["--echo", &ping, &pong, kind, &slice_us.to_string()]);
    let mut child = Proc::spawn(cmd, "latency echo");
    // The echo notifies once its ports exist.
    let t = Instant::now();
    let mut ready = false;
    while !ready {
        assert!(child.is_running(), "the echo process exited");
        assert!(
            t.elapsed() < REPLY_TIMEOUT,
            "the echo process did not start"
        );
        ends.listen
            .timed_wait(|_| ready = true, WAIT_SLICE)
            .expect("wait");
    }
    let mut msg = Box::<M>::new_uninit();
    M::zeroed_in(&mut msg);
    // SAFETY: `zeroed_in` initialised every byte.
    let mut msg = unsafe { msg.assume_init() };
    let mut series = Series::new();
    let warm = 200;
    for k in 0..warm + samples {
        let seq = k as u64 + 1;
        set_sequence(&mut msg, seq);
        let d = round_trip(&ends, &msg, seq);
        if k >= warm {
            series.record(d);
        }
        std::thread::sleep(PACE);
    }
    set_sequence(&mut msg, STOP);
    ends.send(&msg);
    ends.notify.notify().expect("notify");
    let start = Instant::now();
    while child.is_running() && start.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(10));
    }
    drop(child);
    summary(&series);
    series
}

/// One round trip: publish, notify, wait for the echo of `seq`.
fn round_trip<M: Message + 'static>(ends: &Ends<M>, msg: &M, seq: u64) -> Duration {
    let t0 = Instant::now();
    ends.send(msg);
    ends.notify.notify().expect("notify");
    loop {
        while let Some(s) = ends.rx.receive().expect("receive") {
            if s.payload().header().sequence == seq {
                return t0.elapsed();
            }
        }
        assert!(t0.elapsed() < REPLY_TIMEOUT, "no echo of {seq}");
        ends.listen.timed_wait(|_| {}, WAIT_SLICE).expect("wait");
    }
}

// -------------------------------------------------------------------------------------
// The planner service
// -------------------------------------------------------------------------------------

/// Writes the bench's planner configuration.
fn planner_toml(dir: &Path, o: &Options) -> PathBuf {
    let p = dir.join("planner.toml");
    std::fs::write(
        &p,
        format!(
            "[budget]\nreplan_2d_ms = {0}\nreplan_3d_ms = {1}\n\
             min_spacing_ms = {MIN_SPACING_MS}\nduty_cycle = 1.0\nduty_window_ms = {DUTY_WINDOW_MS}\n\n\
             [solver]\nthreads = {SOLVER_THREADS}\n{2}",
            o.budget_2d_ms,
            o.budget_3d_ms,
            o.message_slice_us
                .map(|us| format!("\n[scheduling]\nmessage_slice_us = {us}\n"))
                .unwrap_or_default()
        ),
    )
    .expect("write planner.toml");
    p
}

/// The planner's compute gate as the bench sees it: the plans it caused (from its pop-up
/// to the plan's receipt, conservatively wider than the planner's own interval) at
/// `threads` cores each.
struct Gate {
    plans: Vec<(Instant, Instant)>,
}

impl Gate {
    /// Waits until a plan of `budget_ms` fits the duty cycle with a 10 % margin.
    fn wait_admitted(&self, budget_ms: u64) {
        let window = Duration::from_millis(DUTY_WINDOW_MS);
        let need = Duration::from_millis(budget_ms * u64::from(SOLVER_THREADS));
        loop {
            let now = Instant::now();
            let from = now.checked_sub(window).unwrap_or(now);
            let used: Duration = self
                .plans
                .iter()
                .map(|&(a, b)| {
                    let (a, b) = (a.max(from), b.min(now));
                    b.saturating_duration_since(a) * SOLVER_THREADS
                })
                .sum();
            let spaced = self
                .plans
                .last()
                .is_none_or(|&(a, _)| now >= a + Duration::from_millis(MIN_SPACING_MS * 2));
            if spaced && used + need <= window.mul_f64(0.9) {
                return;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    }
}

/// One planner of `model`: the first plan, then (2-D only) the service round trip, then
/// the trigger-to-plan samples.
fn service(o: &Options, v: &str, model: Model, cond: &str) -> (Option<Series>, Series) {
    let dir = TempDir::new(&format!("latency-{v}"));
    let cfg = planner_toml(dir.path(), o);
    let mut p = planner(&cfg, v, &dir.path().join("planner.log"));
    let mut h = FakeHarness::new(v);
    assert!(
        h.wait_until(Duration::from_secs(60), |h| h.status.is_some()),
        "no status from the planner"
    );
    let name = match model {
        Model::TwoD => "2d-min-time-avoidable",
        Model::ThreeD => "3d-min-time-avoidable",
    };
    let sc = bundled(name)
        .expect("bundled scenario")
        .expect("scenario exists");
    h.set_time(0.0);
    for t in scenario_threats(&sc) {
        h.send_threat(t);
    }
    let t0 = Instant::now();
    h.send_tasking(tasking_from(&sc, 1));
    h.wake();
    assert!(
        h.wait_until(Duration::from_secs(120), |h| !h.plans.is_empty()),
        "no first plan: {:?}",
        h.status
    );
    let mut gate = Gate {
        plans: vec![(t0, Instant::now())],
    };
    let mut t = 1.0;
    let rt = (model == Model::TwoD).then(|| {
        println!("[{cond}] service round trip");
        let mut s = Series::new();
        let warm = 200;
        for k in 0..warm + o.service_samples() {
            t += 0.002;
            h.set_time(t);
            let plan = h.plans.last().expect("a plan");
            let x = state_at(plan, t).expect("plan state");
            let (id, own) = (plan.plan_id, ownship_2d(t, 0, [x[0], x[1], x[2]]));
            let own = OwnshipState { plan_id: id, ..own };
            let start = Instant::now();
            let seq = h.send_ownship(own);
            h.wake();
            assert!(
                h.wait_until(REPLY_TIMEOUT, |h| h
                    .status
                    .is_some_and(|s| s.last_input_sequence >= seq)),
                "no status for ownship {seq}"
            );
            if k >= warm {
                s.record(start.elapsed());
            }
            std::thread::sleep(PACE);
        }
        summary(&s);
        s
    });
    println!(
        "[{cond}] trigger to plan, {name}, budget {} ms",
        o.budget_ms(model)
    );
    let mut s = Series::new();
    for _ in 0..o.trigger_samples(model) {
        gate.wait_admitted(o.budget_ms(model));
        t += 1.0;
        h.set_time(t);
        let plan = h.plans.last().expect("a plan");
        let ahead = t + o.budget_ms(model) as f64 * 1e-3 + 40.0;
        let x = state_at(plan, ahead).expect("plan state");
        let threat = match model {
            Model::TwoD => static_threat(POPUP_ID, [x[0], x[1], 0.0], [1500.0, 1500.0, 0.0]),
            Model::ThreeD => static_threat(POPUP_ID, [x[0], x[1], x[2]], [1500.0; 3]),
        };
        let (plans, deferred) = (h.plans.len(), h.last_status().triggers_deferred);
        let start = Instant::now();
        h.send_threat(threat);
        h.wake();
        assert!(
            h.wait_until(REPLY_TIMEOUT, |h| h.plans.len() > plans),
            "no plan for the pop-up at {t} s: {:?}",
            h.status
        );
        let end = Instant::now();
        s.record(end - start);
        gate.plans.push((start, end));
        let new = h.plans.last().expect("a plan");
        assert_eq!(new.trigger(), Some(Trigger::PopUp), "not a pop-up plan");
        s.compute_ms.push(new.compute_ms);
        s.overhead_ms
            .push((end - start).as_secs_f64() * 1e3 - new.compute_ms);
        // The status that follows the plan says whether the gate held the pop-up back.
        h.wait_until(Duration::from_secs(5), |h| {
            h.status
                .is_some_and(|st| st.plans_made as usize >= h.plans.len())
        });
        s.deferred += h.last_status().triggers_deferred - deferred;
    }
    summary(&s);
    assert!(p.is_running(), "the planner exited");
    drop(h);
    let _ = p.terminate(Duration::from_secs(30));
    (rt, s)
}

fn summary(s: &Series) {
    println!(
        "  {} samples: p50 {} µs, p99 {} µs, max {} µs{}",
        s.h.len(),
        s.us(0.5),
        s.us(0.99),
        s.max_us(),
        if s.deferred > 0 {
            format!(", {} deferred", s.deferred)
        } else {
            String::new()
        }
    );
    if !s.compute_ms.is_empty() {
        println!("  the planner's compute and the rest: {}", s.compute_json());
    }
}

/// The calling thread's scheduler slice, set for as long as this lives (0: left alone).
struct Slice(bool);

impl Slice {
    fn set(us: u64) -> Slice {
        if us == 0 {
            return Slice(false);
        }
        let out = sched::set_thread_slice(Duration::from_micros(us)).expect("sched_setattr");
        assert!(
            matches!(out, sched::SliceOutcome::Applied(_)),
            "the scheduler slice was not applied ({out:?}); run with --message-slice-us 0"
        );
        Slice(true)
    }
}

impl Drop for Slice {
    fn drop(&mut self) {
        if self.0 {
            let _ = sched::reset_thread_slice();
        }
    }
}

// -------------------------------------------------------------------------------------
// Affinity, load, machine
// -------------------------------------------------------------------------------------

/// Pins this process (every thread; children inherit it) to [`CORES`].
fn pin_self() {
    let pid = std::process::id().to_string();
    let ok = Command::new("taskset")
        .args(["-a", "-p", "-c", CORES, &pid])
        .stdout(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    assert!(
        ok,
        "taskset -a -p -c {CORES} {pid} failed (is util-linux installed?)"
    );
    let allowed = std::fs::read_to_string("/proc/self/status")
        .unwrap_or_default()
        .lines()
        .find(|l| l.starts_with("Cpus_allowed_list"))
        .map(str::to_string)
        .unwrap_or_default();
    println!("pinned: {allowed}");
}

/// One busy-loop process per core of [`CORES`], killed on drop.
struct Hog(Vec<Child>);

impl Hog {
    fn start(limit: Duration) -> Hog {
        let exe = std::env::current_exe().expect("current_exe");
        let children = CORES
            .split(',')
            .map(|core| {
                Command::new("taskset")
                    .args(["-c", core])
                    .arg(&exe)
                    .args(["--hog", &limit.as_secs().to_string()])
                    .stdin(Stdio::null())
                    .spawn()
                    .expect("spawn the CPU hog")
            })
            .collect();
        Hog(children)
    }
}

impl Drop for Hog {
    fn drop(&mut self) {
        for c in &mut self.0 {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// Keeps one core busy until `limit` or the parent's exit.
fn hog(limit: Duration) {
    let parent = std::os::unix::process::parent_id();
    let end = Instant::now() + limit;
    let mut x = 1u64;
    while Instant::now() < end && std::os::unix::process::parent_id() == parent {
        for _ in 0..1_000_000 {
            x = std::hint::black_box(x.wrapping_mul(6364136223846793005).wrapping_add(1));
        }
    }
}

/// Other cargo and rustc processes (the `cargo bench` that started this one aside).
fn other_builds() -> String {
    let parent = std::os::unix::process::parent_id().to_string();
    ["cargo", "rustc"]
        .iter()
        .filter_map(|name| {
            let out = Command::new("pgrep").args(["-x", name]).output().ok()?;
            let n = String::from_utf8_lossy(&out.stdout)
                .lines()
                .filter(|pid| pid.trim() != parent)
                .count();
            (n > 0).then(|| format!("{n} {name}"))
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn cpu_model() -> String {
    std::fs::read_to_string("/proc/cpuinfo")
        .unwrap_or_default()
        .lines()
        .find(|l| l.starts_with("model name"))
        .and_then(|l| l.split(':').nth(1))
        .map(|s| s.trim().to_string())
        .unwrap_or_default()
}

fn shell(cmd: &[&str]) -> String {
    Command::new(cmd[0])
        .args(&cmd[1..])
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
        .unwrap_or_default()
}

//! Idle CPU of the planner service.
//!
//! Runs `service::run` in this process with the default configuration (heartbeat 1 s) on a
//! vehicle id of its own, gives it a world and a first plan (the tasking and threats of
//! `2d-min-time-avoidable`), then reads this process's CPU time from the OS over idle
//! seconds (10 by default): `/proc/self/stat` (utime + stime, in USER_HZ = 100 ticks) and
//! the sum of `/proc/self/task/*/schedstat` (nanoseconds on a CPU, every thread). Nothing
//! but the service runs: the main thread sleeps.
//!
//! ```sh
//! cargo run --release -p wingman-planner --example idle_cpu            # 10 s
//! cargo run --release -p wingman-planner --example idle_cpu -- 30      # 30 s
//! ```

use std::time::{Duration, Instant};

use iceoryx2::port::update_connections::UpdateConnections;
use wingman_interfaces::*;
use wingman_ipc as ipc;
use wingman_planner::service::{RunOptions, ServiceConfig, Shutdown};
use wingman_planning::clock::MonotonicClock;
use wingman_planning::scenario::bundled;

/// CPU time of this process: (stat ticks in ns, schedstat ns over all threads).
fn cpu_ns() -> (u64, u64) {
    let stat = std::fs::read_to_string("/proc/self/stat").expect("/proc/self/stat");
    // Fields after the command name, which ends with the last ')': state is field 3,
    // utime 14 and stime 15.
    let rest = &stat[stat.rfind(')').expect("comm") + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f[11].parse::<u64>().unwrap() + f[12].parse::<u64>().unwrap();
    let mut sched = 0;
    for task in std::fs::read_dir("/proc/self/task").expect("/proc/self/task") {
        let path = task.unwrap().path().join("schedstat");
        if let Ok(s) = std::fs::read_to_string(path) {
            sched += s
                .split_whitespace()
                .next()
                .and_then(|v| v.parse::<u64>().ok())
                .unwrap_or(0);
        }
    }
    (ticks * 10_000_000, sched)
}

fn rss_kib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        })
        .unwrap_or(0)
}

fn main() {
    let seconds: u64 = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(10);
    let vehicle = format!("idle-{}", std::process::id());
    let config = ServiceConfig {
        vehicle_id: vehicle.clone(),
        ..ServiceConfig::default()
    };
    let shutdown = Shutdown::new();
    let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
    let options = RunOptions {
        config,
        clock,
        handle_signals: false,
        shutdown: shutdown.clone(),
    };
    let service = std::thread::spawn(move || wingman_planner::service::run(options));

    // A minimal harness: the world, a wake-up, then read the status.
    let node = ipc::node(&format!("idle-harness-{vehicle}"), false).unwrap();
    let threats =
        ipc::publisher(&ipc::open_publish_subscribe::<ThreatReport>(&node, &vehicle).unwrap())
            .unwrap();
    let tasking =
        ipc::publisher(&ipc::open_publish_subscribe::<Tasking>(&node, &vehicle).unwrap()).unwrap();
    let status =
        ipc::subscriber(&ipc::open_publish_subscribe::<PlannerStatus>(&node, &vehicle).unwrap())
            .unwrap();
    let wake = ipc::notifier(
        &ipc::open_event(&node, &vehicle, Service::PlannerWake).unwrap(),
        ipc::WAKE_INPUT,
    )
    .unwrap();
    // Wait for the service's first heartbeat: its subscribers exist, so what is sent next
    // reaches them (a publisher hands its history to late subscribers only when it sends
    // again or updates its connections).
    let started = Instant::now();
    while status.receive().unwrap().is_none() {
        let _ = status.update_connections();
        assert!(started.elapsed() < Duration::from_secs(30), "no heartbeat");
        std::thread::sleep(Duration::from_millis(20));
    }
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    let mut seq = 0;
    for (k, t) in sc.known_static_threats().enumerate() {
        seq += 1;
        let mut r = ThreatReport::zeroed();
        r.header = Header::new(SENDER_HARNESS, seq, 0);
        r.threat_id = k as u32 + 1;
        r.kind = ThreatKind::Static.to_wire();
        r.center_m = t.center_m;
        r.axes_m = t.axes_m;
        r.exponents = t.exponents;
        r.yaw_rad = t.yaw_rad;
        threats.send_copy(r).unwrap();
    }
    let mut t = Tasking::zeroed();
    seq += 1;
    t.header = Header::new(SENDER_HARNESS, seq, 0);
    t.revision = 1;
    t.model = sc.model.to_wire();
    t.objective = sc.objective.to_wire();
    t.limits = sc.vehicle;
    t.weights = sc.weights;
    let s = &sc.start;
    t.start_state = s.state(sc.model);
    let f = sc.final_point.as_ref().unwrap();
    t.final_state = f.state(sc.model);
    t.target_count = sc.targets.len() as u32;
    for (k, p) in sc.targets.iter().enumerate() {
        t.targets_m[k] = *p;
    }
    tasking.send_copy(t).unwrap();
    wake.notify().unwrap();

    let mut last = None;
    while last.is_none_or(|s: PlannerStatus| {
        s.plans_made == 0 || s.state == PlannerState::Planning.to_wire()
    }) {
        assert!(
            started.elapsed() < Duration::from_secs(120),
            "no first plan: {last:?}"
        );
        std::thread::sleep(Duration::from_millis(20));
        let _ = tasking.update_connections();
        let _ = threats.update_connections();
        while let Some(sample) = status.receive().unwrap() {
            last = Some(*sample.payload());
        }
    }
    let first = last.unwrap();
    println!(
        "first plan: id {} in {:.1} ms; now idle for {seconds} s (heartbeat {} ms)",
        first.current_plan_id,
        first.last_plan_compute_ms,
        ServiceConfig::default().status.heartbeat_ms
    );
    // Let the plan's aftermath settle, then measure.
    std::thread::sleep(Duration::from_millis(500));
    while let Some(sample) = status.receive().unwrap() {
        last = Some(*sample.payload());
    }
    let seq0 = last.map_or(0, |s| s.header.sequence);
    let (stat0, sched0) = cpu_ns();
    let t0 = Instant::now();
    std::thread::sleep(Duration::from_secs(seconds));
    let (stat1, sched1) = cpu_ns();
    let wall = t0.elapsed().as_secs_f64();
    while let Some(sample) = status.receive().unwrap() {
        last = Some(*sample.payload());
    }
    let heartbeats = last.map_or(0, |s| s.header.sequence) - seq0;
    let sched_ms = (sched1 - sched0) as f64 * 1e-6;
    let stat_ms = (stat1 - stat0) as f64 * 1e-6;
    let share = sched_ms / (wall * 1e3) * 100.0;
    println!("idle wall time           {wall:.2} s");
    println!("CPU (schedstat, ns)      {sched_ms:.3} ms = {share:.4} % of one core");
    println!(
        "CPU (stat, 10 ms ticks)  {stat_ms:.0} ms = {:.3} % of one core",
        stat_ms / (wall * 1e3) * 100.0
    );
    println!("statuses published       {heartbeats} (heartbeats)");
    println!("resident memory          {} KiB", rss_kib());
    println!(
        "plans made               {}",
        last.map(|s| s.plans_made).unwrap_or(0)
    );
    let verdict = if share < 1.0 { "below" } else { "ABOVE" };
    println!("idle CPU is {verdict} 1 % of one core");

    shutdown.request();
    wake.notify().unwrap();
    let summary = service.join().unwrap().unwrap();
    println!("service stopped: {:?}", summary.exit);
    if share >= 1.0 {
        std::process::exit(1);
    }
}

//! Idle CPU of the planner service.
//!
//! Runs the service in this process (`ServiceThread`) with the default configuration (heartbeat 1 s) on a
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

use wingman_planner::service::{ServiceConfig, ServiceThread};
use wingman_planning::scenario::bundled;
use wingman_planning::scenario::messages::{take_off_tasking, take_off_threat_reports};
use wingman_testkit::fake_harness::FakeHarness;

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
    wingman_ipc::logging::init();
    let service = ServiceThread::start(config).expect("start the service");

    // A minimal harness: the world and the tasking, a wake-up, then the first plan.
    let mut h = FakeHarness::new(&vehicle);
    let sc = bundled("2d-min-time-avoidable").unwrap().unwrap();
    h.first_plan(
        &take_off_threat_reports(&sc),
        take_off_tasking(&sc, 1),
        Duration::from_secs(120),
    );
    let first = h.last_status();
    println!(
        "first plan: id {} in {:.1} ms; now idle for {seconds} s (heartbeat {} ms)",
        first.current_plan_id,
        first.last_plan_compute_ms,
        ServiceConfig::default().status.heartbeat_ms
    );
    // Let the plan's aftermath settle, then measure.
    std::thread::sleep(Duration::from_millis(500));
    h.poll();
    let seq0 = h.last_status().header.sequence;
    let (stat0, sched0) = cpu_ns();
    let t0 = Instant::now();
    std::thread::sleep(Duration::from_secs(seconds));
    let (stat1, sched1) = cpu_ns();
    let wall = t0.elapsed().as_secs_f64();
    h.poll();
    let last = h.last_status();
    let heartbeats = last.header.sequence - seq0;
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
    println!("plans made               {}", last.plans_made);
    let verdict = if share < 1.0 { "below" } else { "ABOVE" };
    println!("idle CPU is {verdict} 1 % of one core");

    let summary = service.stop(|| h.wake()).expect("the service stops");
    println!("service stopped: {:?}", summary.exit);
    if share >= 1.0 {
        std::process::exit(1);
    }
}

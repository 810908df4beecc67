//! Fixtures of the service's tests: the fake harness, test configuration and messages of
//! `wingman-testkit`, the scenario's messages, and the message loop driven pass by pass.
#![allow(dead_code, unused_imports)]

use std::time::{Duration, Instant};

pub use wingman_interfaces::*;
pub use wingman_planner::service::ServiceThread;
pub use wingman_planning::scenario::messages::{
    take_off_tasking as tasking_from, take_off_threat_reports as scenario_threats,
};
pub use wingman_testkit::fake_harness::*;
pub use wingman_testkit::process::vehicle;

use wingman_ipc::ServiceConfig;
use wingman_planner::service::{RunOptions, Shutdown};
use wingman_planning::clock::MonotonicClock;
use wingman_planning::scenario::Scenario;

/// The message loop driven pass by pass from the test thread (no WaitSet): the test
/// decides when inputs are drained relative to the solve thread's work.
pub struct Driven {
    pub ml: wingman_planner::service::MessageLoop,
    pub h: FakeHarness,
}

impl Driven {
    /// A message loop with `config` and its fake harness.
    pub fn new(config: ServiceConfig) -> Driven {
        wingman_ipc::logging::init();
        let clock: &'static MonotonicClock = Box::leak(Box::new(MonotonicClock::new()));
        let v = config.vehicle_id.clone();
        let options = RunOptions {
            config,
            clock,
            handle_signals: false,
            shutdown: Shutdown::new(),
            replay_cuts: None,
        };
        let ml = wingman_planner::service::MessageLoop::new(&options).expect("message loop");
        let h = FakeHarness::new(&v);
        Driven { ml, h }
    }

    /// One pass of the loop (status published), then the harness takes what came.
    pub fn pass(&mut self) {
        self.ml.process(false);
        self.h.poll();
    }

    /// Passes until nothing is planning or waiting for the compute gate (at most 120 s).
    pub fn settle(&mut self) {
        let start = Instant::now();
        loop {
            self.pass();
            if self.ml.status_message().state() != Some(PlannerState::Planning) {
                return;
            }
            assert!(
                start.elapsed() < Duration::from_secs(120),
                "still planning after 120 s: {:?}",
                self.ml.status_message()
            );
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    /// The status the loop would publish now.
    pub fn status(&self) -> PlannerStatus {
        self.ml.status_message()
    }

    /// Sends the threats known at take-off and the tasking of scenario `name` at mission
    /// time 0 (no pass).
    pub fn send_scenario(&mut self, name: &str) -> Scenario {
        let sc = wingman_planning::scenario::bundled(name).unwrap().unwrap();
        self.h.set_time(0.0);
        for t in scenario_threats(&sc) {
            self.h.send_threat(t);
        }
        self.h.send_tasking(tasking_from(&sc, 1));
        sc
    }

    /// [`Driven::send_scenario`], then settles on the first plan.
    pub fn first_plan(&mut self, name: &str) -> Scenario {
        let sc = self.send_scenario(name);
        self.settle();
        assert_eq!(self.status().plans_made, 1, "no first plan");
        assert_eq!(self.h.plans.len(), 1);
        sc
    }
}

/// The threats and tasking of bundled scenario `name` sent by `h`, and its first plan
/// waited for (at most `wait`).
pub fn first_plan_of(h: &mut FakeHarness, name: &str, wait: Duration) -> Scenario {
    let sc = wingman_planning::scenario::bundled(name).unwrap().unwrap();
    h.first_plan(&scenario_threats(&sc), tasking_from(&sc, 1), wait);
    sc
}

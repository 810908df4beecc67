//! A small fake harness for the service tests: it publishes inputs over real iceoryx2
//! services (through the same QoS helpers as the planner, `wingman-ipc`), wakes the
//! planner, and collects the plans and statuses it publishes; and messages built for
//! tests. Every test uses its own vehicle id ([`crate::process::vehicle`]), so parallel
//! tests never share a service.

use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use iceoryx2::port::listener::ListenerWaitError;
use wingman_interfaces::*;
use wingman_ipc::{self as ipc, ClientPorts, Ipc, ServiceConfig};

/// A configuration for tests: generous budgets (a debug build plans ~40x slower than a
/// release one; a converged plan returns early anyway), a fast heartbeat, short spacing.
pub fn test_config(vehicle_id: &str) -> ServiceConfig {
    let mut c = ServiceConfig {
        vehicle_id: vehicle_id.to_string(),
        ..ServiceConfig::default()
    };
    c.budget.plan_2d_ms = 20_000;
    c.budget.plan_3d_ms = 20_000;
    c.budget.replan_2d_ms = 20_000;
    c.budget.replan_3d_ms = 20_000;
    c.budget.min_spacing_ms = 250;
    c.budget.duty_cycle = 1.0;
    c.budget.duty_window_ms = 60_000;
    c.status.heartbeat_ms = 100;
    c
}

/// The harness side of the services.
pub struct FakeHarness {
    pub vehicle: String,
    ports: ClientPorts,
    /// Header sequence of the last input sent (one counter over all inputs).
    pub sequence: u64,
    /// Mission time of the next input, ns.
    pub mission_ns: i64,
    /// Every plan received, in order.
    pub plans: Vec<Box<Plan>>,
    pub status: Option<PlannerStatus>,
    _node: Node<Ipc>,
}

impl FakeHarness {
    pub fn new(vehicle: &str) -> FakeHarness {
        let node = ipc::node(&format!("fake-harness-{vehicle}"), false).unwrap();
        FakeHarness {
            ports: ClientPorts::open(&node, vehicle).unwrap(),
            vehicle: vehicle.to_string(),
            sequence: 0,
            mission_ns: 0,
            plans: Vec::new(),
            status: None,
            _node: node,
        }
    }

    /// The input publishers (for messages sent as they are).
    pub fn inputs(&self) -> &ipc::InputPublishers {
        &self.ports.inputs
    }

    /// The next input header.
    pub fn header(&mut self) -> Header {
        self.sequence += 1;
        Header::new(SENDER_HARNESS, self.sequence, self.mission_ns)
    }

    /// Sets the mission clock, s.
    pub fn set_time(&mut self, t: f64) {
        self.mission_ns = (t * 1e9).round() as i64;
    }

    pub fn send_tasking(&mut self, mut m: Tasking) -> u64 {
        m.header = self.header();
        self.ports.inputs.tasking.send_copy(m).unwrap();
        m.header.sequence
    }

    pub fn send_route(&mut self, mut m: LeadRoute) -> u64 {
        m.header = self.header();
        self.ports.inputs.route.send_copy(m).unwrap();
        m.header.sequence
    }

    pub fn send_lead_state(&mut self, mut m: LeadState) -> u64 {
        m.header = self.header();
        self.ports.inputs.lead_state.send_copy(m).unwrap();
        m.header.sequence
    }

    pub fn send_threat(&mut self, mut m: ThreatReport) -> u64 {
        m.header = self.header();
        self.ports.inputs.threats.send_copy(m).unwrap();
        m.header.sequence
    }

    /// Sends a threat report as it is, header included (for invalid messages).
    pub fn send_threat_raw(&mut self, m: ThreatReport) {
        self.ports.inputs.threats.send_copy(m).unwrap();
    }

    pub fn send_fix(&mut self, mut m: TrackFix) -> u64 {
        m.header = self.header();
        self.ports.inputs.tracks.send_copy(m).unwrap();
        m.header.sequence
    }

    pub fn send_ownship(&mut self, mut m: OwnshipState) -> u64 {
        m.header = self.header();
        self.ports.inputs.ownship.send_copy(m).unwrap();
        m.header.sequence
    }

    /// Hands the publishers' history to subscribers that joined since their last send (a
    /// restarted planner), as the harness does every step.
    pub fn refresh(&self) {
        self.ports.inputs.update_connections();
    }

    /// Wakes the planner (after publishing).
    pub fn wake(&self) {
        self.ports.wake.notify().unwrap();
    }

    /// Waits for the planner's first heartbeat, sends `threats` and `tasking` at mission
    /// time 0, wakes the planner and waits (at most `wait`) until its first plan is
    /// published and it is no longer planning.
    pub fn first_plan(&mut self, threats: &[ThreatReport], tasking: Tasking, wait: Duration) {
        assert!(
            self.wait_until(Duration::from_secs(60), |h| h.status.is_some()),
            "no heartbeat from the planner"
        );
        self.set_time(0.0);
        for t in threats {
            self.send_threat(*t);
        }
        self.send_tasking(tasking);
        self.wake();
        assert!(
            self.wait_until(wait, |h| !h.plans.is_empty()
                && h.status.is_some_and(
                    |s| s.plans_made == 1 && s.state() != Some(PlannerState::Planning)
                )),
            "no first plan: {:?}",
            self.status
        );
    }

    /// Takes the plans and statuses published so far.
    pub fn poll(&mut self) {
        self.ports.update_subscriptions();
        while let Some(sample) = self.ports.plan.receive().unwrap() {
            let mut b = Box::<Plan>::new_uninit();
            // SAFETY: copies one initialised `Plan` into the box's room for one.
            let b = unsafe {
                std::ptr::copy_nonoverlapping(sample.payload(), b.as_mut_ptr(), 1);
                b.assume_init()
            };
            b.validate().expect("the planner publishes valid plans");
            self.plans.push(b);
        }
        while let Some(sample) = self.ports.status.receive().unwrap() {
            let s = *sample.payload();
            s.validate().expect("the planner publishes valid statuses");
            self.status = Some(s);
        }
    }

    /// Waits (on `wake/harness`) until `done` holds, at most `timeout`.
    pub fn wait_until(&mut self, timeout: Duration, done: impl Fn(&FakeHarness) -> bool) -> bool {
        let start = Instant::now();
        loop {
            self.poll();
            if done(self) {
                return true;
            }
            if start.elapsed() > timeout {
                return false;
            }
            // A signal (a child planner killed by the test) interrupts the wait: a spurious
            // wake-up, as any other.
            match self
                .ports
                .listener
                .timed_wait(|_| {}, Duration::from_millis(50))
            {
                Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
                Err(e) => panic!("waiting on wake/harness: {e:?}"),
            }
        }
    }

    /// Waits until the planner has accepted the last input sent (its status echoes the
    /// sequence) and is not planning. A rejected last input is never echoed: wait on
    /// `messages_rejected` for it instead.
    pub fn wait_processed(&mut self, timeout: Duration) -> bool {
        let seq = self.sequence;
        self.wait_until(timeout, |h| {
            h.status.is_some_and(|s| {
                s.last_input_sequence >= seq && s.state() != Some(PlannerState::Planning)
            })
        })
    }

    /// The newest status (panics if none came).
    pub fn last_status(&self) -> PlannerStatus {
        self.status.expect("a status")
    }
}

/// A static elliptic threat report.
pub fn static_threat(id: u32, center: [f64; 3], axes: [f64; 3]) -> ThreatReport {
    let mut r = ThreatReport::zeroed();
    r.threat_id = id;
    r.kind = ThreatKind::Static.to_wire();
    r.center_m = center;
    r.axes_m = axes;
    r.exponents = [2.0, 2.0, if axes[2] > 0.0 { 2.0 } else { 0.0 }];
    r.name = threat_name(&format!("threat-{id}"));
    r
}

/// An ownship state of a 2-D mission at `t` flying plan `plan_id`.
pub fn ownship_2d(t: f64, plan_id: u64, state: [f64; 3]) -> OwnshipState {
    let mut o = OwnshipState::zeroed();
    o.time_s = t;
    o.model = Model::TwoD.to_wire();
    o.plan_id = plan_id;
    o.state[..3].copy_from_slice(&state);
    o
}

/// A moving threat on a road far north of the plan, driving east at 10 m/s.
pub fn moving_threat(id: u32) -> ThreatReport {
    let mut r = ThreatReport::zeroed();
    r.threat_id = id;
    r.kind = ThreatKind::Moving.to_wire();
    r.axes_m = [3000.0, 1500.0, 0.0];
    r.road_point_count = 2;
    r.road_m[0] = [-60000.0, 120000.0, 0.0];
    r.road_m[1] = [60000.0, 120000.0, 0.0];
    r.estimate_time_s = 0.0;
    r.estimate_mean = [1000.0, 10.0, 0.0];
    r.estimate_covariance = [250000.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 0.01];
    r.accel_sigma_mps2 = 0.2;
    r.accel_tau_s = 30.0;
    r
}

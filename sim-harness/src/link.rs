//! The harness's iceoryx2 ports to the planner, `wingman_ipc::ClientPorts` (the planner's
//! own QoS helpers, so both sides agree): publishers of every input, subscribers of `plan`
//! and `status`, the `wake/planner` notifier and the `wake/harness` listener; with one
//! header sequence counter across the inputs. Every message sent or taken goes into the
//! flight log.

use std::time::{Duration, Instant};

use iceoryx2::node::Node;
use wingman_interfaces::{
    Header, LeadRoute, LeadState, Message, OwnshipState, Plan, PlannerState, PlannerStatus,
    SENDER_HARNESS, Tasking, ThreatReport, TrackFix, Wire,
};
use wingman_ipc::{self as ipc, ClientPorts, Ipc, IpcError};

use crate::flight_log::{Direction, Entry, Kind, LogWriter};

/// A port operation that failed.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    #[error("iceoryx2: {0}")]
    Ipc(#[from] IpcError),
    #[error("cannot {what}: {detail}")]
    Port { what: &'static str, detail: String },
}

fn port_err(what: &'static str, e: impl core::fmt::Debug) -> LinkError {
    LinkError::Port {
        what,
        detail: format!("{e:?}"),
    }
}

/// What the planner published, taken in one poll.
#[derive(Debug, Default)]
pub struct Received {
    pub plans: Vec<Box<Plan>>,
    /// Messages that failed `validate()` (dropped).
    pub rejected: u64,
}

/// The harness's side of the services of one vehicle.
pub struct PlannerLink {
    ports: ClientPorts,
    /// Header sequence of the last input sent (one counter over every input service).
    sequence: u64,
    /// Mission time stamped on the next input, s.
    mission_s: f64,
    last_status: Option<PlannerStatus>,
    pub log: LogWriter,
    // Declared last: dropped after every port.
    _node: Node<Ipc>,
}

macro_rules! sender {
    ($name:ident, $port:ident, $ty:ty) => {
        /// Stamps the header (next sequence, mission time), sends and logs the message;
        /// returns its sequence.
        pub fn $name(&mut self, mut m: $ty) -> Result<u64, LinkError> {
            m.header = self.next_header();
            self.ports
                .inputs
                .$port
                .send_copy(m)
                .map_err(|e| port_err(concat!("send ", stringify!($ty)), e))?;
            self.log.message(Direction::ToPlanner, self.mission_s, &m);
            Ok(m.header.sequence)
        }
    };
}

impl PlannerLink {
    /// Opens every port of `vehicle_id` on a node of its own.
    pub fn open(vehicle_id: &str, log: LogWriter) -> Result<PlannerLink, LinkError> {
        let node = ipc::node(&format!("wingman-harness-{vehicle_id}"), false)?;
        Ok(PlannerLink {
            ports: ClientPorts::open(&node, vehicle_id)?,
            sequence: 0,
            mission_s: 0.0,
            last_status: None,
            log,
            _node: node,
        })
    }

    /// Sets the mission time stamped on the inputs that follow.
    pub fn set_time(&mut self, t: f64) {
        self.mission_s = t;
    }

    /// The sequence of the last input sent.
    pub fn sequence(&self) -> u64 {
        self.sequence
    }

    /// Continues the header sequence above `last` (a resumed flight: the planner has
    /// processed inputs up to `last`, and the lock-step clock waits for the status to echo
    /// a higher one).
    pub fn continue_sequence(&mut self, last: u64) {
        self.sequence = self.sequence.max(last);
    }

    /// The newest status taken.
    pub fn status(&self) -> Option<&PlannerStatus> {
        self.last_status.as_ref()
    }

    /// Forgets the newest status (a new planner process is starting: wait for its own).
    pub fn forget_status(&mut self) {
        self.last_status = None;
    }

    fn next_header(&mut self) -> Header {
        self.sequence += 1;
        Header::new(
            SENDER_HARNESS,
            self.sequence,
            (self.mission_s * 1e9).round() as i64,
        )
    }

    sender!(send_tasking, tasking, Tasking);
    sender!(send_route, route, LeadRoute);
    sender!(send_lead_state, lead_state, LeadState);
    sender!(send_threat, threats, ThreatReport);
    sender!(send_fix, tracks, TrackFix);
    sender!(send_ownship, ownship, OwnshipState);

    /// Sends a logged input exactly as it was, header included (a replay). Returns
    /// `false` for a kind that is not an input.
    pub fn send_logged(&mut self, kind: Kind, bytes: &[u8]) -> Result<bool, LinkError> {
        macro_rules! resend {
            ($port:ident, $ty:ty) => {{
                let m: $ty = <$ty as Wire>::read_from_bytes(bytes)
                    .map_err(|e| port_err("decode a logged message", e))?;
                self.ports
                    .inputs
                    .$port
                    .send_copy(m)
                    .map_err(|e| port_err("send a logged message", e))?;
                m.header.sequence
            }};
        }
        let sequence = match kind {
            Kind::Tasking => resend!(tasking, Tasking),
            Kind::LeadRoute => resend!(route, LeadRoute),
            Kind::LeadState => resend!(lead_state, LeadState),
            Kind::ThreatReport => resend!(threats, ThreatReport),
            Kind::TrackFix => resend!(tracks, TrackFix),
            Kind::OwnshipState => resend!(ownship, OwnshipState),
            Kind::Plan | Kind::PlannerStatus => return Ok(false),
        };
        self.sequence = self.sequence.max(sequence);
        Ok(true)
    }

    /// Hands the publishers' history to subscribers that joined since (a restarted
    /// planner); called every step.
    pub fn refresh(&self) {
        self.ports.inputs.update_connections();
    }

    /// Wakes the planner (after publishing a step's inputs).
    pub fn wake(&self) -> Result<(), LinkError> {
        self.ports
            .wake
            .notify()
            .map(|_| ())
            .map_err(|e| port_err("notify wake/planner", e))
    }

    /// Takes every status and plan published so far; each is validated first (an
    /// invalid one is counted and dropped) and logged.
    pub fn poll(&mut self) -> Result<Received, LinkError> {
        let mut out = Received::default();
        self.ports.update_subscriptions();
        // The status first: the planner publishes a plan before the status that follows
        // it, so the plans taken after a status include every plan that status counts.
        while let Some(sample) = self
            .ports
            .status
            .receive()
            .map_err(|e| port_err("receive a status", e))?
        {
            let s = *sample.payload();
            drop(sample);
            self.log.message(Direction::FromPlanner, self.mission_s, &s);
            match s.validate() {
                Ok(()) => self.last_status = Some(s),
                Err(e) => {
                    out.rejected += 1;
                    tracing::warn!(error = %e, "dropped an invalid status");
                }
            }
        }
        while let Some(sample) = self
            .ports
            .plan
            .receive()
            .map_err(|e| port_err("receive a plan", e))?
        {
            let mut b = Box::<Plan>::new_uninit();
            // SAFETY: copies one initialised `Plan` from shared memory into the box's room
            // for one (160 KiB: never through the stack).
            let b = unsafe {
                std::ptr::copy_nonoverlapping(sample.payload(), b.as_mut_ptr(), 1);
                b.assume_init()
            };
            drop(sample);
            self.log
                .message(Direction::FromPlanner, self.mission_s, &*b);
            match b.validate() {
                Ok(()) => out.plans.push(b),
                Err(e) => {
                    out.rejected += 1;
                    tracing::warn!(error = %e, "dropped an invalid plan");
                }
            }
        }
        Ok(out)
    }

    /// Waits on `wake/harness` (at most `timeout`) for the planner to publish something.
    pub fn wait(&self, timeout: Duration) -> Result<(), LinkError> {
        self.ports
            .listener
            .timed_wait(|_| {}, timeout)
            .map(|_| ())
            .map_err(|e| port_err("wait on wake/harness", e))
    }

    /// Waits until the planner has processed every input sent (its status echoes the
    /// last sequence) and is not planning, taking what it publishes meanwhile; at most
    /// `timeout`, and `alive()` is asked between waits (a dead planner ends the wait).
    /// Returns what was received and whether the condition was met.
    pub fn sync(
        &mut self,
        timeout: Duration,
        mut alive: impl FnMut() -> bool,
    ) -> Result<(Received, bool), LinkError> {
        let start = Instant::now();
        let seq = self.sequence;
        let mut all = Received::default();
        loop {
            let r = self.poll()?;
            all.plans.extend(r.plans);
            all.rejected += r.rejected;
            let done = self.last_status.is_some_and(|s| {
                s.last_input_sequence >= seq && s.state() != Some(PlannerState::Planning)
            });
            if done {
                self.log.write(&Entry::Sync {
                    mission_s: self.mission_s,
                    sequence: seq,
                });
                return Ok((all, true));
            }
            if start.elapsed() > timeout || !alive() {
                return Ok((all, false));
            }
            self.wait(Duration::from_millis(100))?;
        }
    }
}

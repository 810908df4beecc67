//! The world model of the message thread: the tasking, the lead's route and state, the
//! threats (static, and moving ones each with a Kalman filter fed by every track fix), the
//! ownship state, and the mission clock read from message headers.
//!
//! Fixed-capacity and allocation-free after construction: every update copies a `Copy`
//! message into a slot. [`World::fill_problem`] writes one plan's [`Problem`] into a
//! problem whose buffers are reused.

use super::sequence_gaps::SequenceGaps;
use std::time::Duration;

use wingman_interfaces::{
    Header, LeadRoute, LeadState, MAX_ROAD_POINTS, MAX_TARGETS, Model, Objective, OwnshipState,
    STALE_LEAD, STALE_OWNSHIP, STALE_TASKING, STALE_TRACKS, Tasking, ThreatKind, ThreatReport,
    TrackFix, ValidationError, Wire,
};

use super::triggers::{self, RouteDecision, TaskingDecision};
use wingman_ipc::config::StalenessConfig;
use wingman_planning::dynamics::{DynamicsError, Limits};
use wingman_planning::estimation::{
    Estimate, EstimationError, GaussMarkov, KalmanFilter, MovingThreat, Road,
};
use wingman_planning::lead::{LeadError, LeadPath};
use wingman_planning::problem::{CostWeights, Problem, Threats};
use wingman_planning::threat::{MAX_THREATS, Superquadric, ThreatError, ThreatLayout};

/// Static threats the world holds (the planner's layout capacity).
pub const MAX_STATIC_THREATS: usize = MAX_THREATS;
/// Moving threats the world holds.
pub const MAX_MOVING_THREATS: usize = 8;

/// The input services, for staleness and header ordering.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Input {
    Tasking = 0,
    LeadRoute = 1,
    LeadState = 2,
    Threats = 3,
    Tracks = 4,
    Ownship = 5,
}

impl Input {
    pub const COUNT: usize = 6;

    pub const fn name(self) -> &'static str {
        match self {
            Input::Tasking => "tasking",
            Input::LeadRoute => "lead/route",
            Input::LeadState => "lead/state",
            Input::Threats => "threats",
            Input::Tracks => "tracks",
            Input::Ownship => "ownship",
        }
    }
}

/// A static threat as reported.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StaticThreat {
    pub report: ThreatReport,
    /// World epoch at which it was last changed.
    pub epoch: u64,
}

impl StaticThreat {
    /// Its superquadric in `D` dimensions (2-D: the first two of each triple).
    pub fn shape<const D: usize>(&self) -> Result<Superquadric<D>, ThreatError> {
        let r = &self.report;
        Superquadric::new(
            std::array::from_fn(|i| r.center_m[i]),
            std::array::from_fn(|i| r.axes_m[i]),
            std::array::from_fn(|i| r.exponents[i]),
            r.yaw_rad,
        )
    }
}

/// A moving threat: its report and the Kalman filter of its distance along the road.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MovingTrack {
    pub report: ThreatReport,
    model: GaussMarkov,
    /// The road in 3-D (z = 0 for a 2-D mission, where it projects as the 2-D road).
    road: Road<3>,
    filter: KalmanFilter,
    meas_sigma: f64,
    /// Wall-clock time of the last report or fix.
    pub last_update: Duration,
    /// World epoch at which the report last changed.
    pub epoch: u64,
    /// Scheduled re-plan time over the current plan, if it touches it.
    pub t_r: Option<f64>,
}

impl MovingTrack {
    fn new(report: &ThreatReport, now: Duration, epoch: u64) -> Result<Self, EstimationError> {
        let model = GaussMarkov::new(report.accel_tau_s, report.accel_sigma_mps2)?;
        let road = Road::<3>::new(report.road())?;
        let cov = nalgebra::Matrix3::from_row_slice(&report.estimate_covariance);
        let estimate = Estimate::new(
            report.estimate_time_s,
            nalgebra::Vector3::from(report.estimate_mean),
            cov,
        )?;
        // The measurement noise comes with each fix; 1 m until the first one.
        let meas_sigma = 1.0;
        Ok(MovingTrack {
            report: *report,
            model,
            road,
            filter: KalmanFilter::new(model, meas_sigma, estimate)?,
            meas_sigma,
            last_update: now,
            epoch,
            t_r: None,
        })
    }

    /// The current estimate of `(d, v, a)`.
    pub fn estimate(&self) -> &Estimate {
        self.filter.estimate()
    }

    /// Predict to the fix's time, then update with its position projected on the road.
    /// A fix the filter refuses leaves the track as it was (not predicted half-way).
    fn apply_fix(&mut self, fix: &TrackFix, now: Duration) -> Result<(), EstimationError> {
        let mut filter = if fix.sigma_m != self.meas_sigma {
            KalmanFilter::new(self.model, fix.sigma_m, *self.filter.estimate())?
        } else {
            self.filter
        };
        filter.predict_to(fix.time_s)?;
        filter.update_position(&self.road, &fix.position_m)?;
        self.filter = filter;
        self.meas_sigma = fix.sigma_m;
        self.last_update = now;
        Ok(())
    }

    /// The threat in `D` dimensions with the current estimate.
    pub fn threat<const D: usize>(&self) -> Result<MovingThreat<D>, EstimationError> {
        let r = &self.report;
        let n = r.road().len();
        let points: [[f64; D]; MAX_ROAD_POINTS] =
            std::array::from_fn(|k| std::array::from_fn(|i| r.road_m[k][i]));
        let road = Road::<D>::new(&points[..n])?;
        let axes = std::array::from_fn(|i| r.axes_m[i]);
        Ok(
            MovingThreat::new(road, axes, self.model, *self.filter.estimate())?
                .with_appears_at(r.appeared_at_s),
        )
    }
}

/// Where a threat report went.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ThreatSlot {
    Static(usize),
    Moving(usize),
}

/// What a threat report changed.
#[derive(Debug, Clone, PartialEq)]
pub enum ThreatChange {
    /// A threat not known before.
    New(ThreatSlot),
    /// A known threat reported with other parameters (the latest report wins).
    Changed(ThreatSlot),
    /// A repeat of the report held.
    Unchanged,
    /// No room for another threat of this kind.
    Full,
    /// A moving threat whose road or estimate the filter refuses.
    Refused(EstimationError),
}

/// What a track fix did.
#[derive(Debug, Clone, PartialEq)]
pub enum FixOutcome {
    /// The filter of this moving threat took it.
    Applied(usize),
    /// No moving threat has this id.
    UnknownThreat,
    /// The filter refused it (e.g. older than the estimate).
    Refused(EstimationError),
}

/// One plan's start, spliced onto the current plan (or the tasking's start).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Splice {
    /// Start (commit) time.
    pub t0: f64,
    /// Start state (model order, zero-padded).
    pub x0: [f64; 7],
    /// Targets of the tasking already passed: the plan visits `targets[targets_from..]`.
    pub targets_from: usize,
}

/// A problem the world cannot write.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BuildError {
    #[error("no tasking")]
    NoTasking,
    #[error("a rendezvous needs the lead's route")]
    NoRoute,
    #[error("tasking limits: {0}")]
    Vehicle(#[from] DynamicsError),
    #[error("lead route: {0}")]
    Lead(#[from] LeadError),
    #[error("threat layout: {0}")]
    Layout(#[from] ThreatError),
}

/// Senders whose last header is kept per input (more interleaving on one input is
/// unusual: two publishers per input service are allowed).
pub const SENDERS_PER_INPUT: usize = 4;

/// The world model.
#[derive(Debug, Clone)]
pub struct World {
    pub tasking: Option<Tasking>,
    pub route: Option<LeadRoute>,
    pub lead_state: Option<LeadState>,
    pub ownship: Option<OwnshipState>,
    statics: [Option<StaticThreat>; MAX_STATIC_THREATS],
    movings: [Option<MovingTrack>; MAX_MOVING_THREATS],
    /// Mission time of the newest header, ns.
    pub now_ns: i64,
    /// Highest header sequence of an accepted input message.
    pub max_sequence: u64,
    /// Grows with every change of the threat world.
    pub epoch: u64,
    /// Threat reports refused for lack of room (the status then says `Degraded`: the
    /// planner ignores a threat).
    pub threats_dropped: u64,
    /// Input messages lost before they were read (gaps in the senders' sequences).
    pub gaps: SequenceGaps,
    last_seen: [Option<Duration>; Input::COUNT],
    /// Per input, the last accepted header of each of up to [`SENDERS_PER_INPUT`] senders.
    last_header: [[Option<Header>; SENDERS_PER_INPUT]; Input::COUNT],
    /// Mission time between the last two ownship reports of one sender, ns (0 before two).
    ownship_step_ns: i64,
}

impl Default for World {
    fn default() -> Self {
        World {
            tasking: None,
            route: None,
            lead_state: None,
            ownship: None,
            statics: [None; MAX_STATIC_THREATS],
            movings: [None; MAX_MOVING_THREATS],
            now_ns: i64::MIN,
            max_sequence: 0,
            epoch: 0,
            threats_dropped: 0,
            gaps: SequenceGaps::default(),
            last_seen: [None; Input::COUNT],
            last_header: [[None; SENDERS_PER_INPUT]; Input::COUNT],
            ownship_step_ns: 0,
        }
    }
}

impl World {
    /// Mission time of the newest header, s (`-inf` before any message).
    pub fn now_s(&self) -> f64 {
        if self.now_ns == i64::MIN {
            f64::NEG_INFINITY
        } else {
            self.now_ns as f64 * 1e-9
        }
    }

    /// Accepts a validated message's header: against the same sender's previous one on
    /// this input, its sequence must grow and its mission clock must not go backwards.
    /// Advances the mission clock, the input's freshness and the highest accepted
    /// sequence; a refused header changes nothing.
    pub fn accept_header(
        &mut self,
        input: Input,
        header: &Header,
        wall: Duration,
    ) -> Result<(), ValidationError> {
        let k = input as usize;
        let senders = &mut self.last_header[k];
        let same = senders
            .iter()
            .position(|h| h.is_some_and(|h| h.sender_id == header.sender_id));
        let previous = same.and_then(|s| senders[s]);
        if let Some(previous) = &previous {
            header.check_follows(previous)?;
        }
        // A sender beyond the first few on one input takes the first slot.
        let slot = same
            .or_else(|| senders.iter().position(Option::is_none))
            .unwrap_or(0);
        senders[slot] = Some(*header);
        self.last_seen[k] = Some(wall);
        self.now_ns = self.now_ns.max(header.mission_time_ns);
        if input == Input::Ownship
            && let Some(previous) = previous
        {
            let step = header
                .mission_time_ns
                .saturating_sub(previous.mission_time_ns);
            if step > 0 {
                self.ownship_step_ns = step;
            }
        }
        self.max_sequence = self.max_sequence.max(header.sequence);
        Ok(())
    }

    /// Takes a tasking; the decision says whether it triggers a plan.
    pub fn apply_tasking(&mut self, t: &Tasking) -> TaskingDecision {
        let d = triggers::tasking_decision(self.tasking.as_ref(), t);
        if d != TaskingDecision::Stale {
            self.tasking = Some(*t);
        }
        d
    }

    /// Takes a lead route.
    pub fn apply_route(&mut self, r: &LeadRoute) -> RouteDecision {
        let d = triggers::route_decision(self.route.as_ref(), r);
        if d != RouteDecision::Stale {
            self.route = Some(*r);
        }
        d
    }

    pub fn apply_lead_state(&mut self, s: &LeadState) {
        self.lead_state = Some(*s);
    }

    pub fn apply_ownship(&mut self, s: &OwnshipState) {
        self.ownship = Some(*s);
    }

    /// The mission time between the last two ownship reports of one sender, s (0 before
    /// two): how late the planner may see a moment pass, so time triggers fire this much
    /// earlier.
    pub fn ownship_step_s(&self) -> f64 {
        self.ownship_step_ns as f64 * 1e-9
    }

    /// Takes a threat report: the latest report per `threat_id` wins. A threat that
    /// changes kind leaves its old table only once the new entry is stored: a report that
    /// is refused (no room, or a filter that refuses it) changes nothing. A report refused
    /// for room is counted in [`World::threats_dropped`].
    pub fn apply_threat(&mut self, r: &ThreatReport, wall: Duration) -> ThreatChange {
        let moving = r.kind() == Some(ThreatKind::Moving);
        let epoch = self.epoch + 1;
        let change = if moving {
            let existing = self.moving_index(r.threat_id);
            if let Some(i) = existing
                && let Some(m) = &self.movings[i]
                && same_report(&m.report, r)
            {
                return ThreatChange::Unchanged;
            }
            let (slot, change) = match existing {
                Some(i) => (i, ThreatChange::Changed(ThreatSlot::Moving(i))),
                None => match self.movings.iter().position(Option::is_none) {
                    Some(i) => (i, ThreatChange::New(ThreatSlot::Moving(i))),
                    None => {
                        self.threats_dropped += 1;
                        return ThreatChange::Full;
                    }
                },
            };
            let track = match MovingTrack::new(r, wall, epoch) {
                Ok(t) => t,
                Err(e) => return ThreatChange::Refused(e),
            };
            self.movings[slot] = Some(track);
            if let Some(i) = self.static_index(r.threat_id) {
                self.statics[i] = None;
            }
            change
        } else {
            let existing = self.static_index(r.threat_id);
            if let Some(i) = existing
                && let Some(s) = &self.statics[i]
                && same_report(&s.report, r)
            {
                return ThreatChange::Unchanged;
            }
            let (slot, change) = match existing {
                Some(i) => (i, ThreatChange::Changed(ThreatSlot::Static(i))),
                None => match self.statics.iter().position(Option::is_none) {
                    Some(i) => (i, ThreatChange::New(ThreatSlot::Static(i))),
                    None => {
                        self.threats_dropped += 1;
                        return ThreatChange::Full;
                    }
                },
            };
            self.statics[slot] = Some(StaticThreat { report: *r, epoch });
            if let Some(i) = self.moving_index(r.threat_id) {
                self.movings[i] = None;
            }
            change
        };
        self.epoch = epoch;
        change
    }

    /// Feeds a track fix to its moving threat's filter.
    pub fn apply_fix(&mut self, f: &TrackFix, wall: Duration) -> FixOutcome {
        let Some(i) = self.moving_index(f.threat_id) else {
            return FixOutcome::UnknownThreat;
        };
        let Some(track) = self.movings[i].as_mut() else {
            return FixOutcome::UnknownThreat;
        };
        match track.apply_fix(f, wall) {
            Ok(()) => FixOutcome::Applied(i),
            Err(e) => FixOutcome::Refused(e),
        }
    }

    fn static_index(&self, id: u32) -> Option<usize> {
        self.statics
            .iter()
            .position(|s| s.as_ref().is_some_and(|s| s.report.threat_id == id))
    }

    fn moving_index(&self, id: u32) -> Option<usize> {
        self.movings
            .iter()
            .position(|s| s.as_ref().is_some_and(|s| s.report.threat_id == id))
    }

    /// A static threat by slot.
    pub fn static_threat(&self, i: usize) -> Option<&StaticThreat> {
        self.statics.get(i).and_then(Option::as_ref)
    }

    /// A moving threat by slot.
    pub fn moving(&self, i: usize) -> Option<&MovingTrack> {
        self.movings.get(i).and_then(Option::as_ref)
    }

    /// A moving threat by slot, mutable (its scheduled `t_r`).
    pub fn moving_mut(&mut self, i: usize) -> Option<&mut MovingTrack> {
        self.movings.get_mut(i).and_then(Option::as_mut)
    }

    /// The static threats held.
    pub fn statics(&self) -> impl Iterator<Item = &StaticThreat> {
        self.statics.iter().flatten()
    }

    /// The moving threats held, with their slots.
    pub fn movings(&self) -> impl Iterator<Item = (usize, &MovingTrack)> {
        self.movings
            .iter()
            .enumerate()
            .filter_map(|(i, m)| m.as_ref().map(|m| (i, m)))
    }

    /// Clears every moving threat's scheduled `t_r`.
    pub fn clear_schedules(&mut self) {
        for m in self.movings.iter_mut().flatten() {
            m.t_r = None;
        }
    }

    /// The earliest scheduled `t_r`.
    pub fn next_replan(&self) -> Option<f64> {
        self.movings
            .iter()
            .flatten()
            .filter_map(|m| m.t_r)
            .min_by(f64::total_cmp)
    }

    /// Bits `STALE_*` of inputs that stopped arriving, at wall-clock time `wall`.
    pub fn stale_bits(&self, wall: Duration, bounds: &StalenessConfig) -> u32 {
        let old = |seen: Option<Duration>, ms: u64| {
            seen.is_none_or(|s| wall.saturating_sub(s) > Duration::from_millis(ms))
        };
        let Some(tasking) = &self.tasking else {
            return STALE_TASKING;
        };
        let mut bits = 0;
        if tasking.objective() == Some(Objective::MinTimeRendezvous)
            && old(self.last_seen[Input::LeadState as usize], bounds.lead_ms)
        {
            bits |= STALE_LEAD;
        }
        if old(self.last_seen[Input::Ownship as usize], bounds.ownship_ms) {
            bits |= STALE_OWNSHIP;
        }
        if self
            .movings
            .iter()
            .flatten()
            .any(|m| old(Some(m.last_update), bounds.tracks_ms))
        {
            bits |= STALE_TRACKS;
        }
        bits
    }

    /// Writes the problem of one plan starting at `splice` into `out`, reusing its
    /// buffers. Threats whose shape does not fit the model (e.g. a static threat without
    /// a vertical axis in a 3-D mission) are left out; their count is returned.
    pub fn fill_problem(&self, splice: &Splice, out: &mut Problem) -> Result<usize, BuildError> {
        let t = self.tasking.as_ref().ok_or(BuildError::NoTasking)?;
        let (Some(model), Some(objective)) = (t.model(), t.objective()) else {
            return Err(BuildError::NoTasking);
        };
        out.limits = wingman_planning::problem::vehicle_limits(model, &t.limits)?;
        out.model = model;
        out.objective = objective;
        out.weights = CostWeights {
            alpha: t.weights.alpha,
            beta: t.weights.beta,
            stiffness: t.weights.stiffness,
        };
        out.t0 = splice.t0;
        out.x0 = splice.x0;
        let targets = t.targets();
        out.targets.clear();
        out.targets
            .extend_from_slice(&targets[splice.targets_from.min(targets.len())..]);
        out.final_state = match objective {
            Objective::MinTimeRendezvous => None,
            _ => Some(t.final_state),
        };
        out.final_time = (objective == Objective::FixedTime).then_some(t.final_time_s);
        out.wind = match model {
            Model::TwoD => [t.wind_mps[0], t.wind_mps[1], 0.0],
            Model::ThreeD => t.wind_mps,
        };
        out.lead = match objective {
            Objective::MinTimeRendezvous => {
                let r = self.route.as_ref().ok_or(BuildError::NoRoute)?;
                Some(LeadPath::new(r.points(), r.speed_mps, r.start_time_s)?)
            }
            _ => None,
        };
        let stiffness = t.weights.stiffness;
        match model {
            Model::TwoD => {
                if !matches!(out.threats, Threats::Planar { .. }) {
                    out.threats = Threats::Planar {
                        layout: ThreatLayout::new(stiffness)?,
                        moving: Vec::with_capacity(MAX_MOVING_THREATS),
                    };
                }
                let Threats::Planar { layout, moving } = &mut out.threats else {
                    unreachable!("set just above");
                };
                self.fill_threats(layout, moving, stiffness)
            }
            Model::ThreeD => {
                if !matches!(out.threats, Threats::Spatial { .. }) {
                    out.threats = Threats::Spatial {
                        layout: ThreatLayout::new(stiffness)?,
                        moving: Vec::with_capacity(MAX_MOVING_THREATS),
                    };
                }
                let Threats::Spatial { layout, moving } = &mut out.threats else {
                    unreachable!("set just above");
                };
                self.fill_threats(layout, moving, stiffness)
            }
        }
    }

    fn fill_threats<const D: usize>(
        &self,
        layout: &mut ThreatLayout<D>,
        moving: &mut Vec<MovingThreat<D>>,
        stiffness: f64,
    ) -> Result<usize, BuildError> {
        *layout = ThreatLayout::new(stiffness)?;
        let mut skipped = 0;
        for s in self.statics() {
            match s.shape::<D>() {
                Ok(q) => layout.push(q)?,
                Err(_) => skipped += 1,
            }
        }
        moving.clear();
        for (_, m) in self.movings() {
            match m.threat::<D>() {
                Ok(t) if moving.len() < moving.capacity() => moving.push(t),
                _ => skipped += 1,
            }
        }
        Ok(skipped)
    }
}

/// Two reports of the same threat say the same (headers aside).
fn same_report(a: &ThreatReport, b: &ThreatReport) -> bool {
    let h = core::mem::size_of::<Header>();
    a.as_bytes()[h..] == b.as_bytes()[h..]
}

/// A placeholder problem whose buffers hold a full plan's inputs, allocated once at
/// start-up and refilled by [`World::fill_problem`] for every plan.
pub fn reusable_problem() -> Problem {
    let limits = Limits::planar(1.0, 1.0).expect("positive placeholder limits");
    Problem {
        model: Model::TwoD,
        objective: Objective::MinTime,
        limits,
        weights: CostWeights {
            alpha: 0.5,
            beta: 0.5,
            stiffness: 1.0,
        },
        t0: 0.0,
        x0: [0.0; 7],
        targets: Vec::with_capacity(MAX_TARGETS),
        final_state: None,
        final_time: None,
        lead: None,
        threats: Threats::Planar {
            layout: ThreatLayout::new(1.0).expect("positive placeholder stiffness"),
            moving: Vec::with_capacity(MAX_MOVING_THREATS),
        },
        wind: [0.0; 3],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_senders_sequence_must_grow_on_an_input_whoever_else_sends_there() {
        let mut w = World::default();
        let wall = Duration::ZERO;
        let h = |sender: u32, sequence: u64| Header::new(sender, sequence, 1_000);
        assert!(w.accept_header(Input::Threats, &h(2, 5), wall).is_ok());
        // Another sender in between: its own counter, accepted.
        assert!(w.accept_header(Input::Threats, &h(7, 1), wall).is_ok());
        // The first sender may not step back or repeat, though another sent since.
        for sequence in [5, 4] {
            assert!(matches!(
                w.accept_header(Input::Threats, &h(2, sequence), wall),
                Err(ValidationError::SequenceNotIncreasing { .. })
            ));
        }
        assert!(w.accept_header(Input::Threats, &h(2, 6), wall).is_ok());
        // A refused header moved nothing: the highest accepted sequence is 6.
        assert_eq!(w.max_sequence, 6);
        // Another input keeps its own record.
        assert!(w.accept_header(Input::Ownship, &h(2, 3), wall).is_ok());
    }

    /// The ownship step is one sender's: a second sender 0.5 s behind, in between, does
    /// not make it 0.6 s; other inputs and refused headers do not move it.
    #[test]
    fn the_ownship_step_is_taken_per_sender() {
        let mut w = World::default();
        // (input, sender, sequence, mission time in ms, accepted, the step after it in s).
        let reports = [
            (Input::Ownship, 2, 1, 10_000, true, 0.0),
            (Input::Ownship, 7, 1, 9_500, true, 0.0),
            (Input::Ownship, 2, 2, 10_100, true, 0.1),
            (Input::Ownship, 7, 2, 9_600, true, 0.1),
            (Input::LeadState, 2, 3, 10_150, true, 0.1),
            // A repeated sequence is refused: its 0.3 s step does not count.
            (Input::Ownship, 2, 2, 10_400, false, 0.1),
            (Input::Ownship, 2, 4, 10_300, true, 0.2),
        ];
        for (input, sender, sequence, t_ms, accepted, step) in reports {
            let header = Header::new(sender, sequence, t_ms * 1_000_000);
            let result = w.accept_header(input, &header, Duration::ZERO);
            assert_eq!(result.is_ok(), accepted, "{input:?} {sender} {sequence}");
            assert!(
                (w.ownship_step_s() - step).abs() < 1e-12,
                "after {input:?} {sender} {sequence}: {} s",
                w.ownship_step_s()
            );
        }
    }
}

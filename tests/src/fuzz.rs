//! Fuzzing the planner's inputs at scale (the seeded generator behind the `fuzz_inputs`
//! binary; a short run is a test): random and mutated bytes of every input message go
//! through `validate()` and, over real iceoryx2 services, through the message loop of a
//! planner service running in this process.
//!
//! Each case is one input message, of a type drawn at random:
//! - a third are random bytes (header included: almost all fail `validate()` at once);
//! - the rest are a valid message of that type with a valid header (this sender, the next
//!   sequence, the mission clock; a tasking or route the next revision), whose body gets
//!   one to four mutations: an 8-byte word
//!   set to NaN, an infinity, ±0, ±1e300, a tiny number, random bits, or a pair of `u32`s
//!   (0, 1, 2^31, `u32::MAX`, a small number), or one bit flipped. These reach the
//!   handlers whenever they stay valid: a tasking, a route, threats, fixes, lead and
//!   ownship states of every shape the checks let through.
//!
//! What must hold: a message that passes `validate()` holds no non-finite number; every
//! message is read, the service rejects (counts in `messages_rejected`) exactly those that
//! fail `validate()` and counts none as lost (`messages_lost`), it never panics or stops,
//! and every plan and status it publishes validates. Messages go in rounds of at most four (the smallest subscriber buffer), each
//! waited for by the service's read count, so none is lost to a full buffer.

use std::time::{Duration, Instant};

use rand::{Rng, RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use wingman_interfaces::*;
use wingman_ipc::ServiceConfig;
use wingman_planner::service::{ExitReason, ServiceThread};
use wingman_planning::scenario::bundled;
use wingman_planning::scenario::messages::{take_off_tasking, take_off_threat_reports};
use wingman_testkit::fake_harness::{FakeHarness, static_threat};

/// Messages per round: no input subscriber buffers fewer.
const ROUND: usize = 4;
/// The longest wait for the service to read a round.
const WAIT: Duration = Duration::from_secs(60);
/// The header's size: mutations of a valid message keep its header.
const HEADER_BYTES: usize = size_of::<Header>();

/// What a run did.
#[derive(Debug, Clone, Default)]
pub struct FuzzSummary {
    pub cases: u64,
    /// Cases that passed `validate()` (and so reached the handlers).
    pub valid: u64,
    /// Cases that failed it (the service must reject exactly these).
    pub invalid: u64,
    /// Plans the service published meanwhile.
    pub plans: u64,
    pub elapsed: Duration,
}

/// A failure: what broke, and the case that broke it (its type and bytes in hex).
#[derive(Debug, Clone)]
pub struct FuzzFailure {
    pub what: String,
    pub case: Option<(u64, &'static str, String)>,
}

impl std::fmt::Display for FuzzFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.what)?;
        if let Some((k, kind, hex)) = &self.case {
            write!(f, " (case {k}, a {kind}: {hex})")?;
        }
        Ok(())
    }
}

/// The valid message of each input type that mutations start from.
struct Templates {
    tasking: Tasking,
    route: LeadRoute,
    lead_state: LeadState,
    threat: ThreatReport,
    fix: TrackFix,
    ownship: OwnshipState,
}

impl Templates {
    fn new() -> Templates {
        let sc = bundled("2d-min-time-rendezvous-avoidable")
            .expect("a bundled scenario")
            .expect("valid");
        let mut route = LeadRoute::zeroed();
        route.revision = 1;
        route.point_count = 3;
        route.points_m[1] = [40_000.0, 10_000.0, 0.0];
        route.points_m[2] = [80_000.0, 10_000.0, 0.0];
        route.speed_mps = 150.0;
        let mut lead_state = LeadState::zeroed();
        lead_state.position_m = [1000.0, 2000.0, 0.0];
        lead_state.speed_mps = 150.0;
        let mut fix = TrackFix::zeroed();
        fix.threat_id = 90;
        fix.position_m = [30_000.0, 20_000.0, 0.0];
        fix.sigma_m = 50.0;
        let mut ownship = OwnshipState::zeroed();
        ownship.model = sc.model.to_wire();
        Templates {
            tasking: take_off_tasking(&sc, 2),
            route,
            lead_state,
            threat: take_off_threat_reports(&sc)
                .first()
                .copied()
                .unwrap_or_else(|| static_threat(1, [30_000.0, 30_000.0, 0.0], [4000.0; 3])),
            fix,
            ownship,
        }
    }
}

/// The six input types.
const KINDS: [&str; 6] = [
    "Tasking",
    "LeadRoute",
    "LeadState",
    "ThreatReport",
    "TrackFix",
    "OwnshipState",
];

/// One case's message, built from the generator; sent by `send`.
enum Case {
    Tasking(Box<Tasking>),
    Route(Box<LeadRoute>),
    LeadState(LeadState),
    Threat(Box<ThreatReport>),
    Fix(TrackFix),
    Ownship(OwnshipState),
}

/// Random bytes (no header given), or `template` with `header` and a mutated body.
fn build<M: Message>(template: &M, header: Option<Header>, rng: &mut ChaCha8Rng) -> M {
    let mut bytes = if let Some(header) = header {
        // Every message starts with its header.
        let mut b = template.as_bytes().to_vec();
        b[..HEADER_BYTES].copy_from_slice(header.as_bytes());
        for _ in 0..rng.random_range(1..=4) {
            mutate(&mut b, rng);
        }
        b
    } else {
        let mut b = vec![0u8; size_of::<M>()];
        rng.fill_bytes(&mut b);
        b
    };
    bytes.truncate(size_of::<M>());
    M::read_from_bytes(&bytes).expect("the message's size")
}

/// One mutation of the body (past the header) of a message's bytes.
fn mutate(b: &mut [u8], rng: &mut ChaCha8Rng) {
    let words = (b.len() - HEADER_BYTES) / 8;
    let at = HEADER_BYTES + 8 * rng.random_range(0..words);
    let word: [u8; 8] = match rng.random_range(0..12) {
        0 => f64::NAN.to_le_bytes(),
        1 => f64::INFINITY.to_le_bytes(),
        2 => f64::NEG_INFINITY.to_le_bytes(),
        3 => 0.0f64.to_le_bytes(),
        4 => (-0.0f64).to_le_bytes(),
        5 => 1e300f64.to_le_bytes(),
        6 => (-1e300f64).to_le_bytes(),
        7 => f64::MIN_POSITIVE.to_le_bytes(),
        8 => rng.next_u64().to_le_bytes(),
        9 => {
            let special = [0, 1, 1 << 31, u32::MAX, rng.random_range(0..64)];
            let lo = special[rng.random_range(0..special.len())];
            let hi = special[rng.random_range(0..special.len())];
            (u64::from(hi) << 32 | u64::from(lo)).to_le_bytes()
        }
        10 => (rng.random_range(-1e6..1e6f64)).to_le_bytes(),
        _ => {
            let mut w = [0u8; 8];
            w.copy_from_slice(&b[at..at + 8]);
            let bit = rng.random_range(0..64);
            (u64::from_le_bytes(w) ^ (1 << bit)).to_le_bytes()
        }
    };
    b[at..at + 8].copy_from_slice(&word);
}

impl Case {
    /// A case of a random type; a tasking or a route template gets the next revision
    /// first, so that a valid one is news to the planner (a new plan).
    fn draw(t: &mut Templates, header: Option<Header>, rng: &mut ChaCha8Rng) -> (usize, Case) {
        let kind = rng.random_range(0..KINDS.len());
        let case = match kind {
            0 => {
                t.tasking.revision = t.tasking.revision.wrapping_add(1);
                Case::Tasking(Box::new(build(&t.tasking, header, rng)))
            }
            1 => {
                t.route.revision = t.route.revision.wrapping_add(1);
                Case::Route(Box::new(build(&t.route, header, rng)))
            }
            2 => Case::LeadState(build(&t.lead_state, header, rng)),
            3 => Case::Threat(Box::new(build(&t.threat, header, rng))),
            4 => Case::Fix(build(&t.fix, header, rng)),
            _ => Case::Ownship(build(&t.ownship, header, rng)),
        };
        (kind, case)
    }

    /// `validate()`, and for a message that passes, that it holds no non-finite number.
    fn check(&self) -> Result<bool, String> {
        fn one<M: Message>(m: &M) -> Result<bool, String> {
            match m.validate() {
                Ok(()) => match m.first_non_finite() {
                    None => Ok(true),
                    Some(field) => Err(format!("`{field}` is not finite past validate()")),
                },
                Err(_) => Ok(false),
            }
        }
        match self {
            Case::Tasking(m) => one(&**m),
            Case::Route(m) => one(&**m),
            Case::LeadState(m) => one(m),
            Case::Threat(m) => one(&**m),
            Case::Fix(m) => one(m),
            Case::Ownship(m) => one(m),
        }
    }

    fn hex(&self) -> String {
        let bytes = match self {
            Case::Tasking(m) => m.as_bytes(),
            Case::Route(m) => m.as_bytes(),
            Case::LeadState(m) => m.as_bytes(),
            Case::Threat(m) => m.as_bytes(),
            Case::Fix(m) => m.as_bytes(),
            Case::Ownship(m) => m.as_bytes(),
        };
        bytes.iter().map(|b| format!("{b:02x}")).collect()
    }

    fn send(self, h: &FakeHarness) -> Result<(), String> {
        let inputs = h.inputs();
        let sent = match self {
            Case::Tasking(m) => inputs.tasking.send_copy(*m).map(drop),
            Case::Route(m) => inputs.route.send_copy(*m).map(drop),
            Case::LeadState(m) => inputs.lead_state.send_copy(m).map(drop),
            Case::Threat(m) => inputs.threats.send_copy(*m).map(drop),
            Case::Fix(m) => inputs.tracks.send_copy(m).map(drop),
            Case::Ownship(m) => inputs.ownship.send_copy(m).map(drop),
        };
        sent.map_err(|e| format!("send: {e:?}"))
    }
}

/// Runs `cases` cases from `seed` against a planner service on `vehicle` started here
/// (deployment defaults but a 100 ms heartbeat); `progress` is called after each round
/// with the cases done.
pub fn run(
    cases: u64,
    seed: u64,
    vehicle: &str,
    mut progress: impl FnMut(u64),
) -> Result<FuzzSummary, FuzzFailure> {
    let fail = |what: String| FuzzFailure { what, case: None };
    let mut config = ServiceConfig {
        vehicle_id: vehicle.to_string(),
        ..ServiceConfig::default()
    };
    config.status.heartbeat_ms = 100;
    let service = ServiceThread::start(config).map_err(|e| fail(format!("start: {e}")))?;
    let mut h = FakeHarness::new(vehicle);
    if !h.wait_until(WAIT, |h| h.status.is_some()) {
        return Err(fail("no heartbeat from the service".into()));
    }
    let mut templates = Templates::new();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut summary = FuzzSummary::default();
    let started = Instant::now();
    let received_before = h.last_status().messages_received;
    let rejected_before = h.last_status().messages_rejected;
    let mut sent = 0u64;
    while summary.cases < cases {
        let n = ROUND.min((cases - summary.cases) as usize);
        for _ in 0..n {
            // Mission time moves on a millisecond per case: the time triggers run too.
            h.mission_ns += 1_000_000;
            // A third are random bytes: they take no sequence of this sender's.
            let header = (!rng.random_ratio(1, 3)).then(|| h.header());
            let (kind, case) = Case::draw(&mut templates, header, &mut rng);
            let k = summary.cases;
            let valid = case.check().map_err(|what| FuzzFailure {
                what,
                case: Some((k, KINDS[kind], case.hex())),
            })?;
            summary.valid += u64::from(valid);
            summary.invalid += u64::from(!valid);
            case.send(&h).map_err(fail)?;
            summary.cases += 1;
            sent += 1;
        }
        h.wake();
        let want = received_before + sent;
        if !h.wait_until(WAIT, |h| {
            h.status.is_some_and(|s| s.messages_received >= want)
        }) {
            return Err(fail(format!(
                "the service stopped reading after {} cases: {:?}",
                summary.cases, h.status
            )));
        }
        let s = h.last_status();
        if s.messages_lost != 0 {
            return Err(fail(format!(
                "after {} cases the service counts {} messages lost (none was)",
                summary.cases, s.messages_lost
            )));
        }
        if s.messages_rejected - rejected_before != summary.invalid {
            return Err(fail(format!(
                "after {} cases the service rejected {} messages, {} failed validate()",
                summary.cases,
                s.messages_rejected - rejected_before,
                summary.invalid
            )));
        }
        summary.plans += h.plans.len() as u64;
        h.plans.clear();
        progress(summary.cases);
    }
    summary.elapsed = started.elapsed();
    let end = service
        .stop(|| h.wake())
        .map_err(|e| fail(format!("the service failed: {e}")))?;
    if end.exit != ExitReason::Requested {
        return Err(fail(format!("the service exited: {:?}", end.exit)));
    }
    Ok(summary)
}

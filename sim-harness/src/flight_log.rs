//! `flight.log`: every message between the harness and the planner, both ways, with its
//! mission and wall-clock time, plus the lock-step barriers — a stream of bincode 2
//! (serde, standard configuration) [`Entry`] values. A message is kept as its exact wire
//! bytes (`docs/INTERFACES.md`), so the log needs no schema of its own and a reader gets
//! the very message the other side saw.

use std::fs::File;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::Path;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use wingman_interfaces::{Message, Plan, Service, Wire};

/// Version of the log format; a reader refuses other versions.
pub const LOG_VERSION: u32 = 1;

/// Which way a message went.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Direction {
    ToPlanner,
    FromPlanner,
}

/// The message type of a logged message.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Kind {
    Tasking,
    LeadRoute,
    LeadState,
    ThreatReport,
    TrackFix,
    OwnshipState,
    Plan,
    PlannerStatus,
}

impl Kind {
    /// The kind of a service's messages (`None` for the event services).
    pub fn of(service: Service) -> Option<Kind> {
        Some(match service {
            Service::Tasking => Kind::Tasking,
            Service::LeadRoute => Kind::LeadRoute,
            Service::LeadState => Kind::LeadState,
            Service::Threats => Kind::ThreatReport,
            Service::Tracks => Kind::TrackFix,
            Service::Ownship => Kind::OwnshipState,
            Service::Plan => Kind::Plan,
            Service::Status => Kind::PlannerStatus,
            Service::PlannerWake | Service::HarnessWake => return None,
        })
    }
}

/// One record of the log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Entry {
    /// First record: what was flown and the planner's configuration (TOML).
    Start {
        version: u32,
        scenario: String,
        vehicle_id: String,
        clock: String,
        planner_config: String,
    },
    /// A message, as its wire bytes.
    Message {
        /// Wall-clock time since the start of the flight, ns.
        wall_ns: u64,
        /// The harness's mission time when it sent or took the message, s.
        mission_s: f64,
        direction: Direction,
        kind: Kind,
        bytes: Vec<u8>,
    },
    /// A lock-step barrier: the harness notified the planner and waited until its status
    /// echoed `sequence` with the planner idle.
    Sync { mission_s: f64, sequence: u64 },
    /// Last record.
    End { mission_s: f64, completed: bool },
    /// A resumed flight (`fly --resume`), right after `Start`: the flight took over the
    /// mission of a planner already flying it, at mission time `mission_s` (the planner was
    /// at `planner_s`, flying plan `plan_id`, with inputs processed up to `last_sequence`).
    /// Added after `End`, so logs written before it read as they did.
    Resume {
        mission_s: f64,
        planner_s: f64,
        plan_id: u64,
        last_sequence: u64,
    },
}

/// The log could not be written or read.
#[derive(Debug, thiserror::Error)]
pub enum LogError {
    #[error("{path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: record {index}: {message}")]
    Decode {
        path: String,
        index: usize,
        message: String,
    },
    #[error("{path}: not a flight log of version {LOG_VERSION} ({found})")]
    Version { path: String, found: String },
}

/// Writes the log as the flight goes.
pub struct LogWriter {
    out: Option<BufWriter<File>>,
    path: String,
    start: Instant,
    failed: bool,
}

impl LogWriter {
    /// Creates (truncates) `path`.
    pub fn create(path: &Path) -> Result<LogWriter, LogError> {
        let p = path.display().to_string();
        let f = File::create(path).map_err(|source| LogError::Io {
            path: p.clone(),
            source,
        })?;
        Ok(LogWriter {
            out: Some(BufWriter::new(f)),
            path: p,
            start: Instant::now(),
            failed: false,
        })
    }

    /// A writer that keeps nothing (tests, replays).
    pub fn discard() -> LogWriter {
        LogWriter {
            out: None,
            path: String::new(),
            start: Instant::now(),
            failed: false,
        }
    }

    /// Appends one record. A write error is logged once; the flight goes on.
    pub fn write(&mut self, entry: &Entry) {
        let Some(out) = self.out.as_mut() else {
            return;
        };
        if let Err(e) =
            bincode::serde::encode_into_std_write(entry, out, bincode::config::standard())
            && !self.failed
        {
            self.failed = true;
            tracing::error!(path = %self.path, error = %e, "cannot write the flight log");
        }
    }

    /// Appends a message.
    pub fn message<M: Message>(&mut self, direction: Direction, mission_s: f64, m: &M) {
        let Some(kind) = Kind::of(M::SERVICE) else {
            return;
        };
        if self.out.is_none() {
            return;
        }
        let entry = Entry::Message {
            wall_ns: self.start.elapsed().as_nanos() as u64,
            mission_s,
            direction,
            kind,
            bytes: m.as_bytes().to_vec(),
        };
        self.write(&entry);
    }

    /// Flushes to the file.
    pub fn flush(&mut self) -> Result<(), LogError> {
        if let Some(out) = self.out.as_mut() {
            out.flush().map_err(|source| LogError::Io {
                path: self.path.clone(),
                source,
            })?;
        }
        Ok(())
    }
}

/// Reads every record of a log.
pub fn read(path: &Path) -> Result<Vec<Entry>, LogError> {
    let p = path.display().to_string();
    let f = File::open(path).map_err(|source| LogError::Io {
        path: p.clone(),
        source,
    })?;
    let mut r = BufReader::new(f);
    let mut entries = Vec::new();
    loop {
        // End of file between records ends the log.
        let mut probe = [0u8; 1];
        match r.read(&mut probe) {
            Ok(0) => break,
            Ok(_) => {}
            Err(source) => return Err(LogError::Io { path: p, source }),
        }
        let mut chained = (&probe[..]).chain(&mut r);
        let entry: Entry =
            bincode::serde::decode_from_std_read(&mut chained, bincode::config::standard())
                .map_err(|e| LogError::Decode {
                    path: p.clone(),
                    index: entries.len(),
                    message: e.to_string(),
                })?;
        entries.push(entry);
    }
    match entries.first() {
        Some(Entry::Start { version, .. }) if *version == LOG_VERSION => Ok(entries),
        Some(Entry::Start { version, .. }) => Err(LogError::Version {
            path: p,
            found: format!("version {version}"),
        }),
        _ => Err(LogError::Version {
            path: p,
            found: "no start record".into(),
        }),
    }
}

/// The logged bytes of every message of `kind` that went `direction`, in log order.
pub fn messages(
    entries: &[Entry],
    direction: Direction,
    kind: Kind,
) -> impl Iterator<Item = &[u8]> + '_ {
    entries.iter().filter_map(move |e| match e {
        Entry::Message {
            direction: d,
            kind: k,
            bytes,
            ..
        } if *d == direction && *k == kind => Some(bytes.as_slice()),
        _ => None,
    })
}

/// Every plan the harness took, in log order (a plan of the wrong length is skipped).
pub fn plans(entries: &[Entry]) -> impl Iterator<Item = Box<Plan>> + '_ {
    messages(entries, Direction::FromPlanner, Kind::Plan).filter_map(decode_plan)
}

/// A message of type `M` from its logged bytes (`None` if the length is wrong).
pub fn decode<M: Wire>(bytes: &[u8]) -> Option<M> {
    M::read_from_bytes(bytes).ok()
}

/// A plan from its logged bytes, on the heap (160 KiB never cross the stack).
pub fn decode_plan(bytes: &[u8]) -> Option<Box<Plan>> {
    if bytes.len() != size_of::<Plan>() {
        return None;
    }
    let mut b = Box::<Plan>::new_uninit();
    // SAFETY: `Plan` is a plain wire type (every bit pattern is a value) and the lengths
    // match; the copy goes byte for byte into the box's room for one plan.
    unsafe {
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), b.as_mut_ptr().cast::<u8>(), bytes.len());
        Some(b.assume_init())
    }
}

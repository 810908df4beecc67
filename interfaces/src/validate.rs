//! The typed error of `validate()` and the small checks every message uses.
//!
//! The error is `Copy` and holds only static strings and numbers, so rejecting a message
//! never allocates (the planner's message loop relies on that).

use crate::PROTOCOL_VERSION;

/// Why a received message was rejected. Names the offending field.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum ValidationError {
    /// The sender speaks another version of this contract.
    #[error("protocol version {found}, this side speaks {expected}")]
    ProtocolVersion { expected: u32, found: u32 },
    /// A floating-point field holds NaN or an infinity.
    #[error("field `{field}` holds a non-finite number")]
    NonFinite { field: &'static str },
    /// A count field is larger than the array it counts.
    #[error("field `{field}` is {count}, over the capacity {capacity}")]
    CountOverCapacity {
        field: &'static str,
        count: u32,
        capacity: u32,
    },
    /// A count field is smaller than the message needs (e.g. a road of one point).
    #[error("field `{field}` is {count}, under the minimum {minimum}")]
    CountTooSmall {
        field: &'static str,
        count: u32,
        minimum: u32,
    },
    /// An enum field holds a value this version does not know.
    #[error("field `{field}` holds the unknown value {value}")]
    UnknownEnum { field: &'static str, value: u32 },
    /// Times in the message (or against the previous message) go backwards.
    #[error("time goes backwards at `{field}`")]
    TimeBackwards { field: &'static str },
    /// A number outside the range the field allows.
    #[error("field `{field}` is out of range: {problem}")]
    OutOfRange {
        field: &'static str,
        problem: &'static str,
    },
    /// A sender's header sequence does not grow on a service: a repeat or a step back.
    #[error("header sequence {found} does not follow {previous}")]
    SequenceNotIncreasing { previous: u64, found: u64 },
}

impl ValidationError {
    /// A short, stable name of the error class, for counters and logs.
    pub const fn kind(&self) -> &'static str {
        match self {
            ValidationError::ProtocolVersion { .. } => "protocol-version",
            ValidationError::NonFinite { .. } => "non-finite",
            ValidationError::CountOverCapacity { .. } => "count-over-capacity",
            ValidationError::CountTooSmall { .. } => "count-too-small",
            ValidationError::UnknownEnum { .. } => "unknown-enum",
            ValidationError::TimeBackwards { .. } => "time-backwards",
            ValidationError::OutOfRange { .. } => "out-of-range",
            ValidationError::SequenceNotIncreasing { .. } => "sequence-not-increasing",
        }
    }
}

/// The result of a check.
pub type Checked<T = ()> = Result<T, ValidationError>;

pub(crate) fn protocol(found: u32) -> Checked {
    if found == PROTOCOL_VERSION {
        Ok(())
    } else {
        Err(ValidationError::ProtocolVersion {
            expected: PROTOCOL_VERSION,
            found,
        })
    }
}

/// `count` as an index bound, if it is within `min..=capacity`.
pub(crate) fn count(field: &'static str, count: u32, min: u32, capacity: usize) -> Checked<usize> {
    // Capacities are small constants; the conversion cannot truncate.
    let cap = capacity as u32;
    if count > cap {
        return Err(ValidationError::CountOverCapacity {
            field,
            count,
            capacity: cap,
        });
    }
    if count < min {
        return Err(ValidationError::CountTooSmall {
            field,
            count,
            minimum: min,
        });
    }
    Ok(count as usize)
}

pub(crate) fn enum_value<T>(
    field: &'static str,
    value: u32,
    parse: fn(u32) -> Option<T>,
) -> Checked<T> {
    parse(value).ok_or(ValidationError::UnknownEnum { field, value })
}

pub(crate) fn positive(field: &'static str, v: f64) -> Checked {
    if v > 0.0 {
        Ok(())
    } else {
        Err(ValidationError::OutOfRange {
            field,
            problem: "must be positive",
        })
    }
}

pub(crate) fn non_negative(field: &'static str, v: f64) -> Checked {
    if v >= 0.0 {
        Ok(())
    } else {
        Err(ValidationError::OutOfRange {
            field,
            problem: "must not be negative",
        })
    }
}

pub(crate) fn within(
    field: &'static str,
    v: f64,
    lo: f64,
    hi: f64,
    problem: &'static str,
) -> Checked {
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(ValidationError::OutOfRange { field, problem })
    }
}

pub(crate) fn not_before(field: &'static str, later: f64, earlier: f64) -> Checked {
    if later >= earlier {
        Ok(())
    } else {
        Err(ValidationError::TimeBackwards { field })
    }
}

/// Every point of a polyline differs horizontally from the one before it.
pub(crate) fn polyline(field: &'static str, points: &[[f64; 3]]) -> Checked {
    for w in points.windows(2) {
        let (dx, dy) = (w[1][0] - w[0][0], w[1][1] - w[0][1]);
        if dx * dx + dy * dy <= 0.0 {
            return Err(ValidationError::OutOfRange {
                field,
                problem: "consecutive points must differ horizontally",
            });
        }
    }
    Ok(())
}

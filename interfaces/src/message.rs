use crate::layout::Wire;
use crate::{Header, Service, ValidationError};

/// A top-level message: a wire type with a header, a service, and a validity check.
pub trait Message: Wire + core::fmt::Debug {
    /// The service this message travels on.
    const SERVICE: Service;

    /// The common header.
    fn header(&self) -> &Header;

    /// Rejects a message that is not safe to act on: another protocol version, NaN or
    /// infinity anywhere, a count over capacity, an unknown enum value, times going
    /// backwards inside the message, a number outside its range.
    fn validate(&self) -> Result<(), ValidationError>;
}

/// Shared first steps of every `validate()`: protocol version, then every `f64` finite.
pub(crate) fn validate_common<M: Message>(m: &M) -> Result<(), ValidationError> {
    m.header().validate()?;
    match m.first_non_finite() {
        Some(field) => Err(ValidationError::NonFinite { field }),
        None => Ok(()),
    }
}

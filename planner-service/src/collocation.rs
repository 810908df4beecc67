//! Direct orthogonal collocation at Legendre–Gauss–Radau points (FORMULATION.md §4): the
//! LGR scheme, the mesh and node layout, and the sparse NLP of the transcription.

pub mod lgr;
pub mod mesh;
pub mod transcription;

pub use lgr::Lgr;
pub use mesh::{Layout, Mesh};
pub use transcription::{Transcription, TranscriptionSettings};

//! Direct orthogonal collocation at Legendre–Gauss–Radau points (FORMULATION.md §4): the
//! LGR scheme, the mesh and node layout, and the sparse NLP of the transcription.

pub mod export;
pub mod kkt;
pub mod lgr;
pub mod mesh;
pub mod nlp_settings;
pub mod refine;
pub mod solve;
pub mod transcription;
pub mod warm;

pub use export::{ExportSettings, export, fly_reference};
pub use kkt::{KktLabels, KktSolver, StructuredKkt};
pub use lgr::Lgr;
pub use mesh::{Layout, Mesh};
pub use refine::{RefineSettings, interval_errors, refine, split_crossings};
pub use solve::{
    FeralOrdering, FeralScaling, MuStrategy, NlpOutcome, NlpSettings, NlpSettingsError, NlpStatus,
    PrimalDual, SolveBudget, solve,
};
pub use transcription::{Transcription, TranscriptionSettings};

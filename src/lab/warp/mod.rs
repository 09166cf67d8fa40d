//! `penumbra warp`: look at any sampling routine of the library or BSDF sampler — its samples
//! in an equal-area projection, their histogram beside the integrated pdf, the chi-square
//! verdict of the test suite's harness — and dump samples / evaluate pdfs for external tools.
//!
//! - [`registry`]: the routines, their parameters and defaults.
//! - [`params`]: `KEY=VALUE` parsing and validation.
//! - [`run`]: drawing samples (harness stream or sample pattern) and the chi-square test.
//! - [`plot`]: equal-area projections and the PNG panels.
//! - [`io`]: text and `.npy` tables.

pub mod io;
pub mod params;
pub mod plot;
pub mod registry;
pub mod run;

pub use registry::{Domain, ROUTINES, Routine, Warp, build, find, list_text};
pub use run::{RunConfig, RunResult, chi2_config, pdf_at, run};

//! The lab: the lecture's comparison figures rendered and measured, with montages, a
//! convergence plot and an HTML/JSON report.
//!
//! `figures` declares what to render (one [`figures::Figure`] per lecture slide), `runner`
//! renders and measures it against a reference, `report` writes `results.json`, the
//! convergence plot and `index.html`. `warp` is the sampling-routine explorer behind
//! `penumbra warp`.

pub mod figures;
pub mod mask;
pub mod report;
pub mod runner;
pub mod warp;

pub use figures::{Figure, Panel, lecture_figures};
pub use report::LabResults;
pub use runner::{LabOptions, run_lab};

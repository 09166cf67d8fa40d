//! The lab: comparison figures, convergence plots and the HTML report. TODO(issue 7).

pub mod warp;

//! The compiled half of the `penumbra` Python package (`penumbra._native`): scenes, renders
//! into numpy arrays, image I/O and metrics, sample-range merges and the warp registry. The
//! pure-Python half (`python/penumbra/`) accepts the friendlier argument forms and documents
//! the API; everything that computes is the renderer's own library code.

use pyo3::prelude::*;

mod errors;
mod images;
mod render;
mod warp;

/// How the CLI words errors and warnings (said once, no repeated prefixes): shared, not copied.
#[path = "../../src/cli/messages.rs"]
#[allow(dead_code)]
mod messages;

/// The module `penumbra._native`.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    render::register(m)?;
    images::register(m)?;
    warp::register(m)?;
    Ok(())
}

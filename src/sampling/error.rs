//! Errors of the sampling module: bad weights or shapes given to the distributions.

use thiserror::Error;

/// Why a distribution or sampler could not be built.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SamplingError {
    /// There was nothing to sample from.
    #[error("cannot build a distribution from zero weights/bins")]
    Empty,
    /// A weight was negative, NaN or infinite.
    #[error("weight {index} is {value}, but weights must be finite and non-negative")]
    BadWeight {
        /// Position of the offending weight.
        index: usize,
        /// Its value.
        value: f32,
    },
    /// All weights were zero.
    #[error("all weights are zero")]
    ZeroSum,
    /// A sample pattern name that `--pattern` does not know.
    #[error(
        "unknown sample pattern {name:?}; expected one of: fixed, random, grid, stratified, lhs, sobol"
    )]
    UnknownPattern {
        /// The name given.
        name: String,
    },
    /// The data length does not match the stated shape.
    #[error("2D distribution of {nu}x{nv} needs {} values, got {len}", nu * nv)]
    Shape {
        /// Columns.
        nu: usize,
        /// Rows.
        nv: usize,
        /// Number of values supplied.
        len: usize,
    },
}

/// Check that weights are finite and non-negative; the first offender is reported.
pub(crate) fn check_weights(w: &[f32]) -> Result<(), SamplingError> {
    if w.is_empty() {
        return Err(SamplingError::Empty);
    }
    match w.iter().position(|x| !(x.is_finite() && *x >= 0.0)) {
        Some(index) => Err(SamplingError::BadWeight {
            index,
            value: w[index],
        }),
        None => Ok(()),
    }
}

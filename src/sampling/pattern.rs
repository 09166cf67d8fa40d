//! Sample patterns: the 1D/2D samples of N eye rays × M shadow rays in a pixel.
//!
//! Every value is a pure function of (seed, pixel, dimension, index, count): no RNG state is
//! shared between threads, so the image is the same under any scheduling.
//! TODO(issue 2): implement fixed, random, grid, stratified, lhs, sobol.

use glam::{UVec2, Vec2};

/// The pattern names accepted by `--pattern`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PatternKind {
    /// Always the same point (the centre of the domain).
    Fixed,
    /// Independent uniform random points (PCG).
    Random,
    /// Regular near-square grid of stratum centres.
    Grid,
    /// Jittered stratified: one random point per stratum of a near-square grid.
    Stratified,
    /// Latin hypercube (N-rooks).
    Lhs,
    /// Owen-scrambled Sobol (sobol_burley).
    Sobol,
}

/// A generator of well-distributed samples for one dimension of a pixel's sample set.
///
/// `index ∈ [0, count)` picks the sample in a set of `count` samples that the pattern
/// stratifies jointly; `dim` names the integrand dimension (each gets an independent scramble).
pub trait SamplePattern: Send + Sync {
    /// The 1D sample `index` of `count` for `dim` in `pixel`.
    fn sample_1d(&self, pixel: UVec2, dim: u32, index: u32, count: u32) -> f32;
    /// The 2D sample `index` of `count` for `dim` in `pixel`.
    fn sample_2d(&self, pixel: UVec2, dim: u32, index: u32, count: u32) -> Vec2;
    /// Which pattern this is.
    fn kind(&self) -> PatternKind;
}

/// Make the pattern of `kind` with a global seed.
pub fn make_pattern(kind: PatternKind, seed: u64) -> Box<dyn SamplePattern> {
    let _ = (kind, seed);
    todo!("issue 2")
}

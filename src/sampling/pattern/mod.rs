//! Sample patterns: the 1D/2D samples of N eye rays × M shadow rays in a pixel.
//!
//! Every value is a pure function of (seed, pixel, dimension, index, count): no RNG state is
//! shared between threads, so the image is the same under any scheduling.
//!
//! Semantics of `sample_2d(pixel, dim, index, count)`: the `count` samples of one (pixel, dim)
//! are stratified jointly. Strata are assigned to indices through a hashed permutation keyed by
//! (seed, pixel, dim), so that reusing an index in another dimension does not correlate them.
//! Indices ≥ `count` wrap modulo `count` for the stratified patterns; `count = 0` counts as 1.
//!
//! The definitions, one file each (`fixed.rs`, …: its keys, its 1D and its 2D values):
//! - `fixed`: always the centre (0.5, 0.5) (0.5 in 1D).
//! - `random`: independent uniform points, a SplitMix64 hash of (seed, pixel, dim, index).
//! - `grid`: centres of an nx × ny grid with nx·ny = count, where nx is the largest divisor of
//!   count with nx ≤ √count (x gets nx cells, y gets ny). A prime count therefore gives
//!   1 × count strip strata: still one sample per stratum, but stratified along y only.
//! - `stratified`: one uniformly jittered point in each stratum of that same grid.
//! - `lhs`: Latin hypercube (N-rooks): count strata on each axis, x and y strata permuted
//!   independently, jittered inside.
//! - `sobol`: Owen-scrambled Sobol (sobol_burley), dimensions 0 and 1 of a sequence whose seed
//!   is hashed from (seed, pixel, dim) ("padding" by independent shuffles, which keeps every 2D
//!   projection a (0,2)-sequence). Indices ≥ 2^16 continue in a differently seeded sequence.
//!
//! 1D versions are analogous (`grid`: stratum centres, `stratified`/`lhs`: jittered strata).
//! What they share: `sets.rs` (a sample set's keys and strata, and the dispatch by kind).
//!
//! Hot path: [`SamplePattern::pixel`] makes one pixel's [`PixelSamples`] (in `pixel.rs`), which
//! derives each sample set's keys once, at its first use, then evaluates the set 16
//! consecutive indices at a time (integrators walk a pixel's indices in order), so most
//! samples cost one compare and a load. `stratified` batches run in an integer form (`fast.rs`:
//! lane-parallel permutation rounds; stratum and jitter as one fixed-point number; its portable
//! loops compiled for every instruction set by `Cpu::dispatch`) or with AVX-512 intrinsics
//! (`avx512.rs`). The values are bit-identical to those of `sample_1d` / `sample_2d`
//! (tests/pat_golden.rs).

mod avx512;
mod fast;
mod fixed;
mod grid;
mod lhs;
mod pixel;
mod random;
mod sets;
mod sobol;
mod stratified;
#[cfg(test)]
mod tests;

pub use pixel::PixelSamples;

use glam::{UVec2, Vec2};
use std::fmt;
use std::str::FromStr;

use super::error::SamplingError;
use super::hash::{hash_keys, hash_step};
use crate::isa::Cpu;
#[cfg(target_arch = "x86_64")]
use crate::isa::{Kernel, Token};
#[cfg(target_arch = "x86_64")]
use avx512::RawSets;
use sets::{SetKeys, Strata};

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

impl PatternKind {
    /// Every pattern, in CLI order.
    pub const ALL: [PatternKind; 6] = [
        PatternKind::Fixed,
        PatternKind::Random,
        PatternKind::Grid,
        PatternKind::Stratified,
        PatternKind::Lhs,
        PatternKind::Sobol,
    ];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            PatternKind::Fixed => "fixed",
            PatternKind::Random => "random",
            PatternKind::Grid => "grid",
            PatternKind::Stratified => "stratified",
            PatternKind::Lhs => "lhs",
            PatternKind::Sobol => "sobol",
        }
    }
}

impl fmt::Display for PatternKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for PatternKind {
    type Err = SamplingError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| SamplingError::UnknownPattern {
                name: s.to_string(),
            })
    }
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
    /// The same samples for one pixel, with that pixel's keys hashed once (hot path).
    fn pixel(&self, pixel: UVec2) -> PixelSamples;
    /// [`SamplePattern::pixel`] written over `out` in place: no ~3.6 KB value is built and
    /// moved, and `out`'s per-count caches (which depend on the count only) stay warm.
    fn pixel_into(&self, pixel: UVec2, out: &mut PixelSamples) {
        *out = self.pixel(pixel);
    }
}

/// Make the pattern of `kind` with a global seed.
pub fn make_pattern(kind: PatternKind, seed: u64) -> Box<dyn SamplePattern> {
    Box::new(Pattern::new(seed, kind))
}

/// Near-square factorisation nx × ny = count with nx the largest divisor ≤ √count (nx ≤ ny).
pub fn grid_dims(count: u32) -> (u32, u32) {
    let count = count.max(1);
    let mut nx = (count as f64).sqrt() as u32;
    while nx * nx > count {
        nx -= 1;
    }
    while !count.is_multiple_of(nx) {
        nx -= 1;
    }
    (nx, count / nx)
}

/// Domain-separation tags so that 1D and 2D requests, and x and y axes, never share a hash.
const TAG_1D: u64 = 0x1d1d;
const TAG_2D: u64 = 0x2d2d;
const TAG_LHS_Y: u64 = 0x7979_7979;
const TAG_JITTER: u64 = 0x6a69_7474;

/// Dimensions whose keys [`PixelSamples`] precomputes (the direct-lighting integrator uses 5).
pub const CACHED_DIMS: usize = 8;

/// The one implementation behind every [`PatternKind`].
#[derive(Clone, Copy, Debug)]
pub struct Pattern {
    /// Global seed.
    pub seed: u64,
    /// Which pattern.
    pub kind: PatternKind,
    /// The instruction set of the `stratified` chunk fills, detected once in [`Pattern::new`]:
    /// the default x86-64 target has SSE2 only (4 u32 lanes, no 64-bit vector multiply), so
    /// they are also compiled for AVX2 and AVX-512 (16 u32 lanes = one vector), with the same
    /// values (integer ops, exact conversions, IEEE division, a compare-select).
    cpu: Cpu,
}

impl Pattern {
    /// The pattern `kind` with global seed `seed`, its chunk fills on this CPU's widest vectors.
    pub fn new(seed: u64, kind: PatternKind) -> Self {
        Self {
            seed,
            kind,
            cpu: Cpu::detect(),
        }
    }

    /// Hash state after (seed, pixel): the prefix shared by every dimension of the pixel.
    #[inline]
    fn pixel_hash(&self, pixel: UVec2) -> u64 {
        hash_keys(&[self.seed, pixel.x as u64, pixel.y as u64])
    }

    /// The keys of one (pixel, dim, 1D/2D) sample set, from the pixel's hash prefix.
    #[inline]
    fn set(&self, prefix: u64, dim: u32, tag: u64) -> SetKeys {
        self.set_of_dim(hash_step(prefix, dim as u64), tag)
    }

    /// [`Pattern::set`] from the hash state after (seed, pixel, dim), which the 1D and 2D sets
    /// of one dimension share.
    #[inline]
    fn set_of_dim(&self, dim_hash: u64, tag: u64) -> SetKeys {
        SetKeys::new(self.kind, hash_step(dim_hash, tag))
    }
}

impl SamplePattern for Pattern {
    fn sample_1d(&self, pixel: UVec2, dim: u32, index: u32, count: u32) -> f32 {
        self.set(self.pixel_hash(pixel), dim, TAG_1D).sample_1d(
            self.kind,
            index,
            &Strata::new(count),
        )
    }

    fn sample_2d(&self, pixel: UVec2, dim: u32, index: u32, count: u32) -> Vec2 {
        self.set(self.pixel_hash(pixel), dim, TAG_2D).sample_2d(
            self.kind,
            index,
            &Strata::new(count),
        )
    }

    fn kind(&self) -> PatternKind {
        self.kind
    }

    fn pixel(&self, pixel: UVec2) -> PixelSamples {
        let mut px = self.pixel_empty(pixel);
        self.pixel_into(pixel, &mut px);
        px
    }

    fn pixel_into(&self, pixel: UVec2, out: &mut PixelSamples) {
        let prefix = self.pixel_hash(pixel);
        out.reset(*self, pixel, prefix);
        #[cfg(target_arch = "x86_64")]
        if out.raw_mode {
            /// [`Pattern::raw_stratified_avx512`] as a kernel.
            struct Raw<'a>(&'a Pattern, u64, &'a mut [RawSets; 2]);
            impl Kernel for Raw<'_> {
                type Output = ();
                #[inline(always)]
                fn run<T: Token>(self, t: T) {
                    // Raw mode is entered only on AVX-512 (`Pattern::raw_mode`).
                    if let Some(a) = t.avx512() {
                        self.0.raw_stratified_avx512(a, self.1, self.2);
                    }
                }
            }
            self.cpu.dispatch(Raw(self, prefix, &mut out.raw));
        }
        // Otherwise each set's keys are derived at its first chunk fill (`PixelSamples`).
    }
}

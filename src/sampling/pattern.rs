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
//! - `fixed`: always the centre (0.5, 0.5) (0.5 in 1D).
//! - `random`: independent uniform points from a PCG stream keyed by (seed, pixel, dim, index).
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

use glam::{UVec2, Vec2};
use std::fmt;
use std::str::FromStr;

use super::ONE_MINUS_EPSILON;
use super::error::SamplingError;
use super::hash::{hash_keys, next_f32, pcg_from_keys};
use super::permutation::permute;

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
}

/// Make the pattern of `kind` with a global seed.
pub fn make_pattern(kind: PatternKind, seed: u64) -> Box<dyn SamplePattern> {
    Box::new(Pattern { kind, seed })
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

/// The one implementation behind every [`PatternKind`].
#[derive(Clone, Copy, Debug)]
pub struct Pattern {
    /// Which pattern.
    pub kind: PatternKind,
    /// Global seed.
    pub seed: u64,
}

impl Pattern {
    /// Hash key of one (pixel, dim, 1D/2D) sample set.
    #[inline]
    fn key(&self, pixel: UVec2, dim: u32, tag: u64) -> u64 {
        hash_keys(&[self.seed, pixel.x as u64, pixel.y as u64, dim as u64, tag])
    }

    /// Two independent uniform numbers for sample `index` of the set `key`.
    #[inline]
    fn uniforms(key: u64, index: u32, tag: u64) -> (f32, f32) {
        let mut rng = pcg_from_keys(&[key, index as u64, tag]);
        (next_f32(&mut rng), next_f32(&mut rng))
    }

    /// Owen-scrambled Sobol dimension `d` (0 or 1) of sample `index` in the sequence `key`.
    #[inline]
    fn sobol(key: u64, index: u32, d: u32) -> f32 {
        // sobol_burley holds 2^16 points per sequence; later indices use a fresh sequence.
        let seed = hash_keys(&[key, (index >> 16) as u64]) as u32;
        sobol_burley::sample(index & 0xffff, d, seed)
    }
}

/// (stratum + jitter) / n, kept inside [0, 1).
#[inline]
fn in_stratum(stratum: u32, jitter: f32, n: u32) -> f32 {
    ((stratum as f32 + jitter) / n as f32).min(ONE_MINUS_EPSILON)
}

impl SamplePattern for Pattern {
    fn sample_1d(&self, pixel: UVec2, dim: u32, index: u32, count: u32) -> f32 {
        let count = count.max(1);
        let key = self.key(pixel, dim, TAG_1D);
        match self.kind {
            PatternKind::Fixed => 0.5,
            PatternKind::Random => Self::uniforms(key, index, TAG_JITTER).0,
            PatternKind::Grid => in_stratum(permute(index, count, key), 0.5, count),
            PatternKind::Stratified | PatternKind::Lhs => {
                let j = Self::uniforms(key, index % count, TAG_JITTER).0;
                in_stratum(permute(index, count, key), j, count)
            }
            PatternKind::Sobol => Self::sobol(key, index, 0),
        }
    }

    fn sample_2d(&self, pixel: UVec2, dim: u32, index: u32, count: u32) -> Vec2 {
        let count = count.max(1);
        let key = self.key(pixel, dim, TAG_2D);
        match self.kind {
            PatternKind::Fixed => Vec2::splat(0.5),
            PatternKind::Random => {
                let (a, b) = Self::uniforms(key, index, TAG_JITTER);
                Vec2::new(a, b)
            }
            PatternKind::Grid | PatternKind::Stratified => {
                let (nx, ny) = grid_dims(count);
                let s = permute(index, count, key);
                let (jx, jy) = if self.kind == PatternKind::Grid {
                    (0.5, 0.5)
                } else {
                    Self::uniforms(key, index % count, TAG_JITTER)
                };
                Vec2::new(in_stratum(s % nx, jx, nx), in_stratum(s / nx, jy, ny))
            }
            PatternKind::Lhs => {
                let sx = permute(index, count, key);
                let sy = permute(index, count, hash_keys(&[key, TAG_LHS_Y]));
                let (jx, jy) = Self::uniforms(key, index % count, TAG_JITTER);
                Vec2::new(in_stratum(sx, jx, count), in_stratum(sy, jy, count))
            }
            PatternKind::Sobol => Vec2::new(Self::sobol(key, index, 0), Self::sobol(key, index, 1)),
        }
    }

    fn kind(&self) -> PatternKind {
        self.kind
    }
}

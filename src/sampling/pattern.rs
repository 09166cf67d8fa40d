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
//!
//! Hot path: [`SamplePattern::pixel`] hashes the keys of one pixel's first [`CACHED_DIMS`]
//! dimensions once ([`PixelSamples`]); per sample only the permutation rounds and one jitter
//! hash remain. The values are identical to those of `sample_1d` / `sample_2d`.

use glam::{UVec2, Vec2};
use std::fmt;
use std::str::FromStr;

use super::ONE_MINUS_EPSILON;
use super::error::SamplingError;
use super::hash::{hash_keys, hash_step, uniform_pair};
use super::permutation::{PermDomain, Permutation};
use std::cell::Cell;

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
}

/// Make the pattern of `kind` with a global seed.
pub fn make_pattern(kind: PatternKind, seed: u64) -> Box<dyn SamplePattern> {
    Box::new(Pattern { seed, kind })
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
}

impl Pattern {
    /// Hash state after (seed, pixel): the prefix shared by every dimension of the pixel.
    #[inline]
    fn pixel_hash(&self, pixel: UVec2) -> u64 {
        hash_keys(&[self.seed, pixel.x as u64, pixel.y as u64])
    }

    /// The keys of one (pixel, dim, 1D/2D) sample set, from the pixel's hash prefix.
    #[inline]
    fn set(&self, prefix: u64, dim: u32, tag: u64) -> SetKeys {
        SetKeys::new(self.kind, hash_step(hash_step(prefix, dim as u64), tag))
    }
}

/// Everything derived from the key of one (pixel, dim, 1D/2D) sample set.
#[derive(Clone, Copy, Debug, Default)]
struct SetKeys {
    /// Strata → index assignment (x axis for LHS).
    perm: Permutation,
    /// LHS y-axis permutation.
    perm_y: Permutation,
    /// Jitter / random stream key.
    jitter: u64,
    /// Set key, for Sobol sequences past the first 2^16 points.
    key: u64,
    /// Sobol seed of the first 2^16 points.
    sobol0: u32,
}

impl SetKeys {
    /// Derive only what `kind` needs.
    #[inline]
    fn new(kind: PatternKind, key: u64) -> Self {
        let mut s = SetKeys {
            key,
            ..Default::default()
        };
        match kind {
            PatternKind::Fixed => {}
            PatternKind::Random => s.jitter = hash_step(key, TAG_JITTER),
            PatternKind::Grid => s.perm = Permutation::new(key),
            PatternKind::Stratified => {
                s.perm = Permutation::new(key);
                s.jitter = hash_step(key, TAG_JITTER);
            }
            PatternKind::Lhs => {
                s.perm = Permutation::new(key);
                s.perm_y = Permutation::new(hash_keys(&[key, TAG_LHS_Y]));
                s.jitter = hash_step(key, TAG_JITTER);
            }
            PatternKind::Sobol => s.sobol0 = Self::sobol_seed(key, 0),
        }
        s
    }

    /// sobol_burley holds 2^16 points per sequence; later indices use a fresh sequence.
    #[inline]
    fn sobol_seed(key: u64, hi: u32) -> u32 {
        hash_keys(&[key, hi as u64]) as u32
    }

    /// Owen-scrambled Sobol dimension `d` (0 or 1) of sample `index`.
    #[inline]
    fn sobol(&self, index: u32, d: u32) -> f32 {
        let hi = index >> 16;
        let seed = if hi == 0 {
            self.sobol0
        } else {
            Self::sobol_seed(self.key, hi)
        };
        sobol_burley::sample(index & 0xffff, d, seed)
    }

    #[inline]
    fn sample_1d(&self, kind: PatternKind, index: u32, st: &Strata) -> f32 {
        let count = st.count;
        match kind {
            PatternKind::Fixed => 0.5,
            PatternKind::Random => uniform_pair(self.jitter, index).0,
            PatternKind::Grid => in_stratum(self.perm.apply_in(index, &st.dom), 0.5, count),
            PatternKind::Stratified | PatternKind::Lhs => {
                let j = uniform_pair(self.jitter, st.wrap(index)).0;
                in_stratum(self.perm.apply_in(index, &st.dom), j, count)
            }
            PatternKind::Sobol => self.sobol(index, 0),
        }
    }

    #[inline]
    fn sample_2d(&self, kind: PatternKind, index: u32, st: &Strata) -> Vec2 {
        let count = st.count;
        match kind {
            PatternKind::Fixed => Vec2::splat(0.5),
            PatternKind::Random => {
                let (a, b) = uniform_pair(self.jitter, index);
                Vec2::new(a, b)
            }
            PatternKind::Grid => {
                let (sx, sy) = st.cell(self.perm.apply_in(index, &st.dom));
                Vec2::new(in_stratum(sx, 0.5, st.nx), in_stratum(sy, 0.5, st.ny))
            }
            PatternKind::Stratified => {
                let (sx, sy) = st.cell(self.perm.apply_in(index, &st.dom));
                let (jx, jy) = uniform_pair(self.jitter, st.wrap(index));
                Vec2::new(in_stratum(sx, jx, st.nx), in_stratum(sy, jy, st.ny))
            }
            PatternKind::Lhs => {
                let sx = self.perm.apply_in(index, &st.dom);
                let sy = self.perm_y.apply_in(index, &st.dom);
                let (jx, jy) = uniform_pair(self.jitter, st.wrap(index));
                Vec2::new(in_stratum(sx, jx, count), in_stratum(sy, jy, count))
            }
            PatternKind::Sobol => Vec2::new(self.sobol(index, 0), self.sobol(index, 1)),
        }
    }
}

/// What a sample set of `count` points needs besides its keys (grid shape, permutation
/// width), computed once per count instead of for every sample.
#[derive(Clone, Copy, Debug, Default)]
struct Strata {
    count: u32,
    nx: u32,
    ny: u32,
    /// log2(nx) when nx is a power of two (the common square counts), else `u32::MAX`.
    nx_log2: u32,
    dom: PermDomain,
}

impl Strata {
    #[inline]
    fn new(count: u32) -> Self {
        let count = count.max(1);
        let (nx, ny) = grid_dims(count);
        Self {
            count,
            nx,
            ny,
            nx_log2: if nx.is_power_of_two() {
                nx.trailing_zeros()
            } else {
                u32::MAX
            },
            dom: PermDomain::new(count),
        }
    }

    /// `index` wrapped into [0, count).
    #[inline]
    fn wrap(&self, index: u32) -> u32 {
        if index < self.count {
            index
        } else {
            index % self.count
        }
    }

    /// Grid cell (column, row) of stratum `s`.
    #[inline]
    fn cell(&self, s: u32) -> (u32, u32) {
        if self.nx_log2 != u32::MAX {
            (s & (self.nx - 1), s >> self.nx_log2)
        } else {
            (s % self.nx, s / self.nx)
        }
    }
}

/// (stratum + jitter) / n, kept inside [0, 1).
#[inline]
fn in_stratum(stratum: u32, jitter: f32, n: u32) -> f32 {
    ((stratum as f32 + jitter) / n as f32).min(ONE_MINUS_EPSILON)
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
        let prefix = self.pixel_hash(pixel);
        PixelSamples {
            pattern: *self,
            pixel,
            sets_1d: std::array::from_fn(|d| self.set(prefix, d as u32, TAG_1D)),
            sets_2d: std::array::from_fn(|d| self.set(prefix, d as u32, TAG_2D)),
            strata: Cell::default(),
        }
    }
}

/// One pixel's sample sets with the keys of the first [`CACHED_DIMS`] dimensions precomputed;
/// returns exactly what the pattern's `sample_1d` / `sample_2d` return for this pixel.
#[derive(Clone, Debug)]
pub struct PixelSamples {
    pattern: Pattern,
    pixel: UVec2,
    sets_1d: [SetKeys; CACHED_DIMS],
    sets_2d: [SetKeys; CACHED_DIMS],
    /// The two most recently used sample counts' [`Strata`] (an integrator asks for two: N for
    /// the pixel filter, N·M for the shading dimensions).
    strata: Cell<[Strata; 2]>,
}

impl PixelSamples {
    /// The pixel these samples belong to.
    #[inline]
    pub fn pixel(&self) -> UVec2 {
        self.pixel
    }

    /// The [`Strata`] of `count`, from the two-entry cache.
    #[inline]
    fn strata(&self, count: u32) -> Strata {
        let count = count.max(1);
        let mut c = self.strata.get();
        if c[0].count == count {
            return c[0];
        }
        if c[1].count != count {
            c[1] = Strata::new(count);
        }
        c.swap(0, 1);
        self.strata.set(c);
        c[0]
    }

    /// The 1D sample `index` of `count` for `dim`.
    #[inline]
    pub fn sample_1d(&self, dim: u32, index: u32, count: u32) -> f32 {
        match self.sets_1d.get(dim as usize) {
            Some(s) => s.sample_1d(self.pattern.kind, index, &self.strata(count)),
            None => self.pattern.sample_1d(self.pixel, dim, index, count),
        }
    }

    /// The 2D sample `index` of `count` for `dim`.
    #[inline]
    pub fn sample_2d(&self, dim: u32, index: u32, count: u32) -> Vec2 {
        match self.sets_2d.get(dim as usize) {
            Some(s) => s.sample_2d(self.pattern.kind, index, &self.strata(count)),
            None => self.pattern.sample_2d(self.pixel, dim, index, count),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_samples_equal_the_pattern_values() {
        // The cached per-pixel path must return bit-identical values, in cached dimensions
        // and past them, for stratified counts and wrapped indices.
        for kind in PatternKind::ALL {
            let pat = Pattern { seed: 7, kind };
            for pixel in [UVec2::new(0, 0), UVec2::new(13, 511)] {
                let px = pat.pixel(pixel);
                assert_eq!(px.pixel(), pixel);
                for dim in [0u32, 3, 7, 8, 40] {
                    for (index, count) in [(0u32, 1u32), (5, 16), (63, 64), (70, 64), (9, 37)] {
                        assert_eq!(
                            px.sample_1d(dim, index, count).to_bits(),
                            pat.sample_1d(pixel, dim, index, count).to_bits(),
                            "{kind} dim {dim} index {index}"
                        );
                        assert_eq!(
                            px.sample_2d(dim, index, count).to_array().map(f32::to_bits),
                            pat.sample_2d(pixel, dim, index, count)
                                .to_array()
                                .map(f32::to_bits),
                            "{kind} dim {dim} index {index}"
                        );
                    }
                }
            }
        }
    }
}

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
//! dimensions once ([`PixelSamples`]), which then evaluates each of those sample sets 16
//! consecutive indices at a time (integrators walk a pixel's indices in order), so most
//! samples cost one compare and a load. `stratified` batches run in an integer form
//! (vectorisable permutation rounds; stratum and jitter as one fixed-point number). The values
//! are bit-identical to those of `sample_1d` / `sample_2d` (tests/pat_golden.rs).

use glam::{UVec2, Vec2};
use std::fmt;
use std::str::FromStr;

use super::ONE_MINUS_EPSILON;
use super::error::SamplingError;
use super::hash::{HASH_INIT, hash_keys, hash_step, mix64, uniform_pair};
use super::permutation::{PermDomain, Permutation};
#[cfg(target_arch = "x86_64")]
use crate::isa::Avx512;
use crate::isa::{Cpu, Isa, Kernel, Token};
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

/// Everything derived from the key of one (pixel, dim, 1D/2D) sample set.
#[derive(Clone, Copy, Debug, Default)]
struct SetKeys {
    /// Strata → index assignment (x axis for LHS).
    perm: Permutation,
    /// LHS y-axis permutation.
    perm_y: Permutation,
    /// Jitter / random stream key.
    jitter: u64,
    /// `jitter` + [`HASH_INIT`]: [`uniform_pair`]`(jitter, i)` hashes `jitter_fast + i · HASH_INIT`.
    jitter_fast: u64,
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
                s.jitter_fast = s.jitter.wrapping_add(HASH_INIT);
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

    #[inline(always)]
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

    #[inline(always)]
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

/// The key material of one tag's (1D or 2D) sets of a pixel's [`CACHED_DIMS`] dimensions
/// in the `stratified` AVX-512 path: per dimension the permutation's mixed keys (`k`, `k2`
/// of [`Permutation::from_mixed`]) and the jitter key, as the vector hashes produce them.
#[derive(Clone, Copy, Debug, Default)]
struct RawSets {
    k: [u64; CACHED_DIMS],
    k2: [u64; CACHED_DIMS],
    jitter: [u64; CACHED_DIMS],
}

impl RawSets {
    /// The [`SetKeys`] of dimension `d` (< [`CACHED_DIMS`]): what `SetKeys::new` makes for a
    /// `stratified` set (its `key` is only read by `sobol`).
    #[inline]
    fn set(&self, d: usize) -> SetKeys {
        SetKeys {
            perm: Permutation::from_mixed(self.k[d], self.k2[d]),
            jitter: self.jitter[d],
            jitter_fast: self.jitter[d].wrapping_add(HASH_INIT),
            ..Default::default()
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
        let mut px = self.pixel_of_sets(pixel, Default::default(), Default::default());
        self.pixel_into(pixel, &mut px);
        px
    }

    fn pixel_into(&self, pixel: UVec2, out: &mut PixelSamples) {
        out.reset(*self, pixel);
        #[cfg(target_arch = "x86_64")]
        if out.raw_mode {
            /// [`Pattern::raw_stratified_avx512`] as a kernel.
            struct Raw<'a>(&'a Pattern, UVec2, &'a mut [RawSets; 2]);
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
            self.cpu.dispatch(Raw(self, pixel, &mut out.raw));
            return;
        }
        let prefix = self.pixel_hash(pixel);
        for d in 0..CACHED_DIMS {
            let dim = hash_step(prefix, d as u64);
            out.sets_1d[d] = self.set_of_dim(dim, TAG_1D);
            out.sets_2d[d] = self.set_of_dim(dim, TAG_2D);
        }
    }
}

impl Pattern {
    /// The raw set keys of [`SamplePattern::pixel`] of a `stratified` pattern on AVX-512
    /// ([`RawSets`]): the keys of the 8 cached dimensions are 8 u64 lanes, so every hash of a
    /// pixel's set keys is one vector op, and they are stored as they come (6 vector stores;
    /// the round keys of a dimension are derived when its chunk is filled, for the few
    /// dimensions an integrator uses).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn raw_stratified_avx512(&self, t: Avx512, pixel: UVec2, raw: &mut [RawSets; 2]) {
        use super::hash::{hash_step_avx512, mix64_avx512};
        use std::arch::x86_64::*;
        const _: () = assert!(CACHED_DIMS == 8, "one 8-lane vector of dimensions");
        // SAFETY: `t` proves the CPU runs AVX-512.
        let (prefix, lanes) = unsafe {
            (
                _mm512_set1_epi64(self.pixel_hash(pixel) as i64),
                _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7),
            )
        };
        let dims = hash_step_avx512(t, prefix, lanes);
        for (tag, out) in [TAG_1D, TAG_2D].into_iter().zip(raw.iter_mut()) {
            // The `stratified` arm of `SetKeys::new` for the 8 keys of one tag.
            // SAFETY: as above.
            let (tag, tag_jitter) = unsafe {
                (
                    _mm512_set1_epi64(tag as i64),
                    _mm512_set1_epi64(TAG_JITTER as i64),
                )
            };
            let key = hash_step_avx512(t, dims, tag);
            let k = mix64_avx512(t, key);
            let k2 = mix64_avx512(t, k);
            let jitter = hash_step_avx512(t, key, tag_jitter);
            // SAFETY: AVX-512 as above; each field is 8 u64 = 64 bytes, the width of the
            // unaligned store.
            unsafe {
                _mm512_storeu_si512(out.k.as_mut_ptr() as *mut __m512i, k);
                _mm512_storeu_si512(out.k2.as_mut_ptr() as *mut __m512i, k2);
                _mm512_storeu_si512(out.jitter.as_mut_ptr() as *mut __m512i, jitter);
            }
        }
    }

    /// Whether [`PixelSamples`] of this pattern hold raw keys (see `PixelSamples::raw_mode`).
    fn raw_mode(&self) -> bool {
        cfg!(target_arch = "x86_64")
            && self.kind == PatternKind::Stratified
            && self.cpu.isa() == Isa::Avx512
    }

    /// The [`PixelSamples`] of `pixel` with these sets' keys and empty caches.
    #[inline(always)]
    fn pixel_of_sets(
        &self,
        pixel: UVec2,
        sets_1d: [SetKeys; CACHED_DIMS],
        sets_2d: [SetKeys; CACHED_DIMS],
    ) -> PixelSamples {
        PixelSamples {
            pattern: *self,
            pixel,
            sets_1d,
            sets_2d,
            raw_mode: self.raw_mode(),
            raw: Default::default(),
            learned: Default::default(),
            strata: Cell::default(),
            fast: [Cell::new(FastStrata::NONE), Cell::new(FastStrata::NONE)],
            chunks_1d: Default::default(),
            chunks_2d: Default::default(),
        }
    }
}

/// The shape of a `stratified` sample set of `count` points in the integer form of the
/// [`PixelSamples`] fast path; only usable (`valid`) for counts of at most 2^24 strata (where
/// the fixed-point arithmetic and the f32 cell split below are exact).
#[derive(Clone, Copy, Debug)]
struct FastStrata {
    /// The `count` argument this was made for; `u64::MAX` (no u32 count) marks an empty slot.
    key: u64,
    /// Whether `count` has a fast form (else the general path serves it).
    valid: bool,
    /// Permutation domain [0, count).
    dom: PermDomain,
    /// Grid width nx.
    nx: u32,
    /// nx − 1 (used when nx is a power of two).
    nx_mask: u32,
    /// log2(nx) when nx is a power of two, else `u32::MAX` (the cell split then divides).
    nx_log2: u32,
    /// count · 2^24, nx · 2^24, ny · 2^24 (exact in f32): the divisors of a stratum index
    /// with its 24-bit jitter appended as fraction bits.
    div_1d: f32,
    div_x: f32,
    div_y: f32,
    /// Every 1D stratum index is < 2^7, so stratum · 2^24 + jitter fits an i32.
    small_1d: bool,
    /// The same for both 2D axes.
    small_2d: bool,
}

impl FastStrata {
    /// An empty cache slot.
    const NONE: Self = Self {
        key: u64::MAX,
        valid: false,
        dom: PermDomain::ONE,
        nx: 1,
        nx_mask: 0,
        nx_log2: 0,
        div_1d: FIX_ONE,
        div_x: FIX_ONE,
        div_y: FIX_ONE,
        small_1d: false,
        small_2d: false,
    };

    /// The fast form of `count` (`valid` if it has one).
    fn new(count: u32) -> Self {
        let st = Strata::new(count);
        if st.count > 1 << 24 {
            return Self {
                key: count as u64,
                ..Self::NONE
            };
        }
        Self {
            key: count as u64,
            valid: true,
            dom: st.dom,
            nx: st.nx,
            nx_mask: st.nx - 1,
            nx_log2: st.nx_log2,
            div_1d: st.count as f32 * FIX_ONE,
            div_x: st.nx as f32 * FIX_ONE,
            div_y: st.ny as f32 * FIX_ONE,
            // Bounds of every computed index, including the unspecified ones past `count`
            // (below 2^bits for a power-of-two domain, below n otherwise).
            small_1d: st.dom.mask() < 1 << 7,
            small_2d: st.nx - 1 < 1 << 7
                && if st.dom.is_pow2() {
                    st.dom.mask() >> st.nx_log2 < 1 << 7
                } else {
                    (st.count - 1) / st.nx < 1 << 7
                },
        }
    }

    /// The full 64-bit jitter hashes of indices `base..base + CHUNK` of `set` (x: bits 8..32,
    /// y: bits 40..64), in a plain loop over u64 lanes that vectorises whole.
    #[inline(always)]
    fn jitter_hashes(set: &SetKeys, base: u32) -> [u64; CHUNK] {
        let mut h = [0u64; CHUNK];
        for (k, o) in h.iter_mut().enumerate() {
            let i = base.wrapping_add(k as u32) as u64;
            *o = mix64(set.jitter_fast.wrapping_add(i.wrapping_mul(HASH_INIT)));
        }
        h
    }

    /// Stratified 1D samples `base..base + CHUNK` of `set` (those < count are the same f32s as
    /// [`SetKeys::sample_1d`]; the rest are unspecified).
    #[inline(always)]
    fn chunk_1d(&self, set: &SetKeys, base: u32) -> [f32; CHUNK] {
        let strata: [u32; CHUNK] = set.perm.apply_many(base, &self.dom);
        let h = Self::jitter_hashes(set, base);
        let mut jx = [0u32; CHUNK];
        for (j, h) in jx.iter_mut().zip(&h) {
            *j = *h as u32 >> 8;
        }
        fixed_chunk(&strata, &jx, self.div_1d, self.small_1d)
    }

    /// Stratified 2D samples `base..base + CHUNK` of `set` (see [`FastStrata::chunk_1d`]).
    #[inline(always)]
    fn chunk_2d(&self, set: &SetKeys, base: u32) -> [Vec2; CHUNK] {
        let strata: [u32; CHUNK] = set.perm.apply_many(base, &self.dom);
        let h = Self::jitter_hashes(set, base);
        // Plain loops, not `array::map` / `from_fn`: those were left as out-of-line calls,
        // which the target_feature copies below cannot widen.
        let (mut sx, mut sy) = ([0u32; CHUNK], [0u32; CHUNK]);
        let (mut jx, mut jy) = ([0u32; CHUNK], [0u32; CHUNK]);
        if self.nx_log2 != u32::MAX {
            for k in 0..CHUNK {
                sx[k] = strata[k] & self.nx_mask;
                sy[k] = strata[k] >> self.nx_log2;
            }
        } else {
            for k in 0..CHUNK {
                (sx[k], sy[k]) = split_f32(strata[k], self.nx);
            }
        }
        for k in 0..CHUNK {
            jx[k] = h[k] as u32 >> 8;
            jy[k] = (h[k] >> 40) as u32;
        }
        let x = fixed_chunk(&sx, &jx, self.div_x, self.small_2d);
        let y = fixed_chunk(&sy, &jy, self.div_y, self.small_2d);
        let mut v = [Vec2::ZERO; CHUNK];
        for k in 0..CHUNK {
            v[k] = Vec2::new(x[k], y[k]);
        }
        v
    }

    /// [`FastStrata::chunk_1d`] on `cpu`.
    #[inline(always)]
    fn chunk_1d_on(&self, cpu: Cpu, set: &SetKeys, base: u32) -> [f32; CHUNK] {
        /// The chunk fill as a kernel: the AVX-512 form on AVX-512, else the portable loops
        /// compiled for the set.
        struct Fill<'a>(&'a FastStrata, &'a SetKeys, u32);
        impl Kernel for Fill<'_> {
            type Output = [f32; CHUNK];
            #[inline(always)]
            fn run<T: Token>(self, t: T) -> [f32; CHUNK] {
                #[cfg(target_arch = "x86_64")]
                if let Some(a) = t.avx512() {
                    return self.0.chunk_1d_avx512(a, self.1, self.2);
                }
                let _ = t;
                self.0.chunk_1d(self.1, self.2)
            }
        }
        cpu.dispatch(Fill(self, set, base))
    }

    /// [`FastStrata::chunk_2d`] on `cpu`.
    #[inline(always)]
    fn chunk_2d_on(&self, cpu: Cpu, set: &SetKeys, base: u32) -> [Vec2; CHUNK] {
        /// As in [`FastStrata::chunk_1d_on`].
        struct Fill<'a>(&'a FastStrata, &'a SetKeys, u32);
        impl Kernel for Fill<'_> {
            type Output = [Vec2; CHUNK];
            #[inline(always)]
            fn run<T: Token>(self, t: T) -> [Vec2; CHUNK] {
                #[cfg(target_arch = "x86_64")]
                if let Some(a) = t.avx512() {
                    return self.0.chunk_2d_avx512(a, self.1, self.2);
                }
                let _ = t;
                self.0.chunk_2d(self.1, self.2)
            }
        }
        cpu.dispatch(Fill(self, set, base))
    }

    /// [`FastStrata::chunk_1d`] on AVX-512, written with intrinsics, one 16-lane vector per
    /// step (compiled from the portable loops, LLVM split the 16 lanes 8 + 4 + 2 + 1 + 1); any
    /// count, since the permutation cycle-walks on lane masks.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn chunk_1d_avx512(&self, t: Avx512, set: &SetKeys, base: u32) -> [f32; CHUNK] {
        use std::arch::x86_64::*;
        let v = self.chunk_1d_vec_avx512(t, &set.perm, set.jitter_fast, base);
        let mut out = [0.0f32; CHUNK];
        // SAFETY: `t` proves AVX-512; `out` is 16 f32 = 64 bytes, the width of the store.
        unsafe { _mm512_storeu_ps(out.as_mut_ptr(), v) };
        out
    }

    /// The values of [`FastStrata::chunk_1d_avx512`] in one vector, from the set's
    /// permutation and `jitter_fast` key.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn chunk_1d_vec_avx512(
        &self,
        t: Avx512,
        perm: &Permutation,
        jitter_fast: u64,
        base: u32,
    ) -> std::arch::x86_64::__m512 {
        let strata = perm.apply_16_avx512(t, base, &self.dom);
        let (jx, _) = jitters_avx512(t, jitter_fast, base);
        if self.small_1d {
            fixed_small_avx512(t, strata, jx, self.div_1d)
        } else {
            fixed_wide_avx512(t, strata, jx, self.div_1d)
        }
    }

    /// [`FastStrata::chunk_2d`] on AVX-512 (see [`FastStrata::chunk_1d_avx512`]).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn chunk_2d_avx512(&self, t: Avx512, set: &SetKeys, base: u32) -> [Vec2; CHUNK] {
        if !self.small_2d {
            return self.chunk_2d(set, base);
        }
        let mut out = [Vec2::ZERO; CHUNK];
        let (x, y) = self.chunk_2d_vec_avx512(t, &set.perm, set.jitter_fast, base);
        // SAFETY: `out` is 16 `Vec2`.
        unsafe { store_2d_avx512(t, out.as_mut_ptr(), x, y) };
        out
    }

    /// The x and y values of [`FastStrata::chunk_2d_avx512`] as two vectors (`small_2d` only),
    /// from the set's permutation and `jitter_fast` key.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn chunk_2d_vec_avx512(
        &self,
        t: Avx512,
        perm: &Permutation,
        jitter_fast: u64,
        base: u32,
    ) -> (std::arch::x86_64::__m512, std::arch::x86_64::__m512) {
        use std::arch::x86_64::*;
        let strata = perm.apply_16_avx512(t, base, &self.dom);
        let (jx, jy) = jitters_avx512(t, jitter_fast, base);
        // SAFETY: `t` proves the CPU runs AVX-512.
        let (sx, sy) = unsafe {
            if self.nx_log2 != u32::MAX {
                (
                    _mm512_and_si512(strata, _mm512_set1_epi32(self.nx_mask as i32)),
                    _mm512_srl_epi32(strata, _mm_cvtsi32_si128(self.nx_log2 as i32)),
                )
            } else {
                // `split_f32` on 16 lanes (exact conversions, IEEE division, truncation).
                let nx = _mm512_set1_epi32(self.nx as i32);
                let q = _mm512_cvttps_epu32(_mm512_div_ps(
                    _mm512_cvtepi32_ps(strata),
                    _mm512_cvtepi32_ps(nx),
                ));
                (_mm512_sub_epi32(strata, _mm512_mullo_epi32(q, nx)), q)
            }
        };
        (
            fixed_small_avx512(t, sx, jx, self.div_x),
            fixed_small_avx512(t, sy, jy, self.div_y),
        )
    }
}

/// The 16 values (x, y) of a 2D chunk written to `out` as 16 `Vec2`, interleaved
/// (x0, y0, x1, y1, ...).
///
/// # Safety
/// `out` must be valid for writing 16 `Vec2` (no alignment needed).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn store_2d_avx512(
    _: Avx512,
    out: *mut Vec2,
    x: std::arch::x86_64::__m512,
    y: std::arch::x86_64::__m512,
) {
    use std::arch::x86_64::*;
    let p = out as *mut f32;
    // SAFETY: the token proves AVX-512; `Vec2` is `repr(C)` (x, y), so 16 of them are 32
    // contiguous f32 = two 64-byte unaligned stores, valid by the caller's contract.
    unsafe {
        // Lanes ≥ 16 of the index pick from `y`.
        let lo = _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23);
        let hi = _mm512_setr_epi32(8, 24, 9, 25, 10, 26, 11, 27, 12, 28, 13, 29, 14, 30, 15, 31);
        _mm512_storeu_ps(p, _mm512_permutex2var_ps(x, lo, y));
        _mm512_storeu_ps(p.add(16), _mm512_permutex2var_ps(x, hi, y));
    }
}

/// The 24-bit jitters (x, y) of indices `base..base + 16` of a set with key `jitter_fast` on
/// AVX-512: the same hashes as [`FastStrata::jitter_hashes`], 8 u64 lanes at a time.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn jitters_avx512(
    t: Avx512,
    jitter_fast: u64,
    base: u32,
) -> (std::arch::x86_64::__m512i, std::arch::x86_64::__m512i) {
    use super::hash::mix64_avx512;
    use std::arch::x86_64::*;
    debug_assert!(base.is_multiple_of(CHUNK as u32));
    // `base` is a multiple of 16, so `base + k` (k < 16) never wraps a u32 and the hashed
    // `jitter_fast + (base + k) · H` is `(jitter_fast + base · H) + k · H` (mod 2^64): one
    // scalar start and constant steps instead of a conversion and a 64-bit multiply per lane.
    let start = jitter_fast.wrapping_add((base as u64).wrapping_mul(HASH_INIT));
    let step = |k: u64| k.wrapping_mul(HASH_INIT) as i64;
    // SAFETY: `t` proves the CPU runs AVX-512.
    let (start, lo, hi) = unsafe {
        let start = _mm512_set1_epi64(start as i64);
        let lo = _mm512_setr_epi64(
            step(0),
            step(1),
            step(2),
            step(3),
            step(4),
            step(5),
            step(6),
            step(7),
        );
        let hi = _mm512_setr_epi64(
            step(8),
            step(9),
            step(10),
            step(11),
            step(12),
            step(13),
            step(14),
            step(15),
        );
        (start, lo, hi)
    };
    // SAFETY: as above.
    let (l, h) = unsafe { (_mm512_add_epi64(start, lo), _mm512_add_epi64(start, hi)) };
    let h0 = mix64_avx512(t, l);
    let h1 = mix64_avx512(t, h);
    // SAFETY: as above.
    unsafe {
        // The low (`h as u32`) and high (`(h >> 32) as u32`) halves of the 16 hashes: the even
        // and odd u32 words of (h0, h1); `(h >> 40) as u32` is the high half shifted by 8.
        let even = _mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 26, 28, 30);
        let odd = _mm512_setr_epi32(1, 3, 5, 7, 9, 11, 13, 15, 17, 19, 21, 23, 25, 27, 29, 31);
        let jx = _mm512_srli_epi32::<8>(_mm512_permutex2var_epi32(h0, even, h1));
        let jy = _mm512_srli_epi32::<8>(_mm512_permutex2var_epi32(h0, odd, h1));
        (jx, jy)
    }
}

/// The `small` form of [`fixed_chunk`] on 16 lanes: (stratum << 24 | j) as i32 → f32 (round
/// to nearest, as `as f32`), IEEE division, then `v < 1⁻ ? v : 1⁻`, which is exactly
/// `vminps(v, 1⁻)` (it returns the second operand unless v < 1⁻).
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn fixed_small_avx512(
    _: Avx512,
    strata: std::arch::x86_64::__m512i,
    j: std::arch::x86_64::__m512i,
    div: f32,
) -> std::arch::x86_64::__m512 {
    use std::arch::x86_64::*;
    // SAFETY: the token proves the CPU runs AVX-512.
    unsafe {
        let fixed = _mm512_or_si512(_mm512_slli_epi32::<24>(strata), j);
        let v = _mm512_div_ps(_mm512_cvtepi32_ps(fixed), _mm512_set1_ps(div));
        _mm512_min_ps(v, _mm512_set1_ps(ONE_MINUS_EPSILON))
    }
}

/// (s mod nx, s / nx) for s, nx < 2^24 through an f32 division, which vectorises (a u32
/// division does not). Exact: s and nx convert exactly; if nx divides s the quotient q is
/// exact, else s/nx = q + r/nx lies at least 1/nx below q + 1 while half an ulp of it is at
/// most 2^-24 · s/nx < 1/nx, so the rounded quotient stays in [q, q + 1) and truncates to q.
#[inline(always)]
fn split_f32(s: u32, nx: u32) -> (u32, u32) {
    let q = (s as f32 / nx as f32) as u32;
    (s - q * nx, q)
}

/// The general form of [`fixed_chunk`] on 16 lanes, for strata ≥ 2^7: (stratum << 24 | j) in
/// 8 i64 lanes → f32 (round to nearest, as the scalar `as i64 as f32`), IEEE division, then
/// the same `vminps` as [`fixed_small_avx512`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn fixed_wide_avx512(
    _: Avx512,
    strata: std::arch::x86_64::__m512i,
    j: std::arch::x86_64::__m512i,
    div: f32,
) -> std::arch::x86_64::__m512 {
    use std::arch::x86_64::*;
    // SAFETY: the token proves the CPU runs AVX-512 (F and DQ).
    unsafe {
        // Eight lanes (a 256-bit half) at a time, unrolled: a closure would be compiled
        // without the AVX-512 features.
        let (s0, j0) = (_mm512_castsi512_si256(strata), _mm512_castsi512_si256(j));
        let (s1, j1) = (
            _mm512_extracti64x4_epi64::<1>(strata),
            _mm512_extracti64x4_epi64::<1>(j),
        );
        let lo = _mm512_cvtepi64_ps(_mm512_or_si512(
            _mm512_slli_epi64::<24>(_mm512_cvtepu32_epi64(s0)),
            _mm512_cvtepu32_epi64(j0),
        ));
        let hi = _mm512_cvtepi64_ps(_mm512_or_si512(
            _mm512_slli_epi64::<24>(_mm512_cvtepu32_epi64(s1)),
            _mm512_cvtepu32_epi64(j1),
        ));
        let fixed = _mm512_insertf32x8::<1>(_mm512_castps256_ps512(lo), hi);
        let v = _mm512_div_ps(fixed, _mm512_set1_ps(div));
        _mm512_min_ps(v, _mm512_set1_ps(ONE_MINUS_EPSILON))
    }
}

/// [`in_stratum_fixed`] of a chunk; `small` (every stratum < 2^7) takes an i32 form that
/// vectorises (the same values: the integer is the same and exact either way).
#[inline(always)]
fn fixed_chunk(strata: &[u32; CHUNK], j: &[u32; CHUNK], div: f32, small: bool) -> [f32; CHUNK] {
    let mut out = [0.0f32; CHUNK];
    if small {
        for k in 0..CHUNK {
            let v = ((strata[k] << 24) | j[k]) as i32 as f32 / div;
            out[k] = if v < ONE_MINUS_EPSILON {
                v
            } else {
                ONE_MINUS_EPSILON
            };
        }
    } else {
        for k in 0..CHUNK {
            out[k] = in_stratum_fixed(strata[k], j[k], div);
        }
    }
    out
}

/// 2^24: one in the 24-bit fixed point of the jitter.
const FIX_ONE: f32 = (1u32 << 24) as f32;

/// (stratum + jitter) / n with the jitter's 24 bits `j` and `div = n · 2^24`: the same f32 as
/// [`in_stratum`]`(stratum, j · 2^-24, n)` for stratum < 2^24. Both round the exact value
/// stratum + j · 2^-24 once (scaled by 2^24, which commutes with rounding) and then divide
/// by the exact n, so the results agree bit for bit; this form saves the conversions.
#[inline(always)]
fn in_stratum_fixed(stratum: u32, j: u32, div: f32) -> f32 {
    let v = (((stratum as u64) << 24) | j as u64) as i64 as f32 / div;
    // `v` is never NaN, so this is `v.min(ONE_MINUS_EPSILON)` in a single `minss`.
    if v < ONE_MINUS_EPSILON {
        v
    } else {
        ONE_MINUS_EPSILON
    }
}

/// Indices per [`Chunk`]: a sample set's values are computed this many at a time.
const CHUNK: usize = 16;

/// Precomputed values of consecutive indices [base, base + len) of one sample set for one
/// count: integrators walk a pixel's indices in order, so a batch evaluated in one tight loop
/// (keys in registers, no per-call lookups) serves the next `len` requests with one compare.
#[derive(Clone, Debug)]
struct Chunk<T: Copy> {
    /// The count the values belong to.
    count: Cell<u32>,
    /// First index.
    base: Cell<u32>,
    /// Number of valid values (0 = empty).
    len: Cell<u32>,
    /// The values of indices base..base + len.
    v: [Cell<T>; CHUNK],
}

impl<T: Copy + Default> Default for Chunk<T> {
    fn default() -> Self {
        Self {
            count: Cell::new(0),
            base: Cell::new(0),
            len: Cell::new(0),
            v: Default::default(),
        }
    }
}

impl<T: Copy> Chunk<T> {
    /// The value of `index` of `count`, if this chunk holds it (hot path).
    #[inline(always)]
    fn get(&self, index: u32, count: u32) -> Option<T> {
        let off = index.wrapping_sub(self.base.get());
        if self.count.get() == count && off < self.len.get() {
            return Some(self.v[off as usize % CHUNK].get());
        }
        None
    }

    /// Store the values `v` of the chunk of `index` (< count) and return `index`'s value.
    #[inline(always)]
    fn store(&self, index: u32, count: u32, v: &[T; CHUNK]) -> T {
        let base = index & !(CHUNK as u32 - 1);
        let len = (count - base).min(CHUNK as u32);
        for (c, &x) in self.v.iter().zip(v) {
            c.set(x);
        }
        self.count.set(count);
        self.base.set(base);
        self.len.set(len);
        v[(index - base) as usize % CHUNK]
    }

    /// Whether this chunk holds the values of the chunk at `base` of `count`.
    #[inline(always)]
    fn holds(&self, base: u32, count: u32) -> bool {
        self.count.get() == count && self.base.get() == base && self.len.get() != 0
    }

    /// Where the values go: `v` as plain `T`s, for vector stores.
    #[inline(always)]
    fn values_ptr(&self) -> *mut T {
        // `Cell<T>` has the layout of `T`, and a `Cell` may be written through a shared
        // reference: this pointer may be written while no reference to a value is live.
        self.v.as_ptr().cast::<T>().cast_mut()
    }

    /// Mark the values (written through [`Chunk::values_ptr`]) as those of the chunk at
    /// `base` (a multiple of [`CHUNK`], < count) of `count`.
    #[inline(always)]
    fn mark(&self, base: u32, count: u32) {
        self.count.set(count);
        self.base.set(base);
        self.len.set((count - base).min(CHUNK as u32));
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
    /// The `stratified` AVX-512 form: `raw` holds the keys instead of `sets_1d` / `sets_2d`
    /// (which are then unused), and a miss fills a whole group of chunks (see `learned`).
    raw_mode: bool,
    /// Raw keys of the 1D and 2D sets (raw mode).
    raw: [RawSets; 2],
    /// Per 1D / 2D cached dimension: the count of its last chunk fill (0: never), kept from
    /// pixel to pixel. In raw mode a miss at (base, count) (count a multiple of 16) fills the
    /// chunks at (base, count) of every dimension whose last count was `count`: an integrator draws the same
    /// dimensions for each sample index, so the chunks of one 16-index block are computed
    /// together, their independent hash chains overlapping, with one call and one setup.
    learned: [[Cell<u32>; CACHED_DIMS]; 2],
    /// The two most recently used sample counts' [`Strata`] (an integrator asks for two: N for
    /// the pixel filter, N·M for the shading dimensions).
    strata: Cell<[Strata; 2]>,
    /// The same in the `stratified` fast form: two slots, most recent first.
    fast: [Cell<FastStrata>; 2],
    /// Batches of precomputed `stratified` values per cached 1D / 2D dimension.
    chunks_1d: [Chunk<f32>; CACHED_DIMS],
    chunks_2d: [Chunk<Vec2>; CACHED_DIMS],
}

impl PixelSamples {
    /// Make these the samples of `pixel` under `pattern` except for the set keys (which the
    /// caller writes next): every chunk emptied, the per-count caches kept (they depend on
    /// the count only).
    #[inline]
    fn reset(&mut self, pattern: Pattern, pixel: UVec2) {
        self.pattern = pattern;
        self.pixel = pixel;
        self.raw_mode = pattern.raw_mode();
        for c in &self.chunks_1d {
            c.len.set(0);
        }
        for c in &self.chunks_2d {
            c.len.set(0);
        }
    }

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

    /// The [`FastStrata`] of `count`, from the two-slot cache (most recent first).
    #[inline]
    fn fast(&self, count: u32) -> FastStrata {
        let a = self.fast[0].get();
        if a.key == count as u64 {
            return a;
        }
        let b = self.fast[1].get();
        if b.key == count as u64 {
            return b;
        }
        let f = FastStrata::new(count);
        self.fast[1].set(a);
        self.fast[0].set(f);
        f
    }

    /// The 1D sample `index` of `count` for `dim`.
    #[inline(always)]
    pub fn sample_1d(&self, dim: u32, index: u32, count: u32) -> f32 {
        if let Some(c) = self.chunks_1d.get(dim as usize)
            && let Some(v) = c.get(index, count)
        {
            return v;
        }
        self.sample_1d_miss(dim, index, count)
    }

    /// [`PixelSamples::sample_1d`] when no chunk holds the value (see [`PixelSamples::miss`]).
    #[inline(never)]
    fn sample_1d_miss(&self, dim: u32, index: u32, count: u32) -> f32 {
        #[cfg(target_arch = "x86_64")]
        if self.raw_mode
            && let Some(v) = self.miss_raw(0, dim, index, count)
        {
            // SAFETY: the 1D chunk of `dim` holds `index` now; it stores f32s.
            return unsafe {
                *self.chunks_1d[dim as usize]
                    .values_ptr()
                    .cast::<f32>()
                    .add(v)
            };
        }
        self.miss(
            self.set_keys(0, dim),
            &self.chunks_1d,
            Arity {
                dim,
                index,
                count,
                general: |p: &Pattern| p.sample_1d(self.pixel, dim, index, count),
                eval: |set: &SetKeys, kind, i, st: &Strata| set.sample_1d(kind, i, st),
                fast: |f: &FastStrata, set: &SetKeys, base| {
                    f.chunk_1d_on(self.pattern.cpu, set, base)
                },
            },
        )
    }

    /// The 2D sample `index` of `count` for `dim`.
    #[inline(always)]
    pub fn sample_2d(&self, dim: u32, index: u32, count: u32) -> Vec2 {
        if let Some(c) = self.chunks_2d.get(dim as usize)
            && let Some(v) = c.get(index, count)
        {
            return v;
        }
        self.sample_2d_miss(dim, index, count)
    }

    /// [`PixelSamples::sample_2d`] when no chunk holds the value (see [`PixelSamples::miss`]).
    #[inline(never)]
    fn sample_2d_miss(&self, dim: u32, index: u32, count: u32) -> Vec2 {
        #[cfg(target_arch = "x86_64")]
        if self.raw_mode
            && let Some(v) = self.miss_raw(1, dim, index, count)
        {
            // SAFETY: the 2D chunk of `dim` holds `index` now.
            return unsafe { *self.chunks_2d[dim as usize].values_ptr().add(v) };
        }
        self.miss(
            self.set_keys(1, dim),
            &self.chunks_2d,
            Arity {
                dim,
                index,
                count,
                general: |p: &Pattern| p.sample_2d(self.pixel, dim, index, count),
                eval: |set: &SetKeys, kind, i, st: &Strata| set.sample_2d(kind, i, st),
                fast: |f: &FastStrata, set: &SetKeys, base| {
                    f.chunk_2d_on(self.pattern.cpu, set, base)
                },
            },
        )
    }

    /// The keys of the 1D (`arity` 0) or 2D (1) set of `dim`, if it is a cached dimension.
    #[inline]
    fn set_keys(&self, arity: usize, dim: u32) -> Option<SetKeys> {
        let d = dim as usize;
        if d >= CACHED_DIMS {
            return None;
        }
        Some(if self.raw_mode {
            self.raw[arity].set(d)
        } else if arity == 0 {
            self.sets_1d[d]
        } else {
            self.sets_2d[d]
        })
    }

    /// A raw-mode miss of the 1D (`arity` 0) or 2D (1) value `index` of `count` of `dim`:
    /// if the AVX-512 fill serves it, fill its chunk and the group's (see `learned`) and
    /// return `index`'s offset in the chunk; else `None` (the general path serves it).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn miss_raw(&self, arity: usize, dim: u32, index: u32, count: u32) -> Option<usize> {
        let d = dim as usize;
        if d >= CACHED_DIMS || index >= count {
            return None;
        }
        let f = self.fast(count);
        if !f.valid || (arity == 1 && !f.small_2d) {
            return None;
        }
        let base = index & !(CHUNK as u32 - 1);
        self.learned[arity][d].set(count);
        let mut masks = [0u32; 2];
        masks[arity] = 1 << d;
        // Group fills only for counts that are whole blocks: the renderer's 16-lane packets
        // then stay in step with the blocks. Otherwise a packet spans two blocks and the pixel
        // filter's walk runs ahead of the shading dimensions: a group fill of its next block
        // would evict the block they still read, and every block would be filled 2–3 times.
        for k in (0..CACHED_DIMS).filter(|_| count.is_multiple_of(CHUNK as u32)) {
            if self.learned[0][k].get() == count && !self.chunks_1d[k].holds(base, count) {
                masks[0] |= 1 << k;
            }
            if f.small_2d
                && self.learned[1][k].get() == count
                && !self.chunks_2d[k].holds(base, count)
            {
                masks[1] |= 1 << k;
            }
        }
        /// [`PixelSamples::fill_avx512`] as a kernel.
        struct Fill<'a>(&'a PixelSamples, &'a FastStrata, u32, u32, [u32; 2]);
        impl Kernel for Fill<'_> {
            type Output = ();
            #[inline(always)]
            fn run<T: Token>(self, t: T) {
                // Raw mode is entered only on AVX-512 (`Pattern::raw_mode`).
                if let Some(a) = t.avx512() {
                    self.0.fill_avx512(a, self.1, self.2, self.3, self.4);
                }
            }
        }
        self.pattern
            .cpu
            .dispatch(Fill(self, &f, base, count, masks));
        Some((index - base) as usize)
    }

    /// Fill the 1D chunks of the dimensions in `masks[0]` and the 2D chunks of those in
    /// `masks[1]` (`small_2d` only) with their values at `base` of `count`, from the raw keys.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn fill_avx512(&self, t: Avx512, f: &FastStrata, base: u32, count: u32, masks: [u32; 2]) {
        use std::arch::x86_64::*;
        let [mut m1, mut m2] = masks;
        while m1 != 0 {
            let d = m1.trailing_zeros() as usize;
            m1 &= m1 - 1;
            let r = &self.raw[0];
            let perm = Permutation::from_mixed(r.k[d], r.k2[d]);
            let v = f.chunk_1d_vec_avx512(t, &perm, r.jitter[d].wrapping_add(HASH_INIT), base);
            let c = &self.chunks_1d[d];
            // SAFETY: `t` proves AVX-512; the chunk's values are 16 f32 = 64 bytes, the width
            // of the store.
            unsafe { _mm512_storeu_ps(c.values_ptr(), v) };
            c.mark(base, count);
        }
        while m2 != 0 {
            let d = m2.trailing_zeros() as usize;
            m2 &= m2 - 1;
            let r = &self.raw[1];
            let perm = Permutation::from_mixed(r.k[d], r.k2[d]);
            let (x, y) = f.chunk_2d_vec_avx512(t, &perm, r.jitter[d].wrapping_add(HASH_INIT), base);
            let c = &self.chunks_2d[d];
            // SAFETY: the chunk's values are 16 `Vec2`.
            unsafe { store_2d_avx512(t, c.values_ptr(), x, y) };
            c.mark(base, count);
        }
    }

    /// A value no chunk holds: refill the chunk of `index` (< count; the `stratified` fast form
    /// where it applies) or evaluate the general way (uncached dimension, wrapped index).
    /// Written once for 1D and 2D; inlined into each so that every loop is specialised.
    #[inline(always)]
    fn miss<T, G, E, F>(
        &self,
        set: Option<SetKeys>,
        chunks: &[Chunk<T>; CACHED_DIMS],
        a: Arity<G, E, F>,
    ) -> T
    where
        T: Copy + Default,
        G: Fn(&Pattern) -> T,
        E: Fn(&SetKeys, PatternKind, u32, &Strata) -> T,
        F: Fn(&FastStrata, &SetKeys, u32) -> [T; CHUNK],
    {
        let Arity {
            dim,
            index,
            count,
            general,
            eval,
            fast,
        } = a;
        let Some(set) = set else {
            return general(&self.pattern);
        };
        let set = &set;
        let kind = self.pattern.kind;
        if index >= count {
            return eval(set, kind, index, &self.strata(count));
        }
        let base = index & !(CHUNK as u32 - 1);
        let f = if kind == PatternKind::Stratified {
            self.fast(count)
        } else {
            FastStrata::NONE
        };
        let v = if f.valid {
            fast(&f, set, base)
        } else {
            // Every other pattern and count: the general evaluation, batched the same way.
            let st = self.strata(count);
            let len = (count - base).min(CHUNK as u32) as usize;
            let batch = |kind| {
                let mut v = [T::default(); CHUNK];
                for (k, o) in v.iter_mut().enumerate().take(len) {
                    *o = eval(set, kind, base + k as u32, &st);
                }
                v
            };
            // One loop per kind, so that each loop body is that kind's arithmetic only.
            match kind {
                PatternKind::Fixed => batch(PatternKind::Fixed),
                PatternKind::Random => batch(PatternKind::Random),
                PatternKind::Grid => batch(PatternKind::Grid),
                PatternKind::Stratified => batch(PatternKind::Stratified),
                PatternKind::Lhs => batch(PatternKind::Lhs),
                PatternKind::Sobol => batch(PatternKind::Sobol),
            }
        };
        chunks[dim as usize].store(index, count, &v)
    }
}

/// What [`PixelSamples::miss`] needs of one request and of its dimension count (1D or 2D):
/// the request, the uncached evaluation, the per-index evaluation and the fast chunk.
struct Arity<G, E, F> {
    dim: u32,
    index: u32,
    count: u32,
    general: G,
    eval: E,
    fast: F,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_samples_equal_the_pattern_values() {
        // The cached per-pixel path must return bit-identical values, in cached dimensions
        // and past them, for stratified counts and wrapped indices.
        for (kind, isa) in PatternKind::ALL
            .into_iter()
            .flat_map(|k| Isa::available().into_iter().map(move |i| (k, i)))
        {
            let pat = Pattern {
                seed: 7,
                kind,
                cpu: isa.cpu(),
            };
            for pixel in [UVec2::new(0, 0), UVec2::new(13, 511)] {
                let px = pat.pixel(pixel);
                assert_eq!(px.pixel(), pixel);
                for dim in [0u32, 3, 7, 8, 40] {
                    for (index, count) in [
                        (0u32, 1u32),
                        (5, 16),
                        (63, 64),
                        (70, 64),
                        (9, 37),
                        (40_000, 1 << 16),
                        (17, 1 << 18),
                    ] {
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

    #[test]
    fn pixel_into_reuses_samples_bit_identically() {
        // One PixelSamples refilled pixel after pixel (warm chunks and count caches of the
        // previous pixel) returns what a fresh one returns.
        for (kind, isa) in PatternKind::ALL
            .into_iter()
            .flat_map(|k| Isa::available().into_iter().map(move |i| (k, i)))
        {
            let pat = Pattern {
                seed: 5,
                kind,
                cpu: isa.cpu(),
            };
            let mut px = pat.pixel(UVec2::new(9, 9));
            for (n, pixel) in [UVec2::new(0, 0), UVec2::new(3, 1), UVec2::new(3, 2)]
                .into_iter()
                .enumerate()
            {
                pat.pixel_into(pixel, &mut px);
                let fresh = pat.pixel(pixel);
                assert_eq!(px.pixel(), pixel);
                // Starting with the previous pixel's last count: its chunks must not serve.
                for count in [16u32, 64, 5, 37][..4 - n].iter().copied().chain([16]) {
                    for index in 0..count {
                        for dim in [0u32, 4, 9] {
                            assert_eq!(
                                px.sample_1d(dim, index, count).to_bits(),
                                fresh.sample_1d(dim, index, count).to_bits(),
                                "{kind} {isa:?} 1d count {count} index {index}"
                            );
                            assert_eq!(
                                px.sample_2d(dim, index, count).to_array().map(f32::to_bits),
                                fresh
                                    .sample_2d(dim, index, count)
                                    .to_array()
                                    .map(f32::to_bits),
                                "{kind} {isa:?} 2d count {count} index {index}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn group_fills_serve_every_access_order() {
        // Raw-mode misses fill every dimension last seen with the same count: the values must
        // not depend on the order of the requests (renderer order with two counts, dimension
        // after dimension, and backwards; counts 32 and 96 are whole blocks, so the group
        // fills take part), on each instruction set.
        for isa in Isa::available() {
            let pat = Pattern {
                seed: 3,
                kind: PatternKind::Stratified,
                cpu: isa.cpu(),
            };
            let mut px = pat.pixel(UVec2::ZERO);
            for (p, pixel) in [UVec2::new(4, 5), UVec2::new(6, 5), UVec2::new(9, 1)]
                .into_iter()
                .enumerate()
            {
                pat.pixel_into(pixel, &mut px);
                let check_1d = |dim, i, n| {
                    assert_eq!(
                        px.sample_1d(dim, i, n).to_bits(),
                        pat.sample_1d(pixel, dim, i, n).to_bits(),
                        "{isa:?} pixel {pixel} 1d dim {dim} index {i} count {n}"
                    )
                };
                let check_2d = |dim, i, n| {
                    assert_eq!(
                        px.sample_2d(dim, i, n).to_array().map(f32::to_bits),
                        pat.sample_2d(pixel, dim, i, n).to_array().map(f32::to_bits),
                        "{isa:?} pixel {pixel} 2d dim {dim} index {i} count {n}"
                    )
                };
                let (spp, m) = (32u32, 3u32);
                match p {
                    0 => {
                        for i in 0..spp {
                            check_2d(0, i, spp);
                            for j in 0..m {
                                check_1d(1, i * m + j, spp * m);
                                check_2d(2, i * m + j, spp * m);
                                check_2d(4, i * m + j, spp * m);
                            }
                        }
                    }
                    1 => {
                        for dim in [0u32, 4, 1, 2] {
                            for i in 0..spp * m {
                                check_2d(dim, i, spp * m);
                                check_1d(dim, i, spp * m);
                            }
                        }
                    }
                    _ => {
                        for i in (0..spp).rev() {
                            check_1d(3, i, spp);
                            check_2d(2, i, spp);
                            check_2d(0, i, spp * m);
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn non_power_of_two_chunks_equal_the_pattern_values() {
        // Every index of non-power-of-two counts through the chunk fills (cycle-walking
        // permutation, divided cell split), on each instruction set: small and large strata,
        // grids with a power-of-two width (12), square (100, 400), strip (7, 37) and wide (262:
        // 2 × 131 rows) shapes, up to the 2^24 limit of the fast form and past it.
        for isa in Isa::available() {
            let pat = Pattern {
                seed: 11,
                kind: PatternKind::Stratified,
                cpu: isa.cpu(),
            };
            for pixel in [UVec2::new(1, 2), UVec2::new(300, 7)] {
                let px = pat.pixel(pixel);
                for count in [
                    3u32,
                    7,
                    12,
                    37,
                    100,
                    262,
                    400,
                    1000,
                    (1 << 24) - 3,
                    (1 << 24) + 3,
                ] {
                    let first = if count > 5000 { count - 40 } else { 0 };
                    for index in (first..count).chain([0, 17, count - 1]) {
                        for dim in [0u32, 5] {
                            assert_eq!(
                                px.sample_1d(dim, index, count).to_bits(),
                                pat.sample_1d(pixel, dim, index, count).to_bits(),
                                "{isa:?} 1d count {count} index {index}"
                            );
                            assert_eq!(
                                px.sample_2d(dim, index, count).to_array().map(f32::to_bits),
                                pat.sample_2d(pixel, dim, index, count)
                                    .to_array()
                                    .map(f32::to_bits),
                                "{isa:?} 2d count {count} index {index}"
                            );
                        }
                    }
                }
            }
        }
    }
}

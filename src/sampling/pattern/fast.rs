//! The integer form of `stratified` sets, the fast path of [`PixelSamples`](super::PixelSamples):
//! a stratum index with its 24-bit jitter appended as fraction bits is one fixed-point number,
//! so a chunk of 16 values is integer permutation rounds, integer hashes, one exact conversion
//! and one IEEE division per value — the same f32s as the definition in `stratified.rs`
//! (tests/pat_golden.rs). Plain loops over the chunk's 16 lanes, compiled for every instruction
//! set the CPU runs (`Cpu::dispatch`); on AVX-512 the intrinsics of `avx512.rs` serve instead.

use glam::Vec2;

use super::pixel::CHUNK;
use super::sets::{SetKeys, Strata};
use crate::isa::{Cpu, Kernel, Token};
use crate::sampling::ONE_MINUS_EPSILON;
use crate::sampling::hash::{HASH_INIT, mix64};
use crate::sampling::permutation::PermDomain;

/// The shape of a `stratified` sample set of `count` points in the integer form of the
/// [`PixelSamples`] fast path; only usable (`valid`) for counts of at most 2^24 strata (where
/// the fixed-point arithmetic and the f32 cell split below are exact).
#[derive(Clone, Copy, Debug)]
pub(super) struct FastStrata {
    /// The `count` argument this was made for; `u64::MAX` (no u32 count) marks an empty slot.
    pub(super) key: u64,
    /// Whether `count` has a fast form (else the general path serves it).
    pub(super) valid: bool,
    /// Permutation domain [0, count).
    pub(super) dom: PermDomain,
    /// Grid width nx.
    pub(super) nx: u32,
    /// nx − 1 (used when nx is a power of two).
    pub(super) nx_mask: u32,
    /// log2(nx) when nx is a power of two, else `u32::MAX` (the cell split then divides).
    pub(super) nx_log2: u32,
    /// count · 2^24, nx · 2^24, ny · 2^24 (exact in f32): the divisors of a stratum index
    /// with its 24-bit jitter appended as fraction bits.
    pub(super) div_1d: f32,
    pub(super) div_x: f32,
    pub(super) div_y: f32,
    /// Every 1D stratum index is < 2^7, so stratum · 2^24 + jitter fits an i32.
    pub(super) small_1d: bool,
    /// The same for both 2D axes.
    pub(super) small_2d: bool,
}

impl FastStrata {
    /// An empty cache slot.
    pub(super) const NONE: Self = Self {
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
    pub(super) fn new(count: u32) -> Self {
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
    /// y: bits 40..64), one 64-bit hash per lane.
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
    pub(super) fn chunk_2d(&self, set: &SetKeys, base: u32) -> [Vec2; CHUNK] {
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
    pub(super) fn chunk_1d_on(&self, cpu: Cpu, set: &SetKeys, base: u32) -> [f32; CHUNK] {
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
    pub(super) fn chunk_2d_on(&self, cpu: Cpu, set: &SetKeys, base: u32) -> [Vec2; CHUNK] {
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
}

/// (s mod nx, s / nx) for s, nx < 2^24 through an f32 division (x86 has no vector integer
/// division). Exact: s and nx convert exactly; if nx divides s the quotient q is
/// exact, else s/nx = q + r/nx lies at least 1/nx below q + 1 while half an ulp of it is at
/// most 2^-24 · s/nx < 1/nx, so the rounded quotient stays in [q, q + 1) and truncates to q.
#[inline(always)]
fn split_f32(s: u32, nx: u32) -> (u32, u32) {
    let q = (s as f32 / nx as f32) as u32;
    (s - q * nx, q)
}

/// [`in_stratum_fixed`] of a chunk; `small` (every stratum < 2^7) takes an i32 form (the same
/// values: the integer is the same and exact either way).
// Measured: the i32 form took mis-area from 3283 to 3278 Ir per sample (2cba393).
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
    // `v` is never NaN, so this is `v.min(ONE_MINUS_EPSILON)` without `min`'s NaN handling.
    if v < ONE_MINUS_EPSILON {
        v
    } else {
        ONE_MINUS_EPSILON
    }
}

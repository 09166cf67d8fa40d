//! The AVX-512 form of the `stratified` fast path: a pixel's set keys hashed 8 dimensions per
//! vector ([`RawSets`]), chunks of 16 values as one 16-lane vector per step, and the group
//! fills of [`PixelSamples`](super::PixelSamples) in raw mode. The same values as the integer
//! form of `fast.rs` and the definition in `stratified.rs` (tests/pat_golden.rs).

use super::CACHED_DIMS;
use super::sets::SetKeys;
use crate::sampling::hash::HASH_INIT;
use crate::sampling::permutation::Permutation;
#[cfg(target_arch = "x86_64")]
use {
    super::fast::FastStrata,
    super::pixel::{CHUNK, PixelSamples},
    super::{Pattern, TAG_1D, TAG_2D, TAG_JITTER},
    crate::isa::{Avx512, Kernel, Token},
    crate::sampling::ONE_MINUS_EPSILON,
    glam::Vec2,
};

/// The key material of one tag's (1D or 2D) sets of a pixel's [`CACHED_DIMS`] dimensions
/// in the `stratified` AVX-512 path: per dimension the permutation's mixed keys (`k`, `k2`
/// of [`Permutation::from_mixed`]) and the jitter key, as the vector hashes produce them.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct RawSets {
    k: [u64; CACHED_DIMS],
    k2: [u64; CACHED_DIMS],
    jitter: [u64; CACHED_DIMS],
}

impl RawSets {
    /// The [`SetKeys`] of dimension `d` (< [`CACHED_DIMS`]): what `SetKeys::new` makes for a
    /// `stratified` set (its `key` is only read by `sobol`).
    #[inline]
    pub(super) fn set(&self, d: usize) -> SetKeys {
        SetKeys {
            perm: Permutation::from_mixed(self.k[d], self.k2[d]),
            jitter: self.jitter[d],
            jitter_fast: self.jitter[d].wrapping_add(HASH_INIT),
            ..Default::default()
        }
    }
}

impl Pattern {
    /// The raw set keys of [`SamplePattern::pixel`] of a `stratified` pattern on AVX-512
    /// ([`RawSets`]): the keys of the 8 cached dimensions are 8 u64 lanes, so every hash of a
    /// pixel's set keys is one vector op, and they are stored as they come (6 vector stores;
    /// the round keys of a dimension are derived when its chunk is filled, for the few
    /// dimensions an integrator uses). `prefix`: the pixel's [`Pattern::pixel_hash`].
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn raw_stratified_avx512(&self, t: Avx512, prefix: u64, raw: &mut [RawSets; 2]) {
        use crate::sampling::hash::{hash_step_avx512, mix64_avx512};
        use std::arch::x86_64::*;
        const _: () = assert!(CACHED_DIMS == 8, "one 8-lane vector of dimensions");
        // SAFETY: `t` proves the CPU runs AVX-512.
        let (prefix, lanes) = unsafe {
            (
                _mm512_set1_epi64(prefix as i64),
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
}

impl FastStrata {
    /// [`FastStrata::chunk_1d`] on AVX-512, written with intrinsics, one 16-lane vector per
    /// step; any count, since the permutation cycle-walks on lane masks.
    // Over the portable loops: 1-thread 256² 64 spp mis-area 0.778 → 0.744 s (d25f354).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn chunk_1d_avx512(&self, t: Avx512, set: &SetKeys, base: u32) -> [f32; CHUNK] {
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
    pub(super) fn chunk_2d_avx512(&self, t: Avx512, set: &SetKeys, base: u32) -> [Vec2; CHUNK] {
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
    use crate::sampling::hash::mix64_avx512;
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
        // Two 8-lane halves written out: a closure would lose the AVX-512 target features.
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

impl PixelSamples {
    /// A raw-mode miss of the 1D (`arity` 0) or 2D (1) value `index` of `count` of `dim`:
    /// if the AVX-512 fill serves it, fill its chunk and the group's (see `learned`) and
    /// return `index`'s offset in the chunk; else `None` (the general path serves it).
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(super) fn miss_raw(&self, arity: usize, dim: u32, index: u32, count: u32) -> Option<usize> {
        let d = dim as usize;
        if d >= CACHED_DIMS || index >= count {
            return None;
        }
        let f = self.fast(count);
        if !f.valid || (arity == 1 && !f.small_2d) {
            return None;
        }
        let base = index & !(CHUNK as u32 - 1);
        let alone = self.alone[arity] & (1 << d) != 0;
        if !alone {
            self.learned[arity][d].set(count);
        }
        let mut masks = [0u32; 2];
        masks[arity] = 1 << d;
        // Group fills only for counts that are whole blocks: the renderer's 16-lane packets
        // then stay in step with the blocks. Otherwise a packet spans two blocks and the pixel
        // filter's walk runs ahead of the shading dimensions: a group fill of its next block
        // would evict the block they still read, and every block would be filled 2–3 times.
        // A dimension read ahead of the others (`alone`) fills its own chunk only.
        for k in (0..CACHED_DIMS).filter(|_| !alone && count.is_multiple_of(CHUNK as u32)) {
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
}

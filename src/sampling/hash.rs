//! Stateless hashing and per-sample PCG streams: every random number is a pure function of
//! (seed, pixel, sample index, dimension), so renders are identical under any scheduling.

use rand_core::Rng;
use rand_pcg::Pcg32;

/// 64-bit finaliser (splitmix64 / murmur3 style): a good avalanche for combining keys.
#[inline]
pub fn mix64(mut x: u64) -> u64 {
    x ^= x >> 30;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^= x >> 27;
    x = x.wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// [`mix64`] of 8 u64 lanes on AVX-512 (DQ: 64-bit multiply), lane for lane the same.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn mix64_avx512(
    _: crate::isa::Avx512,
    x: std::arch::x86_64::__m512i,
) -> std::arch::x86_64::__m512i {
    use std::arch::x86_64::*;
    // SAFETY: the token proves the CPU runs AVX-512 (F and DQ).
    unsafe {
        let x = _mm512_xor_si512(x, _mm512_srli_epi64::<30>(x));
        let x = _mm512_mullo_epi64(x, _mm512_set1_epi64(0xbf58_476d_1ce4_e5b9_u64 as i64));
        let x = _mm512_xor_si512(x, _mm512_srli_epi64::<27>(x));
        let x = _mm512_mullo_epi64(x, _mm512_set1_epi64(0x94d0_49bb_1331_11eb_u64 as i64));
        _mm512_xor_si512(x, _mm512_srli_epi64::<31>(x))
    }
}

/// [`hash_step`] of 8 u64 lanes on AVX-512 (DQ), lane for lane the same.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn hash_step_avx512(
    t: crate::isa::Avx512,
    h: std::arch::x86_64::__m512i,
    k: std::arch::x86_64::__m512i,
) -> std::arch::x86_64::__m512i {
    use std::arch::x86_64::*;
    // SAFETY: the token proves the CPU runs AVX-512.
    let x = unsafe {
        let c = _mm512_set1_epi64(0x9e37_79b9_7f4a_7c15_u64 as i64);
        let t = _mm512_add_epi64(_mm512_add_epi64(k, c), _mm512_slli_epi64::<6>(h));
        _mm512_xor_si512(h, t)
    };
    mix64_avx512(t, x)
}

/// Hash any number of 64-bit keys into one well-mixed 64-bit value.
#[inline]
pub fn hash_keys(keys: &[u64]) -> u64 {
    keys.iter().fold(HASH_INIT, |h, &k| hash_step(h, k))
}

/// The state [`hash_keys`] starts from: `hash_keys(&[a, b]) == hash_step(hash_step(HASH_INIT, a), b)`.
pub const HASH_INIT: u64 = 0x9e37_79b9_7f4a_7c15;

/// One step of [`hash_keys`]: lets callers hash a shared key prefix once and extend it.
#[inline]
pub fn hash_step(h: u64, k: u64) -> u64 {
    mix64(h ^ k.wrapping_add(0x9e37_79b9_7f4a_7c15).wrapping_add(h << 6))
}

/// Two uniform f32 in [0, 1) for element `index` of the stream `key`: one SplitMix64 output
/// (a Weyl step then [`mix64`]), i.e. a counter-based generator with no state to carry.
#[inline]
pub fn uniform_pair(key: u64, index: u32) -> (f32, f32) {
    let h = mix64(key.wrapping_add((index as u64).wrapping_add(1).wrapping_mul(HASH_INIT)));
    (u32_to_unit(h as u32), u32_to_unit((h >> 32) as u32))
}

/// A PCG32 stream seeded from a hash of keys (no state shared between threads).
#[inline]
pub fn pcg_from_keys(keys: &[u64]) -> Pcg32 {
    let h = hash_keys(keys);
    Pcg32::new(h, mix64(h ^ 0xda3e_39cb_94b9_5bdb) | 1)
}

/// A uniform f32 in [0, 1) from the top 24 bits of a u32.
#[inline]
pub fn u32_to_unit(x: u32) -> f32 {
    (x >> 8) as f32 * (1.0 / (1u32 << 24) as f32)
}

/// The next uniform f32 in [0, 1) of a PCG stream.
#[inline]
pub fn next_f32(rng: &mut Pcg32) -> f32 {
    u32_to_unit(rng.next_u32())
}

//! Hashed random permutations of [0, n): a pure function of (index, n, key), so strata can be
//! assigned to sample indices without storing a shuffled table (idea after Kensler 2013,
//! "Correlated Multi-Jittered Sampling"; this construction is our own).

/// The keys of one round, pre-derived from the permutation key (see [`round`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct RoundKeys {
    /// Xored in first.
    x: u32,
    /// Odd multiplier.
    m: u32,
    /// Added before the fixed multiplier.
    a: u32,
}

impl RoundKeys {
    /// The round of xor key `k` and multiplier `m` (made odd).
    #[inline]
    fn new(k: u32, m: u32) -> Self {
        Self {
            x: k,
            m: m | 1,
            a: k >> 16,
        }
    }
}

/// One keyed round of invertible operations on `bits`-bit integers (`mask = 2^bits − 1`,
/// `s1 = bits/2 + 1`, `s2 = bits/3 + 1`).
#[inline(always)]
fn round(i: u32, r: &RoundKeys, dom: &PermDomain) -> u32 {
    // Each step is a bijection of [0, 2^bits): xor/add a constant, multiply by an odd number,
    // and xor with a right shift of itself (the result stays inside the mask). The low `bits`
    // bits of a sum or product depend only on the operands' low bits, so masking once after
    // each multiply gives the same value as masking every operand.
    let mut i = (i ^ r.x).wrapping_mul(r.m) & dom.mask;
    i ^= i >> dom.s1;
    i = i.wrapping_add(r.a).wrapping_mul(0x2c1b_3c6d) & dom.mask;
    i ^ (i >> dom.s2)
}

/// The image of `index` under a pseudo-random permutation of [0, n) selected by `key`.
///
/// Indices ≥ n wrap modulo n; n = 0 is treated as 1. Works for any n by cycle-walking a
/// bijection of the enclosing power of two (expected < 2 steps).
pub fn permute(index: u32, n: u32, key: u64) -> u32 {
    Permutation::new(key).apply(index, n)
}

/// The round keys of one [`permute`] key, derived once so that a sample set that permutes many
/// indices under the same key (one pixel's strata) pays the two key hashes only once.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Permutation {
    r: [RoundKeys; 3],
}

impl Permutation {
    /// The round keys of `key`.
    #[inline]
    pub fn new(key: u64) -> Self {
        let k = super::hash::mix64(key);
        Self::from_mixed(k, super::hash::mix64(k))
    }

    /// [`Permutation::new`] from `k = mix64(key)` and `k2 = mix64(k)` (computed elsewhere,
    /// e.g. 8 keys at a time on vectors).
    #[inline]
    pub(crate) fn from_mixed(k: u64, k2: u64) -> Self {
        let [k0, k1, k2, k3] = [k as u32, (k >> 32) as u32, k2 as u32, (k2 >> 32) as u32];
        Self {
            r: [
                RoundKeys::new(k0, k1),
                RoundKeys::new(k2, k3),
                RoundKeys::new(k1 ^ k2, k0 ^ k3),
            ],
        }
    }

    /// Same as [`permute`]`(index, n, key)` for the key this was made from.
    #[inline]
    pub fn apply(&self, index: u32, n: u32) -> u32 {
        self.apply_in(index, &PermDomain::new(n))
    }

    /// [`Permutation::apply`] with the domain's bit width precomputed (hot path).
    #[inline]
    pub fn apply_in(&self, index: u32, dom: &PermDomain) -> u32 {
        let n = dom.n;
        self.apply_wrapped(if index < n { index } else { index % n }, dom)
    }

    /// [`Permutation::apply_in`] of an index already in [0, n) (hot path: the caller wrapped it).
    #[inline(always)]
    pub fn apply_wrapped(&self, index: u32, dom: &PermDomain) -> u32 {
        // n = 1 needs no special case: its mask is 0, so every round maps to 0.
        let mut i = index;
        loop {
            i = round(i, &self.r[0], dom);
            i = round(i, &self.r[1], dom);
            i = round(i, &self.r[2], dom);
            if i < dom.n {
                return i;
            }
        }
    }
}

impl Permutation {
    /// The images of the `N` consecutive indices `base..base + N` (each < n), computed in one
    /// loop over all `N` lanes: for a power of two n (no cycle-walking) the three
    /// rounds once; otherwise every lane walks its cycle until all lanes are inside [0, n)
    /// (lanes already inside keep their value, so each is the scalar [`Permutation::apply_wrapped`]).
    /// Entries for indices ≥ n (when base + N > n) are unspecified.
    #[inline(always)]
    pub fn apply_many<const N: usize>(&self, base: u32, dom: &PermDomain) -> [u32; N] {
        let (p, d) = (*self, *dom);
        let rounds = |i: u32| round(round(round(i, &p.r[0], &d), &p.r[1], &d), &p.r[2], &d);
        let mut out = [0u32; N];
        if d.is_pow2() {
            for (k, o) in out.iter_mut().enumerate() {
                *o = rounds(base.wrapping_add(k as u32));
            }
        } else {
            for (k, o) in out.iter_mut().enumerate() {
                let i = base.wrapping_add(k as u32);
                // Indices ≥ n start from 0 instead: a cycle of [n, 2^bits) alone would never end.
                *o = rounds(if i < d.n { i } else { 0 });
            }
            while out.iter().any(|&o| o >= d.n) {
                for o in out.iter_mut() {
                    let r = rounds(*o);
                    *o = if *o >= d.n { r } else { *o };
                }
            }
        }
        out
    }
}

#[cfg(target_arch = "x86_64")]
impl Permutation {
    /// [`Permutation::apply_many`] of the 16 indices `base..base + 16` as one AVX-512 vector:
    /// the same rounds, lane for lane (u32 wrapping multiply, logical shifts by the same
    /// counts, masks); for a non-power-of-two n, lanes outside [0, n) walk on under a lane mask
    /// until every lane is inside (indices ≥ n start from 0, as in `apply_many`).
    #[inline(always)]
    pub(crate) fn apply_16_avx512(
        &self,
        t: crate::isa::Avx512,
        base: u32,
        dom: &PermDomain,
    ) -> std::arch::x86_64::__m512i {
        use std::arch::x86_64::*;
        /// The rounds on 16 lanes (a function, not a closure: a closure would be compiled
        /// without the AVX-512 features).
        #[inline(always)]
        fn rounds(
            _: crate::isa::Avx512,
            mut i: __m512i,
            keys: &[(__m512i, __m512i, __m512i); 3],
            mask: __m512i,
            (s1, s2): (__m128i, __m128i),
        ) -> __m512i {
            // SAFETY: the token proves the CPU runs AVX-512.
            unsafe {
                let fixed = _mm512_set1_epi32(0x2c1b_3c6d);
                for &(x, m, a) in keys {
                    i = _mm512_xor_si512(i, x);
                    i = _mm512_and_si512(_mm512_mullo_epi32(i, m), mask);
                    i = _mm512_xor_si512(i, _mm512_srl_epi32(i, s1));
                    i = _mm512_add_epi32(i, a);
                    i = _mm512_and_si512(_mm512_mullo_epi32(i, fixed), mask);
                    i = _mm512_xor_si512(i, _mm512_srl_epi32(i, s2));
                }
                i
            }
        }
        // SAFETY: the token proves the CPU runs AVX-512.
        unsafe {
            let mask = _mm512_set1_epi32(dom.mask as i32);
            // Shift counts < 32 (bits ≤ 32), as the scalar `>>`.
            let shifts = (
                _mm_cvtsi32_si128(dom.s1 as i32),
                _mm_cvtsi32_si128(dom.s2 as i32),
            );
            let mut keys = [(
                _mm512_setzero_si512(),
                _mm512_setzero_si512(),
                _mm512_setzero_si512(),
            ); 3];
            for (k, r) in keys.iter_mut().zip(&self.r) {
                *k = (
                    _mm512_set1_epi32(r.x as i32),
                    _mm512_set1_epi32(r.m as i32),
                    _mm512_set1_epi32(r.a as i32),
                );
            }
            let lanes = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
            let idx = _mm512_add_epi32(_mm512_set1_epi32(base as i32), lanes);
            if dom.is_pow2() {
                return rounds(t, idx, &keys, mask, shifts);
            }
            let n = _mm512_set1_epi32(dom.n as i32);
            let mut i = rounds(
                t,
                _mm512_maskz_mov_epi32(_mm512_cmplt_epu32_mask(idx, n), idx),
                &keys,
                mask,
                shifts,
            );
            loop {
                let out = _mm512_cmpge_epu32_mask(i, n);
                if out == 0 {
                    return i;
                }
                i = _mm512_mask_mov_epi32(i, out, rounds(t, i, &keys, mask, shifts));
            }
        }
    }
}

/// The length of a permuted range with the width of its enclosing power of two, which
/// [`Permutation::apply_in`] would otherwise recompute for every index.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PermDomain {
    /// Length (≥ 1).
    n: u32,
    /// 2^bits − 1 with 2^bits the smallest power of two ≥ n.
    mask: u32,
    /// First shift of a round, bits/2 + 1.
    s1: u32,
    /// Second shift of a round, bits/3 + 1.
    s2: u32,
}

impl Default for PermDomain {
    /// The domain [0, 1).
    fn default() -> Self {
        Self::new(1)
    }
}

impl PermDomain {
    /// The domain [0, 1).
    pub const ONE: Self = Self {
        n: 1,
        mask: 0,
        s1: 1,
        s2: 1,
    };

    /// The domain [0, n) (n = 0 counts as 1).
    #[inline]
    pub fn new(n: u32) -> Self {
        let n = n.max(1);
        let bits = 32 - (n - 1).leading_zeros();
        let mask = if bits == 32 {
            u32::MAX
        } else {
            (1 << bits) - 1
        };
        Self {
            n,
            mask,
            s1: bits / 2 + 1,
            s2: bits / 3 + 1,
        }
    }

    /// The length n.
    #[inline]
    pub fn len(&self) -> u32 {
        self.n
    }

    /// 2^bits − 1, with 2^bits the smallest power of two ≥ n.
    #[inline]
    pub fn mask(&self) -> u32 {
        self.mask
    }

    /// Whether n is a power of two (no cycle-walking: every round stays inside [0, n)).
    #[inline]
    pub fn is_pow2(&self) -> bool {
        self.mask.wrapping_add(1) == self.n
    }

    /// Never true: the domain holds at least one element.
    #[inline]
    pub fn is_empty(&self) -> bool {
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::{Chi2Config, chi2_discrete};

    #[test]
    fn permute_is_a_bijection_for_every_length() {
        for n in 1..=300u32 {
            for key in [0u64, 1, 0xdead_beef, u64::MAX] {
                let mut seen = vec![false; n as usize];
                for i in 0..n {
                    let j = permute(i, n, key) as usize;
                    assert!(!seen[j], "n = {n}, key = {key}: {j} hit twice");
                    seen[j] = true;
                }
            }
        }
        assert_eq!(permute(5, 0, 3), 0);
        assert_eq!(permute(7, 5, 9), permute(2, 5, 9));
    }

    #[test]
    fn chi2_permute_image_is_uniform_over_keys() {
        // Over random keys, where a fixed index lands must be uniform on [0, n), for a
        // power of two and for an awkward length that needs cycle-walking.
        for (n, index) in [(16u32, 3u32), (37, 0), (37, 36)] {
            let pmf = vec![1.0 / n as f64; n as usize];
            let cfg = Chi2Config {
                samples: 200_000,
                num_tests: 3,
                ..Default::default()
            };
            let r = chi2_discrete(&cfg, &pmf, |u| {
                let key = ((u[0].to_bits() as u64) << 40)
                    ^ ((u[1].to_bits() as u64) << 20)
                    ^ u[2].to_bits() as u64;
                Some(permute(index, n, key) as usize)
            });
            assert!(r.passed, "n = {n}, index = {index}: {}", r.summary());
        }
    }
}

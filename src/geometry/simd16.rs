//! Sixteen f32 lanes (one per ray of a packet) on three backends: AVX-512 (one `__m512`, masks
//! in `__mmask16`), AVX2 (two `__m256`, masks as sign bits) and portable lane loops. The packet
//! kernels are generic over [`Simd`] and instantiated inside `#[target_feature]` functions, into
//! which these `#[inline(always)]` operations (and the intrinsics they call) are inlined.
//!
//! Every operation is the IEEE single-precision operation per lane (no fused multiply-add), and
//! `min`/`max` have the semantics of SSE `minps`/`maxps` (glam's `Vec4::min`/`max`): the second
//! operand unless the first is strictly smaller/larger. Hence a lane computes exactly what the
//! scalar (`Vec4`) code computes for that ray.

// Lane loops `for i in 0..PACKET` index several arrays at once.
#![allow(clippy::needless_range_loop)]

use super::Ray;
pub(super) use crate::isa::Portable;
use crate::isa::Token;
use std::ops::{Add, Mul, Sub};

/// Lanes per vector: rays per packet.
pub const LANES: usize = 16;

/// One f32 per ray, in memory.
pub type Lanes = [f32; LANES];

/// A 16-lane f32 vector type with lane masks (see the module docs), implemented by the
/// instruction-set tokens of [`crate::isa`]. The operations that make vectors or masks from
/// nothing take the token (`self`); every other one takes a vector, which exists only where a
/// token did: so the intrinsics run only on CPUs that have them, by construction. Nominally
/// `pub` (the module is private, so no other crate can name it) because the sealed supertrait
/// of the public `packet::PacketRayForm` names it.
pub trait Simd: Token {
    /// Sixteen f32 lanes.
    type F: Copy + Add<Output = Self::F> + Sub<Output = Self::F> + Mul<Output = Self::F>;
    /// A lane mask.
    type M: Copy;
    /// Every lane `x`.
    fn splat(self, x: f32) -> Self::F;
    /// The lanes of `a`.
    fn load(self, a: &Lanes) -> Self::F;
    /// Write the lanes to `a`.
    fn store(v: Self::F, a: &mut Lanes);
    /// Lane-wise IEEE quotient.
    fn div(a: Self::F, b: Self::F) -> Self::F;
    /// Lane-wise IEEE square root.
    fn sqrt(a: Self::F) -> Self::F;
    /// The rays' origins, directions and t_max transposed to lanes: `[o.x, o.y, o.z, d.x,
    /// d.y, d.z, t_max]`.
    fn rays(self, rays: &[Ray; LANES]) -> [Self::F; 7];
    /// `if a < b { a } else { b }` per lane (SSE `minps`).
    fn min(a: Self::F, b: Self::F) -> Self::F;
    /// `if a > b { a } else { b }` per lane (SSE `maxps`).
    fn max(a: Self::F, b: Self::F) -> Self::F;
    /// `a < b` (false for NaN).
    fn lt(a: Self::F, b: Self::F) -> Self::M;
    /// `a <= b` (false for NaN).
    fn le(a: Self::F, b: Self::F) -> Self::M;
    /// `a == b` (false for NaN).
    fn eq(a: Self::F, b: Self::F) -> Self::M;
    /// Lanes whose sign bit is set.
    fn sign(a: Self::F) -> Self::M;
    /// `1.0` with the sign of each lane.
    fn sign_one(a: Self::F) -> Self::F;
    /// `|a|` (the sign bit cleared).
    fn abs(a: Self::F) -> Self::F;
    /// `if m { a } else { b }` per lane.
    fn select(m: Self::M, a: Self::F, b: Self::F) -> Self::F;
    /// `a & b`.
    fn and(a: Self::M, b: Self::M) -> Self::M;
    /// `a | b`.
    fn or(a: Self::M, b: Self::M) -> Self::M;
    /// `a & !b`.
    fn andnot(a: Self::M, b: Self::M) -> Self::M;
    /// `a ^ b`.
    fn xor(a: Self::M, b: Self::M) -> Self::M;
    /// One bit per lane (bit i = lane i).
    fn bits(m: Self::M) -> u32;
    /// Lanes whose bit patterns are equal (integer compare: ids kept in f32 lanes).
    fn eq_bits(a: Self::F, b: Self::F) -> Self::M;
    /// The bit pattern plus one in lanes `m` (`next_up` of a non-negative finite value),
    /// `a` elsewhere.
    fn inc_bits(m: Self::M, a: Self::F) -> Self::F;
    /// The mask with lane i set where bit i of `b` is (the inverse of [`Simd::bits`]).
    fn mask(self, b: u32) -> Self::M;
    /// The 16 × 16 transpose: lane k of result i is lane i of `rows[k]` (bits moved as is).
    fn transpose(rows: [Self::F; LANES]) -> [Self::F; LANES];
}

/// Code generic over the [`Simd`] backends (the 16-ray packet kernels).
pub(crate) trait SimdKernel {
    /// What the kernel returns.
    type Output;
    /// The kernel on backend `s`.
    fn run<S: Simd>(self, s: S) -> Self::Output;
}

/// `k` on the [`Simd`] backend of token `t`: called from a [`crate::isa::Kernel`], so inside
/// the function `Cpu::dispatch` compiled for `t`'s set (the other arms fold away: `t`'s type
/// fixes which one is taken).
#[inline(always)]
pub(crate) fn on_simd<T: Token, K: SimdKernel>(t: T, k: K) -> K::Output {
    #[cfg(target_arch = "x86_64")]
    if let Some(a) = t.avx512() {
        return k.run(a);
    }
    #[cfg(target_arch = "x86_64")]
    if let Some(a) = t.avx2() {
        return k.run(a);
    }
    let _ = t;
    k.run(Portable)
}

/// A [`SimdKernel`] as a [`crate::isa::Kernel`], for `Cpu::dispatch`.
pub(crate) struct OnSimd<K>(pub K);

impl<K: SimdKernel> crate::isa::Kernel for OnSimd<K> {
    type Output = K::Output;
    #[inline(always)]
    fn run<T: Token>(self, t: T) -> K::Output {
        on_simd(t, self.0)
    }
}

/// [`Simd::transpose`] through memory, for the backends without a faster one.
#[inline(always)]
fn transpose_lanes(a: &[Lanes; LANES]) -> [Lanes; LANES] {
    let mut t = [[0.0f32; LANES]; LANES];
    for k in 0..LANES {
        for i in 0..LANES {
            t[i][k] = a[k][i];
        }
    }
    t
}

/// [`Simd::rays`] by scalar moves.
#[inline(always)]
fn ray_arrays(rays: &[Ray; LANES]) -> [Lanes; 7] {
    let mut a = [[0.0f32; LANES]; 7];
    for (i, r) in rays.iter().enumerate() {
        let (o, d) = (r.o.to_array(), r.d.to_array());
        for k in 0..3 {
            a[k][i] = o[k];
            a[3 + k][i] = d[k];
        }
        a[6][i] = r.t_max;
    }
    a
}

/// Sixteen lanes of the portable backend: plain lane loops. `pub`
/// only because the public token [`Portable`] implements [`Simd`] (the module is private).
#[derive(Clone, Copy)]
pub struct PV(Lanes);

macro_rules! lanewise {
    ($t:ty, $tr:ident, $f:ident, $op:tt) => {
        impl std::ops::$tr for $t {
            type Output = $t;
            #[inline(always)]
            fn $f(self, o: $t) -> $t {
                let mut r = [0.0; LANES];
                for i in 0..LANES {
                    r[i] = self.0[i] $op o.0[i];
                }
                PV(r)
            }
        }
    };
}
lanewise!(PV, Add, add, +);
lanewise!(PV, Sub, sub, -);
lanewise!(PV, Mul, mul, *);
lanewise!(PV, Div, div, /);

impl PV {
    #[inline(always)]
    fn map2(self, o: PV, f: impl Fn(f32, f32) -> f32) -> PV {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = f(self.0[i], o.0[i]);
        }
        PV(r)
    }
    #[inline(always)]
    fn cmp(self, o: PV, f: impl Fn(f32, f32) -> bool) -> [u32; LANES] {
        let mut m = [0; LANES];
        for i in 0..LANES {
            m[i] = if f(self.0[i], o.0[i]) { !0 } else { 0 };
        }
        m
    }
}

#[inline(always)]
fn zip(a: [u32; LANES], b: [u32; LANES], f: impl Fn(u32, u32) -> u32) -> [u32; LANES] {
    let mut m = [0; LANES];
    for i in 0..LANES {
        m[i] = f(a[i], b[i]);
    }
    m
}

impl Simd for Portable {
    type F = PV;
    type M = [u32; LANES];
    #[inline(always)]
    fn splat(self, x: f32) -> PV {
        PV([x; LANES])
    }
    #[inline(always)]
    fn load(self, a: &Lanes) -> PV {
        PV(*a)
    }
    #[inline(always)]
    fn store(v: PV, a: &mut Lanes) {
        *a = v.0;
    }
    #[inline(always)]
    fn div(a: PV, b: PV) -> PV {
        a / b
    }
    #[inline(always)]
    fn sqrt(a: PV) -> PV {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = a.0[i].sqrt();
        }
        PV(r)
    }
    #[inline(always)]
    fn rays(self, rays: &[Ray; LANES]) -> [PV; 7] {
        ray_arrays(rays).map(PV)
    }
    #[inline(always)]
    fn min(a: PV, b: PV) -> PV {
        a.map2(b, |a, b| if a < b { a } else { b })
    }
    #[inline(always)]
    fn max(a: PV, b: PV) -> PV {
        a.map2(b, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    fn lt(a: PV, b: PV) -> Self::M {
        a.cmp(b, |a, b| a < b)
    }
    #[inline(always)]
    fn le(a: PV, b: PV) -> Self::M {
        a.cmp(b, |a, b| a <= b)
    }
    #[inline(always)]
    fn eq(a: PV, b: PV) -> Self::M {
        a.cmp(b, |a, b| a == b)
    }
    #[inline(always)]
    fn sign(a: PV) -> Self::M {
        let mut m = [0; LANES];
        for i in 0..LANES {
            m[i] = ((a.0[i].to_bits() as i32) >> 31) as u32;
        }
        m
    }
    #[inline(always)]
    fn sign_one(a: PV) -> PV {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = f32::from_bits(1.0f32.to_bits() | (a.0[i].to_bits() & 0x8000_0000));
        }
        PV(r)
    }
    #[inline(always)]
    fn abs(a: PV) -> PV {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = a.0[i].abs();
        }
        PV(r)
    }
    #[inline(always)]
    fn select(m: Self::M, a: PV, b: PV) -> PV {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = f32::from_bits((a.0[i].to_bits() & m[i]) | (b.0[i].to_bits() & !m[i]));
        }
        PV(r)
    }
    #[inline(always)]
    fn and(a: Self::M, b: Self::M) -> Self::M {
        zip(a, b, |a, b| a & b)
    }
    #[inline(always)]
    fn or(a: Self::M, b: Self::M) -> Self::M {
        zip(a, b, |a, b| a | b)
    }
    #[inline(always)]
    fn andnot(a: Self::M, b: Self::M) -> Self::M {
        zip(a, b, |a, b| a & !b)
    }
    #[inline(always)]
    fn xor(a: Self::M, b: Self::M) -> Self::M {
        zip(a, b, |a, b| a ^ b)
    }
    #[inline(always)]
    fn bits(m: Self::M) -> u32 {
        m.iter()
            .enumerate()
            .fold(0, |b, (i, &m)| b | (m >> 31) << i)
    }
    #[inline(always)]
    fn eq_bits(a: PV, b: PV) -> Self::M {
        let mut m = [0; LANES];
        for i in 0..LANES {
            m[i] = if a.0[i].to_bits() == b.0[i].to_bits() {
                !0
            } else {
                0
            };
        }
        m
    }
    #[inline(always)]
    fn inc_bits(m: Self::M, a: PV) -> PV {
        let mut r = [0.0; LANES];
        for i in 0..LANES {
            r[i] = f32::from_bits(a.0[i].to_bits().wrapping_add(m[i] >> 31));
        }
        PV(r)
    }
    #[inline(always)]
    fn mask(self, b: u32) -> Self::M {
        let mut m = [0; LANES];
        for i in 0..LANES {
            m[i] = 0u32.wrapping_sub(b >> i & 1);
        }
        m
    }
    #[inline(always)]
    fn transpose(rows: [PV; LANES]) -> [PV; LANES] {
        transpose_lanes(&rows.map(|r| r.0)).map(PV)
    }
}

/// The x86-64 backends, implemented for the tokens [`Avx2`] and [`Avx512`]: a vector `A2` or
/// `A5` is made only from a token (or from another vector), and a token only on a CPU with
/// its features, which is what the `SAFETY` comments below rely on. The kernels run inside
/// `crate::isa::Cpu::dispatch`'s `#[target_feature]` functions, into which these
/// `#[inline(always)]` operations inline.
#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{LANES, Lanes, Ray, Simd, transpose_lanes};
    use crate::isa::{Avx2, Avx512};
    use std::arch::x86_64::*;
    use std::mem::{offset_of, size_of};

    /// Byte offsets of the seven fields of [`Simd::rays`] within a `Ray` (glam's `Vec3` is
    /// `repr(C)`: x, y, z at 0, 4, 8).
    const FIELDS: [usize; 7] = [
        offset_of!(Ray, o),
        offset_of!(Ray, o) + 4,
        offset_of!(Ray, o) + 8,
        offset_of!(Ray, d),
        offset_of!(Ray, d) + 4,
        offset_of!(Ray, d) + 8,
        offset_of!(Ray, t_max),
    ];

    /// Byte offset of ray `i` (for gathers; 16 rays are far below `i32::MAX` bytes).
    const fn ray_offset(i: usize) -> i32 {
        (i * size_of::<Ray>()) as i32
    }

    /// Sixteen lanes of [`Avx2`]: two `__m256`; a mask is the sign bits of a vector. The
    /// field is private: only the token's operations make one.
    #[derive(Clone, Copy)]
    pub struct A2(__m256, __m256);

    /// Sixteen lanes of [`Avx512`]: one `__m512`; masks are `__mmask16`. The field is
    /// private: only the token's operations make one.
    #[derive(Clone, Copy)]
    pub struct A5(__m512);

    macro_rules! binop {
        ($t:ident, $tr:ident, $f:ident, $i2:ident, $i5:ident) => {
            impl std::ops::$tr for A2 {
                type Output = A2;
                #[inline(always)]
                fn $f(self, o: A2) -> A2 {
                    // SAFETY: AVX2 is available (see the module docs).
                    unsafe { A2($i2(self.0, o.0), $i2(self.1, o.1)) }
                }
            }
            impl std::ops::$tr for A5 {
                type Output = A5;
                #[inline(always)]
                fn $f(self, o: A5) -> A5 {
                    // SAFETY: AVX-512F is available (see the module docs).
                    unsafe { A5($i5(self.0, o.0)) }
                }
            }
        };
    }
    binop!(A2, Add, add, _mm256_add_ps, _mm512_add_ps);
    binop!(A2, Sub, sub, _mm256_sub_ps, _mm512_sub_ps);
    binop!(A2, Mul, mul, _mm256_mul_ps, _mm512_mul_ps);

    /// Every lane `x`. Private: called by the token's `splat` and by operations that hold an
    /// `A2` (so the CPU runs AVX2).
    #[inline(always)]
    fn set2(x: f32) -> A2 {
        // SAFETY: AVX2 is available (see the module docs).
        unsafe { A2(_mm256_set1_ps(x), _mm256_set1_ps(x)) }
    }

    /// The lanes of `a` (private, as [`set2`]).
    #[inline(always)]
    fn load2(a: &Lanes) -> A2 {
        // SAFETY: AVX2 is available; `a` holds 16 floats (unaligned loads).
        unsafe {
            A2(
                _mm256_loadu_ps(a.as_ptr()),
                _mm256_loadu_ps(a.as_ptr().add(8)),
            )
        }
    }

    /// Apply a two-operand `__m256` intrinsic to both halves.
    macro_rules! halves {
        ($f:expr, $a:expr, $b:expr) => {
            // SAFETY: AVX2 is available (see the module docs).
            unsafe { A2($f($a.0, $b.0), $f($a.1, $b.1)) }
        };
    }

    impl Simd for Avx2 {
        type F = A2;
        type M = A2;
        #[inline(always)]
        fn splat(self, x: f32) -> A2 {
            set2(x)
        }
        #[inline(always)]
        fn load(self, a: &Lanes) -> A2 {
            load2(a)
        }
        #[inline(always)]
        fn store(v: A2, a: &mut Lanes) {
            // SAFETY: AVX2 is available; `a` holds 16 floats (unaligned stores).
            unsafe {
                _mm256_storeu_ps(a.as_mut_ptr(), v.0);
                _mm256_storeu_ps(a.as_mut_ptr().add(8), v.1);
            }
        }
        #[inline(always)]
        fn div(a: A2, b: A2) -> A2 {
            halves!(_mm256_div_ps, a, b)
        }
        #[inline(always)]
        fn sqrt(a: A2) -> A2 {
            // SAFETY: AVX2 is available (see the module docs).
            unsafe { A2(_mm256_sqrt_ps(a.0), _mm256_sqrt_ps(a.1)) }
        }
        #[inline(always)]
        fn rays(self, rays: &[Ray; LANES]) -> [A2; 7] {
            let base = rays.as_ptr() as *const f32;
            // SAFETY: AVX2 is available; every gathered address is ray i's field at byte
            // offset ray_offset(i) + FIELDS[k] < size_of_val(rays), inside the array.
            unsafe {
                let lo = _mm256_setr_epi32(
                    ray_offset(0),
                    ray_offset(1),
                    ray_offset(2),
                    ray_offset(3),
                    ray_offset(4),
                    ray_offset(5),
                    ray_offset(6),
                    ray_offset(7),
                );
                let hi = _mm256_add_epi32(lo, _mm256_set1_epi32(ray_offset(8)));
                let mut out = [A2(_mm256_setzero_ps(), _mm256_setzero_ps()); 7];
                for k in 0..7 {
                    let f = _mm256_set1_epi32(FIELDS[k] as i32);
                    out[k] = A2(
                        _mm256_i32gather_ps::<1>(base, _mm256_add_epi32(lo, f)),
                        _mm256_i32gather_ps::<1>(base, _mm256_add_epi32(hi, f)),
                    );
                }
                out
            }
        }
        #[inline(always)]
        fn min(a: A2, b: A2) -> A2 {
            halves!(_mm256_min_ps, a, b)
        }
        #[inline(always)]
        fn max(a: A2, b: A2) -> A2 {
            halves!(_mm256_max_ps, a, b)
        }
        #[inline(always)]
        fn lt(a: A2, b: A2) -> A2 {
            halves!(_mm256_cmp_ps::<_CMP_LT_OQ>, a, b)
        }
        #[inline(always)]
        fn le(a: A2, b: A2) -> A2 {
            halves!(_mm256_cmp_ps::<_CMP_LE_OQ>, a, b)
        }
        #[inline(always)]
        fn eq(a: A2, b: A2) -> A2 {
            halves!(_mm256_cmp_ps::<_CMP_EQ_OQ>, a, b)
        }
        #[inline(always)]
        fn sign(a: A2) -> A2 {
            // A mask is read by its sign bits only.
            a
        }
        #[inline(always)]
        fn sign_one(a: A2) -> A2 {
            let s = set2(-0.0);
            let one = set2(1.0);
            // SAFETY: AVX2 is available (see the module docs).
            unsafe {
                A2(
                    _mm256_or_ps(one.0, _mm256_and_ps(a.0, s.0)),
                    _mm256_or_ps(one.1, _mm256_and_ps(a.1, s.1)),
                )
            }
        }
        #[inline(always)]
        fn abs(a: A2) -> A2 {
            // `_mm256_andnot_ps(x, y)` is `!x & y`.
            halves!(_mm256_andnot_ps, set2(-0.0), a)
        }
        #[inline(always)]
        fn select(m: A2, a: A2, b: A2) -> A2 {
            // SAFETY: AVX2 is available (see the module docs).
            unsafe {
                A2(
                    _mm256_blendv_ps(b.0, a.0, m.0),
                    _mm256_blendv_ps(b.1, a.1, m.1),
                )
            }
        }
        #[inline(always)]
        fn and(a: A2, b: A2) -> A2 {
            halves!(_mm256_and_ps, a, b)
        }
        #[inline(always)]
        fn or(a: A2, b: A2) -> A2 {
            halves!(_mm256_or_ps, a, b)
        }
        #[inline(always)]
        fn andnot(a: A2, b: A2) -> A2 {
            // `_mm256_andnot_ps(x, y)` is `!x & y`.
            halves!(_mm256_andnot_ps, b, a)
        }
        #[inline(always)]
        fn xor(a: A2, b: A2) -> A2 {
            halves!(_mm256_xor_ps, a, b)
        }
        #[inline(always)]
        fn bits(m: A2) -> u32 {
            // SAFETY: AVX2 is available (see the module docs).
            unsafe {
                (_mm256_movemask_ps(m.0) as u32) | (_mm256_movemask_ps(m.1) as u32) << (LANES / 2)
            }
        }
        #[inline(always)]
        fn eq_bits(a: A2, b: A2) -> A2 {
            // SAFETY: AVX2 is available (see the module docs).
            unsafe {
                let (a0, a1) = (_mm256_castps_si256(a.0), _mm256_castps_si256(a.1));
                let (b0, b1) = (_mm256_castps_si256(b.0), _mm256_castps_si256(b.1));
                A2(
                    _mm256_castsi256_ps(_mm256_cmpeq_epi32(a0, b0)),
                    _mm256_castsi256_ps(_mm256_cmpeq_epi32(a1, b1)),
                )
            }
        }
        #[inline(always)]
        fn inc_bits(m: A2, a: A2) -> A2 {
            // SAFETY: AVX2 is available (see the module docs).
            let up = unsafe {
                let one = _mm256_set1_epi32(1);
                let (a0, a1) = (_mm256_castps_si256(a.0), _mm256_castps_si256(a.1));
                A2(
                    _mm256_castsi256_ps(_mm256_add_epi32(a0, one)),
                    _mm256_castsi256_ps(_mm256_add_epi32(a1, one)),
                )
            };
            Self::select(m, up, a)
        }
        #[inline(always)]
        fn mask(self, b: u32) -> A2 {
            // SAFETY: AVX2 is available (see the module docs).
            unsafe {
                let lo = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
                let hi = _mm256_slli_epi32::<8>(lo);
                let v = _mm256_set1_epi32(b as i32);
                A2(
                    _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(v, lo), lo)),
                    _mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_and_si256(v, hi), hi)),
                )
            }
        }
        #[inline(always)]
        fn transpose(rows: [A2; LANES]) -> [A2; LANES] {
            let mut a = [[0.0f32; LANES]; LANES];
            for k in 0..LANES {
                Self::store(rows[k], &mut a[k]);
            }
            let t = transpose_lanes(&a);
            let mut out = [set2(0.0); LANES];
            for i in 0..LANES {
                out[i] = load2(&t[i]);
            }
            out
        }
    }

    impl Simd for Avx512 {
        type F = A5;
        type M = __mmask16;
        #[inline(always)]
        fn splat(self, x: f32) -> A5 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { A5(_mm512_set1_ps(x)) }
        }
        #[inline(always)]
        fn load(self, a: &Lanes) -> A5 {
            // SAFETY: AVX-512F is available; `a` holds 16 floats (unaligned load).
            unsafe { A5(_mm512_loadu_ps(a.as_ptr())) }
        }
        #[inline(always)]
        fn store(v: A5, a: &mut Lanes) {
            // SAFETY: AVX-512F is available; `a` holds 16 floats (unaligned store).
            unsafe { _mm512_storeu_ps(a.as_mut_ptr(), v.0) }
        }
        #[inline(always)]
        fn div(a: A5, b: A5) -> A5 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { A5(_mm512_div_ps(a.0, b.0)) }
        }
        #[inline(always)]
        fn sqrt(a: A5) -> A5 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { A5(_mm512_sqrt_ps(a.0)) }
        }
        #[inline(always)]
        fn rays(self, rays: &[Ray; LANES]) -> [A5; 7] {
            // Ray i's seven floats as row i (masked loads: nothing past the ray is read),
            // transposed: field k of every ray is then row FIELDS[k] / 4. Shuffles instead of
            // seven gathers, which are slow on some CPUs (Zen 4).
            const RAY_FLOATS: usize = size_of::<Ray>() / 4;
            const _: () = assert!(size_of::<Ray>() == 28 && RAY_FLOATS == 7);
            let base = rays.as_ptr() as *const f32;
            let mut rows = [self.splat(0.0); LANES];
            for i in 0..LANES {
                // SAFETY: AVX-512F is available; lanes 0..7 lie in ray i (28 bytes from
                // base + 7i floats), and masked-off lanes are not accessed.
                rows[i] = A5(unsafe { _mm512_maskz_loadu_ps(0x7f, base.add(RAY_FLOATS * i)) });
            }
            let t = Self::transpose(rows);
            let mut out = [t[0]; 7];
            for k in 0..7 {
                out[k] = t[FIELDS[k] / 4];
            }
            out
        }
        #[inline(always)]
        fn min(a: A5, b: A5) -> A5 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { A5(_mm512_min_ps(a.0, b.0)) }
        }
        #[inline(always)]
        fn max(a: A5, b: A5) -> A5 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { A5(_mm512_max_ps(a.0, b.0)) }
        }
        #[inline(always)]
        fn lt(a: A5, b: A5) -> __mmask16 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { _mm512_cmp_ps_mask::<_CMP_LT_OQ>(a.0, b.0) }
        }
        #[inline(always)]
        fn le(a: A5, b: A5) -> __mmask16 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { _mm512_cmp_ps_mask::<_CMP_LE_OQ>(a.0, b.0) }
        }
        #[inline(always)]
        fn eq(a: A5, b: A5) -> __mmask16 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(a.0, b.0) }
        }
        #[inline(always)]
        fn sign(a: A5) -> __mmask16 {
            // SAFETY: AVX-512DQ is available (see the module docs).
            unsafe { _mm512_movepi32_mask(_mm512_castps_si512(a.0)) }
        }
        #[inline(always)]
        fn sign_one(a: A5) -> A5 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe {
                let s = _mm512_set1_epi32(i32::MIN);
                let one = _mm512_castps_si512(_mm512_set1_ps(1.0));
                let x = _mm512_and_si512(_mm512_castps_si512(a.0), s);
                A5(_mm512_castsi512_ps(_mm512_or_si512(x, one)))
            }
        }
        #[inline(always)]
        fn abs(a: A5) -> A5 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { A5(_mm512_abs_ps(a.0)) }
        }
        #[inline(always)]
        fn select(m: __mmask16, a: A5, b: A5) -> A5 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { A5(_mm512_mask_blend_ps(m, b.0, a.0)) }
        }
        #[inline(always)]
        fn and(a: __mmask16, b: __mmask16) -> __mmask16 {
            a & b
        }
        #[inline(always)]
        fn or(a: __mmask16, b: __mmask16) -> __mmask16 {
            a | b
        }
        #[inline(always)]
        fn andnot(a: __mmask16, b: __mmask16) -> __mmask16 {
            a & !b
        }
        #[inline(always)]
        fn xor(a: __mmask16, b: __mmask16) -> __mmask16 {
            a ^ b
        }
        #[inline(always)]
        fn bits(m: __mmask16) -> u32 {
            m as u32
        }
        #[inline(always)]
        fn eq_bits(a: A5, b: A5) -> __mmask16 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe { _mm512_cmpeq_epi32_mask(_mm512_castps_si512(a.0), _mm512_castps_si512(b.0)) }
        }
        #[inline(always)]
        fn inc_bits(m: __mmask16, a: A5) -> A5 {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe {
                let x = _mm512_castps_si512(a.0);
                let y = _mm512_mask_add_epi32(x, m, x, _mm512_set1_epi32(1));
                A5(_mm512_castsi512_ps(y))
            }
        }
        #[inline(always)]
        fn mask(self, b: u32) -> __mmask16 {
            b as __mmask16
        }
        #[inline(always)]
        fn transpose(rows: [A5; LANES]) -> [A5; LANES] {
            // SAFETY: AVX-512F is available (see the module docs).
            unsafe {
                let mut r = [_mm512_setzero_ps(); LANES];
                for k in 0..LANES {
                    r[k] = rows[k].0;
                }
                // 2 × 2 blocks of floats within each 128-bit lane, then of pairs: u[4j + m]
                // holds, in 128-bit lane L, element 4L + m of rows 4j..4j + 3.
                let mut t = [_mm512_setzero_ps(); LANES];
                for j in 0..8 {
                    t[2 * j] = _mm512_unpacklo_ps(r[2 * j], r[2 * j + 1]);
                    t[2 * j + 1] = _mm512_unpackhi_ps(r[2 * j], r[2 * j + 1]);
                }
                let mut u = [_mm512_setzero_ps(); LANES];
                for j in 0..4 {
                    let (a, b) = (_mm512_castps_pd(t[4 * j]), _mm512_castps_pd(t[4 * j + 2]));
                    let (c, d) = (
                        _mm512_castps_pd(t[4 * j + 1]),
                        _mm512_castps_pd(t[4 * j + 3]),
                    );
                    u[4 * j] = _mm512_castpd_ps(_mm512_unpacklo_pd(a, b));
                    u[4 * j + 1] = _mm512_castpd_ps(_mm512_unpackhi_pd(a, b));
                    u[4 * j + 2] = _mm512_castpd_ps(_mm512_unpacklo_pd(c, d));
                    u[4 * j + 3] = _mm512_castpd_ps(_mm512_unpackhi_pd(c, d));
                }
                // Then the 128-bit lanes: result 4L + m gathers lane L of u[m], u[4 + m],
                // u[8 + m], u[12 + m].
                let mut out = [A5(_mm512_setzero_ps()); LANES];
                for m in 0..4 {
                    let (a, b, c, d) = (u[m], u[4 + m], u[8 + m], u[12 + m]);
                    let v0 = _mm512_shuffle_f32x4::<0x44>(a, b);
                    let v1 = _mm512_shuffle_f32x4::<0xee>(a, b);
                    let v2 = _mm512_shuffle_f32x4::<0x44>(c, d);
                    let v3 = _mm512_shuffle_f32x4::<0xee>(c, d);
                    out[m] = A5(_mm512_shuffle_f32x4::<0x88>(v0, v2));
                    out[4 + m] = A5(_mm512_shuffle_f32x4::<0xdd>(v0, v2));
                    out[8 + m] = A5(_mm512_shuffle_f32x4::<0x88>(v1, v3));
                    out[12 + m] = A5(_mm512_shuffle_f32x4::<0xdd>(v1, v3));
                }
                out
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Special values for the lanes: zeros of both signs, infinities, NaN, tiny and huge.
    const SPECIAL: [f32; 8] = [
        0.0,
        -0.0,
        f32::INFINITY,
        f32::NEG_INFINITY,
        f32::NAN,
        1e-30,
        -3.5,
        f32::MAX,
    ];

    /// All pairs of special values over two 16-lane rows (64 pairs in four rounds).
    fn rows(round: usize) -> (Lanes, Lanes) {
        let (mut a, mut b) = ([0.0; LANES], [0.0; LANES]);
        for i in 0..LANES {
            let k = round * LANES + i;
            a[i] = SPECIAL[k / 8];
            b[i] = SPECIAL[k % 8];
        }
        (a, b)
    }

    /// The bit patterns of the lanes of `f`, NaNs as one pattern: the portable lanes may carry
    /// other NaN bits than x86's default NaN (Rust leaves them unspecified), and a NaN's sign
    /// and payload never decide a ray query (every comparison with a NaN lane fails).
    fn lane_bits<S: Simd>(f: S::F) -> [u32; LANES] {
        let mut a = [0.0; LANES];
        S::store(f, &mut a);
        a.map(canon)
    }

    /// `x`'s bits, with every NaN as `f32::NAN` (see [`lane_bits`]).
    fn canon(x: f32) -> u32 {
        // The NaN test on the integer bits: a float `is_nan` select may keep `x`'s NaN bits
        // (it did in some builds).
        let b = x.to_bits();
        if b & 0x7fff_ffff > 0x7f80_0000 {
            f32::NAN.to_bits()
        } else {
            b
        }
    }

    /// Every operation of backend `S` on the special values, as bit patterns.
    fn results<S: Simd>(s: S) -> Vec<u32> {
        let mut v = Vec::new();
        for round in 0..4 {
            let (a, b) = std::hint::black_box(rows(round));
            let (x, y) = (s.load(&a), s.load(&b));
            let values = [
                x + y,
                x - y,
                x * y,
                S::div(x, y),
                S::sqrt(x),
                S::min(x, y),
                S::max(x, y),
                S::sign_one(x),
                S::abs(x),
                S::select(S::lt(x, y), x, y),
            ];
            for f in values {
                v.extend(lane_bits::<S>(f));
            }
            v.extend(lane_bits::<S>(S::inc_bits(S::lt(x, y), x)));
            let masks = [
                S::lt(x, y),
                S::le(x, y),
                S::eq(x, y),
                S::sign(x),
                S::eq_bits(x, y),
                s.mask(0x8421 << round),
            ];
            let (m0, m1) = (masks[0], masks[2]);
            let combos = [
                S::and(m0, m1),
                S::or(m0, m1),
                S::andnot(m0, m1),
                S::xor(m0, m1),
            ];
            v.extend(masks.iter().chain(&combos).map(|&m| S::bits(m)));
        }
        let rows: [S::F; LANES] =
            std::array::from_fn(|k| s.load(&std::array::from_fn(|i| (k * LANES + i) as f32)));
        for f in S::transpose(rows) {
            v.extend(lane_bits::<S>(f));
        }
        let rays: [Ray; LANES] = std::array::from_fn(|i| Ray {
            o: Vec3::new(i as f32, -(i as f32), 0.5),
            d: Vec3::new(1.0, i as f32 * 0.25, -2.0),
            t_max: 100.0 + i as f32,
        });
        for f in s.rays(&rays) {
            v.extend(lane_bits::<S>(f));
        }
        v
    }

    /// The scalar reference of [`results`]: per lane what the portable backend must compute.
    #[test]
    fn portable_lanes_are_the_scalar_operations() {
        let (a, b) = rows(1);
        let r = results(Portable);
        let per_round = 11 * LANES + 10;
        for i in 0..LANES {
            let (x, y) = (a[i], b[i]);
            let at = |k: usize| r[per_round + k * LANES + i];
            assert_eq!(at(0), canon(x + y));
            assert_eq!(at(3), canon(x / y));
            assert_eq!(at(4), canon(x.sqrt()));
            // SSE semantics: the second operand unless the first is strictly smaller/larger.
            assert_eq!(at(5), canon(if x < y { x } else { y }));
            assert_eq!(at(6), canon(if x > y { x } else { y }));
            assert_eq!(at(7), canon(1.0f32.copysign(x)));
            assert_eq!(at(8), canon(x.abs()));
            let up = f32::from_bits(x.to_bits().wrapping_add(1));
            assert_eq!(at(10), canon(if x < y { up } else { x }));
        }
        // The transpose follows the four rounds: result i, lane k = row k, lane i = 16k + i.
        let t = &r[4 * per_round..];
        for i in 0..LANES {
            for k in 0..LANES {
                assert_eq!(t[i * LANES + k], ((k * LANES + i) as f32).to_bits());
            }
        }
    }

    /// The x86 backends agree with the portable one bit for bit (where the CPU has them).
    #[test]
    #[cfg(target_arch = "x86_64")]
    fn x86_backends_match_portable_lanes() {
        struct Results;
        impl SimdKernel for Results {
            type Output = Vec<u32>;
            #[inline(always)]
            fn run<S: Simd>(self, s: S) -> Vec<u32> {
                results(s)
            }
        }
        let want = results(Portable);
        for isa in crate::isa::Isa::available() {
            let cpu = isa.on_this_cpu().expect("available");
            assert_eq!(cpu.dispatch(OnSimd(Results)), want, "{isa:?}");
        }
    }
}

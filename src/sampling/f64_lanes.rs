//! f64 arithmetic written once for one lane or for four: the [`Real`] trait, implemented by
//! `f64` and (on x86-64) by [`F64x4`], four f64 lanes in one AVX2 register.
//!
//! Arvo's solid-angle triangle sampling, its atan2 and its sin/cos run in f64 (f32 cancels
//! catastrophically on small triangles), and the integrator's triangle-light kernel draws four
//! lanes per register. Both are the same generic functions ([`atan2`], [`sin_cos_0_8`],
//! `spherical_triangle`'s projection and inversion): the scalar path is that code at `f64`,
//! the vector path the same code at [`F64x4`], so a vector lane computes exactly the bits of
//! the scalar code (IEEE operations lane by lane, no fused multiply-add, the same order).
//!
//! Every operation has the semantics of the `f64` method of the same name for the inputs the
//! algorithms give it (see each method); [`Real::lit`] makes constants from an existing value,
//! so an [`F64x4`] exists only where an AVX2 token made one, and its intrinsics run only on
//! CPUs that have them, by construction.

use glam::{DVec3, Vec3};
use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

/// A lane mask of a [`Real`] type (`bool` for `f64`).
pub trait Mask:
    Copy + BitAnd<Output = Self> + BitOr<Output = Self> + BitXor<Output = Self> + Not<Output = Self>
{
}

impl Mask for bool {}

/// One f64 or several f64 lanes, with the operations of Arvo's sampler (see the module docs).
pub trait Real:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Per-lane booleans.
    type Mask: Mask;
    /// `x` in every lane (a constant of `self`'s type).
    fn lit(self, x: f64) -> Self;
    /// IEEE square root.
    fn sqrt(self) -> Self;
    /// The sign bit cleared.
    fn abs(self) -> Self;
    /// `f64::max(self, o)` for a non-NaN `o`: `o` where `self` is NaN.
    fn max(self, o: Self) -> Self;
    /// `f64::clamp(self, lo, hi)`: NaN stays NaN.
    fn clamp(self, lo: f64, hi: f64) -> Self;
    /// The magnitude of `self` with the sign bit of `sign`.
    fn copysign(self, sign: Self) -> Self;
    /// `self < o` (false for NaN).
    fn lt(self, o: Self) -> Self::Mask;
    /// `self > o` (false for NaN).
    fn gt(self, o: Self) -> Self::Mask;
    /// `self >= o` (false for NaN).
    fn ge(self, o: Self) -> Self::Mask;
    /// `self == o` (false for NaN).
    fn eq(self, o: Self) -> Self::Mask;
    /// `self != o` (true for NaN).
    fn ne(self, o: Self) -> Self::Mask;
    /// Neither infinite nor NaN.
    fn is_finite(self) -> Self::Mask;
    /// The sign bit is set.
    fn is_sign_negative(self) -> Self::Mask;
    /// Bit `i` (0 ≤ i < 63) of the representation is set.
    fn bit(self, i: u32) -> Self::Mask;
    /// The sign bit flipped where `m`.
    fn neg_where(self, m: Self::Mask) -> Self;
    /// `if m { a } else { b }` per lane.
    fn select(m: Self::Mask, a: Self, b: Self) -> Self;
}

impl Real for f64 {
    type Mask = bool;
    #[inline(always)]
    fn lit(self, x: f64) -> f64 {
        x
    }
    #[inline(always)]
    fn sqrt(self) -> f64 {
        f64::sqrt(self)
    }
    #[inline(always)]
    fn abs(self) -> f64 {
        f64::abs(self)
    }
    #[inline(always)]
    fn max(self, o: f64) -> f64 {
        f64::max(self, o)
    }
    #[inline(always)]
    fn clamp(self, lo: f64, hi: f64) -> f64 {
        f64::clamp(self, lo, hi)
    }
    #[inline(always)]
    fn copysign(self, sign: f64) -> f64 {
        f64::copysign(self, sign)
    }
    #[inline(always)]
    fn lt(self, o: f64) -> bool {
        self < o
    }
    #[inline(always)]
    fn gt(self, o: f64) -> bool {
        self > o
    }
    #[inline(always)]
    fn ge(self, o: f64) -> bool {
        self >= o
    }
    #[inline(always)]
    fn eq(self, o: f64) -> bool {
        self == o
    }
    #[inline(always)]
    fn ne(self, o: f64) -> bool {
        self != o
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
    #[inline(always)]
    fn is_sign_negative(self) -> bool {
        f64::is_sign_negative(self)
    }
    #[inline(always)]
    fn bit(self, i: u32) -> bool {
        self.to_bits() >> i & 1 != 0
    }
    #[inline(always)]
    fn neg_where(self, m: bool) -> f64 {
        f64::from_bits(self.to_bits() ^ (m as u64) << 63)
    }
    #[inline(always)]
    fn select(m: bool, a: f64, b: f64) -> f64 {
        if m { a } else { b }
    }
}

/// A 3-vector of [`Real`]s (R³): `DVec3`'s arithmetic in the same order (so at `f64` the same
/// bits), for one lane or four.
#[derive(Clone, Copy, Debug)]
pub struct R3<R> {
    /// x.
    pub x: R,
    /// y.
    pub y: R,
    /// z.
    pub z: R,
}

impl<R: Real> R3<R> {
    /// `DVec3::dot`.
    #[inline(always)]
    pub fn dot(self, o: Self) -> R {
        (self.x * o.x) + (self.y * o.y) + (self.z * o.z)
    }

    /// `DVec3::cross`.
    #[inline(always)]
    pub fn cross(self, o: Self) -> Self {
        R3 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    /// `DVec3::length`.
    #[inline(always)]
    pub fn length(self) -> R {
        self.dot(self).sqrt()
    }

    /// `DVec3::length_recip`.
    #[inline(always)]
    pub fn length_recip(self) -> R {
        self.x.lit(1.0) / self.length()
    }

    /// Every coordinate times `s`.
    #[inline(always)]
    pub fn scale(self, s: R) -> Self {
        R3 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }

    /// `if m { a } else { b }` per lane.
    #[inline(always)]
    pub fn select(m: R::Mask, a: Self, b: Self) -> Self {
        R3 {
            x: R::select(m, a.x, b.x),
            y: R::select(m, a.y, b.y),
            z: R::select(m, a.z, b.z),
        }
    }
}

impl<R: Real> Add for R3<R> {
    type Output = Self;
    #[inline(always)]
    fn add(self, o: Self) -> Self {
        R3 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl<R: Real> Sub for R3<R> {
    type Output = Self;
    #[inline(always)]
    fn sub(self, o: Self) -> Self {
        R3 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

impl From<DVec3> for R3<f64> {
    #[inline(always)]
    fn from(v: DVec3) -> Self {
        R3 {
            x: v.x,
            y: v.y,
            z: v.z,
        }
    }
}

impl From<Vec3> for R3<f64> {
    /// `Vec3::as_dvec3` (exact).
    #[inline(always)]
    fn from(v: Vec3) -> Self {
        v.as_dvec3().into()
    }
}

impl From<R3<f64>> for DVec3 {
    #[inline(always)]
    fn from(v: R3<f64>) -> Self {
        DVec3::new(v.x, v.y, v.z)
    }
}

/// `atan2(y, x)` in f64 (angle of (x, y) in [−π, π]) from plain arithmetic and selects: no
/// libm call and no branch, so the spherical triangle's solid angle,
/// 2·atan2(|triple product|, 1 + a·b + b·c + c·a), runs on several lanes at once. Within 2 ulp
/// of libm over the whole domain (zeros, subnormals, huge and infinite values, both signs;
/// tested as [`super::warps::atan2_f64`]); NaN in, NaN out.
///
/// Reduction: the octant swap gives t = n/d ∈ [0, 1] (n = min(|x|, |y|), d = max), then
/// atan t = θc + atan((t − c)/(1 + tc)) for the nearest of c ∈ {0, ¼, ½, 1}, so the Taylor
/// series only sees |r| ≤ 0.163 and converges to below f64 rounding by r²¹. The centres are
/// powers of two so that r = (n − c·d)/(d + c·n) (one division) has an exact numerator: c·d
/// is exact and the subtraction too (Sterbenz: each centre's range has c·d/2 ≤ n ≤ 2·c·d).
#[inline(always)]
pub fn atan2<R: Real>(y: R, x: R) -> R {
    // Boundaries between the centres: t = ⅛ (so that n ≥ c·d/2 for c = ¼), then the tangents
    // of the mid-angles between atan ¼, atan ½ and π/4.
    const B2: f64 = 0.369_924_076_215_481_23;
    const B3: f64 = 0.720_759_220_056_126_5;
    // atan ¼ and atan ½ in two parts (hi + lo), and the lo parts of π/4, π/2 and π.
    const TH_Q_HI: f64 = 0.244_978_663_126_864_14;
    const TH_Q_LO: f64 = 1.069_875_561_873_445_1e-17;
    const TH_H_HI: f64 = 0.463_647_609_000_806_1;
    const TH_H_LO: f64 = 2.269_877_745_296_168_7e-17;
    const PI4_LO: f64 = 3.061_616_997_868_383e-17;
    const PI2_LO: f64 = 6.123_233_995_736_766e-17;
    const PI_LO: f64 = 1.224_646_799_147_353_2e-16;
    let c = |v: f64| y.lit(v);
    let sel = R::select;
    let (ay, ax) = (y.abs(), x.abs());
    let swap = ay.gt(ax);
    let (n, d) = (sel(swap, ax, ay), sel(swap, ay, ax));
    // Special cases by select: ∞/∞ is t = 1 (angle π/4 of the octant), 0/0 is t = 0.
    let inf = n.eq(c(f64::INFINITY)) & d.eq(c(f64::INFINITY));
    let n = sel(inf, c(1.0), n);
    let d = sel(inf | d.eq(c(0.0)), c(1.0), d);
    // Exact power-of-two scaling keeps d + c·n finite and c·d normal (t is unchanged).
    let s = sel(
        d.gt(c(1e300)),
        c(1.0 / 1024.0),
        sel(d.lt(c(1e-290)), c(18_446_744_073_709_551_616.0), c(1.0)), // 2⁶⁴
    );
    let (n, d) = (n * s, d * s);
    let (c1, c2, c3) = (n.gt(c(0.125) * d), n.gt(c(B2) * d), n.gt(c(B3) * d));
    let cc = sel(c3, c(1.0), sel(c2, c(0.5), c(0.25)));
    // Centre 0 divides n/d directly (no c·d term: it would be 0·∞ for d = ∞).
    let num = sel(c1, n - cc * d, n);
    let den = sel(c1, d + cc * n, d);
    let r = num / den;
    let r2 = r * r;
    // Taylor coefficients 1/(2k+1) with alternating signs, r³ … r²¹, by Estrin's scheme
    // (pairs, then powers r⁴, r⁸, r¹⁶): a chain of 5 multiply-adds instead of Horner's 10,
    // which in scalar code is latency. p enters the result multiplied by r² ≤ 0.027.
    let (r4, r8) = (r2 * r2, r2 * r2 * (r2 * r2));
    let r16 = r8 * r8;
    let p01 = c(-1.0 / 3.0) + r2 * c(1.0 / 5.0);
    let p23 = c(-1.0 / 7.0) + r2 * c(1.0 / 9.0);
    let p45 = c(-1.0 / 11.0) + r2 * c(1.0 / 13.0);
    let p67 = c(-1.0 / 15.0) + r2 * c(1.0 / 17.0);
    let p89 = c(-1.0 / 19.0) + r2 * c(1.0 / 21.0);
    let p = ((p01 + r4 * p23) + r8 * (p45 + r4 * p67)) + r16 * p89;
    let atan_r = r + r * r2 * p;
    let th_hi = sel(
        c3,
        c(std::f64::consts::FRAC_PI_4),
        sel(c2, c(TH_H_HI), sel(c1, c(TH_Q_HI), c(0.0))),
    );
    let th_lo = sel(
        c3,
        c(PI4_LO),
        sel(c2, c(TH_H_LO), sel(c1, c(TH_Q_LO), c(0.0))),
    );
    // atan t ∈ [0, π/4]; the octant maps it to k + σ·atan t, k ∈ {0, π/2, π}, σ = ±1.
    let atan_t = th_hi + (th_lo + atan_r);
    let neg = x.is_sign_negative();
    let k_hi = sel(
        swap,
        c(std::f64::consts::FRAC_PI_2),
        sel(neg, c(std::f64::consts::PI), c(0.0)),
    );
    let k_lo = sel(swap, c(PI2_LO), sel(neg, c(PI_LO), c(0.0)));
    // σ = −1 where swap ≠ neg.
    let signed = atan_t.neg_where(swap ^ neg);
    let a = k_hi + (k_lo + signed);
    a.copysign(y)
}

/// `(sin x, cos x)` in f64 for 0 ≤ x ≤ 8 only (the caller guarantees the range; outside it
/// the result is inaccurate, never UB). Pure arithmetic and selects, so Arvo's sampler
/// (x = ξ₁Ω ∈ [0, 4π]) runs on several lanes at once without a libm call per lane.
///
/// Cody–Waite reduction by π/2 to the nearest quadrant q, in two parts (the high part has 8
/// trailing zero bits, so q·hi is exact for the q ≤ 5 that occur), then Taylor series on
/// |r| ≤ π/4 up to r¹⁵ / r¹⁶, whose truncation error (< 5e-17) is below f64 rounding. Error
/// vs libm is tested (≤ 2 ulp, as [`super::warps::sin_cos_0_8_f64`]).
#[inline(always)]
pub fn sin_cos_0_8<R: Real>(x: R) -> (R, R) {
    const PIO2_HI: f64 = f64::from_bits(std::f64::consts::FRAC_PI_2.to_bits() & !0xff);
    // The zeroed bits, plus π/2 − FRAC_PI_2 (the part of π/2 that f64 cannot hold).
    const PIO2_LO: f64 = (std::f64::consts::FRAC_PI_2 - PIO2_HI) + 6.123_233_995_736_766e-17;
    // The nearest quadrant q by the 1.5·2⁵² trick: adding it rounds x·2/π to an integer
    // (ulp 1 there) whose low bits are q's, and subtracting it again gives q exactly.
    // Not `as i32`: its saturation was 16 scalar conversions per kernel loop (dbcda06).
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    // 1/n! for the Taylor terms (exact to f64 rounding as constant expressions).
    const F3: f64 = 1.0 / 6.0;
    const F5: f64 = F3 / 20.0;
    const F7: f64 = F5 / 42.0;
    const F9: f64 = F7 / 72.0;
    const F11: f64 = F9 / 110.0;
    const F13: f64 = F11 / 156.0;
    const F15: f64 = F13 / 210.0;
    const F2: f64 = 0.5;
    const F4: f64 = F2 / 12.0;
    const F6: f64 = F4 / 30.0;
    const F8: f64 = F6 / 56.0;
    const F10: f64 = F8 / 90.0;
    const F12: f64 = F10 / 132.0;
    const F14: f64 = F12 / 182.0;
    const F16: f64 = F14 / 240.0;
    let c = |v: f64| x.lit(v);
    let shifted = x * c(std::f64::consts::FRAC_2_PI) + c(SHIFT);
    let qf = shifted - c(SHIFT);
    let r = (x - qf * c(PIO2_HI)) - qf * c(PIO2_LO);
    let r2 = r * r;
    // Estrin's scheme (pairs, then powers r⁴, r⁸), not Horner: a dependency chain of 4
    // multiply-adds instead of 7. The polynomials are damped by r² ≤ 0.62 in the result, so
    // the slightly different rounding does not show.
    let (r4, r8) = (r2 * r2, r2 * r2 * (r2 * r2));
    let ps = (c(-F3) + r2 * c(F5))
        + r4 * (c(-F7) + r2 * c(F9))
        + r8 * ((c(-F11) + r2 * c(F13)) - r4 * c(F15));
    let sin_r = r + r * r2 * ps;
    let pc = (c(F4) - r2 * c(F6))
        + r4 * (c(F8) - r2 * c(F10))
        + r8 * ((c(F12) - r2 * c(F14)) + r4 * c(F16));
    let cos_r = c(1.0) - r2 * c(F2) + r2 * r2 * pc;
    // Rotate by qπ/2 (q's low bits are those of `shifted`): odd q swaps sine and cosine,
    // bit 1 of q negates the sine, bit 1 of q + 1 (= bit 0 ⊕ bit 1 of q) the cosine.
    let (odd, half) = (shifted.bit(0), shifted.bit(1));
    let (a, b) = (R::select(odd, cos_r, sin_r), R::select(odd, sin_r, cos_r));
    (a.neg_where(half), b.neg_where(odd ^ half))
}

#[cfg(target_arch = "x86_64")]
pub use avx2::{F64x4, M64x4};

#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{Mask, Real};
    use crate::isa::Avx2;
    use std::arch::x86_64::*;
    use std::ops::{Add, BitAnd, BitOr, BitXor, Div, Mul, Neg, Not, Sub};

    /// Four f64 lanes in one AVX2 register. The field is private and every constructor takes
    /// an [`Avx2`] token, so a value proves that this CPU runs AVX2: that is what makes the
    /// intrinsics of its operations sound.
    #[derive(Clone, Copy, Debug)]
    pub struct F64x4(__m256d);

    /// A lane mask of [`F64x4`] (each lane all ones or all zeros), made only by comparing
    /// [`F64x4`]s (so it proves AVX2 as they do).
    #[derive(Clone, Copy, Debug)]
    pub struct M64x4(__m256d);

    impl F64x4 {
        /// Every lane `x`.
        #[inline(always)]
        pub fn splat(_: Avx2, x: f64) -> F64x4 {
            // SAFETY: the token proves AVX2 (see `crate::isa::Token`).
            F64x4(unsafe { _mm256_set1_pd(x) })
        }

        /// The four f32 of `a` widened (exactly) to f64: lane i is `a[i] as f64`.
        #[inline(always)]
        pub fn from_f32(_: Avx2, a: &[f32; 4]) -> F64x4 {
            // SAFETY: the token proves AVX2; `a` holds 4 floats (unaligned load).
            F64x4(unsafe { _mm256_cvtps_pd(_mm_loadu_ps(a.as_ptr())) })
        }

        /// The four lanes of `a`.
        #[inline(always)]
        pub fn from_array(_: Avx2, a: [f64; 4]) -> F64x4 {
            // SAFETY: the token proves AVX2; `a` holds 4 doubles (unaligned load).
            F64x4(unsafe { _mm256_loadu_pd(a.as_ptr()) })
        }

        /// The lanes rounded to f32 (as `as f32`: to nearest).
        #[inline(always)]
        pub fn to_f32(self) -> [f32; 4] {
            let mut a = [0.0f32; 4];
            // SAFETY: `self` proves AVX2; `a` holds 4 floats (unaligned store).
            unsafe { _mm_storeu_ps(a.as_mut_ptr(), _mm256_cvtpd_ps(self.0)) };
            a
        }

        /// The lanes.
        #[inline(always)]
        pub fn to_array(self) -> [f64; 4] {
            let mut a = [0.0f64; 4];
            // SAFETY: `self` proves AVX2; `a` holds 4 doubles (unaligned store).
            unsafe { _mm256_storeu_pd(a.as_mut_ptr(), self.0) };
            a
        }

        /// `x` in every lane (a value holds the proof of AVX2).
        #[inline(always)]
        fn set(x: f64) -> __m256d {
            // SAFETY: only called by operations on an `F64x4` or `M64x4`, which prove AVX2.
            unsafe { _mm256_set1_pd(x) }
        }
    }

    impl M64x4 {
        /// Bit i set where lane i is.
        #[inline(always)]
        pub fn bits(self) -> u32 {
            // SAFETY: `self` proves AVX2.
            unsafe { _mm256_movemask_pd(self.0) as u32 }
        }
    }

    macro_rules! binop {
        ($ty:ident, $tr:ident, $f:ident, $i:ident) => {
            impl $tr for $ty {
                type Output = $ty;
                #[inline(always)]
                fn $f(self, o: $ty) -> $ty {
                    // SAFETY: `self` proves AVX2 (see `F64x4`).
                    $ty(unsafe { $i(self.0, o.0) })
                }
            }
        };
    }
    binop!(F64x4, Add, add, _mm256_add_pd);
    binop!(F64x4, Sub, sub, _mm256_sub_pd);
    binop!(F64x4, Mul, mul, _mm256_mul_pd);
    binop!(F64x4, Div, div, _mm256_div_pd);
    binop!(M64x4, BitAnd, bitand, _mm256_and_pd);
    binop!(M64x4, BitOr, bitor, _mm256_or_pd);
    binop!(M64x4, BitXor, bitxor, _mm256_xor_pd);

    impl Neg for F64x4 {
        type Output = F64x4;
        #[inline(always)]
        fn neg(self) -> F64x4 {
            // SAFETY: `self` proves AVX2. Flipping the sign bit is f64 negation.
            F64x4(unsafe { _mm256_xor_pd(self.0, F64x4::set(-0.0)) })
        }
    }

    impl Not for M64x4 {
        type Output = M64x4;
        #[inline(always)]
        fn not(self) -> M64x4 {
            // SAFETY: `self` proves AVX2.
            M64x4(unsafe { _mm256_xor_pd(self.0, _mm256_castsi256_pd(_mm256_set1_epi64x(-1))) })
        }
    }

    impl Mask for M64x4 {}

    /// A comparison with predicate `P` as an [`M64x4`].
    macro_rules! cmp {
        ($f:ident, $p:ident) => {
            #[inline(always)]
            fn $f(self, o: F64x4) -> M64x4 {
                // SAFETY: `self` proves AVX2.
                M64x4(unsafe { _mm256_cmp_pd::<$p>(self.0, o.0) })
            }
        };
    }

    impl Real for F64x4 {
        type Mask = M64x4;
        #[inline(always)]
        fn lit(self, x: f64) -> F64x4 {
            F64x4(F64x4::set(x))
        }
        #[inline(always)]
        fn sqrt(self) -> F64x4 {
            // SAFETY: `self` proves AVX2.
            F64x4(unsafe { _mm256_sqrt_pd(self.0) })
        }
        #[inline(always)]
        fn abs(self) -> F64x4 {
            // SAFETY: `self` proves AVX2. `andnot(x, y)` is `!x & y`: the sign bit cleared.
            F64x4(unsafe { _mm256_andnot_pd(F64x4::set(-0.0), self.0) })
        }
        #[inline(always)]
        fn max(self, o: F64x4) -> F64x4 {
            // SAFETY: `self` proves AVX2. `maxpd` returns its second operand unless the first
            // is strictly greater, so `o` where `self` is NaN (`f64::max` for a non-NaN `o`).
            F64x4(unsafe { _mm256_max_pd(self.0, o.0) })
        }
        #[inline(always)]
        fn clamp(self, lo: f64, hi: f64) -> F64x4 {
            // SAFETY: `self` proves AVX2. `maxpd(lo, x)` is `if lo > x { lo } else { x }` and
            // `minpd(hi, m)` is `if hi < m { hi } else { m }`: `f64::clamp`, NaN passing.
            F64x4(unsafe { _mm256_min_pd(F64x4::set(hi), _mm256_max_pd(F64x4::set(lo), self.0)) })
        }
        #[inline(always)]
        fn copysign(self, sign: F64x4) -> F64x4 {
            let s = F64x4::set(-0.0);
            // SAFETY: `self` proves AVX2.
            F64x4(unsafe { _mm256_or_pd(_mm256_andnot_pd(s, self.0), _mm256_and_pd(s, sign.0)) })
        }
        cmp!(lt, _CMP_LT_OQ);
        cmp!(gt, _CMP_GT_OQ);
        cmp!(ge, _CMP_GE_OQ);
        cmp!(eq, _CMP_EQ_OQ);
        cmp!(ne, _CMP_NEQ_UQ);
        #[inline(always)]
        fn is_finite(self) -> M64x4 {
            // |x| < ∞ is false for ±∞ and NaN.
            self.abs().lt(self.lit(f64::INFINITY))
        }
        #[inline(always)]
        fn is_sign_negative(self) -> M64x4 {
            // SAFETY: `self` proves AVX2. As signed 64-bit integers, the lanes with the sign
            // bit set are the negative ones.
            M64x4(unsafe {
                _mm256_castsi256_pd(_mm256_cmpgt_epi64(
                    _mm256_setzero_si256(),
                    _mm256_castpd_si256(self.0),
                ))
            })
        }
        #[inline(always)]
        fn bit(self, i: u32) -> M64x4 {
            // SAFETY: `self` proves AVX2.
            M64x4(unsafe {
                let b = _mm256_set1_epi64x(1i64 << i);
                let x = _mm256_and_si256(_mm256_castpd_si256(self.0), b);
                _mm256_castsi256_pd(_mm256_cmpeq_epi64(x, b))
            })
        }
        #[inline(always)]
        fn neg_where(self, m: M64x4) -> F64x4 {
            // SAFETY: `self` proves AVX2. The sign bit where m's lane is all ones.
            F64x4(unsafe { _mm256_xor_pd(self.0, _mm256_and_pd(m.0, F64x4::set(-0.0))) })
        }
        #[inline(always)]
        fn select(m: M64x4, a: F64x4, b: F64x4) -> F64x4 {
            // SAFETY: `a` proves AVX2. `blendv` takes `a` where m's sign bit is set (all of a
            // set lane's bits are).
            F64x4(unsafe { _mm256_blendv_pd(b.0, a.0, m.0) })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::hash::pcg_from_keys;
    use rand_core::Rng;

    /// Awkward f64 inputs: zeros, subnormals, huge, infinite, NaN, both signs, and ordinary
    /// values around the reduction boundaries.
    fn specials() -> Vec<f64> {
        let mut v = vec![
            0.0,
            f64::MIN_POSITIVE,
            f64::MIN_POSITIVE / 3.0,
            1e-300,
            1e-200,
            0.125,
            0.369_924_076_215_481_23,
            0.720_759_220_056_126_5,
            0.5,
            1.0,
            2.0,
            1e200,
            1e301,
            f64::MAX,
            f64::INFINITY,
            f64::NAN,
        ];
        let neg: Vec<f64> = v.iter().map(|x| -x).collect();
        v.extend(neg);
        v
    }

    /// Random f64: uniform bit patterns (every exponent, NaNs too) and ordinary magnitudes.
    fn randoms(seed: u64, n: usize) -> Vec<f64> {
        let mut rng = pcg_from_keys(&[41, seed]);
        (0..n)
            .map(|i| {
                let bits = rng.next_u64();
                if i % 2 == 0 {
                    f64::from_bits(bits)
                } else {
                    // Mantissa in [1, 2), exponent in [-64, 64), random sign.
                    let m = f64::from_bits(0x3ff0_0000_0000_0000 | bits >> 12);
                    let e = (bits & 127) as i32 - 64;
                    let s = if bits >> 7 & 1 == 0 { 1.0 } else { -1.0 };
                    s * m * 2f64.powi(e)
                }
            })
            .collect()
    }

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan())
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn f64x4_atan2_and_sin_cos_are_the_scalar_bits() {
        let Some(t) = crate::isa::Avx2::new() else {
            return;
        };
        let mut xs = randoms(1, 40_000);
        let mut ys = randoms(2, 40_000);
        // Every pair of specials.
        for &y in &specials() {
            for &x in &specials() {
                xs.push(x);
                ys.push(y);
            }
        }
        let mut rng = pcg_from_keys(&[42]);
        let sc: Vec<f64> = (0..xs.len())
            .map(|_| 8.0 * (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64)
            .collect();
        let n = xs.len() / 4 * 4;
        for i in (0..n).step_by(4) {
            let load = |a: &[f64]| F64x4::from_array(t, a[i..i + 4].try_into().unwrap());
            let a = atan2(load(&ys), load(&xs)).to_array();
            let (sv, cv) = sin_cos_0_8(load(&sc));
            let (sv, cv) = (sv.to_array(), cv.to_array());
            for l in 0..4 {
                let (y, x, s) = (ys[i + l], xs[i + l], sc[i + l]);
                assert!(same(a[l], atan2(y, x)), "atan2({y:e}, {x:e})");
                let (ws, wc) = sin_cos_0_8(s);
                assert!(same(sv[l], ws) && same(cv[l], wc), "sin_cos({s:e})");
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn f64x4_operations_are_the_f64_methods() {
        let Some(t) = crate::isa::Avx2::new() else {
            return;
        };
        let mut xs = randoms(3, 4000);
        let mut ys = randoms(4, 4000);
        for &y in &specials() {
            for &x in &specials() {
                xs.push(x);
                ys.push(y);
            }
        }
        let n = xs.len() / 4 * 4;
        for i in (0..n).step_by(4) {
            let load = |a: &[f64]| F64x4::from_array(t, a[i..i + 4].try_into().unwrap());
            let (x, y) = (load(&xs), load(&ys));
            let m = |m: M64x4| m.bits();
            let ops = [
                (x + y).to_array(),
                (x - y).to_array(),
                (x * y).to_array(),
                (x / y).to_array(),
                (-x).to_array(),
                x.sqrt().to_array(),
                x.abs().to_array(),
                x.clamp(-1.0, 1.0).to_array(),
                x.copysign(y).to_array(),
                x.neg_where(x.lt(y)).to_array(),
                F64x4::select(x.ge(y), x, y).to_array(),
            ];
            let masks = [
                m(x.lt(y)),
                m(x.gt(y)),
                m(x.ge(y)),
                m(x.eq(y)),
                m(x.ne(y)),
                m(x.is_finite()),
                m(x.is_sign_negative()),
                m(x.bit(0)),
                m(x.bit(1)),
                m(!x.lt(y) ^ x.bit(0) | x.eq(y) & x.bit(1)),
            ];
            for l in 0..4 {
                let (a, b) = (xs[i + l], ys[i + l]);
                let want = [
                    a + b,
                    a - b,
                    a * b,
                    a / b,
                    -a,
                    a.sqrt(),
                    a.abs(),
                    a.clamp(-1.0, 1.0),
                    a.copysign(b),
                    Real::neg_where(a, a < b),
                    if a >= b { a } else { b },
                ];
                for (k, (got, want)) in ops.iter().zip(want).enumerate() {
                    assert!(same(got[l], want), "op {k} of ({a:e}, {b:e})");
                }
                let want = [
                    a < b,
                    a > b,
                    a >= b,
                    a == b,
                    a != b,
                    a.is_finite(),
                    a.is_sign_negative(),
                    a.to_bits() & 1 != 0,
                    a.to_bits() & 2 != 0,
                    !(a < b) ^ (a.to_bits() & 1 != 0) | (a == b) & (a.to_bits() & 2 != 0),
                ];
                for (k, (got, want)) in masks.iter().zip(want).enumerate() {
                    assert_eq!(got >> l & 1 != 0, want, "mask {k} of ({a:e}, {b:e})");
                }
                // `max` is `f64::max` for a non-NaN second operand (the only use).
                // (Signed zeros aside: `f64::max` may return either, and 1 − q² is never −0.)
                let zeros = a == 0.0 && b == 0.0;
                if !b.is_nan() && !zeros {
                    assert!(same(x.max(y).to_array()[l], a.max(b)), "max({a:e}, {b:e})");
                }
            }
        }
    }
}

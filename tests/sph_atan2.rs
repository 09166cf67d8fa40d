//! The libm-free f64 atan2 and sincos of the spherical-triangle sampler against libm, in ulps.

use penumbra::sampling::warps::{atan2_f64, sin_cos_0_8_f64};

/// Distance in ulps between two f64 of the same sign (u64::MAX if the signs differ or one is
/// NaN and the other not); 0 for two NaNs.
fn ulps(a: f64, b: f64) -> u64 {
    if a.is_nan() || b.is_nan() {
        return if a.is_nan() && b.is_nan() {
            0
        } else {
            u64::MAX
        };
    }
    if a == b {
        return 0;
    }
    if a.is_sign_negative() != b.is_sign_negative() {
        return u64::MAX;
    }
    a.to_bits().abs_diff(b.to_bits())
}

/// splitmix64: reproducible bits without a dependency.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn unit(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Largest ulp distance from libm over `pairs`, with the worst pair.
fn worst(pairs: impl Iterator<Item = (f64, f64)>) -> (u64, f64, f64) {
    let mut w = (0, 0.0, 0.0);
    for (y, x) in pairs {
        let e = ulps(atan2_f64(y, x), y.atan2(x));
        if e > w.0 {
            w = (e, y, x);
        }
    }
    w
}

/// ≤ 2 ulp where the solid angle calls it (num = |triple product| ∈ [0, 1], den ∈ [−2, 4]),
/// including tiny triangles (num → 0), den → 0 and negative den.
#[test]
fn atan2_f64_solid_angle_domain_within_2_ulp() {
    let mut rng = Rng(1);
    let n = 2_000_000;
    let pairs = (0..n).map(|i| {
        let num = match i % 4 {
            0 => rng.unit(),
            1 => rng.unit() * 10f64.powf(-20.0 * rng.unit()),
            2 => 10f64.powf(-300.0 * rng.unit()),
            _ => rng.unit() * 1e-3,
        };
        let den = match i % 3 {
            0 => 6.0 * rng.unit() - 2.0,
            1 => (2.0 * rng.unit() - 1.0) * 10f64.powf(-15.0 * rng.unit()),
            _ => -num * (0.5 + rng.unit()),
        };
        (num, den)
    });
    let (e, y, x) = worst(pairs);
    println!("solid-angle domain: max {e} ulp at atan2({y:e}, {x:e})");
    assert!(e <= 2, "{e} ulp at atan2({y:e}, {x:e})");
}

/// ≤ 2 ulp over the whole f64 plane: random bit patterns (all exponents, both signs,
/// subnormals) and pairs of nearby magnitudes (the octant and centre boundaries).
#[test]
fn atan2_f64_whole_domain_within_2_ulp() {
    let mut rng = Rng(2);
    let finite = |b: u64| {
        let v = f64::from_bits(b);
        if v.is_finite() { v } else { 1.0 }
    };
    let random = (0..1_000_000).map(|_| (finite(rng.next()), finite(rng.next())));
    let (e, y, x) = worst(random);
    println!("random bits: max {e} ulp at atan2({y:e}, {x:e})");
    assert!(e <= 2, "{e} ulp at atan2({y:e}, {x:e})");
    let mut rng = Rng(3);
    let near = (0..1_000_000).map(|i| {
        let x = f64::from_bits(rng.next() >> 2) * if i % 2 == 0 { 1.0 } else { -1.0 };
        let ratio = 1.2 * rng.unit() * if i % 3 == 0 { -1.0 } else { 1.0 };
        (finite((x * ratio).to_bits()), x)
    });
    let (e, y, x) = worst(near);
    println!("near ratios: max {e} ulp at atan2({y:e}, {x:e})");
    assert!(e <= 2, "{e} ulp at atan2({y:e}, {x:e})");
}

/// Zeros, infinities, NaN, extremes: the same bits as libm (signs of zero included).
#[test]
fn atan2_f64_special_values_match_libm() {
    let vals = [
        0.0,
        -0.0,
        f64::MIN_POSITIVE,
        5e-324,
        -5e-324,
        1e-300,
        1.0,
        -1.0,
        0.198_912_367_379_658,
        0.668_178_637_919_298_9,
        1e300,
        f64::MAX,
        -f64::MAX,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];
    for &y in &vals {
        for &x in &vals {
            let (a, b) = (atan2_f64(y, x), y.atan2(x));
            let e = ulps(a, b);
            assert!(e <= 2, "atan2({y:e}, {x:e}) = {a:e}, libm {b:e}");
            if a == 0.0 || a.is_infinite() {
                assert_eq!(a.to_bits(), b.to_bits(), "atan2({y:e}, {x:e})");
            }
        }
    }
}

/// The sincos Arvo calls is within 2 ulp of libm (or 1e-16 absolute near its zeros) on
/// [0, 8] ⊃ [0, 4π].
#[test]
fn sin_cos_0_8_f64_within_2_ulp() {
    let n = 1 << 21;
    let mut rng = Rng(4);
    let mut worst = (0u64, 0.0);
    for i in 0..=n {
        let x = if i % 2 == 0 {
            8.0 * i as f64 / n as f64
        } else {
            8.0 * rng.unit()
        };
        let (s, c) = sin_cos_0_8_f64(x);
        let (se, ce) = x.sin_cos();
        for (v, e) in [(s, se), (c, ce)] {
            // Near a zero of sin or cos the reduction's absolute error dominates: count ulps
            // of the result only where it is not tiny.
            let d = if e.abs() < 1e-3 {
                assert!((v - e).abs() < 1e-18, "x = {x:e}: {v:e} vs {e:e}");
                0
            } else {
                ulps(v, e)
            };
            if d > worst.0 {
                worst = (d, x);
            }
        }
    }
    println!("sin_cos_0_8_f64: max {} ulp at x = {:e}", worst.0, worst.1);
    assert!(worst.0 <= 2, "{} ulp at x = {:e}", worst.0, worst.1);
}

//! Warps from the unit square to hemispheres, spheres, disks, triangles and cones, each derived
//! by the inversion method (marginal + conditional), with its pdf and, where natural, its inverse.
//!
//! Conventions: directions are in a local frame with +z the pole (normal); pdfs over directions
//! are per unit solid angle; pdfs over points are per unit area.

use glam::{Vec2, Vec3};
use std::f32::consts::{FRAC_1_PI, FRAC_PI_2, FRAC_PI_4, PI, TAU};

/// `sqrt(max(0, x))`: guards against tiny negative arguments from rounding.
#[inline]
pub fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

/// Direction with polar cosine `cos_theta` around +z and azimuth `phi`.
#[inline]
pub fn spherical_direction(cos_theta: f32, phi: f32) -> Vec3 {
    // (1 − c)(1 + c) keeps sin θ accurate near the poles, where 1 − c² cancels.
    let sin_theta = safe_sqrt((1.0 - cos_theta) * (1.0 + cos_theta));
    let (sp, cp) = phi.sin_cos();
    Vec3::new(sin_theta * cp, sin_theta * sp, cos_theta)
}

/// `(sin 2πt, cos 2πt)` for a fraction of a turn `t` in [0, 1] (the warps' azimuth 2πξ), without
/// a libm `sincosf` call (on the hot path of every BSDF sample).
///
/// Reduction is exact: s = 4t, q = nearest quadrant, r = s − q ∈ [−½, ½] (Sterbenz), so the
/// polynomials only ever see |2πt − qπ/2| ≤ π/4; their minimax fits (Lawson iteration) are off by
/// ≤ 1.3e-9 (sin) and 3.3e-8 (cos) before their coefficients are rounded to f32. Abs. error
/// vs f64 ≤ 2e-7 is tested (measured 1.1e-7).
/// Being a polynomial in the exact r, it is also *more* accurate than `(TAU * t).sin_cos()`,
/// which first rounds the angle.
#[inline]
pub fn sin_cos_turn(t: f32) -> (f32, f32) {
    let s = 4.0 * t;
    // s + ½ ≥ 0 for t ≥ 0, so truncation is floor: cvttss2si instead of a libm/SSE4.1 round.
    let q = (s + 0.5) as i32;
    let r = s - q as f32;
    let r2 = r * r;
    // sin(π/2·r) and cos(π/2·r) on r ∈ [−½, ½]. The leading sin coefficient is the fit's,
    // not π/2: both round to neighbouring f32 values and the fit's is the more accurate.
    #[allow(clippy::approx_constant)]
    let sin_r =
        r * (1.570_796_2 + r2 * (-0.645_962_94 + r2 * (0.079_675_9 + r2 * -0.004_592_288_8)));
    let cos_r = 1.0 + r2 * (-1.233_698 + r2 * (0.253_606_36 + r2 * -0.020_426_25));
    // Quadrant q rotates by qπ/2: odd q swaps sin and cos; sin is negated in quadrants 2, 3
    // and cos in quadrants 1, 2 — sign bits set by integer xor instead of branches.
    let (a, b) = if q & 1 == 0 {
        (sin_r, cos_r)
    } else {
        (cos_r, sin_r)
    };
    let sin_sign = ((q & 2) as u32) << 30;
    let cos_sign = (((q + 1) & 2) as u32) << 30;
    (
        f32::from_bits(a.to_bits() ^ sin_sign),
        f32::from_bits(b.to_bits() ^ cos_sign),
    )
}

/// `(sin x, cos x)` in f64 for 0 ≤ x ≤ 8 only (the caller guarantees the range; outside it
/// the result is inaccurate, never UB): [`super::f64_lanes::sin_cos_0_8`] at one lane (the
/// algorithm and its constants live there, written once for one lane or four). Error vs
/// libm is tested (≤ 2 ulp).
#[inline(always)]
pub fn sin_cos_0_8_f64(x: f64) -> (f64, f64) {
    super::f64_lanes::sin_cos_0_8(x)
}

/// `atan2(y, x)` in f64 (angle of (x, y) in [−π, π]) from plain arithmetic and selects:
/// [`super::f64_lanes::atan2`] at one lane (the algorithm and its constants live there).
/// Within 2 ulp of libm over the whole domain (zeros, subnormals, huge and infinite values,
/// both signs; tested); NaN in, NaN out.
#[inline(always)]
pub fn atan2_f64(y: f64, x: f64) -> f64 {
    super::f64_lanes::atan2(y, x)
}

/// [`spherical_direction`] with the azimuth given in turns (φ = 2πt, t ∈ [0, 1]), via
/// [`sin_cos_turn`]: what every warp with φ = 2πξ calls.
#[inline]
fn spherical_direction_turn(cos_theta: f32, t: f32) -> Vec3 {
    let sin_theta = safe_sqrt((1.0 - cos_theta) * (1.0 + cos_theta));
    let (sp, cp) = sin_cos_turn(t);
    Vec3::new(sin_theta * cp, sin_theta * sp, cos_theta)
}

/// [`direction_from_one_minus_cos`] with the azimuth in turns (φ = 2πt, t ∈ [0, 1]).
#[inline]
fn direction_from_one_minus_cos_turn(t_cos: f32, t: f32) -> Vec3 {
    let t_cos = t_cos.clamp(0.0, 2.0);
    let sin_theta = safe_sqrt(t_cos * (2.0 - t_cos));
    let (sp, cp) = sin_cos_turn(t);
    Vec3::new(sin_theta * cp, sin_theta * sp, 1.0 - t_cos)
}

/// Azimuth of a direction in [0, 2π).
#[inline]
fn azimuth(d: Vec3) -> f32 {
    let p = d.y.atan2(d.x);
    // p + 2π can round up to 2π for tiny negative p; wrap so that φ/2π stays in [0, 1).
    let p = if p < 0.0 { p + TAU } else { p };
    if p >= TAU { 0.0 } else { p }
}

/// The resolution of the samplers' inputs: the patterns and the test harness draw ξ on the
/// grid k·2⁻²⁴, k < 2²⁴.
pub const XI_MIN: f32 = 1.0 / (1u32 << 24) as f32;

/// ξ ∈ [0, 1) clamped to [2⁻²⁴, 1) for the warps that map ξ = 0 to the edge of their
/// support — the horizon (cos θ = 0), the rim of the tent — where the pdf is 0: ξ = 0 (and the
/// finer values some patterns give below 2⁻²⁴) becomes 2⁻²⁴, the next point of the 24-bit
/// grid, in the same stratum (a bias below 2⁻²⁴ of the mass). Every other input is returned as
/// is, so the samples of every ξ ≥ 2⁻²⁴ are bit-identical to the plain map's.
#[inline(always)]
pub fn open_unit(xi: f32) -> f32 {
    xi.max(XI_MIN)
}

/// Uniform hemisphere: cos θ = ξ₁, φ = 2πξ₂ (marginal of θ is sin θ, conditional of φ uniform),
/// with ξ₁ ≥ 2⁻²⁴ ([`open_unit`]), so no sample lies on the horizon.
#[inline]
pub fn uniform_hemisphere(u: Vec2) -> Vec3 {
    spherical_direction_turn(open_unit(u.x), u.y)
}

/// Pdf of [`uniform_hemisphere`]: 1/(2π) on z ≥ 0.
#[inline]
pub fn uniform_hemisphere_pdf(d: Vec3) -> f32 {
    if d.z >= 0.0 { 0.5 * FRAC_1_PI } else { 0.0 }
}

/// Inverse of [`uniform_hemisphere`].
#[inline]
pub fn uniform_hemisphere_inverse(d: Vec3) -> Vec2 {
    Vec2::new(d.z, azimuth(d) / TAU)
}

/// Cosine-weighted hemisphere: cos θ = √ξ₁, φ = 2πξ₂ (Malley's method by inversion), with
/// ξ₁ ≥ 2⁻²⁴ ([`open_unit`]), so cos θ ≥ 2⁻¹²: no sample lies on the horizon, where the pdf
/// is 0.
#[inline]
pub fn cosine_hemisphere(u: Vec2) -> Vec3 {
    spherical_direction_turn(open_unit(u.x).sqrt(), u.y)
}

/// Pdf of [`cosine_hemisphere`]: cos θ / π on z ≥ 0.
#[inline]
pub fn cosine_hemisphere_pdf(d: Vec3) -> f32 {
    d.z.max(0.0) * FRAC_1_PI
}

/// Inverse of [`cosine_hemisphere`].
#[inline]
pub fn cosine_hemisphere_inverse(d: Vec3) -> Vec2 {
    Vec2::new(d.z * d.z, azimuth(d) / TAU)
}

/// Cosine-power (Phong lobe) hemisphere, pdf ∝ cosⁿθ: the marginal cdf of θ is
/// 1 − cos^(n+1)θ, so cos θ = ξ₁^(1/(n+1)); φ = 2πξ₂.
///
/// ξ₁ ≥ 2⁻²⁴ ([`open_unit`]) keeps ln ξ₁ ≥ −16.7, so cos θ ≥ 2^(−24/(n+1)) > 0. With
/// ξ₁ = 0 itself, ln 0 = −∞ gave a direction exactly on the horizon with pdf 0 (issue 16:
/// `penumbra warp cosine-power -p n=100` with seed 5 and 10⁶ samples rejected its own
/// chi-square test).
#[inline]
pub fn cosine_power_hemisphere(u: Vec2, n: f32) -> Vec3 {
    // 1 − cos θ = −expm1(ln ξ₁ / (n+1)) stays accurate for very sharp lobes, where
    // ξ₁^(1/(n+1)) rounds to 1 in f32.
    let one_minus_cos = -(open_unit(u.x).ln() / (n + 1.0)).exp_m1();
    direction_from_one_minus_cos_turn(one_minus_cos, u.y)
}

/// Direction with 1 − cos θ = `t` around +z and azimuth `phi`, accurate for tiny θ.
#[inline]
pub fn direction_from_one_minus_cos(t: f32, phi: f32) -> Vec3 {
    let t = t.clamp(0.0, 2.0);
    let sin_theta = safe_sqrt(t * (2.0 - t));
    let (sp, cp) = phi.sin_cos();
    Vec3::new(sin_theta * cp, sin_theta * sp, 1.0 - t)
}

/// Pdf of [`cosine_power_hemisphere`]: (n+1)/(2π)·cosⁿθ on z ≥ 0.
#[inline]
pub fn cosine_power_hemisphere_pdf(d: Vec3, n: f32) -> f32 {
    if d.z <= 0.0 {
        return 0.0;
    }
    (n + 1.0) * 0.5 * FRAC_1_PI * d.z.powf(n)
}

/// Inverse of [`cosine_power_hemisphere`].
#[inline]
pub fn cosine_power_hemisphere_inverse(d: Vec3, n: f32) -> Vec2 {
    // ξ₁ = cos^(n+1) θ = exp((n+1)·ln(1 − t)) with t = 1 − cos θ computed without cancellation.
    let t = one_minus_cos_of(d).clamp(0.0, 1.0);
    Vec2::new(((n + 1.0) * (-t).ln_1p()).exp(), azimuth(d) / TAU)
}

/// Uniform sphere: cos θ = 1 − 2ξ₁, φ = 2πξ₂.
#[inline]
pub fn uniform_sphere(u: Vec2) -> Vec3 {
    spherical_direction_turn(1.0 - 2.0 * u.x, u.y)
}

/// Pdf of [`uniform_sphere`]: 1/(4π).
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    0.25 * FRAC_1_PI
}

/// Inverse of [`uniform_sphere`].
#[inline]
pub fn uniform_sphere_inverse(d: Vec3) -> Vec2 {
    Vec2::new((1.0 - d.z) * 0.5, azimuth(d) / TAU)
}

/// Shirley–Chiu concentric map of the unit square to the unit disk (area preserving,
/// low distortion, so stratification survives the warp).
#[inline]
pub fn concentric_disk(u: Vec2) -> Vec2 {
    let o = 2.0 * u - Vec2::ONE;
    if o.x == 0.0 && o.y == 0.0 {
        return Vec2::ZERO;
    }
    let (r, theta) = if o.x.abs() > o.y.abs() {
        (o.x, FRAC_PI_4 * (o.y / o.x))
    } else {
        (o.y, FRAC_PI_2 - FRAC_PI_4 * (o.x / o.y))
    };
    let (s, c) = theta.sin_cos();
    Vec2::new(r * c, r * s)
}

/// Pdf of [`concentric_disk`] per unit area: 1/π inside the unit disk.
#[inline]
pub fn concentric_disk_pdf(p: Vec2) -> f32 {
    if p.length_squared() <= 1.0 {
        FRAC_1_PI
    } else {
        0.0
    }
}

/// Inverse of [`concentric_disk`].
pub fn concentric_disk_inverse(p: Vec2) -> Vec2 {
    let r = p.length();
    if r == 0.0 {
        return Vec2::splat(0.5);
    }
    let mut theta = p.y.atan2(p.x);
    if theta < -FRAC_PI_4 {
        theta += TAU;
    }
    // The four wedges of the square map to the four quarter-sectors of the disk.
    let (a, b) = if theta < FRAC_PI_4 {
        (r, r * theta / FRAC_PI_4)
    } else if theta < 3.0 * FRAC_PI_4 {
        (-r * (theta - FRAC_PI_2) / FRAC_PI_4, r)
    } else if theta < 5.0 * FRAC_PI_4 {
        (-r, -r * (theta - PI) / FRAC_PI_4)
    } else {
        (r * (theta - 3.0 * FRAC_PI_2) / FRAC_PI_4, -r)
    };
    (Vec2::new(a, b) + Vec2::ONE) * 0.5
}

/// Uniform barycentrics (b0, b1) on a triangle; b2 = 1 − b0 − b1. Uses the square-root
/// parametrisation: b0 = 1 − √ξ₁, b1 = ξ₂√ξ₁ (marginal + conditional inversion of the area).
#[inline]
pub fn uniform_triangle(u: Vec2) -> Vec2 {
    let su = u.x.sqrt();
    Vec2::new(1.0 - su, u.y * su)
}

/// Inverse of [`uniform_triangle`].
#[inline]
pub fn uniform_triangle_inverse(b: Vec2) -> Vec2 {
    let su = 1.0 - b.x;
    let v = if su > 0.0 { b.y / su } else { 0.5 };
    Vec2::new(su * su, v)
}

/// Point uniformly distributed by area on triangle (p0, p1, p2); pdf = 1/area.
#[inline]
pub fn uniform_triangle_point(u: Vec2, p0: Vec3, p1: Vec3, p2: Vec3) -> Vec3 {
    let b = uniform_triangle(u);
    p0 * b.x + p1 * b.y + p2 * (1.0 - b.x - b.y)
}

/// Uniform in the solid angle of a cone around +z with cos of half-angle `cos_max`:
/// cos θ = 1 − ξ₁(1 − cos θmax), φ = 2πξ₂.
#[inline]
pub fn uniform_cone(u: Vec2, cos_max: f32) -> Vec3 {
    direction_from_one_minus_cos_turn(u.x * (1.0 - cos_max), u.y)
}

/// Pdf of [`uniform_cone`]: 1/(2π(1 − cos θmax)) inside the cone.
#[inline]
pub fn uniform_cone_pdf(d: Vec3, cos_max: f32) -> f32 {
    if d.z >= cos_max {
        1.0 / (TAU * (1.0 - cos_max))
    } else {
        0.0
    }
}

/// Inverse of [`uniform_cone`].
#[inline]
pub fn uniform_cone_inverse(d: Vec3, cos_max: f32) -> Vec2 {
    Vec2::new(one_minus_cos_of(d) / (1.0 - cos_max), azimuth(d) / TAU)
}

/// 1 − cos θ of a unit direction, accurate near +z (where 1 − z cancels).
#[inline]
pub fn one_minus_cos_of(d: Vec3) -> f32 {
    if d.z > 0.5 {
        (d.x * d.x + d.y * d.y) / (1.0 + d.z)
    } else {
        1.0 - d.z
    }
}

/// 1 − cos θmax of a cone with sin²θmax = `sin2_max` (θmax ≤ 90°), without cancellation:
/// for a sphere light of radius r at distance d, sin²θmax = r²/d².
#[inline]
pub fn cone_one_minus_cos(sin2_max: f32) -> f32 {
    let s2 = sin2_max.clamp(0.0, 1.0);
    s2 / (1.0 + safe_sqrt(1.0 - s2))
}

/// Uniform in a cone around +z given sin²θmax (θmax ≤ 90°); the accurate form of
/// [`uniform_cone`] for the tiny cones of distant sphere lights.
#[inline]
pub fn uniform_cone_sin2(u: Vec2, sin2_max: f32) -> Vec3 {
    direction_from_one_minus_cos_turn(u.x * cone_one_minus_cos(sin2_max), u.y)
}

/// Angular slack (radians) of the inside tests of direction pdfs: 4 ulp of 1, about the
/// rounding of an f32 unit vector that went through a frame and a normalisation. Without it a
/// sample drawn on the rim of its support (ξ = 1 − 2⁻²⁴) can round to just outside and get
/// pdf 0 from the very pdf that drew it.
pub const DIRECTION_SLACK: f32 = 4.0 * f32::EPSILON;

/// Pdf of [`uniform_cone_sin2`]: 1/(2π(1 − cos θmax)) inside the cone (widened by
/// [`DIRECTION_SLACK`], so that rim samples rounded outside keep their density).
#[inline]
pub fn uniform_cone_sin2_pdf(d: Vec3, sin2_max: f32) -> f32 {
    let sin_slack = sin2_max.max(0.0).sqrt() + DIRECTION_SLACK;
    let inside = d.z > 0.0 && d.x * d.x + d.y * d.y <= sin_slack * sin_slack * d.length_squared();
    if inside {
        1.0 / (TAU * cone_one_minus_cos(sin2_max))
    } else {
        0.0
    }
}

/// Inverse of [`uniform_cone_sin2`].
#[inline]
pub fn uniform_cone_sin2_inverse(d: Vec3, sin2_max: f32) -> Vec2 {
    Vec2::new(
        one_minus_cos_of(d) / cone_one_minus_cos(sin2_max),
        azimuth(d) / TAU,
    )
}

/// Power heuristic with β = 2 (Veach): weight of a sample drawn with `nf` samples of pdf `f_pdf`
/// against `ng` samples of pdf `g_pdf`.
#[inline]
pub fn power_heuristic(nf: f32, f_pdf: f32, ng: f32, g_pdf: f32) -> f32 {
    let f = nf * f_pdf;
    let g = ng * g_pdf;
    if f.is_infinite() {
        return 1.0;
    }
    let (f2, g2) = (f * f, g * g);
    if f2 + g2 == 0.0 { 0.0 } else { f2 / (f2 + g2) }
}

/// Balance heuristic (Veach).
#[inline]
pub fn balance_heuristic(nf: f32, f_pdf: f32, ng: f32, g_pdf: f32) -> f32 {
    let f = nf * f_pdf;
    let g = ng * g_pdf;
    if f.is_infinite() {
        return 1.0;
    }
    if f + g == 0.0 { 0.0 } else { f / (f + g) }
}

/// 1D tent (triangle filter) of radius r centred at 0, by inverting its cdf on each half:
/// pdf(x) = (r − |x|)/r². The left half's w = 2u is clamped to ≥ 2⁻²⁴ ([`open_unit`]), so
/// u = 0 lands at −r(1 − 2⁻¹²) instead of on the rim −r, where the pdf is 0 (the right half
/// never reaches r).
#[inline(always)]
pub fn tent(u: f32, r: f32) -> f32 {
    // Both halves as one computation with selects instead of a branch: the pixel filter draws
    // u uniformly, so a branch on u < 0.5 mispredicts half the time. Same values bit for bit:
    // w is 2u (left) or 1 − (2u − 1) (right), and −r·x = −(r·x) exactly.
    let left = u < 0.5;
    let w = if left {
        open_unit(2.0 * u)
    } else {
        1.0 - (2.0 * u - 1.0)
    };
    let m = r * (1.0 - w.sqrt());
    if left { -m } else { m }
}

/// Pdf of [`tent`].
#[inline]
pub fn tent_pdf(x: f32, r: f32) -> f32 {
    if x.abs() >= r {
        0.0
    } else {
        (r - x.abs()) / (r * r)
    }
}

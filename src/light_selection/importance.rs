//! Conservative importance of a bounded group of lights for a receiver (Conty Estevez & Kulla
//! 2018, as refined in pbrt-v4's `LightBounds::Importance`): Φ · cos θ′ / d², times cos θ′ᵢ
//! when the receiver's normal is known.
//!
//! θ′ widens the angle between the emission axis and the receiver by the cone of normals θo and
//! by the angle θb the bounds subtend, so the result is zero only where no light in the group
//! can send any light to the receiver. That zero test is what every strategy relies on for
//! unbiasedness; the magnitude is a heuristic.

use crate::lights::LightBounds;
use glam::Vec3;

/// Importances are clamped here so a receiver on top of a point light cannot make a pmf NaN.
const MAX_IMPORTANCE: f32 = 1e30;

/// cos(a − b) for angles given by (sin, cos), clamped to 1 when a < b (θ′ = max(0, a − b)).
#[inline]
fn cos_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        1.0
    } else {
        cos_a * cos_b + sin_a * sin_b
    }
}

/// sin(a − b), clamped to 0 when a < b.
#[inline]
fn sin_sub_clamped(sin_a: f32, cos_a: f32, sin_b: f32, cos_b: f32) -> f32 {
    if cos_a > cos_b {
        0.0
    } else {
        sin_a * cos_b - cos_a * sin_b
    }
}

#[inline]
fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

/// Importance of the lights in `b` for any receiver inside the sphere (`center`, `radius`)
/// (radius 0: a point). `n` is the receiver's geometric normal on the viewer's side, or zero
/// when unknown. Reflection only: lights entirely below the receiver's tangent plane get 0,
/// matching the integrator, which only gathers light from above the geometric surface.
pub fn importance_sphere(center: Vec3, radius: f32, n: Vec3, b: &LightBounds) -> f32 {
    if b.phi.is_nan() || b.phi <= 0.0 {
        return 0.0;
    }
    let pc = (b.min + b.max) * 0.5;
    let rl = (b.max - b.min).length() * 0.5;
    let to_p = center - pc;
    let d = to_p.length();
    // Distance from the receiver region to the light's centre, floored so nearby lights do not
    // get unbounded weight. The floor is pbrt-v4's half diagonal (a length compared with a
    // squared length: deliberately weak, since flooring by its square makes every large node
    // that contains the receiver look equally far away), and a quarter of the region's size.
    let d_eff = (d - radius).max(0.0);
    let d2 = (d_eff * d_eff)
        .max(rl)
        .max(0.25 * radius * radius)
        .max(1e-12);
    // Angle subtended by the light's bounding sphere as seen from anywhere in the region.
    let r_sum = rl + radius;
    let (sin_b, cos_b) = if d <= r_sum || d == 0.0 {
        (0.0, -1.0)
    } else {
        let s = r_sum / d;
        (s, safe_sqrt(1.0 - s * s))
    };
    let wi = if d > 0.0 { to_p / d } else { Vec3::Z };
    let mut cos_w = b.w.dot(wi);
    if b.two_sided {
        cos_w = cos_w.abs();
    }
    let sin_w = safe_sqrt(1.0 - cos_w * cos_w);
    let cos_o = b.cos_theta_o.clamp(-1.0, 1.0);
    let sin_o = safe_sqrt(1.0 - cos_o * cos_o);
    let cos_x = cos_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    let sin_x = sin_sub_clamped(sin_w, cos_w, sin_o, cos_o);
    let cos_p = cos_sub_clamped(sin_x, cos_x, sin_b, cos_b);
    if cos_p <= b.cos_theta_e {
        return 0.0;
    }
    let mut imp = b.phi * cos_p / d2;
    if n != Vec3::ZERO && cos_b > -1.0 {
        // Angle between the normal and the direction to the light, narrowed by θb: zero only
        // if every direction toward the bounds is below the tangent plane.
        let cos_i = n.dot(-wi).clamp(-1.0, 1.0);
        let sin_i = safe_sqrt(1.0 - cos_i * cos_i);
        let cos_pi = cos_sub_clamped(sin_i, cos_i, sin_b, cos_b);
        if cos_pi <= 0.0 {
            return 0.0;
        }
        imp *= cos_pi;
    }
    if imp.is_nan() {
        return 0.0;
    }
    imp.min(MAX_IMPORTANCE)
}

/// Importance of the lights in `b` for a receiver at `p` with normal `n` (zero if unknown).
#[inline]
pub fn importance(p: Vec3, n: Vec3, b: &LightBounds) -> f32 {
    importance_sphere(p, 0.0, n, b)
}

/// The union of two light bounds: box union, a cone containing both cones, summed power.
pub fn union(a: &LightBounds, b: &LightBounds) -> LightBounds {
    union_with_angles(a, (0.0, 0.0), b, (0.0, 0.0), false).0
}

/// The half angle θ = acos(cos) of a cone as [`cone_union`] measures it (cos clamped to [−1, 1]).
#[inline]
pub fn cone_angle(cos: f32) -> f32 {
    cos.clamp(-1.0, 1.0).acos()
}

/// [`union`] for bounds whose angles (θo, θe) = ([`cone_angle`] of cos θo, of cos θe) are
/// already known, returning the union's angles too: the same bounds bit for bit, with the
/// arc cosines a build would otherwise take again at every later union and cost.
#[inline]
pub fn union_angles(
    a: &LightBounds,
    ta: (f32, f32),
    b: &LightBounds,
    tb: (f32, f32),
) -> (LightBounds, (f32, f32)) {
    union_with_angles(a, ta, b, tb, true)
}

/// `union`'s one body: with `known`, `ta`/`tb` are the inputs' angles and the result's are
/// returned; without, the angles are computed where needed and the returned ones are zero.
#[inline(always)]
fn union_with_angles(
    a: &LightBounds,
    ta: (f32, f32),
    b: &LightBounds,
    tb: (f32, f32),
    known: bool,
) -> (LightBounds, (f32, f32)) {
    if a.phi.is_nan() || a.phi <= 0.0 {
        return (*b, tb);
    }
    if b.phi.is_nan() || b.phi <= 0.0 {
        return (*a, ta);
    }
    let (w, cos_o, theta_o) = if a.w == b.w {
        // Same axis (e.g. every light facing down): no trigonometry needed.
        let c = a.cos_theta_o.min(b.cos_theta_o);
        (a.w, c, pick_angle(c, a.cos_theta_o, ta.0, tb.0))
    } else {
        let (theta_a, theta_b) = if known {
            (ta.0, tb.0)
        } else {
            (cone_angle(a.cos_theta_o), cone_angle(b.cos_theta_o))
        };
        match cone_union_angles(a.w, a.cos_theta_o, theta_a, b.w, theta_b) {
            Cone::A => (a.w, a.cos_theta_o, ta.0),
            Cone::B => (b.w, b.cos_theta_o, tb.0),
            Cone::Whole => (a.w, -1.0, if known { cone_angle(-1.0) } else { 0.0 }),
            Cone::New(w, c) => (w, c, if known { cone_angle(c) } else { 0.0 }),
        }
    };
    let cos_e = a.cos_theta_e.min(b.cos_theta_e);
    (
        LightBounds {
            min: a.min.min(b.min),
            max: a.max.max(b.max),
            w,
            phi: a.phi + b.phi,
            cos_theta_o: cos_o,
            cos_theta_e: cos_e,
            two_sided: a.two_sided || b.two_sided,
        },
        (theta_o, pick_angle(cos_e, a.cos_theta_e, ta.1, tb.1)),
    )
}

/// The angle of `c` = `ca.min(cb)`: `ca`'s where `min` returned `ca`, else `cb`'s.
#[inline(always)]
fn pick_angle(c: f32, ca: f32, ta: f32, tb: f32) -> f32 {
    if c.to_bits() == ca.to_bits() { ta } else { tb }
}

/// What [`cone_union`] returns for two different axes.
enum Cone {
    /// The first cone contains the second.
    A,
    /// The second contains the first.
    B,
    /// Every direction (cos = −1, axis: the first's).
    Whole,
    /// A new axis and cos of its half angle.
    New(Vec3, f32),
}

/// [`cone_union`]'s case analysis for axes `wa` ≠ `wb` with half angles θa (cos θa = `cos_a`)
/// and θb.
#[inline(always)]
fn cone_union_angles(wa: Vec3, cos_a: f32, theta_a: f32, wb: Vec3, theta_b: f32) -> Cone {
    let cos_d = wa.dot(wb).clamp(-1.0, 1.0);
    // A single direction (one planar emitter, θb = 0) inside the first cone: glibc's acosf
    // is non-increasing (checked on every f32 in [−1, 1]), so cos θd ≥ cos θa gives θd ≤ θa
    // and the first test below passes, as it must (the direction is in the cone). The common
    // case of a build adding one light to a group, without an arc cosine.
    if theta_b == 0.0 && cos_d >= cos_a.clamp(-1.0, 1.0) {
        return Cone::A;
    }
    let theta_d = cos_d.acos();
    if (theta_d + theta_b).min(std::f32::consts::PI) <= theta_a {
        return Cone::A;
    }
    if (theta_d + theta_a).min(std::f32::consts::PI) <= theta_b {
        return Cone::B;
    }
    let theta_o = (theta_a + theta_d + theta_b) * 0.5;
    if theta_o >= std::f32::consts::PI {
        return Cone::Whole;
    }
    let theta_r = theta_o - theta_a;
    let axis = wa.cross(wb);
    if axis.length_squared() < 1e-12 {
        return Cone::Whole;
    }
    let w = glam::Quat::from_axis_angle(axis.normalize(), theta_r) * wa;
    // A little slack so f32 rounding of the rotation cannot leave a normal outside the cone.
    Cone::New(
        w.normalize(),
        (theta_o + 1e-4).min(std::f32::consts::PI).cos(),
    )
}

/// The smallest cone (axis, cos of half angle) around two cones (pbrt-v4 `Union(DirectionCone)`).
pub fn cone_union(wa: Vec3, cos_a: f32, wb: Vec3, cos_b: f32) -> (Vec3, f32) {
    // Same axis (e.g. every light facing down): no trigonometry needed.
    if wa == wb {
        return (wa, cos_a.min(cos_b));
    }
    match cone_union_angles(wa, cos_a, cone_angle(cos_a), wb, cone_angle(cos_b)) {
        Cone::A => (wa, cos_a),
        Cone::B => (wb, cos_b),
        Cone::Whole => (wa, -1.0),
        Cone::New(w, c) => (w, c),
    }
}

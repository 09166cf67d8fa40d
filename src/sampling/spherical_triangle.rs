//! Uniform sampling of the solid angle subtended by a triangle (Arvo 1995).
//!
//! Arvo's method is an inversion: ξ₁ picks the sub-triangle (A, B, Ĉ) of area ξ₁·Ω, which fixes
//! the vertex Ĉ on arc AC; ξ₂ then picks the point on arc BĈ with the right conditional density
//! (uniform in 1 − cos of the arc length from B). All the trigonometry runs in f64, because for
//! small triangles it cancels catastrophically in f32.
//!
//! Branch-free throughout (validity flags and selects, libm-free trigonometry), and written once
//! over [`Real`]: at `f64` it is the one-lane sampler, at [`super::f64_lanes::F64x4`] the
//! triangle-light lane kernel's, which draws four lanes per AVX2 register with the same bits
//! ([`SolidAngleDraw::lanes4`]; callgrind of cornell 128² 16 spp path: the kernel 633.6 M →
//! 377.6 M Ir, docs/path-tracing.md).

use super::f64_lanes::{R3, Real, atan2, sin_cos_0_8};
use super::warps::DIRECTION_SLACK;
use glam::{DVec3, Vec2, Vec3};

/// A triangle (a, b, c) seen from point `p`, precomputed for solid-angle sampling.
#[derive(Clone, Copy, Debug)]
pub struct SphericalTriangle {
    /// Unit vectors from the viewpoint to the three vertices.
    pub a: Vec3,
    /// Second vertex direction.
    pub b: Vec3,
    /// Third vertex direction.
    pub c: Vec3,
    /// Solid angle (sr).
    pub area: f32,
    /// The same vertices in f64.
    da: DVec3,
    db: DVec3,
    dc: DVec3,
    /// Solid angle in f64.
    area64: f64,
    /// What [`Self::sample`] needs.
    arvo: Arvo<f64>,
    /// +1 or −1: orientation of (a, b, c), for the inside test.
    orientation: f64,
}

/// Solid angle of the spherical triangle of unit vectors (Van Oosterom & Strackee 1983);
/// accurate for tiny triangles, unlike the angle excess α + β + γ − π.
/// The atan2 is [`atan2`] (arithmetic and selects, no libm call).
#[inline(always)]
fn solid_angle<R: Real>(a: R3<R>, b: R3<R>, c: R3<R>) -> R {
    let num = a.dot(b.cross(c)).abs();
    let den = num.lit(1.0) + a.dot(b) + b.dot(c) + c.dot(a);
    num.lit(2.0) * atan2(num, den)
}

/// `v` normalised, and whether that is possible: `DVec3::try_normalize`'s arithmetic (the same
/// bits) with a flag instead of an `Option`, so callers combine flags by select rather than
/// branch on each (lanes take different branches).
#[inline(always)]
fn unit<R: Real>(v: R3<R>) -> (R3<R>, R::Mask) {
    let rcp = v.length_recip();
    (v.scale(rcp), rcp.is_finite() & rcp.gt(rcp.lit(0.0)))
}

/// Unit tangent at `a` of the great-circle arc towards `b`; the flag is false if b = ±a.
#[inline(always)]
fn tangent<R: Real>(a: R3<R>, b: R3<R>) -> (R3<R>, R::Mask) {
    unit(b - a.scale(a.dot(b)))
}

/// The unit directions from a viewpoint to a triangle's vertices and its solid angle, for one
/// lane or several.
#[derive(Clone, Copy, Debug)]
struct Projection<R> {
    da: R3<R>,
    db: R3<R>,
    dc: R3<R>,
    area64: R,
}

impl<R: Real> Projection<R> {
    /// Unit directions from `p` to (v0, v1, v2) and the solid angle; the flag is false where
    /// a vertex coincides with `p`. Everything is computed and the flags combined at the end
    /// (no early return), so lanes run it together, whichever of them fail.
    #[inline(always)]
    fn new(p: R3<R>, v0: R3<R>, v1: R3<R>, v2: R3<R>) -> (Self, R::Mask) {
        let (da, ok_a) = unit(v0 - p);
        let (db, ok_b) = unit(v1 - p);
        let (dc, ok_c) = unit(v2 - p);
        let proj = Self {
            da,
            db,
            dc,
            area64: solid_angle(da, db, dc),
        };
        (proj, ok_a & ok_b & ok_c)
    }

    /// The sampler's state; the flag is false where the triangle is too small or degenerate
    /// to sample.
    #[inline(always)]
    fn arvo(&self) -> (Arvo<R>, R::Mask) {
        let Self { da, db, dc, area64 } = *self;
        let big = area64.ge(area64.lit(SphericalTriangle::MIN_SOLID_ANGLE)) & area64.is_finite();
        let ((t_ab, ok_ab), (t_ac, ok_ac)) = (tangent(da, db), tangent(da, dc));
        // α = angle between the two unit tangents: its cosine and sine directly.
        let (cos_alpha, sin_alpha) = (t_ab.dot(t_ac), t_ab.cross(t_ac).length());
        let arvo = Arvo {
            a: da,
            b: db,
            area64,
            cos_alpha,
            sin_alpha,
            c_perp: t_ac,
        };
        (arvo, big & ok_ab & ok_ac)
    }
}

/// The first, cheap half of [`SphericalTriangle::new`]: the vertex directions and the solid
/// angle. A light decides from the solid angle whether to sample by solid angle at all, then
/// finishes the same projection with [`SphericalProjection::sampler`] instead of normalising
/// and measuring the triangle a second time.
#[derive(Clone, Copy, Debug)]
pub struct SphericalProjection(Projection<f64>);

impl SphericalProjection {
    /// Unit directions from `p` to (v0, v1, v2); `None` if a vertex coincides with `p`.
    #[inline(always)]
    pub fn new(p: Vec3, v0: Vec3, v1: Vec3, v2: Vec3) -> Option<Self> {
        let (proj, ok) = Projection::new(p.into(), v0.into(), v1.into(), v2.into());
        ok.then_some(Self(proj))
    }

    /// Solid angle (sr), f64.
    #[inline(always)]
    pub fn solid_angle(&self) -> f64 {
        self.0.area64
    }

    /// One direction drawn as [`SphericalTriangle::sample`] draws it, without building the
    /// whole sampler (the hot path of triangle lights: one sample per projection).
    #[inline(always)]
    pub fn sample(&self, u: Vec2) -> Option<Vec3> {
        let (arvo, ok) = self.0.arvo();
        ok.then(|| DVec3::from(arvo.sample(u.x as f64, u.y as f64)).as_vec3())
    }

    /// The sampler of this triangle; `None` if it is too small or degenerate to sample.
    #[inline]
    pub fn sampler(self) -> Option<SphericalTriangle> {
        let (arvo, ok) = self.0.arvo();
        if !ok {
            return None;
        }
        let Projection { da, db, dc, area64 } = self.0;
        let (da, db, dc) = (DVec3::from(da), DVec3::from(db), DVec3::from(dc));
        let triple = da.dot(db.cross(dc));
        Some(SphericalTriangle {
            a: da.as_vec3(),
            b: db.as_vec3(),
            c: dc.as_vec3(),
            area: area64 as f32,
            da,
            db,
            dc,
            area64,
            arvo,
            orientation: if triple >= 0.0 { 1.0 } else { -1.0 },
        })
    }
}

/// The f64 half of one solid-angle sample of a triangle from a point: the solid angle Ω
/// (`None` where a vertex coincides with the point) and the drawn direction (`None` where
/// the triangle is too small or degenerate to sample). What [`SphericalProjection::new`] and
/// [`SphericalProjection::sample`] give, drawn by [`SolidAngleDraw::new`] one lane at a time
/// or by [`SolidAngleDraw::lanes4`] four lanes per register, with the same bits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolidAngleDraw {
    /// Ω (sr) rounded to f32.
    pub omega: Option<f32>,
    /// The unit direction drawn uniformly in the triangle's solid angle.
    pub wi: Option<Vec3>,
}

/// [`SolidAngleDraw`] for one lane or several, before it is split into lanes.
#[derive(Clone, Copy, Debug)]
struct Draw<R: Real> {
    omega: R,
    omega_ok: R::Mask,
    wi: R3<R>,
    wi_ok: R::Mask,
}

impl<R: Real> Draw<R> {
    /// Project triangle (v0, v1, v2) around `p` and draw direction (ux, uy) in it.
    #[inline(always)]
    fn new(p: R3<R>, v: [R3<R>; 3], ux: R, uy: R) -> Self {
        let (proj, omega_ok) = Projection::new(p, v[0], v[1], v[2]);
        let (arvo, ok) = proj.arvo();
        Draw {
            omega: proj.area64,
            omega_ok,
            wi: arvo.sample(ux, uy),
            wi_ok: omega_ok & ok,
        }
    }
}

impl SolidAngleDraw {
    /// Neither a solid angle nor a direction.
    pub const NONE: SolidAngleDraw = SolidAngleDraw {
        omega: None,
        wi: None,
    };

    /// Triangle (v0, v1, v2) seen from `p`, direction drawn with `u`.
    #[inline(always)]
    pub fn new(p: Vec3, v: [Vec3; 3], u: Vec2) -> Self {
        let v = [v[0].into(), v[1].into(), v[2].into()];
        let d = Draw::new(p.into(), v, u.x as f64, u.y as f64);
        SolidAngleDraw {
            omega: d.omega_ok.then_some(d.omega as f32),
            wi: d.wi_ok.then(|| DVec3::from(d.wi).as_vec3()),
        }
    }

    /// [`Self::new`] of four lanes at once, on AVX2: lane i has point `(p[0][i], p[1][i],
    /// p[2][i])`, vertices `v[j]` likewise and draw `(u[0][i], u[1][i])`.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub fn lanes4(
        t: crate::isa::Avx2,
        p: [&[f32; 4]; 3],
        v: [[&[f32; 4]; 3]; 3],
        u: [&[f32; 4]; 2],
    ) -> [Self; 4] {
        use super::f64_lanes::F64x4;
        let wide = |c: [&[f32; 4]; 3]| R3 {
            x: F64x4::from_f32(t, c[0]),
            y: F64x4::from_f32(t, c[1]),
            z: F64x4::from_f32(t, c[2]),
        };
        let (ux, uy) = (F64x4::from_f32(t, u[0]), F64x4::from_f32(t, u[1]));
        // Written out, not `array::map`: that is a call, outside the AVX2 code.
        let d = Draw::new(wide(p), [wide(v[0]), wide(v[1]), wide(v[2])], ux, uy);
        let omega = d.omega.to_f32();
        let (x, y, z) = (d.wi.x.to_f32(), d.wi.y.to_f32(), d.wi.z.to_f32());
        let (omega_ok, wi_ok) = (d.omega_ok.bits(), d.wi_ok.bits());
        std::array::from_fn(|i| SolidAngleDraw {
            omega: (omega_ok >> i & 1 != 0).then_some(omega[i]),
            wi: (wi_ok >> i & 1 != 0).then_some(Vec3::new(x[i], y[i], z[i])),
        })
    }
}

/// The state of Arvo's inversion for one triangle (or one per lane).
#[derive(Clone, Copy, Debug)]
struct Arvo<R> {
    /// Vertex directions A and B.
    a: R3<R>,
    b: R3<R>,
    /// Solid angle.
    area64: R,
    /// cos and sin of the interior angle α at A (Arvo needs only these and sin(ξ₁Ω − α),
    /// which the angle-difference identity gives without an atan2 and a second sincos).
    cos_alpha: R,
    sin_alpha: R,
    /// Unit tangent at A of the arc AC (where the sub-triangle's far vertex Ĉ moves).
    c_perp: R3<R>,
}

impl<R: Real> Arvo<R> {
    /// Unit direction uniformly distributed in the spherical triangle for the draw (ux, uy)
    /// (f32 values widened). Branch-free (selects only), so lanes sample together.
    #[inline(always)]
    fn sample(&self, ux: R, uy: R) -> R3<R> {
        let (a, b) = (self.a, self.b);
        let one = ux.lit(1.0);
        let sub_area = ux * self.area64;
        let (sin_alpha, cos_alpha) = (self.sin_alpha, self.cos_alpha);
        // (s, t) = (sin, cos) of (ξ₁Ω − α); ξ₁Ω ∈ [0, 4π] ⊂ [0, 8] since `arvo` checked Ω.
        let (sin_sub, cos_sub) = sin_cos_0_8(sub_area);
        let s = sin_sub * cos_alpha - cos_sub * sin_alpha;
        let t = cos_sub * cos_alpha + sin_sub * sin_alpha;
        let uu = t - cos_alpha;
        let v = s + sin_alpha * a.dot(b);
        // q = cos of the arc from A to Ĉ, the far vertex of the sub-triangle of area ξ₁·Ω.
        let den = (v * s + uu * t) * sin_alpha;
        let q = (((v * t - uu * s) * cos_alpha - v) / den).clamp(-1.0, 1.0);
        let q = R::select(den.ne(ux.lit(0.0)), q, one);
        let c_perp = self.c_perp;
        // A unit vector already (a ⟂ c_perp, both unit): no renormalisation on this f64
        // sqrt/div latency chain, whose rounding would vanish in the f32 result anyway.
        let c_hat = a.scale(q) + c_perp.scale((one - q * q).max(ux.lit(0.0)).sqrt());
        // cos of the arc from B is uniform between Ĉ·B and 1.
        let z = one - uy * (one - c_hat.dot(b));
        let (t, ok) = tangent(b, c_hat);
        let dir = b.scale(z) + t.scale((one - z * z).max(ux.lit(0.0)).sqrt());
        // Unit up to f64 rounding (b ⟂ t, z² + (1 − z²) = 1), far below the f32 result's ulp.
        R3::select(ok, dir, b)
    }
}

impl SphericalTriangle {
    /// Smallest solid angle (sr) this sampler accepts: below it f64 Arvo loses accuracy, and
    /// callers should sample by area instead.
    pub const MIN_SOLID_ANGLE: f64 = 1e-10;

    /// Project triangle (v0, v1, v2) onto the unit sphere around `p`; `None` if degenerate.
    pub fn new(p: Vec3, v0: Vec3, v1: Vec3, v2: Vec3) -> Option<Self> {
        SphericalProjection::new(p, v0, v1, v2)?.sampler()
    }

    /// Unit direction uniformly distributed in the spherical triangle; pdf = 1/area.
    pub fn sample(&self, u: Vec2) -> Vec3 {
        DVec3::from(self.arvo.sample(u.x as f64, u.y as f64)).as_vec3()
    }

    /// Inverse of [`Self::sample`] for a direction inside the triangle.
    pub fn inverse(&self, d: Vec3) -> Vec2 {
        let (a, b, c) = (self.da, self.db, self.dc);
        let Some(d) = d.as_dvec3().try_normalize() else {
            return Vec2::ZERO;
        };
        // Ĉ: where the great circle through B and d meets arc AC.
        let Some(mut c_hat) = b.cross(d).cross(a.cross(c)).try_normalize() else {
            return Vec2::ZERO; // d = B: any ξ₁ maps there.
        };
        if c_hat.dot(a + c) < 0.0 {
            c_hat = -c_hat;
        }
        let u0 = solid_angle(a.into(), b.into(), c_hat.into()) / self.area64;
        let den = 1.0 - c_hat.dot(b);
        let u1 = if den > 0.0 {
            (1.0 - d.dot(b)) / den
        } else {
            0.0
        };
        Vec2::new(u0.clamp(0.0, 1.0) as f32, u1.clamp(0.0, 1.0) as f32)
    }

    /// Whether direction `d` (any length) points into the triangle, or within
    /// [`DIRECTION_SLACK`] radians of it: samples drawn on an edge (ξ on the boundary of the
    /// unit square) are rounded to f32 and may land a hair outside.
    pub fn contains(&self, d: Vec3) -> bool {
        let d = d.as_dvec3() * self.orientation;
        // d·(x × y) / |x × y| is the sine of d's angle above the plane of edge (x, y).
        let slack = -(DIRECTION_SLACK as f64) * d.length();
        let side = |x: DVec3, y: DVec3| {
            let n = x.cross(y);
            d.dot(n) >= slack * n.length()
        };
        side(self.da, self.db) && side(self.db, self.dc) && side(self.dc, self.da)
    }

    /// Solid-angle pdf of [`Self::sample`] at direction `d`: 1/area inside, 0 outside.
    pub fn pdf(&self, d: Vec3) -> f32 {
        if self.contains(d) {
            (1.0 / self.area64) as f32
        } else {
            0.0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spherical_triangle_octant_has_area_pi_over_2() {
        let t = SphericalTriangle::new(Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z).unwrap();
        assert!((t.area - std::f32::consts::FRAC_PI_2).abs() < 1e-6);
        // The corners of the unit square map to the vertices.
        assert!((t.sample(Vec2::new(0.0, 1.0)) - Vec3::X).length() < 1e-5);
        assert!((t.sample(Vec2::new(0.7, 0.0)) - Vec3::Y).length() < 1e-5);
        assert!((t.sample(Vec2::new(1.0, 1.0)) - Vec3::Z).length() < 1e-5);
        assert!(t.contains(Vec3::ONE) && !t.contains(-Vec3::ONE));
    }

    #[test]
    fn spherical_triangle_degenerate_is_none() {
        let o = Vec3::ZERO;
        assert!(SphericalTriangle::new(o, Vec3::X, 2.0 * Vec3::X, Vec3::Y).is_none());
        assert!(SphericalTriangle::new(o, o, Vec3::X, Vec3::Y).is_none());
        assert!(SphericalTriangle::new(o, Vec3::NAN, Vec3::X, Vec3::Y).is_none());
        // Viewpoint in the triangle's plane: zero solid angle.
        assert!(SphericalTriangle::new(o, Vec3::X, Vec3::Y, Vec3::X + Vec3::Y).is_none());
    }

    /// Random and awkward (point, triangle, draw) cases: ordinary triangles at all distances,
    /// a vertex on the point, collinear vertices, the point in or a hair off the triangle's
    /// plane (grazing), tiny far triangles (below the sampler's minimum), triangles that fill
    /// almost a hemisphere, non-finite vertices, draws on the unit square's edges.
    fn draw_cases() -> Vec<(Vec3, [Vec3; 3], Vec2)> {
        use crate::sampling::hash::{next_f32, pcg_from_keys};
        let mut rng = pcg_from_keys(&[51]);
        let mut r = move || next_f32(&mut rng);
        let mut cases = Vec::new();
        let edges = [0.0, 1.0 - f32::EPSILON / 2.0, 0.5, f32::MIN_POSITIVE];
        for i in 0..4000 {
            let scale = 10f32.powi(i % 7 - 3);
            let mut v3 = |s: f32| Vec3::new(r() - 0.5, r() - 0.5, r() - 0.5) * s;
            let p = v3(2.0);
            let c = v3(8.0) + Vec3::new(0.0, 0.0, 3.0);
            let mut v = [c + v3(scale), c + v3(scale), c + v3(scale)];
            match i % 10 {
                0 => v[1] = p,                                  // a vertex on the point
                1 => v[2] = v[0] + (v[1] - v[0]) * r(),         // collinear
                2 => v[2] = p + (v[0] - p) + (v[1] - p) * -1.5, // point in the plane
                3 => {
                    // A hair off the plane (grazing).
                    let n = (v[1] - v[0]).cross(v[2] - v[0]).normalize();
                    let off = n * (1e-6 * (r() - 0.5));
                    v[2] = p + (v[0] - p) * 0.3 + (v[1] - p) * 0.6 + off;
                }
                4 => v = v.map(|x| p + (x - p).normalize() * 1e4 + v3(1e-3)), // tiny, far
                5 => {
                    v = [
                        p + Vec3::X * 1e-3,
                        p + Vec3::Y * 1e-3,
                        p - Vec3::X - Vec3::Y,
                    ]
                } // huge
                6 if i % 20 == 6 => v[0] = Vec3::NAN,
                6 => v[2] = Vec3::new(f32::INFINITY, 0.0, 1.0),
                _ => {}
            }
            let u = Vec2::new(r(), r());
            let u = match i % 13 {
                0 => Vec2::new(edges[i as usize / 13 % 4], u.y),
                1 => Vec2::new(u.x, edges[i as usize / 13 % 4]),
                2 => Vec2::new(edges[i as usize / 13 % 4], edges[i as usize / 7 % 4]),
                _ => u,
            };
            cases.push((p, v, u));
        }
        cases
    }

    fn draw_bits(d: SolidAngleDraw) -> (Option<u32>, Option<[u32; 3]>) {
        (
            d.omega.map(f32::to_bits),
            d.wi.map(|w| w.to_array().map(f32::to_bits)),
        )
    }

    #[cfg(target_arch = "x86_64")]
    #[test]
    fn four_lane_draws_are_the_one_lane_bits() {
        let Some(t) = crate::isa::Avx2::new() else {
            return;
        };
        let cases = draw_cases();
        let (mut some, mut none) = (0, 0);
        for c in cases.chunks_exact(4) {
            let col = |f: &dyn Fn(usize) -> f32| -> [f32; 4] { std::array::from_fn(f) };
            let p = [0, 1, 2].map(|a| col(&|i| c[i].0[a]));
            let v = [0, 1, 2].map(|j| [0, 1, 2].map(|a| col(&|i| c[i].1[j][a])));
            let u = [0, 1].map(|a| col(&|i| c[i].2[a]));
            let got = SolidAngleDraw::lanes4(
                t,
                [&p[0], &p[1], &p[2]],
                v.each_ref().map(|v| [&v[0], &v[1], &v[2]]),
                [&u[0], &u[1]],
            );
            for (i, &(p, v, u)) in c.iter().enumerate() {
                let want = SolidAngleDraw::new(p, v, u);
                assert_eq!(draw_bits(got[i]), draw_bits(want), "{p} {v:?} {u}");
                // The one-lane draw is what the projection's own methods give.
                let proj = SphericalProjection::new(p, v[0], v[1], v[2]);
                let omega = proj.map(|q| q.solid_angle() as f32);
                let wi = proj.and_then(|q| q.sample(u));
                let old = SolidAngleDraw { omega, wi };
                assert_eq!(draw_bits(want), draw_bits(old), "{p} {v:?} {u}");
                if want.wi.is_some() {
                    some += 1;
                } else {
                    none += 1;
                }
            }
        }
        // Both outcomes are exercised, the valid ones mostly.
        assert!(some > 2500 && none > 400, "{some} drawn, {none} not");
    }
}

//! Diffuse emissive sphere. Seen from outside, solid-angle sampling draws a direction uniformly in
//! the cone the sphere subtends ([`crate::sampling::uniform_cone_sin2`], accurate for tiny
//! cones); area sampling draws a point uniformly on the whole sphere and rejects the far side.
//! From inside (only an inward-emitting or two-sided sphere lights its interior) every point is
//! visible and area sampling is used in both modes. A two-sided sphere is an outward one to
//! receivers outside and an inward one to receivers inside.

use super::{
    Emitter, LightBounds, LightLiSample, LightSampleContext, LightSource, SamplingMode,
    area_sample, area_to_solid_angle, is_positive, solid_angle_sample,
};
use crate::sampling::{Frame, uniform_cone_sin2, uniform_cone_sin2_pdf, uniform_sphere};
use crate::{Rgb, luminance};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Relative slack on r² within which a receiver counts as on (so inside) an inward sphere:
/// far above the rounding of a hit on the sphere (~1e-6), far below any gap a scene models.
const ON_SPHERE: f32 = 1e-4;

/// A sphere emitting constant radiance `l` outward (or inward, into its interior).
#[derive(Clone, Copy, Debug)]
pub struct SphereLight {
    /// Centre.
    pub center: Vec3,
    /// Radius (> 0).
    pub radius: f32,
    /// Emitted radiance.
    pub l: Rgb,
    /// Emits toward the inside instead of the outside.
    pub inward: bool,
    /// Emits to both sides (pbrt-v4's `twosided`): `inward` is then ignored.
    pub two_sided: bool,
}

/// Where a receiver is relative to the sphere, which decides the sampling technique.
enum View {
    /// Outside an outward sphere in solid-angle mode: the cone toward the centre.
    Cone { frame: Frame, sin2: f32 },
    /// Sample the sphere's area (and keep only the points that emit toward the receiver).
    Area,
    /// The receiver cannot see the emitting side (outside an inward sphere, inside an outward
    /// one): no sample, pdf 0.
    Dark,
}

impl SphereLight {
    /// A sphere light; `None` for a non-positive or non-finite radius or non-finite input.
    pub fn new(center: Vec3, radius: f32, l: Rgb, inward: bool) -> Option<Self> {
        if !is_positive(radius) || !radius.is_finite() || !center.is_finite() || !l.is_finite() {
            return None;
        }
        Some(Self {
            center,
            radius,
            l,
            inward,
            two_sided: false,
        })
    }

    /// The same sphere emitting to both sides when `two_sided`.
    pub fn with_two_sided(self, two_sided: bool) -> Self {
        Self { two_sided, ..self }
    }

    /// Whether the sphere acts as an inward emitter for a receiver at `p`: a two-sided one
    /// lights its inside from the inside and its outside from the outside.
    fn inward_for(&self, p: Vec3) -> bool {
        if self.two_sided {
            (self.center - p).length_squared() <= self.radius * self.radius
        } else {
            self.inward
        }
    }

    /// Technique for a receiver at `p`; shared by `sample_li` and `pdf_li` so they agree.
    fn view(&self, p: Vec3, mode: SamplingMode) -> View {
        let to_c = self.center - p;
        let d2 = to_c.length_squared();
        let r2 = self.radius * self.radius;
        let inward = self.inward_for(p);
        // A receiver on an inward sphere (a hit on the light's own surface, its rounding on
        // either side) sees the interior: it used to count as outside half the time.
        let outside = if inward {
            d2 > r2 * (1.0 + ON_SPHERE)
        } else {
            d2 > r2
        };
        match (outside, inward) {
            (true, false) if mode == SamplingMode::SolidAngle => View::Cone {
                frame: Frame::from_normal(to_c / d2.sqrt()),
                sin2: self.radius * self.radius / d2,
            },
            (true, false) | (false, true) => View::Area,
            _ => View::Dark,
        }
    }

    /// First point where the ray `p + t·wi` (t > 0) meets the sphere from outside, or the exit
    /// point from inside; `None` if it misses.
    fn intersect(&self, p: Vec3, wi: Vec3) -> Option<Vec3> {
        let oc = p - self.center;
        let b = oc.dot(wi);
        // c − b² computed as the squared distance from the centre to the ray: no cancellation
        // for distant receivers where |oc|² and b² are both huge.
        let perp = oc - b * wi;
        let disc = self.radius * self.radius - perp.length_squared();
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        let c = oc.length_squared() - self.radius * self.radius;
        // Roots −b ± s; the near one from outside (c > 0), the far one from inside. An inward
        // sphere is seen from inside (or from its own surface, `view`): always the far one,
        // else a receiver on the sphere rounded outside found itself (t ≈ 0).
        let t = if c > 0.0 && !self.inward_for(p) {
            -b - s
        } else {
            -b + s
        };
        if !is_positive(t) {
            return None;
        }
        // Project onto the sphere: removes the rounding of t.
        let q = p + wi * t - self.center;
        Some(self.center + q * (self.radius / q.length()))
    }

    /// Area pdf of a uniform point on the sphere.
    #[inline]
    fn pdf_area(&self) -> f32 {
        1.0 / (4.0 * PI * self.radius * self.radius)
    }
}

impl LightSource for SphereLight {
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        mode: SamplingMode,
    ) -> Option<LightLiSample> {
        match self.view(ctx.p, mode) {
            View::Dark => None,
            View::Cone { frame, sin2 } => {
                let local = uniform_cone_sin2(u, sin2);
                let wi = frame.to_world(local).normalize();
                // Rays at the cone's rim may miss by rounding: fall back to the tangent point.
                let p_light = self.intersect(ctx.p, wi).unwrap_or_else(|| {
                    let to_c = self.center - ctx.p;
                    ctx.p + wi * wi.dot(to_c).max(0.0)
                });
                solid_angle_sample(wi, p_light, uniform_cone_sin2_pdf(Vec3::Z, sin2), self.l)
            }
            View::Area => {
                let n_out = uniform_sphere(u);
                let p_light = self.center + self.radius * n_out;
                let s = area_sample(ctx.p, p_light, n_out, self.pdf_area(), self.l)?;
                // Only points whose emitting side faces the receiver: the far side of an outward
                // sphere is hidden behind its near side.
                let n_emit = if self.inward_for(ctx.p) {
                    -n_out
                } else {
                    n_out
                };
                (n_emit.dot(s.wi) < 0.0).then_some(s)
            }
        }
    }

    fn power(&self) -> f32 {
        let sides = if self.two_sided { 2.0 } else { 1.0 };
        sides * luminance(self.l) * PI * 4.0 * PI * self.radius * self.radius
    }

    fn bounds(&self) -> Option<LightBounds> {
        let r = Vec3::splat(self.radius);
        Some(LightBounds {
            min: self.center - r,
            max: self.center + r,
            w: Vec3::Z,
            phi: self.power(),
            // Normals point everywhere.
            cos_theta_o: -1.0,
            cos_theta_e: 0.0,
            two_sided: self.two_sided,
        })
    }
}

impl Emitter for SphereLight {
    /// The hit point is recomputed from `wi` (first visible intersection), so `p_light` and
    /// `n_light` are not needed and a caller's rounding cannot make the pdf inconsistent.
    fn pdf_li(
        &self,
        ctx: &LightSampleContext,
        wi: Vec3,
        _p_light: Vec3,
        _n_light: Vec3,
        mode: SamplingMode,
    ) -> f32 {
        match self.view(ctx.p, mode) {
            View::Dark => 0.0,
            View::Cone { frame, sin2 } => uniform_cone_sin2_pdf(frame.to_local(wi), sin2),
            View::Area => match self.intersect(ctx.p, wi) {
                Some(q) => {
                    let n_out = (q - self.center) / self.radius;
                    area_to_solid_angle(self.pdf_area(), ctx.p, q, n_out)
                }
                None => 0.0,
            },
        }
    }

    /// `p` is the point on the sphere; its outward normal is recomputed from the centre, so the
    /// orientation of the caller's `n` does not matter.
    fn radiance(&self, p: Vec3, _n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        let out = (p - self.center).dot(w) > 0.0;
        if self.two_sided || out != self.inward {
            self.l
        } else {
            Rgb::ZERO
        }
    }
}

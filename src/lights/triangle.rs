//! Diffuse emissive triangle: area sampling (uniform barycentrics) or solid-angle sampling
//! (Arvo's spherical triangle, [`crate::sampling::SphericalTriangle`]).

use super::{
    LightBounds, LightLiSample, LightSampleContext, LightSource, Planar, SamplingMode, area_sample,
    diffuse_power, is_positive, sees_emitting_side, solid_angle_sample, spherical_ok,
    triangle_solid_angle,
};
use crate::Rgb;
use crate::sampling::{SolidAngleDraw, uniform_triangle_point};
use glam::{Vec2, Vec3};

/// A triangle emitting constant radiance `l` on the side of `n` (both sides if `two_sided`).
#[derive(Clone, Copy, Debug)]
pub struct TriangleLight {
    /// Vertices (world space).
    pub p: [Vec3; 3],
    /// Unit emitting normal (the surface's geometric normal, pbrt orientation).
    pub n: Vec3,
    /// Area.
    pub area: f32,
    /// Emitted radiance.
    pub l: Rgb,
    /// Emits on both sides.
    pub two_sided: bool,
}

impl TriangleLight {
    /// A light on triangle (p0, p1, p2) with emitting normal `n`; `None` if the area is zero.
    pub fn new(p: [Vec3; 3], n: Vec3, l: Rgb, two_sided: bool) -> Option<Self> {
        let area = 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
        if !is_positive(area) || !area.is_finite() {
            return None;
        }
        Some(Self {
            p,
            n: n.normalize(),
            area,
            l,
            two_sided,
        })
    }
}

impl TriangleLight {
    /// [`LightSource::sample_li`] with the f64 half of a solid-angle sample already drawn
    /// (`draw`, `None` in area mode): [`SolidAngleDraw::new`] of this triangle from `ctx.p`
    /// with `u`, one lane at a time or four per register in the lane kernel. The rest, shared
    /// by both, is here.
    #[inline(always)]
    pub fn sample_li_drawn(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        draw: Option<SolidAngleDraw>,
    ) -> Option<LightLiSample> {
        if !self.faces(ctx.p) {
            return None;
        }
        if let Some(SolidAngleDraw {
            omega: Some(omega),
            wi,
        }) = draw
            && spherical_ok(omega)
        {
            let wi = wi?;
            // Where the sampled direction meets the triangle's plane (the shadow-ray target).
            let denom = self.n.dot(wi);
            let t = self.n.dot(self.p[0] - ctx.p) / denom;
            if !is_positive(t) || !t.is_finite() {
                return None;
            }
            return solid_angle_sample(wi, ctx.p + wi * t, 1.0 / omega, self.l);
        }
        let p_light = uniform_triangle_point(u, self.p[0], self.p[1], self.p[2]);
        area_sample(ctx.p, p_light, self.n, 1.0 / self.area, self.l)
    }
}

impl LightSource for TriangleLight {
    // Always inlined: a call leaves the lane kernel one lane at a time (51e942d, 1-thread
    // 256² 64 spp light-area 0.55 → 0.34 s).
    #[inline(always)]
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        mode: SamplingMode,
    ) -> Option<LightLiSample> {
        if !self.faces(ctx.p) {
            return None;
        }
        // One projection serves both the sampling-rule decision and the sampler (the same
        // Ω as `spherical_omega`, without normalising and measuring the triangle twice).
        let draw = match mode {
            SamplingMode::SolidAngle => Some(SolidAngleDraw::new(ctx.p, self.p, u)),
            SamplingMode::Area => None,
        };
        self.sample_li_drawn(ctx, u, draw)
    }

    fn power(&self) -> f32 {
        diffuse_power(self.l, self.area, self.two_sided)
    }

    fn bounds(&self) -> Option<LightBounds> {
        let min = self.p[0].min(self.p[1]).min(self.p[2]);
        let max = self.p[0].max(self.p[1]).max(self.p[2]);
        self.planar_bounds(min, max)
    }
}

impl Planar for TriangleLight {
    #[inline]
    fn normal(&self) -> Vec3 {
        self.n
    }

    #[inline]
    fn emitted(&self) -> Rgb {
        self.l
    }

    #[inline]
    fn is_two_sided(&self) -> bool {
        self.two_sided
    }

    #[inline]
    fn surface_area(&self) -> f32 {
        self.area
    }

    /// Whether a receiver at `p` can see the emitting side at all (one-sided lights are dark
    /// from behind; a receiver in the plane sees nothing).
    #[inline]
    fn faces(&self, p: Vec3) -> bool {
        sees_emitting_side(self.n, self.p[0], self.two_sided, p)
    }

    /// Solid angle Ω to sample uniformly from `p` in solid-angle mode, or `None` where the rule
    /// of [`spherical_ok`] says to sample by area. `sample_li` and `pdf_li` both decide through
    /// this one function (and both use this Ω for the pdf), so the sample and its pdf agree.
    fn spherical_omega(&self, p: Vec3, mode: SamplingMode) -> Option<f32> {
        if mode != SamplingMode::SolidAngle {
            return None;
        }
        let omega = triangle_solid_angle(p, self.p[0], self.p[1], self.p[2]);
        spherical_ok(omega).then_some(omega)
    }
}

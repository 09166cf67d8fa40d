//! Diffuse emissive parallelogram `corner + s·e1 + t·e2`, s, t ∈ [0, 1]: area sampling, or
//! solid-angle sampling of the spherical rectangle (Ureña et al. 2013,
//! [`crate::sampling::SphericalRectangle`]) when the edges are perpendicular.

use super::{
    LightBounds, LightLiSample, LightSampleContext, LightSource, Planar, SamplingMode, area_sample,
    diffuse_power, is_positive, sees_emitting_side, solid_angle_sample, spherical_ok,
    triangle_solid_angle,
};
use crate::Rgb;
use crate::sampling::SphericalRectangle;
use glam::{Vec2, Vec3};

/// A parallelogram emitting constant radiance `l` on the side of `n` (both sides if `two_sided`).
#[derive(Clone, Copy, Debug)]
pub struct QuadLight {
    /// Corner at s = t = 0.
    pub corner: Vec3,
    /// First edge.
    pub e1: Vec3,
    /// Second edge.
    pub e2: Vec3,
    /// Unit geometric normal, oriented to the emitting side given at construction.
    pub n: Vec3,
    /// Area |e1 × e2|.
    pub area: f32,
    /// Emitted radiance.
    pub l: Rgb,
    /// Emits on both sides.
    pub two_sided: bool,
    /// Edges perpendicular: the spherical-rectangle sampler applies.
    pub rectangular: bool,
}

impl QuadLight {
    /// A light on the parallelogram `corner + s·e1 + t·e2` emitting toward `n`; `None` for zero
    /// area, a zero normal, a normal in the quad's plane, or non-finite input.
    pub fn new(corner: Vec3, e1: Vec3, e2: Vec3, n: Vec3, l: Rgb, two_sided: bool) -> Option<Self> {
        if !(corner.is_finite() && e1.is_finite() && e2.is_finite() && n.is_finite()) {
            return None;
        }
        if !l.is_finite() {
            return None;
        }
        let c = e1.cross(e2);
        let area = c.length();
        if !is_positive(area) || !area.is_finite() {
            return None;
        }
        // The true geometric normal, turned to the side the caller says emits: cosines and the
        // inside/outside test must use the plane's own normal even if `n` is slightly off.
        let mut ng = c / area;
        let side = ng.dot(n);
        if side == 0.0 || !side.is_finite() {
            return None;
        }
        if side < 0.0 {
            ng = -ng;
        }
        let cos_edges = e1.dot(e2) / (e1.length() * e2.length());
        Some(Self {
            corner,
            e1,
            e2,
            n: ng,
            area,
            l,
            two_sided,
            rectangular: (cos_edges.abs() as f64) <= SphericalRectangle::MAX_EDGE_COS,
        })
    }
}

impl LightSource for QuadLight {
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        mode: SamplingMode,
    ) -> Option<LightLiSample> {
        if !self.faces(ctx.p) {
            return None;
        }
        match self.spherical_omega(ctx.p, mode) {
            Some(omega) => {
                let sr = SphericalRectangle::new(ctx.p, self.corner, self.e1, self.e2)?;
                let p_light = sr.sample(u);
                let wi = (p_light - ctx.p).normalize_or_zero();
                if wi == Vec3::ZERO {
                    return None;
                }
                solid_angle_sample(wi, p_light, 1.0 / omega, self.l)
            }
            None => {
                let p_light = self.corner + u.x * self.e1 + u.y * self.e2;
                area_sample(ctx.p, p_light, self.n, 1.0 / self.area, self.l)
            }
        }
    }

    fn power(&self) -> f32 {
        diffuse_power(self.l, self.area, self.two_sided)
    }

    fn bounds(&self) -> Option<LightBounds> {
        let c = [
            self.corner,
            self.corner + self.e1,
            self.corner + self.e2,
            self.corner + self.e1 + self.e2,
        ];
        let min = c[0].min(c[1]).min(c[2]).min(c[3]);
        let max = c[0].max(c[1]).max(c[2]).max(c[3]);
        self.planar_bounds(min, max)
    }
}

impl Planar for QuadLight {
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

    /// Whether a receiver at `p` can see the emitting side (none from the plane itself).
    #[inline]
    fn faces(&self, p: Vec3) -> bool {
        sees_emitting_side(self.n, self.corner, self.two_sided, p)
    }

    /// Solid angle Ω to sample uniformly from `p` in solid-angle mode (as two spherical
    /// triangles: cheaper than setting up the rectangle sampler), or `None` where area sampling
    /// is used instead: skewed parallelograms (the sampler needs right angles) and solid angles
    /// outside [`spherical_ok`]. `sample_li` and `pdf_li` share this rule and this Ω.
    fn spherical_omega(&self, p: Vec3, mode: SamplingMode) -> Option<f32> {
        if mode != SamplingMode::SolidAngle || !self.rectangular {
            return None;
        }
        let (c, c1, c2, c12) = (
            self.corner,
            self.corner + self.e1,
            self.corner + self.e2,
            self.corner + self.e1 + self.e2,
        );
        let omega = triangle_solid_angle(p, c, c1, c12) + triangle_solid_angle(p, c, c12, c2);
        spherical_ok(omega).then_some(omega)
    }
}

//! Diffuse emissive disk, sampled by area with the concentric map.
//!
//! `SamplingMode::SolidAngle` falls back to area sampling: uniform sampling of the spherical
//! ellipse a disk subtends (Guillén et al. 2017) is not implemented; the fallback stays consistent
//! because `pdf_li` ignores the mode in the same way.

use super::{
    LightBounds, LightLiSample, LightSampleContext, LightSource, Planar, SamplingMode, area_sample,
    diffuse_power, is_positive, sees_emitting_side,
};
use crate::Rgb;
use crate::sampling::{Frame, concentric_disk};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// A disk emitting constant radiance `l` on the side of `normal` (both sides if `two_sided`).
#[derive(Clone, Copy, Debug)]
pub struct DiskLight {
    /// Centre.
    pub center: Vec3,
    /// Frame whose `n` is the unit emitting normal.
    pub frame: Frame,
    /// Radius (> 0).
    pub radius: f32,
    /// Emitted radiance.
    pub l: Rgb,
    /// Emits on both sides.
    pub two_sided: bool,
}

impl DiskLight {
    /// A disk light; `None` for a zero normal, a non-positive radius or non-finite input.
    pub fn new(center: Vec3, normal: Vec3, radius: f32, l: Rgb, two_sided: bool) -> Option<Self> {
        if !is_positive(radius) || !radius.is_finite() || !center.is_finite() || !l.is_finite() {
            return None;
        }
        let n = normal.try_normalize()?;
        Some(Self {
            center,
            frame: Frame::from_normal(n),
            radius,
            l,
            two_sided,
        })
    }

    /// Area π r².
    #[inline]
    pub fn area(&self) -> f32 {
        PI * self.radius * self.radius
    }
}

impl LightSource for DiskLight {
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        _mode: SamplingMode,
    ) -> Option<LightLiSample> {
        if !self.faces(ctx.p) {
            return None;
        }
        let q = concentric_disk(u) * self.radius;
        let p_light = self.center + self.frame.s * q.x + self.frame.t * q.y;
        area_sample(ctx.p, p_light, self.frame.n, 1.0 / self.area(), self.l)
    }

    fn power(&self) -> f32 {
        diffuse_power(self.l, self.area(), self.two_sided)
    }

    fn bounds(&self) -> Option<LightBounds> {
        // Half-extent of a disk along axis i is r·sqrt(1 − n_i²).
        let n = self.frame.n;
        let ext = Vec3::new(
            (1.0 - n.x * n.x).max(0.0).sqrt(),
            (1.0 - n.y * n.y).max(0.0).sqrt(),
            (1.0 - n.z * n.z).max(0.0).sqrt(),
        ) * self.radius;
        self.planar_bounds(self.center - ext, self.center + ext)
    }
}

impl Planar for DiskLight {
    #[inline]
    fn normal(&self) -> Vec3 {
        self.frame.n
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
        self.area()
    }

    /// Whether a receiver at `p` can see the emitting side (none from the plane itself).
    #[inline]
    fn faces(&self, p: Vec3) -> bool {
        sees_emitting_side(self.frame.n, self.center, self.two_sided, p)
    }

    /// Always area sampling (see the module comment), whatever the mode.
    #[inline]
    fn spherical_omega(&self, _p: Vec3, _mode: SamplingMode) -> Option<f32> {
        None
    }
}

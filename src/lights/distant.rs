//! Distant (directional) light: radiance arriving from a single direction, a delta in direction.

use super::{LightBounds, LightLiSample, LightSampleContext, LightSource, SamplingMode, far_point};
use crate::{Rgb, luminance};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Scene radius assumed before [`DistantLight::preprocess`] runs: large enough that shadow rays
/// still leave any ordinary scene.
pub(crate) const DEFAULT_SCENE_RADIUS: f32 = 1e5;

/// Light arriving from direction `w_light` with irradiance `l` on a surface facing it.
#[derive(Clone, Copy, Debug)]
pub struct DistantLight {
    /// Unit direction from the scene toward the light.
    pub w_light: Vec3,
    /// Emitted radiance scale (irradiance at normal incidence).
    pub l: Rgb,
    /// Scene bounding-sphere radius (from preprocess).
    pub scene_radius: f32,
}

impl DistantLight {
    /// A distant light shining from `w_light` (toward the light); a zero direction falls back
    /// to +z.
    pub fn new(w_light: Vec3, l: Rgb) -> Self {
        Self {
            w_light: w_light.try_normalize().unwrap_or(Vec3::Z),
            l,
            scene_radius: DEFAULT_SCENE_RADIUS,
        }
    }

    /// Record the scene's bounding sphere (for shadow-ray endpoints and power).
    pub fn preprocess(&mut self, _center: Vec3, radius: f32) {
        if radius > 0.0 && radius.is_finite() {
            self.scene_radius = radius;
        }
    }
}

impl LightSource for DistantLight {
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        _u: Vec2,
        _mode: SamplingMode,
    ) -> Option<LightLiSample> {
        Some(LightLiSample {
            wi: self.w_light,
            li: self.l,
            pdf: 1.0,
            p_light: far_point(ctx.p, self.w_light, self.scene_radius),
            delta: true,
        })
    }

    /// Power through the scene's bounding disk, π r² L.
    fn power(&self) -> f32 {
        PI * self.scene_radius * self.scene_radius * luminance(self.l)
    }

    fn bounds(&self) -> Option<LightBounds> {
        None
    }
}

//! Uniform infinite light: the same radiance from every direction (a constant sky), sampled
//! uniformly over the sphere.

use super::distant::DEFAULT_SCENE_RADIUS;
use super::{
    Emitter, LightBounds, LightLiSample, LightSampleContext, LightSource, SamplingMode, far_point,
};
use crate::sampling::{uniform_sphere, uniform_sphere_pdf};
use crate::{Rgb, luminance};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Constant radiance `l` arriving from every direction.
#[derive(Clone, Copy, Debug)]
pub struct UniformInfiniteLight {
    /// Radiance.
    pub l: Rgb,
    /// Scene bounding-sphere radius (from preprocess).
    pub scene_radius: f32,
}

impl UniformInfiniteLight {
    /// A uniform sky of radiance `l`.
    pub fn new(l: Rgb) -> Self {
        Self {
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

impl LightSource for UniformInfiniteLight {
    /// Uniform over the whole sphere (not the hemisphere around `ctx.n`): transmissive
    /// surfaces receive light from below too, and the mode does not apply to infinite lights.
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        _mode: SamplingMode,
    ) -> Option<LightLiSample> {
        let wi = uniform_sphere(u);
        Some(LightLiSample {
            wi,
            li: self.l,
            pdf: uniform_sphere_pdf(),
            p_light: far_point(ctx.p, wi, self.scene_radius),
            delta: false,
        })
    }

    /// Flux entering the scene's bounding sphere, 4πr² · πL (pbrt-v4): on the same scale as
    /// a distant light's π r² L, which enters through the sphere's cross-section.
    fn power(&self) -> f32 {
        4.0 * PI * PI * self.scene_radius * self.scene_radius * luminance(self.l)
    }

    fn bounds(&self) -> Option<LightBounds> {
        None
    }
}

impl Emitter for UniformInfiniteLight {
    fn pdf_li(&self, _: &LightSampleContext, _: Vec3, _: Vec3, _: Vec3, _: SamplingMode) -> f32 {
        uniform_sphere_pdf()
    }

    fn radiance(&self, _p: Vec3, _n: Vec3, _uv: Vec2, _w: Vec3) -> Rgb {
        self.l
    }
}

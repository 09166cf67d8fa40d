//! Light sources. Each returns radiance and a **solid-angle** pdf (area pdfs are converted in
//! one place, [`area_to_solid_angle`]), its power Φ and its bounds (for power and BVH selection).
//! TODO(issue 4): point, spot, distant, triangle/quad/sphere/disk area lights, uniform
//! infinite, environment map; area and solid-angle sampling.

use crate::Rgb;
use glam::{Vec2, Vec3};

/// Where light is being gathered: a point and its geometric normal (zero for "any direction").
#[derive(Clone, Copy, Debug)]
pub struct LightSampleContext {
    /// Receiving point.
    pub p: Vec3,
    /// Geometric normal at `p`, flipped toward the viewer (or zero).
    pub n: Vec3,
}

/// How an area light draws its samples.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SamplingMode {
    /// Uniform over the emitter's surface, converted by cos θy / r².
    Area,
    /// Uniform over the solid angle it subtends where supported (else area).
    SolidAngle,
}

/// A sampled connection from a receiving point to a light.
#[derive(Clone, Copy, Debug)]
pub struct LightLiSample {
    /// Unit direction from the receiver toward the light.
    pub wi: Vec3,
    /// Incident radiance along -wi (before visibility).
    pub li: Rgb,
    /// Solid-angle pdf of `wi` (1 for delta lights).
    pub pdf: f32,
    /// The sampled point on the light (for the shadow ray); for infinite/distant lights a
    /// point far outside the scene along `wi`.
    pub p_light: Vec3,
    /// True for point, spot and distant lights (no MIS with BSDF sampling possible).
    pub delta: bool,
}

/// Spatial and directional bounds of a light's emission (used by the light BVH).
#[derive(Clone, Copy, Debug)]
pub struct LightBounds {
    /// Box around the emitter.
    pub min: Vec3,
    /// Box around the emitter.
    pub max: Vec3,
    /// Central emission direction.
    pub w: Vec3,
    /// Power bound (luminance-weighted).
    pub phi: f32,
    /// Cosine of the spread of surface normals around `w`.
    pub cos_theta_o: f32,
    /// Cosine of the emission angle beyond the normals (π/2 for diffuse).
    pub cos_theta_e: f32,
    /// Emits on both sides.
    pub two_sided: bool,
}

/// The interface every light implements.
pub trait LightSource {
    /// Sample incident illumination at `ctx` with the 2D sample `u`.
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        mode: SamplingMode,
    ) -> Option<LightLiSample>;
    /// Solid-angle pdf that `sample_li` would draw direction `wi` which hits the light at
    /// `p_light` with light normal `n_light` (for infinite lights, only `wi` matters).
    fn pdf_li(
        &self,
        ctx: &LightSampleContext,
        wi: Vec3,
        p_light: Vec3,
        n_light: Vec3,
        mode: SamplingMode,
    ) -> f32;
    /// Emitted radiance leaving the light's surface at `p` with normal `n` in direction `w`
    /// (area lights), or arriving from direction -`w` (infinite lights). Zero for delta lights.
    fn radiance(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb;
    /// Total emitted power Φ (luminance, W-equivalent) — for power-proportional selection.
    fn power(&self) -> f32;
    /// Bounds for light-BVH selection; `None` for infinite lights (sampled separately).
    fn bounds(&self) -> Option<LightBounds>;
}

/// Convert an area pdf at a point `p_light` with normal `n_light`, seen from `p`, to a
/// solid-angle pdf: pdf_ω = pdf_A · r² / |cos θy|. Returns 0 at grazing angles.
#[inline]
pub fn area_to_solid_angle(pdf_area: f32, p: Vec3, p_light: Vec3, n_light: Vec3) -> f32 {
    let d = p_light - p;
    let r2 = d.length_squared();
    if r2 == 0.0 {
        return 0.0;
    }
    let cos = (n_light.dot(d) / r2.sqrt()).abs();
    if cos <= 0.0 { 0.0 } else { pdf_area * r2 / cos }
}

pub mod triangle;

pub use triangle::TriangleLight;

/// Closed set of lights (enum dispatch: a million emissive triangles stay compact and fast).
#[derive(Clone, Debug)]
pub enum Light {
    /// Diffuse emissive triangle.
    Triangle(TriangleLight),
}

impl Light {
    /// True for lights at infinity (environment, uniform sky), hit by rays that escape.
    pub fn is_infinite(&self) -> bool {
        false
    }
}

impl LightSource for Light {
    #[inline]
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        mode: SamplingMode,
    ) -> Option<LightLiSample> {
        match self {
            Light::Triangle(l) => l.sample_li(ctx, u, mode),
        }
    }
    #[inline]
    fn pdf_li(
        &self,
        ctx: &LightSampleContext,
        wi: Vec3,
        p_light: Vec3,
        n_light: Vec3,
        mode: SamplingMode,
    ) -> f32 {
        match self {
            Light::Triangle(l) => l.pdf_li(ctx, wi, p_light, n_light, mode),
        }
    }
    #[inline]
    fn radiance(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        match self {
            Light::Triangle(l) => l.radiance(p, n, uv, w),
        }
    }
    fn power(&self) -> f32 {
        match self {
            Light::Triangle(l) => l.power(),
        }
    }
    fn bounds(&self) -> Option<LightBounds> {
        match self {
            Light::Triangle(l) => l.bounds(),
        }
    }
}

//! Light sources. Each returns radiance and a **solid-angle** pdf (area pdfs are converted in
//! one place, [`area_to_solid_angle`]), its power Φ and its bounds (for power and BVH selection).
//!
//! One light per file: [`TriangleLight`], [`MaskedTriangleLight`], [`QuadLight`],
//! [`SphereLight`], [`DiskLight`] (area lights, area or solid-angle sampling), [`PointLight`],
//! [`SpotLight`], [`DistantLight`] (delta lights), [`UniformInfiniteLight`] and [`EnvMapLight`]
//! (infinite lights).

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
    /// Total emitted power Φ (luminance, W-equivalent) — for power-proportional selection.
    fn power(&self) -> f32;
    /// Bounds for light-BVH selection; `None` for infinite lights (sampled separately).
    fn bounds(&self) -> Option<LightBounds>;
}

/// What the lights that rays can reach (area and infinite lights) add to [`LightSource`]: the
/// radiance a ray finds on them and the pdf with which `sample_li` draws a direction. Delta
/// lights (point, spot, distant) have neither — no ray hits them — so only [`Light`] answers
/// for them (zero), and a new area light cannot inherit a silent zero.
pub trait Emitter: LightSource {
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
    /// (area lights), or arriving from direction -`w` (infinite lights).
    fn radiance(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb;
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

/// Smallest solid angle (sr) for which area lights sample the spherical polygon: below it the
/// spherical construction loses precision in f32/f64, while area sampling is already nearly
/// uniform in solid angle (the light is small and far), so nothing is lost by falling back.
pub const MIN_SPHERICAL_SOLID_ANGLE: f32 = 1e-4;
/// Largest solid angle (sr, just under the 2π of a half-space) for which area lights sample the
/// spherical polygon: beyond it the receiver is almost in the light's plane next to a large
/// light, the polygon's corners are nearly antipodal and the construction is ill-conditioned.
pub const MAX_SPHERICAL_SOLID_ANGLE: f32 = 6.22;

/// Whether a spherical polygon of solid angle `omega` is sampled directly (see the thresholds).
#[inline]
pub(crate) fn spherical_ok(omega: f32) -> bool {
    (MIN_SPHERICAL_SOLID_ANGLE..=MAX_SPHERICAL_SOLID_ANGLE).contains(&omega)
}

pub mod disk;
pub mod distant;
pub mod envmap;
pub mod masked;
pub mod point;
pub mod quad;
pub mod sphere;
pub mod spot;
pub mod triangle;
pub mod uniform_infinite;

pub use disk::DiskLight;
pub use distant::DistantLight;
pub use envmap::EnvMapLight;
pub use masked::MaskedTriangleLight;
pub use point::PointLight;
pub use quad::QuadLight;
pub use sphere::SphereLight;
pub use spot::SpotLight;
pub use triangle::TriangleLight;
pub use uniform_infinite::UniformInfiniteLight;

/// Closed set of lights (enum dispatch: a million emissive triangles stay compact and fast;
/// the bulky environment map is boxed so it does not inflate every triangle).
#[derive(Clone, Debug)]
pub enum Light {
    /// Diffuse emissive triangle.
    Triangle(TriangleLight),
    /// Diffuse emissive triangle under an alpha cut-out.
    MaskedTriangle(Box<MaskedTriangleLight>),
    /// Diffuse emissive parallelogram.
    Quad(QuadLight),
    /// Diffuse emissive sphere.
    Sphere(SphereLight),
    /// Diffuse emissive disk.
    Disk(DiskLight),
    /// Isotropic point light.
    Point(PointLight),
    /// Spot light with smoothstep falloff.
    Spot(SpotLight),
    /// Directional light from infinitely far away.
    Distant(DistantLight),
    /// Constant radiance from every direction.
    UniformInfinite(UniformInfiniteLight),
    /// Lat-long environment map.
    EnvMap(Box<EnvMapLight>),
}

/// Calls `$body` with `$l` bound to the inner light of every variant.
macro_rules! dispatch {
    ($self:expr, $l:ident => $body:expr) => {
        match $self {
            Light::Triangle($l) => $body,
            Light::MaskedTriangle($l) => $body,
            Light::Quad($l) => $body,
            Light::Sphere($l) => $body,
            Light::Disk($l) => $body,
            Light::Point($l) => $body,
            Light::Spot($l) => $body,
            Light::Distant($l) => $body,
            Light::UniformInfinite($l) => $body,
            Light::EnvMap($l) => $body,
        }
    };
}

/// A light as the integrator's vector kernels (`integrator/lanes.rs`) take it: which kernel
/// samples it exactly as its own `sample_li` does, with the data that kernel reads.
#[derive(Clone, Copy, Debug)]
pub enum LaneLight<'a> {
    /// A triangle: sampled by area or by solid angle, 16 receivers at a time.
    Triangle(&'a TriangleLight),
}

impl Light {
    /// The vector kernel for this light's samples, if one exists (`None`: one sample at a time).
    #[inline(always)]
    pub fn lane_kind(&self) -> Option<LaneLight<'_>> {
        match self {
            Light::Triangle(t) => Some(LaneLight::Triangle(t)),
            _ => None,
        }
    }

    /// True for lights at infinity (environment, uniform sky), hit by rays that escape.
    pub fn is_infinite(&self) -> bool {
        matches!(self, Light::UniformInfinite(_) | Light::EnvMap(_))
    }

    /// True for lights described by a Dirac delta (point, spot, distant): no ray can hit them,
    /// so they cannot be combined with BSDF sampling by MIS.
    pub fn is_delta(&self) -> bool {
        matches!(self, Light::Point(_) | Light::Spot(_) | Light::Distant(_))
    }

    /// Give distant and infinite lights the scene's bounding sphere (they need it to place
    /// shadow-ray endpoints and to compute their power); a no-op for the others.
    pub fn preprocess(&mut self, center: Vec3, radius: f32) {
        match self {
            Light::Distant(l) => l.preprocess(center, radius),
            Light::UniformInfinite(l) => l.preprocess(center, radius),
            Light::EnvMap(l) => l.preprocess(center, radius),
            _ => {}
        }
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
        dispatch!(self, l => l.sample_li(ctx, u, mode))
    }
    fn power(&self) -> f32 {
        dispatch!(self, l => l.power())
    }
    fn bounds(&self) -> Option<LightBounds> {
        dispatch!(self, l => l.bounds())
    }
}

/// [`dispatch!`] over the lights that are [`Emitter`]s; `$delta` for point, spot and distant
/// lights, which no ray can hit.
macro_rules! dispatch_emitter {
    ($self:expr, $l:ident => $body:expr, $delta:expr) => {
        match $self {
            Light::Triangle($l) => $body,
            Light::MaskedTriangle($l) => $body,
            Light::Quad($l) => $body,
            Light::Sphere($l) => $body,
            Light::Disk($l) => $body,
            Light::UniformInfinite($l) => $body,
            Light::EnvMap($l) => $body,
            Light::Point(_) | Light::Spot(_) | Light::Distant(_) => $delta,
        }
    };
}

impl Emitter for Light {
    #[inline]
    fn pdf_li(
        &self,
        ctx: &LightSampleContext,
        wi: Vec3,
        p_light: Vec3,
        n_light: Vec3,
        mode: SamplingMode,
    ) -> f32 {
        dispatch_emitter!(self, l => l.pdf_li(ctx, wi, p_light, n_light, mode), 0.0)
    }
    #[inline]
    fn radiance(&self, p: Vec3, n: Vec3, uv: Vec2, w: Vec3) -> Rgb {
        dispatch_emitter!(self, l => l.radiance(p, n, uv, w), Rgb::ZERO)
    }
}

/// Solid angle (sr) of triangle (a, b, c) seen from `p` (Van Oosterom & Strackee 1983, in f64
/// because it cancels for small triangles); 0 if degenerate. Cheaper than building a
/// [`crate::sampling::SphericalTriangle`], so `pdf_li` (called for every emitter hit under MIS)
/// and the sampling-rule decision use it.
pub(crate) fn triangle_solid_angle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    // The same projection `sample_li` starts from, so both see bit-identical solid angles.
    crate::sampling::SphericalProjection::new(p, a, b, c)
        .map_or(0.0, |proj| proj.solid_angle() as f32)
}

/// The connection from `p` to `p_light`, a point drawn with area density `pdf_area` on an
/// emitter of radiance `l` whose normal there is `n_light`: the one place where a sampled point
/// on an area light becomes a [`LightLiSample`] with a solid-angle pdf.
// Always inlined, like `TriangleLight::sample_li` (whose comment has the measurement).
#[inline(always)]
pub(crate) fn area_sample(
    p: Vec3,
    p_light: Vec3,
    n_light: Vec3,
    pdf_area: f32,
    l: Rgb,
) -> Option<LightLiSample> {
    let d = p_light - p;
    let dist = d.length();
    if !is_positive(dist) {
        return None;
    }
    let pdf = area_to_solid_angle(pdf_area, p, p_light, n_light);
    (is_positive(pdf) && pdf.is_finite()).then_some(LightLiSample {
        wi: d / dist,
        li: l,
        pdf,
        p_light,
        delta: false,
    })
}

/// A direction drawn by solid angle with density `pdf`, reaching the emitter at `p_light`.
#[inline]
pub(crate) fn solid_angle_sample(
    wi: Vec3,
    p_light: Vec3,
    pdf: f32,
    l: Rgb,
) -> Option<LightLiSample> {
    (is_positive(pdf) && pdf.is_finite()).then_some(LightLiSample {
        wi,
        li: l,
        pdf,
        p_light,
        delta: false,
    })
}

/// Whether a receiver at `p` sees the emitting side of the plane through `origin` with unit
/// normal `n`: one-sided emitters are dark from behind, and nothing is seen from the plane.
#[inline]
pub(crate) fn sees_emitting_side(n: Vec3, origin: Vec3, two_sided: bool, p: Vec3) -> bool {
    let s = n.dot(p - origin);
    if two_sided { s != 0.0 } else { s > 0.0 }
}

/// A flat diffuse emitter of constant radiance (triangle, quad, disk): what their one shared
/// [`Emitter`] impl needs.
pub(crate) trait Planar: LightSource {
    /// Unit geometric normal on the emitting side.
    fn normal(&self) -> Vec3;
    /// Emitted radiance.
    fn emitted(&self) -> Rgb;
    /// Emits on both sides.
    fn is_two_sided(&self) -> bool;
    /// Surface area.
    fn surface_area(&self) -> f32;
    /// Whether a receiver at `p` sees the emitting side (one-sided emitters are dark from
    /// behind; nothing is seen from the plane itself).
    fn faces(&self, p: Vec3) -> bool;
    /// Solid angle Ω that `sample_li` samples uniformly from `p` in `mode`, or `None` where it
    /// samples by area. `sample_li` and `pdf_li` decide by this one rule and use this Ω, so
    /// a sample and its pdf agree.
    fn spherical_omega(&self, p: Vec3, mode: SamplingMode) -> Option<f32>;

    /// The light-BVH bounds of this emitter inside the box `min`..`max`: one normal
    /// (cos θo = 1) and diffuse emission over its hemisphere (cos θe = 0).
    fn planar_bounds(&self, min: Vec3, max: Vec3) -> Option<LightBounds> {
        Some(LightBounds {
            min,
            max,
            w: self.normal(),
            phi: self.power(),
            cos_theta_o: 1.0,
            cos_theta_e: 0.0,
            two_sided: self.is_two_sided(),
        })
    }
}

impl<T: Planar> Emitter for T {
    /// 1/Ω where the shape's rule chose solid-angle sampling, else the area pdf 1/A converted;
    /// zero where the receiver does not face the emitting side (`sample_li` never samples
    /// there). The caller guarantees that the direction hits the emitter, so no inside test.
    #[inline]
    fn pdf_li(
        &self,
        ctx: &LightSampleContext,
        _wi: Vec3,
        p_light: Vec3,
        _n_light: Vec3,
        mode: SamplingMode,
    ) -> f32 {
        if !self.faces(ctx.p) {
            return 0.0;
        }
        match self.spherical_omega(ctx.p, mode) {
            Some(omega) => 1.0 / omega,
            None => area_to_solid_angle(1.0 / self.surface_area(), ctx.p, p_light, self.normal()),
        }
    }

    /// The constant radiance on the emitting side(s), zero behind a one-sided emitter.
    #[inline]
    fn radiance(&self, _p: Vec3, _n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        if self.is_two_sided() || self.normal().dot(w) > 0.0 {
            self.emitted()
        } else {
            Rgb::ZERO
        }
    }
}

/// Power Φ of a diffuse emitter of radiance `l` and area `area`: π·L·A per emitting side.
#[inline]
pub(crate) fn diffuse_power(l: Rgb, area: f32, two_sided: bool) -> f32 {
    let sides = if two_sided { 2.0 } else { 1.0 };
    crate::luminance(l) * area * std::f32::consts::PI * sides
}

/// `x > 0`, false for NaN: guards written as `!is_positive(x)` reject NaN along with
/// non-positive values (a plain `x <= 0.0` would let NaN through).
#[inline]
pub(crate) fn is_positive(x: f32) -> bool {
    x > 0.0
}

/// Endpoint of a shadow ray toward a light at infinity: twice the scene radius along `wi`,
/// safely outside the scene's bounding sphere from any point inside it.
#[inline]
pub(crate) fn far_point(p: Vec3, wi: Vec3, scene_radius: f32) -> Vec3 {
    p + wi * (2.0 * scene_radius)
}

//! Image environment light in one of two layouts, importance-sampled by a piecewise-constant
//! 2D distribution over its pixels.
//!
//! - Equal-area octahedral (pbrt-v4's `ImageInfiniteLight`, square images): a light-space
//!   direction maps to the square by Clarberg's equal-area map ([`crate::sampling::equal_area`]);
//!   radiance is the nearest texel (pbrt-v4's `LookupNearest` with octahedral wrapping); the
//!   distribution is each texel's mean of the (clamped) channels, and since every texel covers
//!   the same solid angle 4π/n², the solid-angle pdf is pdf_uv / 4π.
//! - Latitude-longitude (equirectangular; what penumbra reads when a map is not square): in
//!   light space z is up; a direction (sin θ cos φ, sin θ sin φ, cos θ) maps to u = φ/2π ∈ [0, 1)
//!   across the image and v = θ/π ∈ [0, 1] down it, so row 0 (the top) is the zenith θ = 0 and
//!   the bottom row the nadir; radiance is bilinear; the distribution is built from
//!   luminance × sin θ (sin θ is the Jacobian of the lat-long map, dω = 2π² sin θ du dv), so
//!   the solid-angle pdf is pdf_uv / (2π² sin θ).
//!
//! `light_to_world` (a rotation, possibly with uniform scale or a mirror) carries light-space
//! directions into the world.

use super::distant::DEFAULT_SCENE_RADIUS;
use super::{
    Emitter, LightBounds, LightLiSample, LightSampleContext, LightSource, SamplingMode, far_point,
    is_positive,
};
use crate::material::texture::ImageRgb;
use crate::sampling::Distribution2D;
use crate::sampling::equal_area::{
    equal_area_sphere_to_square, equal_area_square_to_sphere, wrap_octahedral_texel,
};
use crate::{Rgb, luminance};
use anyhow::{Result, bail};
use glam::{Mat3, Vec2, Vec3};
use std::f32::consts::{PI, TAU};
use std::sync::Arc;

/// How an environment image covers the sphere.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvLayout {
    /// pbrt-v4's equal-area octahedral square.
    EqualArea,
    /// Latitude-longitude (row 0 = zenith).
    LatLong,
}

/// Image environment light.
#[derive(Clone, Debug)]
pub struct EnvMapLight {
    /// The map.
    pub image: Arc<ImageRgb>,
    /// Its layout.
    pub layout: EnvLayout,
    /// Radiance multiplier.
    pub scale: Rgb,
    /// Light-to-world rotation (orthonormal columns).
    pub to_world: Mat3,
    /// Distribution over (u, v): ∝ luminance × sin θ (lat-long), ∝ texel channel mean
    /// (equal-area).
    pub distribution: Distribution2D,
    /// Average radiance luminance over the sphere (for power).
    pub mean_luminance: f32,
    /// Scene bounding-sphere radius (from preprocess).
    pub scene_radius: f32,
}

impl EnvMapLight {
    /// A lat-long light and its sampling distribution. Errors on an empty or inconsistent
    /// image, non-finite pixels or scale, or a transform that is not a rotation up to uniform
    /// scale (shear or non-uniform scale would distort solid angles and break the pdf).
    pub fn new(
        image: Arc<ImageRgb>,
        scale: Rgb,
        light_to_world: crate::geometry::Transform,
    ) -> Result<Self> {
        let to_world = check(&image, scale, light_to_world)?;
        let (w, h) = (image.width as usize, image.height as usize);
        // Per-pixel importance: bilinear lookups reach one pixel into the neighbours, so the
        // 3×3 maximum (averaged with the pixel itself, to keep peaks sharp) is positive wherever
        // the interpolated radiance is; a tiny floor keeps the pdf positive everywhere anyway.
        let lum: Vec<f32> = image
            .pixels
            .iter()
            .map(|&p| luminance(p.max(Rgb::ZERO) * scale.abs()))
            .collect();
        let at = |x: isize, y: isize| {
            let x = x.rem_euclid(w as isize) as usize;
            let y = y.clamp(0, h as isize - 1) as usize;
            lum[y * w + x]
        };
        let mut f = vec![0.0f32; w * h];
        let (mut total, mut total_sin, mut mean_num) = (0.0f64, 0.0f64, 0.0f64);
        for y in 0..h {
            let sin_theta = (PI * (y as f32 + 0.5) / h as f32).sin();
            for x in 0..w {
                let (xi, yi) = (x as isize, y as isize);
                let mut mx = 0.0f32;
                for dy in -1..=1 {
                    for dx in -1..=1 {
                        mx = mx.max(at(xi + dx, yi + dy));
                    }
                }
                let v = 0.5 * (lum[y * w + x] + mx) * sin_theta;
                f[y * w + x] = v;
                total += v as f64;
                total_sin += sin_theta as f64;
                mean_num += (lum[y * w + x] * sin_theta) as f64;
            }
        }
        let floor = if total > 0.0 {
            (1e-4 * total / total_sin) as f32
        } else {
            1.0
        };
        for y in 0..h {
            let sin_theta = (PI * (y as f32 + 0.5) / h as f32).sin();
            for v in &mut f[y * w..(y + 1) * w] {
                *v += floor * sin_theta;
            }
        }
        Ok(Self {
            distribution: Distribution2D::new(&f, w, h),
            mean_luminance: (mean_num / total_sin) as f32,
            image,
            layout: EnvLayout::LatLong,
            scale,
            to_world,
            scene_radius: DEFAULT_SCENE_RADIUS,
        })
    }

    /// pbrt-v4's equal-area octahedral light of a square image, sampled in proportion to each
    /// texel's mean (clamped) channel value as pbrt-v4 does. Errors as [`EnvMapLight::new`],
    /// and on a non-square image.
    pub fn equal_area(
        image: Arc<ImageRgb>,
        scale: Rgb,
        light_to_world: crate::geometry::Transform,
    ) -> Result<Self> {
        let to_world = check(&image, scale, light_to_world)?;
        if image.width != image.height {
            bail!(
                "environment map: an equal-area map must be square, found {}x{}",
                image.width,
                image.height
            );
        }
        let n = image.width as usize;
        let scaled = |p: Rgb| p.max(Rgb::ZERO) * scale.abs();
        let f: Vec<f32> = image
            .pixels
            .iter()
            .map(|&p| {
                let c = scaled(p);
                (c.x + c.y + c.z) / 3.0
            })
            .collect();
        // Every texel covers the same solid angle: the sphere's mean is the texels' mean.
        let mean: f64 = image
            .pixels
            .iter()
            .map(|&p| luminance(scaled(p)) as f64)
            .sum::<f64>()
            / (n * n) as f64;
        Ok(Self {
            // All-zero maps get a uniform distribution (Distribution1D's rule).
            distribution: Distribution2D::new(&f, n, n),
            mean_luminance: mean as f32,
            image,
            layout: EnvLayout::EqualArea,
            scale,
            to_world,
            scene_radius: DEFAULT_SCENE_RADIUS,
        })
    }

    /// Record the scene's bounding sphere (for shadow-ray endpoints and power).
    pub fn preprocess(&mut self, _center: Vec3, radius: f32) {
        if radius > 0.0 && radius.is_finite() {
            self.scene_radius = radius;
        }
    }

    /// Map coordinates (u, v) of a world direction, and the Jacobian factor there (sin θ for
    /// lat-long, 1 for equal-area).
    #[inline]
    pub fn direction_to_uv(&self, w: Vec3) -> (Vec2, f32) {
        let d = (self.to_world.transpose() * w).normalize();
        if self.layout == EnvLayout::EqualArea {
            return (equal_area_sphere_to_square(d), 1.0);
        }
        let cos_theta = d.z.clamp(-1.0, 1.0);
        let sin_theta = (d.x * d.x + d.y * d.y).sqrt();
        let theta = sin_theta.atan2(cos_theta);
        let mut phi = d.y.atan2(d.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let u = phi / TAU;
        let u = if u >= 1.0 { 0.0 } else { u };
        (Vec2::new(u, theta / PI), sin_theta)
    }

    /// World direction of map coordinates (u, v), and the Jacobian factor there (sin θ for
    /// lat-long, 1 for equal-area).
    #[inline]
    pub fn uv_to_direction(&self, uv: Vec2) -> (Vec3, f32) {
        if self.layout == EnvLayout::EqualArea {
            return (
                (self.to_world * equal_area_square_to_sphere(uv)).normalize(),
                1.0,
            );
        }
        let (sin_t, cos_t) = (uv.y * PI).sin_cos();
        let (sin_p, cos_p) = (uv.x * TAU).sin_cos();
        let d = Vec3::new(sin_t * cos_p, sin_t * sin_p, cos_t);
        ((self.to_world * d).normalize(), sin_t)
    }

    /// Solid-angle density of a direction whose map density is `pdf_uv` and Jacobian factor
    /// `jac` ([`EnvMapLight::uv_to_direction`]).
    #[inline]
    fn solid_angle_pdf(&self, pdf_uv: f32, jac: f32) -> f32 {
        match self.layout {
            EnvLayout::EqualArea => pdf_uv / (4.0 * PI),
            EnvLayout::LatLong => pdf_uv / (2.0 * PI * PI * jac),
        }
    }

    /// Scaled radiance at map coordinates. Equal-area: the nearest texel, wrapping across the
    /// square's edges as the octahedron does (pbrt-v4). Lat-long: bilinear, wrapping in u,
    /// clamped in v (wrapping in v would blend the zenith with the nadir).
    pub fn lookup(&self, uv: Vec2) -> Rgb {
        let (w, h) = (self.image.width as isize, self.image.height as isize);
        if self.layout == EnvLayout::EqualArea {
            let (x, y) = wrap_octahedral_texel(
                (uv.x * w as f32).floor() as i64,
                (uv.y * h as f32).floor() as i64,
                w as i64,
            );
            return self.image.pixels[y * w as usize + x].max(Rgb::ZERO) * self.scale;
        }
        let x = uv.x * w as f32 - 0.5;
        let y = uv.y * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: isize, j: isize| {
            let i = i.rem_euclid(w) as usize;
            let j = j.clamp(0, h - 1) as usize;
            self.image.pixels[j * w as usize + i]
        };
        let (xi, yi) = (x0 as isize, y0 as isize);
        let c = at(xi, yi) * (1.0 - fx) * (1.0 - fy)
            + at(xi + 1, yi) * fx * (1.0 - fy)
            + at(xi, yi + 1) * (1.0 - fx) * fy
            + at(xi + 1, yi + 1) * fx * fy;
        c.max(Rgb::ZERO) * self.scale
    }
}

/// Validate an environment image, its scale and transform; the light-to-world rotation.
fn check(image: &ImageRgb, scale: Rgb, light_to_world: crate::geometry::Transform) -> Result<Mat3> {
    let (w, h) = (image.width as usize, image.height as usize);
    if w == 0 || h == 0 || image.pixels.len() != w * h {
        bail!(
            "environment map: bad image {}x{} with {} pixels",
            image.width,
            image.height,
            image.pixels.len()
        );
    }
    if !scale.is_finite() || image.pixels.iter().any(|p| !p.is_finite()) {
        bail!("environment map: non-finite pixel or scale");
    }
    let m = Mat3::from_mat4(light_to_world.m);
    let cols = [m.x_axis, m.y_axis, m.z_axis];
    let len = cols[0].length();
    let ortho = len > 0.0
        && len.is_finite()
        && cols.iter().all(|c| (c.length() / len - 1.0).abs() < 1e-3)
        && (cols[0].dot(cols[1]).abs() + cols[1].dot(cols[2]).abs() + cols[2].dot(cols[0]).abs())
            / (len * len)
            < 1e-3;
    if !ortho {
        bail!("environment map: light-to-world transform must be a rotation");
    }
    Ok(Mat3::from_cols(cols[0] / len, cols[1] / len, cols[2] / len))
}

impl LightSource for EnvMapLight {
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        _mode: SamplingMode,
    ) -> Option<LightLiSample> {
        let (uv, pdf_uv) = self.distribution.sample(u);
        let (wi, jac) = self.uv_to_direction(uv);
        if !is_positive(jac) || !is_positive(pdf_uv) {
            return None;
        }
        let pdf = self.solid_angle_pdf(pdf_uv, jac);
        pdf.is_finite().then(|| LightLiSample {
            wi,
            li: self.lookup(uv),
            pdf,
            p_light: far_point(ctx.p, wi, self.scene_radius),
            delta: false,
        })
    }

    /// Flux entering the scene's bounding sphere, 4πr² · π · mean L (pbrt-v4).
    fn power(&self) -> f32 {
        4.0 * PI * PI * self.scene_radius * self.scene_radius * self.mean_luminance
    }

    fn bounds(&self) -> Option<LightBounds> {
        None
    }
}

impl Emitter for EnvMapLight {
    fn pdf_li(
        &self,
        _ctx: &LightSampleContext,
        wi: Vec3,
        _: Vec3,
        _: Vec3,
        _: SamplingMode,
    ) -> f32 {
        let (uv, jac) = self.direction_to_uv(wi);
        if !is_positive(jac) {
            return 0.0;
        }
        // The square's far edges (u or v = 1) belong to the last texel.
        let uv = uv.min(Vec2::splat(crate::sampling::ONE_MINUS_EPSILON));
        self.solid_angle_pdf(self.distribution.pdf(uv), jac)
    }

    fn radiance(&self, _p: Vec3, _n: Vec3, _uv: Vec2, w: Vec3) -> Rgb {
        self.lookup(self.direction_to_uv(w).0)
    }
}

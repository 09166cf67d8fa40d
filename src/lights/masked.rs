//! An emissive triangle with an alpha cut-out (pbrt-v4's `"float alpha"` / `"texture alpha"`
//! on an area light): where the coverage is a, the surface emits a·L on average. A BSDF ray
//! finds that through the hit test itself (it keeps a hit with probability a, then sees L); a
//! light sample draws its point exactly as the unmasked triangle would and weighs L by the
//! coverage there, so both strategies estimate the same integral and MIS combines them. (The
//! deterministic weight has less variance than pbrt-v4's stochastic test at the sampled point,
//! and agrees with it for the binary masks real scenes use.)

use super::{LightBounds, LightLiSample, LightSampleContext, LightSource, Planar, SamplingMode};
use super::{TriangleLight, diffuse_power};
use crate::Rgb;
use crate::geometry::Alpha;
use glam::{Vec2, Vec3};

/// Coverage samples per triangle for the power of a textured mask (a 4 × 4 barycentric grid).
const POWER_PROBES: u32 = 4;

/// Share of the unmasked power a textured mask's light keeps at least, so that a triangle the
/// probes all saw as cut away still has a chance wherever the texture lets some light out.
const MIN_POWER_SHARE: f32 = 1.0 / 16.0;

/// A [`TriangleLight`] whose emission is masked by `alpha` over the uv of its vertices.
#[derive(Clone, Debug)]
pub struct MaskedTriangleLight {
    /// The triangle as if unmasked: its samples, pdfs and hit radiance.
    pub tri: TriangleLight,
    /// Texture coordinates of the three vertices.
    pub uv: [Vec2; 3],
    /// The coverage over uv.
    pub alpha: Alpha,
    /// Mean coverage over the triangle (constant masks: exact; textures: probed).
    coverage: f32,
    /// (p1 − p0) × (p2 − p0) / its squared length: barycentrics of a point are two triple
    /// products with it, so a light sample needs no cross product of the edges.
    bary_axis: Vec3,
}

impl MaskedTriangleLight {
    /// The light of `tri` under the mask `alpha`; `None` where the mask removes it entirely
    /// (a constant coverage ≤ 0, which no ray hits).
    pub fn new(tri: TriangleLight, uv: [Vec2; 3], alpha: Alpha) -> Option<Self> {
        let coverage = match &alpha {
            Alpha::Constant(a) if !(*a > 0.0) => return None,
            Alpha::Constant(a) => a.min(1.0),
            Alpha::Texture(_) => {
                let n = POWER_PROBES;
                let mut sum = 0.0;
                for i in 0..n {
                    for j in 0..n {
                        let s = ((i as f32 + 0.5) / n as f32).sqrt();
                        let t = (j as f32 + 0.5) / n as f32;
                        sum += Self::coverage_at(&alpha, &uv, [1.0 - s, s * (1.0 - t), s * t]);
                    }
                }
                (sum / (n * n) as f32).max(MIN_POWER_SHARE)
            }
        };
        let [p0, p1, p2] = tri.p;
        let n = (p1 - p0).cross(p2 - p0);
        Some(Self {
            tri,
            uv,
            alpha,
            coverage,
            bary_axis: n / n.length_squared(),
        })
    }

    /// Coverage in [0, 1] at barycentrics `b` (weights of the three vertices).
    fn coverage_at(alpha: &Alpha, uv: &[Vec2; 3], b: [f32; 3]) -> f32 {
        let st = uv[0] * b[0] + uv[1] * b[1] + uv[2] * b[2];
        alpha.coverage(st).clamp(0.0, 1.0)
    }

    /// Barycentrics of `p` (a point on the triangle's plane), clamped onto the triangle.
    fn barycentrics(&self, p: Vec3) -> [f32; 3] {
        let [p0, p1, p2] = self.tri.p;
        let b1 = (p - p0).cross(p2 - p0).dot(self.bary_axis).max(0.0);
        let b2 = (p1 - p0).cross(p - p0).dot(self.bary_axis).max(0.0);
        let s = b1 + b2;
        let (b1, b2) = if s > 1.0 { (b1 / s, b2 / s) } else { (b1, b2) };
        [1.0 - b1 - b2, b1, b2]
    }
}

impl LightSource for MaskedTriangleLight {
    fn sample_li(
        &self,
        ctx: &LightSampleContext,
        u: Vec2,
        mode: SamplingMode,
    ) -> Option<LightLiSample> {
        let mut s = self.tri.sample_li(ctx, u, mode)?;
        let a = Self::coverage_at(&self.alpha, &self.uv, self.barycentrics(s.p_light));
        if !(a > 0.0) {
            return None;
        }
        s.li *= a;
        Some(s)
    }

    fn power(&self) -> f32 {
        diffuse_power(self.tri.l, self.tri.area, self.tri.two_sided) * self.coverage
    }

    fn bounds(&self) -> Option<LightBounds> {
        let p = self.tri.p;
        self.planar_bounds(p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]))
    }
}

/// The unmasked triangle's geometry and pdfs: the mask changes what a sample carries, not
/// where samples fall. `emitted` is the full L, which a BSDF ray sees at the hits the mask
/// keeps.
impl Planar for MaskedTriangleLight {
    #[inline]
    fn normal(&self) -> Vec3 {
        self.tri.normal()
    }
    #[inline]
    fn emitted(&self) -> Rgb {
        self.tri.emitted()
    }
    #[inline]
    fn is_two_sided(&self) -> bool {
        self.tri.is_two_sided()
    }
    #[inline]
    fn surface_area(&self) -> f32 {
        self.tri.surface_area()
    }
    #[inline]
    fn faces(&self, p: Vec3) -> bool {
        self.tri.faces(p)
    }
    fn spherical_omega(&self, p: Vec3, mode: SamplingMode) -> Option<f32> {
        self.tri.spherical_omega(p, mode)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> TriangleLight {
        let p = [Vec3::ZERO, Vec3::X, Vec3::Y];
        TriangleLight::new(p, Vec3::Z, Rgb::ONE, false).unwrap()
    }

    #[test]
    fn barycentrics_recover_the_vertices_weights() {
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let m = MaskedTriangleLight::new(tri(), uv, Alpha::Constant(0.5)).unwrap();
        let b = m.barycentrics(Vec3::new(0.2, 0.3, 0.0));
        assert!(
            (b[0] - 0.5).abs() < 1e-6 && (b[1] - 0.2).abs() < 1e-6 && (b[2] - 0.3).abs() < 1e-6
        );
        // A point just outside (rounding of a plane intersection) lands on the edge.
        let b = m.barycentrics(Vec3::new(0.6, 0.5, 0.0));
        assert!(b.iter().all(|&w| w >= 0.0) && (b.iter().sum::<f32>() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn power_scales_by_the_mean_coverage_and_zero_coverage_is_no_light() {
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let full = tri().power();
        let m = MaskedTriangleLight::new(tri(), uv, Alpha::Constant(0.25)).unwrap();
        assert!((m.power() - 0.25 * full).abs() < 1e-6);
        assert!(MaskedTriangleLight::new(tri(), uv, Alpha::Constant(0.0)).is_none());
        assert!(MaskedTriangleLight::new(tri(), uv, Alpha::Constant(f32::NAN)).is_none());
    }
}

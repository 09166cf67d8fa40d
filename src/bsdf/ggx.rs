//! Trowbridge–Reitz (GGX) microfacet distribution, isotropic or anisotropic, with Smith
//! masking–shadowing and visible-normal sampling (Heitz 2018, "Sampling the GGX Distribution of
//! Visible Normals"). All directions are in the local shading frame (z = macro normal).

use crate::sampling::{concentric_disk, safe_sqrt};
use glam::{Vec2, Vec3};
use std::f32::consts::PI;

/// Below this roughness (both axes) a surface is treated as perfectly smooth (delta lobe):
/// the GGX lobe would be narrower than f32 can resolve reliably.
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// pbrt-v4's roughness remap (`TrowbridgeReitzDistribution::RoughnessToAlpha`): α = √r, so that
/// a perceptually linear "roughness" parameter maps to the GGX width.
#[inline]
pub fn roughness_to_alpha(roughness: f32) -> f32 {
    roughness.max(0.0).sqrt()
}

/// True when `alpha` is below [`SMOOTH_ALPHA`] on both axes.
#[inline]
pub fn is_smooth(alpha: Vec2) -> bool {
    alpha.max_element() < SMOOTH_ALPHA
}

/// GGX distribution with widths `alpha_x`, `alpha_y` along the local x and y axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrowbridgeReitz {
    /// Width along x.
    pub alpha_x: f32,
    /// Width along y.
    pub alpha_y: f32,
}

impl TrowbridgeReitz {
    /// Distribution with widths `alpha` (clamped to ≥ 1e-4 so that D stays finite in f32).
    #[inline]
    pub fn new(alpha: Vec2) -> Self {
        let a = if alpha.is_finite() {
            alpha.max(Vec2::splat(1e-4))
        } else {
            Vec2::ONE
        };
        Self {
            alpha_x: a.x,
            alpha_y: a.y,
        }
    }

    /// Microfacet normal density D(wm) (per projected area: ∫ D(wm) cos θm dωm = 1).
    #[inline]
    pub fn d(&self, wm: Vec3) -> f32 {
        if wm.z <= 0.0 {
            return 0.0;
        }
        // cos⁴θ (1 + tan²θ (cos²φ/αx² + sin²φ/αy²))² = (z² + x²/αx² + y²/αy²)² for unit wm,
        // which avoids tan θ blowing up near grazing.
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let q = wm.z * wm.z + (wm.x / ax).powi(2) + (wm.y / ay).powi(2);
        1.0 / (PI * ax * ay * q * q)
    }

    /// Smith auxiliary function Λ(w).
    #[inline]
    pub fn lambda(&self, w: Vec3) -> f32 {
        let z2 = w.z * w.z;
        if z2 == 0.0 {
            return f32::INFINITY;
        }
        let a2_tan2 = ((self.alpha_x * w.x).powi(2) + (self.alpha_y * w.y).powi(2)) / z2;
        0.5 * ((1.0 + a2_tan2).sqrt() - 1.0)
    }

    /// Smith masking G1(w) = 1 / (1 + Λ(w)).
    #[inline]
    pub fn g1(&self, w: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// Height-correlated masking–shadowing G(wo, wi) = 1 / (1 + Λ(wo) + Λ(wi)).
    #[inline]
    pub fn g(&self, wo: Vec3, wi: Vec3) -> f32 {
        1.0 / (1.0 + self.lambda(wo) + self.lambda(wi))
    }

    /// Distribution of normals visible from `w`: D_w(wm) = G1(w)/cos θ · D(wm) · max(0, w·wm).
    /// This is the density (per solid angle of wm) that [`TrowbridgeReitz::sample_wm`] draws.
    #[inline]
    pub fn pdf(&self, w: Vec3, wm: Vec3) -> f32 {
        let cos = w.z.abs();
        let wdm = w.dot(wm);
        if cos == 0.0 || wdm <= 0.0 {
            return 0.0;
        }
        self.g1(w) / cos * self.d(wm) * wdm
    }

    /// Draw a visible microfacet normal for `w` (w.z > 0): stretch the view to the unit-roughness
    /// configuration, sample the projected hemisphere (a disk whose far half is foreshortened by
    /// the view), lift to the hemisphere and unstretch.
    pub fn sample_wm(&self, w: Vec3, u: Vec2) -> Vec3 {
        let (ax, ay) = (self.alpha_x, self.alpha_y);
        let wh = Vec3::new(ax * w.x, ay * w.y, w.z).normalize();
        let len2 = wh.x * wh.x + wh.y * wh.y;
        let t1 = if len2 > 1e-14 {
            Vec3::new(-wh.y, wh.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = wh.cross(t1);
        let mut p = concentric_disk(u);
        // Warp the disk so that its density matches the projected area of the visible half.
        let s = 0.5 * (1.0 + wh.z);
        p.y = (1.0 - s) * safe_sqrt(1.0 - p.x * p.x) + s * p.y;
        let nh = p.x * t1 + p.y * t2 + safe_sqrt(1.0 - p.length_squared()) * wh;
        Vec3::new(ax * nh.x, ay * nh.y, nh.z.max(1e-6)).normalize()
    }
}

//! Alpha cut-outs (pbrt-v4's shape `"float alpha"` / `"texture alpha"`): a mesh's coverage in
//! [0, 1] over its uv. A ray's hit on such a surface counts when the coverage a at the hit is
//! 1, never when a ≤ 0, and otherwise when a hash of the ray (and of the primitive, so that
//! stacked cut-outs decide independently) falls at or below a — pbrt-v4's stochastic alpha
//! test, deterministic for a given ray. Camera, BSDF and shadow rays all see the same test, so
//! a surface of coverage a passes a fraction 1 − a of the light.

use crate::sampling::hash::{hash_keys, u32_to_unit};
use glam::{Vec2, Vec3};
use std::fmt::Debug;
use std::sync::Arc;

/// A coverage that varies over the surface (a float texture), evaluated at a hit's uv.
pub trait AlphaTexture: Send + Sync + Debug {
    /// Coverage at texture coordinates `uv` (values outside [0, 1] act as clamped).
    fn alpha(&self, uv: Vec2) -> f32;
}

/// A mesh's alpha mask.
#[derive(Clone, Debug)]
pub enum Alpha {
    /// The same coverage everywhere (pbrt-v4's `"float alpha"`).
    Constant(f32),
    /// Coverage from a texture over uv (pbrt-v4's `"texture alpha"`).
    Texture(Arc<dyn AlphaTexture>),
}

impl Alpha {
    /// Coverage at `uv`.
    #[inline]
    pub fn coverage(&self, uv: Vec2) -> f32 {
        match self {
            Alpha::Constant(a) => *a,
            Alpha::Texture(t) => t.alpha(uv),
        }
    }

    /// True if the hit at `uv` of the ray (`o`, `d`) on the triangle named by `key` counts.
    #[inline]
    pub fn keeps(&self, uv: Vec2, o: Vec3, d: Vec3, key: u64) -> bool {
        let a = self.coverage(uv);
        if a >= 1.0 {
            return true;
        }
        if a.is_nan() || a <= 0.0 {
            return false;
        }
        alpha_hash(o, d, key) <= a
    }
}

/// A uniform number in [0, 1) from the ray's bits and a key naming the surface.
#[inline]
pub fn alpha_hash(o: Vec3, d: Vec3, key: u64) -> f32 {
    let b = |v: f32| v.to_bits() as u64;
    let h = hash_keys(&[
        b(o.x) | b(o.y) << 32,
        b(o.z) | b(d.x) << 32,
        b(d.y) | b(d.z) << 32,
        key,
    ]);
    u32_to_unit((h >> 32) as u32)
}

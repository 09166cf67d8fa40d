//! What a closest-hit query returns.

use super::Ray;
use crate::sampling::Frame;
use glam::{Vec2, Vec3};

/// Sentinel for "no area light attached".
pub const NO_LIGHT: u32 = u32::MAX;

/// A ray–surface intersection.
///
/// Normal conventions follow pbrt-v4: `ng` is the geometric normal of the primitive (for
/// triangle meshes with per-vertex normals it is flipped to the side of the shading normal;
/// otherwise its orientation follows the winding/ReverseOrientation). It is *not* flipped
/// toward the ray; one-sided area lights emit on the side of `ng`.
#[derive(Clone, Copy, Debug)]
// C layout: sixteen 4-byte fields in this order, which the packet queries write as one
// 64-byte row (`SurfaceHit::from_lanes`).
#[repr(C)]
pub struct SurfaceHit {
    /// Ray parameter of the hit.
    pub t: f32,
    /// Hit point (world space).
    pub p: Vec3,
    /// Unit geometric normal.
    pub ng: Vec3,
    /// Unit shading normal (interpolated, same hemisphere as `ng`).
    pub ns: Vec3,
    /// Surface parameterisation (texture coordinates).
    pub uv: Vec2,
    /// Conservative absolute error bound of `p` along `ng` (with room for the rounding of a
    /// spawned ray's origin), the offset of spawned rays.
    pub p_error: f32,
    /// Index of the primitive in the scene's geometry.
    pub prim: u32,
    /// Material index into `Scene::materials`.
    pub material: u32,
    /// Index into `Scene::lights` of the area light on this primitive, or [`NO_LIGHT`].
    pub light: u32,
}

// The layout `from_lanes` relies on: no padding.
const _: () = assert!(std::mem::size_of::<SurfaceHit>() == 64);

impl SurfaceHit {
    /// The hit whose fields, in declaration order, have the bit patterns `a` (f32 and u32
    /// fields alike).
    #[inline(always)]
    pub(super) fn from_lanes(a: [f32; 16]) -> Self {
        // SAFETY: `SurfaceHit` is `repr(C)` with sixteen 4-byte fields (glam's `Vec3` and
        // `Vec2` are `repr(C)` structs of f32) and no padding (size 64, asserted above);
        // every bit pattern is a valid f32 and u32.
        unsafe { std::mem::transmute::<[f32; 16], SurfaceHit>(a) }
    }

    /// Origin for a ray leaving the surface toward direction `w`: `p` moved along ±ng (the
    /// side of `w`) by `p_error`, which bounds both the point's error and the rounding of
    /// this sum (pbrt-v4's `OffsetRayOrigin`, its step of one ulp per coordinate folded into
    /// the bound). The origin is then on the surface's `w` side or, where the bound is zero
    /// (a hit on the plane x = 0 has an exact x), exactly on it; either way the surface lies
    /// at t ≤ 0 of the spawned ray, and the triangle tests reject hits that are not provably
    /// beyond t = 0 (`self_hit_bound`), so the ray cannot hit the surface it leaves. (Quadrics
    /// are solved in f64 after an f32 map to object space: the offset alone suffices, with
    /// the margin over that map's error that tests/geometry.rs measures.)
    #[inline]
    pub fn spawn_origin(&self, w: Vec3) -> Vec3 {
        let off = self.ng * self.p_error;
        if w.dot(self.ng) >= 0.0 {
            self.p + off
        } else {
            self.p - off
        }
    }

    /// A shadow ray from this hit to just short of `target`: leaving from
    /// [`Self::spawn_origin`] toward `target`, with direction `target − origin` and
    /// t_max = [`SHADOW_T_MAX`].
    ///
    /// The far end is shortened by a relative [`SHADOW_EPSILON`] instead of being offset by
    /// an error bound as the near end is (pbrt-v4's `SpawnRayTo` offsets both): a light
    /// sample carries no error bound here (solid-angle samples are not barycentric
    /// combinations, whose bound the hit records use), and the relative gap, 1e-4 of the
    /// distance, exceeds the few-ulp error of the sampled point (~1e-7 of its coordinates)
    /// unless the receiver is closer to the light point than ~1e-3 of that point's distance
    /// from the origin: receivers in contact with a light, which this rule accepts. At the
    /// near end no relative gap can work: there the rounding is absolute and t starts at 0.
    #[inline]
    pub fn spawn_ray_to(&self, target: Vec3) -> Ray {
        let o = self.spawn_origin(target - self.p);
        Ray {
            o,
            d: target - o,
            t_max: SHADOW_T_MAX,
        }
    }
}

/// Shadow rays stop this fraction of their length short of the light point so they do not
/// hit the light itself.
pub const SHADOW_EPSILON: f32 = 1e-4;

/// The `t_max` of every shadow ray (its direction spans origin to light point).
pub const SHADOW_T_MAX: f32 = 1.0 - SHADOW_EPSILON;

/// How a hit is seen along a ray: the set-up every estimator does before sampling there.
#[derive(Clone, Copy, Debug)]
pub struct ShadingGeometry {
    /// Unit direction toward the viewer.
    pub wo: Vec3,
    /// The ray arrives on the side the geometric normal points to.
    pub front: bool,
    /// Geometric normal flipped toward the viewer.
    pub n: Vec3,
    /// Shading frame around the shading normal flipped toward the viewer.
    pub frame: Frame,
    /// `wo` in `frame`.
    pub wo_local: Vec3,
}

impl ShadingGeometry {
    /// The shading geometry of a hit with geometric normal `ng` and shading normal `ns` seen
    /// along ray direction `d`.
    #[inline(always)]
    pub fn new(d: Vec3, ng: Vec3, ns: Vec3) -> Self {
        let wo = -d.normalize();
        let front = d.dot(ng) < 0.0;
        let n = if front { ng } else { -ng };
        let ns = if ns.dot(wo) < 0.0 { -ns } else { ns };
        let frame = Frame::from_normal(ns);
        Self {
            wo,
            front,
            n,
            frame,
            wo_local: frame.to_local(wo),
        }
    }
}

//! Shared machinery of the estimation passes of [`super::wald`] and [`super::adaptive`]: a
//! low-resolution grid of eye rays through the scene's camera, and the measured contribution
//! of one light at one hit (one light sample, shadow ray included).
//!
//! Every random number is a pure function of (seed, pass, pixel, draw), and results are
//! gathered in pixel order, so the passes are deterministic under any thread schedule.

use crate::bsdf::{Bsdf, Bxdf, gathers_from};
use crate::geometry::ray::Ray;
use crate::geometry::{RayQuery, ShadingGeometry, SurfaceHit};
use crate::lights::{LightSampleContext, LightSource, SamplingMode};
use crate::luminance;
use crate::sampling::Frame;
use crate::sampling::hash::{next_f32, pcg_from_keys};
use crate::scene::Scene;
use glam::{UVec2, Vec2, Vec3};
use rand_pcg::Pcg32;

use super::ShadingPoint;

/// A camera-ray hit prepared for light sampling.
pub struct EyeHit {
    /// The hit.
    pub hit: SurfaceHit,
    /// What a selector sees.
    pub sp: ShadingPoint,
    /// A vertex after a bounce (not a camera-ray hit).
    pub secondary: bool,
    bsdf: Bsdf,
    frame: Frame,
    wo_local: Vec3,
    /// Geometric normal flipped toward the viewer (`sp.n` is zero for transmitting BSDFs).
    n: Vec3,
}

/// Resolution of an estimation grid whose longer side is `max_side`, with the film's aspect.
pub fn estimate_resolution(scene: &Scene, max_side: u32) -> UVec2 {
    let r = scene.film.resolution.as_vec2().max(Vec2::ONE);
    let s = max_side.max(1) as f32 / r.max_element();
    UVec2::new(
        ((r.x * s).round() as u32).max(1),
        ((r.y * s).round() as u32).max(1),
    )
}

/// The per-pixel random stream of an estimation pass.
pub fn pixel_rng(seed: u64, tag: u64, pass: u32, pixel: u32) -> Pcg32 {
    pcg_from_keys(&[seed, tag, pass as u64, pixel as u64])
}

/// The hit of a jittered eye ray through `pixel` of a `res` grid, if it hits a surface with a
/// material.
pub fn eye_hit(scene: &Scene, res: UVec2, pixel: u32, rng: &mut Pcg32) -> Option<EyeHit> {
    let (x, y) = (pixel % res.x, pixel / res.x);
    let jitter = Vec2::new(next_f32(rng), next_f32(rng));
    let p_raster = Vec2::new(x as f32, y as f32) + jitter;
    let ray = scene.camera.generate_ray(p_raster, res);
    hit_along(scene, &ray)
}

/// The next hit after one BSDF sample at `eh`: a secondary vertex, where a path tracer
/// selects a light too (and where the lights that matter can differ from the eye hits').
pub fn bounce_hit(scene: &Scene, eh: &EyeHit, rng: &mut Pcg32) -> Option<EyeHit> {
    let uc = next_f32(rng);
    let u = Vec2::new(next_f32(rng), next_f32(rng));
    let s = eh.bsdf.sample(eh.wo_local, uc, u)?;
    if !(s.pdf > 0.0) {
        return None;
    }
    let wi = eh.frame.to_world(s.wi).try_normalize()?;
    let mut bh = hit_along(scene, &Ray::new(eh.hit.spawn_origin(wi), wi))?;
    bh.secondary = true;
    Some(bh)
}

/// The shading set-up at the first hit of `ray`, if its surface has a material.
fn hit_along(scene: &Scene, ray: &Ray) -> Option<EyeHit> {
    let hit = scene.geometry.intersect(ray)?;
    let material = scene.materials.get(hit.material as usize)?;
    let g = ShadingGeometry::new(ray.d, hit.ng, hit.ns);
    let bsdf = material.bsdf(&hit, g.front);
    // As the integrator's shading point: no normal where light comes from both sides.
    let sp_n = if bsdf.transmits() { Vec3::ZERO } else { g.n };
    Some(EyeHit {
        bsdf,
        wo_local: g.wo_local,
        frame: g.frame,
        sp: ShadingPoint {
            p: hit.p,
            n: sp_n,
            wo: g.wo,
        },
        n: g.n,
        secondary: false,
        hit,
    })
}

/// Luminance of one light-sampling estimate f·Li·cos/pdf_ω of scene light `light` at `eh`
/// (not divided by any selection probability), zero if occluded.
pub fn contribution(scene: &Scene, eh: &EyeHit, light: u32, u: Vec2) -> f32 {
    contribution_mis(scene, eh, light, u).0
}

/// [`contribution`] and, for MIS, the ratio r = pdf_BSDF(wi) / pdf_ω(wi) of BSDF sampling's
/// density to the light sample's at the sampled direction (0 for delta lights).
pub fn contribution_mis(scene: &Scene, eh: &EyeHit, light: u32, u: Vec2) -> (f32, f32) {
    let Some(l) = scene.lights.get(light as usize) else {
        return (0.0, 0.0);
    };
    let ctx = LightSampleContext {
        p: eh.hit.p,
        n: eh.n,
    };
    let Some(ls) = l.sample_li(&ctx, u, SamplingMode::SolidAngle) else {
        return (0.0, 0.0);
    };
    let wi_local = eh.frame.to_local(ls.wi);
    // The integrator's hemisphere rule, so the estimate measures what it will gather.
    if (ls.pdf.is_nan() || ls.pdf <= 0.0)
        || !gathers_from(eh.bsdf.transmits(), ls.wi.dot(eh.n), wi_local.z)
    {
        return (0.0, 0.0);
    }
    let v = luminance(eh.bsdf.f(eh.wo_local, wi_local) * ls.li) * wi_local.z.abs() / ls.pdf;
    if (v.is_nan() || v <= 0.0) || !v.is_finite() {
        return (0.0, 0.0);
    }
    // The renderer's shadow ray: from just off the surface to just short of the light point.
    if scene.geometry.occluded(&eh.hit.spawn_ray_to(ls.p_light)) {
        return (0.0, 0.0);
    }
    let r = if ls.delta {
        0.0
    } else {
        eh.bsdf.pdf(eh.wo_local, wi_local) / ls.pdf
    };
    (v, if r.is_finite() && r > 0.0 { r } else { 0.0 })
}

/// Two uniform numbers.
#[inline]
pub fn next_2d(rng: &mut Pcg32) -> Vec2 {
    Vec2::new(next_f32(rng), next_f32(rng))
}

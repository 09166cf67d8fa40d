//! The lecture's direct-lighting estimators of
//! L(x, ωo) = Le + ∫ f(ωo, x, ωi) · Li · V · cosθx cosθy / ‖x − y‖² dA_y:
//! BSDF (projected solid angle) sampling, light sampling (area or solid angle) and MIS.
//!
//! Both techniques estimate the same integrand restricted to directions above the geometric
//! surface on the viewer's side (reflection only), so their MIS combination stays unbiased even
//! where shading normals disagree with the geometry.

use super::{MisHeuristic, Strategy};
use crate::Rgb;
use crate::bsdf::{Bsdf, BsdfSample, Bxdf, LobeSampling};
use crate::geometry::interaction::NO_LIGHT;
use crate::geometry::{Ray, RayQuery, SurfaceHit};
use crate::light_selection::{LightSelector, SelectedLight, ShadingPoint, UniformSelector};
use crate::lights::{LightSampleContext, LightSource, SamplingMode};
use crate::sampling::{Frame, PixelSamples, SamplePattern, balance_heuristic, power_heuristic};
use crate::scene::Scene;
use glam::{Vec2, Vec3};

/// Pattern dimension of the pixel-filter sample.
pub const DIM_FILTER: u32 = 0;
/// Pattern dimension of the light-selection number.
pub const DIM_LIGHT_SELECT: u32 = 1;
/// Pattern dimension of the point on the light.
pub const DIM_LIGHT: u32 = 2;
/// Pattern dimension of the BSDF lobe choice.
pub const DIM_LOBE: u32 = 3;
/// Pattern dimension of the BSDF direction.
pub const DIM_BSDF: u32 = 4;

/// Shadow rays stop this fraction short of the light point so they do not hit the light itself.
const SHADOW_EPSILON: f32 = 1e-4;

/// One estimator configured for one render.
pub struct DirectLighting<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Light selection.
    pub selector: &'a dyn LightSelector,
    /// Sample pattern.
    pub pattern: &'a dyn SamplePattern,
    /// Estimator.
    pub strategy: Strategy,
    /// MIS heuristic.
    pub mis: MisHeuristic,
    /// Eye rays per pixel (N).
    pub eye_rays: u32,
    /// Light / BSDF samples per eye ray (M).
    pub shadow_rays: u32,
    /// How BSDF lobes are sampled.
    pub bsdf_sampling: LobeSampling,
    /// Light sampling technique of `mis`.
    pub mis_light: SamplingMode,
}

/// The pattern values one light sample and one BSDF sample consume, drawn together up front:
/// the permutation hash chains of the four dimensions are independent, so evaluating them
/// back to back lets the CPU overlap them instead of waiting on each behind a ray query.
#[derive(Clone, Copy, Default)]
struct Draws {
    /// Light-selection number (`DIM_LIGHT_SELECT`).
    light_select: f32,
    /// Point on the light (`DIM_LIGHT`).
    light: Vec2,
    /// Lobe choice (`DIM_LOBE`).
    lobe: f32,
    /// BSDF direction (`DIM_BSDF`).
    bsdf: Vec2,
}

impl Draws {
    /// The draws of sample `index` of `count`; only the dimensions the strategy reads.
    /// Forced inline: out of line, the draws came back through memory after a call.
    #[inline(always)]
    fn new(px: &PixelSamples, index: u32, count: u32, light: bool, bsdf: bool) -> Self {
        let mut d = Draws::default();
        if light {
            d.light_select = px.sample_1d(DIM_LIGHT_SELECT, index, count);
            d.light = px.sample_2d(DIM_LIGHT, index, count);
        }
        if bsdf {
            d.lobe = px.sample_1d(DIM_LOBE, index, count);
            d.bsdf = px.sample_2d(DIM_BSDF, index, count);
        }
        d
    }
}

/// The shading state at a camera-ray hit. The parts whose address goes to out-of-line calls
/// (hit, BSDF, light context) are borrowed from separate locals: a struct with one field
/// passed by address is kept whole in memory, so owning them would force every other field
/// (frame, wo) through the stack too.
struct Shading<'h> {
    hit: &'h SurfaceHit,
    bsdf: &'h Bsdf,
    /// The hit point and the geometric normal flipped toward the viewer.
    ctx: &'h LightSampleContext,
    frame: Frame,
    wo_local: Vec3,
    /// World-space direction toward the viewer (for selectors that need a [`ShadingPoint`]).
    wo: Vec3,
    /// `Some(n)` when light selection is uniform over `n` lights (picked inline).
    uniform: Option<u32>,
}

impl Shading<'_> {
    /// The selector's view of this shading point, built only for selectors that read it.
    #[inline]
    fn shading_point(&self) -> ShadingPoint {
        ShadingPoint {
            p: self.ctx.p,
            n: self.ctx.n,
            wo: self.wo,
        }
    }
}

impl<'a> DirectLighting<'a> {
    /// Light sampling mode implied by the strategy.
    fn mode(&self) -> SamplingMode {
        match self.strategy {
            Strategy::LightArea => SamplingMode::Area,
            Strategy::Mis => self.mis_light,
            _ => SamplingMode::SolidAngle,
        }
    }

    #[inline]
    fn heuristic(&self, f_pdf: f32, g_pdf: f32) -> f32 {
        match self.mis {
            MisHeuristic::Power => power_heuristic(1.0, f_pdf, 1.0, g_pdf),
            MisHeuristic::Balance => balance_heuristic(1.0, f_pdf, 1.0, g_pdf),
        }
    }

    /// Radiance along camera ray `ray` for eye sample `eye` of the pixel whose samples are `px`
    /// (from [`SamplePattern::pixel`]); also returns the number of rays traced.
    pub fn li(&self, px: &PixelSamples, eye: u32, ray: &Ray) -> (Rgb, u64) {
        let scene = self.scene;
        let m = self.shadow_rays.max(1);
        let count = self.eye_rays.max(1) * m;
        let (use_light, use_bsdf) = match self.strategy {
            Strategy::LightArea | Strategy::LightSolidAngle => (true, false),
            Strategy::Bsdf => (false, true),
            Strategy::Mis => (true, true),
        };
        // The first sample's draws are pure arithmetic that does not depend on the hit: issued
        // before the camera ray's traversal, they overlap with its memory-bound work (wasted
        // only for camera rays that escape).
        let first = Draws::new(px, eye * m, count, use_light, use_bsdf);
        let Some(hit) = scene.geometry.intersect(ray) else {
            return (self.escaped(ray.d), 1);
        };
        let mut rays = 1u64;
        let wo = -ray.d.normalize();
        let mut l = Rgb::ZERO;
        if hit.light != NO_LIGHT {
            l += scene.lights[hit.light as usize].radiance(hit.p, hit.ng, hit.uv, wo);
        }
        let front = ray.d.dot(hit.ng) < 0.0;
        let ng = if front { hit.ng } else { -hit.ng };
        let ns = if hit.ns.dot(wo) < 0.0 {
            -hit.ns
        } else {
            hit.ns
        };
        let frame = Frame::from_normal(ns);
        let Some(material) = scene.materials.get(hit.material as usize) else {
            return (l, rays);
        };
        let mut bsdf = material.bsdf(&hit, front);
        if self.bsdf_sampling != LobeSampling::Importance {
            bsdf.set_sampling(self.bsdf_sampling);
        }
        let ctx = LightSampleContext { p: hit.p, n: ng };
        let sh = Shading {
            bsdf: &bsdf,
            wo_local: frame.to_local(wo),
            frame,
            wo,
            ctx: &ctx,
            uniform: if use_light {
                self.selector.uniform_count()
            } else {
                None
            },
            hit: &hit,
        };
        let mis = self.strategy == Strategy::Mis;
        let mut sum = Rgb::ZERO;
        for j in 0..m {
            let d = if j == 0 {
                first
            } else {
                Draws::new(px, eye * m + j, count, use_light, use_bsdf)
            };
            if use_light {
                sum += self.light_sample(&sh, &d, mis, &mut rays);
            }
            if use_bsdf {
                sum += self.bsdf_sample(&sh, &d, mis, &mut rays);
            }
        }
        l += sum / m as f32;
        (l, rays)
    }

    /// Radiance of the infinite lights seen along an escaping ray.
    fn escaped(&self, d: Vec3) -> Rgb {
        let w = d.normalize();
        self.scene
            .infinite_lights
            .iter()
            .map(|&i| self.scene.lights[i as usize].radiance(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, w))
            .sum()
    }

    /// One light-sampling estimate f·Li·cos / (pmf·pdf), MIS-weighted when `mis`.
    fn light_sample(&self, sh: &Shading, d: &Draws, mis: bool, rays: &mut u64) -> Rgb {
        let sel = match sh.uniform {
            Some(count) => UniformSelector::pick(count, d.light_select),
            None => self.selector.sample(&sh.shading_point(), d.light_select),
        };
        let Some(SelectedLight { index, pmf }) = sel else {
            return Rgb::ZERO;
        };
        let light = &self.scene.lights[index as usize];
        let Some(ls) = light.sample_li(sh.ctx, d.light, self.mode()) else {
            return Rgb::ZERO;
        };
        if !(ls.pdf > 0.0) || pmf <= 0.0 || ls.li == Rgb::ZERO || ls.wi.dot(sh.ctx.n) <= 0.0 {
            return Rgb::ZERO;
        }
        let wi_local = sh.frame.to_local(ls.wi);
        // Under MIS the BSDF pdf is needed too: one dispatch evaluates both (for the few
        // occluded samples it is wasted, cheaper than a second call for all the others).
        let weigh = mis && !ls.delta;
        let (f, bsdf_pdf) = if weigh {
            sh.bsdf.f_pdf(sh.wo_local, wi_local)
        } else {
            (sh.bsdf.f(sh.wo_local, wi_local), 0.0)
        };
        let f = f * wi_local.z.abs();
        if f == Rgb::ZERO {
            return Rgb::ZERO;
        }
        *rays += 1;
        if self
            .scene
            .geometry
            .occluded(&shadow_ray(sh.hit, ls.p_light))
        {
            return Rgb::ZERO;
        }
        let pdf = pmf * ls.pdf;
        let w = if weigh {
            self.heuristic(pdf, bsdf_pdf)
        } else {
            1.0
        };
        f * ls.li * (w / pdf)
    }

    /// One BSDF-sampling estimate f·cos·Le / pdf, MIS-weighted when `mis`.
    fn bsdf_sample(&self, sh: &Shading, d: &Draws, mis: bool, rays: &mut u64) -> Rgb {
        // Lambert inline: `Bsdf::sample` carries every BSDF and stays out of line, so the
        // common diffuse hit paid a call and a `BsdfSample` returned through memory.
        let sample = match sh.bsdf {
            Bsdf::Lambert(b) => b.sample(sh.wo_local, d.lobe, d.bsdf),
            other => other.sample(sh.wo_local, d.lobe, d.bsdf),
        };
        let Some(bs) = sample else {
            return Rgb::ZERO;
        };
        if !(bs.pdf > 0.0) {
            return Rgb::ZERO;
        }
        let wi = sh.frame.to_world(bs.wi).normalize();
        // Only specular transmission (smooth glass) may leave below the geometric surface;
        // every other sample there is rejected exactly as light sampling rejects it.
        if wi.dot(sh.ctx.n) <= 0.0 && !bs.delta {
            return Rgb::ZERO;
        }
        let weight = bs.f * (bs.wi.z.abs() / bs.pdf);
        if weight == Rgb::ZERO || !weight.is_finite() {
            return Rgb::ZERO;
        }
        // One logical ray, resolved in two cheaper queries: the nearest emitter along it (a BVH
        // of emitters only), then whether the scene blocks the way to it. The first hit of the
        // ray is an emitter exactly when that emitter is visible, so this is the closest-hit
        // estimator without a closest-hit query for the many rays that miss every light.
        *rays += 1;
        let ray = Ray::new(sh.hit.spawn_origin(wi), wi);
        if let Some(h) = self.scene.emitters.intersect(&ray) {
            let light = &self.scene.lights[h.light as usize];
            let le = light.radiance(h.p, h.ng, h.uv, -wi);
            if le == Rgb::ZERO || self.scene.geometry.occluded(&shadow_ray(sh.hit, h.p)) {
                return Rgb::ZERO;
            }
            return weight * le * self.bsdf_mis_weight(sh, &bs, mis, h.light, wi, h.p, h.ng);
        }
        if self.scene.infinite_lights.is_empty() || self.scene.geometry.occluded(&ray) {
            return Rgb::ZERO;
        }
        let mut sum = Rgb::ZERO;
        for &i in &self.scene.infinite_lights {
            let light = &self.scene.lights[i as usize];
            let le = light.radiance(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, wi);
            if le == Rgb::ZERO {
                continue;
            }
            sum += le * self.bsdf_mis_weight(sh, &bs, mis, i, wi, Vec3::ZERO, Vec3::ZERO);
        }
        weight * sum
    }
    /// MIS weight of BSDF sample `bs` that reached light `light` at (p, n) along `wi`
    /// (1 without MIS and for delta lobes, which light sampling cannot produce).
    #[allow(clippy::too_many_arguments)]
    fn bsdf_mis_weight(
        &self,
        sh: &Shading,
        bs: &BsdfSample,
        mis: bool,
        light: u32,
        wi: Vec3,
        p: Vec3,
        n: Vec3,
    ) -> f32 {
        if !mis || bs.delta {
            return 1.0;
        }
        // Rare (emitter hits only): the plain virtual call, whatever the selector.
        let pdf_l = self.selector.pmf(&sh.shading_point(), light)
            * self.scene.lights[light as usize].pdf_li(sh.ctx, wi, p, n, self.mode());
        self.heuristic(bs.pdf, pdf_l)
    }
}

/// A shadow ray from `hit` to just short of `target`: offset at the origin by the hit's error
/// bound, shortened at the far end by [`SHADOW_EPSILON`].
#[inline]
pub fn shadow_ray(hit: &SurfaceHit, target: Vec3) -> Ray {
    let o = hit.spawn_origin(target - hit.p);
    Ray {
        o,
        d: target - o,
        t_max: 1.0 - SHADOW_EPSILON,
    }
}

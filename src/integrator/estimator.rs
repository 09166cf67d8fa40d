//! The per-sample maths of the integrator, in one file: read this first.
//!
//! At a path vertex x seen from ωo, next-event estimation and BSDF sampling both estimate the
//! lecture's direct-lighting integral
//!
//!   L(x, ωo) = ∫ f(ωo, x, ωi) · Le(y, −ωi) · V(x, y) · cosθx cosθy / ‖x − y‖² dA_y
//!
//! - **light sampling** ([`light_estimate`]): a light picked with probability `pmf`, a direction
//!   ωi toward it with solid-angle pdf `p_L`; value f·Le·|cosθx| / (pmf·p_L), counted if the
//!   [`shadow_ray`] to the light point is clear;
//! - **BSDF sampling** ([`bsdf_ray_of`]): ωi drawn with pdf `p_B`, the ray carries the weight
//!   f·|cosθx| / p_B, and the emission Le it reaches is counted with the weight
//!   [`emission_weight`] (at the last vertex of a path the stages find that emission with a
//!   query of the emitters only, then test its visibility; see `stages.rs`).
//!
//! Under MIS each technique's value is weighted by the heuristic of its own density against
//! the other's *for the same direction*: a light sample by h(pmf·p_L, p_B), an emitter reached
//! by a BSDF ray by h(p_B, pmf·p_L) ([`nee_pdf`] includes the light-selection pmf, so every
//! selector stays unbiased). Delta lobes and delta lights cannot be produced by the other
//! technique: their weight is 1. The pmf inside both weights is the selector's deterministic
//! one; `ris` divides its light sample by a random 1/W instead, which keeps the estimate
//! unbiased, but weighting with it too would make the two weights of a direction sum to 1
//! only on average (a bias: `mis_tests.rs`).
//!
//! Both techniques estimate the same integrand restricted by one hemisphere rule,
//! [`gathers_from`]: above the geometric surface on the viewer's side for reflecting BSDFs;
//! both sides for transmitting ones (rough glass, diffuse transmission), except directions on
//! which the geometric and shading normals disagree. So their MIS combination stays unbiased
//! even where shading normals disagree with the geometry.
//!
//! The stages (`stages.rs`) call these functions for one lane at a time; the vector kernels
//! (`lanes.rs`) call the very same functions in loops over 16 lanes, so every lane's bits are
//! those of this file whichever path it takes.

use super::MisHeuristic;
use crate::Rgb;
use crate::bsdf::{BsdfSample, Bxdf, gathers_from};
use crate::geometry::{Ray, SurfaceHit};
use crate::light_selection::{LightSelector, ShadingPoint};
use crate::lights::{Emitter, Light, LightLiSample, LightSampleContext, SamplingMode};
use crate::sampling::Frame;
use glam::{Vec2, Vec3};

/// A shadow ray from `hit` to just short of `target` ([`SurfaceHit::spawn_ray_to`], the one
/// rule for every shadow ray).
#[inline]
pub fn shadow_ray(hit: &SurfaceHit, target: Vec3) -> Ray {
    hit.spawn_ray_to(target)
}

/// The light-sampling estimate f·Li·cos / (pmf·pdf) of light sample `ls` (its light picked
/// with probability `pmf`) at a receiver with BSDF `bsdf`, shading `frame`, local `wo_local`,
/// context `ctx` and hit `hit`, weighted by heuristic `mis` against BSDF sampling when given,
/// with h(mis_pmf·pdf, p_B): `mis_pmf` is the selection pmf a BSDF ray reaching the same light
/// would compute ([`crate::light_selection::SelectedLight::mis_pmf`]; `pmf` itself for every
/// selector but RIS, whose `pmf` is random), so the two weights of a direction sum to 1:
/// the shadow ray it needs, its value if that ray is clear (`None` when it is zero anyway) and
/// the MIS weight inside that value (1 without MIS or for a delta light: `online` selection
/// records the value without it). pbrt-v4's `SampleLd` after the light is chosen and sampled.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn light_estimate(
    ls: &LightLiSample,
    pmf: f32,
    mis_pmf: f32,
    bsdf: &impl Bxdf,
    frame: &Frame,
    wo_local: Vec3,
    ctx: &LightSampleContext,
    hit: &SurfaceHit,
    mis: Option<MisHeuristic>,
) -> Option<(Ray, Rgb, f32)> {
    // The hemisphere rule; a reflecting BSDF's needs no shading cosine, so it is decided
    // before the frame change, as the lane kernels have always done it.
    let transmits = bsdf.transmits();
    if !(ls.pdf > 0.0)
        || pmf <= 0.0
        || ls.li == Rgb::ZERO
        || (!transmits && !gathers_from(false, ls.wi.dot(ctx.n), 0.0))
    {
        return None;
    }
    let wi_local = frame.to_local(ls.wi);
    if transmits && !gathers_from(true, ls.wi.dot(ctx.n), wi_local.z) {
        return None;
    }
    // Under MIS the BSDF pdf is needed too: one evaluation yields both (wasted on the few
    // occluded samples, cheaper than evaluating twice for all the others).
    let weigh = if ls.delta { None } else { mis };
    let (f, bsdf_pdf) = if weigh.is_some() {
        bsdf.f_pdf(wo_local, wi_local)
    } else {
        (bsdf.f(wo_local, wi_local), 0.0)
    };
    let f = f * wi_local.z.abs();
    if f == Rgb::ZERO {
        return None;
    }
    let pdf = pmf * ls.pdf;
    let w = match weigh {
        Some(h) => h.weight(mis_pmf * ls.pdf, bsdf_pdf),
        None => 1.0,
    };
    Some((shadow_ray(hit, ls.p_light), f * ls.li * (w / pdf), w))
}

/// A sampled BSDF direction as a ray, before what it reaches is known.
#[derive(Clone, Copy)]
pub(super) struct BsdfRay {
    /// The ray, from the hit's spawn origin along the unit direction ωi.
    pub(super) ray: Ray,
    /// f·|cosθ| / pdf: the path throughput's factor for this bounce.
    pub(super) weight: Rgb,
    /// Solid-angle pdf of ωi (1 for delta lobes).
    pub(super) pdf: f32,
    /// Drawn from a delta lobe.
    pub(super) delta: bool,
}

impl BsdfRay {
    /// A placeholder for lanes without a ray.
    pub(super) const NONE: BsdfRay = BsdfRay {
        ray: Ray {
            o: Vec3::ZERO,
            d: Vec3::ZERO,
            t_max: 0.0,
        },
        weight: Rgb::ZERO,
        pdf: 0.0,
        delta: false,
    };
}

/// BSDF sample `bs` of a reflecting BSDF (local frame `frame`) at `hit`, whose geometric
/// normal facing the viewer is `n`, as a ray with its weight f·cos / pdf; `None` when the
/// estimate is zero without tracing it. Shared by the per-lane path and the lane kernels.
#[inline(always)]
pub(super) fn bsdf_ray_of(
    bs: &BsdfSample,
    frame: &Frame,
    n: Vec3,
    hit: &SurfaceHit,
) -> Option<BsdfRay> {
    bsdf_ray_through(bs, false, frame, n, hit)
}

/// [`bsdf_ray_of`] for a BSDF that transmits (`transmits`) or not.
#[inline(always)]
pub(super) fn bsdf_ray_through(
    bs: &BsdfSample,
    transmits: bool,
    frame: &Frame,
    n: Vec3,
    hit: &SurfaceHit,
) -> Option<BsdfRay> {
    if !(bs.pdf > 0.0) {
        return None;
    }
    let wi = frame.to_world(bs.wi).normalize();
    // The rule light sampling applies (`light_estimate`). Delta samples cannot meet light
    // sampling, but a transmitting BSDF's obey it too (a refraction that leaves on the
    // viewer's side of the geometry leaks light); a reflecting BSDF's delta samples (mirrors)
    // keep their exemption, so opaque images stay as they were.
    let exempt = bs.delta && !transmits;
    if !(exempt || gathers_from(transmits, wi.dot(n), bs.wi.z)) {
        return None;
    }
    let weight = bs.f * (bs.wi.z.abs() / bs.pdf);
    if weight == Rgb::ZERO || !weight.is_finite() {
        return None;
    }
    Some(BsdfRay {
        ray: Ray::new(hit.spawn_origin(wi), wi),
        weight,
        pdf: bs.pdf,
        delta: bs.delta,
    })
}

/// What the MIS weight of emission found by a BSDF-sampled ray needs to know of the vertex
/// that sampled it (besides whether its lobe was a delta, see [`emission_weight`]): the
/// sample's pdf and where next-event estimation stood there, for the density it would have
/// drawn the same direction with.
#[derive(Clone, Copy, Debug)]
pub(super) struct PrevVertex {
    /// Solid-angle pdf of the BSDF sample that left the vertex.
    pub(super) pdf: f32,
    /// The vertex as light selection saw it (point, geometric normal toward the viewer, ωo).
    pub(super) at: ShadingPoint,
}

/// The density with which next-event estimation at `at` (light selection, then `light`'s own
/// sampling in `mode`) draws direction `wi` toward light `index` at `p` with normal `n` (zero
/// for infinite lights): pmf · p_L, the pmf of the vertex class of `at` (`secondary`: a vertex
/// after the first).
#[allow(clippy::too_many_arguments)]
#[inline]
pub(super) fn nee_pdf(
    selector: &dyn LightSelector,
    secondary: bool,
    light: &Light,
    index: u32,
    at: &ShadingPoint,
    wi: Vec3,
    p: Vec3,
    n: Vec3,
    mode: SamplingMode,
) -> f32 {
    let ctx = LightSampleContext { p: at.p, n: at.n };
    selector.pmf_at(at, index, secondary) * light.pdf_li(&ctx, wi, p, n, mode)
}

/// How a vertex combines its two techniques (the `--strategy`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Techniques {
    /// BSDF sampling only: emission reached by BSDF rays counts fully.
    Bsdf,
    /// Light sampling only: emission is found by next-event estimation alone.
    Light,
    /// Both, weighted by the heuristic.
    Mis(MisHeuristic),
}

impl Techniques {
    /// Whether light samples are drawn.
    #[inline(always)]
    pub(super) fn light(self) -> bool {
        !matches!(self, Techniques::Bsdf)
    }

    /// Whether BSDF samples are drawn and gather emission: under every strategy, at every
    /// vertex (the path's last too). Under light sampling alone only what they reach through
    /// a delta lobe counts ([`emission_weight`]): no light sample can produce that direction,
    /// so without them a light seen in a mirror or through glass at a path's last vertex was
    /// lost (tests/furnace_mirror.rs). Their other values are 0 and trace nothing
    /// ([`emitter_hit_value`]).
    #[inline(always)]
    pub(super) fn bsdf(self) -> bool {
        true
    }

    /// The MIS heuristic, if the techniques are combined.
    #[inline(always)]
    pub(super) fn mis(self) -> Option<MisHeuristic> {
        match self {
            Techniques::Mis(h) => Some(h),
            _ => None,
        }
    }
}

/// Weight of emission reached by a BSDF sample (one from a delta lobe, or a camera ray, when
/// `delta`), given `pdfs()` = (the sample's density, next-event estimation's density for the
/// same direction): 1 after a delta vertex (no light sample can produce that direction) and
/// without light sampling, 0 with light sampling alone (which already counts it), the MIS
/// heuristic otherwise (`pdfs` is evaluated only then).
#[inline]
pub(super) fn emission_weight(
    t: Techniques,
    delta: bool,
    pdfs: impl FnOnce() -> (f32, f32),
) -> f32 {
    if delta {
        return 1.0;
    }
    match t {
        Techniques::Bsdf => 1.0,
        Techniques::Light => 0.0,
        Techniques::Mis(h) => {
            let (bsdf_pdf, nee_pdf) = pdfs();
            h.weight(bsdf_pdf, nee_pdf)
        }
    }
}

/// Whether the emission a path's current ray reaches is counted, the ray having left vertex
/// `depth` − 1 (`depth` 0: a camera ray): always, except under `hide_emitters` (Mitsuba 3's
/// `hide_emitters`) for what a camera ray sees directly, an emitter's surface or the
/// environment. Light that reaches the camera by a bounce is unchanged: next-event estimation
/// at the camera ray's hit, its BSDF rays that reach emitters (with their MIS weights, which
/// never involved the camera ray's emission) and every later vertex. So the image is the
/// lighting of the scene without the emitters' own pixels, and a renderer's choice of light
/// sampling changes every pixel of it that it can change.
#[inline(always)]
pub(super) fn counts_emission(hide_emitters: bool, depth: u32) -> bool {
    !(hide_emitters && depth == 0)
}

/// The value a BSDF ray of weight `weight` gathers from area light `light` hit at (`p`, `n`,
/// `uv`) along unit `wi`: weight·Le·w with w its [`emission_weight`] (`None` when Le is zero).
#[inline]
pub(super) fn emitter_hit_value(
    light: &Light,
    p: Vec3,
    n: Vec3,
    uv: Vec2,
    wi: Vec3,
    weight: Rgb,
    w: impl FnOnce() -> f32,
) -> Option<Rgb> {
    let le = light.radiance(p, n, uv, -wi);
    if le == Rgb::ZERO {
        return None;
    }
    // A zero weight (light sampling alone, not after a delta lobe) needs no shadow ray.
    let w = w();
    if w == 0.0 {
        return None;
    }
    Some(weight * le * w)
}

/// Radiance arriving along unit direction `wi` that escaped the scene: every infinite light's
/// Le (indices `infinite` into `lights`), each times its weight `w(index)`.
#[inline]
pub(super) fn escaped_radiance(
    lights: &[Light],
    infinite: &[u32],
    wi: Vec3,
    mut w: impl FnMut(u32) -> f32,
) -> Rgb {
    let mut sum = Rgb::ZERO;
    for &i in infinite {
        let le = lights[i as usize].radiance(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, wi);
        // Skipping a zero changes no bit of the sum (which starts at +0 and never is −0).
        if le == Rgb::ZERO {
            continue;
        }
        sum += le * w(i);
    }
    sum
}

/// The first vertex (0: the camera ray's hit) whose BSDF ray plays Russian roulette. pbrt-v4
/// plays from the second (1); from the fourth, the Cornell box at 64 spp has relMSE 2.03e-3
/// against Mitsuba's converged path render instead of 3.06e-3, for about the same
/// time × error (the first bounces carry most of the indirect light, which roulette there
/// turns into noise), and passes the reference test's tolerance (2.7e-3).
pub const ROULETTE_FROM: u32 = 3;

/// Russian roulette on a path's throughput `beta` after vertex `depth` (0: the camera ray's
/// hit) sampled its BSDF, pbrt-v4's rule from vertex [`ROULETTE_FROM`] on: a path whose
/// largest throughput component is below 1 survives with probability p equal to it (`u()`, a
/// uniform draw, is read only then). Returns p for a surviving path, whose throughput is then
/// divided by p so that the estimate stays unbiased (E = p·β/p + (1 − p)·0 = β), and `None`
/// for one that ends.
#[inline]
pub(super) fn roulette(depth: u32, beta: Rgb, u: impl FnOnce() -> f32) -> Option<f32> {
    let top = beta.max_element();
    if depth < ROULETTE_FROM || !(top < 1.0) {
        return Some(1.0);
    }
    let q = (1.0 - top).max(0.0);
    if u() < q { None } else { Some(1.0 - q) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn emission_weight_counts_each_direction_once_across_the_two_techniques() {
        let pdfs = || (2.0, 0.5);
        let never = || -> (f32, f32) { panic!("pdfs read where no heuristic needs them") };
        // After the camera or a delta lobe no light sample can produce the direction.
        for t in [
            Techniques::Bsdf,
            Techniques::Light,
            Techniques::Mis(MisHeuristic::Power),
        ] {
            assert_eq!(emission_weight(t, true, never), 1.0, "{t:?}");
        }
        assert_eq!(emission_weight(Techniques::Bsdf, false, never), 1.0);
        assert_eq!(emission_weight(Techniques::Light, false, never), 0.0);
        for h in [MisHeuristic::Power, MisHeuristic::Balance] {
            let w = emission_weight(Techniques::Mis(h), false, pdfs);
            assert_eq!(w, h.weight(2.0, 0.5));
            // The light sample of the same direction takes the complement.
            assert!((w + h.weight(0.5, 2.0) - 1.0).abs() < 1e-6, "{h:?}");
        }
    }

    #[test]
    fn hide_emitters_hides_only_what_camera_rays_see() {
        for depth in 0..4 {
            assert!(counts_emission(false, depth), "{depth}");
        }
        assert!(!counts_emission(true, 0));
        for depth in 1..4 {
            assert!(counts_emission(true, depth), "{depth}");
        }
    }

    #[test]
    fn roulette_keeps_the_expected_throughput() {
        let never = || -> f32 { panic!("drew a number where no roulette is played") };
        // The first vertex and throughputs of at least 1 always continue, drawing nothing.
        assert_eq!(
            roulette(ROULETTE_FROM - 1, Rgb::splat(0.1), never),
            Some(1.0)
        );
        assert_eq!(roulette(3, Rgb::new(0.2, 1.0, 0.1), never), Some(1.0));
        // Otherwise survival with p = max component: E[survive / p] = 1.
        let beta = Rgb::new(0.25, 0.5, 0.1);
        let n = 10_000;
        let mut expected = 0.0f64;
        for i in 0..n {
            let u = (i as f32 + 0.5) / n as f32;
            if let Some(p) = roulette(ROULETTE_FROM, beta, || u) {
                assert_eq!(p, 0.5);
                expected += 1.0 / p as f64;
            }
        }
        assert!((expected / n as f64 - 1.0).abs() < 1e-3, "{expected}");
        assert_eq!(roulette(ROULETTE_FROM + 1, Rgb::ZERO, || 0.999), None);
    }
}

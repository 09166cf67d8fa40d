//! The lecture's direct-lighting estimators of
//! L(x, ωo) = Le + ∫ f(ωo, x, ωi) · Li · V · cosθx cosθy / ‖x − y‖² dA_y:
//! BSDF (projected solid angle) sampling, light sampling (area or solid angle) and MIS.
//!
//! Both techniques estimate the same integrand restricted by one hemisphere rule,
//! [`gathers_from`]: above the geometric surface on the viewer's side for reflecting BSDFs;
//! both sides for transmitting ones (rough glass, diffuse transmission), except directions on
//! which the geometric and shading normals disagree. So their MIS combination stays unbiased
//! even where shading normals disagree with the geometry.

use super::lanes::{DiffuseBsdfLanes, Pending, Receivers, Sampled, TriangleLightLanes};
use super::{MisHeuristic, Strategy};
use crate::Rgb;
use crate::bsdf::{Bsdf, BsdfSample, Bxdf, LobeSampling, gathers_from};
use crate::geometry::interaction::NO_LIGHT;
use crate::geometry::packet::bits;
use crate::geometry::{PACKET, Ray, RayPacket, SurfaceHit};
use crate::light_selection::{LightSelector, SelectedLight, ShadingPoint, UniformSelector};
use crate::lights::{Emitter, Light, LightLiSample, LightSampleContext, LightSource, SamplingMode};
use crate::sampling::{Frame, PixelSamples, SamplePattern};
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
/// Pattern dimension of the thin-lens sample (index: the eye sample, count N). The last
/// dimension, beyond those of any path vertex, so that adding it changed no other decision's
/// numbers (pinhole images are bit-identical to before); read only by cameras with a lens.
pub const DIM_LENS: u32 = u32::MAX;

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
/// the permutation hash chains of the dimensions are independent, so evaluating them back to
/// back lets the CPU overlap them instead of waiting on each behind a ray query. The lobe
/// choice (`DIM_LOBE`) is drawn later, only for receivers whose BSDF has lobes to choose
/// (values are pure functions of pixel, dimension and index, so skipping it changes nothing).
#[derive(Clone, Copy, Default)]
struct Draws {
    /// Light-selection number (`DIM_LIGHT_SELECT`).
    light_select: f32,
    /// Point on the light (`DIM_LIGHT`).
    light: Vec2,
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
            d.bsdf = px.sample_2d(DIM_BSDF, index, count);
        }
        d
    }
}

/// A packet of camera samples for [`DirectLighting::li_packet`]: lane k < `n` is eye sample
/// `eye[k]` of pixel `pixel[k]` (an index into the caller's [`PixelSamples`]) along ray k of
/// `rays`.
#[derive(Clone, Copy, Debug)]
pub struct CameraPacket {
    /// Lanes in use.
    pub n: usize,
    /// Per lane: index of its pixel's samples.
    pub pixel: [u8; PACKET],
    /// Per lane: eye sample index within the pixel.
    pub eye: [u32; PACKET],
    /// The camera rays, in lanes (as the vector code that makes them and the packet query
    /// that traces them both want).
    pub rays: RayPacket,
}

impl Default for CameraPacket {
    fn default() -> Self {
        Self::new()
    }
}

impl CameraPacket {
    /// An empty packet.
    pub fn new() -> Self {
        Self {
            n: 0,
            pixel: [0; PACKET],
            eye: [0; PACKET],
            rays: RayPacket::from_rays(&[Ray::new(Vec3::ZERO, Vec3::Z); PACKET]),
        }
    }

    /// True when every lane is in use.
    pub fn is_full(&self) -> bool {
        self.n == PACKET
    }

    /// Empty the packet (its arrays are overwritten lane by lane as it fills again).
    pub fn clear(&mut self) {
        self.n = 0;
    }

    /// Append a lane (ignored when full).
    pub fn push(&mut self, pixel: u8, eye: u32, ray: Ray) {
        if self.n < PACKET {
            self.pixel[self.n] = pixel;
            self.eye[self.n] = eye;
            self.rays.set(self.n, &ray);
            self.n += 1;
        }
    }

    /// Mask of the lanes in use.
    fn active(&self) -> u32 {
        ((1u64 << self.n) - 1) as u32
    }
}

/// A sampled BSDF direction as a ray, before what it reaches is known.
#[derive(Clone, Copy)]
pub(super) struct BsdfRay {
    pub(super) ray: Ray,
    /// f·cos / pdf.
    pub(super) weight: Rgb,
    pub(super) pdf: f32,
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

/// The working arrays of [`DirectLighting::li_packet`], made once per render thread's tile
/// instead of per packet (every lane a packet reads is written first by that packet).
pub struct PacketScratch {
    /// Each lane's draws for the current round of shadow rays.
    drawn: [Draws; PACKET],
    hits: [Option<SurfaceHit>; PACKET],
    lanes: [Option<LaneShading>; PACKET],
    emitter_hits: [Option<SurfaceHit>; PACKET],
    light: Pending,
    bsdf: Pending,
    sampled: Sampled,
    rx: Receivers,
    tri_lanes: TriangleLightLanes,
    bsdf_lanes: DiffuseBsdfLanes,
}

impl Default for PacketScratch {
    fn default() -> Self {
        Self::new()
    }
}

impl PacketScratch {
    /// Fresh working arrays.
    pub fn new() -> Self {
        Self {
            drawn: [Draws::default(); PACKET],
            hits: [None; PACKET],
            lanes: [const { None }; PACKET],
            emitter_hits: [None; PACKET],
            light: Pending::new(),
            bsdf: Pending::new(),
            sampled: Sampled::new(),
            rx: Receivers::new(),
            tri_lanes: TriangleLightLanes::new(),
            bsdf_lanes: DiffuseBsdfLanes::new(),
        }
    }
}

/// The per-lane part of a camera-ray hit's shading state (the geometry is in [`Receivers`]).
struct LaneShading {
    bsdf: Bsdf,
    /// The hit point and the geometric normal flipped toward the viewer.
    ctx: LightSampleContext,
}

impl LaneShading {
    /// The view the per-sample estimators take of lane `k`.
    #[inline]
    fn view<'a>(&'a self, k: usize, hit: &'a SurfaceHit, rx: &Receivers) -> Shading<'a> {
        let g = rx.geometry(k);
        Shading {
            hit,
            bsdf: &self.bsdf,
            ctx: &self.ctx,
            frame: g.frame,
            wo_local: g.wo_local,
            wo: g.wo,
        }
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
}

impl Shading<'_> {
    /// The selector's view of this shading point, built only for selectors that read it.
    /// A transmitting BSDF gathers from both sides, so the selector gets no normal (zero):
    /// with one, importance-based selectors would give lights behind the surface (the bulb's
    /// filament) probability 0.
    #[inline]
    fn shading_point(&self) -> ShadingPoint {
        ShadingPoint {
            p: self.ctx.p,
            n: if self.bsdf.transmits() {
                Vec3::ZERO
            } else {
                self.ctx.n
            },
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

    /// Radiance along camera ray `ray` for eye sample `eye` of the pixel whose samples are `px`
    /// (from [`SamplePattern::pixel`]); also returns the number of rays traced. A packet of one
    /// lane: the same numbers as that lane of any [`Self::li_packet`].
    pub fn li(&self, px: &PixelSamples, eye: u32, ray: &Ray) -> (Rgb, u64) {
        let mut cam = CameraPacket::new();
        cam.push(0, eye, *ray);
        let mut out = [Rgb::ZERO; PACKET];
        let mut scratch = PacketScratch::new();
        let rays = self.li_packet(std::slice::from_ref(px), &cam, &mut out, &mut scratch);
        (out[0], rays)
    }

    /// Radiance of each lane of `cam` (lane k: eye sample `cam.eye[k]` of the pixel whose
    /// samples are `pxs[cam.pixel[k]]`, along `cam.ray[k]`) into `out[k]`; returns the number of
    /// rays traced. Each ray kind goes to the geometry as one packet query, so the coherent
    /// camera and shadow rays of neighbouring samples share their traversal.
    pub fn li_packet(
        &self,
        pxs: &[PixelSamples],
        cam: &CameraPacket,
        out: &mut [Rgb; PACKET],
        scratch: &mut PacketScratch,
    ) -> u64 {
        let scene = self.scene;
        let PacketScratch {
            drawn,
            hits,
            lanes,
            emitter_hits,
            light,
            bsdf,
            sampled,
            rx,
            tri_lanes,
            bsdf_lanes,
        } = scratch;
        let n = cam.n;
        let m = self.shadow_rays.max(1);
        let count = self.eye_rays.max(1) * m;
        let (use_light, use_bsdf) = match self.strategy {
            Strategy::LightArea | Strategy::LightSolidAngle => (true, false),
            Strategy::Bsdf => (false, true),
            Strategy::Mis => (true, true),
        };
        // A macro, not a closure: the closure was outlined and returned the draws through
        // memory, and reading them back stalled on store forwarding.
        macro_rules! draws {
            ($k:expr, $j:expr) => {
                Draws::new(
                    &pxs[cam.pixel[$k] as usize],
                    cam.eye[$k] * m + $j,
                    count,
                    use_light,
                    use_bsdf,
                )
            };
        }
        // The first round's draws are pure arithmetic that does not depend on the hits:
        // issued before the camera rays' traversal, they overlap with its memory-bound work.
        for (k, d) in drawn.iter_mut().enumerate().take(n) {
            *d = draws!(k, 0);
        }
        scene
            .geometry
            .intersect_packet_cols(&cam.rays, cam.active(), hits, &mut rx.cols);
        // Normal and bump maps replace the shading normals before the frames are built.
        crate::scene::shading_normals::perturb_hits(scene, &mut hits[..], &mut rx.cols);
        let mut rays = n as u64;
        let isa = scene.geometry.isa();
        // The hits' shading geometry for all lanes at once, then each lane's emission and
        // BSDF; Lambertian receivers go to the lane kernels (their triangle-light samples and
        // their BSDF rays).
        rx.shade(&cam.rays, isa);
        rx.diffuse = 0;
        for k in 0..n {
            out[k] = match &hits[k] {
                None => {
                    lanes[k] = None;
                    self.escaped(cam.rays.ray(k).d)
                }
                Some(hit) => self.shade(k, hit, rx, &mut lanes[k]),
            };
        }
        let shaded = lanes
            .iter()
            .enumerate()
            .take(n)
            .fold(0u32, |s, (k, l)| s | (l.is_some() as u32) << k);
        let mode = self.mode();
        let uniform = if use_light {
            self.selector.uniform_count()
        } else {
            None
        };
        let mis = self.strategy == Strategy::Mis;
        let mut sums = [Rgb::ZERO; PACKET];
        let mut picked = [SelectedLight { index: 0, pmf: 0.0 }; PACKET];
        for j in 0..m {
            light.active = 0;
            bsdf.active = 0;
            sampled.clear();
            tri_lanes.active = 0;
            bsdf_lanes.active = 0;
            // Which lanes take the per-lane paths (and the light each picked).
            let (mut lone_light, mut lone_bsdf) = (0u32, 0u32);
            for k in 0..n {
                let Some(lane) = &lanes[k] else { continue };
                let Some(hit) = &hits[k] else { continue };
                if j > 0 {
                    drawn[k] = draws!(k, j);
                }
                let d = &drawn[k];
                let diffuse = rx.diffuse >> k & 1 != 0;
                if use_light {
                    let sel = match uniform {
                        Some(count) => UniformSelector::pick(count, d.light_select),
                        None => self
                            .selector
                            .sample(&lane.view(k, hit, rx).shading_point(), d.light_select),
                    };
                    if let Some(sel) = sel {
                        match &scene.lights[sel.index as usize] {
                            Light::Triangle(tri) if diffuse => {
                                tri_lanes.load(k, tri, sel.pmf, d.light)
                            }
                            _ => {
                                picked[k] = sel;
                                lone_light |= 1 << k;
                            }
                        }
                    }
                }
                if use_bsdf {
                    if diffuse {
                        bsdf_lanes.load(k, d.bsdf);
                    } else {
                        lone_bsdf |= 1 << k;
                    }
                }
            }
            // The kernels write every lane of their output, so they go first and the per-lane
            // paths then fill in their own lanes. One logical ray per sample that has one
            // (for BSDF samples whatever comes of it: an emitter query, maybe a visibility
            // test).
            if tri_lanes.active != 0 {
                rays += u64::from(tri_lanes.run(rx, mis.then_some(self.mis), mode, isa, light));
            }
            if bsdf_lanes.active != 0 {
                rays += u64::from(bsdf_lanes.run(rx, isa, sampled));
            }
            for k in bits(lone_light) {
                let (Some(lane), Some(hit)) = (&lanes[k], &hits[k]) else {
                    continue;
                };
                let sh = lane.view(k, hit, rx);
                if let Some((r, v)) = self.light_sample(&sh, picked[k], drawn[k].light, mis) {
                    light.set(k, &r, v);
                    rays += 1;
                }
            }
            for k in bits(lone_bsdf) {
                let (Some(lane), Some(hit)) = (&lanes[k], &hits[k]) else {
                    continue;
                };
                let px = &pxs[cam.pixel[k] as usize];
                let lobe = px.sample_1d(DIM_LOBE, cam.eye[k] * m + j, count);
                if let Some(b) = self.bsdf_ray(&lane.view(k, hit, rx), lobe, drawn[k].bsdf) {
                    rays += 1;
                    sampled.set(k, &b);
                }
            }
            if sampled.active != 0 {
                scene
                    .emitters
                    .intersect_packet(&sampled.rays, sampled.active, emitter_hits);
                for k in bits(sampled.active) {
                    let hit = emitter_hits[k].as_ref();
                    // Most BSDF rays reach no light: nothing to gather, no view to build.
                    if hit.is_none() && scene.infinite_lights.is_empty() {
                        continue;
                    }
                    let (Some(lane), Some(at)) = (&lanes[k], &hits[k]) else {
                        continue;
                    };
                    let b = sampled.get(k);
                    if let Some((r, v)) = self.bsdf_gather(&lane.view(k, at, rx), &b, hit, mis) {
                        bsdf.set(k, &r, v);
                    }
                }
            }
            light.resolve(&scene.geometry);
            bsdf.resolve(&scene.geometry);
            if use_light {
                light.add_to(shaded, &mut sums);
            }
            if use_bsdf {
                bsdf.add_to(shaded, &mut sums);
            }
        }
        for k in bits(shaded) {
            out[k] += sums[k] / m as f32;
        }
        rays
    }

    /// Emitted radiance at camera hit `hit` of lane `k` (its shading geometry in `rx`); its
    /// BSDF and light-sample context (if it has a material) go to `lane`, and a Lambertian
    /// BSDF marks the lane diffuse in `rx`.
    #[inline(always)]
    fn shade(
        &self,
        k: usize,
        hit: &SurfaceHit,
        rx: &mut Receivers,
        lane: &mut Option<LaneShading>,
    ) -> Rgb {
        let scene = self.scene;
        let g = rx.geometry(k);
        let mut l = Rgb::ZERO;
        if hit.light != NO_LIGHT {
            l += scene.lights[hit.light as usize].radiance(hit.p, hit.ng, hit.uv, g.wo);
        }
        let Some(material) = scene.materials.get(hit.material as usize) else {
            *lane = None;
            return l;
        };
        // The BSDF is stored straight into the lane: a diffuse one from registers, any other
        // by the out-of-line constructor. (Both paths through one local, the copy out of it
        // read 16-byte pieces before the smaller stores that wrote them had landed: a
        // store-forwarding stall on every hit.)
        let ctx = LightSampleContext { p: hit.p, n: g.n };
        let lane = match material.lambert(hit) {
            Some(b) => lane.insert(LaneShading {
                bsdf: Bsdf::Lambert(b),
                ctx,
            }),
            None => lane.insert(LaneShading {
                bsdf: material.bsdf(hit, g.front),
                ctx,
            }),
        };
        if self.bsdf_sampling != LobeSampling::Importance {
            lane.bsdf.set_sampling(self.bsdf_sampling);
        }
        if let Bsdf::Lambert(b) = &lane.bsdf {
            rx.set_diffuse(k, b);
        }
        l
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

    /// One light-sampling estimate of light `sel`, MIS-weighted when `mis`: the shadow ray it
    /// needs and its value if that ray is clear (`None` when it is zero anyway).
    fn light_sample(
        &self,
        sh: &Shading,
        sel: SelectedLight,
        u: Vec2,
        mis: bool,
    ) -> Option<(Ray, Rgb)> {
        let light = &self.scene.lights[sel.index as usize];
        let ls = light.sample_li(sh.ctx, u, self.mode())?;
        light_estimate(
            &ls,
            sel.pmf,
            sh.bsdf,
            &sh.frame,
            sh.wo_local,
            sh.ctx,
            sh.hit,
            mis.then_some(self.mis),
        )
    }

    /// The first half of one BSDF-sampling estimate f·cos·Le / pdf: the sampled ray and its
    /// weight f·cos / pdf (`None` when the estimate is zero without tracing it).
    fn bsdf_ray(&self, sh: &Shading, lobe: f32, u: Vec2) -> Option<BsdfRay> {
        // Lambert inline: `Bsdf::sample` carries every BSDF and stays out of line, so the
        // common diffuse hit paid a call and a `BsdfSample` returned through memory.
        let (bs, transmits) = match sh.bsdf {
            Bsdf::Lambert(b) => (b.sample(sh.wo_local, lobe, u), false),
            other => (other.sample(sh.wo_local, lobe, u), other.transmits()),
        };
        bsdf_ray_through(&bs?, transmits, &sh.frame, sh.ctx.n, sh.hit)
    }

    /// The second half: given the nearest emitter `hit` along the sampled ray (a BVH of
    /// emitters only), the ray whose blocking would void the estimate and its value, MIS-
    /// weighted when `mis`. The first hit of the ray is an emitter exactly when that emitter
    /// is visible, so this is the closest-hit estimator without a closest-hit query for the
    /// many rays that miss every light.
    fn bsdf_gather(
        &self,
        sh: &Shading,
        b: &BsdfRay,
        hit: Option<&SurfaceHit>,
        mis: bool,
    ) -> Option<(Ray, Rgb)> {
        let wi = b.ray.d;
        if let Some(h) = hit {
            let light = &self.scene.lights[h.light as usize];
            let le = light.radiance(h.p, h.ng, h.uv, -wi);
            if le == Rgb::ZERO {
                return None;
            }
            let w = self.bsdf_mis_weight(sh, b, mis, h.light, h.p, h.ng);
            return Some((shadow_ray(sh.hit, h.p), b.weight * le * w));
        }
        if self.scene.infinite_lights.is_empty() {
            return None;
        }
        let mut sum = Rgb::ZERO;
        for &i in &self.scene.infinite_lights {
            let light = &self.scene.lights[i as usize];
            let le = light.radiance(Vec3::ZERO, Vec3::ZERO, Vec2::ZERO, wi);
            if le == Rgb::ZERO {
                continue;
            }
            sum += le * self.bsdf_mis_weight(sh, b, mis, i, Vec3::ZERO, Vec3::ZERO);
        }
        Some((b.ray, b.weight * sum))
    }

    /// MIS weight of BSDF sample `b` that reached light `light` at (p, n) (1 without MIS and
    /// for delta lobes, which light sampling cannot produce).
    fn bsdf_mis_weight(
        &self,
        sh: &Shading,
        b: &BsdfRay,
        mis: bool,
        light: u32,
        p: Vec3,
        n: Vec3,
    ) -> f32 {
        if !mis || b.delta {
            return 1.0;
        }
        // Rare (emitter hits only): the plain virtual call, whatever the selector.
        let pdf_l = self.selector.pmf(&sh.shading_point(), light)
            * self.scene.lights[light as usize].pdf_li(sh.ctx, b.ray.d, p, n, self.mode());
        self.mis.weight(b.pdf, pdf_l)
    }
}

/// The light-sampling estimate f·Li·cos / (pmf·pdf) of light sample `ls` (its light picked
/// with probability `pmf`) at a receiver with BSDF `bsdf`, shading `frame`, local `wo_local`,
/// context `ctx` and hit `hit`, weighted by heuristic `mis` against BSDF sampling when given:
/// the shadow ray it needs and its value if that ray is clear. One definition for the per-lane
/// path and the lane kernels, so both compute the same bits.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn light_estimate(
    ls: &LightLiSample,
    pmf: f32,
    bsdf: &impl Bxdf,
    frame: &Frame,
    wo_local: Vec3,
    ctx: &LightSampleContext,
    hit: &SurfaceHit,
    mis: Option<MisHeuristic>,
) -> Option<(Ray, Rgb)> {
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
    // Under MIS the BSDF pdf is needed too: one dispatch evaluates both (for the few
    // occluded samples it is wasted, cheaper than a second call for all the others).
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
        Some(h) => h.weight(pdf, bsdf_pdf),
        None => 1.0,
    };
    Some((shadow_ray(hit, ls.p_light), f * ls.li * (w / pdf)))
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
    // keep their old exemption, so opaque images stay as they were.
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

/// A shadow ray from `hit` to just short of `target` ([`SurfaceHit::spawn_ray_to`], the one
/// rule for every shadow ray).
#[inline]
pub fn shadow_ray(hit: &SurfaceHit, target: Vec3) -> Ray {
    hit.spawn_ray_to(target)
}

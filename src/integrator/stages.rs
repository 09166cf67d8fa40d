//! The integrator as named stages over work queues, in the spirit of pbrt-v4's wavefront
//! integrator on the CPU: a packet of [`PACKET`] paths (one per lane) goes through one small
//! function per stage, each reading and writing structure-of-arrays queues ([`Queues`]); the
//! maths of one sample is in `estimator.rs`, the vector kernels of the common case in
//! `lanes.rs`.
//!
//! ```text
//!  camera rays ─▶ draw ─▶ intersect ─▶ shade ─┬─▶ round j = 0 .. M: draw ─▶ sample_lights
//!  (render.rs)      ▲    closest hits  Le·w·β, │     ─▶ sample_bsdfs ─▶ (j = 0) continue_or_terminate
//!                   │                  BSDFs   │     ─▶ gather_emitters ─▶ trace_shadows ─▶ accumulate
//!                   │                          └─▶ finish: L += β·Σ/M; the continuing paths advance
//!                   └──── continuing BSDF rays (while depth < max depth) ◀──┘
//! ```
//!
//! The driver ([`Integrator::li_wave`]) takes a wave of camera packets one depth at a time:
//! the paths that continue past a vertex wait as [`PathRecord`]s and are packed 16 to a packet
//! again at the next depth (compaction), so a packet keeps its lanes full after the first
//! bounces; a path's radiance goes to its wave slot when it ends.
//!
//! Direct lighting is the path with max depth 1: its BSDF rays are the last of the path, so
//! `gather_emitters` finds what they reach with a query of the emitters alone (most BSDF rays
//! reach no light: no closest-hit query of the whole scene for them) and tests the visibility
//! of the emitters found; `finish` terminates every path. Path tracing loops: round 0's BSDF
//! ray of a vertex before the last continues its path (Russian roulette permitting), and the
//! emission it finds is counted by `shade` at the next vertex. Every value is a pure function of
//! the path's pixel, sample index and pattern dimension, and each lane's value is what the
//! one-lane packet ([`Integrator::li`]) computes, so neither packets nor threads change a bit.

use super::dims::{VertexDims, rounds_at, sample_index};
use super::estimator::{
    BsdfRay, Techniques, bsdf_ray_through, counts_emission, emission_weight, emitter_hit_value,
    escaped_radiance, light_estimate, nee_pdf, roulette,
};
use super::lanes::{DiffuseBsdfLanes, TriangleLightLanes};
use super::queues::{
    BsdfRays, CameraPacket, Draws, LaneShading, PathLanes, PathRecord, Receivers, ShadowRays,
};
use super::{MisHeuristic, Strategy};
use crate::Rgb;
use crate::bsdf::{Bsdf, Bxdf, LaneBsdf, LobeSampling};
use crate::geometry::interaction::NO_LIGHT;
use crate::geometry::packet::bits;
use crate::geometry::{PACKET, Ray, RayPacket, RayQuery, SurfaceHit};
use crate::light_selection::online::LearnRecord;
use crate::light_selection::{
    LightSelector, SelectedLight, SelectorKind, ShadingPoint, UniformSelector,
};
use crate::lights::{Emitter, LaneLight, LightSampleContext, LightSource, SamplingMode};
use crate::sampling::{Frame, PixelSamples, SamplePattern};
use crate::scene::Scene;
use glam::{Vec2, Vec3};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// The integrator configured for one render.
pub struct Integrator<'a> {
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
    /// pbrt-v4's `maxdepth`: the most vertices of a path that sample lights and the BSDF
    /// (1: direct lighting; 0: emission seen by camera rays only).
    pub max_depth: u32,
    /// Russian roulette on the path throughput (pbrt-v4's rule, from vertex [`super::estimator::ROULETTE_FROM`]).
    pub roulette: bool,
    /// Leave out the emission camera rays see directly (Mitsuba 3's `hide_emitters`; see
    /// [`RenderOptions::hide_emitters`](super::RenderOptions::hide_emitters)).
    pub hide_emitters: bool,
}

/// The work queues of one render thread (made once per tile, not per packet: every lane a
/// stage reads was written first by an earlier stage of the same packet).
pub struct Queues {
    /// The paths' state.
    paths: PathLanes,
    /// Each lane's draws for the current round.
    drawn: Draws,
    /// The closest hits of the paths' rays.
    hits: [Option<SurfaceHit>; PACKET],
    /// The hits' shading geometry, as columns.
    rx: Receivers,
    /// Per lane: the BSDF and light-sample context of its hit (`None`: no material or no hit).
    shading: [Option<LaneShading>; PACKET],
    /// Per lane with a [`LaneShading`]: the hit point and the geometric normal flipped toward
    /// the viewer.
    ctx: [LightSampleContext; PACKET],
    /// Lanes with a [`LaneShading`]: the vertices that sample lights and BSDFs.
    shaded: u32,
    /// Light samples for the triangle-light kernel.
    tri_lanes: TriangleLightLanes,
    /// Lanes whose light sample is taken one lane at a time.
    lone_light: u32,
    /// Per `lone_light` lane: the light it picked.
    picked: [SelectedLight; PACKET],
    /// BSDF samples for the Lambertian kernel.
    bsdf_lanes: DiffuseBsdfLanes,
    /// Lanes whose BSDF sample is taken one lane at a time.
    lone_bsdf: u32,
    /// The BSDF rays of the round.
    bsdf_rays: BsdfRays,
    /// The nearest emitter along each BSDF ray.
    emitter_hits: [Option<SurfaceHit>; PACKET],
    /// Light samples that count unless their shadow ray is blocked.
    nee: ShadowRays,
    /// Emission reached by BSDF rays that counts unless the emitter is hidden.
    gathered: ShadowRays,
    /// Per lane: the sum over this vertex's rounds.
    sums: [Rgb; PACKET],
    /// Record what the light samples of these vertex classes delivered (`online`
    /// selection's rounds): bit 0 primary vertices, bit 1 secondary ones; 0 records nothing.
    pub learning: u8,
    /// Lanes that selected a light this round (when their class is `learning`).
    chosen: u32,
    /// Per `chosen` lane: the light and its pmf.
    chosen_light: [SelectedLight; PACKET],
    /// The records of the light samples taken since the caller last drained them.
    pub records: Vec<LearnRecord>,
}

impl Default for Queues {
    fn default() -> Self {
        Self::new()
    }
}

impl Queues {
    /// Fresh queues.
    pub fn new() -> Self {
        Self {
            paths: PathLanes::new(),
            drawn: Draws::new(),
            hits: [None; PACKET],
            rx: Receivers::new(),
            shading: [const { None }; PACKET],
            ctx: [LightSampleContext {
                p: Vec3::ZERO,
                n: Vec3::ZERO,
            }; PACKET],
            shaded: 0,
            tri_lanes: TriangleLightLanes::new(),
            lone_light: 0,
            picked: [SelectedLight::exact(0, 0.0); PACKET],
            bsdf_lanes: DiffuseBsdfLanes::new(),
            lone_bsdf: 0,
            bsdf_rays: BsdfRays::new(),
            emitter_hits: [None; PACKET],
            nee: ShadowRays::new(),
            gathered: ShadowRays::new(),
            sums: [Rgb::ZERO; PACKET],
            learning: 0,
            chosen: 0,
            chosen_light: [SelectedLight::exact(0, 0.0); PACKET],
            records: Vec::new(),
        }
    }

    /// The view the per-lane estimators take of lane `k` (a shaded lane).
    #[inline]
    fn view(&self, k: usize) -> Option<Shading<'_>> {
        let (Some(lane), Some(hit)) = (&self.shading[k], &self.hits[k]) else {
            return None;
        };
        let g = self.rx.geometry(k);
        Some(Shading {
            hit,
            bsdf: &lane.bsdf,
            ctx: &self.ctx[k],
            frame: g.frame,
            wo_local: g.wo_local,
            wo: g.wo,
        })
    }
}

/// The paths of a wave between vertices (made once per render thread and reused): those of
/// the current depth and those that continue to the next.
#[derive(Default)]
pub struct Wave {
    now: Vec<PathRecord>,
    next: Vec<PathRecord>,
}

impl Wave {
    /// An empty wave.
    pub fn new() -> Self {
        Self::default()
    }
}

/// When set, [`Integrator::li_wave`] times its ray queries by kind into
/// [`RayCounts::timed`] (for `penumbra bench`; two clock reads per packet query otherwise
/// not made).
pub static TIME_QUERIES: AtomicBool = AtomicBool::new(false);

/// Rays of one kind of query and the time spent in those queries.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueryTime {
    /// Rays traced.
    pub rays: u64,
    /// Nanoseconds in the queries.
    pub ns: u64,
}

impl QueryTime {
    /// Millions of rays per second of query time.
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / (self.ns as f64).max(1.0) * 1e3
    }

    fn add(&mut self, other: &QueryTime) {
        self.rays += other.rays;
        self.ns += other.ns;
    }
}

/// With [`TIME_QUERIES`]: the time of each kind of ray query.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct QueryTimes {
    /// Camera rays' closest-hit packet queries.
    pub camera: QueryTime,
    /// Shadow rays (light samples and the visibility of emitters BSDF rays reached), any-hit
    /// packet queries.
    pub shadow: QueryTime,
    /// Continuing BSDF rays' closest-hit queries (one ray each).
    pub secondary: QueryTime,
}

/// Rays traced, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RayCounts {
    /// Camera rays (closest hit, coherent packets).
    pub camera: u64,
    /// Light samples' shadow rays (any hit).
    pub shadow: u64,
    /// BSDF rays that continue their path (closest hit, one query each).
    pub secondary: u64,
    /// BSDF rays that end their path: the emitters' query, then a visibility test of those
    /// that reach one.
    pub gather: u64,
    /// Query times (zero unless [`TIME_QUERIES`] was set).
    pub timed: QueryTimes,
}

impl RayCounts {
    /// All kinds together.
    pub fn total(&self) -> u64 {
        self.camera + self.shadow + self.secondary + self.gather
    }

    /// Add `other`.
    pub fn add(&mut self, other: &RayCounts) {
        self.camera += other.camera;
        self.shadow += other.shadow;
        self.secondary += other.secondary;
        self.gather += other.gather;
        self.timed.camera.add(&other.timed.camera);
        self.timed.shadow.add(&other.timed.shadow);
        self.timed.secondary.add(&other.timed.secondary);
    }
}

/// After a vertex of the packet whose lanes `live` entered it: the paths that ended give
/// their radiance (`out`) to `radiance`, those that continue (the active lanes) wait in
/// `next`.
#[inline(always)]
fn retire(
    q: &Queues,
    live: u32,
    out: &[Rgb; PACKET],
    radiance: &mut [Rgb],
    next: &mut Vec<PathRecord>,
) {
    let going = q.paths.active;
    for k in bits(live & !going) {
        radiance[q.paths.id[k] as usize] = out[k];
    }
    for k in bits(going) {
        next.push(q.paths.record(k, out[k]));
    }
}

/// The shading state at a hit, as the per-lane estimators read it: the hit, BSDF and light
/// context borrowed from where they live, the frame and `wo` owned.
// Borrowed, not owned: mis-area 3791 → 3769 Ir/sample (24eb8e6).
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

impl<'a> Integrator<'a> {
    /// How the strategy combines the techniques.
    #[inline]
    fn techniques(&self) -> Techniques {
        match self.strategy {
            Strategy::LightArea | Strategy::LightSolidAngle => Techniques::Light,
            Strategy::Bsdf => Techniques::Bsdf,
            Strategy::Mis => Techniques::Mis(self.mis),
        }
    }

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
        let mut queues = Queues::new();
        let rays = self.li_packet(std::slice::from_ref(px), &cam, &mut out, &mut queues);
        (out[0], rays)
    }

    /// Radiance of each lane of `cam` (lane k: eye sample `cam.eye[k]` of the pixel whose
    /// samples are `pxs[cam.pixel[k]]`, along `cam.rays` lane k) into `out[k]`; returns the
    /// number of rays traced. A wave of one packet ([`Self::li_wave`]).
    pub fn li_packet(
        &self,
        pxs: &[PixelSamples],
        cam: &CameraPacket,
        out: &mut [Rgb; PACKET],
        q: &mut Queues,
    ) -> u64 {
        *out = [Rgb::ZERO; PACKET];
        let mut wave = Wave::new();
        self.li_wave(pxs, std::slice::from_ref(cam), out, q, &mut wave)
            .total()
    }

    /// Radiance of every path of camera packets `cams` (path `i·PACKET + k`: lane k of
    /// `cams[i]`, eye sample `cams[i].eye[k]` of the pixel whose samples are
    /// `pxs[cams[i].pixel[k]]`) into `radiance[i·PACKET + k]` (lanes past a packet's end are
    /// left as they are); returns the rays traced by kind. The driver of the stages, one depth
    /// at a time: the camera packets go through their first vertex as they are (their
    /// coherent rays share the packet query), and the paths that continue wait in the wave's
    /// queue; the paths at each later depth are then packed 16 to a packet whatever packet
    /// they came from (*compaction*), so a packet whose paths ended does not keep running
    /// with few lanes. Each lane's numbers are independent of its packet, so the radiance of
    /// every path is what the path alone would get ([`Self::li`]).
    pub fn li_wave(
        &self,
        pxs: &[PixelSamples],
        cams: &[CameraPacket],
        radiance: &mut [Rgb],
        q: &mut Queues,
        wave: &mut Wave,
    ) -> RayCounts {
        let t = self.techniques();
        let mut rays = RayCounts::default();
        let timing = TIME_QUERIES.load(Ordering::Relaxed);
        wave.next.clear();
        for (i, cam) in cams.iter().enumerate() {
            let first = (i * PACKET) as u32;
            q.paths.start(cam, first);
            let mut out = [Rgb::ZERO; PACKET];
            // The first round's draws are pure arithmetic that does not depend on the hits:
            // issued before the camera rays' traversal, they overlap with its memory-bound
            // work.
            self.draw(pxs, q, t, 0, q.paths.active, self.continues(0));
            let clock = timing.then(Instant::now);
            let traced = self.intersect(&cam.rays, q);
            rays.camera += traced;
            if let Some(c) = clock {
                rays.timed.camera.add(&QueryTime {
                    rays: traced,
                    ns: c.elapsed().as_nanos() as u64,
                });
            }
            self.shade(&cam.rays, q, t, &mut out);
            self.vertex(pxs, q, t, &mut out, &mut rays, timing);
            retire(q, cam.active(), &out, radiance, &mut wave.next);
        }
        let mut depth = 0;
        while !wave.next.is_empty() {
            std::mem::swap(&mut wave.now, &mut wave.next);
            wave.next.clear();
            depth += 1;
            for recs in wave.now.chunks(PACKET) {
                let mut out = [Rgb::ZERO; PACKET];
                q.paths.load(recs, depth, &mut out);
                let live = q.paths.active;
                self.draw(pxs, q, t, 0, live, self.continues(depth));
                let next = q.paths.rays;
                let clock = timing.then(Instant::now);
                self.intersect(&next, q);
                if let Some(c) = clock {
                    rays.timed.secondary.add(&QueryTime {
                        rays: u64::from(live.count_ones()),
                        ns: c.elapsed().as_nanos() as u64,
                    });
                }
                self.shade(&next, q, t, &mut out);
                self.vertex(pxs, q, t, &mut out, &mut rays, timing);
                retire(q, live, &out, radiance, &mut wave.next);
            }
        }
        rays
    }

    /// The light and BSDF sampling of the packet's current vertex, whose ray has been traced
    /// and shaded (its emission added): its M rounds (N eye rays × M shadow rays at the first
    /// vertex, one round later), then *finish*; afterwards the active lanes are the paths
    /// that continue (at the next depth). Nothing at max depth 0.
    #[inline(always)]
    fn vertex(
        &self,
        pxs: &[PixelSamples],
        q: &mut Queues,
        t: Techniques,
        out: &mut [Rgb; PACKET],
        rays: &mut RayCounts,
        timing: bool,
    ) {
        let depth = q.paths.depth;
        if depth >= self.max_depth {
            q.paths.active = 0;
            return;
        }
        let m = rounds_at(depth, self.shadow_rays.max(1));
        // Whether this vertex's BSDF ray (round 0's) may continue the path.
        let go_on = self.continues(depth);
        q.sums = [Rgb::ZERO; PACKET];
        for j in 0..m {
            if j > 0 {
                self.draw(pxs, q, t, j, q.shaded, false);
            }
            rays.shadow += self.sample_lights(q, t);
            let bsdf = self.sample_bsdfs(pxs, q, t, j, go_on && j == 0);
            if go_on && j == 0 {
                self.continue_or_terminate(pxs, q, t, m);
            }
            // Continuing rays find their emission at the next vertex (stage *shade*).
            let on = if go_on && j == 0 { q.paths.next } else { 0 };
            let on_rays = u64::from(on.count_ones());
            rays.secondary += on_rays;
            rays.gather += bsdf - on_rays;
            self.gather_emitters(q, t, on);
            let clock = timing.then(Instant::now);
            self.trace_shadows(q);
            if q.chosen != 0 {
                self.record(q, t);
            }
            if let Some(c) = clock {
                let traced = q.nee.active.count_ones() + q.gathered.active.count_ones();
                rays.timed.shadow.add(&QueryTime {
                    rays: u64::from(traced),
                    ns: c.elapsed().as_nanos() as u64,
                });
            }
            self.accumulate(q, t);
        }
        self.finish(q, m, out);
    }

    /// Whether the BSDF ray of vertex `depth` may continue its path (a later vertex samples
    /// lights and the BSDF): pbrt-v4's `depth + 1 < maxdepth`. Otherwise that ray is the
    /// path's last and only gathers the emission it reaches.
    #[inline(always)]
    fn continues(&self, depth: u32) -> bool {
        depth + 1 < self.max_depth
    }

    /// Stage *draw*: round `j`'s light and BSDF draws of the lanes `on` (only the dimensions
    /// the techniques read), at the vertex's dimensions and sample index (`dims.rs`). The
    /// permutation hash chains of the dimensions are independent, so drawing them back to back
    /// lets the CPU overlap them instead of waiting on each behind a ray query; the lobe choice
    /// is drawn later, only for receivers whose BSDF has lobes to choose (values are pure
    /// functions of pixel, dimension and index, so skipping it changes nothing).
    /// `go_on`: the round's BSDF ray may continue the path (so it is drawn whatever the
    /// techniques).
    // Forced inline: mis-area 2821 → 2808 Ir/sample (60f7c18).
    #[inline(always)]
    fn draw(
        &self,
        pxs: &[PixelSamples],
        q: &mut Queues,
        t: Techniques,
        j: u32,
        on: u32,
        go_on: bool,
    ) {
        let (n, m, depth) = (self.eye_rays.max(1), self.shadow_rays.max(1), q.paths.depth);
        let dims = VertexDims::at(depth);
        let (light, bsdf) = (t.light(), t.bsdf() || go_on);
        for k in bits(on) {
            let px = &pxs[q.paths.pixel[k] as usize];
            let (index, count) = sample_index(depth, q.paths.sample[k], j, n, m);
            let d = &mut q.drawn;
            if light {
                d.light_select[k] = px.sample_1d(dims.light_select, index, count);
                let u = px.sample_2d(dims.light, index, count);
                [d.light[0][k], d.light[1][k]] = [u.x, u.y];
            }
            if bsdf {
                let u = px.sample_2d(dims.bsdf, index, count);
                [d.bsdf[0][k], d.bsdf[1][k]] = [u.x, u.y];
            }
        }
    }

    /// Stage *intersect*: the closest hit of every active path's ray, with the hits' columns
    /// for the shading kernel. Returns the rays traced.
    #[inline(always)]
    fn intersect(&self, rays: &RayPacket, q: &mut Queues) -> u64 {
        let active = q.paths.active;
        let geometry = &self.scene.geometry;
        let counted = if q.paths.depth == 0 {
            geometry.intersect_packet_cols(rays, active, &mut q.hits, &mut q.rx.cols);
            u64::from(active.count_ones())
        } else {
            // Later vertices' rays are incoherent: one query per ray beats the packet's shared
            // traversal there (callgrind, cornell path 64² 4 spp: 200.8M Ir against 216.2M).
            // They were counted when their BSDF samples made them.
            let cols = &mut q.rx.cols;
            for k in bits(active) {
                let hit = geometry.intersect(&rays.ray(k));
                if let Some(h) = &hit {
                    for c in 0..3 {
                        cols.p[c][k] = h.p[c];
                        cols.ng[c][k] = h.ng[c];
                        cols.ns[c][k] = h.ns[c];
                    }
                    cols.p_error[k] = h.p_error;
                }
                q.hits[k] = hit;
            }
            0
        };
        // Normal and bump maps replace the shading normals before the frames are built.
        if self.scene.perturbs_normals {
            crate::scene::shading_normals::perturb_hits(
                self.scene,
                active,
                &mut q.hits[..],
                &mut q.rx.cols,
            );
        }
        counted
    }

    /// Stage *shade*: every hit's shading geometry (all lanes at once), then per lane the
    /// emission the ray found (an emitter hit or, for rays that escaped, the infinite lights),
    /// weighted by [`emission_weight`] against the vertex it left and by β, into `out`; and
    /// the BSDF at each hit with a material, routed to the Lambertian kernels when
    /// [`Bsdf::lane_kind`] says they evaluate it.
    #[inline(always)]
    fn shade(&self, rays: &RayPacket, q: &mut Queues, t: Techniques, out: &mut [Rgb; PACKET]) {
        q.rx.shade(rays, self.scene.geometry.cpu());
        q.rx.diffuse = 0;
        let mut shaded = 0;
        let emits = counts_emission(self.hide_emitters, q.paths.depth);
        for k in bits(q.paths.active) {
            let le = match &q.hits[k] {
                None => {
                    q.shading[k] = None;
                    if emits {
                        self.escaped(rays.ray(k).d.normalize(), &q.paths, k, t)
                    } else {
                        Rgb::ZERO
                    }
                }
                Some(hit) => {
                    let lane = (&mut q.shading[k], &mut q.ctx[k]);
                    let le = self.shade_hit(k, hit, &mut q.rx, lane, &q.paths, t, emits);
                    shaded |= (q.shading[k].is_some() as u32) << k;
                    le
                }
            };
            out[k] += q.paths.beta.get(k) * (le * q.paths.le_scale[k]);
        }
        q.shaded = shaded;
    }

    /// Stage *sample_lights*: each shaded lane picks a light and samples it; the light's
    /// [`LightSource`] kind routes the sample to the triangle-light kernel (for receivers the
    /// Lambertian kernels take) or to the per-lane path. Their shadow rays and values go to
    /// the `nee` queue. Returns the shadow rays made.
    #[inline(always)]
    fn sample_lights(&self, q: &mut Queues, t: Techniques) -> u64 {
        q.nee.active = 0;
        q.chosen = 0;
        if !t.light() {
            return 0;
        }
        let scene = self.scene;
        q.tri_lanes.active = 0;
        q.lone_light = 0;
        // Uniform picks ignore the shading point: pick here, without a ShadingPoint or the
        // selector per sample.
        let uniform =
            (self.selector.kind() == SelectorKind::Uniform).then_some(scene.lights.len() as u32);
        let secondary = q.paths.depth > 0;
        let learning = q.learning >> u8::from(secondary) & 1 != 0;
        for k in bits(q.shaded) {
            let u = q.drawn.light_select[k];
            let sel = match uniform {
                Some(count) => UniformSelector::pick(count, u),
                None => match q.view(k) {
                    Some(sh) => self.selector.sample_at(&sh.shading_point(), u, secondary),
                    None => continue,
                },
            };
            let Some(sel) = sel else { continue };
            if learning {
                q.chosen |= 1 << k;
                q.chosen_light[k] = sel;
            }
            let diffuse = q.rx.diffuse >> k & 1 != 0;
            match scene.lights[sel.index as usize].lane_kind() {
                Some(LaneLight::Triangle(tri)) if diffuse => {
                    q.tri_lanes.load(k, tri, sel.pmf, sel.mis_pmf)
                }
                _ => {
                    q.picked[k] = sel;
                    q.lone_light |= 1 << k;
                }
            }
        }
        let mut rays = 0;
        // The kernel writes every lane of its output, so it goes first and the per-lane path
        // then fills in its own lanes.
        if q.tri_lanes.active != 0 {
            let cpu = scene.geometry.cpu();
            let (mis, mode) = (t.mis(), self.mode());
            let u = &q.drawn.light;
            rays += u64::from(q.tri_lanes.run(&q.rx, u, mis, mode, cpu, &mut q.nee));
        }
        for k in bits(q.lone_light) {
            let Some(sh) = q.view(k) else { continue };
            if let Some((r, v, w)) = self.light_sample(&sh, q.picked[k], q.drawn.light(k), t) {
                q.nee.set_weighted(k, &r, v, w);
                rays += 1;
            }
        }
        rays
    }

    /// Stage *sample_bsdfs*: each shaded lane samples its BSDF (round `j`): Lambertian
    /// receivers in the kernel, the others one lane at a time; the rays and their weights go
    /// to the `bsdf_rays` queue. Returns the rays made (one logical ray per sample, whatever
    /// comes of it: an emitter query, maybe a visibility test).
    /// `go_on`: the rays may continue their paths (they are sampled whatever the techniques).
    #[inline(always)]
    fn sample_bsdfs(
        &self,
        pxs: &[PixelSamples],
        q: &mut Queues,
        t: Techniques,
        j: u32,
        go_on: bool,
    ) -> u64 {
        q.bsdf_rays.clear();
        if !(t.bsdf() || go_on) {
            return 0;
        }
        q.bsdf_lanes.active = q.shaded & q.rx.diffuse;
        q.lone_bsdf = q.shaded & !q.rx.diffuse;
        let mut rays = 0;
        // The kernel goes first, as in `sample_lights`.
        if q.bsdf_lanes.active != 0 {
            let cpu = self.scene.geometry.cpu();
            rays += u64::from(
                q.bsdf_lanes
                    .run(&q.rx, &q.drawn.bsdf, cpu, &mut q.bsdf_rays),
            );
        }
        let (n, m, depth) = (self.eye_rays.max(1), self.shadow_rays.max(1), q.paths.depth);
        let dim = VertexDims::at(depth).lobe;
        for k in bits(q.lone_bsdf) {
            let Some(sh) = q.view(k) else { continue };
            let px = &pxs[q.paths.pixel[k] as usize];
            let (index, count) = sample_index(depth, q.paths.sample[k], j, n, m);
            let lobe = px.sample_1d(dim, index, count);
            if let Some(b) = self.bsdf_ray(&sh, lobe, q.drawn.bsdf(k)) {
                rays += 1;
                q.bsdf_rays.set(k, &b);
            }
        }
        rays
    }

    /// Stage *gather_emitters*, for BSDF rays that end their path (all of them in direct
    /// lighting): the nearest emitter along each (a BVH of emitters only) and the value it
    /// gives, with the ray whose blocking voids it, to the `gathered` queue. The first hit of
    /// the ray is an emitter exactly when that emitter is visible, so this is the closest-hit
    /// estimator without a closest-hit query for the many rays that miss every light.
    /// Lanes of `continuing` are skipped: their rays go on to the next vertex.
    #[inline(always)]
    fn gather_emitters(&self, q: &mut Queues, t: Techniques, continuing: u32) {
        let scene = self.scene;
        q.gathered.active = 0;
        let ending = q.bsdf_rays.active & !continuing;
        let secondary = q.paths.depth > 0;
        if ending == 0 || !t.bsdf() {
            return;
        }
        scene
            .emitters
            .intersect_packet(&q.bsdf_rays.rays, ending, &mut q.emitter_hits);
        for k in bits(ending) {
            let hit = q.emitter_hits[k].as_ref();
            // Most BSDF rays reach no light: nothing to gather, no view to build.
            if hit.is_none() && scene.infinite_lights.is_empty() {
                continue;
            }
            let Some(sh) = q.view(k) else { continue };
            let b = q.bsdf_rays.get(k);
            if let Some((r, v)) = self.bsdf_gather(&sh, &b, hit, t, secondary) {
                q.gathered.set(k, &r, v);
            }
        }
    }

    /// After *trace_shadows*, when learning: what each light sample of the round would have
    /// delivered as the only strategy, f·Le·G·V/pdf_ω (its value times the selection pmf,
    /// without the MIS weight), zero when its shadow ray was blocked or the sample was void,
    /// so the learned tables see occlusion. Not the MIS-weighted value: its weight falls with
    /// the light's own selection probability (as p² under the power heuristic), so a light
    /// learned low would record ever lower values and sink to the defensive floor.
    fn record(&self, q: &mut Queues, t: Techniques) {
        let secondary = q.paths.depth > 0;
        for k in bits(q.chosen) {
            let sel = q.chosen_light[k];
            let Some(sh) = q.view(k) else { continue };
            let w = q.nee.weight(k);
            let value = match (q.nee.clear_value(k), t.mis()) {
                (None, _) => 0.0,
                (Some(v), None) => crate::luminance(v) * sel.pmf,
                // The value without its MIS weight: the weight divided out (sampling the
                // light again cost 43 % of the recording, many-mesh callgrind), unless it
                // underflowed, then the same light sample again (same draw) without MIS.
                (Some(v), Some(_)) if w > 0.0 => crate::luminance(v) * (sel.pmf / w),
                (Some(_), Some(_)) => self
                    .light_sample(&sh, sel, q.drawn.light(k), Techniques::Light)
                    .map_or(0.0, |(_, v, _)| crate::luminance(v) * sel.pmf),
            };
            let p = sh.ctx.p;
            q.records.push(LearnRecord {
                p,
                light: sel.index,
                value,
                secondary,
            });
        }
    }

    /// Stage *trace_shadows*: the visibility of every light sample and gathered emitter, one
    /// packet query each.
    #[inline(always)]
    fn trace_shadows(&self, q: &mut Queues) {
        q.nee.resolve(&self.scene.geometry);
        q.gathered.resolve(&self.scene.geometry);
    }

    /// Stage *accumulate*: the round's clear values into the vertex's sums (light sample first,
    /// then BSDF sample).
    #[inline(always)]
    fn accumulate(&self, q: &mut Queues, t: Techniques) {
        if t.light() {
            q.nee.add_to(q.shaded, &mut q.sums);
        }
        if t.bsdf() {
            q.gathered.add_to(q.shaded, &mut q.sums);
        }
    }

    /// Stage *continue_or_terminate* (after round 0's BSDF samples of a vertex whose ray may
    /// go on): each lane with a BSDF ray continues with throughput β·f·cos/pdf unless Russian
    /// roulette ([`roulette`]) ends it; the ray, the new β, the emission scale and what the
    /// MIS weight at the next hit needs go to the path queue ([`PathLanes::set_next`]). Lanes
    /// without a ray, or ended, terminate (their ray then only gathers emission).
    #[inline(always)]
    fn continue_or_terminate(&self, pxs: &[PixelSamples], q: &mut Queues, t: Techniques, m: u32) {
        let depth = q.paths.depth;
        let (n, mm) = (self.eye_rays.max(1), self.shadow_rays.max(1));
        let dim = VertexDims::at(depth).roulette;
        // The share of this vertex's BSDF-sampled emission the continuing ray carries: the
        // other rounds gather theirs (1/M each) when BSDF samples gather at all.
        let rounds_share = if t.bsdf() { 1.0 / m as f32 } else { 1.0 };
        q.paths.next = 0;
        for k in bits(q.bsdf_rays.active) {
            let Some(sh) = q.view(k) else { continue };
            let b = q.bsdf_rays.get(k);
            let beta = q.paths.beta.get(k) * b.weight;
            let survive = if self.roulette {
                let px = &pxs[q.paths.pixel[k] as usize];
                roulette(depth, beta, || {
                    let (index, count) = sample_index(depth, q.paths.sample[k], 0, n, mm);
                    px.sample_1d(dim, index, count)
                })
            } else {
                Some(1.0)
            };
            let Some(p) = survive else { continue };
            let at = sh.shading_point();
            q.paths.set_next(k, &b, beta / p, p * rounds_share, at);
        }
        q.paths.rays = q.bsdf_rays.rays;
    }

    /// Stage *finish*: each shaded path adds β times the mean of its `m` rounds to its
    /// radiance; then the continuing paths move to their next vertex and the others end
    /// (direct lighting's all end here).
    #[inline(always)]
    fn finish(&self, q: &mut Queues, m: u32, out: &mut [Rgb; PACKET]) {
        for k in bits(q.shaded) {
            out[k] += q.paths.beta.get(k) * (q.sums[k] / m as f32);
        }
        q.paths.advance();
    }

    /// The emitted radiance path `k`'s ray finds at `hit` (its shading geometry in `rx`),
    /// weighted against light sampling at the vertex the ray left (in `paths`), if it `emits`
    /// ([`counts_emission`]; zero otherwise); the hit's BSDF
    /// and light-sample context (if it has a material) go to `lane`'s two places, and a BSDF
    /// the Lambertian kernels evaluate marks the lane diffuse in `rx`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn shade_hit(
        &self,
        k: usize,
        hit: &SurfaceHit,
        rx: &mut Receivers,
        (lane, ctx): (&mut Option<LaneShading>, &mut LightSampleContext),
        paths: &PathLanes,
        t: Techniques,
        emits: bool,
    ) -> Rgb {
        let scene = self.scene;
        let g = rx.geometry(k);
        let mut l = Rgb::ZERO;
        if emits && hit.light != NO_LIGHT {
            let light = &scene.lights[hit.light as usize];
            let le = light.radiance(hit.p, hit.ng, hit.uv, g.wo);
            let w = emission_weight(t, paths.prev_delta(k), || {
                let prev = paths.prev(k);
                let wi = -g.wo;
                let at = &prev.at;
                let nee = nee_pdf(
                    self.selector,
                    paths.depth >= 2,
                    light,
                    hit.light,
                    at,
                    wi,
                    hit.p,
                    hit.ng,
                    self.mode(),
                );
                (prev.pdf, nee)
            });
            l += le * w;
        }
        let Some(material) = scene.materials.get(hit.material as usize) else {
            *lane = None;
            return l;
        };
        // The BSDF is stored straight into the lane, a diffuse one built here, any other by
        // the general constructor (not through one local: a slow copy per hit, 04e0d80).
        // The context has its own array (copied into the lane: 9 % of cornell direct, AVX-512).
        *ctx = LightSampleContext { p: hit.p, n: g.n };
        let lane = match material.lambert(hit) {
            Some(b) => lane.insert(LaneShading {
                bsdf: Bsdf::Lambert(b),
            }),
            None => lane.insert(LaneShading {
                bsdf: material.bsdf(hit, g.front),
            }),
        };
        if self.bsdf_sampling != LobeSampling::Importance {
            lane.bsdf.set_sampling(self.bsdf_sampling);
        }
        if matches!(lane.bsdf, Bsdf::DispersiveDielectric(_)) {
            lane.bsdf.for_throughput(paths.beta.get(k));
        }
        if let Some(LaneBsdf::Lambert(albedo)) = lane.bsdf.lane_kind() {
            rx.set_diffuse(k, albedo);
        }
        l
    }

    /// Radiance of the infinite lights seen along unit direction `wi` by path `k`'s ray,
    /// which escaped, each weighted against light sampling at the vertex the ray left.
    #[inline]
    fn escaped(&self, wi: Vec3, paths: &PathLanes, k: usize, t: Techniques) -> Rgb {
        let scene = self.scene;
        escaped_radiance(&scene.lights, &scene.infinite_lights, wi, |i| {
            emission_weight(t, paths.prev_delta(k), || {
                let prev = paths.prev(k);
                let light = &scene.lights[i as usize];
                let (p, n) = (Vec3::ZERO, Vec3::ZERO);
                let from = paths.depth >= 2;
                let nee = nee_pdf(
                    self.selector,
                    from,
                    light,
                    i,
                    &prev.at,
                    wi,
                    p,
                    n,
                    self.mode(),
                );
                (prev.pdf, nee)
            })
        })
    }

    /// One light-sampling estimate of light `sel` (per-lane path): the shadow ray it needs and
    /// its value if that ray is clear (`None` when it is zero anyway).
    fn light_sample(
        &self,
        sh: &Shading,
        sel: SelectedLight,
        u: Vec2,
        t: Techniques,
    ) -> Option<(Ray, Rgb, f32)> {
        let light = &self.scene.lights[sel.index as usize];
        let ls = light.sample_li(sh.ctx, u, self.mode())?;
        light_estimate(
            &ls,
            sel.pmf,
            sel.mis_pmf,
            sh.bsdf,
            &sh.frame,
            sh.wo_local,
            sh.ctx,
            sh.hit,
            t.mis(),
        )
    }

    /// One BSDF sample (per-lane path) as a ray with its weight f·cos / pdf (`None` when the
    /// estimate is zero without tracing it).
    fn bsdf_ray(&self, sh: &Shading, lobe: f32, u: Vec2) -> Option<BsdfRay> {
        // Lambert here, the rest through `Bsdf::sample`: mis-area 2863 → 2821 Ir/sample (7943ee0).
        let (bs, transmits) = match sh.bsdf {
            Bsdf::Lambert(b) => (b.sample(sh.wo_local, lobe, u), false),
            other => (other.sample(sh.wo_local, lobe, u), other.transmits()),
        };
        bsdf_ray_through(&bs?, transmits, &sh.frame, sh.ctx.n, sh.hit)
    }

    /// What BSDF ray `b` from `sh` gathers given the nearest emitter `hit` along it (`None`:
    /// it escapes unless blocked): the ray whose blocking voids it and its value, weighted
    /// against light sampling at `sh`.
    fn bsdf_gather(
        &self,
        sh: &Shading,
        b: &BsdfRay,
        hit: Option<&SurfaceHit>,
        t: Techniques,
        secondary: bool,
    ) -> Option<(Ray, Rgb)> {
        let wi = b.ray.d;
        let mode = self.mode();
        if let Some(h) = hit {
            let light = &self.scene.lights[h.light as usize];
            let v = emitter_hit_value(light, h.p, h.ng, h.uv, wi, b.weight, || {
                emission_weight(t, b.delta, || {
                    let at = sh.shading_point();
                    (
                        b.pdf,
                        nee_pdf(
                            self.selector,
                            secondary,
                            light,
                            h.light,
                            &at,
                            wi,
                            h.p,
                            h.ng,
                            mode,
                        ),
                    )
                })
            })?;
            return Some((super::estimator::shadow_ray(sh.hit, h.p), v));
        }
        if self.scene.infinite_lights.is_empty() {
            return None;
        }
        let scene = self.scene;
        let sum = escaped_radiance(&scene.lights, &scene.infinite_lights, wi, |i| {
            emission_weight(t, b.delta, || {
                let light = &scene.lights[i as usize];
                let at = sh.shading_point();
                let (p, n) = (Vec3::ZERO, Vec3::ZERO);
                (
                    b.pdf,
                    nee_pdf(self.selector, secondary, light, i, &at, wi, p, n, mode),
                )
            })
        });
        Some((b.ray, b.weight * sum))
    }
}

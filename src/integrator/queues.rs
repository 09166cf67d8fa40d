//! The work queues the stages (`stages.rs`) pass to each other: the state of a packet of
//! [`PACKET`] paths (lane k = path k) in structure-of-arrays form, one queue per kind of work
//! item, each with a bitmask of the lanes that hold one. Queues live per render thread (one
//! [`super::stages::Queues`] per tile) and are overwritten lane by lane, never reallocated.
//!
//! - [`CameraPacket`]: the camera stage's output, the rays that start the paths;
//! - [`PathLanes`]: what a path carries from vertex to vertex (throughput β, the previous
//!   vertex for the MIS weight of the emission it finds, depth, pixel and sample ids);
//! - [`Receivers`] and [`LaneShading`]: the hit/shading queue (hit geometry as columns, the
//!   BSDF per lane);
//! - [`BsdfRays`]: sampled BSDF rays before what they reach is known;
//! - [`ShadowRays`]: values that count unless their ray is blocked.
//!
//! The queues that feed the vector kernels (light samples of triangle lights, BSDF samples of
//! Lambertian receivers) sit with their kernels in `lanes.rs`.

use super::estimator::{BsdfRay, PrevVertex};
use crate::Rgb;
use crate::bsdf::{Bsdf, Lambert};
use crate::geometry::{Geometry, HitColumns, PACKET, Ray, RayPacket};
use crate::light_selection::ShadingPoint;
use glam::{Vec2, Vec3};

/// One f32 per lane.
pub(super) type Lanes = [f32; PACKET];

/// One `Vec3` per lane, as three coordinate arrays (contiguous across lanes).
#[derive(Clone, Copy)]
pub(super) struct V3 {
    pub(super) x: Lanes,
    pub(super) y: Lanes,
    pub(super) z: Lanes,
}

impl V3 {
    /// Every lane zero.
    pub(super) const ZERO: V3 = V3::splat(Vec3::ZERO);

    /// Every lane `v`.
    pub(super) const fn splat(v: Vec3) -> V3 {
        V3 {
            x: [v.x; PACKET],
            y: [v.y; PACKET],
            z: [v.z; PACKET],
        }
    }

    /// Lane k.
    #[inline(always)]
    pub(super) fn get(&self, k: usize) -> Vec3 {
        Vec3::new(self.x[k], self.y[k], self.z[k])
    }

    /// Make lane k `v`.
    #[inline(always)]
    pub(super) fn set(&mut self, k: usize, v: Vec3) {
        self.x[k] = v.x;
        self.y[k] = v.y;
        self.z[k] = v.z;
    }
}

/// Lane k of a column triple.
#[inline(always)]
pub(super) fn col(c: &[Lanes; 3], k: usize) -> Vec3 {
    Vec3::new(c[0][k], c[1][k], c[2][k])
}

/// The camera stage's ray queue: lane k < `n` is eye sample `eye[k]` of pixel `pixel[k]` (an
/// index into the caller's pixel samples) along ray k of `rays`.
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

    /// Copy the lanes (not the rays) into `to`, the packet's place in a wave, whose rays are
    /// then made in place: the rays are most of a packet's bytes.
    #[inline]
    pub fn complete(&self, to: &mut CameraPacket) {
        to.n = self.n;
        to.pixel = self.pixel;
        to.eye = self.eye;
    }

    /// Mask of the lanes in use.
    pub(super) fn active(&self) -> u32 {
        ((1u64 << self.n) - 1) as u32
    }
}

/// What each path carries from one vertex to the next.
pub(super) struct PathLanes {
    /// Paths still alive.
    pub(super) active: u32,
    /// Vertices behind the paths' current rays (0: camera rays). All lanes of a packet are at
    /// the same depth.
    pub(super) depth: u32,
    /// Per lane: index of its pixel's samples (the pattern's pixel).
    pub(super) pixel: [u8; PACKET],
    /// Per lane: eye sample index within the pixel (the pattern's sample index at depth 0).
    pub(super) sample: [u32; PACKET],
    /// Per lane: the path's index in its wave (where its radiance goes when it ends).
    pub(super) id: [u32; PACKET],
    /// Throughput β: the product of the BSDF weights f·cos / pdf of the bounces so far
    /// (divided by the Russian-roulette survival probabilities).
    pub(super) beta: V3,
    /// Per lane: the factor of the emission the current ray finds (1 for camera rays): the
    /// share of the previous vertex's BSDF-sampled emission this ray stands for (1/M beside
    /// the other rounds' gathered rays), times the roulette survival probability that β was
    /// divided by (that emission belongs to the previous vertex, which counts it whether the
    /// path survives or not).
    pub(super) le_scale: Lanes,
    /// The rays of the paths that continue (written by stage *continue_or_terminate*).
    pub(super) rays: RayPacket,
    /// Lanes whose path continues past the current vertex.
    pub(super) next: u32,
    /// Per continuing lane: its throughput at the next vertex.
    beta_next: V3,
    /// Bit k: path k's current ray left the camera or a delta lobe (its emission weight is 1).
    prev_delta: u32,
    /// Per lane: the pdf of the BSDF sample that made the current ray.
    prev_pdf: Lanes,
    /// Per lane: the vertex the current ray left, as light selection saw it.
    prev_at: [ShadingPoint; PACKET],
}

impl PathLanes {
    /// No paths.
    pub(super) fn new() -> Self {
        Self {
            active: 0,
            depth: 0,
            pixel: [0; PACKET],
            sample: [0; PACKET],
            id: [0; PACKET],
            beta: V3::splat(Vec3::ONE),
            le_scale: [1.0; PACKET],
            rays: RayPacket::from_rays(&[Ray::new(Vec3::ZERO, Vec3::Z); PACKET]),
            next: 0,
            beta_next: V3::splat(Vec3::ONE),
            prev_delta: u32::MAX,
            prev_pdf: [0.0; PACKET],
            prev_at: [ShadingPoint {
                p: Vec3::ZERO,
                n: Vec3::ZERO,
                wo: Vec3::ZERO,
            }; PACKET],
        }
    }

    /// The paths of camera packet `cam`: β = 1, leaving the camera (whose rays count what they
    /// see with weight 1, as a delta vertex's); lane k is path `first + k` of its wave.
    #[inline]
    pub(super) fn start(&mut self, cam: &CameraPacket, first: u32) {
        self.active = cam.active();
        self.depth = 0;
        self.pixel = cam.pixel;
        self.sample = cam.eye;
        self.id = std::array::from_fn(|k| first + k as u32);
        self.beta = V3::splat(Vec3::ONE);
        self.le_scale = [1.0; PACKET];
        self.next = 0;
        self.prev_delta = u32::MAX;
    }

    /// Path k continues along BSDF ray `b` (sampled at `at`, as light selection saw it) with
    /// throughput `beta` at the next vertex and emission scale `le_scale` there (the current
    /// vertex's emission has been counted: its fields can be overwritten).
    #[inline]
    pub(super) fn set_next(
        &mut self,
        k: usize,
        b: &BsdfRay,
        beta: crate::Rgb,
        le_scale: f32,
        at: ShadingPoint,
    ) {
        self.next |= 1 << k;
        self.beta_next.set(k, beta);
        self.le_scale[k] = le_scale;
        self.prev_delta = (self.prev_delta & !(1 << k)) | ((b.delta as u32) << k);
        self.prev_pdf[k] = b.pdf;
        self.prev_at[k] = at;
    }

    /// Move to the next vertex: the continuing paths stay active with their new throughput,
    /// the others end.
    #[inline]
    pub(super) fn advance(&mut self) {
        self.active = self.next;
        self.next = 0;
        if self.active != 0 {
            self.beta = self.beta_next;
            self.depth += 1;
        }
    }

    /// Load waiting paths `recs` (at most [`PACKET`], all at vertex `depth`) into lanes
    /// 0..recs.len(), their radiance so far into `out`: each lane then holds exactly the state
    /// it had when [`Self::record`] saved it (lanes are independent: a path's numbers do not
    /// depend on the lane or the packet it runs in).
    #[inline]
    pub(super) fn load(&mut self, recs: &[PathRecord], depth: u32, out: &mut [Rgb; PACKET]) {
        debug_assert!(recs.len() <= PACKET);
        self.active = ((1u64 << recs.len()) - 1) as u32;
        self.depth = depth;
        self.next = 0;
        let mut delta = 0;
        for (k, r) in recs.iter().enumerate() {
            self.pixel[k] = r.pixel;
            self.sample[k] = r.sample;
            self.id[k] = r.id;
            self.beta.set(k, r.beta);
            self.le_scale[k] = r.le_scale;
            self.rays.set(k, &r.ray);
            delta |= (r.prev_delta as u32) << k;
            self.prev_pdf[k] = r.prev_pdf;
            self.prev_at[k] = r.prev_at;
            out[k] = r.l;
        }
        self.prev_delta = delta;
    }

    /// Lane k's path as it waits for its next vertex, with radiance `l` so far (valid for
    /// an active lane after [`Self::advance`]).
    #[inline]
    pub(super) fn record(&self, k: usize, l: Rgb) -> PathRecord {
        PathRecord {
            ray: self.rays.ray(k),
            beta: self.beta.get(k),
            l,
            prev_at: self.prev_at[k],
            le_scale: self.le_scale[k],
            prev_pdf: self.prev_pdf[k],
            id: self.id[k],
            sample: self.sample[k],
            pixel: self.pixel[k],
            prev_delta: self.prev_delta(k),
        }
    }

    /// Whether path k's current ray left the camera or a delta lobe.
    #[inline(always)]
    pub(super) fn prev_delta(&self, k: usize) -> bool {
        self.prev_delta >> k & 1 != 0
    }

    /// The vertex path k's current ray left (read only where an MIS weight needs it).
    #[inline]
    pub(super) fn prev(&self, k: usize) -> PrevVertex {
        PrevVertex {
            pdf: self.prev_pdf[k],
            at: self.prev_at[k],
        }
    }
}

/// A path between two vertices, out of its lane: the wave's queue of paths waiting for their
/// next vertex holds these, and the paths at one depth are packed 16 to a packet again
/// whatever packets they came from (see `stages.rs`, *compaction*).
#[derive(Clone, Copy, Debug)]
pub(super) struct PathRecord {
    /// The ray to trace next.
    pub(super) ray: Ray,
    /// Throughput β at the next vertex.
    pub(super) beta: Rgb,
    /// Radiance gathered so far.
    pub(super) l: Rgb,
    /// The vertex the ray left, as light selection saw it.
    pub(super) prev_at: ShadingPoint,
    /// Emission scale of the ray (see [`PathLanes::le_scale`]).
    pub(super) le_scale: f32,
    /// Pdf of the BSDF sample that made the ray.
    pub(super) prev_pdf: f32,
    /// Index of the path in its wave.
    pub(super) id: u32,
    /// Eye sample index within the pixel.
    pub(super) sample: u32,
    /// Index of the pixel's samples.
    pub(super) pixel: u8,
    /// The ray left a delta lobe.
    pub(super) prev_delta: bool,
}

/// The pattern values of a round's light and BSDF samples, per lane (written by the draw
/// stage, read by the per-lane paths and, as columns, by the kernels).
pub(super) struct Draws {
    /// Light-selection numbers.
    pub(super) light_select: Lanes,
    /// Points on the lights: `light[axis][lane]`.
    pub(super) light: [Lanes; 2],
    /// BSDF directions: `bsdf[axis][lane]`.
    pub(super) bsdf: [Lanes; 2],
}

impl Draws {
    /// All zero.
    pub(super) fn new() -> Self {
        Self {
            light_select: [0.0; PACKET],
            light: [[0.0; PACKET]; 2],
            bsdf: [[0.0; PACKET]; 2],
        }
    }

    /// Lane k's point-on-light draw.
    #[inline(always)]
    pub(super) fn light(&self, k: usize) -> Vec2 {
        Vec2::new(self.light[0][k], self.light[1][k])
    }

    /// Lane k's BSDF-direction draw.
    #[inline(always)]
    pub(super) fn bsdf(&self, k: usize) -> Vec2 {
        Vec2::new(self.bsdf[0][k], self.bsdf[1][k])
    }
}

/// The hit/shading queue's geometry: each hit's shading geometry (computed for all lanes at
/// once by `Receivers::shade`, a kernel in `lanes.rs`) and, for the Lambertian ones, what the
/// kernels read. Bit k of `diffuse` marks lane k as a receiver for the Lambertian kernels.
#[derive(Clone, Copy)]
pub(super) struct Receivers {
    /// Lanes whose receiver is Lambertian with cosine sampling.
    pub(super) diffuse: u32,
    /// The hits' points, normals and error bounds, written by the closest-hit query itself.
    pub(super) cols: HitColumns,
    pub(super) wo: V3,
    pub(super) front: [bool; PACKET],
    /// Geometric normal facing the viewer (the light-sample context's).
    pub(super) n: V3,
    pub(super) s: V3,
    pub(super) t: V3,
    pub(super) sn: V3,
    pub(super) wo_local: V3,
    pub(super) albedo: V3,
}

impl Receivers {
    /// No lanes loaded.
    pub(super) fn new() -> Self {
        Self {
            diffuse: 0,
            cols: HitColumns::new(),
            wo: V3::ZERO,
            front: [false; PACKET],
            n: V3::ZERO,
            s: V3::ZERO,
            t: V3::ZERO,
            sn: V3::ZERO,
            wo_local: V3::ZERO,
            albedo: V3::ZERO,
        }
    }

    /// Route lane k to the Lambertian kernels with albedo `r`.
    #[inline]
    pub(super) fn set_diffuse(&mut self, k: usize, r: Rgb) {
        self.diffuse |= 1 << k;
        self.albedo.set(k, r);
    }

    /// Lane k's Lambertian BSDF as the kernels evaluate it (valid for `diffuse` lanes).
    #[inline(always)]
    pub(super) fn lambert(&self, k: usize) -> Lambert {
        // Importance and cosine sampling coincide for a Lambertian BSDF.
        Lambert {
            r: self.albedo.get(k),
            sampling: crate::bsdf::LobeSampling::Importance,
        }
    }
}

/// The per-lane part of a hit's shading state (the geometry is in [`Receivers`], the light
/// sample context beside it in the stages' queues).
pub(super) struct LaneShading {
    /// The BSDF at the hit.
    pub(super) bsdf: Bsdf,
}

/// Values that count unless their ray is blocked (light samples' shadow rays, the visibility
/// rays of BSDF rays that reached an emitter): the rays go to the geometry as one packet
/// query, in the lanes the kernels write them to.
pub(super) struct ShadowRays {
    /// Lanes with a ray.
    pub(super) active: u32,
    pub(super) rays: RayPacket,
    value: V3,
    /// Per lane: the MIS weight inside `value` (1 without MIS), so `online`'s records can
    /// take the light sample's unweighted value without sampling the light again.
    weight: [f32; PACKET],
    /// After [`Self::resolve`]: the active lanes whose rays are clear.
    clear: u32,
}

impl ShadowRays {
    /// No lanes active.
    pub(super) fn new() -> Self {
        Self {
            active: 0,
            rays: RayPacket::from_rays(&[Ray::new(Vec3::ZERO, Vec3::Z); PACKET]),
            value: V3::ZERO,
            weight: [1.0; PACKET],
            clear: 0,
        }
    }

    /// Lane k's ray and value, not (yet) active.
    #[inline(always)]
    pub(super) fn put(&mut self, k: usize, ray: &Ray, value: Rgb) {
        self.rays.set(k, ray);
        self.value.set(k, value);
    }

    /// Lane k's ray, value and the MIS weight inside the value, not (yet) active.
    #[inline(always)]
    pub(super) fn put_weighted(&mut self, k: usize, ray: &Ray, value: Rgb, weight: f32) {
        self.put(k, ray, value);
        self.weight[k] = weight;
    }

    /// Make lane k active with `ray`, `value` and the MIS weight inside the value.
    #[inline]
    pub(super) fn set_weighted(&mut self, k: usize, ray: &Ray, value: Rgb, weight: f32) {
        self.active |= 1 << k;
        self.put_weighted(k, ray, value, weight);
    }

    /// Make lane k active with `ray` and `value`.
    #[inline]
    pub(super) fn set(&mut self, k: usize, ray: &Ray, value: Rgb) {
        self.active |= 1 << k;
        self.put(k, ray, value);
    }

    /// Lane k's value (for tests of the kernels that write it).
    #[cfg(test)]
    pub(super) fn value(&self, k: usize) -> Rgb {
        self.value.get(k)
    }

    /// Trace the active rays: afterwards [`Self::add_to`] adds the values whose ray is clear.
    pub(super) fn resolve(&mut self, geometry: &Geometry) {
        let blocked = if self.active != 0 {
            geometry.occluded_packet(&self.rays, self.active)
        } else {
            0
        };
        self.clear = self.active & !blocked;
    }

    /// Lane k's value if it had a ray and the ray is clear (after [`Self::resolve`]).
    #[inline]
    pub(super) fn clear_value(&self, k: usize) -> Option<Rgb> {
        (self.clear >> k & 1 != 0).then(|| self.value.get(k))
    }

    /// The MIS weight of lane k's value (as last written by a `*_weighted` call).
    #[inline]
    pub(super) fn weight(&self, k: usize) -> f32 {
        self.weight[k]
    }

    /// Add to `sums` each lane's value where its ray is clear, zero elsewhere, for the lanes
    /// `on` (valid after [`Self::resolve`]).
    #[inline]
    pub(super) fn add_to(&self, on: u32, sums: &mut [Rgb; PACKET]) {
        for (k, s) in sums.iter_mut().enumerate() {
            if on >> k & 1 != 0 {
                let clear = self.clear >> k & 1 != 0;
                *s += if clear { self.value.get(k) } else { Rgb::ZERO };
            }
        }
    }
}

/// The BSDF rays of a packet's lanes (bit k of `active`: lane k has one), field by field: the
/// rays go to the query as they are, and the rest is read only for lanes that need it.
pub(super) struct BsdfRays {
    /// Lanes with a ray.
    pub(super) active: u32,
    /// The rays.
    pub(super) rays: RayPacket,
    weight: V3,
    pdf: Lanes,
    /// Bit k: lane k's sample is from a delta lobe.
    delta: u32,
}

impl BsdfRays {
    /// No lanes active.
    pub(super) fn new() -> Self {
        Self {
            active: 0,
            rays: RayPacket::from_rays(&[Ray::new(Vec3::ZERO, Vec3::Z); PACKET]),
            weight: V3::ZERO,
            pdf: [0.0; PACKET],
            delta: 0,
        }
    }

    /// Start a new round: no lanes active.
    #[inline]
    pub(super) fn clear(&mut self) {
        self.active = 0;
        self.delta = 0;
    }

    /// Lane k's ray, not (yet) active (and not from a delta lobe).
    #[inline(always)]
    pub(super) fn put(&mut self, k: usize, b: &BsdfRay) {
        self.rays.set(k, &b.ray);
        self.weight.set(k, b.weight);
        self.pdf[k] = b.pdf;
    }

    /// Make lane k active with ray `b`.
    #[inline]
    pub(super) fn set(&mut self, k: usize, b: &BsdfRay) {
        self.active |= 1 << k;
        self.put(k, b);
        self.delta |= (b.delta as u32) << k;
    }

    /// Lane k's ray.
    #[inline]
    pub(super) fn get(&self, k: usize) -> BsdfRay {
        BsdfRay {
            ray: self.rays.ray(k),
            weight: self.weight.get(k),
            pdf: self.pdf[k],
            delta: self.delta >> k & 1 != 0,
        }
    }
}

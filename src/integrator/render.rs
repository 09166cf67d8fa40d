//! The render loop: 16×16 tiles in parallel (rayon); every sample is a pure function of
//! (seed, pixel, sample index, dimension), and tiles are assembled in a fixed order, so the
//! image is bit-identical for any thread count and schedule.

use super::RenderOptions;
use super::dims::{DIM_FILTER, DIM_LENS};
use super::film::{FilterSampler, box_sample, filter_sample, tent_sample};
use super::queues::CameraPacket;
use super::stages::{Integrator, Queues, RayCounts, Wave};
use crate::Rgb;
use crate::camera::CameraRays;
use crate::geometry::{PACKET, Ray, RayPacket};
use crate::image::Image;
use crate::isa::{Cpu, Kernel, Token};
use crate::light_selection::online::{Digest, OnlineLearner};
use crate::light_selection::{LightSelector, SelectorKind, make_selector};
use crate::sampling::{PixelSamples, make_pattern};
use crate::scene::Filter;
use crate::scene::Scene;
use glam::{UVec2, Vec2, Vec3};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

const TILE: u32 = 16;

/// Camera packets per wave (see [`Integrator::li_wave`]): the paths of this many packets are
/// compacted together at each depth.
const WAVE: usize = 64;

/// The most pixels along each axis one splatted sample reaches (filter radius ≤ 8).
const SPLAT_SPAN: usize = 17;

/// What a render thread reuses from tile to tile.
struct TileWork {
    /// One per pixel of a tile (a pixel's slot is its index in the tile).
    pxs: Vec<PixelSamples>,
    /// The wave's camera packets, all [`WAVE`] of them kept (their rays are made in place).
    cams: Vec<CameraPacket>,
    /// Per camera packet: its lanes' filter weights.
    weights: Vec<[f32; PACKET]>,
    /// Per camera packet: its lanes' positions in their pixels (splatting only).
    us: Vec<[Vec2; PACKET]>,
    /// Per path of the wave: its radiance.
    radiance: Vec<Rgb>,
    queues: Queues,
    wave: Wave,
}

impl TileWork {
    fn new(pattern: &dyn crate::sampling::SamplePattern) -> Self {
        Self {
            // The filter samples of a wave's camera packets are drawn before any is shaded.
            pxs: (0..TILE * TILE)
                .map(|_| {
                    let mut px = pattern.pixel(UVec2::ZERO);
                    px.read_ahead_2d(DIM_FILTER);
                    px
                })
                .collect(),
            cams: vec![CameraPacket::new(); WAVE],
            weights: vec![[1.0; PACKET]; WAVE],
            us: vec![[Vec2::ZERO; PACKET]; WAVE],
            radiance: vec![Rgb::ZERO; WAVE * PACKET],
            queues: Queues::new(),
            wave: Wave::new(),
        }
    }
}

/// What a render measured.
#[derive(Clone, Debug)]
pub struct RenderStats {
    /// Wall time of the render loop (excluding scene build).
    pub time: Duration,
    /// Rays traced (camera, shadow and BSDF rays).
    pub rays: u64,
    /// The same by kind.
    pub by_kind: RayCounts,
    /// Samples whose radiance was NaN/Inf and were dropped.
    pub non_finite: u64,
    /// Render loops the samples took: 1, or `online` selection's rounds (fewer than
    /// [`super::online_rounds`] once its learning has settled on power selection).
    pub rounds: u32,
}

impl RenderStats {
    /// Millions of rays per second.
    pub fn mrays_per_s(&self) -> f64 {
        self.rays as f64 / self.time.as_secs_f64().max(1e-9) / 1e6
    }
}

/// Render `scene` at `res` with `opts`.
pub fn render(
    scene: &Scene,
    res: UVec2,
    opts: &RenderOptions,
) -> anyhow::Result<(Image, RenderStats)> {
    if opts.light_selection == SelectorKind::Online {
        return super::rounds::render_online(scene, res, opts);
    }
    let selector = make_selector(opts.light_selection, scene, opts.seed);
    let (img, stats, _) = render_with(scene, res, opts, selector.as_ref(), None)?;
    Ok((img, stats))
}

/// [`render`] with light selection `selector`; with a `learner`, every tile also records
/// what its light samples delivered and returns it summed ([`OnlineLearner::digest`]), in
/// tile order.
pub(super) fn render_with(
    scene: &Scene,
    res: UVec2,
    opts: &RenderOptions,
    selector: &dyn LightSelector,
    learner: Option<&OnlineLearner>,
) -> anyhow::Result<(Image, RenderStats, Vec<Digest>)> {
    anyhow::ensure!(
        res.x > 0 && res.y > 0,
        "resolution must be positive, got {}x{}",
        res.x,
        res.y
    );
    anyhow::ensure!(opts.spp > 0, "--spp must be at least 1");
    let samples = opts.samples()?;
    let pattern = make_pattern(opts.pattern, opts.seed);
    let est = Integrator {
        scene,
        selector,
        pattern: pattern.as_ref(),
        strategy: opts.strategy,
        mis: opts.mis,
        eye_rays: opts.spp,
        shadow_rays: opts.shadow_rays.max(1),
        bsdf_sampling: opts.bsdf_sampling,
        mis_light: opts.mis_light,
        max_depth: opts.depth(),
        roulette: opts.roulette,
        hide_emitters: opts.hide_emitters,
    };
    let camera = scene.camera.rays(res);
    // Splatting draws each sample uniformly over its pixel (a box of radius ½) and weighs it
    // by the film's filter afterwards, into every pixel within the filter's radius: `apron`
    // pixels around each tile receive its samples too.
    let splat = opts.splat;
    let film_filter = scene.film.filter;
    let filter = if splat {
        FilterSampler::new(&Filter::Box {
            radius: Vec2::splat(0.5),
        })?
    } else {
        FilterSampler::new(&film_filter)?
    };
    let apron = if splat {
        film_filter.radius().max_element().ceil().max(0.0) as u32
    } else {
        0
    };
    let tent = match film_filter {
        Filter::Triangle { radius } => Some(radius),
        _ => None,
    };
    anyhow::ensure!(
        (2 * apron + 1) as usize <= SPLAT_SPAN,
        "--splat: the pixel filter's radius {} is wider than splatting supports",
        film_filter.radius().max_element()
    );
    let cpu = scene.geometry.cpu();
    let tiles_x = res.x.div_ceil(TILE);
    let tiles_y = res.y.div_ceil(TILE);
    let n_tiles = (tiles_x * tiles_y) as u64;
    let bar = if opts.progress && std::io::stderr().is_terminal() {
        let b = ProgressBar::with_draw_target(Some(n_tiles), ProgressDrawTarget::stderr());
        if let Ok(style) =
            ProgressStyle::with_template("{bar:40} {percent:>3}% {elapsed} ETA {eta}")
        {
            b.set_style(style);
        }
        b
    } else {
        ProgressBar::hidden()
    };
    let rays = AtomicU64::new(0);
    let counts = std::sync::Mutex::new(RayCounts::default());
    let bad = AtomicU64::new(0);
    let works: Vec<std::sync::Mutex<Option<TileWork>>> = (0..rayon::current_num_threads().max(1))
        .map(|_| std::sync::Mutex::new(None))
        .collect();
    let start = Instant::now();
    let (tiles, digests): (Vec<TileOut>, Vec<Option<Digest>>) = (0..tiles_x * tiles_y)
        .into_par_iter()
        // Per worker thread: one PixelSamples per pixel of a tile (filled in place) and the
        // wave's queues, made once and reused from tile to tile (rayon's `map_init` would make
        // them again for every split of the range).
        .map(|t| {
            let me = rayon::current_thread_index().unwrap_or(0) % works.len();
            let mut guard = works[me].lock().unwrap_or_else(|e| e.into_inner());
            let work = guard.get_or_insert_with(|| TileWork::new(pattern.as_ref()));
            let (tx, ty) = (t % tiles_x, t / tiles_x);
            let x0 = tx * TILE;
            let y0 = ty * TILE;
            let x1 = (x0 + TILE).min(res.x);
            let y1 = (y0 + TILE).min(res.y);
            let (w, h) = (x1 - x0, y1 - y0);
            // Samples in pixel-major order, PACKET at a time into camera packets, up to
            // WAVE packets at a time into a wave: a pixel's sum adds its samples in index
            // order, exactly as one loop per pixel would, whatever order the wave's paths
            // finish in.
            let mut sums = vec![Rgb::ZERO; (w * h) as usize];
            // Splatting: per pixel of the tile and its apron (row-major, `aw` wide), the
            // filter-weighted radiance and the sum of the weights.
            let aw = w + 2 * apron;
            let mut splats = if splat {
                vec![(Rgb::ZERO, 0.0f32); (aw * (h + 2 * apron)) as usize]
            } else {
                Vec::new()
            };
            let TileWork {
                pxs,
                cams,
                weights,
                us,
                radiance,
                queues,
                wave,
            } = work;
            queues.learning = learner.map_or(0, OnlineLearner::learning);
            queues.records.clear();
            // The wave's packets before `filled` are complete; the lanes of the next one fill
            // `cam`, whose rays are made straight into its place in the wave.
            let mut filled = 0;
            let mut cam = CameraPacket::new();
            let (mut tile_rays, mut tile_bad) = (RayCounts::default(), 0u64);
            let mut flush = |cams: &[CameraPacket],
                             weights: &[[f32; PACKET]],
                             us: &[[Vec2; PACKET]],
                             pxs: &[PixelSamples]| {
                let counts = est.li_wave(pxs, cams, radiance, queues, wave);
                tile_rays.add(&counts);
                if splat {
                    for (i, (cam, u)) in cams.iter().zip(us.iter()).enumerate() {
                        for k in 0..cam.n {
                            let l = radiance[i * PACKET + k];
                            if !l.is_finite() {
                                tile_bad += 1;
                                continue;
                            }
                            // The filter is separable: its weight in the pixel `d` columns
                            // and `e` rows away is gx[d]·gy[e], each the profile at the
                            // sample's offset from that pixel's centre.
                            let n = (2 * apron + 1) as usize;
                            let (mut gx, mut gy) = ([0.0f32; SPLAT_SPAN], [0.0f32; SPLAT_SPAN]);
                            for d in 0..n {
                                let c = d as f32 - apron as f32 + 0.5;
                                let (ox, oy) = (u[k].x - c, u[k].y - c);
                                // The tent (the default filter) inline, in f32.
                                (gx[d], gy[d]) = match tent {
                                    Some(r) => {
                                        ((r.x - ox.abs()).max(0.0), (r.y - oy.abs()).max(0.0))
                                    }
                                    None => (
                                        film_filter.profile(0, ox as f64) as f32,
                                        film_filter.profile(1, oy as f64) as f32,
                                    ),
                                };
                            }
                            let slot = cam.pixel[k] as u32;
                            // The top-left pixel of the sample's neighbourhood, in the apron's
                            // coordinates.
                            let corner = (slot / w) * aw + slot % w;
                            for (e, &wy) in gy[..n].iter().enumerate() {
                                if wy == 0.0 {
                                    continue;
                                }
                                let row = corner as usize + e * aw as usize;
                                for (d, &wx) in gx[..n].iter().enumerate() {
                                    let f = wx * wy;
                                    if f == 0.0 {
                                        continue;
                                    }
                                    let s = &mut splats[row + d];
                                    s.0 += l * f;
                                    s.1 += f;
                                }
                            }
                        }
                    }
                    return;
                }
                // A pixel's consecutive samples are summed in a register (`sum`, of pixel
                // `cur`), the same additions in the same order (through `sums`: 3 % of cornell
                // direct, AVX-512, perf).
                // Filters with negative lobes weight their samples (mean weight 1); box, tent
                // and gaussian samples all weigh exactly 1.
                let analytic = filter.is_analytic();
                let (mut cur, mut sum) = (usize::MAX, Rgb::ZERO);
                for (i, (cam, weight)) in cams.iter().zip(weights).enumerate() {
                    for (k, &l) in radiance[i * PACKET..][..cam.n].iter().enumerate() {
                        let l = if analytic { l } else { l * weight[k] };
                        if !l.is_finite() {
                            tile_bad += 1;
                            continue;
                        }
                        let slot = cam.pixel[k] as usize;
                        if slot != cur {
                            if cur != usize::MAX {
                                sums[cur] = sum;
                            }
                            (cur, sum) = (slot, sums[slot]);
                        }
                        sum += l;
                    }
                }
                if cur != usize::MAX {
                    sums[cur] = sum;
                }
            };
            // Per lane: the pixel and filter draw; the camera rays of a full packet are then
            // made all at once (16 lanes of vector sqrt / division instead of a scalar chain).
            let mut lanes = CameraLanes::new();
            let lens = camera.needs_lens_sample();
            for y in y0..y1 {
                for x in x0..x1 {
                    if opts.is_cancelled() {
                        break;
                    }
                    let pixel = UVec2::new(x, y);
                    // The pixel's slot is its index in the tile (and in `sums`).
                    let slot = ((y - y0) * w + (x - x0)) as usize;
                    pattern.pixel_into(pixel, &mut pxs[slot]);
                    for i in samples.clone() {
                        let k = cam.n;
                        lanes.pixel[k] = pixel;
                        lanes.u[k] = pxs[slot].sample_2d(DIM_FILTER, i, opts.spp);
                        if lens {
                            lanes.lens[k] = pxs[slot].sample_2d(DIM_LENS, i, opts.spp);
                        }
                        cam.pixel[k] = slot as u8;
                        cam.eye[k] = i;
                        cam.n = k + 1;
                        if cam.is_full() {
                            cam.complete(&mut cams[filled]);
                            lanes.rays(cpu, &camera, &filter, &mut cams[filled].rays);
                            weights[filled] = lanes.weight;
                            us[filled] = lanes.u;
                            filled += 1;
                            if filled == WAVE {
                                flush(cams, weights, us, pxs);
                                filled = 0;
                            }
                            cam.clear();
                        }
                    }
                }
            }
            if cam.n > 0 {
                cam.complete(&mut cams[filled]);
                lanes.rays(cpu, &camera, &filter, &mut cams[filled].rays);
                weights[filled] = lanes.weight;
                us[filled] = lanes.u;
                filled += 1;
            }
            if filled > 0 {
                flush(&cams[..filled], &weights[..filled], &us[..filled], pxs);
            }
            let out = if splat {
                TileOut::Splats(splats)
            } else {
                TileOut::Pixels(sums.iter().map(|&s| s / samples.len() as f32).collect())
            };
            rays.fetch_add(tile_rays.total(), Ordering::Relaxed);
            if let Ok(mut c) = counts.lock() {
                c.add(&tile_rays);
            }
            bad.fetch_add(tile_bad, Ordering::Relaxed);
            bar.inc(1);
            let digest = learner.map(|l| l.digest(&queues.records));
            (out, digest)
        })
        .unzip();
    bar.finish_and_clear();
    if opts.is_cancelled() {
        return Err(super::Cancelled.into());
    }
    let time = start.elapsed();
    let mut img = Image::new(res.x, res.y);
    // Splats are summed tile by tile in tile order, so a pixel that receives samples from
    // several tiles adds them in the same order for any thread count.
    let mut received = if splat {
        vec![(Rgb::ZERO, 0.0f32); (res.x * res.y) as usize]
    } else {
        Vec::new()
    };
    for (t, tile) in tiles.iter().enumerate() {
        let t = t as u32;
        let (x0, y0) = ((t % tiles_x) * TILE, (t / tiles_x) * TILE);
        let w = (x0 + TILE).min(res.x) - x0;
        match tile {
            TileOut::Pixels(pixels) => {
                for (i, px) in pixels.iter().enumerate() {
                    let (x, y) = (x0 + i as u32 % w, y0 + i as u32 / w);
                    img.pixels[(y * res.x + x) as usize] = *px;
                }
            }
            TileOut::Splats(splats) => {
                let aw = w + 2 * apron;
                for (i, s) in splats.iter().enumerate() {
                    let x = (x0 + i as u32 % aw) as i64 - apron as i64;
                    let y = (y0 + i as u32 / aw) as i64 - apron as i64;
                    if x < 0 || y < 0 || x >= res.x as i64 || y >= res.y as i64 {
                        continue;
                    }
                    let r = &mut received[(y as u32 * res.x + x as u32) as usize];
                    r.0 += s.0;
                    r.1 += s.1;
                }
            }
        }
    }
    if splat {
        for (px, (l, wsum)) in img.pixels.iter_mut().zip(&received) {
            *px = if *wsum > 0.0 { *l / *wsum } else { Rgb::ZERO };
        }
    }
    let stats = RenderStats {
        time,
        rays: rays.into_inner(),
        by_kind: counts.into_inner().unwrap_or_default(),
        non_finite: bad.into_inner(),
        rounds: 1,
    };
    if stats.non_finite > 0 {
        eprintln!(
            "warning: {} samples had a non-finite radiance and were dropped",
            stats.non_finite
        );
    }
    Ok((img, stats, digests.into_iter().flatten().collect()))
}

/// The camera samples of a packet's lanes before their rays are made.
/// A finished tile: its pixels, or (splatting) the weighted radiance and weight sums of its
/// pixels and apron.
enum TileOut {
    Pixels(Vec<Rgb>),
    Splats(Vec<(Rgb, f32)>),
}

struct CameraLanes {
    /// Per lane: the pixel.
    pixel: [UVec2; PACKET],
    /// Per lane: the pixel-filter draw.
    u: [Vec2; PACKET],
    /// Per lane: the lens draw (thin-lens cameras only).
    lens: [Vec2; PACKET],
    /// Per lane: the filter weight of the sample (1 unless the filter has negative lobes).
    weight: [f32; PACKET],
}

impl CameraLanes {
    fn new() -> Self {
        Self {
            pixel: [UVec2::ZERO; PACKET],
            u: [Vec2::splat(0.5); PACKET],
            lens: [Vec2::splat(0.5); PACKET],
            weight: [1.0; PACKET],
        }
    }

    /// The camera ray (and filter weight) of every lane into `ray` (lanes past the packet's
    /// end get rays too, of stale samples, which nothing reads). A pinhole perspective camera
    /// under a box or tent filter, the common case, runs [`filter_sample`] then
    /// [`CameraRays::direction`] per lane exactly as the scalar [`CameraRays::generate`], on
    /// `isa`'s widest vectors; other cameras and tabulated filters take one scalar loop.
    #[inline]
    fn rays(&mut self, cpu: Cpu, camera: &CameraRays, filter: &FilterSampler, ray: &mut RayPacket) {
        if !(camera.is_pinhole() && filter.is_analytic()) {
            return self.rays_general(camera, filter, ray);
        }
        struct Rays<'a>(
            &'a CameraLanes,
            &'a CameraRays,
            &'a Filter,
            &'a mut RayPacket,
        );
        impl Kernel for Rays<'_> {
            type Output = ();
            #[inline(always)]
            fn run<T: Token>(self, _: T) {
                self.0.rays_portable(self.1, self.2, self.3)
            }
        }
        cpu.dispatch(Rays(self, camera, filter.filter(), ray))
    }

    /// Any camera and filter: [`FilterSampler::sample`] then [`CameraRays::generate_lens`].
    fn rays_general(&mut self, camera: &CameraRays, filter: &FilterSampler, ray: &mut RayPacket) {
        for k in 0..PACKET {
            let (p, w) = filter.sample(self.pixel[k], self.u[k]);
            self.weight[k] = w;
            ray.set(k, &camera.generate_lens(p, self.lens[k]));
        }
    }

    /// [`CameraLanes::rays`] as plain loops over the lanes, compiled for each instruction set.
    #[inline(always)]
    fn rays_portable(&self, camera: &CameraRays, filter: &Filter, ray: &mut RayPacket) {
        // One loop per filter kind with the kind's own inversion inlined: a loop that can call
        // the tabulated arm stays scalar, one call per lane (cornell direct mis: camera rays
        // 229 → 1208 perf samples when that happened).
        match *filter {
            Filter::Box { radius } => self.rays_with(camera, ray, |p, u| box_sample(p, u, radius)),
            Filter::Triangle { radius } => {
                self.rays_with(camera, ray, |p, u| tent_sample(p, u, radius))
            }
            // Not taken: `rays` sends tabulated filters to `rays_general`.
            _ => self.rays_with(camera, ray, |p, u| filter_sample(filter, p, u)),
        }
    }

    /// [`CameraLanes::rays_portable`] with the raster position of each lane from `sample`.
    #[inline(always)]
    fn rays_with(
        &self,
        camera: &CameraRays,
        ray: &mut RayPacket,
        sample: impl Fn(UVec2, Vec2) -> Vec2,
    ) {
        let o = Ray::new(camera.origin(), Vec3::Z);
        for k in 0..PACKET {
            let d = camera.direction(sample(self.pixel[k], self.u[k]));
            ray.set(k, &Ray { d, ..o });
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::Camera;
    use crate::isa::Isa;
    use crate::sampling::PatternKind;

    #[test]
    fn packet_camera_rays_equal_the_scalar_rays() {
        // Every instruction set's 16-lane rays are bit for bit the scalar
        // `generate(filter_sample(..))` of each lane, for both filters and lanes spanning
        // several pixels (as packets do for small sample counts).
        let camera = Camera::look_at(
            Vec3::new(0.3, 1.0, -4.0),
            Vec3::new(0.0, 0.8, 0.0),
            Vec3::Y,
            39.0,
        )
        .expect("valid camera");
        let rays = camera.rays(UVec2::new(97, 61));
        let pattern = crate::sampling::make_pattern(PatternKind::Random, 3);
        let radius = Vec2::new(1.0, 0.75);
        for filter in [Filter::Box { radius }, Filter::Triangle { radius }] {
            for isa in Isa::available() {
                for packet in 0..8u32 {
                    let mut lanes = CameraLanes::new();
                    for k in 0..PACKET {
                        let n = packet * PACKET as u32 + k as u32;
                        lanes.pixel[k] = UVec2::new(n % 97, (n / 3) % 61);
                        lanes.u[k] = pattern.sample_2d(lanes.pixel[k], 0, n, 1 << 20);
                    }
                    let mut out = RayPacket::from_rays(&[Ray::new(Vec3::ZERO, Vec3::Z); PACKET]);
                    let sampler = FilterSampler::new(&filter).expect("box and tent sample");
                    lanes.rays(isa.cpu(), &rays, &sampler, &mut out);
                    for (k, r) in (0..PACKET).map(|k| (k, out.ray(k))) {
                        let want =
                            rays.generate(filter_sample(&filter, lanes.pixel[k], lanes.u[k]));
                        let bits = |r: &Ray| [r.o, r.d].map(|v| v.to_array().map(f32::to_bits));
                        assert_eq!(bits(&r), bits(&want), "{isa:?} {filter:?} lane {k}");
                        assert_eq!(r.t_max, want.t_max);
                    }
                }
            }
        }
    }
}

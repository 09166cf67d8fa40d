//! The render loop: 16×16 tiles in parallel (rayon); every sample is a pure function of
//! (seed, pixel, sample index, dimension), and tiles are assembled in a fixed order, so the
//! image is bit-identical for any thread count and schedule.

use super::RenderOptions;
use super::direct::{DIM_FILTER, DirectLighting};
use super::film::filter_sample;
use crate::Rgb;
use crate::image::Image;
use crate::light_selection::make_selector;
use crate::sampling::make_pattern;
use crate::scene::Scene;
use glam::UVec2;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use rayon::prelude::*;
use std::io::IsTerminal;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

const TILE: u32 = 16;

/// What a render measured.
#[derive(Clone, Debug)]
pub struct RenderStats {
    /// Wall time of the render loop (excluding scene build).
    pub time: Duration,
    /// Rays traced (camera, shadow and BSDF rays).
    pub rays: u64,
    /// Samples whose radiance was NaN/Inf and were dropped.
    pub non_finite: u64,
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
    anyhow::ensure!(
        res.x > 0 && res.y > 0,
        "resolution must be positive, got {}x{}",
        res.x,
        res.y
    );
    anyhow::ensure!(opts.spp > 0, "--spp must be at least 1");
    let selector = make_selector(&opts.light_selection, scene, opts.seed)?;
    let pattern = make_pattern(opts.pattern, opts.seed);
    let est = DirectLighting {
        scene,
        selector: selector.as_ref(),
        pattern: pattern.as_ref(),
        strategy: opts.strategy,
        mis: opts.mis,
        eye_rays: opts.spp,
        shadow_rays: opts.shadow_rays.max(1),
        bsdf_sampling: opts.bsdf_sampling,
        mis_light: opts.mis_light,
    };
    let camera = scene.camera.rays(res);
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
    let bad = AtomicU64::new(0);
    let start = Instant::now();
    let tiles: Vec<Vec<Rgb>> = (0..tiles_x * tiles_y)
        .into_par_iter()
        .map(|t| {
            let (tx, ty) = (t % tiles_x, t / tiles_x);
            let x0 = tx * TILE;
            let y0 = ty * TILE;
            let x1 = (x0 + TILE).min(res.x);
            let y1 = (y0 + TILE).min(res.y);
            let mut out = Vec::with_capacity(((x1 - x0) * (y1 - y0)) as usize);
            let (mut tile_rays, mut tile_bad) = (0u64, 0u64);
            for y in y0..y1 {
                for x in x0..x1 {
                    let pixel = UVec2::new(x, y);
                    let px = pattern.pixel(pixel);
                    let mut sum = Rgb::ZERO;
                    for i in 0..opts.spp {
                        let u = px.sample_2d(DIM_FILTER, i, opts.spp);
                        let p = filter_sample(&scene.film.filter, pixel, u);
                        let ray = camera.generate(p);
                        let (l, r) = est.li(&px, i, &ray);
                        tile_rays += r;
                        if l.is_finite() {
                            sum += l;
                        } else {
                            tile_bad += 1;
                        }
                    }
                    out.push(sum / opts.spp as f32);
                }
            }
            rays.fetch_add(tile_rays, Ordering::Relaxed);
            bad.fetch_add(tile_bad, Ordering::Relaxed);
            bar.inc(1);
            out
        })
        .collect();
    bar.finish_and_clear();
    let time = start.elapsed();
    let mut img = Image::new(res.x, res.y);
    for (t, tile) in tiles.iter().enumerate() {
        let t = t as u32;
        let (x0, y0) = ((t % tiles_x) * TILE, (t / tiles_x) * TILE);
        let w = (x0 + TILE).min(res.x) - x0;
        for (i, px) in tile.iter().enumerate() {
            let (x, y) = (x0 + i as u32 % w, y0 + i as u32 / w);
            img.pixels[(y * res.x + x) as usize] = *px;
        }
    }
    let stats = RenderStats {
        time,
        rays: rays.into_inner(),
        non_finite: bad.into_inner(),
    };
    if stats.non_finite > 0 {
        eprintln!(
            "warning: {} samples had a non-finite radiance and were dropped",
            stats.non_finite
        );
    }
    Ok((img, stats))
}

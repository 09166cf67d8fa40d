//! Adaptive selection: the [`SpatialSelector`] grid, with per-cell tables *learned* from
//! measured contributions.
//!
//! The renderer has no progressive passes, so learning happens in a deterministic pre-pass
//! (like [`super::wald`], but per cell): a low-resolution grid of eye rays; at each hit a few
//! lights are drawn from the spatial selector, their contribution f·Li·cos/pdf is measured with
//! a shadow ray, and each cell keeps the running average of every light's measured
//! contribution. Occluded lights average to zero, which the spatial bound cannot know.
//!
//! Unbiasedness: cells with too little training data use the spatial table alone; trained
//! cells mix p = β·p_spatial + (1 − β)·p_learned with β = max([`AdaptiveConfig::beta`]
//! (default 20%), spatial mass of the lights never measured in the cell) — the learned table
//! only takes over the probability of lights it has measured — and `make_selector` mixes the
//! result with power selection at a probed share of at least 10 % ([`super::defensive`]), so
//! every light with power keeps p > 0.

use super::estimate::{contribution, estimate_resolution, eye_hit, next_2d, pixel_rng};
use super::spatial::{CellTable, SpatialSelector};
use super::{FiniteSelector, LightSet, ONE_MINUS_EPS, ShadingPoint};
use crate::sampling::hash::next_f32;
use crate::scene::Scene;
use rayon::prelude::*;

/// Parameters of the training pass.
#[derive(Clone, Debug)]
pub struct AdaptiveConfig {
    /// Longer side of the training image in pixels.
    pub resolution: u32,
    /// Jittered passes.
    pub passes: u32,
    /// Lights tested per training pixel and pass.
    pub lights_per_pixel: u32,
    /// Measurements a cell needs before its learned table is used.
    pub min_records: usize,
    /// Share β of the spatial table kept in trained cells.
    pub beta: f32,
    /// Seed (the render's seed).
    pub seed: u64,
}

impl AdaptiveConfig {
    /// Defaults: 64-pixel training image, 4 passes, 8 lights per pixel, ≥ 64 measurements,
    /// β = 20%.
    pub fn new(seed: u64) -> Self {
        Self {
            resolution: 64,
            passes: 4,
            lights_per_pixel: 8,
            min_records: 64,
            beta: 0.2,
            seed,
        }
    }
}

/// Spatial grid plus learned per-cell tables.
pub struct AdaptiveSelector {
    spatial: SpatialSelector,
    /// Per cell: learned table and the spatial share β kept there.
    learned: CellMixtures,
    /// Number of cells with a learned table.
    pub trained_cells: usize,
}

/// Per grid cell, an optional learned table and the share β of the spatial table kept beside
/// it: p = β·p_spatial + (1 − β)·p_learned in trained cells, p_spatial elsewhere. The one
/// mixture of [`AdaptiveSelector`] and the online selector's tables
/// ([`super::online::LearnedTables`]), so both sample exactly the pmf they report.
#[derive(Clone, Default)]
pub struct CellMixtures(Vec<Option<(CellTable, f32)>>);

impl CellMixtures {
    /// `cells` untrained cells.
    pub fn new(cells: usize) -> Self {
        Self(vec![None; cells])
    }

    /// Give cell `cell` the learned table `t` beside spatial share `beta`.
    pub fn set(&mut self, cell: usize, t: CellTable, beta: f32) {
        self.0[cell] = Some((t, beta));
    }

    /// The learned table at `ctx`, if its cell was trained, and the spatial share there.
    fn at(&self, spatial: &SpatialSelector, ctx: &ShadingPoint) -> (Option<&CellTable>, f32) {
        let cell = spatial.grid().cell(ctx.p);
        match self.0.get(cell).and_then(|t| t.as_ref()) {
            Some((t, beta)) => (Some(t), *beta),
            None => (None, 1.0),
        }
    }

    /// Draw from the mixture at `ctx`: the spatial table for u < β, else the learned table.
    pub fn sample(
        &self,
        spatial: &SpatialSelector,
        ctx: &ShadingPoint,
        u: f32,
    ) -> Option<(u32, f32)> {
        // Each branch's own pick returns its probability: only the other one is looked up
        // (the same products and sum as `pmf`, so the same bits).
        let (learned, b) = self.at(spatial, ctx);
        match learned {
            Some(t) if u >= b => {
                let (i, pl) = t.pick(((u - b) / (1.0 - b)).min(ONE_MINUS_EPS))?;
                Some((i, b * spatial.pmf(ctx, i) + (1.0 - b) * pl))
            }
            _ => {
                let (i, ps) = spatial.sample(ctx, (u / b).min(ONE_MINUS_EPS))?;
                let pl = learned.map_or(0.0, |t| t.prob(i));
                Some((i, b * ps + (1.0 - b) * pl))
            }
        }
    }

    /// Probability that [`Self::sample`] draws light `i` at `ctx`.
    pub fn pmf(&self, spatial: &SpatialSelector, ctx: &ShadingPoint, i: u32) -> f32 {
        let (learned, b) = self.at(spatial, ctx);
        let l = learned.map_or(0.0, |t| t.prob(i));
        b * spatial.pmf(ctx, i) + (1.0 - b) * l
    }
}

impl AdaptiveSelector {
    /// Build the grid and train it on `scene`.
    pub fn new(scene: &Scene, set: &LightSet, cfg: &AdaptiveConfig) -> Self {
        let spatial = SpatialSelector::new(scene, set);
        let mut learned = CellMixtures::new(spatial.grid().len());
        let mut trained_cells = 0;
        if !set.finite.is_empty() {
            let res = estimate_resolution(scene, cfg.resolution);
            let pixels = res.x * res.y;
            // (cell, light, value), gathered in (pass, pixel, draw) order.
            let mut records: Vec<(u32, u32, f32)> = Vec::new();
            for pass in 0..cfg.passes.max(1) {
                let per_pixel: Vec<Vec<(u32, u32, f32)>> = (0..pixels)
                    .into_par_iter()
                    .map(|px| {
                        let mut rng = pixel_rng(cfg.seed, 0xada9, pass, px);
                        let Some(eh) = eye_hit(scene, res, px, &mut rng) else {
                            return Vec::new();
                        };
                        let cell = spatial.grid().cell(eh.sp.p) as u32;
                        (0..cfg.lights_per_pixel)
                            .filter_map(|_| {
                                let (i, _) = spatial.sample(&eh.sp, next_f32(&mut rng))?;
                                let c = contribution(
                                    scene,
                                    &eh,
                                    set.finite[i as usize],
                                    next_2d(&mut rng),
                                );
                                Some((cell, i, c))
                            })
                            .collect()
                    })
                    .collect();
                records.extend(per_pixel.into_iter().flatten());
            }
            // Stable sort: within a (cell, light) group the sums keep their fixed order.
            records.sort_by_key(|&(c, l, _)| (c, l));
            let mut start = 0;
            while start < records.len() {
                let cell = records[start].0;
                let end = start + records[start..].partition_point(|r| r.0 == cell);
                if end - start >= cfg.min_records {
                    let (ids, weights) = average(&records[start..end]);
                    // Spatial probability mass of the lights measured here (occluded ones
                    // included): what the training has an opinion about.
                    let (c, _) = spatial.grid().sphere(cell as usize);
                    let sp = ShadingPoint {
                        p: c,
                        n: glam::Vec3::ZERO,
                        wo: glam::Vec3::ZERO,
                    };
                    let mut tested: Vec<u32> = records[start..end].iter().map(|r| r.1).collect();
                    tested.dedup();
                    let mass: f32 = tested.iter().map(|&l| spatial.pmf(&sp, l)).sum();
                    let beta = cfg.beta.max(1.0 - mass).clamp(0.0, 1.0);
                    let t = CellTable::new(ids, &weights);
                    if t.is_usable() && beta < 1.0 {
                        learned.set(cell as usize, t, beta);
                        trained_cells += 1;
                    }
                }
                start = end;
            }
        }
        Self {
            spatial,
            learned,
            trained_cells,
        }
    }
}

/// Mean measured value per light of one cell's records (sorted by light); lights that never
/// contributed are left out.
fn average(records: &[(u32, u32, f32)]) -> (Vec<u32>, Vec<f32>) {
    let (mut ids, mut weights) = (Vec::new(), Vec::new());
    let mut k = 0;
    while k < records.len() {
        let light = records[k].1;
        let mut sum = 0.0f64;
        let mut n = 0u32;
        while k < records.len() && records[k].1 == light {
            sum += records[k].2 as f64;
            n += 1;
            k += 1;
        }
        let mean = (sum / n as f64) as f32;
        if mean > 0.0 && mean.is_finite() {
            ids.push(light);
            weights.push(mean);
        }
    }
    (ids, weights)
}

impl FiniteSelector for AdaptiveSelector {
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        self.learned.sample(&self.spatial, ctx, u)
    }

    fn pmf(&self, ctx: &ShadingPoint, i: u32) -> f32 {
        self.learned.pmf(&self.spatial, ctx, i)
    }
}

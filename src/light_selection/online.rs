//! Online selection (`--light-selection online`): the [`SpatialSelector`] grid with per-cell
//! tables learned *while the image renders*, separately for primary vertices (camera-ray
//! hits) and secondary ones (every later path vertex).
//!
//! The render runs in rounds of sample indices (`integrator::rounds`). During a round every
//! light sample the integrator takes records what it would deliver as the only strategy
//! ([`LearnRecord`]): f·Le·G/pdf_ω *without* its MIS weight (the weight falls with the light's
//! own selection probability, so a weighted record would push a light learned low ever
//! lower), zero when the shadow ray is blocked — so occlusion, which no bound knows, is
//! learned. Each tile
//! sums its records per (vertex class, cell, light) ([`OnlineLearner::digest`]); at the round
//! boundary the digests are merged in tile order ([`OnlineLearner::merge`]), which makes the
//! running averages — and every later round's distribution — independent of the thread count
//! and schedule. The next round samples from [`OnlineLearner::snapshot`]: per class and cell
//! p = β·p_spatial + (1 − β)·p_learned (the [`CellMixtures`] of [`super::adaptive`]; a cell
//! with few records keeps more of its spatial table: [`OnlineConfig::shrinkage`]), mixed with
//! power selection at
//! a share δ ≥ [`DEFENSIVE_FLOOR`] chosen by held-out probe rays of that class
//! ([`super::defensive`]), so every light with power keeps p > 0 and a table that does not pay
//! leaves the selector as power selection.
//!
//! Unbiasedness: each round's samples are drawn from, and MIS-weighted with the pmf of, that
//! round's frozen distribution (which depends only on earlier rounds), so each round's image is
//! unbiased and so is their sample-weighted sum.

use super::adaptive::CellMixtures;
use super::defensive::{self, Defensive, ProbeConfig};
use super::power::PowerSelector;
use super::spatial::{CellTable, SpatialSelector};
use super::{
    FiniteSelector, GRID_MARGIN, LightSelector, LightSet, Selector, SelectorKind, ShadingPoint,
};
use crate::scene::Scene;
use glam::Vec3;
use std::collections::BTreeMap;
use std::sync::Arc;

/// What one light sample delivered, as the integrator records it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LearnRecord {
    /// The shading point.
    pub p: Vec3,
    /// Scene index of the selected light.
    pub light: u32,
    /// Luminance of f·Le·G/pdf_ω without MIS weight (not divided by the selection pmf); 0 if
    /// blocked.
    pub value: f32,
    /// A vertex after the first (not a camera-ray hit).
    pub secondary: bool,
}

/// A tile's records summed per (class, cell, light): sorted by key, each (key, Σ value, count).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Digest(Vec<(u64, f64, u32)>);

/// Parameters of the learner.
#[derive(Clone, Debug)]
pub struct OnlineConfig {
    /// Measurements a cell needs before its learned table is used.
    pub min_records: u64,
    /// Share β of the spatial table kept in trained cells.
    pub beta: f32,
    /// Pseudo-count k of the spatial prior in a cell: its n records' table weighs at most
    /// n / (n + k) beside the spatial table ([`OnlineLearner`]'s tables).
    pub shrinkage: f64,
    /// A class whose probes keep power selection (δ = 1) once its tables' spatial share
    /// ([`LearnedTables::prior_share`]) is at most this settles on power selection.
    pub settle_below: f64,
    /// Seed (the render's seed).
    pub seed: u64,
}

impl OnlineConfig {
    /// Defaults: ≥ 16 measurements per cell, β = 20 %, k = 256 (a cell's table takes half
    /// the probability at 256 records, 80 % from 1024 on).
    pub fn new(seed: u64) -> Self {
        Self {
            min_records: 16,
            beta: 0.2,
            shrinkage: 256.0,
            settle_below: 0.5,
            seed,
        }
    }
}

/// Running sums per light of one (class, cell): light → (Σ value, count).
type CellSums = BTreeMap<u32, (f64, u64)>;

/// The learner: the spatial grid and the running sums of every (class, cell).
pub struct OnlineLearner {
    set: LightSet,
    spatial: Arc<SpatialSelector>,
    /// Index `class · cells + cell`; class 0 primary, 1 secondary.
    sums: Vec<CellSums>,
    cfg: OnlineConfig,
    /// Records merged so far, per class.
    pub records: [u64; 2],
    /// Per class: settled on power selection for the rest of the render (see
    /// [`Self::advance`]): no more probes, records or tables.
    frozen: [bool; 2],
}

impl OnlineLearner {
    /// The untrained learner of `scene`.
    pub fn new(scene: &Scene, cfg: OnlineConfig) -> Self {
        let set = LightSet::new(&scene.lights);
        let spatial = Arc::new(SpatialSelector::new(scene, &set));
        let cells = spatial.grid().len();
        Self {
            set,
            spatial,
            sums: vec![CellSums::new(); 2 * cells],
            cfg,
            records: [0; 2],
            frozen: [false; 2],
        }
    }

    /// The vertex classes whose light samples the next round records: bit 0 primary, bit 1
    /// secondary (the classes not yet settled on power selection).
    pub fn learning(&self) -> u8 {
        u8::from(!self.frozen[0]) | u8::from(!self.frozen[1]) << 1
    }

    /// Whether every class the render has (`secondary`: paths past their first vertex) has
    /// settled on power selection: the rest of the render needs no rounds.
    pub fn settled(&self, secondary: bool) -> bool {
        self.frozen[0] && (!secondary || self.frozen[1])
    }

    /// Sum one tile's records per (class, cell, light). Records of lights without bounds
    /// (environment, distant) are dropped: their share is fixed ([`super::INFINITE_SHARE`]).
    pub fn digest(&self, records: &[LearnRecord]) -> Digest {
        let cells = self.spatial.grid().len() as u64;
        let mut keyed: Vec<(u64, f32)> = records
            .iter()
            .filter_map(|r| {
                let local = *self.set.local.get(r.light as usize)?;
                if local == u32::MAX || !r.value.is_finite() {
                    return None;
                }
                let cell = self.spatial.grid().cell(r.p) as u64;
                let slot = u64::from(r.secondary) * cells + cell;
                Some((slot << 32 | u64::from(local), r.value.max(0.0)))
            })
            .collect();
        // Stable: within a key the values keep the tile's (deterministic) record order.
        keyed.sort_by_key(|&(k, _)| k);
        let mut out: Vec<(u64, f64, u32)> = Vec::new();
        for (k, v) in keyed {
            match out.last_mut() {
                Some(last) if last.0 == k => {
                    last.1 += v as f64;
                    last.2 += 1;
                }
                _ => out.push((k, v as f64, 1)),
            }
        }
        Digest(out)
    }

    /// Add the digests of a round, in tile order.
    pub fn merge<'d>(&mut self, digests: impl IntoIterator<Item = &'d Digest>) {
        let cells = self.spatial.grid().len();
        for d in digests {
            for &(k, sum, n) in &d.0 {
                let slot = (k >> 32) as usize;
                let light = k as u32;
                let e = self.sums[slot].entry(light).or_insert((0.0, 0));
                e.0 += sum;
                e.1 += u64::from(n);
                self.records[usize::from(slot >= cells)] += u64::from(n);
            }
        }
    }

    /// The learned tables of class `class` (0 primary, 1 secondary) from the sums so far.
    ///
    /// A cell's table is shrunk toward its prior as a whole: the spatial share there is
    /// β = max([`OnlineConfig::beta`], spatial mass of the lights never measured in the cell,
    /// k/(n + k)) for n records and k = [`OnlineConfig::shrinkage`], so a cell with few records
    /// leans on its spatial table and earns its learned one as its records grow (per-light
    /// shrinkage toward the spatial prior was measured worse: see docs/many-lights.md).
    fn tables(&self, class: usize) -> LearnedTables {
        let cells = self.spatial.grid().len();
        let mut learned = CellMixtures::new(cells);
        let mut trained = 0;
        let k = self.cfg.shrinkage;
        // Σ n·β over the cells with records (β = 1 where the cell keeps its spatial table).
        let (mut records, mut prior) = (0u64, 0.0f64);
        for (cell, sums) in self.sums[class * cells..(class + 1) * cells]
            .iter()
            .enumerate()
        {
            let n: u64 = sums.values().map(|s| s.1).sum();
            records += n;
            if n < self.cfg.min_records {
                prior += n as f64;
                continue;
            }
            let (mut ids, mut weights) = (Vec::new(), Vec::new());
            for (&light, &(sum, count)) in sums {
                let mean = (sum / count.max(1) as f64) as f32;
                if mean > 0.0 && mean.is_finite() {
                    ids.push(light);
                    weights.push(mean);
                }
            }
            // Spatial mass of the lights measured here (occluded ones included): what the
            // measurements have an opinion about; the rest keeps its spatial probability.
            // The spatial pmf is constant over a cell: its centre stands for all of it.
            let (c, _) = self.spatial.grid().sphere(cell);
            let sp = ShadingPoint {
                p: c,
                n: Vec3::ZERO,
                wo: Vec3::ZERO,
            };
            let mass: f32 = sums.keys().map(|&l| self.spatial.pmf(&sp, l)).sum();
            let shrink = (k / (n as f64 + k)) as f32;
            let beta = self.cfg.beta.max(1.0 - mass).max(shrink).clamp(0.0, 1.0);
            let t = CellTable::new(ids, &weights);
            if t.is_usable() && beta < 1.0 {
                learned.set(cell, t, beta);
                trained += 1;
                prior += n as f64 * f64::from(beta);
            } else {
                prior += n as f64;
            }
        }
        LearnedTables {
            spatial: Arc::clone(&self.spatial),
            learned,
            trained_cells: trained,
            prior_share: if records > 0 {
                prior / records as f64
            } else {
                1.0
            },
        }
    }

    /// The distribution the next round samples from: per vertex class the learned tables
    /// mixed with power selection at the share their probes chose. With `secondary` false
    /// (direct lighting: no secondary vertices) the secondary class reuses the primary one.
    pub fn snapshot(&self, scene: &Scene, secondary: bool) -> OnlineSnapshot {
        let power = PowerSelector::new(&self.set.bounds);
        let mix = |class: usize| {
            if self.frozen[class] {
                // Settled on power selection: δ = 1 never consults the tables.
                let tables = LearnedTables::untrained(Arc::clone(&self.spatial));
                return Defensive::with_share(tables, power.clone(), 1.0);
            }
            let tables = self.tables(class);
            let mut cfg = ProbeConfig::new(self.cfg.seed, GRID_MARGIN);
            cfg.primary = class == 0;
            cfg.bounce = class == 1;
            let probes = defensive::probe(scene, &self.set, &power, &tables, &cfg);
            let delta = defensive::choose_share(&probes, cfg.margin, cfg.min_hits);
            Defensive::with_share(tables, power.clone(), delta)
        };
        let primary = mix(0);
        let secondary = secondary.then(|| mix(1));
        OnlineSnapshot { primary, secondary }
    }

    /// [`Self::snapshot`] wrapped as the render's selector.
    pub fn selector(&self, scene: &Scene, secondary: bool) -> Box<dyn LightSelector> {
        self.wrap(self.snapshot(scene, secondary))
    }

    /// A snapshot as the render's selector.
    fn wrap(&self, snap: OnlineSnapshot) -> Box<dyn LightSelector> {
        Box::new(Selector::new(
            SelectorKind::Online,
            self.set.clone(),
            Box::new(snap),
        ))
    }

    /// The next round's selector ([`Self::selector`]), settling each class whose probes kept
    /// power selection (δ = 1) although its tables were already mature
    /// ([`OnlineConfig::settle_below`]): on a scene where the learned distribution does not
    /// pay (many-mesh), more records would only cost time. The decision depends only on the
    /// merged records and the seed, so the image stays the same for any thread count.
    pub fn advance(&mut self, scene: &Scene, secondary: bool) -> Box<dyn LightSelector> {
        let snap = self.snapshot(scene, secondary);
        for class in 0..1 + usize::from(secondary) {
            let mix = snap.class(class == 1);
            if mix.share() >= 1.0 && mix.inner().prior_share <= self.cfg.settle_below {
                self.frozen[class] = true;
            }
        }
        self.wrap(snap)
    }
}

/// One class's learned tables over the spatial grid (the mixture of [`super::AdaptiveSelector`]).
pub struct LearnedTables {
    spatial: Arc<SpatialSelector>,
    learned: CellMixtures,
    /// Cells with a learned table.
    pub trained_cells: usize,
    /// The spatial table's share β where the records fell (record-weighted mean over the
    /// cells, 1 in untrained cells): how much the learned tables could still change the
    /// distribution the probes judged.
    pub prior_share: f64,
}

impl LearnedTables {
    /// No learned table: the spatial grid alone.
    fn untrained(spatial: Arc<SpatialSelector>) -> Self {
        let cells = spatial.grid().len();
        Self {
            spatial,
            learned: CellMixtures::new(cells),
            trained_cells: 0,
            prior_share: 1.0,
        }
    }
}

impl FiniteSelector for LearnedTables {
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        self.learned.sample(&self.spatial, ctx, u)
    }

    fn pmf(&self, ctx: &ShadingPoint, i: u32) -> f32 {
        self.learned.pmf(&self.spatial, ctx, i)
    }
}

/// One round's frozen distribution: a defensive mixture per vertex class.
pub struct OnlineSnapshot {
    primary: Defensive<LearnedTables>,
    /// `None`: secondary vertices use the primary mixture.
    secondary: Option<Defensive<LearnedTables>>,
}

impl OnlineSnapshot {
    /// The mixture of `secondary` vertices (or primary ones).
    pub fn class(&self, secondary: bool) -> &Defensive<LearnedTables> {
        match (&self.secondary, secondary) {
            (Some(s), true) => s,
            _ => &self.primary,
        }
    }

    /// The power shares δ (primary, secondary).
    pub fn shares(&self) -> (f32, f32) {
        (self.class(false).share(), self.class(true).share())
    }

    /// The trained cells (primary, secondary).
    pub fn trained_cells(&self) -> (usize, usize) {
        (
            self.class(false).inner().trained_cells,
            self.class(true).inner().trained_cells,
        )
    }
}

impl FiniteSelector for OnlineSnapshot {
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        self.primary.sample(ctx, u)
    }

    fn pmf(&self, ctx: &ShadingPoint, i: u32) -> f32 {
        self.primary.pmf(ctx, i)
    }

    fn sample_at(&self, ctx: &ShadingPoint, u: f32, secondary: bool) -> Option<(u32, f32)> {
        self.class(secondary).sample(ctx, u)
    }

    fn pmf_at(&self, ctx: &ShadingPoint, i: u32, secondary: bool) -> f32 {
        self.class(secondary).pmf(ctx, i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digests_sum_per_key_in_record_order() {
        let opts = crate::scene::load::LoadOptions::default();
        let scene = crate::scene::load::load("many-open", &opts)
            .expect("built-in")
            .scene;
        let learner = OnlineLearner::new(&scene, OnlineConfig::new(1));
        let r = |light, value, secondary| LearnRecord {
            p: Vec3::ZERO,
            light,
            value,
            secondary,
        };
        let d = learner.digest(&[r(3, 1.0, false), r(3, 2.0, false), r(3, 5.0, true)]);
        assert_eq!(d.0.len(), 2);
        assert_eq!((d.0[0].1, d.0[0].2), (3.0, 2));
        assert_eq!((d.0[1].1, d.0[1].2), (5.0, 1));
    }
}

//! Which light a shadow ray goes to. Every selector returns `(light, pmf)` and can answer the
//! pmf of any light for the same shading context, so MIS can weight BSDF samples that hit an
//! emitter. Rule for all: any light that could contribute keeps a non-zero probability.
//!
//! Strategies, one per file: [`uniform`], [`power`] (alias table over Φ), [`exhaustive`]
//! (importance of every light per shading point, O(N): the yardstick), [`bvh`] (light BVH à la
//! Conty Estevez & Kulla 2018 / pbrt-v4), [`wald`] (Wald et al. 2003: one global distribution
//! estimated from low-resolution eye rays), [`spatial`] (a grid of per-cell tables built from
//! conservative bounds), [`adaptive`] (the spatial grid, trained per cell by eye rays),
//! [`online`] (the grid's tables learned while the image renders, per vertex class), and
//! [`ris`] (resampled importance sampling of K power-sampled candidates; `sample` returns the
//! inverse of RIS's contribution weight, not an exact probability, and beside it the
//! deterministic pmf MIS weights with: [`SelectedLight::mis_pmf`], [`SelectorKind::exact_pmf`])
//! and [`ris_bvh`] (the same over K light-BVH-sampled candidates).
//!
//! Every strategy except `uniform` works on the *finite* lights (those with [`LightBounds`]);
//! [`Selector`] wraps it and gives lights without bounds (environment, sky, distant) a fixed
//! share [`INFINITE_SHARE`] of the probability, split uniformly among them.

pub mod adaptive;
pub mod bvh;
pub mod defensive;
pub mod estimate;
pub mod exhaustive;
pub mod importance;
pub mod kind;
pub mod online;
pub mod power;
pub mod ris;
pub mod ris_bvh;
pub mod spatial;
pub mod uniform;
pub mod wald;

pub use adaptive::AdaptiveSelector;
pub use bvh::BvhSelector;
pub use exhaustive::ExhaustiveSelector;
pub use importance::importance;
pub use kind::SelectorKind;
pub use power::PowerSelector;
pub use ris::RisSelector;
pub use ris_bvh::RisBvhSelector;
pub use spatial::SpatialSelector;
pub use uniform::UniformSelector;
pub use wald::WaldSelector;

use crate::lights::{LightBounds, LightSource};
use glam::Vec3;

/// The shading context a selector may use.
#[derive(Clone, Copy, Debug)]
pub struct ShadingPoint {
    /// Position.
    pub p: Vec3,
    /// Geometric normal, flipped toward the viewer.
    pub n: Vec3,
    /// Direction toward the viewer.
    pub wo: Vec3,
}

/// A selected light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SelectedLight {
    /// Index into `Scene::lights`.
    pub index: u32,
    /// What the light estimate divides by: the probability of having chosen it, or for
    /// `ris` and `ris-bvh` the inverse of RIS's contribution weight (a random number whose
    /// reciprocal is an unbiased estimate of the choice's 1/pmf).
    pub pmf: f32,
    /// The probability the MIS weights use: [`LightSelector::pmf_at`] of this light at this
    /// point, which a BSDF ray that reaches the light computes too, so the two techniques'
    /// weights of every direction sum to 1 exactly. Equal to `pmf` for every exact selector.
    pub mis_pmf: f32,
}

impl SelectedLight {
    /// Light `index` chosen with the exact probability `pmf` (MIS uses the same).
    pub fn exact(index: u32, pmf: f32) -> Self {
        Self {
            index,
            pmf,
            mis_pmf: pmf,
        }
    }
}

/// Chooses a light for a shading point.
pub trait LightSelector: Send + Sync {
    /// Pick a light with the uniform number `u`; `None` if there are no lights (or none can
    /// contribute at `ctx`).
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<SelectedLight>;
    /// Probability that `sample` picks `light` at `ctx`.
    fn pmf(&self, ctx: &ShadingPoint, light: u32) -> f32;
    /// [`Self::sample`] at a vertex of the given class: a camera-ray hit (`secondary` false) or
    /// a later path vertex. Only `online` tells them apart.
    fn sample_at(&self, ctx: &ShadingPoint, u: f32, secondary: bool) -> Option<SelectedLight> {
        let _ = secondary;
        self.sample(ctx, u)
    }
    /// [`Self::pmf`] of [`Self::sample_at`] with the same class.
    fn pmf_at(&self, ctx: &ShadingPoint, light: u32, secondary: bool) -> f32 {
        let _ = secondary;
        self.pmf(ctx, light)
    }
    /// Which strategy this is.
    fn kind(&self) -> SelectorKind;
    /// Name as accepted by `--light-selection`.
    fn name(&self) -> &'static str {
        self.kind().name()
    }
}

/// A strategy over the finite lights `0..n` (indices into [`LightSet::finite`]).
pub trait FiniteSelector: Send + Sync {
    /// Pick a finite light: (local index, pmf).
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)>;
    /// Probability of local index `i`.
    fn pmf(&self, ctx: &ShadingPoint, i: u32) -> f32;
    /// [`Self::sample`] at a primary (`secondary` false) or later path vertex.
    fn sample_at(&self, ctx: &ShadingPoint, u: f32, secondary: bool) -> Option<(u32, f32)> {
        let _ = secondary;
        self.sample(ctx, u)
    }
    /// [`Self::pmf`] of [`Self::sample_at`] with the same class.
    fn pmf_at(&self, ctx: &ShadingPoint, i: u32, secondary: bool) -> f32 {
        let _ = secondary;
        self.pmf(ctx, i)
    }
    /// [`Self::sample_at`] and, third, the pmf for the MIS weights
    /// ([`SelectedLight::mis_pmf`]): [`Self::pmf_at`] of the chosen light, which is the second
    /// number itself for every selector but RIS.
    fn sample_mis_at(
        &self,
        ctx: &ShadingPoint,
        u: f32,
        secondary: bool,
    ) -> Option<(u32, f32, f32)> {
        self.sample_at(ctx, u, secondary).map(|(i, p)| (i, p, p))
    }
}

/// Probability given to the lights without bounds (infinite and distant) when the scene also
/// has finite lights: a fixed share, because no spatial bound says how much they matter.
pub const INFINITE_SHARE: f32 = 0.1;

/// The scene's lights split into finite ones (with bounds) and the rest.
#[derive(Clone, Debug, Default)]
pub struct LightSet {
    /// Scene indices of the lights with bounds.
    pub finite: Vec<u32>,
    /// Their bounds, in the same order.
    pub bounds: Vec<LightBounds>,
    /// Scene indices of the lights without bounds (infinite, distant).
    pub other: Vec<u32>,
    /// Scene index → local index in `finite`, or `u32::MAX` for the others.
    pub local: Vec<u32>,
}

impl LightSet {
    /// Split `lights`.
    pub fn new(lights: &[crate::lights::Light]) -> Self {
        let mut s = LightSet {
            local: vec![u32::MAX; lights.len()],
            ..Default::default()
        };
        for (i, l) in lights.iter().enumerate() {
            match l.bounds() {
                Some(b) if !l.is_infinite() && b.min.is_finite() && b.max.is_finite() => {
                    s.local[i] = s.finite.len() as u32;
                    s.finite.push(i as u32);
                    s.bounds.push(sanitize(b));
                }
                _ => s.other.push(i as u32),
            }
        }
        s
    }

    /// Probability of choosing the group of finite lights at all.
    pub fn finite_share(&self) -> f32 {
        match (self.finite.is_empty(), self.other.is_empty()) {
            (true, _) => 0.0,
            (false, true) => 1.0,
            (false, false) => 1.0 - INFINITE_SHARE,
        }
    }
}

/// Bounds with a finite non-negative power and unit direction, so no NaN reaches a pmf.
fn sanitize(mut b: LightBounds) -> LightBounds {
    if !(b.phi.is_finite() && b.phi >= 0.0) {
        b.phi = 0.0;
    }
    b.w = b.w.try_normalize().unwrap_or(Vec3::Z);
    if !b.cos_theta_o.is_finite() {
        b.cos_theta_o = -1.0;
    }
    if !b.cos_theta_e.is_finite() {
        b.cos_theta_e = 0.0;
    }
    b
}

/// A [`FiniteSelector`] plus the fixed share of the unbounded lights: what `make_selector`
/// returns for every strategy but `uniform`.
pub struct Selector {
    kind: SelectorKind,
    set: LightSet,
    finite: Box<dyn FiniteSelector>,
}

impl Selector {
    /// Wrap `finite`, a `kind` strategy that selects among `set.finite`.
    pub fn new(kind: SelectorKind, set: LightSet, finite: Box<dyn FiniteSelector>) -> Self {
        Self { kind, set, finite }
    }

    /// The inner strategy (for tests and benchmarks).
    pub fn inner(&self) -> &dyn FiniteSelector {
        self.finite.as_ref()
    }
}

impl LightSelector for Selector {
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<SelectedLight> {
        self.sample_at(ctx, u, false)
    }

    fn pmf(&self, ctx: &ShadingPoint, light: u32) -> f32 {
        self.pmf_at(ctx, light, false)
    }

    fn sample_at(&self, ctx: &ShadingPoint, u: f32, secondary: bool) -> Option<SelectedLight> {
        let share = self.set.finite_share();
        if u < share {
            // Reuse u: rescaled to [0, 1) it still is uniform for the finite strategy.
            let v = (u / share).min(ONE_MINUS_EPS);
            let (i, p, mis) = self.finite.sample_mis_at(ctx, v, secondary)?;
            let pmf = p * share;
            (pmf > 0.0).then(|| SelectedLight {
                index: self.set.finite[i as usize],
                pmf,
                mis_pmf: mis * share,
            })
        } else {
            let n = self.set.other.len();
            if n == 0 {
                return None;
            }
            let v = ((u - share) / (1.0 - share)).clamp(0.0, ONE_MINUS_EPS);
            let k = ((v * n as f32) as usize).min(n - 1);
            Some(SelectedLight::exact(
                self.set.other[k],
                (1.0 - share) / n as f32,
            ))
        }
    }

    fn pmf_at(&self, ctx: &ShadingPoint, light: u32, secondary: bool) -> f32 {
        let Some(&local) = self.set.local.get(light as usize) else {
            return 0.0;
        };
        let share = self.set.finite_share();
        if local == u32::MAX {
            (1.0 - share) / self.set.other.len().max(1) as f32
        } else {
            share * self.finite.pmf_at(ctx, local, secondary)
        }
    }

    fn kind(&self) -> SelectorKind {
        self.kind
    }
}

/// Reduction of the second moment the grid strategies (`spatial`, `adaptive`) must show over
/// power selection before their tables are used at all: their time per sample is about 1.4–2×
/// power's (a cell lookup and binary searches per call, and each cell scored against every
/// light when first used), so a smaller gain loses at equal time.
pub const GRID_MARGIN: f64 = 0.35;

/// Largest f32 below 1: keeps rescaled sample numbers in [0, 1).
pub const ONE_MINUS_EPS: f32 = 1.0 - f32::EPSILON / 2.0;

/// The `kind` selector for `scene`. `seed` feeds the estimation passes of `wald` and
/// `adaptive` (the others are deterministic without it).
pub fn make_selector(
    kind: SelectorKind,
    scene: &crate::scene::Scene,
    seed: u64,
) -> Box<dyn LightSelector> {
    // Every strategy but uniform selects among the finite lights, wrapped by `Selector`.
    let wrap = |build: &dyn Fn(&LightSet) -> Box<dyn FiniteSelector>| -> Box<dyn LightSelector> {
        let set = LightSet::new(&scene.lights);
        let finite = build(&set);
        Box::new(Selector::new(kind, set, finite))
    };
    match kind {
        SelectorKind::Uniform => Box::new(UniformSelector {
            count: scene.lights.len() as u32,
        }),
        SelectorKind::Power => wrap(&|set| Box::new(PowerSelector::new(&set.bounds))),
        SelectorKind::Exhaustive => wrap(&|set| Box::new(ExhaustiveSelector::new(&set.bounds))),
        SelectorKind::Bvh => wrap(&|set| Box::new(BvhSelector::new(&set.bounds))),
        SelectorKind::Ris { candidates } => {
            wrap(&|set| Box::new(RisSelector::new(&set.bounds, candidates, seed)))
        }
        SelectorKind::RisBvh { candidates } => {
            wrap(&|set| Box::new(RisBvhSelector::new(&set.bounds, candidates, seed)))
        }
        // The learned and grid strategies, mixed with power at the share their probes chose
        // (`defensive.rs`). The margin is what a δ < 1 must gain: little for `wald` (two
        // alias tables, power's cost), more for the grids ([`GRID_MARGIN`]).
        SelectorKind::Wald => wrap(&|set| {
            let inner = WaldSelector::new(scene, set, &wald::WaldConfig::new(seed));
            let cfg = defensive::ProbeConfig::new(seed, 0.05);
            Box::new(defensive::Defensive::new(scene, set, inner, &cfg))
        }),
        SelectorKind::Spatial => wrap(&|set| {
            let inner = SpatialSelector::new(scene, set);
            let cfg = defensive::ProbeConfig::new(seed, GRID_MARGIN);
            Box::new(defensive::Defensive::new(scene, set, inner, &cfg))
        }),
        // Before any round has rendered: the untrained grid (what the first round samples).
        SelectorKind::Online => {
            let learner = online::OnlineLearner::new(scene, online::OnlineConfig::new(seed));
            learner.selector(scene, true)
        }
        SelectorKind::Adaptive => wrap(&|set| {
            let inner = AdaptiveSelector::new(scene, set, &adaptive::AdaptiveConfig::new(seed));
            let cfg = defensive::ProbeConfig::new(seed, GRID_MARGIN);
            Box::new(defensive::Defensive::new(scene, set, inner, &cfg))
        }),
    }
}

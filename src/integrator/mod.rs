//! The integrator and the render loop.
//!
//! Read `estimator` first: the per-sample maths of the lecture's estimators (light sampling by
//! area or solid angle, BSDF sampling, MIS). `stages` runs them as named stages over the work
//! queues of `queues`, a packet of 16 paths at a time; `lanes` holds the vector kernels of the
//! common case, which lay the same maths over 16 lanes; `dims` says which pattern dimension
//! each decision reads; `render` drives the stages over tiles in parallel; `film` turns pixel
//! samples into raster positions by filter importance sampling.

pub mod dims;
pub mod estimator;
pub mod film;
mod lanes;
#[cfg(test)]
mod mis_tests;
pub mod queues;
pub mod render;
mod rounds;
pub mod stages;

pub use render::{RenderStats, render};
/// The sample ranges of `online` selection's rounds (1, 1, 2, 4, … spp) for a sample range.
pub use rounds::rounds as online_rounds;

use crate::bsdf::LobeSampling;
use crate::light_selection::SelectorKind;
use crate::sampling::{PatternKind, balance_heuristic, power_heuristic};
use std::fmt;
use std::ops::Range;
use std::str::FromStr;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// The estimator selected by `--strategy`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Strategy {
    /// Sample the BSDF (projected solid angle); emitter hits gather Le.
    Bsdf,
    /// Sample the light source area.
    LightArea,
    /// Sample the light's solid angle where supported (area otherwise).
    LightSolidAngle,
    /// One light sample + one BSDF sample combined by multiple importance sampling.
    Mis,
}

impl Strategy {
    /// Every strategy, in CLI order.
    pub const ALL: [Strategy; 4] = [
        Strategy::Bsdf,
        Strategy::LightArea,
        Strategy::LightSolidAngle,
        Strategy::Mis,
    ];

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Bsdf => "bsdf",
            Strategy::LightArea => "light-area",
            Strategy::LightSolidAngle => "light-solid-angle",
            Strategy::Mis => "mis",
        }
    }
}

impl fmt::Display for Strategy {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Strategy {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s.trim())
            .ok_or_else(|| {
                format!("unknown strategy '{s}' (expected one of: bsdf, light-area, light-solid-angle, mis)")
            })
    }
}

/// The light transport the image shows (`--integrator`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IntegratorKind {
    /// Emission plus one bounce of direct light: the path tracer with max depth 1.
    Direct,
    /// Global illumination: the path tracer with [`RenderOptions::max_depth`].
    Path,
}

impl IntegratorKind {
    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Direct => "direct",
            IntegratorKind::Path => "path",
        }
    }
}

impl fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for IntegratorKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim() {
            "direct" => Ok(Self::Direct),
            "path" => Ok(Self::Path),
            _ => Err(format!(
                "unknown integrator '{s}' (expected direct or path)"
            )),
        }
    }
}

/// MIS weighting heuristic.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MisHeuristic {
    /// Power heuristic, β = 2.
    Power,
    /// Balance heuristic.
    Balance,
}

impl MisHeuristic {
    /// Weight of a sample of pdf `f_pdf` combined with one other technique of pdf `g_pdf`
    /// (one sample each).
    #[inline]
    pub fn weight(self, f_pdf: f32, g_pdf: f32) -> f32 {
        match self {
            MisHeuristic::Power => power_heuristic(1.0, f_pdf, 1.0, g_pdf),
            MisHeuristic::Balance => balance_heuristic(1.0, f_pdf, 1.0, g_pdf),
        }
    }
}

impl FromStr for MisHeuristic {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.trim() {
            "power" => Ok(Self::Power),
            "balance" => Ok(Self::Balance),
            _ => Err(format!(
                "unknown MIS heuristic '{s}' (expected power or balance)"
            )),
        }
    }
}

/// Everything that decides how an image is rendered (besides the scene).
#[derive(Clone, Debug)]
pub struct RenderOptions {
    /// Eye rays per pixel (N).
    pub spp: u32,
    /// Light (or BSDF) samples per eye ray (M).
    pub shadow_rays: u32,
    /// Seed of every random number.
    pub seed: u64,
    /// Estimator.
    pub strategy: Strategy,
    /// MIS heuristic.
    pub mis: MisHeuristic,
    /// Sample pattern for every dimension.
    pub pattern: PatternKind,
    /// Light selection strategy (see `light_selection`).
    pub light_selection: SelectorKind,
    /// How `mis` samples lights: by solid angle where supported (default) or by area.
    pub mis_light: crate::lights::SamplingMode,
    /// How BSDF lobes are sampled (the lecture's I₂ variants; importance by default).
    pub bsdf_sampling: LobeSampling,
    /// Direct lighting or path tracing.
    pub integrator: IntegratorKind,
    /// Path tracing's pbrt-v4 `maxdepth`: vertices that sample lights and the BSDF (ignored
    /// by `Direct`, which is 1).
    pub max_depth: u32,
    /// Russian roulette on the path throughput (pbrt-v4's rule; unbiased).
    pub roulette: bool,
    /// Reconstruct pixels by splatting (see `render`): each sample, uniform over its pixel,
    /// adds its radiance weighted by the filter to every pixel the filter reaches, and a
    /// pixel is the weighted mean of what it received (Mitsuba's film). Off: filter
    /// importance sampling, each sample counted by its own pixel only.
    pub splat: bool,
    /// Hide the emitters camera rays see directly (Mitsuba 3's `hide_emitters`): the
    /// emission of the surface or environment a camera ray reaches is not added; the light
    /// emitters cast (next-event estimation, BSDF rays that reach them, later bounces) is
    /// unchanged. Off by default.
    pub hide_emitters: bool,
    /// Show a progress bar.
    pub progress: bool,
    /// Render only sample indices `[start, end)` of the `spp` of every pixel (a part of a
    /// distributed render, see `image::parts`); `None` renders all of `0..spp`. Each index draws
    /// the very numbers it draws in the whole render, so parts add up to it.
    pub sample_range: Option<Range<u32>>,
    /// Set from another thread to stop the render early; it then returns [`Cancelled`].
    pub cancel: Option<Arc<AtomicBool>>,
}

impl RenderOptions {
    /// The max depth the stages run: 1 for direct lighting.
    pub fn depth(&self) -> u32 {
        match self.integrator {
            IntegratorKind::Direct => 1,
            IntegratorKind::Path => self.max_depth,
        }
    }

    /// The sample indices to render: `sample_range`, checked against `spp`, or `0..spp`.
    pub fn samples(&self) -> anyhow::Result<Range<u32>> {
        match &self.sample_range {
            None => Ok(0..self.spp),
            Some(r) if r.start < r.end && r.end <= self.spp => Ok(r.clone()),
            Some(r) => anyhow::bail!(
                "sample range {}..{} must be non-empty and within 0..{} (the spp)",
                r.start,
                r.end,
                self.spp
            ),
        }
    }

    /// Whether the cancellation flag has been set.
    #[inline]
    pub fn is_cancelled(&self) -> bool {
        self.cancel
            .as_ref()
            .is_some_and(|c| c.load(Ordering::Relaxed))
    }
}

/// The render was stopped through [`RenderOptions::cancel`]; no image was produced.
#[derive(Debug, thiserror::Error)]
#[error("render cancelled")]
pub struct Cancelled;

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            spp: 64,
            shadow_rays: 1,
            seed: 0,
            strategy: Strategy::Mis,
            mis: MisHeuristic::Power,
            pattern: PatternKind::Stratified,
            light_selection: SelectorKind::DEFAULT,
            bsdf_sampling: LobeSampling::Importance,
            mis_light: crate::lights::SamplingMode::SolidAngle,
            integrator: IntegratorKind::Direct,
            max_depth: 5,
            roulette: true,
            splat: false,
            hide_emitters: false,
            progress: false,
            sample_range: None,
            cancel: None,
        }
    }
}

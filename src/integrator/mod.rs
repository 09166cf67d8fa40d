//! Direct-lighting estimators and the render loop.
//! TODO(issue 3): render loop + light-area estimator. TODO(issue 4): bsdf, solid-angle, MIS.

use crate::sampling::PatternKind;

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

/// MIS weighting heuristic.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum MisHeuristic {
    /// Power heuristic, β = 2.
    Power,
    /// Balance heuristic.
    Balance,
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
    /// Light selection strategy name (see `light_selection`).
    pub light_selection: String,
    /// Show a progress bar.
    pub progress: bool,
}

//! Which light a shadow ray goes to. Every selector returns `(light, pmf)` and can answer the
//! pmf of any light for the same shading context, so MIS can weight BSDF samples that hit an
//! emitter. Rule for all: any light that could contribute keeps a non-zero probability.
//! TODO(issue 6): power, spatial, adaptive, wald, bvh, exhaustive.

pub mod uniform;

pub use uniform::UniformSelector;

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
    /// Probability of having chosen it.
    pub pmf: f32,
}

/// Chooses a light for a shading point.
pub trait LightSelector: Send + Sync {
    /// Pick a light with the uniform number `u`; `None` if there are no lights.
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<SelectedLight>;
    /// Probability that `sample` picks `light` at `ctx`.
    fn pmf(&self, ctx: &ShadingPoint, light: u32) -> f32;
    /// Name as accepted by `--light-selection`.
    fn name(&self) -> &'static str;
}

/// The selector named `name` (as accepted by `--light-selection`) for `scene`.
pub fn make_selector(
    name: &str,
    scene: &crate::scene::Scene,
) -> anyhow::Result<Box<dyn LightSelector>> {
    match name {
        "uniform" => Ok(Box::new(UniformSelector {
            count: scene.lights.len() as u32,
        })),
        other => anyhow::bail!("unknown light selection '{other}' (expected one of: uniform)"),
    }
}

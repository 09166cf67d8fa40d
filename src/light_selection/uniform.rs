//! Equal probability 1/N for every light.

use super::{LightSelector, SelectedLight, SelectorKind, ShadingPoint};

/// Uniform light selection.
#[derive(Clone, Copy, Debug)]
pub struct UniformSelector {
    /// Number of lights.
    pub count: u32,
}

impl UniformSelector {
    /// The pick of `u` among `count` lights (`None` without lights): the one definition both
    /// [`LightSelector::sample`] and the integrator's inline fast path (taken when the
    /// selector's kind is [`SelectorKind::Uniform`]) use.
    #[inline]
    pub fn pick(count: u32, u: f32) -> Option<SelectedLight> {
        if count == 0 {
            return None;
        }
        let index = ((u * count as f32) as u32).min(count - 1);
        Some(SelectedLight::exact(index, 1.0 / count as f32))
    }
}

impl LightSelector for UniformSelector {
    fn sample(&self, _ctx: &ShadingPoint, u: f32) -> Option<SelectedLight> {
        Self::pick(self.count, u)
    }

    fn pmf(&self, _ctx: &ShadingPoint, light: u32) -> f32 {
        if light < self.count {
            1.0 / self.count as f32
        } else {
            0.0
        }
    }

    fn kind(&self) -> SelectorKind {
        SelectorKind::Uniform
    }
}

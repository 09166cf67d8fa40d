//! Filter importance sampling: a pixel sample becomes a raster position distributed like the
//! reconstruction filter, so every sample has weight 1 and the pixel value is a plain mean.

use crate::sampling::tent;
use crate::scene::Filter;
use glam::{UVec2, Vec2};

/// Raster position of the sample `u ∈ [0,1)²` for `pixel` under `filter`.
#[inline]
pub fn filter_sample(filter: &Filter, pixel: UVec2, u: Vec2) -> Vec2 {
    let center = pixel.as_vec2() + Vec2::splat(0.5);
    let offset = match *filter {
        Filter::Box { radius } => (u * 2.0 - Vec2::ONE) * radius,
        Filter::Triangle { radius } => Vec2::new(tent(u.x, radius.x), tent(u.y, radius.y)),
    };
    center + offset
}

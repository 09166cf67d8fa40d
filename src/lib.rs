//! penumbra: a CPU renderer for BRDF importance sampling and direct lighting.
//!
//! Data flows one way: `scene` builds a [`scene::Scene`] (geometry + BVH, materials, lights,
//! camera); the `integrator` turns camera rays into radiance using `bsdf`, `lights`,
//! `light_selection` and the sample patterns of `sampling`; `image` accumulates and writes it.
//! `sampling` knows nothing of rendering: all sampling math lives there.

// `!(x > 0.0)` is how this crate rejects NaN together with non-positive values, on purpose.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![warn(missing_docs)]

pub mod bsdf;
pub mod camera;
pub mod geometry;
pub mod image;
pub mod integrator;
pub mod isa;
pub mod lab;
pub mod light_selection;
pub mod lights;
pub mod material;
pub mod progressive;
pub mod sampling;
pub mod scene;

/// Linear RGB radiance / reflectance triple.
pub type Rgb = glam::Vec3;

/// Luminance of a linear sRGB/Rec.709 colour (used for power and importance).
#[inline]
pub fn luminance(c: Rgb) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

//! Scalar textures over (u, v): pbrt-v4's float `constant`, `imagemap` and `scale` textures
//! (roughness, bump displacement, the factor of a spectrum `scale` texture).

use super::texture::{ImageRgb, UvMap};
use glam::Vec2;
use std::sync::Arc;

/// A scalar that can vary over the surface.
#[derive(Clone, Debug)]
pub enum FloatTexture {
    /// The same value everywhere.
    Constant(f32),
    /// pbrt-v4's `FloatImageTexture`: `scale` × the image's first channel, bilinearly
    /// filtered (v = 0 at the bottom row); `invert` gives max(0, 1 − that).
    Image {
        /// The image (already decoded with the texture's `encoding`).
        image: Arc<ImageRgb>,
        /// Multiplier, applied before the inversion as pbrt-v4 does.
        scale: f32,
        /// pbrt's `invert`.
        invert: bool,
    },
    /// Product of two float textures (pbrt's float `scale` texture).
    Product(Box<FloatTexture>, Box<FloatTexture>),
    /// A texture looked up through a uv mapping.
    Mapped(UvMap, Box<FloatTexture>),
}

impl FloatTexture {
    /// Value at texture coordinates `uv`.
    #[inline]
    pub fn eval(&self, uv: Vec2) -> f32 {
        match self {
            FloatTexture::Constant(v) => *v,
            FloatTexture::Image {
                image,
                scale,
                invert,
            } => {
                let v = *scale * image.bilinear(uv).x;
                if *invert { (1.0 - v).max(0.0) } else { v }
            }
            FloatTexture::Product(a, b) => a.eval(uv) * b.eval(uv),
            FloatTexture::Mapped(m, t) => t.eval(m.apply(uv)),
        }
    }

    /// The value if it is the same everywhere.
    pub fn constant(&self) -> Option<f32> {
        match self {
            FloatTexture::Constant(v) => Some(*v),
            FloatTexture::Product(a, b) => Some(a.constant()? * b.constant()?),
            FloatTexture::Mapped(_, t) => t.constant(),
            FloatTexture::Image { .. } => None,
        }
    }
}

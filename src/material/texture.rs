//! RGB textures over (u, v).

use super::float_texture::FloatTexture;
use crate::Rgb;
use glam::Vec2;
use std::sync::Arc;

/// A linear-RGB image sampled by (u, v), v = 0 at the bottom row (pbrt convention).
#[derive(Clone, Debug)]
pub struct ImageRgb {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Row-major pixels, top row first.
    pub pixels: Vec<Rgb>,
}

/// pbrt-v4's `UVMapping`: the texture is looked up at (su·u + du, sv·v + dv) (`uscale`,
/// `vscale`, `udelta`, `vdelta`), so one image can tile a floor.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UvMap {
    /// (uscale, vscale).
    pub scale: Vec2,
    /// (udelta, vdelta).
    pub delta: Vec2,
}

impl UvMap {
    /// The identity mapping.
    pub const IDENTITY: UvMap = UvMap {
        scale: Vec2::ONE,
        delta: Vec2::ZERO,
    };

    /// Texture-space coordinates of surface coordinates `uv`.
    #[inline]
    pub fn apply(&self, uv: Vec2) -> Vec2 {
        uv * self.scale + self.delta
    }
}

/// A colour that can vary over the surface.
#[derive(Clone, Debug)]
pub enum Texture {
    /// The same colour everywhere.
    Constant(Rgb),
    /// Bilinearly filtered image lookup times a scale.
    Image {
        /// The image.
        image: Arc<ImageRgb>,
        /// Multiplier.
        scale: Rgb,
    },
    /// Two colours in a checkerboard of `freq` squares per unit of uv.
    Checkerboard {
        /// Colour of even squares.
        a: Rgb,
        /// Colour of odd squares.
        b: Rgb,
        /// Squares per unit uv (u, v).
        freq: Vec2,
    },
    /// The product of two textures (pbrt's spectrum `scale` texture with a varying factor).
    Product(Box<Texture>, Box<Texture>),
    /// A scalar texture as a grey colour.
    Float(FloatTexture),
    /// A texture looked up through a uv mapping.
    Mapped(UvMap, Box<Texture>),
}

impl Texture {
    /// Value at texture coordinates `uv` (inline: a constant is just a load at the hit).
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::Image { image, scale } => image.bilinear(uv) * *scale,
            Texture::Checkerboard { a, b, freq } => {
                let s = (uv * *freq).floor();
                if ((s.x + s.y) as i64).rem_euclid(2) == 0 {
                    *a
                } else {
                    *b
                }
            }
            Texture::Product(a, b) => a.eval(uv) * b.eval(uv),
            Texture::Float(f) => Rgb::splat(f.eval(uv)),
            Texture::Mapped(m, t) => t.eval(m.apply(uv)),
        }
    }
}

impl ImageRgb {
    /// Bilinear lookup with wrap-around addressing.
    pub fn bilinear(&self, uv: Vec2) -> Rgb {
        if self.width == 0 || self.height == 0 {
            return Rgb::ZERO;
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv.x * w as f32 - 0.5;
        let y = (1.0 - uv.y) * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: i64, j: i64| -> Rgb {
            let i = i.rem_euclid(w) as usize;
            let j = j.rem_euclid(h) as usize;
            self.pixels[j * self.width as usize + i]
        };
        let (xi, yi) = (x0 as i64, y0 as i64);
        // Lerps rather than four weights: a region of equal texels returns exactly their
        // value (the weights' products do not sum to exactly 1), so a flat normal map or a
        // constant texture changes nothing.
        let (a, b) = (at(xi, yi), at(xi + 1, yi));
        let (c, d) = (at(xi, yi + 1), at(xi + 1, yi + 1));
        let top = a + (b - a) * fx;
        let bottom = c + (d - c) * fx;
        top + (bottom - top) * fy
    }
}

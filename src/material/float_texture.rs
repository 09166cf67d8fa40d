//! Scalar textures over (u, v): pbrt-v4's float `constant`, `imagemap` and `scale` textures
//! (roughness, bump displacement, the factor of a spectrum `scale` texture).

use super::texture::{ImageRgb, MipMap, TexCoord, UvMap, checkerboard_weight};
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
    /// pbrt-v4's `FloatImageTexture` on a MIP-mapped image (wrap mode, filter).
    Mip {
        /// The pyramid.
        map: Arc<MipMap>,
        /// Multiplier, before the inversion.
        scale: f32,
        /// pbrt's `invert`.
        invert: bool,
    },
    /// pbrt-v4's float `checkerboard` (2D): `a` where ⌊u·fu⌋ + ⌊v·fv⌋ is even, else `b`.
    Checkerboard {
        /// tex1
        a: f32,
        /// tex2
        b: f32,
        /// Squares per unit uv (uscale, vscale).
        freq: Vec2,
    },
}

impl FloatTexture {
    /// Value at texture coordinates `uv` (a point lookup).
    #[inline]
    pub fn eval(&self, uv: Vec2) -> f32 {
        match self {
            FloatTexture::Constant(v) => *v,
            _ => self.eval_at(&TexCoord::point(uv)),
        }
    }

    /// Value over the footprint `tc` (MIP-mapped images and checkerboards filter over it).
    pub fn eval_at(&self, tc: &TexCoord) -> f32 {
        match self {
            FloatTexture::Constant(v) => *v,
            FloatTexture::Image {
                image,
                scale,
                invert,
            } => {
                let v = *scale * image.bilinear(tc.uv).x;
                if *invert { (1.0 - v).max(0.0) } else { v }
            }
            FloatTexture::Mip { map, scale, invert } => {
                let v = *scale * map.lookup(tc).x;
                if *invert { (1.0 - v).max(0.0) } else { v }
            }
            FloatTexture::Product(a, b) => a.eval_at(tc) * b.eval_at(tc),
            FloatTexture::Mapped(m, t) => t.eval_at(&tc.mapped(m)),
            FloatTexture::Checkerboard { a, b, freq } => {
                let w = checkerboard_weight(&tc.scaled(*freq));
                if w == 0.0 {
                    *a
                } else if w == 1.0 {
                    *b
                } else {
                    *a + (*b - *a) * w
                }
            }
        }
    }

    /// True if a lookup depends on the footprint.
    pub fn filters(&self) -> bool {
        match self {
            FloatTexture::Constant(_) | FloatTexture::Image { .. } => false,
            FloatTexture::Mip { .. } | FloatTexture::Checkerboard { .. } => true,
            FloatTexture::Product(a, b) => a.filters() || b.filters(),
            FloatTexture::Mapped(_, t) => t.filters(),
        }
    }

    /// The value if it is the same everywhere.
    pub fn constant(&self) -> Option<f32> {
        match self {
            FloatTexture::Constant(v) => Some(*v),
            FloatTexture::Product(a, b) => Some(a.constant()? * b.constant()?),
            FloatTexture::Mapped(_, t) => t.constant(),
            FloatTexture::Checkerboard { a, b, .. } => (a == b).then_some(*a),
            FloatTexture::Image { .. } | FloatTexture::Mip { .. } => None,
        }
    }
}

/// A float texture as a shape's `"texture alpha"`: the geometry's alpha test evaluates it at
/// each candidate hit's uv (camera, BSDF and shadow rays alike).
impl crate::geometry::AlphaTexture for FloatTexture {
    #[inline]
    fn alpha(&self, uv: Vec2) -> f32 {
        self.eval(uv)
    }
}

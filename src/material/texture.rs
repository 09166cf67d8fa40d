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

/// pbrt-v4's image `wrap` modes: how texel coordinates outside the image are read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Wrap {
    /// Tile the image (pbrt's default).
    #[default]
    Repeat,
    /// Zero outside the image.
    Black,
    /// The nearest edge texel.
    Clamp,
    /// pbrt-v4's octahedral-sphere mirroring (equal-area sphere maps): across an edge the
    /// image continues mirrored about the edge's midpoint.
    OctahedralSphere,
}

impl Wrap {
    /// pbrt-v4's names (`"repeat"`, `"black"`, `"clamp"`, `"octahedralsphere"`).
    pub fn parse(s: &str) -> Option<Wrap> {
        Some(match s {
            "repeat" => Wrap::Repeat,
            "black" => Wrap::Black,
            "clamp" => Wrap::Clamp,
            "octahedralsphere" => Wrap::OctahedralSphere,
            _ => return None,
        })
    }

    /// pbrt-v4's `RemapPixelCoords`: the texel (x, y) of a `w`×`h` image (row 0 at the top)
    /// that integer coordinates (x, y) read, or `None` for black.
    #[inline]
    pub fn remap(self, x: i64, y: i64, w: i64, h: i64) -> Option<(usize, usize)> {
        let (x, y) = match self {
            Wrap::Repeat => (x.rem_euclid(w), y.rem_euclid(h)),
            Wrap::Clamp => (x.clamp(0, w - 1), y.clamp(0, h - 1)),
            Wrap::Black => {
                if x < 0 || x >= w || y < 0 || y >= h {
                    return None;
                }
                (x, y)
            }
            Wrap::OctahedralSphere => {
                let (mut x, mut y) = (x, y);
                if x < 0 {
                    x = -x;
                    y = h - 1 - y;
                } else if x >= w {
                    x = 2 * w - 1 - x;
                    y = h - 1 - y;
                }
                if y < 0 {
                    x = w - 1 - x;
                    y = -y;
                } else if y >= h {
                    x = w - 1 - x;
                    y = 2 * h - 1 - y;
                }
                if w == 1 {
                    x = 0;
                }
                if h == 1 {
                    y = 0;
                }
                // Further than one image away: clamp (pbrt-v4 clamps after mirroring too).
                (x.clamp(0, w - 1), y.clamp(0, h - 1))
            }
        };
        Some((x as usize, y as usize))
    }
}

/// pbrt-v4's image texture `filter` (`"ewa"` is read as trilinear, warned by the loader).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum MipFilter {
    /// The nearest texel of the MIP level below the footprint.
    Point,
    /// Bilinear on the MIP level below the footprint (pbrt-v4's default).
    #[default]
    Bilinear,
    /// Bilinear on the two levels around the footprint, blended.
    Trilinear,
}

/// Texture coordinates with their screen-space derivatives (pbrt-v4's `TexCoord2D`):
/// ∂(u, v)/∂x and ∂(u, v)/∂y over one pixel step (zero: a point lookup).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TexCoord {
    /// (u, v).
    pub uv: Vec2,
    /// ∂(u, v)/∂x.
    pub duvdx: Vec2,
    /// ∂(u, v)/∂y.
    pub duvdy: Vec2,
}

impl TexCoord {
    /// A lookup without footprint (the finest level).
    #[inline]
    pub fn point(uv: Vec2) -> Self {
        TexCoord {
            uv,
            duvdx: Vec2::ZERO,
            duvdy: Vec2::ZERO,
        }
    }

    /// Through a uv mapping (derivatives scale with it).
    #[inline]
    pub fn mapped(&self, m: &UvMap) -> Self {
        TexCoord {
            uv: m.apply(self.uv),
            duvdx: self.duvdx * m.scale,
            duvdy: self.duvdy * m.scale,
        }
    }

    /// Scaled by `f` per axis (a checkerboard's frequency).
    #[inline]
    pub fn scaled(&self, f: Vec2) -> Self {
        TexCoord {
            uv: self.uv * f,
            duvdx: self.duvdx * f,
            duvdy: self.duvdy * f,
        }
    }

    /// pbrt-v4's isotropic filter width: 2 × the largest derivative component.
    #[inline]
    pub fn width(&self) -> f32 {
        2.0 * self
            .duvdx
            .abs()
            .max_element()
            .max(self.duvdy.abs().max_element())
    }
}

/// An image with its MIP pyramid (pbrt-v4's `MIPMap`): level 0 is the image, each next
/// level halves the resolution (rounding up) by averaging 2×2 blocks, down to 1×1.
#[derive(Clone, Debug)]
pub struct MipMap {
    /// Levels, finest first.
    pub levels: Vec<Arc<ImageRgb>>,
    /// Addressing outside [0, 1]².
    pub wrap: Wrap,
    /// How a footprint picks and blends levels.
    pub filter: MipFilter,
}

impl MipMap {
    /// The pyramid of `image`.
    pub fn new(image: Arc<ImageRgb>, wrap: Wrap, filter: MipFilter) -> Self {
        let mut levels = vec![image];
        loop {
            let last = levels.last().expect("level 0");
            if (last.width <= 1 && last.height <= 1) || last.width == 0 || last.height == 0 {
                break;
            }
            let next = last.halved();
            levels.push(Arc::new(next));
        }
        MipMap {
            levels,
            wrap,
            filter,
        }
    }

    /// pbrt-v4's `MIPMap::Filter` for the non-EWA filters: level = levels − 1 + log2(width);
    /// at or beyond the coarsest level its single texel; `Point`/`Bilinear` read level
    /// ⌊level⌋ (≥ 0), `Trilinear` blends ⌊level⌋ and the next (level 0 alone below 1).
    pub fn lookup(&self, tc: &TexCoord) -> Rgb {
        let n = self.levels.len();
        let width = tc.width();
        if width <= 0.0 || n == 1 {
            return self.levels[0].bilinear_wrapped(tc.uv, self.wrap);
        }
        let level = (n - 1) as f32 + width.max(1e-8).log2();
        if level >= (n - 1) as f32 {
            let top = &self.levels[n - 1];
            return top.texel(0, 0, self.wrap);
        }
        let il = level.floor().max(0.0) as usize;
        match self.filter {
            MipFilter::Point => {
                let img = &self.levels[il];
                let x = (tc.uv.x * img.width as f32 - 0.5).round() as i64;
                let y = ((1.0 - tc.uv.y) * img.height as f32 - 0.5).round() as i64;
                img.texel(x, y, self.wrap)
            }
            MipFilter::Bilinear => self.levels[il].bilinear_wrapped(tc.uv, self.wrap),
            MipFilter::Trilinear => {
                let a = self.levels[il].bilinear_wrapped(tc.uv, self.wrap);
                if il == 0 {
                    return a;
                }
                let b = self.levels[il + 1].bilinear_wrapped(tc.uv, self.wrap);
                let t = level - il as f32;
                a + (b - a) * t
            }
        }
    }
}

/// pbrt-v4's 2D checkerboard filtered by a triangle filter of half-width 1.5 × the
/// footprint (its closed-form integral): the weight of the odd squares' value at `tc`
/// (already scaled to squares), 0 or 1 without a footprint.
pub fn checkerboard_weight(tc: &TexCoord) -> f32 {
    // T'' = the ±1 square wave s(x) = (−1)^⌊x⌋: T(x) = ⌊x/2⌋ + P(x mod 2) with P the
    // integral of the triangle wave. In f64: the second difference cancels ~1/r² digits.
    fn t2(x: f64) -> f64 {
        let k = (x * 0.5).floor();
        let y = x - 2.0 * k;
        let p = if y < 1.0 {
            0.5 * y * y
        } else {
            0.5 + 2.0 * (y - 1.0) - 0.5 * (y * y - 1.0)
        };
        k + p
    }
    // The triangle-filtered square wave (1 on even squares, −1 on odd).
    fn bf(x: f32, r: f32) -> f64 {
        let (x, r) = (x as f64, r as f64);
        if (x - r).floor() == (x + r).floor() {
            return 1.0 - 2.0 * ((x.floor() as i64).rem_euclid(2) as f64);
        }
        // Shift by an even number of squares (the wave's period) to keep x small.
        let x = x - 2.0 * (x * 0.5).floor();
        ((t2(x + r) - 2.0 * t2(x) + t2(x - r)) / (r * r)).clamp(-1.0, 1.0)
    }
    let ds = 1.5 * tc.duvdx.x.abs().max(tc.duvdy.x.abs());
    let dt = 1.5 * tc.duvdx.y.abs().max(tc.duvdy.y.abs());
    (0.5 - 0.5 * bf(tc.uv.x, ds) * bf(tc.uv.y, dt)) as f32
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
    /// pbrt-v4's image texture: a MIP-mapped image (wrap mode, filter) times a scale.
    Mip {
        /// The pyramid.
        map: Arc<MipMap>,
        /// Multiplier.
        scale: Rgb,
    },
}

impl Texture {
    /// Value at texture coordinates `uv` (inline: a constant is just a load at the hit).
    #[inline]
    pub fn eval(&self, uv: Vec2) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            _ => self.eval_at(&TexCoord::point(uv)),
        }
    }

    /// Value over the footprint `tc` (MIP-mapped images and checkerboards filter over it;
    /// a zero footprint is a point lookup).
    pub fn eval_at(&self, tc: &TexCoord) -> Rgb {
        match self {
            Texture::Constant(c) => *c,
            Texture::Image { image, scale } => image.bilinear(tc.uv) * *scale,
            Texture::Checkerboard { a, b, freq } => {
                let w = checkerboard_weight(&tc.scaled(*freq));
                if w == 0.0 {
                    *a
                } else if w == 1.0 {
                    *b
                } else {
                    *a + (*b - *a) * w
                }
            }
            Texture::Product(a, b) => a.eval_at(tc) * b.eval_at(tc),
            Texture::Float(f) => Rgb::splat(f.eval_at(tc)),
            Texture::Mapped(m, t) => t.eval_at(&tc.mapped(m)),
            Texture::Mip { map, scale } => map.lookup(tc) * *scale,
        }
    }

    /// True if a lookup depends on the footprint (a MIP-mapped image or a checkerboard).
    pub fn filters(&self) -> bool {
        match self {
            Texture::Constant(_) | Texture::Image { .. } => false,
            Texture::Checkerboard { .. } | Texture::Mip { .. } => true,
            Texture::Product(a, b) => a.filters() || b.filters(),
            Texture::Float(f) => f.filters(),
            Texture::Mapped(_, t) => t.filters(),
        }
    }
}

impl ImageRgb {
    /// Texel (x, y), row 0 at the top, addressed through `wrap`.
    #[inline]
    pub fn texel(&self, x: i64, y: i64, wrap: Wrap) -> Rgb {
        if self.width == 0 || self.height == 0 {
            return Rgb::ZERO;
        }
        match wrap.remap(x, y, self.width as i64, self.height as i64) {
            Some((i, j)) => self.pixels[j * self.width as usize + i],
            None => Rgb::ZERO,
        }
    }

    /// The next MIP level: ⌈w/2⌉ × ⌈h/2⌉, each texel the mean of its 2×2 block (of the
    /// texels that exist on an odd edge; a 1-texel axis averages that texel with itself, as
    /// pbrt-v4's pyramid does).
    pub fn halved(&self) -> ImageRgb {
        let (w, h) = (self.width as usize, self.height as usize);
        let (nw, nh) = (w.div_ceil(2).max(1), h.div_ceil(2).max(1));
        let mut pixels = Vec::with_capacity(nw * nh);
        for y in 0..nh {
            for x in 0..nw {
                let mut sum = Rgb::ZERO;
                let mut n = 0.0f32;
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = (2 * x + dx, 2 * y + dy);
                    // Past an odd edge: skip; a one-texel axis repeats its texel.
                    let sx = if w == 1 { 0 } else { sx };
                    let sy = if h == 1 { 0 } else { sy };
                    if sx < w && sy < h {
                        sum += self.pixels[sy * w + sx];
                        n += 1.0;
                    }
                }
                pixels.push(sum / n);
            }
        }
        ImageRgb {
            width: nw as u32,
            height: nh as u32,
            pixels,
        }
    }

    /// Bilinear lookup with wrap-around addressing.
    #[inline]
    pub fn bilinear(&self, uv: Vec2) -> Rgb {
        self.bilinear_wrapped(uv, Wrap::Repeat)
    }

    /// Bilinear lookup with texels outside the image addressed through `wrap`.
    pub fn bilinear_wrapped(&self, uv: Vec2, wrap: Wrap) -> Rgb {
        if self.width == 0 || self.height == 0 {
            return Rgb::ZERO;
        }
        let (w, h) = (self.width as i64, self.height as i64);
        let x = uv.x * w as f32 - 0.5;
        let y = (1.0 - uv.y) * h as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let at = |i: i64, j: i64| -> Rgb {
            match wrap {
                Wrap::Repeat => {
                    let i = i.rem_euclid(w) as usize;
                    let j = j.rem_euclid(h) as usize;
                    self.pixels[j * self.width as usize + i]
                }
                _ => self.texel(i, j, wrap),
            }
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

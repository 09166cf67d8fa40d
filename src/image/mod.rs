//! Images: the linear-RGB [`Image`], EXR/PFM/PNG I/O with atomic writes, error metrics,
//! false-colour error maps, labelled montages and convergence plots, and the sample-range
//! parts of a distributed render (`parts`).
//!
//! Everything here works on linear radiance; the sRGB transfer is applied only when an 8-bit
//! file or montage is produced, so metrics never see tonemapped values.

pub mod colormap;
pub mod font;
pub mod io;
pub mod metrics;
pub mod montage;
pub mod parts;
pub mod plot;

pub use io::{read_image, save_png_atomic, write_image};
pub use metrics::{ErrorStats, compare, error_image};

use crate::Rgb;

/// A linear-RGB float image, row-major, top row first.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width × height` pixels.
    pub pixels: Vec<Rgb>,
}

impl Image {
    /// A black image.
    pub fn new(width: u32, height: u32) -> Self {
        Self {
            width,
            height,
            pixels: vec![Rgb::ZERO; width as usize * height as usize],
        }
    }

    /// An image whose pixel (x, y) is `f(x, y)`.
    pub fn from_fn(width: u32, height: u32, mut f: impl FnMut(u32, u32) -> Rgb) -> Self {
        let mut pixels = Vec::with_capacity(width as usize * height as usize);
        for y in 0..height {
            for x in 0..width {
                pixels.push(f(x, y));
            }
        }
        Self {
            width,
            height,
            pixels,
        }
    }

    /// Linear index of (x, y); usize arithmetic so large images cannot overflow u32.
    #[inline]
    fn index(&self, x: u32, y: u32) -> usize {
        debug_assert!(
            x < self.width && y < self.height,
            "pixel ({x}, {y}) out of range"
        );
        y as usize * self.width as usize + x as usize
    }

    /// Pixel at (x, y).
    #[inline]
    pub fn get(&self, x: u32, y: u32) -> Rgb {
        self.pixels[self.index(x, y)]
    }

    /// Overwrite the pixel at (x, y).
    #[inline]
    pub fn set(&mut self, x: u32, y: u32, value: Rgb) {
        let i = self.index(x, y);
        self.pixels[i] = value;
    }

    /// Whether `other` has the same width and height.
    pub fn same_size(&self, other: &Image) -> bool {
        self.width == other.width && self.height == other.height
    }

    /// Add `other` pixel-wise (e.g. to accumulate passes).
    ///
    /// # Panics
    /// If the sizes differ: that is a programming error, not bad user input.
    pub fn add_assign(&mut self, other: &Image) {
        assert!(
            self.same_size(other),
            "add_assign: {}x{} vs {}x{}",
            self.width,
            self.height,
            other.width,
            other.height
        );
        for (a, b) in self.pixels.iter_mut().zip(&other.pixels) {
            *a += *b;
        }
    }

    /// Multiply every pixel by `s` (e.g. divide an accumulation by its pass count).
    pub fn scale(&mut self, s: f32) {
        for p in &mut self.pixels {
            *p *= s;
        }
    }

    /// Whether any channel of any pixel is NaN or infinite.
    pub fn has_non_finite(&self) -> bool {
        self.pixels.iter().any(|p| !p.is_finite())
    }

    /// Number of pixels with a NaN or infinite channel.
    pub fn count_non_finite(&self) -> usize {
        self.pixels.iter().filter(|p| !p.is_finite()).count()
    }

    /// Mean over pixels and channels.
    pub fn mean(&self) -> f64 {
        let s: f64 = self.pixels.iter().map(|p| (p.x + p.y + p.z) as f64).sum();
        s / (3.0 * self.pixels.len().max(1) as f64)
    }
}

//! The film's response: how scene radiance (linear sRGB) becomes pixel values. pbrt-v4's
//! `PixelSensor` scales by the imaging ratio (exposure time × ISO / 100) and may white-balance;
//! both are one 3×3 matrix on linear RGB, applied once to the finished image.

use crate::image::Image;
use glam::Mat3;

/// Linear map from rendered radiance to output RGB (identity by default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorResponse {
    /// Output = matrix × radiance.
    pub matrix: Mat3,
}

impl Default for SensorResponse {
    fn default() -> Self {
        Self {
            matrix: Mat3::IDENTITY,
        }
    }
}

impl SensorResponse {
    /// True if it leaves images unchanged.
    pub fn is_identity(&self) -> bool {
        self.matrix == Mat3::IDENTITY
    }

    /// Apply to every pixel (a no-op for the identity, so default renders stay bit-identical).
    pub fn apply(&self, img: &mut Image) {
        if self.is_identity() {
            return;
        }
        for p in &mut img.pixels {
            *p = self.matrix * *p;
        }
    }
}

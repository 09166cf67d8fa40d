//! Rays and the offsets that keep secondary rays off the surface they leave.

use glam::Vec3;

/// A ray `o + t·d`, valid for t in (0, t_max). `d` need not be normalised for shadow rays
/// (then t_max = 1 − ε reaches just short of the target point).
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    /// Origin.
    pub o: Vec3,
    /// Direction.
    pub d: Vec3,
    /// Upper bound of the valid parameter range.
    pub t_max: f32,
}

impl Ray {
    /// A ray with unbounded extent.
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Self {
            o,
            d,
            t_max: f32::INFINITY,
        }
    }

    /// Point at parameter t.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }
}

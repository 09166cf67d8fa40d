//! Rays and the offsets that keep secondary rays off the surface they leave.

use crate::sampling::{PatternKind, make_pattern, uniform_sphere};
use glam::{UVec2, Vec3};

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

/// `n` unbounded rays with origins uniform in the box `bounds` and uniform directions (the
/// seeded random pattern): the query workload of `penumbra bench`'s BVH rows and of
/// `examples/trace_rays`, so both measure the same rays.
pub fn random_query_rays(bounds: (Vec3, Vec3), n: u32) -> Vec<Ray> {
    let (lo, hi) = bounds;
    let pat = make_pattern(PatternKind::Random, 1);
    (0..n)
        .map(|i| {
            let px = UVec2::new(i, 0);
            let (a, b) = (pat.sample_2d(px, 0, 0, 1), pat.sample_2d(px, 1, 0, 1));
            let o = lo + (hi - lo) * Vec3::new(a.x, a.y, pat.sample_1d(px, 2, 0, 1));
            Ray::new(o, uniform_sphere(b))
        })
        .collect()
}

//! Rays and the offsets that keep secondary rays off the surface they leave.

use super::RayQuery;
use crate::sampling::{Frame, PatternKind, cosine_hemisphere, make_pattern, uniform_sphere};
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

/// Secondary rays like a path tracer's diffuse bounces, the incoherent workload of
/// `penumbra bench`'s bounce rows and of `examples/embree_compare`: for each ray of `primary`
/// (camera rays) that hits `g`, one unbounded ray from the hit (its spawn origin) in a
/// cosine-distributed direction about the normal facing the arriving ray (seeded random
/// pattern, ray i's numbers from index i).
pub fn bounce_query_rays(g: &impl RayQuery, primary: &[Ray]) -> Vec<Ray> {
    let pat = make_pattern(PatternKind::Random, 2);
    primary
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            let h = g.intersect(r)?;
            let n = if r.d.dot(h.ng) < 0.0 { h.ng } else { -h.ng };
            let u = pat.sample_2d(UVec2::new(i as u32, 0), 0, 0, 1);
            let d = Frame::from_normal(n).to_world(cosine_hemisphere(u));
            Some(Ray::new(h.spawn_origin(d), d))
        })
        .collect()
}

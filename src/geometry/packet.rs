//! Packet ray queries: [`PACKET`] rays traced together, each with exactly the result of its
//! own scalar query.

use super::{Geometry, Ray, RayQuery, SurfaceHit};

/// Rays per packet query.
pub const PACKET: usize = 16;

impl Geometry {
    /// Closest hit of each active ray (bit i of `active` ⇒ `rays[i]` is traced); `out[i]` is
    /// `None` for inactive lanes and misses. Lane by lane equal to [`RayQuery::intersect`].
    pub fn intersect_packet(
        &self,
        rays: &[Ray; PACKET],
        active: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
    ) {
        for (i, (ray, o)) in rays.iter().zip(out.iter_mut()).enumerate() {
            *o = if active >> i & 1 != 0 {
                self.intersect(ray)
            } else {
                None
            };
        }
    }

    /// Bit i set ⇔ ray i is active and [`RayQuery::occluded`] holds for it.
    pub fn occluded_packet(&self, rays: &[Ray; PACKET], active: u32) -> u32 {
        let mut mask = 0;
        for (i, ray) in rays.iter().enumerate() {
            if active >> i & 1 != 0 && self.occluded(ray) {
                mask |= 1 << i;
            }
        }
        mask
    }
}

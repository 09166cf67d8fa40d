//! Packet ray queries: [`PACKET`] rays traced together (coherent camera rays of one pixel,
//! shadow rays from nearby points toward one light). Each lane's result equals the scalar
//! query's ([`RayQuery::intersect`] / [`RayQuery::occluded`]) bit for bit.

use super::{Geometry, Ray, RayQuery, SurfaceHit};

/// Rays per packet query.
pub const PACKET: usize = 16;

impl Geometry {
    /// Closest hit of each active ray (bit i of `active` ⇒ rays[i] is traced); out[i] = None for
    /// inactive lanes and misses. Equal, lane by lane, to `self.intersect(&rays[i])`.
    pub fn intersect_packet(
        &self,
        rays: &[Ray; PACKET],
        active: u32,
        out: &mut [Option<SurfaceHit>; PACKET],
    ) {
        for (i, (ray, o)) in rays.iter().zip(out.iter_mut()).enumerate() {
            *o = if active & (1 << i) != 0 {
                self.intersect(ray)
            } else {
                None
            };
        }
    }

    /// Bit i set ⇔ ray i is active and `self.occluded(&rays[i])`.
    pub fn occluded_packet(&self, rays: &[Ray; PACKET], active: u32) -> u32 {
        let mut hit = 0;
        for (i, ray) in rays.iter().enumerate() {
            if active & (1 << i) != 0 && self.occluded(ray) {
                hit |= 1 << i;
            }
        }
        hit
    }
}

//! Shapes, transforms, rays and the ray-query acceleration structures (own BVH2 and its 4-wide
//! collapse, obvhs CWBVH).

mod accel;
pub mod alpha;
mod bvh;
pub mod curve;
mod float;
pub mod interaction;
pub(crate) mod packet;
mod primitive;
pub mod quadric;
pub mod ray;
mod simd16;
pub mod transform;
mod tree2;
mod tri4;
pub mod triangle;
mod wide;

pub use accel::{Backend, Geometry};
pub use alpha::{Alpha, AlphaTexture};
pub use interaction::{ShadingGeometry, SurfaceHit};
pub use packet::{HitColumns, PACKET, PacketRayForm, RayPacket};
pub use primitive::{MeshShading, PrimKind, Primitive};
pub use quadric::{Quadric, QuadricKind};
pub use ray::{Ray, bounce_query_rays, random_query_rays};
pub use transform::Transform;

/// Closest-hit and any-hit ray queries: what integrators and lights need from geometry.
pub trait RayQuery: Send + Sync {
    /// Closest intersection with t in (0, ray.t_max), or `None`.
    fn intersect(&self, ray: &Ray) -> Option<SurfaceHit>;
    /// True if anything blocks the ray for t in (0, ray.t_max) (shadow rays).
    fn occluded(&self, ray: &Ray) -> bool;
}

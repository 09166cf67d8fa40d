//! Shapes, transforms, rays and the ray-query acceleration structure (BVH).
//! TODO(issue 3): shapes (mesh, sphere, disk), obvhs-backed BVH, robust ray offsets.

pub mod interaction;
pub mod ray;
pub mod transform;

pub use interaction::SurfaceHit;
pub use ray::Ray;
pub use transform::Transform;

/// Closest-hit and any-hit ray queries: what integrators and lights need from geometry.
pub trait RayQuery: Send + Sync {
    /// Closest intersection with t in (0, ray.t_max), or `None`.
    fn intersect(&self, ray: &Ray) -> Option<SurfaceHit>;
    /// True if anything blocks the ray for t in (0, ray.t_max) (shadow rays).
    fn occluded(&self, ray: &Ray) -> bool;
}

/// All scene geometry behind one BVH. TODO(issue 3): triangles, spheres, disks; obvhs CWBVH.
pub struct Geometry {}

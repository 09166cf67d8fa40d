//! Uniform sampling of the solid angle subtended by a rectangle (Ureña, Fajardo, King 2013).
//! TODO(issue 2): implement; signatures are the contract used by `lights`.

use glam::{Vec2, Vec3};

/// A rectangle `corner + s·ex + t·ey` (s, t ∈ [0,1]) seen from a point, ready to sample.
#[derive(Clone, Copy, Debug)]
pub struct SphericalRectangle {
    /// Solid angle (sr).
    pub solid_angle: f32,
    // implementation-defined precomputed fields follow
}

impl SphericalRectangle {
    /// Precompute for viewpoint `p`; `None` if degenerate or `p` lies in the rectangle's plane.
    pub fn new(p: Vec3, corner: Vec3, ex: Vec3, ey: Vec3) -> Option<Self> {
        let _ = (p, corner, ex, ey);
        todo!("issue 2")
    }

    /// A point on the rectangle whose direction from the viewpoint is uniform in solid angle;
    /// pdf (solid angle) = 1/solid_angle.
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let _ = u;
        todo!("issue 2")
    }
}

//! Uniform sampling of the solid angle subtended by a triangle (Arvo 1995).
//! TODO(issue 2): implement; signatures are the contract used by `lights`.

use glam::{Vec2, Vec3};

/// A triangle (a, b, c) seen from point `p`, precomputed for solid-angle sampling.
#[derive(Clone, Copy, Debug)]
pub struct SphericalTriangle {
    /// Unit vectors from the viewpoint to the three vertices.
    pub a: Vec3,
    /// Second vertex direction.
    pub b: Vec3,
    /// Third vertex direction.
    pub c: Vec3,
    /// Solid angle (sr).
    pub area: f32,
}

impl SphericalTriangle {
    /// Project triangle (v0, v1, v2) onto the unit sphere around `p`; `None` if degenerate.
    pub fn new(p: Vec3, v0: Vec3, v1: Vec3, v2: Vec3) -> Option<Self> {
        let _ = (p, v0, v1, v2);
        todo!("issue 2")
    }

    /// Unit direction uniformly distributed in the spherical triangle; pdf = 1/area.
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let _ = u;
        todo!("issue 2")
    }

    /// Inverse of [`Self::sample`] for a direction inside the triangle.
    pub fn inverse(&self, d: Vec3) -> Vec2 {
        let _ = d;
        todo!("issue 2")
    }
}

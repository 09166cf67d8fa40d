//! Uniform sampling of the solid angle subtended by a rectangle (Ureña, Fajardo, King 2013).
//!
//! In a frame aligned with the rectangle, the solid angle up to a line x = const has a closed
//! form (a spherical quad minus a triangle), so ξ₁ is inverted analytically for x; along that
//! line, the conditional density in y is uniform in h = y/√(x² + y² + z²), which is inverted for
//! y. The math runs in f64: the solid angle is an angle excess that cancels in f32.

use super::warps::DIRECTION_SLACK;
use glam::{DVec3, Vec2, Vec3};
use std::f64::consts::TAU;

/// A rectangle `corner + s·ex + t·ey` (s, t ∈ [0,1]) seen from a point, ready to sample.
#[derive(Clone, Copy, Debug)]
pub struct SphericalRectangle {
    /// Solid angle (sr).
    pub solid_angle: f32,
    /// Viewpoint.
    o: DVec3,
    /// Unit edge directions and the normal facing away from the viewpoint.
    x: DVec3,
    y: DVec3,
    z: DVec3,
    /// Rectangle extent in the local frame centred at the viewpoint (z0 < 0).
    x0: f64,
    x1: f64,
    y0: f64,
    y1: f64,
    z0: f64,
    /// z components of the normals of the edges at y0 and y1.
    b0: f64,
    b1: f64,
    /// 2π minus the two interior angles at the x0 edge: the offset of the x marginal.
    k: f64,
    /// Solid angle in f64.
    s: f64,
}

impl SphericalRectangle {
    /// Largest |cos| between the edges that still counts as a rectangle.
    pub const MAX_EDGE_COS: f64 = 1e-4;

    /// Precompute for viewpoint `p`; `None` if degenerate or `p` lies in the rectangle's plane.
    /// The edges `ex`, `ey` must be perpendicular (|cos| ≤ [`Self::MAX_EDGE_COS`]): the method
    /// does not handle general parallelograms.
    pub fn new(p: Vec3, corner: Vec3, ex: Vec3, ey: Vec3) -> Option<Self> {
        let (o, ex, ey) = (p.as_dvec3(), ex.as_dvec3(), ey.as_dvec3());
        let (exl, eyl) = (ex.length(), ey.length());
        let x = ex.try_normalize()?;
        let y = ey.try_normalize()?;
        if x.dot(y).abs() > Self::MAX_EDGE_COS {
            return None;
        }
        let mut z = x.cross(y);
        let d = corner.as_dvec3() - o;
        let mut z0 = d.dot(z);
        if z0 > 0.0 {
            z = -z;
            z0 = -z0;
        }
        // In-plane viewpoints see no solid angle; relative threshold keeps f64 sane.
        // (NaN input fails this test too, hence the positive form.)
        let far_enough = z0 < -1e-9 * (exl + eyl);
        if !far_enough {
            return None;
        }
        let (x0, y0) = (d.dot(x), d.dot(y));
        let (x1, y1) = (x0 + exl, y0 + eyl);
        // Normals of the planes through the viewpoint and each edge, pointing inwards.
        let n0 = DVec3::new(0.0, z0, -y0).normalize();
        let n1 = DVec3::new(-z0, 0.0, x1).normalize();
        let n2 = DVec3::new(0.0, -z0, y1).normalize();
        let n3 = DVec3::new(z0, 0.0, -x0).normalize();
        let angle = |a: DVec3, b: DVec3| {
            let a = -a;
            a.cross(b).length().atan2(a.dot(b))
        };
        let g0 = angle(n0, n1);
        let g1 = angle(n1, n2);
        let g2 = angle(n2, n3);
        let g3 = angle(n3, n0);
        let s = g0 + g1 + g2 + g3 - TAU;
        if !(s > 0.0 && s.is_finite()) {
            return None;
        }
        Some(Self {
            solid_angle: s as f32,
            o,
            x,
            y,
            z,
            x0,
            x1,
            y0,
            y1,
            z0,
            b0: n0.z,
            b1: n2.z,
            k: TAU - g2 - g3,
            s,
        })
    }

    /// A point on the rectangle whose direction from the viewpoint is uniform in solid angle;
    /// pdf (solid angle) = 1/solid_angle.
    pub fn sample(&self, u: Vec2) -> Vec3 {
        let (u1, u2) = (u.x as f64, u.y as f64);
        let z0 = self.z0;
        // x: invert the marginal solid angle Ω(x) = ξ₁·S.
        let au = u1 * self.s + self.k;
        let (sin_au, cos_au) = au.sin_cos();
        let fu = (cos_au * self.b0 - self.b1) / sin_au;
        let cu = (1.0f64.copysign(fu) / (fu * fu + self.b0 * self.b0).sqrt()).clamp(-1.0, 1.0);
        let xu = -(cu * z0) / (1.0 - cu * cu).max(0.0).sqrt();
        let xu = if xu.is_nan() {
            self.x0
        } else {
            xu.clamp(self.x0, self.x1)
        };
        // y: uniform in h = y / distance along the line x = xu.
        let dd = (xu * xu + z0 * z0).sqrt();
        let h0 = self.y0 / (dd * dd + self.y0 * self.y0).sqrt();
        let h1 = self.y1 / (dd * dd + self.y1 * self.y1).sqrt();
        let hv = h0 + u2 * (h1 - h0);
        let hv2 = hv * hv;
        let yv = if hv2 < 1.0 - 1e-12 {
            (hv * dd / (1.0 - hv2).sqrt()).clamp(self.y0, self.y1)
        } else {
            self.y1
        };
        (self.o + self.x * xu + self.y * yv + self.z * z0).as_vec3()
    }

    /// Whether the ray from the viewpoint along `d` (any length) hits the rectangle, or passes
    /// within [`DIRECTION_SLACK`] radians of it: samples drawn on an edge (ξ on the boundary of
    /// the unit square) are rounded to f32 and may land a hair outside.
    pub fn contains(&self, d: Vec3) -> bool {
        let d = d.as_dvec3();
        let dz = d.dot(self.z);
        if dz >= 0.0 {
            return false;
        }
        let t = self.z0 / dz;
        let (hx, hy) = (t * d.dot(self.x), t * d.dot(self.y));
        // An angle δ moves the hit point by at most δ·distance / cos, and the distance
        // t·|d| ≥ |z0| bounds that from below: slack in the plane of the rectangle.
        let e = DIRECTION_SLACK as f64 * t * d.length() * d.length() / -dz;
        (self.x0 - e..=self.x1 + e).contains(&hx) && (self.y0 - e..=self.y1 + e).contains(&hy)
    }

    /// Solid-angle pdf of [`Self::sample`] in direction `d`: 1/solid_angle on the rectangle.
    pub fn pdf(&self, d: Vec3) -> f32 {
        if self.contains(d) {
            (1.0 / self.s) as f32
        } else {
            0.0
        }
    }

    /// Viewpoint the rectangle was set up for.
    pub fn origin(&self) -> Vec3 {
        self.o.as_vec3()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spherical_rectangle_matches_known_solid_angle() {
        // A unit square seen from distance 1/2 above its centre covers 1/6 of the sphere
        // (it is one face of a cube around the viewpoint): 4π/6.
        let r = SphericalRectangle::new(Vec3::new(0.5, 0.5, 0.5), Vec3::ZERO, Vec3::X, Vec3::Y)
            .unwrap();
        assert!((r.solid_angle - 4.0 * std::f32::consts::PI / 6.0).abs() < 1e-5);
        for &(u, want) in &[
            (Vec2::new(0.0, 0.0), Vec3::new(0.0, 0.0, 0.0)),
            (Vec2::new(1.0, 1.0), Vec3::new(1.0, 1.0, 0.0)),
            (Vec2::new(0.5, 0.5), Vec3::new(0.5, 0.5, 0.0)),
        ] {
            let got = r.sample(u);
            assert!((got - want).length() < 1e-4, "{u} -> {got}, want {want}");
        }
    }

    #[test]
    fn spherical_rectangle_degenerate_is_none() {
        let c = Vec3::ZERO;
        // Viewpoint in the plane, zero edge, non-perpendicular edges, NaN.
        assert!(SphericalRectangle::new(Vec3::new(3.0, 0.0, 0.0), c, Vec3::X, Vec3::Y).is_none());
        assert!(SphericalRectangle::new(Vec3::Z, c, Vec3::ZERO, Vec3::Y).is_none());
        assert!(SphericalRectangle::new(Vec3::Z, c, Vec3::X, Vec3::ONE).is_none());
        assert!(SphericalRectangle::new(Vec3::NAN, c, Vec3::X, Vec3::Y).is_none());
    }
}

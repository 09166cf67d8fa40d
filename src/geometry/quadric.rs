//! Spheres and disks under an arbitrary affine transform: intersected in object space.

use super::Transform;
use super::float::gamma;
use glam::{DVec3, Vec2, Vec3};
use std::f32::consts::PI;

/// Which quadric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum QuadricKind {
    /// Sphere of `radius` centred at the object-space origin.
    Sphere {
        /// Radius.
        radius: f32,
    },
    /// Disk of `radius` in the object-space plane z = `height`, normal +z.
    Disk {
        /// Plane height.
        height: f32,
        /// Radius.
        radius: f32,
    },
}

/// A transformed sphere or disk.
#[derive(Clone, Copy, Debug)]
pub struct Quadric {
    /// Shape in object space.
    pub kind: QuadricKind,
    /// Object-to-world transform.
    pub to_world: Transform,
    /// Flip the outward normal (ReverseOrientation xor handedness swap).
    pub flip: bool,
}

/// Geometry of a quadric hit, before material/light ids are attached.
#[derive(Clone, Copy, Debug)]
pub struct QuadricHit {
    /// World-space point.
    pub p: Vec3,
    /// Unit world-space normal (orientation applied).
    pub n: Vec3,
    /// (u, v) parameterisation.
    pub uv: Vec2,
    /// Offset distance along the normal that clears the rounding error of `p`.
    pub p_error: f32,
}

impl Quadric {
    /// World-space bounding box.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let (lo, hi) = match self.kind {
            QuadricKind::Sphere { radius } => (Vec3::splat(-radius), Vec3::splat(radius)),
            QuadricKind::Disk { height, radius } => (
                Vec3::new(-radius, -radius, height),
                Vec3::new(radius, radius, height),
            ),
        };
        let mut min = Vec3::splat(f32::INFINITY);
        let mut max = Vec3::splat(f32::NEG_INFINITY);
        for i in 0..8 {
            let c = Vec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            );
            let w = self.to_world.point(c);
            min = min.min(w);
            max = max.max(w);
        }
        // Pad so that flat boxes (disks) have non-zero extent and rounding never clips.
        let pad = (max - min).max_element() * 1e-6 + 1e-7;
        (min - pad, max + pad)
    }

    /// Nearest hit parameter t in (0, t_max), or None. Object-space solve in f64 keeps grazing
    /// and distant rays accurate without pbrt's interval arithmetic.
    #[inline]
    pub fn intersect_t(&self, o: Vec3, d: Vec3, t_max: f32) -> Option<f32> {
        let m = &self.to_world.m_inv;
        let oo = m.transform_point3(o).as_dvec3();
        let dd = m.transform_vector3(d).as_dvec3();
        let t = match self.kind {
            QuadricKind::Sphere { radius } => sphere_t(oo, dd, radius as f64, t_max as f64)?,
            QuadricKind::Disk { height, radius } => {
                if dd.z == 0.0 {
                    return None;
                }
                let t = (height as f64 - oo.z) / dd.z;
                if t <= 0.0 || t >= t_max as f64 {
                    return None;
                }
                let p = oo + dd * t;
                if p.x * p.x + p.y * p.y > (radius as f64) * (radius as f64) {
                    return None;
                }
                t
            }
        };
        let t = t as f32;
        if t > 0.0 && t < t_max { Some(t) } else { None }
    }

    /// Surface data at the hit `t` of ray (o, d).
    pub fn hit(&self, o: Vec3, d: Vec3, t: f32) -> QuadricHit {
        let m = &self.to_world.m_inv;
        let oo = m.transform_point3(o).as_dvec3();
        let dd = m.transform_vector3(d).as_dvec3();
        let mut p = oo + dd * t as f64;
        let (n_obj, uv) = match self.kind {
            QuadricKind::Sphere { radius } => {
                // Re-project onto the surface: the point error is then a few ulps of the radius.
                let len = p.length();
                if len > 0.0 {
                    p *= radius as f64 / len;
                }
                let pf = p.as_vec3();
                let phi = pf.y.atan2(pf.x).rem_euclid(2.0 * PI);
                let cos_theta = (pf.z / radius).clamp(-1.0, 1.0);
                (pf, Vec2::new(phi / (2.0 * PI), cos_theta.acos() / PI))
            }
            QuadricKind::Disk { height, radius } => {
                p.z = height as f64;
                let pf = p.as_vec3();
                let r = (pf.x * pf.x + pf.y * pf.y).sqrt();
                let phi = pf.y.atan2(pf.x).rem_euclid(2.0 * PI);
                (
                    Vec3::Z,
                    Vec2::new(phi / (2.0 * PI), 1.0 - r / radius.max(f32::MIN_POSITIVE)),
                )
            }
        };
        let pw = self.to_world.point(p.as_vec3());
        let mut n = self.to_world.normal(n_obj).normalize_or_zero();
        if self.flip {
            n = -n;
        }
        // Object-space error (γ5 of the coordinates) carried through the affine map, plus the
        // map's own rounding (γ3 of the result): pbrt-v4's bound, made isotropic; and γ1 more
        // of the result for the rounding of a spawned ray's origin p + n·d (half an ulp per
        // coordinate), as the triangles' `POINT_ERROR_GAMMA` has. The intersection maps that
        // origin back to object space in f32 and (with the f32 inverse's own error) moves it
        // by less than half this bound (tests/geometry.rs measures it far from the origin).
        let scale = self.to_world.m.x_axis.abs().max_element()
            + self.to_world.m.y_axis.abs().max_element()
            + self.to_world.m.z_axis.abs().max_element();
        let obj_err = gamma(5) * p.as_vec3().abs().max_element() * scale;
        let err = obj_err
            + gamma(4)
                * (pw.abs().max_element() + self.to_world.m.w_axis.truncate().abs().max_element());
        QuadricHit {
            p: pw,
            n,
            uv,
            p_error: err * 3.0f32.sqrt(),
        }
    }
}

/// Smallest root of |o + t d|² = r² in (0, t_max).
#[inline]
fn sphere_t(o: DVec3, d: DVec3, r: f64, t_max: f64) -> Option<f64> {
    let a = d.length_squared();
    if a == 0.0 {
        return None;
    }
    let b = o.dot(d);
    // Discriminant in the numerically stable form |o - (o·d̂)d̂|² (Hearn–Baker / Ray Tracing Gems).
    let f = o - d * (b / a);
    let disc = r * r - f.length_squared();
    if disc < 0.0 {
        return None;
    }
    let s = (a * disc).sqrt();
    let q = if b < 0.0 { -b + s } else { -b - s };
    let (mut t0, mut t1) = (
        q / a,
        if q != 0.0 {
            (o.length_squared() - r * r) / q
        } else {
            0.0
        },
    );
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    if t0 > 0.0 && t0 < t_max {
        Some(t0)
    } else if t1 > 0.0 && t1 < t_max {
        Some(t1)
    } else {
        None
    }
}

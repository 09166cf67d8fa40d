//! Spheres, disks and cylinders under an arbitrary affine transform: intersected in object
//! space.

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
    /// pbrt-v4's partial sphere: the sphere of `radius` cut to z in [zmin, zmax] (within
    /// [−radius, radius]) and φ in [0, phimax], uv = (φ/phimax, (θ − θ_zmin)/(θ_zmax − θ_zmin))
    /// with θ_z = acos(z/radius).
    SphereCut {
        /// Radius.
        radius: f32,
        /// Lower cut.
        zmin: f32,
        /// Upper cut.
        zmax: f32,
        /// Sweep in radians.
        phimax: f32,
    },
    /// pbrt-v4's annulus / partial disk in the plane z = `height`: inner ≤ r ≤ radius and φ in
    /// [0, phimax], normal +z, uv = (φ/phimax, (radius − r)/(radius − inner)).
    DiskCut {
        /// Plane height.
        height: f32,
        /// Outer radius.
        radius: f32,
        /// Inner radius.
        inner: f32,
        /// Sweep in radians.
        phimax: f32,
    },
    /// pbrt-v4's cylinder: x² + y² = radius² for z in [zmin, zmax] and φ in [0, phimax],
    /// outward normal (x, y, 0), uv = (φ/phimax, (z − zmin)/(zmax − zmin)).
    Cylinder {
        /// Radius.
        radius: f32,
        /// Lower end.
        zmin: f32,
        /// Upper end.
        zmax: f32,
        /// Sweep in radians (2π: closed).
        phimax: f32,
    },
    /// pbrt-v4's bilinear patch p(u, v) = lerp(v, lerp(u, p00, p10), lerp(u, p01, p11)) (in
    /// object space; a `bilinearmesh` stores its patches in world space under the identity),
    /// normal ∂p/∂u × ∂p/∂v, texture coordinates bilinear in the corners' `uv`.
    Bilinear {
        /// p00, p10, p01, p11.
        p: [Vec3; 4],
        /// The corners' texture coordinates (pbrt's default: (0,0), (1,0), (0,1), (1,1)).
        uv: [Vec2; 4],
    },
    /// One cubic Bézier segment of pbrt-v4's `curve` (see [`super::curve`]); uv = (u along
    /// the curve, v across its width).
    Curve(super::curve::CurveSegment),
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
            QuadricKind::Disk { height, radius } | QuadricKind::DiskCut { height, radius, .. } => (
                Vec3::new(-radius, -radius, height),
                Vec3::new(radius, radius, height),
            ),
            QuadricKind::Cylinder {
                radius, zmin, zmax, ..
            }
            | QuadricKind::SphereCut {
                radius, zmin, zmax, ..
            } => (
                Vec3::new(-radius, -radius, zmin),
                Vec3::new(radius, radius, zmax),
            ),
            QuadricKind::Bilinear { p, .. } => (
                p[0].min(p[1]).min(p[2].min(p[3])),
                p[0].max(p[1]).max(p[2].max(p[3])),
            ),
            QuadricKind::Curve(c) => c.bounds(),
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
            QuadricKind::SphereCut {
                radius,
                zmin,
                zmax,
                phimax,
            } => sphere_cut_t(oo, dd, radius as f64, [zmin, zmax, phimax], t_max as f64)?,
            QuadricKind::DiskCut {
                height,
                radius,
                inner,
                phimax,
            } => {
                if dd.z == 0.0 {
                    return None;
                }
                let t = (height as f64 - oo.z) / dd.z;
                if t <= 0.0 || t >= t_max as f64 {
                    return None;
                }
                let p = oo + dd * t;
                let r2 = p.x * p.x + p.y * p.y;
                if r2 > (radius as f64).powi(2) || r2 < (inner as f64).powi(2) {
                    return None;
                }
                if !within_phi(p, phimax) {
                    return None;
                }
                t
            }
            QuadricKind::Cylinder {
                radius,
                zmin,
                zmax,
                phimax,
            } => cylinder_t(oo, dd, radius as f64, zmin, zmax, phimax, t_max as f64)?,
            QuadricKind::Bilinear { p, .. } => bilinear_hit(oo, dd, &p, t_max as f64)?.0,
            QuadricKind::Curve(c) => c.intersect(oo, dd, t_max as f64)?.t,
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
        if let QuadricKind::Bilinear { p: c, uv } = self.kind {
            return self.bilinear_surface(oo, dd, t, &c, &uv);
        }
        if let QuadricKind::Curve(c) = self.kind {
            return self.curve_surface(oo, dd, t, &c);
        }
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
                // pbrt-v4's v = (θ − θ_zmin)/(θ_zmax − θ_zmin) with θ_zmin = π: 0 at the
                // bottom pole, 1 at the top.
                (pf, Vec2::new(phi / (2.0 * PI), 1.0 - cos_theta.acos() / PI))
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
            QuadricKind::SphereCut {
                radius,
                zmin,
                zmax,
                phimax,
            } => {
                let len = p.length();
                if len > 0.0 {
                    p *= radius as f64 / len;
                }
                let pf = p.as_vec3();
                let phi = pf.y.atan2(pf.x).rem_euclid(2.0 * PI);
                let theta = |z: f32| (z / radius).clamp(-1.0, 1.0).acos();
                let (t0, t1) = (theta(zmin), theta(zmax));
                let dt = t1 - t0;
                (
                    pf,
                    Vec2::new(
                        phi / phimax.max(f32::MIN_POSITIVE),
                        if dt != 0.0 {
                            (theta(pf.z) - t0) / dt
                        } else {
                            0.0
                        },
                    ),
                )
            }
            QuadricKind::DiskCut {
                height,
                radius,
                inner,
                phimax,
            } => {
                p.z = height as f64;
                let pf = p.as_vec3();
                let r = (pf.x * pf.x + pf.y * pf.y).sqrt();
                let phi = pf.y.atan2(pf.x).rem_euclid(2.0 * PI);
                let dr = radius - inner;
                (
                    Vec3::Z,
                    Vec2::new(
                        phi / phimax.max(f32::MIN_POSITIVE),
                        if dr > 0.0 { (radius - r) / dr } else { 0.0 },
                    ),
                )
            }
            QuadricKind::Cylinder {
                radius,
                zmin,
                zmax,
                phimax,
            } => {
                // Re-project onto the cylinder, as the sphere does.
                let len = (p.x * p.x + p.y * p.y).sqrt();
                if len > 0.0 {
                    p.x *= radius as f64 / len;
                    p.y *= radius as f64 / len;
                }
                let pf = p.as_vec3();
                let phi = pf.y.atan2(pf.x).rem_euclid(2.0 * PI);
                let dz = zmax - zmin;
                (
                    Vec3::new(pf.x, pf.y, 0.0),
                    Vec2::new(
                        phi / phimax.max(f32::MIN_POSITIVE),
                        if dz != 0.0 { (pf.z - zmin) / dz } else { 0.0 },
                    ),
                )
            }
            QuadricKind::Bilinear { .. } | QuadricKind::Curve(_) => unreachable!("handled above"),
        };
        // Object-space error: γ5 of the coordinates.
        self.world_hit(
            p.as_vec3(),
            n_obj,
            uv,
            gamma(5) * p.as_vec3().abs().max_element(),
        )
    }

    /// A hit at object-space point `p_obj` with normal `n_obj` and texture coordinates `uv`,
    /// in world space. Its error bound is pbrt-v4's, made isotropic: the object-space error
    /// `obj_err` carried through the affine map, plus the map's own rounding (γ3 of the
    /// result), and γ1 more of the result for the rounding of a spawned ray's origin p + n·d
    /// (half an ulp per coordinate), as the triangles' `POINT_ERROR_GAMMA` has. The
    /// intersection maps that origin back to object space in f32 and (with the f32 inverse's
    /// own error) moves it by less than half this bound (tests/geometry.rs measures it far
    /// from the origin).
    fn world_hit(&self, p_obj: Vec3, n_obj: Vec3, uv: Vec2, obj_err: f32) -> QuadricHit {
        let pw = self.to_world.point(p_obj);
        let mut n = self.to_world.normal(n_obj).normalize_or_zero();
        if self.flip {
            n = -n;
        }
        let scale = self.to_world.m.x_axis.abs().max_element()
            + self.to_world.m.y_axis.abs().max_element()
            + self.to_world.m.z_axis.abs().max_element();
        let err = obj_err * scale
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

impl Quadric {
    /// Surface data of a bilinear patch hit near `t` (the patch solve again, for (u, v)).
    fn bilinear_surface(
        &self,
        o: DVec3,
        d: DVec3,
        t: f32,
        c: &[Vec3; 4],
        uv: &[Vec2; 4],
    ) -> QuadricHit {
        // The hit was found below t_max = t's successor: solve again just past it.
        let (_, u, v) = bilinear_hit(o, d, c, t as f64 * (1.0 + 1e-6) + 1e-30)
            // Not found again (rounding at an edge): the patch's centre.
            .unwrap_or((t as f64, 0.5, 0.5));
        let cd = c.map(|p| p.as_dvec3());
        let lerp = |a: DVec3, b: DVec3, s: f64| a + (b - a) * s;
        let pobj = lerp(lerp(cd[0], cd[1], u), lerp(cd[2], cd[3], u), v);
        let dpdu = lerp(cd[1] - cd[0], cd[3] - cd[2], v);
        let dpdv = lerp(cd[2] - cd[0], cd[3] - cd[1], u);
        let n_obj = dpdu.cross(dpdv).as_vec3();
        let (uf, vf) = (u as f32, v as f32);
        let tex =
            (uv[0] * (1.0 - uf) + uv[1] * uf) * (1.0 - vf) + (uv[2] * (1.0 - uf) + uv[3] * uf) * vf;
        let big = c.iter().fold(0.0f32, |m, p| m.max(p.abs().max_element()));
        self.world_hit(pobj.as_vec3(), n_obj, tex, gamma(8) * big)
    }
}

impl Quadric {
    /// Surface data of a curve hit at `t` (the curve solve again, for u, v and the normal).
    fn curve_surface(
        &self,
        o: DVec3,
        d: DVec3,
        t: f32,
        c: &super::curve::CurveSegment,
    ) -> QuadricHit {
        let h = c.intersect(o, d, t as f64 * (1.0 + 1e-6) + 1e-30);
        let (u, v, n_obj, tt) = match h {
            Some(h) => (h.u as f32, h.v as f32, h.n.as_vec3(), h.t),
            None => (0.5, 0.5, (-d).normalize_or_zero().as_vec3(), t as f64),
        };
        let pobj = (o + d * tt).as_vec3();
        let big = c.cp.iter().fold(pobj.abs().max_element(), |m, p| {
            m.max(p.abs().max_element())
        });
        self.world_hit(pobj, n_obj, Vec2::new(u, v), gamma(8) * big)
    }
}

/// pbrt-v4's bilinear patch intersection (Reshetov's): the u of the ray's closest approach
/// to the patch's u iso-lines from a quadratic, then v and t from the line through those
/// iso-line points; the nearest (t, u, v) with u, v in [0, 1] and t in (0, t_max).
pub fn bilinear_hit(o: DVec3, d: DVec3, c: &[Vec3; 4], t_max: f64) -> Option<(f64, f64, f64)> {
    let [p00, p10, p01, p11] = c.map(|p| p.as_dvec3());
    let a = (p10 - p00).cross(p01 - p11).dot(d);
    let cc = (p00 - o).cross(d).dot(p01 - p00);
    let b = (p10 - o).cross(d).dot(p11 - p10) - (a + cc);
    // Roots of a u² + b u + c = 0 (a linear equation when a = 0).
    let roots: [f64; 2] = if a.abs() < 1e-300 {
        if b == 0.0 {
            return None;
        }
        [-cc / b, f64::NAN]
    } else {
        let disc = b * b - 4.0 * a * cc;
        if disc < 0.0 {
            return None;
        }
        let s = disc.sqrt();
        let q = if b < 0.0 {
            -0.5 * (b - s)
        } else {
            -0.5 * (b + s)
        };
        let (r0, r1) = (q / a, if q != 0.0 { cc / q } else { -b / a });
        if r0 <= r1 { [r0, r1] } else { [r1, r0] }
    };
    let scale = [o.abs().max_element(), d.abs().max_element()]
        .into_iter()
        .chain([p00, p10, p01, p11].map(|p| p.abs().max_element()))
        .fold(0.0f64, f64::max);
    let eps = 1e-12 * scale.max(1e-300);
    let mut best: Option<(f64, f64, f64)> = None;
    for (k, &u) in roots.iter().enumerate() {
        if !(0.0..=1.0).contains(&u) || (k == 1 && u == roots[0]) {
            continue;
        }
        let uo = p00 + (p10 - p00) * u;
        let ud = p01 + (p11 - p01) * u - uo;
        let deltao = uo - o;
        let perp = d.cross(ud);
        let p2 = perp.length_squared();
        if p2 == 0.0 {
            continue;
        }
        // det[deltao, d, perp] and det[deltao, ud, perp] (columns).
        let v1 = deltao.dot(d.cross(perp));
        let t1 = deltao.dot(ud.cross(perp));
        if !(0.0..=p2).contains(&v1) {
            continue;
        }
        let (t, v) = (t1 / p2, v1 / p2);
        if t > eps && t < t_max && best.is_none_or(|b| t < b.0) {
            best = Some((t, u, v));
        }
    }
    best
}

/// The nearest t in (0, t_max) where the ray meets the cylinder x² + y² = r² inside
/// z ∈ [zmin, zmax] and φ ∈ [0, phimax] (the far root when the near one is clipped away).
fn cylinder_t(
    o: DVec3,
    d: DVec3,
    r: f64,
    zmin: f32,
    zmax: f32,
    phimax: f32,
    t_max: f64,
) -> Option<f64> {
    let a = d.x * d.x + d.y * d.y;
    if a == 0.0 {
        return None;
    }
    let b = o.x * d.x + o.y * d.y;
    // |o⊥ − (o⊥·d̂⊥)d̂⊥|², as the sphere's stable discriminant, in the xy plane.
    let fx = o.x - d.x * (b / a);
    let fy = o.y - d.y * (b / a);
    let disc = r * r - (fx * fx + fy * fy);
    if disc < 0.0 {
        return None;
    }
    let s = (a * disc).sqrt();
    let q = if b < 0.0 { -b + s } else { -b - s };
    let c = o.x * o.x + o.y * o.y - r * r;
    let (mut t0, mut t1) = (q / a, if q != 0.0 { c / q } else { 0.0 });
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    let (zmin, zmax) = (zmin.min(zmax) as f64, zmin.max(zmax) as f64);
    let inside = |t: f64| {
        if !(t > 0.0 && t < t_max) {
            return false;
        }
        let p = o + d * t;
        if p.z < zmin || p.z > zmax {
            return false;
        }
        if phimax as f64 >= 2.0 * std::f64::consts::PI {
            return true;
        }
        let phi = p.y.atan2(p.x).rem_euclid(2.0 * std::f64::consts::PI);
        phi <= phimax as f64
    };
    if inside(t0) {
        Some(t0)
    } else if inside(t1) {
        Some(t1)
    } else {
        None
    }
}

/// Whether object-space point `p` lies within the sweep φ ∈ [0, phimax].
#[inline]
fn within_phi(p: DVec3, phimax: f32) -> bool {
    let tau = 2.0 * std::f64::consts::PI;
    phimax as f64 >= tau || p.y.atan2(p.x).rem_euclid(tau) <= phimax as f64
}

/// Nearest root of |o + t d|² = r² in (0, t_max) whose point lies within the cuts
/// z ∈ [zmin, zmax] and φ ∈ [0, phimax] (pbrt-v4 tries the far root when the near one is
/// cut away, so the inside of a partial sphere is visible through the gap).
fn sphere_cut_t(
    o: DVec3,
    d: DVec3,
    r: f64,
    [zmin, zmax, phimax]: [f32; 3],
    t_max: f64,
) -> Option<f64> {
    let a = d.length_squared();
    if a == 0.0 {
        return None;
    }
    let b = o.dot(d);
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
    let keep = |t: f64| {
        if !(t > 0.0 && t < t_max) {
            return false;
        }
        let p = o + d * t;
        let p = p * (r / p.length());
        !(p.z < zmin as f64 || p.z > zmax as f64) && within_phi(p, phimax)
    };
    [t0, t1].into_iter().find(|&t| keep(t))
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

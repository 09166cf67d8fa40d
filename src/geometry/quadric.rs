//! Spheres, disks and cylinders under an arbitrary affine transform: intersected in object
//! space.

use super::Transform;
use super::alpha::Alpha;
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
#[derive(Clone, Debug)]
pub struct Quadric {
    /// Shape in object space.
    pub kind: QuadricKind,
    /// Object-to-world transform.
    pub to_world: Transform,
    /// Flip the outward normal (ReverseOrientation xor handedness swap).
    pub flip: bool,
    /// Alpha cut-out (pbrt-v4's shape `alpha`): hits it does not keep are ignored by every
    /// query, and the ray goes on to the shape's other side.
    pub alpha: Option<CutOut>,
}

/// A quadric's alpha mask and the key that salts its hash, so that stacked cut-outs decide
/// independently (each wall of one sphere salts it once more).
#[derive(Clone, Debug)]
pub struct CutOut {
    /// Coverage over the shape's uv.
    pub alpha: Alpha,
    /// Names the shape in the hash ([`Alpha::keeps`]); distinct per quadric.
    pub key: u64,
}

impl CutOut {
    /// True if the hit at `uv` of the world ray (`o`, `d`) counts; `salt` names which of the
    /// shape's hits along the ray it is (root index, or a curve hit's u).
    #[inline]
    pub fn keeps(&self, uv: Vec2, o: Vec3, d: Vec3, salt: u64) -> bool {
        self.alpha.keeps(uv, o, d, self.key ^ salt << 32)
    }
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
        if let Some(c) = &self.alpha {
            return self.cut_out_t(o, d, t_max, c);
        }
        let m = &self.to_world.m_inv;
        let oo = m.transform_point3(o).as_dvec3();
        let dd = m.transform_vector3(d).as_dvec3();
        let t = match self.kind {
            QuadricKind::Sphere { radius } => sphere_t(oo, dd, radius as f64, t_max as f64)?,
            QuadricKind::Disk { height, radius } => {
                disk_t(oo, dd, [height, radius, 0.0, FULL_SWEEP], t_max as f64)?
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
            } => disk_t(oo, dd, [height, radius, inner, phimax], t_max as f64)?,
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

    /// [`Self::intersect_t`] of a cut-out: the nearest hit its mask keeps. pbrt-v4 traces on
    /// past a hit its alpha test rejects, so a sphere's or cylinder's far wall shows through
    /// the near wall's holes; each wall decides with its own salt.
    #[inline(never)]
    fn cut_out_t(&self, o: Vec3, d: Vec3, t_max: f32, c: &CutOut) -> Option<f32> {
        let m = &self.to_world.m_inv;
        let oo = m.transform_point3(o).as_dvec3();
        let dd = m.transform_vector3(d).as_dvec3();
        let tm = t_max as f64;
        let in_range_f32 = |t: f64| {
            let t = t as f32;
            (t > 0.0 && t < t_max).then_some(t)
        };
        let roots: [Option<f64>; 2] = match self.kind {
            QuadricKind::Sphere { radius } => {
                let (t0, t1) = sphere_roots(oo, dd, radius as f64)?;
                [t0, t1].map(|t| in_range(t, tm).then_some(t))
            }
            QuadricKind::SphereCut {
                radius,
                zmin,
                zmax,
                phimax,
            } => {
                let r = radius as f64;
                let (t0, t1) = sphere_roots(oo, dd, r)?;
                [t0, t1]
                    .map(|t| sphere_cut_keeps(oo, dd, r, [zmin, zmax, phimax], t, tm).then_some(t))
            }
            QuadricKind::Disk { height, radius } => {
                [disk_t(oo, dd, [height, radius, 0.0, FULL_SWEEP], tm), None]
            }
            QuadricKind::DiskCut {
                height,
                radius,
                inner,
                phimax,
            } => [disk_t(oo, dd, [height, radius, inner, phimax], tm), None],
            QuadricKind::Cylinder {
                radius,
                zmin,
                zmax,
                phimax,
            } => {
                let (t0, t1) = cylinder_roots(oo, dd, radius as f64)?;
                [t0, t1].map(|t| cylinder_keeps(oo, dd, [zmin, zmax, phimax], t, tm).then_some(t))
            }
            QuadricKind::Bilinear { p, uv } => {
                return bilinear_hit_where(oo, dd, &p, tm, |k, u, v| {
                    c.keeps(bilinear_tex(&uv, u, v), o, d, k as u64)
                })
                .and_then(|h| in_range_f32(h.0));
            }
            QuadricKind::Curve(s) => {
                return s
                    .intersect_where(oo, dd, tm, &|h| c.keeps(curve_uv(h), o, d, curve_salt(h)))
                    .and_then(|h| in_range_f32(h.t));
            }
        };
        for (k, t) in roots.into_iter().enumerate() {
            let Some(t) = t.and_then(in_range_f32) else {
                continue;
            };
            if c.keeps(self.hit(o, d, t).uv, o, d, k as u64) {
                return Some(t);
            }
        }
        None
    }

    /// Surface data at the hit `t` of ray (o, d).
    pub fn hit(&self, o: Vec3, d: Vec3, t: f32) -> QuadricHit {
        let m = &self.to_world.m_inv;
        let oo = m.transform_point3(o).as_dvec3();
        let dd = m.transform_vector3(d).as_dvec3();
        let mut p = oo + dd * t as f64;
        if let QuadricKind::Bilinear { p: c, uv } = self.kind {
            return self.bilinear_surface([o, d], oo, dd, t, &c, &uv);
        }
        if let QuadricKind::Curve(c) = self.kind {
            return self.curve_surface([o, d], oo, dd, t, &c);
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

    /// pbrt-v4's surface derivatives at the hit at world point `p` (texture coordinates `uv`,
    /// unit normal `n` as the hit reports it), in world space: [∂p/∂u, ∂p/∂v, ∂n/∂u, ∂n/∂v]
    /// of the shape's (u, v), what a normal map's tangent frame (x along ∂p/∂u) and a bump
    /// map's displaced surface are built from. ∂n is of `n` (negated with the orientation
    /// flip, as a displacement along `n` needs). `None` where ∂p/∂u vanishes (the poles and
    /// centres, where pbrt-v4 too has no frame of its own).
    pub fn derivatives(&self, p: Vec3, uv: Vec2, n: Vec3) -> Option<[Vec3; 4]> {
        let po = self.to_world.m_inv.transform_point3(p).as_dvec3();
        // ∂p/∂u of the sweep about z, common to the swept quadrics.
        let swept = |q: DVec3, phimax: f64| DVec3::new(-q.y, q.x, 0.0) * phimax;
        let (dpdu, dpdv, dndu, dndv) = match self.kind {
            QuadricKind::Sphere { radius } => {
                sphere_derivatives(po, radius, [-radius, radius, FULL_SWEEP])
            }
            QuadricKind::SphereCut {
                radius,
                zmin,
                zmax,
                phimax,
            } => sphere_derivatives(po, radius, [zmin, zmax, phimax]),
            QuadricKind::Disk { radius, .. } => disk_derivatives(po, [radius, 0.0, FULL_SWEEP]),
            QuadricKind::DiskCut {
                radius,
                inner,
                phimax,
                ..
            } => disk_derivatives(po, [radius, inner, phimax]),
            QuadricKind::Cylinder {
                radius,
                zmin,
                zmax,
                phimax,
            } => {
                let r = radius as f64;
                let rho = po.truncate().length();
                if rho == 0.0 {
                    return None;
                }
                let q = DVec3::new(po.x * r / rho, po.y * r / rho, po.z);
                let dpdu = swept(q, phimax as f64);
                // n = (x, y, 0)/r turns with φ only: ∂n/∂u = ∂p/∂u / r.
                (
                    dpdu,
                    DVec3::new(0.0, 0.0, (zmax - zmin) as f64),
                    dpdu / r,
                    DVec3::ZERO,
                )
            }
            QuadricKind::Bilinear { p: c, uv: tuv } => bilinear_derivatives(po, &c, &tuv, uv),
            QuadricKind::Curve(c) => {
                let u = (uv.x as f64).clamp(0.0, 1.0);
                let dpdu = c.tangent(u);
                // pbrt-v4's ∂p/∂v runs across the width, with ∂p/∂u × ∂p/∂v along the hit's
                // normal (object-space normals map back by the transpose); ∂n = 0 as pbrt's.
                let n_out = if self.flip { -n } else { n };
                let n_obj = self
                    .to_world
                    .m
                    .transpose()
                    .transform_vector3(n_out)
                    .as_dvec3();
                let w = c.width[0] as f64 + (c.width[1] as f64 - c.width[0] as f64) * u;
                let dpdv = n_obj.cross(dpdu).normalize_or_zero() * w;
                (dpdu, dpdv, DVec3::ZERO, DVec3::ZERO)
            }
        };
        if dpdu.length_squared() == 0.0 {
            return None;
        }
        let flip = if self.flip { -1.0 } else { 1.0 };
        let out = [
            self.to_world.vector(dpdu.as_vec3()),
            self.to_world.vector(dpdv.as_vec3()),
            self.to_world.normal(dndu.as_vec3()) * flip,
            self.to_world.normal(dndv.as_vec3()) * flip,
        ];
        out.iter().all(|v| v.is_finite()).then_some(out)
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
    /// Surface data of a bilinear patch hit near `t` (the patch solve again, for (u, v)) of the
    /// world ray `world` = (o, d), (`o`, `d`) in object space.
    fn bilinear_surface(
        &self,
        [wo, wd]: [Vec3; 2],
        o: DVec3,
        d: DVec3,
        t: f32,
        c: &[Vec3; 4],
        uv: &[Vec2; 4],
    ) -> QuadricHit {
        // The hit was found below t_max = t's successor: solve again just past it (with the
        // cut-out's test, which rejected any nearer root then and does so again).
        let t_max = t as f64 * (1.0 + 1e-6) + 1e-30;
        let (_, u, v) = match &self.alpha {
            None => bilinear_hit(o, d, c, t_max),
            Some(cut) => bilinear_hit_where(o, d, c, t_max, |k, u, v| {
                cut.keeps(bilinear_tex(uv, u, v), wo, wd, k as u64)
            }),
        }
        // Not found again (rounding at an edge): the patch's centre.
        .unwrap_or((t as f64, 0.5, 0.5));
        let cd = c.map(|p| p.as_dvec3());
        let lerp = |a: DVec3, b: DVec3, s: f64| a + (b - a) * s;
        let pobj = lerp(lerp(cd[0], cd[1], u), lerp(cd[2], cd[3], u), v);
        let dpdu = lerp(cd[1] - cd[0], cd[3] - cd[2], v);
        let dpdv = lerp(cd[2] - cd[0], cd[3] - cd[1], u);
        let n_obj = dpdu.cross(dpdv).as_vec3();
        let tex = bilinear_tex(uv, u, v);
        let big = c.iter().fold(0.0f32, |m, p| m.max(p.abs().max_element()));
        self.world_hit(pobj.as_vec3(), n_obj, tex, gamma(8) * big)
    }
}

impl Quadric {
    /// Surface data of a curve hit at `t` (the curve solve again, for u, v and the normal) of
    /// the world ray `world` = (o, d), (`o`, `d`) in object space.
    fn curve_surface(
        &self,
        [wo, wd]: [Vec3; 2],
        o: DVec3,
        d: DVec3,
        t: f32,
        c: &super::curve::CurveSegment,
    ) -> QuadricHit {
        let t_max = t as f64 * (1.0 + 1e-6) + 1e-30;
        let h = match &self.alpha {
            None => c.intersect(o, d, t_max),
            Some(cut) => c.intersect_where(o, d, t_max, &|h| {
                cut.keeps(curve_uv(h), wo, wd, curve_salt(h))
            }),
        };
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

/// Object-space (∂p/∂u, ∂p/∂v, ∂n/∂u, ∂n/∂v) of the partial sphere `[zmin, zmax, phimax]` of
/// `radius` at `p` (pbrt-v4's: u = φ/φmax, v = (θ − θ_zmin)/(θ_zmax − θ_zmin)).
fn sphere_derivatives(
    p: DVec3,
    radius: f32,
    [zmin, zmax, phimax]: [f32; 3],
) -> (DVec3, DVec3, DVec3, DVec3) {
    let r = radius as f64;
    let len = p.length();
    let p = if len > 0.0 { p * (r / len) } else { p };
    let rho = p.truncate().length();
    if rho == 0.0 {
        return (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    }
    let theta = |z: f32| (z as f64 / r).clamp(-1.0, 1.0).acos();
    let dtheta = theta(zmax) - theta(zmin);
    let dpdu = DVec3::new(-p.y, p.x, 0.0) * phimax as f64;
    // (z cos φ, z sin φ, −r sin θ) with r sin θ = ρ.
    let dpdv = DVec3::new(p.z * p.x / rho, p.z * p.y / rho, -rho) * dtheta;
    // n = p / r: the Weingarten equations give ∂n = ∂p / r exactly.
    (dpdu, dpdv, dpdu / r, dpdv / r)
}

/// Object-space derivatives of the annulus `[radius, inner, phimax]` at `p` (u = φ/φmax,
/// v = (radius − r)/(radius − inner)); flat, so ∂n = 0.
fn disk_derivatives(p: DVec3, [radius, inner, phimax]: [f32; 3]) -> (DVec3, DVec3, DVec3, DVec3) {
    let rho = p.truncate().length();
    if rho == 0.0 {
        return (DVec3::ZERO, DVec3::ZERO, DVec3::ZERO, DVec3::ZERO);
    }
    let dpdu = DVec3::new(-p.y, p.x, 0.0) * phimax as f64;
    let dpdv = DVec3::new(p.x, p.y, 0.0) * ((inner - radius) as f64 / rho);
    (dpdu, dpdv, DVec3::ZERO, DVec3::ZERO)
}

/// Object-space derivatives of the bilinear patch `c` at its point `p` with respect to the
/// texture coordinates `tuv` of its corners (pbrt-v4's (s, t) reparameterisation; the patch
/// (u, v) themselves for the default corners), ∂n by the Weingarten equations (∂²p/∂u∂v is the
/// patch's only second derivative), carried to (s, t) by the same chain rule. `uv` is the
/// hit's texture coordinates (Newton's starting point for the patch's (u, v)).
fn bilinear_derivatives(
    p: DVec3,
    c: &[Vec3; 4],
    tuv: &[Vec2; 4],
    uv: Vec2,
) -> (DVec3, DVec3, DVec3, DVec3) {
    let cd = c.map(|q| q.as_dvec3());
    let lerp = |a: DVec3, b: DVec3, s: f64| a + (b - a) * s;
    let du_at = |v: f64| lerp(cd[1] - cd[0], cd[3] - cd[2], v);
    let dv_at = |u: f64| lerp(cd[2] - cd[0], cd[3] - cd[1], u);
    // The patch's (u, v) of p: Gauss–Newton on |p(u, v) − p|² from the texture coordinates
    // (exact for the default corners, the centre otherwise).
    let default = [Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::ONE];
    let (mut u, mut v) = if *tuv == default {
        (uv.x as f64, uv.y as f64)
    } else {
        (0.5, 0.5)
    };
    for _ in 0..16 {
        let (pu, pv) = (du_at(v), dv_at(u));
        let rr = p - lerp(lerp(cd[0], cd[1], u), lerp(cd[2], cd[3], u), v);
        let (a00, a01, a11) = (pu.dot(pu), pu.dot(pv), pv.dot(pv));
        let det = a00 * a11 - a01 * a01;
        if !(det > 0.0) {
            break;
        }
        let (b0, b1) = (pu.dot(rr), pv.dot(rr));
        let (su, sv) = ((a11 * b0 - a01 * b1) / det, (a00 * b1 - a01 * b0) / det);
        u = (u + su).clamp(0.0, 1.0);
        v = (v + sv).clamp(0.0, 1.0);
        if su.abs() + sv.abs() < 1e-12 {
            break;
        }
    }
    let (dpdu, dpdv) = (du_at(v), dv_at(u));
    let d2 = cd[3] - cd[2] - cd[1] + cd[0];
    let nn = dpdu.cross(dpdv).normalize_or_zero();
    let (e, f, g) = (dpdu.dot(dpdu), dpdu.dot(dpdv), dpdv.dot(dpdv));
    let ff = nn.dot(d2);
    let inv = 1.0 / (e * g - f * f);
    let (dndu, dndv) = if inv.is_finite() {
        (
            (dpdu * (ff * f) - dpdv * (ff * e)) * inv,
            (dpdu * (-ff * g) + dpdv * (ff * f)) * inv,
        )
    } else {
        (DVec3::ZERO, DVec3::ZERO)
    };
    // pbrt-v4: ∂(u, v)/∂(s, t) from the texture coordinates' own derivatives.
    let tl = |a: Vec2, b: Vec2, s: f64| a.as_dvec2() + (b - a).as_dvec2() * s;
    let dstdu = tl(tuv[1], tuv[3], v) - tl(tuv[0], tuv[2], v);
    let dstdv = tl(tuv[2], tuv[3], u) - tl(tuv[0], tuv[1], u);
    let inv_or_0 = |x: f64| if x.abs() < 1e-8 { 0.0 } else { 1.0 / x };
    let (duds, dvds) = (inv_or_0(dstdu.x), inv_or_0(dstdv.x));
    let (dudt, dvdt) = (inv_or_0(dstdu.y), inv_or_0(dstdv.y));
    let dpds = dpdu * duds + dpdv * dvds;
    let mut dpdt = dpdu * dudt + dpdv * dvdt;
    let cst = dpds.cross(dpdt);
    if cst == DVec3::ZERO {
        return (dpdu, dpdv, dndu, dndv);
    }
    let mut sign = 1.0;
    if dpdu.cross(dpdv).dot(cst) < 0.0 {
        dpdt = -dpdt;
        sign = -1.0;
    }
    (
        dpds,
        dpdt,
        dndu * duds + dndv * dvds,
        (dndu * dudt + dndv * dvdt) * sign,
    )
}

/// A curve hit's texture coordinates (u along, v across), as its hit record has them.
#[inline]
fn curve_uv(h: &super::curve::CurveHit) -> Vec2 {
    Vec2::new(h.u as f32, h.v as f32)
}

/// Names a curve hit among the segment's hits along one ray (a curled segment is crossed
/// more than once) for the cut-out's hash.
#[inline]
fn curve_salt(h: &super::curve::CurveHit) -> u64 {
    (h.u as f32).to_bits() as u64
}

/// Texture coordinates at patch parameters (u, v): the corners' uvs interpolated bilinearly.
#[inline]
fn bilinear_tex(uv: &[Vec2; 4], u: f64, v: f64) -> Vec2 {
    let (uf, vf) = (u as f32, v as f32);
    (uv[0] * (1.0 - uf) + uv[1] * uf) * (1.0 - vf) + (uv[2] * (1.0 - uf) + uv[3] * uf) * vf
}

/// pbrt-v4's bilinear patch intersection (Reshetov's): the u of the ray's closest approach
/// to the patch's u iso-lines from a quadratic, then v and t from the line through those
/// iso-line points; the nearest (t, u, v) with u, v in [0, 1] and t in (0, t_max).
pub fn bilinear_hit(o: DVec3, d: DVec3, c: &[Vec3; 4], t_max: f64) -> Option<(f64, f64, f64)> {
    bilinear_hit_where(o, d, c, t_max, |_, _, _| true)
}

/// [`bilinear_hit`] among the roots `keep(root index, u, v)` accepts (a cut-out's test).
pub fn bilinear_hit_where(
    o: DVec3,
    d: DVec3,
    c: &[Vec3; 4],
    t_max: f64,
    keep: impl Fn(usize, f64, f64) -> bool,
) -> Option<(f64, f64, f64)> {
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
        if t > eps && t < t_max && best.is_none_or(|b| t < b.0) && keep(k, u, v) {
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
    let cut = [zmin, zmax, phimax];
    nearest_kept(cylinder_roots(o, d, r)?, |t| {
        cylinder_keeps(o, d, cut, t, t_max)
    })
}

/// The roots t0 ≤ t1 of x² + y² = r² along the ray, if it meets the infinite cylinder.
#[inline]
fn cylinder_roots(o: DVec3, d: DVec3, r: f64) -> Option<(f64, f64)> {
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
    Some((t0, t1))
}

/// Whether root `t` of the cylinder lies in (0, t_max) and within the cut
/// [zmin, zmax, phimax].
#[inline]
fn cylinder_keeps(o: DVec3, d: DVec3, [zmin, zmax, phimax]: [f32; 3], t: f64, t_max: f64) -> bool {
    let (zmin, zmax) = (zmin.min(zmax) as f64, zmin.max(zmax) as f64);
    if !in_range(t, t_max) {
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
}

/// Hit of the annulus `[height, radius, inner, phimax]`, in (0, t_max); a full disk is the
/// annulus of inner radius 0 and sweep 2π.
#[inline]
fn disk_t(
    o: DVec3,
    d: DVec3,
    [height, radius, inner, phimax]: [f32; 4],
    t_max: f64,
) -> Option<f64> {
    if d.z == 0.0 {
        return None;
    }
    let t = (height as f64 - o.z) / d.z;
    if t <= 0.0 || t >= t_max {
        return None;
    }
    let p = o + d * t;
    let r2 = p.x * p.x + p.y * p.y;
    if r2 > (radius as f64).powi(2) || r2 < (inner as f64).powi(2) {
        return None;
    }
    if !within_phi(p, phimax) {
        return None;
    }
    Some(t)
}

/// The sweep of a full disk or sphere: 2π rounded up in f32, so [`within_phi`] accepts every
/// φ without computing it.
const FULL_SWEEP: f32 = 2.0 * PI;

/// Whether object-space point `p` lies within the sweep φ ∈ [0, phimax].
#[inline]
fn within_phi(p: DVec3, phimax: f32) -> bool {
    let tau = 2.0 * std::f64::consts::PI;
    phimax as f64 >= tau || p.y.atan2(p.x).rem_euclid(tau) <= phimax as f64
}

/// Nearest root of |o + t d|² = r² in (0, t_max). A full sphere is not the cut
/// [−r, r, 2π]: [`sphere_cut_keeps`]'s reprojection costs +1.8% Ir on cornell-phong (callgrind).
#[inline]
fn sphere_t(o: DVec3, d: DVec3, r: f64, t_max: f64) -> Option<f64> {
    nearest_kept(sphere_roots(o, d, r)?, |t| in_range(t, t_max))
}

/// Nearest root of |o + t d|² = r² in (0, t_max) whose point lies within the cuts
/// z ∈ [zmin, zmax] and φ ∈ [0, phimax] (pbrt-v4 tries the far root when the near one is
/// cut away, so the inside of a partial sphere is visible through the gap).
fn sphere_cut_t(o: DVec3, d: DVec3, r: f64, cut: [f32; 3], t_max: f64) -> Option<f64> {
    nearest_kept(sphere_roots(o, d, r)?, |t| {
        sphere_cut_keeps(o, d, r, cut, t, t_max)
    })
}

/// Whether root `t` of the sphere of radius `r` lies in (0, t_max) and within the cut
/// [zmin, zmax, phimax].
#[inline]
fn sphere_cut_keeps(
    o: DVec3,
    d: DVec3,
    r: f64,
    [zmin, zmax, phimax]: [f32; 3],
    t: f64,
    t_max: f64,
) -> bool {
    if !in_range(t, t_max) {
        return false;
    }
    let p = o + d * t;
    let p = p * (r / p.length());
    !(p.z < zmin as f64 || p.z > zmax as f64) && within_phi(p, phimax)
}

/// Whether t lies in (0, t_max).
#[inline(always)]
fn in_range(t: f64, t_max: f64) -> bool {
    t > 0.0 && t < t_max
}

/// The nearer of the roots t0 ≤ t1 that `keeps` accepts (the far one where the near one is
/// behind the ray, beyond t_max or cut away).
#[inline(always)]
fn nearest_kept((t0, t1): (f64, f64), keeps: impl Fn(f64) -> bool) -> Option<f64> {
    if keeps(t0) {
        Some(t0)
    } else if keeps(t1) {
        Some(t1)
    } else {
        None
    }
}

/// The roots t0 ≤ t1 of |o + t d|² = r², if the ray meets the sphere.
#[inline]
fn sphere_roots(o: DVec3, d: DVec3, r: f64) -> Option<(f64, f64)> {
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
    Some((t0, t1))
}

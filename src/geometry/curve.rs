//! pbrt-v4's `curve` shape: a cubic Bézier segment swept by a width that varies linearly
//! along it, intersected as pbrt-v4 does (`Curve::IntersectRay` / `RecursiveIntersect`): in a
//! frame where the ray runs along +z from the origin, the segment is split in halves until
//! flat enough, and each flat piece is hit where the ray passes within half the width of the
//! point of the piece nearest to it (between the pieces' end perpendiculars). `flat` curves
//! face the ray, `cylinder` curves do too but shade with a normal turned across the width as
//! a cylinder's, `ribbon` curves have the orientation of their normals (and their width
//! foreshortened by it).

use glam::{DVec3, Vec3};

/// pbrt-v4's curve types.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CurveType {
    /// A ribbon always facing the ray.
    Flat,
    /// A flat ribbon facing the ray, shaded as a cylinder.
    Cylinder,
    /// A ribbon oriented by normals at its ends.
    Ribbon,
}

/// One cubic Bézier segment of a curve (object space).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurveSegment {
    /// Control points.
    pub cp: [Vec3; 4],
    /// Width at u = 0 and u = 1.
    pub width: [f32; 2],
    /// Ribbon normals at u = 0 and u = 1 (unit; unused by the other types).
    pub n: [Vec3; 2],
    /// Flat, cylinder or ribbon.
    pub kind: CurveType,
}

/// A hit: ray parameter, (u, v) on the curve, the object-space normal.
#[derive(Clone, Copy, Debug)]
pub struct CurveHit {
    /// Ray parameter (of the ray as given).
    pub t: f64,
    /// Along the curve.
    pub u: f64,
    /// Across the width, 0..1.
    pub v: f64,
    /// Unit normal (object space).
    pub n: DVec3,
}

fn lerp(a: DVec3, b: DVec3, t: f64) -> DVec3 {
    a + (b - a) * t
}

/// Bézier point and derivative at `u`.
fn bezier(cp: &[DVec3; 4], u: f64) -> (DVec3, DVec3) {
    let a = [
        lerp(cp[0], cp[1], u),
        lerp(cp[1], cp[2], u),
        lerp(cp[2], cp[3], u),
    ];
    let b = [lerp(a[0], a[1], u), lerp(a[1], a[2], u)];
    let d = b[1] - b[0];
    let d = if d.length_squared() > 0.0 {
        3.0 * d
    } else {
        cp[3] - cp[0]
    };
    (lerp(b[0], b[1], u), d)
}

/// de Casteljau at ½: the two halves' control points.
fn split(cp: &[DVec3; 4]) -> [[DVec3; 4]; 2] {
    let m01 = (cp[0] + cp[1]) * 0.5;
    let m12 = (cp[1] + cp[2]) * 0.5;
    let m23 = (cp[2] + cp[3]) * 0.5;
    let a = (m01 + m12) * 0.5;
    let b = (m12 + m23) * 0.5;
    let mid = (a + b) * 0.5;
    [[cp[0], m01, a, mid], [mid, b, m23, cp[3]]]
}

/// An orthonormal frame whose z is `d` (unit), x along `xhint` made perpendicular.
fn ray_frame(d: DVec3, xhint: DVec3) -> [DVec3; 3] {
    let mut x = xhint - d * d.dot(xhint);
    if x.length_squared() < 1e-24 {
        x = if d.x.abs() > 0.5 { DVec3::Y } else { DVec3::X };
        x -= d * d.dot(x);
    }
    let x = x.normalize();
    let y = d.cross(x);
    [x, y, d]
}

impl CurveSegment {
    /// Object-space bounds (control points padded by half the larger width).
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let w = 0.5 * self.width[0].max(self.width[1]);
        let lo = self
            .cp
            .iter()
            .fold(Vec3::splat(f32::INFINITY), |a, &p| a.min(p));
        let hi = self
            .cp
            .iter()
            .fold(Vec3::splat(f32::NEG_INFINITY), |a, &p| a.max(p));
        (lo - Vec3::splat(w), hi + Vec3::splat(w))
    }

    /// ∂p/∂u of the segment at `u` (object space).
    pub fn tangent(&self, u: f64) -> DVec3 {
        bezier(&self.cp.map(|p| p.as_dvec3()), u).1
    }

    /// The nearest hit of ray (o, d) (object space, `d` need not be unit) with t in
    /// (0, t_max).
    pub fn intersect(&self, o: DVec3, d: DVec3, t_max: f64) -> Option<CurveHit> {
        self.intersect_where(o, d, t_max, &|_| true)
    }

    /// [`Self::intersect`] among the hits `keep` accepts (a cut-out's test): the refinement
    /// visits every flat piece the ray's box reaches, so the nearest accepted one is found.
    pub fn intersect_where<K: Fn(&CurveHit) -> bool>(
        &self,
        o: DVec3,
        d: DVec3,
        t_max: f64,
        keep: &K,
    ) -> Option<CurveHit> {
        let len = d.length();
        if !(len > 0.0) {
            return None;
        }
        let dn = d / len;
        let cpo = self.cp.map(|p| p.as_dvec3());
        // pbrt-v4: the ray frame's x along d × (p3 − p0).
        let frame = ray_frame(dn, dn.cross(cpo[3] - cpo[0]));
        let to_ray = |p: DVec3| {
            let q = p - o;
            DVec3::new(q.dot(frame[0]), q.dot(frame[1]), q.dot(frame[2]))
        };
        let cp = cpo.map(to_ray);
        // Refinement depth from the control polygon's second differences (pbrt-v4).
        let mut l0 = 0.0f64;
        for i in 0..2 {
            let dd = (cp[i] - 2.0 * cp[i + 1] + cp[i + 2]).abs();
            l0 = l0.max(dd.max_element());
        }
        let eps = (self.width[0].max(self.width[1]) as f64 * 0.05).max(1e-30);
        let r0 = ((std::f64::consts::SQRT_2 * 6.0 * l0 / (8.0 * eps))
            .max(1.0)
            .log2() as i32)
            / 2;
        let depth = r0.clamp(0, 10);
        let mut best: Option<CurveHit> = None;
        let mut zmax = len * t_max;
        self.recurse(
            &cp, 0.0, 1.0, depth, &mut zmax, &mut best, &frame, dn, len, keep,
        );
        best
    }

    #[allow(clippy::too_many_arguments)]
    fn recurse<K: Fn(&CurveHit) -> bool>(
        &self,
        cp: &[DVec3; 4],
        u0: f64,
        u1: f64,
        depth: i32,
        zmax: &mut f64,
        best: &mut Option<CurveHit>,
        frame: &[DVec3; 3],
        dn: DVec3,
        len: f64,
        keep: &K,
    ) {
        let w = |u: f64| self.width[0] as f64 + (self.width[1] as f64 - self.width[0] as f64) * u;
        // The segment's box against the ray's (x = y = 0, 0 ≤ z ≤ zmax).
        let half = 0.5 * w(u0).max(w(u1));
        let lo = cp
            .iter()
            .fold(DVec3::splat(f64::INFINITY), |a, &p| a.min(p))
            - half;
        let hi = cp
            .iter()
            .fold(DVec3::splat(f64::NEG_INFINITY), |a, &p| a.max(p))
            + half;
        if lo.x > 0.0 || hi.x < 0.0 || lo.y > 0.0 || hi.y < 0.0 || hi.z < 0.0 || lo.z > *zmax {
            return;
        }
        if depth > 0 {
            let [a, b] = split(cp);
            let um = 0.5 * (u0 + u1);
            self.recurse(&a, u0, um, depth - 1, zmax, best, frame, dn, len, keep);
            self.recurse(&b, um, u1, depth - 1, zmax, best, frame, dn, len, keep);
            return;
        }
        // The ray's point (the origin of the xy plane) beyond the start's perpendicular and
        // before the end's.
        let edge0 = (cp[1].y - cp[0].y) * -cp[0].y + cp[0].x * (cp[0].x - cp[1].x);
        if edge0 < 0.0 {
            return;
        }
        let edge1 = (cp[2].y - cp[3].y) * -cp[3].y + cp[3].x * (cp[3].x - cp[2].x);
        if edge1 < 0.0 {
            return;
        }
        let seg = glam::DVec2::new(cp[3].x - cp[0].x, cp[3].y - cp[0].y);
        let denom = seg.length_squared();
        if denom == 0.0 {
            return;
        }
        let wq = (-glam::DVec2::new(cp[0].x, cp[0].y)).dot(seg) / denom;
        let u = (u0 + (u1 - u0) * wq).clamp(u0, u1);
        let mut hit_width = w(u);
        let mut n_ribbon = DVec3::ZERO;
        if self.kind == CurveType::Ribbon {
            let (a, b) = (self.n[0].as_dvec3(), self.n[1].as_dvec3());
            let cos = a.dot(b).clamp(-1.0, 1.0);
            let theta = cos.acos();
            n_ribbon = if theta.abs() < 1e-9 {
                a
            } else {
                let s = theta.sin();
                (a * ((1.0 - u) * theta).sin() + b * (u * theta).sin()) / s
            };
            hit_width *= n_ribbon.dot(dn).abs();
        }
        let (pc, dpcdw) = bezier(cp, wq.clamp(0.0, 1.0));
        let dist2 = pc.x * pc.x + pc.y * pc.y;
        if dist2 > hit_width * hit_width * 0.25 {
            return;
        }
        if pc.z < 0.0 || pc.z > *zmax {
            return;
        }
        let dist = dist2.sqrt();
        let edge = dpcdw.x * -pc.y + pc.x * dpcdw.y;
        let v = if hit_width > 0.0 {
            if edge > 0.0 {
                0.5 + dist / hit_width
            } else {
                0.5 - dist / hit_width
            }
        } else {
            0.5
        };
        // Tangent in object space; the normal from the type.
        let to_obj = |q: DVec3| frame[0] * q.x + frame[1] * q.y + frame[2] * q.z;
        let tangent = to_obj(dpcdw).normalize_or_zero();
        let n = match self.kind {
            CurveType::Ribbon => {
                // pbrt-v4: ∂p/∂v = n × ∂p/∂u, n = ∂p/∂u × ∂p/∂v: the ribbon normal made ⊥.
                let m = n_ribbon - tangent * tangent.dot(n_ribbon);
                m.normalize_or_zero()
            }
            CurveType::Flat | CurveType::Cylinder => {
                let facing = -(dn - tangent * tangent.dot(dn));
                let facing = facing.normalize_or_zero();
                if self.kind == CurveType::Flat {
                    facing
                } else {
                    // Turned about the tangent from −90° at v = 0 to 90° at v = 1.
                    let across = tangent.cross(facing);
                    let th = (v - 0.5) * std::f64::consts::PI;
                    facing * th.cos() + across * th.sin()
                }
            }
        };
        let hit = CurveHit {
            t: pc.z / len,
            u,
            v,
            n,
        };
        if !keep(&hit) {
            return;
        }
        *zmax = pc.z;
        *best = Some(hit);
    }
}

/// The cubic Bézier control points of a uniform cubic B-spline segment with control points
/// `b` (pbrt-v4's `"bspline"` basis).
pub fn bspline_to_bezier(b: [Vec3; 4]) -> [Vec3; 4] {
    let p012 = b[0] * (1.0 / 6.0) + b[1] * (2.0 / 3.0) + b[2] * (1.0 / 6.0);
    let p123 = b[1] * (1.0 / 6.0) + b[2] * (2.0 / 3.0) + b[3] * (1.0 / 6.0);
    let p1 = b[1] * (2.0 / 3.0) + b[2] * (1.0 / 3.0);
    let p2 = b[1] * (1.0 / 3.0) + b[2] * (2.0 / 3.0);
    [p012, p1, p2, p123]
}

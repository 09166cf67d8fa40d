//! Pixel footprints of texture lookups, as pbrt-v4 estimates them for every hit (camera rays
//! and later vertices alike): `Camera::Approximate_dp_dxy` — the hit seen from the camera
//! through rays one pixel apart (the camera's smallest position and direction differentials
//! over the film), met on the hit's tangent plane, scaled by pbrt's
//! max(1/8, 1/√spp) with the scene's sample count (its `Sampler`'s `pixelsamples`, else 64:
//! the scale is fixed when the scene is built, so `--spp` does not change it) — then
//! `SurfaceInteraction::ComputeDifferentials`: ∂(u, v)/∂x, ∂(u, v)/∂y by least squares
//! against the triangle's ∂p/∂u, ∂p/∂v. MIP-mapped images and checkerboards filter over it.

use super::texture::TexCoord;
use crate::camera::Camera;
use crate::geometry::{Geometry, PrimKind, SurfaceHit};
use glam::{UVec2, Vec2, Vec3};

/// pbrt-v4's footprint scale max(1/8, 1/√spp) for `spp` samples per pixel.
pub fn spp_scale(spp: u32) -> f32 {
    (1.0 / (spp.max(1) as f32).sqrt()).max(0.125)
}

/// What a footprint needs of the camera and of the textured triangles.
#[derive(Debug)]
pub struct Footprint {
    origin: Vec3,
    /// Camera x and y axes in world space (unit).
    axes: [Vec3; 2],
    /// Smallest distance between the origins of neighbouring pixels' rays.
    dpos: f32,
    /// Smallest difference between neighbouring pixels' unit directions.
    ddir: f32,
    /// pbrt's max(1/8, 1/√spp).
    scale: f32,
    /// Per primitive: index into `derivs`, or `u32::MAX` (no filtered texture there).
    slot: Vec<u32>,
    /// ∂p/∂u, ∂p/∂v of the triangles that need them.
    derivs: Vec<[Vec3; 2]>,
}

/// pbrt-v4's triangle ∂p/∂u, ∂p/∂v (geometric, from the vertices' uvs), `None` when the uvs
/// are degenerate.
pub fn triangle_dpduv(p: [Vec3; 3], uv: [Vec2; 3]) -> Option<(Vec3, Vec3)> {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if !(det.abs() > 1e-12) {
        return None;
    }
    let inv = 1.0 / det;
    Some((
        (dp02 * duv12.y - dp12 * duv02.y) * inv,
        (dp12 * duv02.x - dp02 * duv12.x) * inv,
    ))
}

impl Footprint {
    /// The footprint model of `camera` at resolution `res` and `spp` samples per pixel for
    /// the primitives of `geometry` whose material `wanted` says filters its textures.
    pub fn new(
        camera: &Camera,
        res: UVec2,
        spp: u32,
        geometry: &Geometry,
        wanted: impl Fn(u32) -> bool,
    ) -> Self {
        // pbrt-v4's FindMinimumDifferentials, on a coarser grid.
        let (mut dpos, mut ddir) = (f32::INFINITY, f32::INFINITY);
        let n = 8;
        for j in 0..=n {
            for i in 0..=n {
                let p = Vec2::new(
                    (res.x as f32 - 1.0) * i as f32 / n as f32,
                    (res.y as f32 - 1.0) * j as f32 / n as f32,
                );
                let r = camera.generate_ray(p, res);
                for step in [Vec2::X, Vec2::Y] {
                    let q = camera.generate_ray(p + step, res);
                    let dp = (q.o - r.o).length();
                    let dd = (q.d.normalize() - r.d.normalize()).length();
                    if dp.is_finite() {
                        dpos = dpos.min(dp);
                    }
                    if dd.is_finite() {
                        ddir = ddir.min(dd);
                    }
                }
            }
        }
        let m = camera.camera_to_world.m;
        let axes = [
            m.transform_vector3(Vec3::X).normalize_or_zero(),
            m.transform_vector3(Vec3::Y).normalize_or_zero(),
        ];
        let origin = m.transform_point3(Vec3::ZERO);
        let mut slot = vec![u32::MAX; geometry.len()];
        let mut derivs = Vec::new();
        for (i, s) in slot.iter_mut().enumerate() {
            let Some(prim) = geometry.primitive(i as u32) else {
                continue;
            };
            if !wanted(prim.material) {
                continue;
            }
            let PrimKind::Triangle { mesh, v } = prim.kind else {
                continue;
            };
            let uv = match &geometry.meshes[mesh as usize].uvs {
                Some(uv) => v.map(|k| uv[k as usize]),
                None => [Vec2::ZERO, Vec2::new(1.0, 0.0), Vec2::ONE],
            };
            if let Some((du, dv)) = triangle_dpduv(prim.p, uv) {
                *s = derivs.len() as u32;
                derivs.push([du, dv]);
            }
        }
        Footprint {
            origin,
            axes,
            dpos: if dpos.is_finite() { dpos } else { 0.0 },
            ddir: if ddir.is_finite() { ddir } else { 0.0 },
            scale: spp_scale(spp),
            slot,
            derivs,
        }
    }

    /// The camera's smallest per-pixel (position, direction) differentials.
    pub fn differentials(&self) -> (f32, f32) {
        (self.dpos, self.ddir)
    }

    /// World-space ∂p/∂x, ∂p/∂y at a point `p` with normal `n` (pbrt's
    /// `Approximate_dp_dxy`, already scaled by [`spp_scale`]), `None` when the camera sees the
    /// plane edge-on or from its own position.
    pub fn dp_dxy(&self, p: Vec3, n: Vec3) -> Option<(Vec3, Vec3)> {
        let d = p - self.origin;
        let dist = d.length();
        if !(dist > 0.0) || !dist.is_finite() {
            return None;
        }
        let r = d / dist;
        let mut a = (self.axes[0] - r * r.dot(self.axes[0])).normalize_or_zero();
        if a == Vec3::ZERO {
            a = (self.axes[1] - r * r.dot(self.axes[1])).normalize_or_zero();
        }
        let b = r.cross(a);
        let meet = |o: Vec3, dir: Vec3| -> Option<Vec3> {
            let den = n.dot(dir);
            if !(den.abs() > 1e-7) {
                return None;
            }
            let t = n.dot(p - o) / den;
            Some(o + dir * t - p)
        };
        let dx = meet(self.origin + a * self.dpos, r + a * self.ddir)?;
        let dy = meet(self.origin + b * self.dpos, r + b * self.ddir)?;
        Some((dx * self.scale, dy * self.scale))
    }

    /// The hit's texture coordinates with their footprint (a point lookup where there is
    /// none: quadrics, degenerate uvs, grazing views).
    pub fn tex_coord(&self, hit: &SurfaceHit) -> TexCoord {
        let point = TexCoord::point(hit.uv);
        let Some(&s) = self.slot.get(hit.prim as usize) else {
            return point;
        };
        let Some(&[dpdu, dpdv]) = self.derivs.get(s as usize) else {
            return point;
        };
        let Some((dpdx, dpdy)) = self.dp_dxy(hit.p, hit.ng) else {
            return point;
        };
        duv_from_dp(dpdu, dpdv, dpdx, dpdy).map_or(point, |(dx, dy)| TexCoord {
            uv: hit.uv,
            duvdx: dx,
            duvdy: dy,
        })
    }
}

/// pbrt-v4's least-squares ∂(u, v)/∂x, ∂(u, v)/∂y from ∂p/∂x, ∂p/∂y (clamped to ±1e8).
pub fn duv_from_dp(dpdu: Vec3, dpdv: Vec3, dpdx: Vec3, dpdy: Vec3) -> Option<(Vec2, Vec2)> {
    let (a00, a01, a11) = (dpdu.dot(dpdu), dpdu.dot(dpdv), dpdv.dot(dpdv));
    let det = a00 * a11 - a01 * a01;
    let inv = if det != 0.0 && (1.0 / det).is_finite() {
        1.0 / det
    } else {
        return None;
    };
    let solve = |d: Vec3| {
        let (b0, b1) = (dpdu.dot(d), dpdv.dot(d));
        Vec2::new((a11 * b0 - a01 * b1) * inv, (a00 * b1 - a01 * b0) * inv)
            .clamp(Vec2::splat(-1e8), Vec2::splat(1e8))
    };
    let (dx, dy) = (solve(dpdx), solve(dpdy));
    (dx.is_finite() && dy.is_finite()).then_some((dx, dy))
}

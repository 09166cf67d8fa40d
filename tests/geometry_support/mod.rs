//! Shared by the BVH tests: random query rays and the brute-force closest hit they are judged
//! by, and the agreement of every query on every backend (the cut-out tests' answers).
#![allow(dead_code)] // Each test file uses part of this module.

use glam::{UVec2, Vec2, Vec3};
use penumbra::geometry::triangle::intersect_triangle;
use penumbra::geometry::{
    Backend, Geometry, PACKET, PrimKind, Primitive, Ray, RayQuery, SurfaceHit,
};
use penumbra::integrator::estimator::shadow_ray;
use penumbra::sampling::{PatternKind, make_pattern, uniform_sphere, uniform_triangle_point};
use penumbra::scene::Scene;

/// Uniform random rays from points in the (enlarged) scene box, a third of them finite.
pub fn random_rays(bounds: (Vec3, Vec3), n: u32, seed: u64) -> Vec<Ray> {
    let pat = make_pattern(PatternKind::Random, seed);
    let (lo, hi) = bounds;
    let ext = hi - lo;
    (0..n)
        .map(|i| {
            let px = UVec2::new(i, 0);
            let a = pat.sample_2d(px, 0, 0, 1);
            let b = pat.sample_2d(px, 1, 0, 1);
            let c = pat.sample_2d(px, 2, 0, 1);
            let o = lo - 0.1 * ext + 1.2 * ext * Vec3::new(a.x, a.y, b.x);
            let d = uniform_sphere(Vec2::new(b.y, c.x));
            let t_max = if i % 3 == 0 {
                c.y * ext.length()
            } else {
                f32::INFINITY
            };
            Ray { o, d, t_max }
        })
        .collect()
}

/// Closest t over every primitive (triangles and quadrics), tested one by one.
pub fn brute_force_t(g: &Geometry, ray: &Ray) -> Option<f32> {
    (0..g.len() as u32)
        .filter_map(|id| g.primitive(id))
        .filter_map(|p| match p.kind {
            PrimKind::Triangle { .. } => {
                intersect_triangle(ray.o, ray.d, ray.t_max, p.p).map(|(t, ..)| t)
            }
            PrimKind::Quadric(q) => g.quadrics[q as usize].intersect_t(ray.o, ray.d, ray.t_max),
        })
        .min_by(f32::total_cmp)
}

/// Triangle `i` of mesh 0 with vertices `p` (material 0, no light).
pub fn triangle(i: u32, p: [Vec3; 3]) -> Primitive {
    Primitive {
        p,
        kind: PrimKind::Triangle {
            mesh: 0,
            v: [i, i, i],
        },
        material: 0,
        light: u32::MAX,
    }
}

/// `n` small random triangles in the box [0, 10]³ (seed 5 of the random pattern).
pub fn triangle_soup(n: u32) -> Vec<Primitive> {
    let pat = make_pattern(PatternKind::Random, 5);
    (0..n)
        .map(|i| {
            let px = UVec2::new(i, 1);
            let p = |d| {
                let a = pat.sample_2d(px, d, 0, 1);
                let b = pat.sample_2d(px, d + 1, 0, 1);
                Vec3::new(a.x, a.y, b.x) * 10.0
            };
            let p0 = p(0);
            let (p1, p2) = (p0 + (p(2) - p0) * 0.2, p0 + (p(4) - p0) * 0.2);
            triangle(i, [p0, p1, p2])
        })
        .collect()
}

/// A soup of `tris` random triangles plus 20 spheres of `sphere_radius` and 20 disks of
/// `disk_radius` at random places in the same box.
pub fn soup_with_quadrics(tris: u32, sphere_radius: f32, disk_radius: f32) -> Geometry {
    use penumbra::geometry::{MeshShading, Quadric, QuadricKind, Transform};
    let pat = make_pattern(PatternKind::Random, 5);
    let mut prims = triangle_soup(tris);
    let mut quadrics = Vec::new();
    for i in 0..40u32 {
        let c = pat.sample_2d(UVec2::new(i, 2), 0, 0, 1);
        let h = pat.sample_2d(UVec2::new(i, 2), 1, 0, 1);
        let kind = if i % 2 == 0 {
            QuadricKind::Sphere {
                radius: sphere_radius,
            }
        } else {
            QuadricKind::Disk {
                height: 0.0,
                radius: disk_radius,
            }
        };
        quadrics.push(Quadric {
            kind,
            to_world: Transform::translate(Vec3::new(c.x, c.y, h.x) * 10.0),
            flip: false,
            alpha: None,
        });
        prims.push(Primitive {
            p: [Vec3::ZERO; 3],
            kind: PrimKind::Quadric(i),
            material: 1,
            light: u32::MAX,
        });
    }
    Geometry::new(prims, vec![MeshShading::default()], quadrics)
}

/// Built-in scene `name` (`triangles` for the procedural meshes of `dense`).
pub fn builtin_scene(name: &str, triangles: Option<u32>) -> Scene {
    let opts = penumbra::scene::load::LoadOptions {
        builtin: penumbra::scene::builtin::BuiltinOptions {
            triangles,
            ..Default::default()
        },
        ..Default::default()
    };
    penumbra::scene::load::load(name, &opts)
        .expect("built-in scene")
        .scene
}

/// 16 jittered camera rays per pixel (one packet each, as the renderer makes them) for
/// `pixels` pixels spread over a 64² image of `scene`, jittered by pattern seed `seed`.
#[allow(dead_code)] // As above.
pub fn camera_packet_rays(scene: &Scene, pixels: u32, seed: u64) -> Vec<Ray> {
    let res = UVec2::new(64, 64);
    let cam = scene.camera.rays(res);
    let pat = make_pattern(PatternKind::Random, seed);
    let mut rays = Vec::new();
    for k in 0..pixels {
        let px = UVec2::new((k * 37) % res.x, (k * 101 / res.x) % res.y);
        for s in 0..penumbra::geometry::PACKET as u32 {
            let j = pat.sample_2d(px, 0, s, penumbra::geometry::PACKET as u32);
            rays.push(cam.generate(px.as_vec2() + j));
        }
    }
    rays
}

/// For each closest hit of `rays` in `scene`: a shadow ray (as the integrator makes them) to a
/// random point of an emitter triangle, and with `reflected` also a ray leaving the surface
/// exactly at the hit point; patterns of seed `seed`.
#[allow(dead_code)] // As above.
pub fn secondary_rays(scene: &Scene, rays: &[Ray], reflected: bool, seed: u64) -> Vec<Ray> {
    let (g, em) = (&scene.geometry, &scene.emitters);
    let pat = make_pattern(PatternKind::Random, seed);
    let mut out = Vec::new();
    for (i, ray) in rays.iter().enumerate() {
        let Some(h) = g.intersect(ray) else {
            continue;
        };
        let Some(p) = em.primitive((i % em.len().max(1)) as u32) else {
            continue;
        };
        let u = pat.sample_2d(UVec2::new(i as u32, 0), 0, 0, 1);
        out.push(shadow_ray(
            &h,
            uniform_triangle_point(u, p.p[0], p.p[1], p.p[2]),
        ));
        if reflected {
            out.push(Ray::new(h.p, -ray.d.reflect(h.ng)));
        }
    }
    out
}

/// `packets` coherent packets from random points of `g`'s box aimed at shared vertices and
/// edge midpoints of its primitives: rays with exact ties between primitives at equal t.
#[allow(dead_code)] // As above.
pub fn tie_rays(g: &Geometry, packets: u32, seed: u64) -> Vec<Ray> {
    let pat = make_pattern(PatternKind::Random, seed);
    let (lo, hi) = g.bounds();
    let mut aimed = Vec::new();
    for k in 0..packets {
        let a = pat.sample_2d(UVec2::new(k, 0), 0, 0, 1);
        let b = pat.sample_2d(UVec2::new(k, 0), 1, 0, 1);
        let o = lo + (hi - lo) * Vec3::new(a.x, a.y, b.x);
        for s in 0..penumbra::geometry::PACKET as u32 {
            let Some(p) = g.primitive((k * 131 + s * 7) % g.len().max(1) as u32) else {
                continue;
            };
            let target = if s % 2 == 0 {
                p.p[0]
            } else {
                (p.p[0] + p.p[1]) * 0.5
            };
            aimed.push(Ray::new(o, target - o));
        }
    }
    aimed
}

/// Per ray: the closest hit of the geometry `build` makes for each backend, with `name` (a
/// name of the hit primitive that does not depend on the backend's leaf order), checked equal
/// across every query and backend: any-hit ⇔ closest-hit, 16-ray packets = one-ray (t to the
/// bit, primitive, uv, point), and the same (name, t) from all three BVHs.
pub fn agreed_hits(
    build: impl Fn(Backend) -> Geometry,
    name: impl Fn(&Geometry, u32) -> u32,
    rays: &[Ray],
) -> Vec<Option<(u32, SurfaceHit)>> {
    let mut first: Option<Vec<Option<(u32, SurfaceHit)>>> = None;
    for backend in [Backend::Wide, Backend::Own, Backend::Obvhs] {
        let g = build(backend);
        let mut got = Vec::with_capacity(rays.len());
        for chunk in rays.chunks(PACKET) {
            let mut pk = [chunk[0]; PACKET];
            pk[..chunk.len()].copy_from_slice(chunk);
            let active = (1u32 << chunk.len()) - 1;
            let mut out = [None; PACKET];
            g.intersect_packet(&pk, active, &mut out);
            let blocked = g.occluded_packet(&pk, active);
            for (i, r) in chunk.iter().enumerate() {
                let h = g.intersect(r);
                assert_eq!(
                    h.is_some(),
                    g.occluded(r),
                    "{backend:?}: closest and any-hit disagree on {r:?}"
                );
                assert_eq!(
                    blocked >> i & 1 == 1,
                    h.is_some(),
                    "{backend:?}: any-hit packet"
                );
                match (&h, &out[i]) {
                    (Some(a), Some(b)) => assert!(
                        a.t.to_bits() == b.t.to_bits()
                            && a.prim == b.prim
                            && a.uv == b.uv
                            && a.p == b.p,
                        "{backend:?}: packet hit {b:?} != one-ray hit {a:?}"
                    ),
                    (None, None) => {}
                    _ => panic!("{backend:?}: packet {:?} vs one-ray {h:?}", out[i]),
                }
                got.push(h.map(|h| (name(&g, h.prim), h)));
            }
        }
        match &first {
            None => first = Some(got),
            Some(f) => {
                let same = f.iter().zip(&got).all(|(a, b)| match (a, b) {
                    (Some((qa, a)), Some((qb, b))) => qa == qb && a.t.to_bits() == b.t.to_bits(),
                    (None, None) => true,
                    _ => false,
                });
                assert!(same, "{backend:?} differs from the wide BVH");
            }
        }
    }
    first.expect("three backends")
}

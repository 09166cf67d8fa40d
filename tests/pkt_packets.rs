//! Packet queries (`intersect_packet`, `occluded_packet`) must answer every active lane exactly
//! like the scalar query on the same ray (t bits, primitive, point, normals, uv) and leave
//! inactive lanes empty: coherent camera packets, incoherent random rays, shadow rays to points
//! on the light, partial masks, rays leaving surfaces, on every backend and on cornell, a dense
//! mesh (rays aimed at shared vertices and edges: exact ties), triangles with quadrics and an
//! empty scene; and rays leaving a lone surface must miss it on every path (the self-hit
//! rejection is part of the test that all paths share).

mod geometry_support;

use geometry_support::{
    brute_force_t, builtin_scene, camera_packet_rays, random_rays, secondary_rays,
    soup_with_quadrics, tie_rays, triangle_soup,
};
use glam::{UVec2, Vec2, Vec3};
use penumbra::geometry::{
    Backend, Geometry, MeshShading, PACKET, PrimKind, Primitive, QuadricKind, Ray, RayQuery,
    SurfaceHit,
};
use penumbra::integrator::estimator::shadow_ray;
use penumbra::isa::Isa;
use penumbra::sampling::{
    PatternKind, concentric_disk, make_pattern, uniform_sphere, uniform_triangle_point,
};

/// Active masks cycled through the packets: full, partial, single lanes.
const MASKS: [u32; 5] = [0xffff, 0xa5c3, 0x0001, 0x8000, 0x7ffe];

/// Every vector backend of the packet kernels (those this CPU lacks resolve to a narrower one,
/// so they are still run, and the supported ones are checked: see `isas_resolve`).
const ISAS: [Isa; 3] = [Isa::Portable, Isa::Avx2, Isa::Avx512];

/// Compares packet and scalar queries over `rays` in packets of 16 on every vector backend;
/// returns the number of hits.
fn check(g: &Geometry, rays: &[Ray]) -> u32 {
    ISAS.iter()
        .map(|&isa| check_on(g, rays, isa))
        .max()
        .unwrap_or(0)
}

/// [`check`] on one backend.
fn check_on(g: &Geometry, rays: &[Ray], isa: Isa) -> u32 {
    let mut hits = 0;
    for (k, chunk) in rays.chunks_exact(PACKET).enumerate() {
        let pk: [Ray; PACKET] = std::array::from_fn(|i| chunk[i]);
        let active = MASKS[k % MASKS.len()];
        let mut out = [None; PACKET];
        g.intersect_packet_on(isa, &pk, active, &mut out);
        let blocked = g.occluded_packet_on(isa, &pk, active);
        for (i, ray) in pk.iter().enumerate() {
            let on = active & (1 << i) != 0;
            let want = if on { g.intersect(ray) } else { None };
            let key = |h: &Option<penumbra::geometry::SurfaceHit>| {
                h.map(|h| {
                    (
                        h.t.to_bits(),
                        h.prim,
                        h.p.to_array().map(f32::to_bits),
                        h.ng.to_array().map(f32::to_bits),
                        h.ns.to_array().map(f32::to_bits),
                        h.uv.to_array().map(f32::to_bits),
                        h.p_error.to_bits(),
                        (h.material, h.light),
                    )
                })
            };
            assert_eq!(
                key(&out[i]),
                key(&want),
                "lane {i} of packet {k} on {isa:?}: {ray:?}"
            );
            hits += want.is_some() as u32;
            let occluded = on && g.occluded(ray);
            assert_eq!(
                blocked & (1 << i) != 0,
                occluded,
                "any-hit lane {i}: {ray:?}"
            );
        }
    }
    hits
}

#[test]
fn packets_match_scalar_queries_on_cornell_for_every_backend() {
    let scene = builtin_scene("cornell", None);
    let cam = camera_packet_rays(&scene, 400, 11);
    let shadow = secondary_rays(&scene, &cam, true, 12);
    let random = random_rays(scene.geometry.bounds(), 16 * 400, 3);
    for backend in [Backend::Wide, Backend::Own, Backend::Obvhs] {
        let g = scene.geometry.rebuild(backend);
        let hits = check(&g, &cam);
        assert!(hits > 16 * 400 / 3, "{backend:?}: {hits} camera hits");
        assert!(check(&g, &shadow) > 1000, "{backend:?} secondary");
        assert!(check(&g, &random) > 1000, "{backend:?} random");
    }
    // The emitter-only geometry (a single leaf).
    assert!(check(&scene.emitters, &cam) + check(&scene.emitters, &random) > 0);
}

#[test]
fn packets_match_scalar_queries_on_a_dense_mesh_with_ties() {
    let scene = builtin_scene("dense", Some(20_000));
    let g = &scene.geometry;
    let cam = camera_packet_rays(&scene, 200, 11);
    assert!(check(g, &cam) > 1000);
    assert!(check(g, &secondary_rays(&scene, &cam, true, 12)) > 100);
    // Coherent packets aimed at shared vertices and edge midpoints: exact ties on equal t.
    let aimed = tie_rays(g, 400, 9);
    assert!(check(g, &aimed) > 1000);
    let own = g.rebuild(Backend::Own);
    assert!(check(&own, &aimed[..16 * 50]) > 100);
}

#[test]
fn packets_match_scalar_queries_with_spheres_and_disks() {
    let g = soup_with_quadrics(2000, 0.6, 0.8);
    let pat = make_pattern(PatternKind::Random, 5);
    // Coherent packets: 16 nearby directions from one origin.
    let mut coherent = Vec::new();
    let (lo, hi) = g.bounds();
    for k in 0..300u32 {
        let a = pat.sample_2d(UVec2::new(k, 3), 0, 0, 1);
        let b = pat.sample_2d(UVec2::new(k, 3), 1, 0, 1);
        let o = lo + (hi - lo) * Vec3::new(a.x, a.y, b.x);
        let target = lo + (hi - lo) * Vec3::new(b.y, a.y, a.x);
        for s in 0..PACKET as u32 {
            let j = pat.sample_2d(UVec2::new(k, 4), 0, s, PACKET as u32) - Vec2::splat(0.5);
            coherent.push(Ray::new(o, target - o + Vec3::new(j.x, j.y, 0.0)));
        }
    }
    let random = random_rays(g.bounds(), 16 * 300, 7);
    for ray in &coherent[..16 * 20] {
        assert_eq!(g.intersect(ray).map(|h| h.t), brute_force_t(&g, ray));
    }
    for backend in [Backend::Wide, Backend::Own] {
        let g = g.rebuild(backend);
        assert!(check(&g, &coherent) > 500, "{backend:?} coherent");
        assert!(check(&g, &random) > 500, "{backend:?} random");
    }
}

#[test]
fn packets_on_an_empty_scene_miss() {
    let g = Geometry::new(Vec::new(), Vec::new(), Vec::new());
    let rays = random_rays((Vec3::ZERO, Vec3::ONE), 16 * 4, 1);
    assert_eq!(check(&g, &rays), 0);
}

#[test]
fn packets_match_scalar_queries_on_duplicated_triangles() {
    // Every triangle twice: each hit ties on exactly equal t, which the packet traversal must
    // resolve like the scalar one (its first-found primitive).
    let soup = triangle_soup(1500);
    let prims: Vec<Primitive> = soup.iter().chain(soup.iter()).copied().collect();
    let g = Geometry::new(prims, vec![MeshShading::default()], Vec::new());
    let (lo, hi) = g.bounds();
    let pat = make_pattern(PatternKind::Random, 13);
    let mut rays = Vec::new();
    for k in 0..300u32 {
        let a = pat.sample_2d(UVec2::new(k, 5), 0, 0, 1);
        let o = lo - (hi - lo) * 0.2 + (hi - lo) * Vec3::new(a.x, a.y, 0.0) * 0.1;
        let Some(p) = g.primitive(k % g.len() as u32) else {
            continue;
        };
        for s in 0..PACKET as u32 {
            let j = pat.sample_2d(UVec2::new(k, 6), 0, s, PACKET as u32) * 0.2;
            let target = p.p[0] + (p.p[1] - p.p[0]) * j.x + (p.p[2] - p.p[0]) * j.y;
            rays.push(Ray::new(o, target - o));
        }
    }
    assert!(check(&g, &rays) > 2000);
}

#[test]
fn packets_match_scalar_queries_on_a_single_leaf() {
    // At most four primitives make a one-leaf tree (the emitter-only geometry of most scenes),
    // whose box the packet tests on vectors before the scalar queries: rays around it, many
    // missing, some grazing its box, in coherent packets (one origin) and incoherent ones.
    let g = Geometry::new(triangle_soup(3), vec![MeshShading::default()], Vec::new());
    let (lo, hi) = g.bounds();
    let ext = hi - lo;
    let pat = make_pattern(PatternKind::Random, 17);
    let mut rays = random_rays((lo - ext, hi + ext), 16 * 40, 3);
    for k in 0..200u32 {
        let a = pat.sample_2d(UVec2::new(k, 1), 0, 0, 1);
        let o = lo - ext + ext * 3.0 * Vec3::new(a.x, a.y, 0.0);
        let Some(p) = g.primitive(k % g.len() as u32) else {
            continue;
        };
        for s in 0..PACKET as u32 {
            // Barycentric-like offsets in [-0.2, 1.2]²: inside the triangle or near it.
            let j = pat.sample_2d(UVec2::new(k, 2), 0, s, PACKET as u32) * 1.4 - Vec2::splat(0.2);
            let target = p.p[0] + (p.p[1] - p.p[0]) * j.x + (p.p[2] - p.p[0]) * j.y;
            rays.push(Ray::new(o, target - o));
        }
    }
    let hits = check(&g, &rays);
    assert!(hits > 100 && hits < rays.len() as u32 / 2, "{hits} hits");
}

/// `n` points of the lone surface `g` seen from `eye` (the closest hits of rays toward random
/// points of its primitives), each with 16 directions drawn uniformly on the sphere (pattern
/// seed `seed`).
fn surface_points(g: &Geometry, eye: Vec3, n: u32, seed: u64) -> Vec<(SurfaceHit, [Vec3; PACKET])> {
    let pat = make_pattern(PatternKind::Random, seed);
    let mut out = Vec::new();
    for k in 0..n {
        let u = pat.sample_2d(UVec2::new(k, 7), 0, 0, 1);
        let Some(p) = g.primitive(k % g.len() as u32) else {
            continue;
        };
        let target = match p.kind {
            PrimKind::Triangle { .. } => uniform_triangle_point(u, p.p[0], p.p[1], p.p[2]),
            PrimKind::Quadric(q) => {
                // A point of the disk z = height, radius r of object space.
                let q = &g.quadrics[q as usize];
                let QuadricKind::Disk { height, radius } = q.kind else {
                    unreachable!("only disks here")
                };
                let d = concentric_disk(u) * (0.9 * radius);
                q.to_world.point(Vec3::new(d.x, d.y, height))
            }
        };
        let Some(h) = g.intersect(&Ray::new(eye, target - eye)) else {
            continue;
        };
        let w = std::array::from_fn(|s| {
            uniform_sphere(pat.sample_2d(UVec2::new(k, 8), 0, s as u32, PACKET as u32))
        });
        out.push((h, w));
    }
    assert!(
        out.len() as u32 > n * 9 / 10,
        "{} of {n} points found",
        out.len()
    );
    out
}

/// Asserts that none of `rays` (packets of 16) hits anything in `g`, by the scalar queries
/// and by the packet queries on every vector backend.
fn assert_clear(g: &Geometry, rays: &[[Ray; PACKET]], what: &str) {
    for pk in rays {
        for ray in pk {
            assert!(
                g.intersect(ray).is_none(),
                "{what}: {ray:?} hits {:?}",
                g.intersect(ray)
            );
            assert!(!g.occluded(ray), "{what}: {ray:?} occluded");
        }
        for isa in ISAS {
            let mut out = [None; PACKET];
            g.intersect_packet_on(isa, pk, 0xffff, &mut out);
            assert!(
                out.iter().all(Option::is_none),
                "{what} on {isa:?}: {out:?}"
            );
            assert_eq!(
                g.occluded_packet_on(isa, pk, 0xffff),
                0,
                "{what} on {isa:?}"
            );
        }
    }
}

#[test]
fn rays_leaving_a_lone_surface_hit_nothing_on_any_path() {
    // A ray spawned at a surface must not hit it, nor its coplanar neighbours, whatever the
    // direction: on the 19×19 floors at y = 0 (where the hit points' error bound, and
    // so the spawn offset, is exactly zero) and y = 0.37, as two triangles (a single BVH leaf:
    // the 4-wide one-ray test and the 16-lane any-hit kernel) and as a 12×12 grid (several
    // leaves: the 16-lane closest-hit kernel), on the BVH2 too (the one-ray test), and on a
    // tilted quad and a disk far from the origin.
    let quad = |corner: Vec3, e1: Vec3, e2: Vec3, k: u32| {
        let mut prims = Vec::new();
        let at = |i: u32, j: u32| corner + e1 * (i as f32 / k as f32) + e2 * (j as f32 / k as f32);
        for j in 0..k {
            for i in 0..k {
                let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1));
                prims.push(geometry_support::triangle(0, [a, b, c]));
                prims.push(geometry_support::triangle(0, [a, c, d]));
            }
        }
        Geometry::new(prims, vec![MeshShading::default()], Vec::new())
    };
    let (x, z) = (Vec3::X * 19.0, Vec3::Z * 19.0);
    let tilted_e1 = Vec3::new(3.0, 1.0, -2.0) * 2.0;
    let tilted_e2 = tilted_e1.cross(Vec3::new(0.3, 1.0, 0.2)).normalize() * 11.0;
    let disk = {
        use penumbra::geometry::{Quadric, Transform};
        let m = glam::Mat4::from_rotation_translation(
            glam::Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 0.7),
            Vec3::new(130.0, -40.0, 75.0),
        );
        let q = Quadric {
            kind: QuadricKind::Disk {
                height: 0.0,
                radius: 9.0,
            },
            to_world: Transform::new(m).unwrap(),
            flip: false,
            alpha: None,
        };
        let p = Primitive {
            p: [Vec3::ZERO; 3],
            kind: PrimKind::Quadric(0),
            material: 0,
            light: u32::MAX,
        };
        Geometry::new(vec![p], vec![MeshShading::default()], vec![q])
    };
    // (name, surface, whether its hit points lie exactly on it)
    let cases = [
        (
            "y = 0 quad",
            quad(Vec3::new(-9.5, 0.0, -9.5), x, z, 1),
            true,
        ),
        (
            "y = 0 grid",
            quad(Vec3::new(-9.5, 0.0, -9.5), x, z, 12),
            true,
        ),
        (
            "y = 0.37 quad",
            quad(Vec3::new(-9.5, 0.37, -9.5), x, z, 1),
            false,
        ),
        (
            "y = 0.37 grid",
            quad(Vec3::new(-9.5, 0.37, -9.5), x, z, 12),
            false,
        ),
        (
            "tilted grid",
            quad(Vec3::new(310.0, -20.0, 45.0), tilted_e1, tilted_e2, 6),
            false,
        ),
        ("tilted disk", disk, false),
    ];
    for (name, g, exact_plane) in cases {
        let (lo, hi) = g.bounds();
        let eye = (lo + hi) * 0.5 + Vec3::new(0.3, 1.0, 0.2).normalize() * (hi - lo).length();
        for backend in [Backend::Wide, Backend::Own] {
            let g = g.rebuild(backend);
            let points = surface_points(&g, eye, 120, 21);
            let mut spawned = Vec::new();
            let mut from_p = Vec::new();
            let mut to = Vec::new();
            for (h, w) in &points {
                spawned.push(w.map(|w| Ray::new(h.spawn_origin(w), w)));
                // Straight from the hit point: exactly on the plane y = 0 (elsewhere the
                // rounded point may lie a little behind the plane, and the ray truly cross it).
                from_p.push(w.map(|w| Ray::new(h.p, w)));
                to.push(w.map(|w| shadow_ray(h, h.p + w * 50.0)));
            }
            let what = format!("{name} on {backend:?}");
            assert_clear(&g, &spawned, &format!("{what}, spawned rays"));
            assert_clear(&g, &to, &format!("{what}, shadow rays"));
            if exact_plane {
                assert_clear(&g, &from_p, &format!("{what}, rays from the hit points"));
            }
        }
    }
}

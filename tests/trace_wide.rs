//! The 4-wide BVH backend must answer every ray query exactly like a brute-force loop over all
//! primitives (same closest t, same hit record up to ties on equal t) and like the own BVH2, on
//! the Cornell box, a random triangle soup mixed with spheres and disks, and the
//! shared-edge/vertex-heavy `dense` mesh (watertightness through the packet test).

mod geometry_support;

use geometry_support::{brute_force_t, random_rays, soup_with_quadrics, triangle};
use glam::{UVec2, Vec3};
use penumbra::geometry::{Backend, Geometry, MeshShading, Primitive, Ray, RayQuery};
use penumbra::sampling::{PatternKind, make_pattern};

/// Checks the wide backend ray by ray; returns (hits, ties on equal t with a different prim).
fn check(g: &Geometry, rays: &[Ray], brute: bool) -> (u32, u32) {
    let wide = g.rebuild(Backend::Wide);
    let own = g.rebuild(Backend::Own);
    assert_eq!(wide.backend(), Some(Backend::Wide));
    let (mut hits, mut ties) = (0, 0);
    for ray in rays {
        let (w, o) = (wide.intersect(ray), own.intersect(ray));
        assert_eq!(
            w.map(|h| h.t),
            o.map(|h| h.t),
            "wide vs own BVH t for {ray:?}"
        );
        if brute {
            assert_eq!(
                w.map(|h| h.t),
                brute_force_t(&wide, ray),
                "brute force {ray:?}"
            );
        }
        if let (Some(w), Some(o)) = (w, o) {
            hits += 1;
            let same = wide.primitive(w.prim).map(|p| (p.p, p.material))
                == own.primitive(o.prim).map(|p| (p.p, p.material));
            if same {
                // Same primitive, same t: the whole record must agree bit for bit.
                assert_eq!(
                    (w.p, w.ng, w.ns, w.uv, w.p_error, w.light),
                    (o.p, o.ng, o.ns, o.uv, o.p_error, o.light),
                    "hit record of {ray:?}"
                );
            } else {
                ties += 1;
            }
        }
        assert_eq!(
            wide.occluded(ray),
            w.is_some(),
            "any-hit vs closest {ray:?}"
        );
    }
    (hits, ties)
}

#[test]
fn wide_matches_brute_force_on_cornell() {
    let g = penumbra::scene::load::load("cornell", &Default::default())
        .expect("cornell")
        .scene
        .geometry;
    let rays = random_rays(g.bounds(), 50_000, 3);
    let (hits, ties) = check(&g, &rays, true);
    eprintln!("cornell: {hits} hits, {ties} ties");
    assert!(hits > 20_000 && ties < 50);
}

#[test]
fn wide_matches_brute_force_on_triangles_spheres_and_disks() {
    let g = soup_with_quadrics(3000, 0.3, 0.5);
    let rays = random_rays(g.bounds(), 30_000, 7);
    let (hits, ties) = check(&g, &rays, true);
    eprintln!("soup: {hits} hits, {ties} ties");
    assert!(hits > 3_000 && ties < 30);
}

#[test]
fn wide_matches_own_bvh_on_a_dense_mesh() {
    let opts = penumbra::scene::load::LoadOptions {
        builtin: penumbra::scene::builtin::BuiltinOptions {
            triangles: Some(20_000),
            ..Default::default()
        },
        ..Default::default()
    };
    let g = penumbra::scene::load::load("dense", &opts)
        .expect("dense")
        .scene
        .geometry;
    // Rays aimed at mesh vertices and edge midpoints: the packet test's exact-zero edge
    // fallback must keep the mesh watertight there.
    let pat = make_pattern(PatternKind::Random, 9);
    let (lo, hi) = g.bounds();
    let mut aimed = Vec::new();
    for i in 0..20_000u32 {
        let Some(p) = g.primitive(i % g.len() as u32) else {
            continue;
        };
        let a = pat.sample_2d(UVec2::new(i, 0), 0, 0, 1);
        let b = pat.sample_2d(UVec2::new(i, 0), 1, 0, 1);
        let o = lo + (hi - lo) * Vec3::new(a.x, a.y, b.x);
        let target = if i % 2 == 0 {
            p.p[0]
        } else {
            (p.p[0] + p.p[1]) * 0.5
        };
        aimed.push(Ray::new(o, target - o));
    }
    let (hits, _) = check(&g, &aimed, false);
    assert!(
        hits > 19_000,
        "{hits} of 20000 vertex/edge rays hit (cracks?)"
    );
}

#[test]
fn wide_handles_coincident_and_degenerate_triangles() {
    // 5000 copies of one triangle plus zero-area slivers: PLOC may build a deep tree here (then
    // the binned-SAH fallback is used); either way every answer must match brute force.
    let tri = [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
    ];
    let mut prims: Vec<Primitive> = (0..5000u32).map(|i| triangle(i, tri)).collect();
    for i in 0..100u32 {
        let x = i as f32 * 0.01;
        prims.push(triangle(
            i,
            [
                Vec3::new(x, 0.0, 0.5),
                Vec3::new(x, 1.0, 0.5),
                Vec3::new(x, 0.5, 0.5),
            ],
        ));
    }
    let g = Geometry::new(prims, vec![MeshShading::default()], Vec::new());
    let rays = random_rays(g.bounds(), 5_000, 13);
    let (hits, _) = check(&g, &rays, true);
    assert!(hits > 100, "{hits} hits");
}

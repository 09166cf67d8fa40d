//! Both BVH backends must answer every ray query identically (closest hit t and primitive,
//! any-hit), on the Cornell box and on a random triangle soup. The own BVH must also equal a
//! brute-force loop over all primitives exactly; obvhs may miss rare hits a few ulps from the
//! ray origin (its box test is not conservative there), so it only has to agree on ≥ 99.9%.

mod geometry_support;

use geometry_support::{brute_force_t, random_rays, triangle_soup};
use penumbra::geometry::{Backend, Geometry, MeshShading, PrimKind, RayQuery};

/// A backend-independent name of a primitive: (mesh, vertex indices) or the quadric index.
fn identity(g: &Geometry, id: u32) -> (u32, [u32; 3]) {
    match g.primitive(id).map(|p| p.kind) {
        Some(PrimKind::Triangle { mesh, v }) => (mesh, v),
        Some(PrimKind::Quadric(q)) => (u32::MAX, [q; 3]),
        None => panic!("hit reports primitive {id} out of range"),
    }
}

fn check_agreement(g: &Geometry, n: u32) {
    let own = g.rebuild(Backend::Own);
    let obvhs = g.rebuild(Backend::Obvhs);
    assert_eq!(own.backend(), Some(Backend::Own));
    assert_eq!(obvhs.backend(), Some(Backend::Obvhs));
    let (mut hits, mut ties, mut blocked, mut differ) = (0u32, 0u32, 0u32, 0u32);
    for ray in random_rays(g.bounds(), n, 11) {
        let (a, b) = (own.intersect(&ray), obvhs.intersect(&ray));
        if let Some(a) = &a {
            assert_eq!(
                Some(a.t),
                brute_force_t(&own, &ray),
                "own BVH t for {ray:?}"
            );
        } else {
            assert_eq!(brute_force_t(&own, &ray), None, "own BVH missed {ray:?}");
        }
        match (&a, &b) {
            (None, None) => {}
            (Some(a), Some(b)) if a.t == b.t => {
                hits += 1;
                if identity(&own, a.prim) != identity(&obvhs, b.prim) {
                    // Equal t on two primitives (a shared edge): either answer is right.
                    ties += 1;
                }
            }
            _ => differ += 1,
        }
        let occ = own.occluded(&ray);
        assert_eq!(
            occ,
            a.is_some(),
            "any-hit disagrees with closest hit for {ray:?}"
        );
        differ += (occ != obvhs.occluded(&ray)) as u32;
        blocked += occ as u32;
    }
    eprintln!(
        "{n} rays: {hits} hits ({ties} ties on equal t), {blocked} blocked, {differ} obvhs differences"
    );
    assert!(hits > n / 10 && ties < n / 1000 && differ < n / 1000);
}

#[test]
fn backends_agree_on_cornell() {
    let loaded = penumbra::scene::load::load("cornell", &Default::default()).expect("cornell");
    check_agreement(&loaded.scene.geometry, 100_000);
}

#[test]
fn backends_agree_on_a_triangle_soup() {
    let prims = triangle_soup(2000);
    let g = Geometry::new(prims, vec![MeshShading::default()], Vec::new());
    check_agreement(&g, 100_000);
}

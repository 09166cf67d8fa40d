//! The `*_cols` packet queries: the hit records equal the plain queries' and, for every lane
//! with a hit, the structure-of-arrays columns hold exactly that record's point, normals and
//! error bound (bit for bit), on every vector backend this CPU runs: cornell camera rays
//! (vertex normals), dense-mesh rays aimed at shared vertices (exact ties, redone by the
//! scalar query; no vertex normals), triangles with quadrics, the single-leaf emitter geometry.

mod geometry_support;

use geometry_support::{
    brute_force_t, builtin_scene, camera_packet_rays, random_rays, soup_with_quadrics, tie_rays,
};
use glam::Vec3;
use penumbra::geometry::RayQuery;
use penumbra::geometry::{Geometry, HitColumns, PACKET, Ray, RayPacket, SurfaceHit};
use penumbra::isa::Isa;

/// Active masks cycled through the packets: full, partial, single lanes, none.
const MASKS: [u32; 6] = [0xffff, 0xa5c3, 0x0001, 0x8000, 0x7ffe, 0];

/// Every field of a hit record, as bits.
fn bits(h: &Option<SurfaceHit>) -> Option<[u32; 16]> {
    h.map(|h| {
        let f = |v: Vec3| v.to_array().map(f32::to_bits);
        let (p, ng, ns) = (f(h.p), f(h.ng), f(h.ns));
        [
            h.t.to_bits(),
            p[0],
            p[1],
            p[2],
            ng[0],
            ng[1],
            ng[2],
            ns[0],
            ns[1],
            ns[2],
            h.uv.x.to_bits(),
            h.uv.y.to_bits(),
            h.p_error.to_bits(),
            h.prim,
            h.material,
            h.light,
        ]
    })
}

/// Lane i of the columns as (p, ng, ns, p_error) bits.
fn lane(c: &HitColumns, i: usize) -> [u32; 10] {
    let a = |v: &[[f32; PACKET]; 3]| [v[0][i], v[1][i], v[2][i]].map(f32::to_bits);
    let (p, ng, ns) = (a(&c.p), a(&c.ng), a(&c.ns));
    [
        p[0],
        p[1],
        p[2],
        ng[0],
        ng[1],
        ng[2],
        ns[0],
        ns[1],
        ns[2],
        c.p_error[i].to_bits(),
    ]
}

/// Columns holding a NaN pattern, so that a lane left unwritten cannot pass by chance.
fn stale() -> HitColumns {
    let x = f32::from_bits(0x7fc0_dead);
    HitColumns {
        p: [[x; PACKET]; 3],
        ng: [[x; PACKET]; 3],
        ns: [[x; PACKET]; 3],
        p_error: [x; PACKET],
    }
}

/// Checks both `*_cols` forms against `intersect_packet_on` over `rays` in packets of 16 on
/// every backend; returns the number of hits (on the last backend).
fn check(g: &Geometry, rays: &[Ray]) -> u32 {
    let mut hits = 0;
    for isa in Isa::available() {
        hits = 0;
        // One set of columns reused across packets (as a caller would): stale lanes must be
        // overwritten where there is a hit.
        let (mut ca, mut cs) = (stale(), stale());
        for (k, chunk) in rays.chunks_exact(PACKET).enumerate() {
            let aos: [Ray; PACKET] = std::array::from_fn(|i| chunk[i]);
            let soa = RayPacket::from_rays(&aos);
            let active = MASKS[k % MASKS.len()];
            let (mut want, mut a, mut s) = ([None; PACKET], [None; PACKET], [None; PACKET]);
            g.intersect_packet_on(isa, &aos, active, &mut want);
            g.intersect_packet_cols_on(isa, &aos, active, &mut a, &mut ca);
            g.intersect_packet_cols_on(isa, &soa, active, &mut s, &mut cs);
            for i in 0..PACKET {
                let w = bits(&want[i]);
                assert_eq!(bits(&a[i]), w, "rows, lane {i} of packet {k} on {isa:?}");
                assert_eq!(
                    bits(&s[i]),
                    w,
                    "soa rows, lane {i} of packet {k} on {isa:?}"
                );
                if let Some(w) = w {
                    // p, ng, ns (fields 1..10) and p_error (field 12).
                    let cols: [u32; 10] =
                        std::array::from_fn(|j| w[if j < 9 { 1 + j } else { 12 }]);
                    assert_eq!(lane(&ca, i), cols, "columns, lane {i} of {k} on {isa:?}");
                    assert_eq!(
                        lane(&cs, i),
                        cols,
                        "soa columns, lane {i} of {k} on {isa:?}"
                    );
                    hits += 1;
                }
            }
        }
    }
    hits
}

#[test]
fn hit_columns_match_rows_on_cornell() {
    let scene = builtin_scene("cornell", None);
    let cam = camera_packet_rays(&scene, 300, 31);
    assert!(check(&scene.geometry, &cam) > 1500);
    let random = random_rays(scene.geometry.bounds(), 16 * 200, 5);
    assert!(check(&scene.geometry, &random) > 400);
    // The emitter-only geometry (a single leaf: scalar records).
    assert!(check(&scene.emitters, &cam) + check(&scene.emitters, &random) > 0);
}

#[test]
fn hit_columns_match_rows_with_ties_and_quadrics() {
    let scene = builtin_scene("dense", Some(5_000));
    let g = &scene.geometry;
    // Coherent packets aimed at shared vertices and edge midpoints: exact ties on equal t.
    let aimed = tie_rays(g, 200, 33);
    assert!(check(g, &aimed) > 1000);
    let q = soup_with_quadrics(1000, 0.6, 0.8);
    let random = random_rays(q.bounds(), 16 * 200, 9);
    for ray in &random[..32] {
        assert_eq!(q.intersect(ray).map(|h| h.t), brute_force_t(&q, ray));
    }
    assert!(check(&q, &random) > 500);
    // Another backend (no wide BVH: every record scalar).
    let own = q.rebuild(penumbra::geometry::Backend::Own);
    assert!(check(&own, &random[..16 * 40]) > 100);
}

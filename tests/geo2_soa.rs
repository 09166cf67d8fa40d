//! The packet queries on the structure-of-arrays form (`intersect_packet`, `occluded_packet` on a
//! [`RayPacket`]) answer every lane exactly like the `[Ray; PACKET]` ones and the scalar
//! queries: camera, shadow and random rays on cornell, rays aimed at shared vertices of a dense
//! mesh (exact ties, redone by the scalar query), triangles with quadrics, the single-leaf
//! emitter geometry, on every vector backend and with partial masks.

mod geometry_support;

use geometry_support::{
    brute_force_t, builtin_scene, camera_packet_rays, random_rays, secondary_rays,
    soup_with_quadrics, tie_rays,
};
use glam::Vec3;
use penumbra::geometry::{Geometry, PACKET, Ray, RayPacket, RayQuery, SurfaceHit};
use penumbra::isa::Isa;

/// Active masks cycled through the packets: full, partial, single lanes, none.
const MASKS: [u32; 6] = [0xffff, 0xa5c3, 0x0001, 0x8000, 0x7ffe, 0];

/// Every vector backend (those this CPU lacks resolve to a narrower one).
const ISAS: [Isa; 3] = [Isa::Portable, Isa::Avx2, Isa::Avx512];

/// Everything a hit record holds, as bits.
type Key = (
    u32,
    u32,
    [u32; 3],
    [u32; 3],
    [u32; 3],
    [u32; 2],
    u32,
    (u32, u32),
);

fn key(h: &Option<SurfaceHit>) -> Option<Key> {
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
}

/// Compares the SoA queries with the AoS ones (and the scalar queries) over `rays` in packets
/// of 16 on every backend; returns the number of (hits, occluded rays) on the last backend.
fn check(g: &Geometry, rays: &[Ray]) -> (u32, u32) {
    let mut counts = (0, 0);
    for isa in ISAS {
        counts = (0, 0);
        for (k, chunk) in rays.chunks_exact(PACKET).enumerate() {
            let aos: [Ray; PACKET] = std::array::from_fn(|i| chunk[i]);
            let soa = RayPacket::from_rays(&aos);
            let active = MASKS[k % MASKS.len()];
            let (mut a, mut s) = ([None; PACKET], [None; PACKET]);
            g.intersect_packet_on(isa, &aos, active, &mut a);
            g.intersect_packet_on(isa, &soa, active, &mut s);
            let blocked = g.occluded_packet_on(isa, &aos, active);
            assert_eq!(
                g.occluded_packet_on(isa, &soa, active),
                blocked,
                "any-hit packet {k} on {isa:?}"
            );
            for (i, ray) in aos.iter().enumerate() {
                assert_eq!(key(&s[i]), key(&a[i]), "lane {i} of packet {k} on {isa:?}");
                let on = active >> i & 1 != 0;
                let want = if on { g.intersect(ray) } else { None };
                assert_eq!(key(&s[i]), key(&want), "scalar, lane {i} of packet {k}");
                assert_eq!(blocked >> i & 1 != 0, on && g.occluded(ray));
                counts.0 += want.is_some() as u32;
                counts.1 += blocked >> i & 1;
            }
        }
    }
    counts
}

#[test]
fn ray_packet_lanes_round_trip() {
    let rays = random_rays((Vec3::ZERO, Vec3::ONE), PACKET as u32, 3);
    let aos: [Ray; PACKET] = std::array::from_fn(|i| Ray {
        t_max: i as f32,
        ..rays[i]
    });
    let soa = RayPacket::from_rays(&aos);
    for (i, r) in aos.iter().enumerate() {
        let back = soa.ray(i);
        assert_eq!((back.o, back.d, back.t_max), (r.o, r.d, r.t_max));
        assert_eq!(soa.o[1][i], r.o.y);
        assert_eq!(soa.d[2][i], r.d.z);
    }
}

#[test]
fn soa_packets_match_aos_packets_on_cornell() {
    let scene = builtin_scene("cornell", None);
    let cam = camera_packet_rays(&scene, 300, 21);
    let (hits, _) = check(&scene.geometry, &cam);
    assert!(hits > 1500, "{hits} camera hits");
    let shadow = secondary_rays(&scene, &cam, false, 22);
    let (_, blocked) = check(&scene.geometry, &shadow);
    assert!(blocked > 50, "{blocked} blocked shadow rays");
    let random = random_rays(scene.geometry.bounds(), 16 * 200, 4);
    let (hits, _) = check(&scene.geometry, &random);
    assert!(hits > 400, "{hits} random hits");
    // The emitter-only geometry (a single leaf).
    assert!(check(&scene.emitters, &cam).0 + check(&scene.emitters, &random).0 > 0);
}

#[test]
fn soa_packets_match_aos_packets_with_ties_and_quadrics() {
    let scene = builtin_scene("dense", Some(5_000));
    let g = &scene.geometry;
    // Coherent packets aimed at shared vertices and edge midpoints: exact ties on equal t.
    let aimed = tie_rays(g, 200, 23);
    assert!(check(g, &aimed).0 > 1000);
    let q = soup_with_quadrics(1000, 0.6, 0.8);
    let random = random_rays(q.bounds(), 16 * 200, 8);
    for ray in &random[..64] {
        assert_eq!(q.intersect(ray).map(|h| h.t), brute_force_t(&q, ray));
    }
    assert!(check(&q, &random).0 > 500);
}

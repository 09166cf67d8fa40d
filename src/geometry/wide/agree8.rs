//! Tests: the 8-wide queries ([`super::ray8`]) return exactly what the 4-wide ones (the
//! reference) return: same primitive, same t and barycentric bits, same any-hit verdict.

use super::{Bary, WideBvh};
use crate::geometry::primitive::{PrimKind, Primitive};
use crate::geometry::tree2::Tree2;
use crate::geometry::{Ray, RayQuery};
use crate::isa::{Isa, Kernel, Token};
use crate::sampling::hash::{next_f32, pcg_from_keys};
use glam::Vec3;
use rand_pcg::Pcg32;

/// Closest hit as comparable bits: (id, t bits, barycentric bits).
type HitBits = Option<(usize, u32, [u32; 3])>;

fn bits(h: Option<(usize, f32, Bary)>) -> HitBits {
    h.map(|(id, t, b)| (id, t.to_bits(), b.map(f32::to_bits)))
}

/// Both traversals' closest and any hits of `rays`, the 8-wide ones inside the AVX2 function
/// of [`crate::isa::Cpu::dispatch`]: per ray ((4-wide, 8-wide) closest, (4-wide, 8-wide) any).
struct Both<'a>(&'a WideBvh, &'a [Ray]);

impl Kernel for Both<'_> {
    type Output = Vec<((HitBits, HitBits), (bool, bool))>;
    #[inline(always)]
    fn run<T: Token>(self, t: T) -> Self::Output {
        let Both(w, rays) = self;
        let avx2 = t.with_avx2().expect("dispatched on AVX2");
        let none = |_: usize, _: f32| f32::INFINITY;
        rays.iter()
            .map(|r| {
                let c4 = w.closest(r.o, r.d, r.t_max, none);
                let c8 = w.closest8(avx2, r.o, r.d, r.t_max, none, |_| {});
                let a4 = w.any(r.o, r.d, r.t_max, |_| false);
                let a8 = w.any8(avx2, r.o, r.d, r.t_max, |_| false);
                ((bits(c4), bits(c8)), (a4, a8))
            })
            .collect()
    }
}

fn rnd3(s: &mut Pcg32) -> Vec3 {
    Vec3::new(next_f32(s), next_f32(s), next_f32(s))
}

#[test]
fn closest8_and_any8_agree_with_the_4_wide_queries_on_dense_random_triangles() {
    let Some(cpu) = Isa::Avx2.on_this_cpu() else {
        eprintln!("no AVX2: nothing to compare");
        return;
    };
    let mut s = pcg_from_keys(&[88]);
    // 200k small triangles in the unit cube: dense, like the `dense` scene's sphere.
    let prims: Vec<Primitive> = (0..200_000u32)
        .map(|i| {
            let p0 = rnd3(&mut s);
            let e = |s: &mut Pcg32| (rnd3(s) - 0.5) * 0.02;
            Primitive {
                p: [p0, p0 + e(&mut s), p0 + e(&mut s)],
                kind: PrimKind::Triangle { mesh: 0, v: [i; 3] },
                material: 0,
                light: u32::MAX,
            }
        })
        .collect();
    let w = wide_of(&prims);
    assert!(w.has_nodes8());
    // Memory: the 8-wide nodes share the packets; a node is twice a 4-wide one (256 vs 128
    // bytes) but there are fewer (measured: 4-wide nodes 20.8, 8-wide nodes 28.9, packets
    // 64.6 B per triangle, so 85.4 → 114.3 B per triangle with both).
    let per_tri = w.bytes().map(|b| b as f64 / prims.len() as f64);
    eprintln!("bytes per triangle (nodes4, nodes8, packets): {per_tri:.1?}");
    assert!(per_tri[1] < 1.5 * per_tri[0], "{per_tri:?}");
    assert!(per_tri.iter().sum::<f64>() < 120.0, "{per_tri:?}");
    // Random rays from inside and outside the cube, half of them bounded; then rays leaving
    // the hit points of the first ones (bounce rays, which start on a triangle).
    let mut rays: Vec<Ray> = (0..100_000)
        .map(|i| {
            let o = rnd3(&mut s) * 1.6 - 0.3;
            let d = rnd3(&mut s) * 2.0 - 1.0;
            let t_max = if i % 2 == 0 { f32::INFINITY } else { 0.3 };
            Ray { o, d, t_max }
        })
        .collect();
    let first = cpu.dispatch(Both(&w, &rays));
    let bounces: Vec<Ray> = rays
        .iter()
        .zip(&first)
        .filter_map(|(r, ((h, _), _))| h.map(|(_, t, _)| r.o + r.d * f32::from_bits(t)))
        .map(|o| Ray {
            o,
            d: rnd3(&mut s) * 2.0 - 1.0,
            t_max: f32::INFINITY,
        })
        .collect();
    assert!(bounces.len() > 20_000, "{} hits", bounces.len());
    rays.extend(bounces);
    let all = cpu.dispatch(Both(&w, &rays));
    let (mut hits, mut blocked) = (0, 0);
    for (r, ((c4, c8), (a4, a8))) in rays.iter().zip(&all) {
        assert_eq!(c4, c8, "closest hit of {r:?}");
        assert_eq!(a4, a8, "any hit of {r:?}");
        assert_eq!(c4.is_some(), *a4, "any vs closest of {r:?}");
        hits += c4.is_some() as usize;
        blocked += *a8 as usize;
    }
    assert!(hits > rays.len() / 4, "{hits} hits of {}", rays.len());
    assert_eq!(hits, blocked);
}

#[test]
fn geometry_queries_through_8_wide_nodes_give_the_4_wide_hit_records_on_cornell() {
    let Some(cpu) = Isa::Avx2.on_this_cpu() else {
        eprintln!("no AVX2: nothing to compare");
        return;
    };
    let scene = crate::scene::builtin::cornell::cornell(&Default::default()).expect("cornell");
    let g = &scene.geometry;
    let _ = cpu;
    assert!(
        g.isa() >= Isa::Avx2,
        "{:?}: this test assumes the geometry runs AVX2",
        g.isa()
    );
    let w = g.wide().expect("the default backend");
    assert!(w.has_nodes8());
    let (lo, hi) = g.bounds();
    let mut s = pcg_from_keys(&[89]);
    let mut rays = Vec::new();
    for i in 0..200_000 {
        let o = lo + (hi - lo) * (rnd3(&mut s) * 1.2 - 0.1);
        let d = rnd3(&mut s) * 2.0 - 1.0;
        let t_max = if i % 3 == 0 {
            (hi - lo).length() * 0.3
        } else {
            f32::INFINITY
        };
        rays.push(Ray { o, d, t_max });
    }
    let (mut hits, mut differ_any) = (0, 0);
    for r in &rays {
        // Geometry::intersect goes through the 8-wide nodes on this CPU; the reference is
        // the 4-wide traversal and the same hit record function.
        let got = g.intersect(r);
        let want = w
            .closest(r.o, r.d, r.t_max, |id, t| {
                g.other_t_outlined(id, r.o, r.d, t)
            })
            .map(|(id, t, b)| g.surface_hit(id, r, t, b));
        assert_eq!(format!("{got:?}"), format!("{want:?}"), "ray {r:?}");
        hits += got.is_some() as usize;
        let any4 = w.any(r.o, r.d, r.t_max, |id| {
            g.other_t_outlined(id, r.o, r.d, r.t_max) < r.t_max
        });
        differ_any += (g.occluded(r) != any4) as usize;
        // Bounce rays: from the hit point in a random direction.
        if let Some(h) = got {
            let b = Ray::new(h.p + h.ng * h.p_error * 2.0, rnd3(&mut s) * 2.0 - 1.0);
            let got = g.intersect(&b);
            let want = w
                .closest(b.o, b.d, b.t_max, |id, t| {
                    g.other_t_outlined(id, b.o, b.d, t)
                })
                .map(|(id, t, bary)| g.surface_hit(id, &b, t, bary));
            assert_eq!(format!("{got:?}"), format!("{want:?}"), "bounce ray {b:?}");
        }
    }
    assert_eq!(differ_any, 0);
    assert!(hits > rays.len() / 3, "{hits} hits of {}", rays.len());
}

#[test]
fn ties_on_shared_edges_and_vertices_give_the_4_wide_hit() {
    let Some(cpu) = Isa::Avx2.on_this_cpu() else {
        eprintln!("no AVX2: nothing to compare");
        return;
    };
    // A 64×64 grid of unit quads (two triangles each) in z = 0, shuffled into the tree by
    // PLOC: rays aimed at grid vertices and edge midpoints hit several triangles at the same
    // t, and which one wins depends on the order they are tested in.
    let n = 64u32;
    let mut prims = Vec::new();
    for y in 0..n {
        for x in 0..n {
            let p = |dx: u32, dy: u32| Vec3::new((x + dx) as f32, (y + dy) as f32, 0.0);
            for tri in [[p(0, 0), p(1, 0), p(1, 1)], [p(0, 0), p(1, 1), p(0, 1)]] {
                let i = prims.len() as u32;
                prims.push(Primitive {
                    p: tri,
                    kind: PrimKind::Triangle { mesh: 0, v: [i; 3] },
                    material: 0,
                    light: u32::MAX,
                });
            }
        }
    }
    let w = wide_of(&prims);
    let mut s = pcg_from_keys(&[90]);
    let rays: Vec<Ray> = (0..100_000)
        .map(|_| {
            let o = Vec3::new(next_f32(&mut s) * 64.0, next_f32(&mut s) * 64.0, 1.0)
                + (rnd3(&mut s) - 0.5) * 8.0;
            let grid = |s: &mut Pcg32| (next_f32(s) * 128.0).floor() * 0.5;
            let target = Vec3::new(grid(&mut s), grid(&mut s), 0.0);
            Ray::new(o, target - o)
        })
        .collect();
    let all = cpu.dispatch(Both(&w, &rays));
    let mut hits = 0;
    for (r, ((c4, c8), (a4, a8))) in rays.iter().zip(&all) {
        assert_eq!(c4, c8, "closest hit of {r:?}");
        assert_eq!(a4, a8, "any hit of {r:?}");
        hits += c4.is_some() as usize;
    }
    assert!(hits > rays.len() / 4, "{hits} hits of {}", rays.len());
}

/// The wide BVH (both node widths) over triangles `prims`, built as the scene build does.
fn wide_of(prims: &[Primitive]) -> WideBvh {
    let boxes: Vec<(Vec3, Vec3)> = prims
        .iter()
        .map(|p| {
            (
                p.p[0].min(p.p[1]).min(p.p[2]),
                p.p[0].max(p.p[1]).max(p.p[2]),
            )
        })
        .collect();
    WideBvh::build(&Tree2::ploc(&boxes), prims, &[]).expect("tree too deep")
}

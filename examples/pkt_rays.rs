//! Scalar vs packet ray queries on coherent workloads (for `penumbra`'s packet API):
//! `cargo run --release --example pkt_rays -- [SCENE] [RES] [SPP]` (defaults cornell 512 64;
//! `dense` has 20k triangles). Traces the camera rays pixel by pixel in packets of 16
//! consecutive stratified samples, and per camera hit a shadow ray to a random point of an
//! emitter, single-threaded; prints Mrays/s of both query kinds, scalar and packet. For
//! instructions per ray run it under callgrind with `--toggle-collect='*pkt_rays::trace_*'`
//! and one of `ONLY=closest_scalar|closest_packet|any_scalar|any_packet`.

use glam::{UVec2, Vec2};
use penumbra::geometry::{Geometry, PACKET, Ray, RayQuery};
use penumbra::sampling::{PatternKind, make_pattern, uniform_triangle_point};
use penumbra::scene::builtin::BuiltinOptions;
use penumbra::scene::load::{LoadOptions, load};
use std::hint::black_box;
use std::time::{Duration, Instant};

/// A packet with its active mask.
type Packet = ([Ray; PACKET], u32);

#[inline(never)]
fn trace_closest_scalar(g: &Geometry, pks: &[Packet]) -> u64 {
    let mut sum = 0u64;
    for (rays, active) in pks {
        for (i, r) in rays.iter().enumerate() {
            if active & (1 << i) != 0
                && let Some(h) = g.intersect(r)
            {
                sum = sum.wrapping_add(h.prim as u64 ^ h.t.to_bits() as u64);
            }
        }
    }
    sum
}

#[inline(never)]
fn trace_closest_packet(g: &Geometry, pks: &[Packet]) -> u64 {
    let mut sum = 0u64;
    let mut out = [None; PACKET];
    for (rays, active) in pks {
        g.intersect_packet(rays, *active, &mut out);
        for h in out.iter().flatten() {
            sum = sum.wrapping_add(h.prim as u64 ^ h.t.to_bits() as u64);
        }
    }
    sum
}

#[inline(never)]
fn trace_any_scalar(g: &Geometry, pks: &[Packet]) -> u64 {
    let mut sum = 0u64;
    for (rays, active) in pks {
        for (i, r) in rays.iter().enumerate() {
            if active & (1 << i) != 0 && g.occluded(r) {
                sum += 1;
            }
        }
    }
    sum
}

#[inline(never)]
fn trace_any_packet(g: &Geometry, pks: &[Packet]) -> u64 {
    pks.iter()
        .map(|(rays, active)| g.occluded_packet(rays, *active).count_ones() as u64)
        .sum()
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("cornell", String::as_str);
    let res: u32 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(512);
    let spp: u32 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(64);
    let only = std::env::var("ONLY").unwrap_or_default();
    let opts = LoadOptions {
        builtin: BuiltinOptions {
            triangles: (name == "dense").then_some(20_000),
            ..Default::default()
        },
        ..Default::default()
    };
    let scene = load(name, &opts)?.scene;
    let g = &scene.geometry;
    let lights = &scene.emitters;
    let cam = scene.camera.rays(UVec2::splat(res));
    // The renderer's own pattern: stratified pixel jitter, random points on the emitters.
    let pattern = make_pattern(PatternKind::Stratified, 1);
    let (mut n_cam, mut n_shadow) = (0u64, 0u64);
    let mut time = [Duration::ZERO; 4];
    let mut sums = [0u64; 4];
    for y in 0..res {
        // One row of pixels at a time: each packet is 16 consecutive samples of one pixel.
        let mut cam_pks: Vec<Packet> = Vec::new();
        let mut shadow_pks: Vec<Packet> = Vec::new();
        for x in 0..res {
            let px = pattern.pixel(UVec2::new(x, y));
            for s0 in (0..spp).step_by(PACKET) {
                let rays: [Ray; PACKET] = std::array::from_fn(|i| {
                    let s = s0 + i as u32;
                    let j = px.sample_2d(0, s, spp);
                    cam.generate(Vec2::new(x as f32, y as f32) + j)
                });
                let active = if spp - s0 >= PACKET as u32 {
                    u32::MAX >> (32 - PACKET)
                } else {
                    (1 << (spp - s0)) - 1
                };
                // Shadow rays from the camera hits to random points of an emitter.
                let mut shadow = [Ray::new(glam::Vec3::ZERO, glam::Vec3::Z); PACKET];
                let mut sh_active = 0u32;
                for (i, r) in rays.iter().enumerate() {
                    let Some(h) = (active & (1 << i) != 0).then(|| g.intersect(r)).flatten() else {
                        continue;
                    };
                    let pick = px.sample_1d(1, s0 + i as u32, spp);
                    let Some(p) = lights.primitive((pick * lights.len() as f32) as u32) else {
                        continue;
                    };
                    let u = px.sample_2d(2, s0 + i as u32, spp);
                    let target = uniform_triangle_point(u, p.p[0], p.p[1], p.p[2]);
                    let o = h.spawn_origin(target - h.p);
                    shadow[i] = Ray {
                        o,
                        d: target - o,
                        t_max: 1.0 - 1e-4,
                    };
                    sh_active |= 1 << i;
                }
                n_cam += active.count_ones() as u64;
                n_shadow += sh_active.count_ones() as u64;
                cam_pks.push((rays, active));
                shadow_pks.push((shadow, sh_active));
            }
        }
        let mut run = |k: usize, tag: &str, f: &dyn Fn() -> u64| {
            if only.is_empty() || only == tag {
                let t = Instant::now();
                sums[k] = sums[k].wrapping_add(black_box(f()));
                time[k] += t.elapsed();
            }
        };
        run(0, "closest_scalar", &|| trace_closest_scalar(g, &cam_pks));
        run(1, "closest_packet", &|| trace_closest_packet(g, &cam_pks));
        run(2, "any_scalar", &|| trace_any_scalar(g, &shadow_pks));
        run(3, "any_packet", &|| trace_any_packet(g, &shadow_pks));
    }
    let mrays = |n: u64, t: Duration| n as f64 / t.as_secs_f64().max(1e-9) / 1e6;
    println!("{name} {res}² × {spp} spp: {n_cam} camera rays, {n_shadow} shadow rays");
    println!(
        "closest: scalar {:.2} Mrays/s, packet {:.2} Mrays/s (results {})",
        mrays(n_cam, time[0]),
        mrays(n_cam, time[1]),
        if sums[0] == sums[1] {
            "equal"
        } else {
            "DIFFER"
        }
    );
    println!(
        "any-hit: scalar {:.2} Mrays/s, packet {:.2} Mrays/s (results {})",
        mrays(n_shadow, time[2]),
        mrays(n_shadow, time[3]),
        if sums[2] == sums[3] {
            "equal"
        } else {
            "DIFFER"
        }
    );
    Ok(())
}

//! penumbra's side of the ray-core comparison with Embree (`scripts/embree-compare.sh` runs both):
//! `cargo run --release --example embree_compare -- SCENE DIR [RAYS] [REPS] [TRIANGLES]`
//! (TRIANGLES: `dense`'s `--triangles`).
//!
//! Writes the scene's triangles (in penumbra's primitive order, so Embree's primID is our prim
//! id) and two incoherent ray sets to DIR — `random` (`random_query_rays`: origins uniform in
//! the scene box, uniform directions) and `bounce` (`bounce_query_rays`: a cosine bounce from
//! each camera-ray hit, a path tracer's second segment) — with penumbra's closest-hit prim id
//! of every ray; then times, single-threaded, the one-ray closest-hit and any-hit queries and
//! the 16-ray packet ones (16 consecutive rays per packet), REPS times each (this thread's CPU
//! time, so that other processes on a loaded machine count less), and prints one
//! line per query: `penumbra SCENE SET QUERY MRAYS HITS`. Files are little-endian: `.tris` is
//! u32 n then n × 9 f32; `.rays` u32 n then n × 7 f32 (o, d, t_max); `.hits` n × (u32 prim id,
//! f32 t; u32::MAX and +∞ for a miss).

use glam::{UVec2, Vec2};
use penumbra::geometry::{
    Geometry, PACKET, PrimKind, Ray, RayQuery, bounce_query_rays, random_query_rays,
};
use penumbra::scene::load::{LoadOptions, load};
use std::hint::black_box;
use std::io::Write;
use std::path::Path;
use std::time::Instant;

fn write_atomic(path: &Path, bytes: &[u8]) -> anyhow::Result<()> {
    let tmp = path.with_extension("tmp");
    std::fs::File::create(&tmp)?.write_all(bytes)?;
    std::fs::rename(&tmp, path)?;
    Ok(())
}

fn push_f32s(out: &mut Vec<u8>, v: &[f32]) {
    for x in v {
        out.extend_from_slice(&x.to_le_bytes());
    }
}

/// Packets of 16 consecutive rays (the last one padded with inactive lanes).
fn packets(rays: &[Ray]) -> Vec<([Ray; PACKET], u32)> {
    rays.chunks(PACKET)
        .map(|c| {
            let mut p = [c[0]; PACKET];
            p[..c.len()].copy_from_slice(c);
            (p, (1u32 << c.len()) - 1)
        })
        .collect()
}

/// Nanoseconds this thread has run on a CPU (`/proc/thread-self/schedstat`), if readable.
fn cpu_ns() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    s.split_whitespace().next()?.parse().ok()
}

/// Seconds of `f` and its result: CPU time of this thread where Linux reports it (on a loaded
/// machine, time spent descheduled is not the ray core's), else wall time.
fn time<T>(f: impl FnOnce() -> T) -> (f64, T) {
    let (c, t) = (cpu_ns(), Instant::now());
    let r = black_box(f());
    let wall = t.elapsed().as_secs_f64();
    match (c, cpu_ns()) {
        (Some(a), Some(b)) => ((b - a) as f64 * 1e-9, r),
        _ => (wall, r),
    }
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn run_set(g: &Geometry, scene: &str, set: &str, rays: &[Ray], reps: usize) {
    let pks = packets(rays);
    let mut secs = vec![Vec::new(); 4];
    let mut hits = [0usize; 4];
    let mut out = [None; PACKET];
    for _ in 0..reps {
        // Interleaved: each repetition runs the four queries once.
        let (s, h) = time(|| rays.iter().filter(|r| g.intersect(r).is_some()).count());
        secs[0].push(s);
        hits[0] = h;
        let (s, h) = time(|| rays.iter().filter(|r| g.occluded(r)).count());
        secs[1].push(s);
        hits[1] = h;
        let (s, h) = time(|| {
            let mut n = 0;
            for (p, a) in &pks {
                g.intersect_packet(p, *a, &mut out);
                n += out.iter().flatten().count();
            }
            n
        });
        secs[2].push(s);
        hits[2] = h;
        let (s, h) = time(|| {
            pks.iter()
                .map(|(p, a)| g.occluded_packet(p, *a).count_ones() as usize)
                .sum()
        });
        secs[3].push(s);
        hits[3] = h;
    }
    for (k, q) in ["closest1", "any1", "closest16", "any16"]
        .iter()
        .enumerate()
    {
        let m = rays.len() as f64 / median(secs[k].clone()) / 1e6;
        println!("penumbra {scene} {set} {q} {m:.3} {}", hits[k]);
    }
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().collect();
    anyhow::ensure!(
        args.len() >= 3,
        "usage: embree_compare SCENE DIR [RAYS] [REPS] [TRIANGLES]"
    );
    let (name, dir) = (&args[1], Path::new(&args[2]));
    let n: u32 = args.get(3).map_or(Ok(1_000_000), |s| s.parse())?;
    let reps: usize = args.get(4).map_or(Ok(3), |s| s.parse())?;
    std::fs::create_dir_all(dir)?;
    let opts = LoadOptions {
        builtin: penumbra::scene::builtin::BuiltinOptions {
            triangles: args.get(5).map(|s| s.parse()).transpose()?,
            ..Default::default()
        },
        ..Default::default()
    };
    let scene = load(name, &opts)?.scene;
    let g = &scene.geometry;
    let mut tris = Vec::new();
    tris.extend_from_slice(&(g.len() as u32).to_le_bytes());
    for id in 0..g.len() as u32 {
        let p = g.primitive(id).expect("id below len");
        anyhow::ensure!(
            matches!(p.kind, PrimKind::Triangle { .. }),
            "{name}: primitive {id} is not a triangle (Embree would see other geometry)"
        );
        for v in p.p {
            push_f32s(&mut tris, &v.to_array());
        }
    }
    write_atomic(&dir.join(format!("{name}.tris")), &tris)?;
    let random = random_query_rays(g.bounds(), n);
    // Camera rays through a grid of about n pixel centres, then one bounce from each hit.
    let side = (n as f64).sqrt().ceil() as u32;
    let cam = scene.camera.rays(UVec2::splat(side));
    let primary: Vec<Ray> = (0..side * side)
        .map(|i| cam.generate(Vec2::new((i % side) as f32 + 0.5, (i / side) as f32 + 0.5)))
        .collect();
    let bounce = bounce_query_rays(g, &primary);
    for (set, rays) in [("random", &random), ("bounce", &bounce)] {
        let mut rb = Vec::with_capacity(4 + rays.len() * 28);
        rb.extend_from_slice(&(rays.len() as u32).to_le_bytes());
        let mut hb = Vec::with_capacity(rays.len() * 8);
        for r in rays.iter() {
            push_f32s(
                &mut rb,
                &[r.o.x, r.o.y, r.o.z, r.d.x, r.d.y, r.d.z, r.t_max],
            );
            let (id, t) = g
                .intersect(r)
                .map_or((u32::MAX, f32::INFINITY), |h| (h.prim, h.t));
            hb.extend_from_slice(&id.to_le_bytes());
            hb.extend_from_slice(&t.to_le_bytes());
        }
        write_atomic(&dir.join(format!("{name}-{set}.rays")), &rb)?;
        write_atomic(&dir.join(format!("{name}-{set}.hits")), &hb)?;
    }
    eprintln!(
        "{name}: {} triangles, {} random + {} bounce rays, isa {:?}",
        g.len(),
        random.len(),
        bounce.len(),
        g.isa()
    );
    for (set, rays) in [("random", &random), ("bounce", &bounce)] {
        run_set(g, name, set, rays, reps);
    }
    Ok(())
}

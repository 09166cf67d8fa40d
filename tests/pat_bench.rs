//! Timing of the per-pixel sample pattern path in the order the renderer walks it (ignored by
//! default: `cargo test --release --test pat_bench -- --ignored --nocapture`).

use glam::UVec2;
use penumbra::sampling::{PatternKind, make_pattern};
use std::time::Instant;

#[test]
#[ignore]
fn pattern_hot_path_timing() {
    let pat = make_pattern(PatternKind::Stratified, 0x5eed);
    // PAT_SPP=64 times one count only (for profiling).
    let only: Option<u32> = std::env::var("PAT_SPP").ok().and_then(|s| s.parse().ok());
    for spp in [16u32, 64, 100] {
        if only.is_some_and(|o| o != spp) {
            continue;
        }
        let mut pxs: Vec<_> = (0..16).map(|_| pat.pixel(UVec2::ZERO)).collect();
        let mut best = f64::MAX;
        let mut sink = 0u32;
        for _ in 0..5 {
            let t = Instant::now();
            let mut slot = 0;
            for y in 0..256u32 {
                for x in 0..256u32 {
                    let px = &mut pxs[slot];
                    slot = (slot + 1) % 16;
                    pat.pixel_into(UVec2::new(x, y), px);
                    for b in (0..spp).step_by(16) {
                        let e = (b + 16).min(spp);
                        for i in b..e {
                            sink ^= px.sample_2d(0, i, spp).x.to_bits();
                        }
                        for i in b..e {
                            sink ^= px.sample_1d(1, i, spp).to_bits();
                            sink ^= px.sample_2d(2, i, spp).y.to_bits();
                            sink ^= px.sample_2d(4, i, spp).x.to_bits();
                        }
                    }
                }
            }
            best = best.min(t.elapsed().as_secs_f64());
        }
        println!("spp {spp}: {:.2} ms (sink {sink})", best * 1e3);
    }
}

//! Golden digests of every pattern's values: the hot-path rewrites of `sampling::pattern` and
//! `sampling::permutation` must keep each f32 bit-identical (images must not change).

use glam::UVec2;
use penumbra::sampling::{PatternKind, make_pattern, permute};

/// FNV-1a over 32-bit words: any changed value changes the digest.
fn fnv(h: &mut u64, w: u32) {
    for b in w.to_le_bytes() {
        *h ^= b as u64;
        *h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
}

/// Digest of 1D and 2D values over pixels, dims (cached and not), counts (square, prime,
/// non-square, power of two, 1, 0) and indices (inside and past `count`), via both entry points.
fn digest(kind: PatternKind) -> u64 {
    let pat = make_pattern(kind, 0x5eed);
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for pixel in [UVec2::new(0, 0), UVec2::new(3, 7), UVec2::new(511, 13)] {
        let px = pat.pixel(pixel);
        for dim in [0u32, 1, 2, 4, 7, 8, 31] {
            for count in [0u32, 1, 2, 3, 4, 12, 16, 37, 64, 100, 256, 1000] {
                for index in (0..count.max(1) + 3).step_by(1 + count as usize / 97) {
                    let (a, b) = (
                        px.sample_1d(dim, index, count),
                        pat.sample_1d(pixel, dim, index, count),
                    );
                    assert_eq!(
                        a.to_bits(),
                        b.to_bits(),
                        "{kind} 1d {pixel} {dim} {index} {count}"
                    );
                    fnv(&mut h, a.to_bits());
                    let (a, b) = (
                        px.sample_2d(dim, index, count),
                        pat.sample_2d(pixel, dim, index, count),
                    );
                    assert_eq!(
                        a.to_array().map(f32::to_bits),
                        b.to_array().map(f32::to_bits)
                    );
                    fnv(&mut h, a.x.to_bits());
                    fnv(&mut h, a.y.to_bits());
                }
            }
        }
        // Alternating counts exercise the per-pixel count cache.
        for i in 0..50u32 {
            let count = [64u32, 256, 64, 9][i as usize % 4];
            fnv(&mut h, px.sample_2d(i % 6, i, count).x.to_bits());
            fnv(&mut h, px.sample_1d(i % 5, i * 3, count).to_bits());
        }
    }
    h
}

#[test]
fn pattern_values_match_the_golden_digests() {
    let got: Vec<(PatternKind, u64)> = PatternKind::ALL.iter().map(|&k| (k, digest(k))).collect();
    println!("{got:x?}");
    let want: [u64; 6] = GOLDEN;
    for ((k, g), w) in got.iter().zip(want) {
        assert_eq!(*g, w, "{k}: digest {g:#x} != golden {w:#x}");
    }
}

#[test]
fn permute_matches_the_golden_digest() {
    let mut h = 0xcbf2_9ce4_8422_2325u64;
    for n in [0u32, 1, 2, 3, 5, 16, 37, 64, 100, 1 << 20, u32::MAX] {
        for key in [0u64, 7, 0xdead_beef_cafe, u64::MAX] {
            for i in [0u32, 1, 2, 15, 36, 63, 99, 1000, u32::MAX] {
                fnv(&mut h, permute(i, n, key));
            }
        }
    }
    println!("{h:#x}");
    assert_eq!(h, GOLDEN_PERMUTE);
}

/// Digests of the values before the hot-path rewrite, in [`PatternKind::ALL`] order.
const GOLDEN: [u64; 6] = [
    0xa1af_06ae_3287_69d5,
    0xaa43_d3f3_bccc_2652,
    0x55cb_b212_2444_e481,
    0xdb5f_7d6e_7230_3bcc,
    0xb6c1_6476_d0b6_3662,
    0x1a3e_0276_119d_2459,
];
/// Digest of `permute` before the rewrite.
const GOLDEN_PERMUTE: u64 = 0x5c05_5541_1332_bbee;

#[test]
fn pixel_samples_match_the_general_path_for_large_counts() {
    // Counts past the i32 fixed-point form (strata ≥ 2^7 per axis) and past the fast form
    // (> 2^24 strata): the per-pixel path must still equal `SamplePattern::sample_*`.
    for kind in PatternKind::ALL {
        let pat = make_pattern(kind, 11);
        let pixel = UVec2::new(5, 9);
        let px = pat.pixel(pixel);
        for count in [200u32, 256, 1 << 14, 1 << 15, 1 << 16, 1 << 25, u32::MAX] {
            for index in [0u32, 1, 17, 255, 4097, 32767, 65535, 1 << 24, u32::MAX - 1] {
                for dim in [1u32, 2] {
                    let a = px.sample_1d(dim, index, count).to_bits();
                    assert_eq!(a, pat.sample_1d(pixel, dim, index, count).to_bits());
                    let a = px.sample_2d(dim, index, count).to_array().map(f32::to_bits);
                    let b = pat.sample_2d(pixel, dim, index, count);
                    assert_eq!(a, b.to_array().map(f32::to_bits), "{kind} {count} {index}");
                }
            }
        }
    }
}

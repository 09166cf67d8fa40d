//! The per-pixel cache and its fast paths against the definitions, bit for bit: every kind,
//! every instruction set this CPU runs, warm and cold caches, any access order.

use super::*;
use crate::isa::Isa;

/// Every pattern kind with `seed` on every instruction set this CPU runs (the set, for messages).
fn every_pattern(seed: u64) -> impl Iterator<Item = (Pattern, Isa)> {
    PatternKind::ALL.into_iter().flat_map(move |kind| {
        Isa::available().into_iter().map(move |isa| {
            let pat = Pattern {
                seed,
                kind,
                cpu: isa.cpu(),
            };
            (pat, isa)
        })
    })
}

/// `px`'s 1D and 2D values of (`dim`, `index`, `count`) are the pattern's definition at
/// `pixel`, bit for bit.
fn assert_defined_values(
    px: &PixelSamples,
    pat: &Pattern,
    dim: u32,
    index: u32,
    count: u32,
    what: &str,
) {
    let pixel = px.pixel();
    assert_eq!(
        px.sample_1d(dim, index, count).to_bits(),
        pat.sample_1d(pixel, dim, index, count).to_bits(),
        "{what} 1d dim {dim} count {count} index {index}"
    );
    assert_eq!(
        px.sample_2d(dim, index, count).to_array().map(f32::to_bits),
        pat.sample_2d(pixel, dim, index, count)
            .to_array()
            .map(f32::to_bits),
        "{what} 2d dim {dim} count {count} index {index}"
    );
}

#[test]
fn pixel_samples_equal_the_pattern_values() {
    // The cached per-pixel path must return bit-identical values, in cached dimensions
    // and past them, for stratified counts and wrapped indices.
    for (pat, isa) in every_pattern(7) {
        for pixel in [UVec2::new(0, 0), UVec2::new(13, 511)] {
            let px = pat.pixel(pixel);
            assert_eq!(px.pixel(), pixel);
            for dim in [0u32, 3, 7, 8, 40] {
                for (index, count) in [
                    (0u32, 1u32),
                    (5, 16),
                    (63, 64),
                    (70, 64),
                    (9, 37),
                    (40_000, 1 << 16),
                    (17, 1 << 18),
                ] {
                    assert_defined_values(
                        &px,
                        &pat,
                        dim,
                        index,
                        count,
                        &format!("{} {isa:?}", pat.kind),
                    );
                }
            }
        }
    }
}

#[test]
fn pixel_into_reuses_samples_bit_identically() {
    // One PixelSamples refilled pixel after pixel (warm chunks and count caches of the
    // previous pixel) returns what a fresh one returns.
    for (pat, isa) in every_pattern(5) {
        let kind = pat.kind;
        let mut px = pat.pixel(UVec2::new(9, 9));
        for (n, pixel) in [UVec2::new(0, 0), UVec2::new(3, 1), UVec2::new(3, 2)]
            .into_iter()
            .enumerate()
        {
            pat.pixel_into(pixel, &mut px);
            let fresh = pat.pixel(pixel);
            assert_eq!(px.pixel(), pixel);
            // Starting with the previous pixel's last count: its chunks must not serve.
            for count in [16u32, 64, 5, 37][..4 - n].iter().copied().chain([16]) {
                for index in 0..count {
                    for dim in [0u32, 4, 9] {
                        assert_eq!(
                            px.sample_1d(dim, index, count).to_bits(),
                            fresh.sample_1d(dim, index, count).to_bits(),
                            "{kind} {isa:?} 1d count {count} index {index}"
                        );
                        assert_eq!(
                            px.sample_2d(dim, index, count).to_array().map(f32::to_bits),
                            fresh
                                .sample_2d(dim, index, count)
                                .to_array()
                                .map(f32::to_bits),
                            "{kind} {isa:?} 2d count {count} index {index}"
                        );
                    }
                }
            }
        }
    }
}

#[test]
fn group_fills_serve_every_access_order() {
    // Raw-mode misses fill every dimension last seen with the same count: the values must
    // not depend on the order of the requests (renderer order with two counts, dimension
    // after dimension, and backwards; counts 32 and 96 are whole blocks, so the group
    // fills take part), on each instruction set.
    for isa in Isa::available() {
        let pat = Pattern {
            seed: 3,
            kind: PatternKind::Stratified,
            cpu: isa.cpu(),
        };
        let mut px = pat.pixel(UVec2::ZERO);
        for (p, pixel) in [UVec2::new(4, 5), UVec2::new(6, 5), UVec2::new(9, 1)]
            .into_iter()
            .enumerate()
        {
            pat.pixel_into(pixel, &mut px);
            let check_1d = |dim, i, n| {
                assert_eq!(
                    px.sample_1d(dim, i, n).to_bits(),
                    pat.sample_1d(pixel, dim, i, n).to_bits(),
                    "{isa:?} pixel {pixel} 1d dim {dim} index {i} count {n}"
                )
            };
            let check_2d = |dim, i, n| {
                assert_eq!(
                    px.sample_2d(dim, i, n).to_array().map(f32::to_bits),
                    pat.sample_2d(pixel, dim, i, n).to_array().map(f32::to_bits),
                    "{isa:?} pixel {pixel} 2d dim {dim} index {i} count {n}"
                )
            };
            let (spp, m) = (32u32, 3u32);
            match p {
                0 => {
                    for i in 0..spp {
                        check_2d(0, i, spp);
                        for j in 0..m {
                            check_1d(1, i * m + j, spp * m);
                            check_2d(2, i * m + j, spp * m);
                            check_2d(4, i * m + j, spp * m);
                        }
                    }
                }
                1 => {
                    for dim in [0u32, 4, 1, 2] {
                        for i in 0..spp * m {
                            check_2d(dim, i, spp * m);
                            check_1d(dim, i, spp * m);
                        }
                    }
                }
                _ => {
                    for i in (0..spp).rev() {
                        check_1d(3, i, spp);
                        check_2d(2, i, spp);
                        check_2d(0, i, spp * m);
                    }
                }
            }
        }
    }
}

#[test]
fn read_ahead_dimension_serves_the_wave_order() {
    // The renderer's order: a wave draws the pixel filter's dimension (read ahead, filled on
    // its own) for all of a pixel's samples, then the shading dimensions block by block; the
    // same again with whole and partial blocks, on each instruction set.
    for isa in Isa::available() {
        let pat = Pattern {
            seed: 9,
            kind: PatternKind::Stratified,
            cpu: isa.cpu(),
        };
        let mut px = pat.pixel(UVec2::ZERO);
        px.read_ahead_2d(0);
        for (pixel, spp) in [
            (UVec2::new(2, 3), 64u32),
            (UVec2::new(3, 3), 40),
            (UVec2::new(4, 3), 64),
        ] {
            pat.pixel_into(pixel, &mut px);
            for i in 0..spp {
                assert_eq!(
                    px.sample_2d(0, i, spp).to_array().map(f32::to_bits),
                    pat.sample_2d(pixel, 0, i, spp).to_array().map(f32::to_bits),
                    "{isa:?} pixel {pixel} filter index {i}"
                );
            }
            for i in 0..spp {
                for dim in [1u32, 2, 4] {
                    assert_eq!(
                        px.sample_1d(dim, i, spp).to_bits(),
                        pat.sample_1d(pixel, dim, i, spp).to_bits(),
                        "{isa:?} pixel {pixel} 1d dim {dim} index {i}"
                    );
                    assert_eq!(
                        px.sample_2d(dim, i, spp).to_array().map(f32::to_bits),
                        pat.sample_2d(pixel, dim, i, spp)
                            .to_array()
                            .map(f32::to_bits),
                        "{isa:?} pixel {pixel} 2d dim {dim} index {i}"
                    );
                }
                // The filter's values again, after the shading dimensions' group fills.
                assert_eq!(
                    px.sample_2d(0, i, spp).to_array().map(f32::to_bits),
                    pat.sample_2d(pixel, 0, i, spp).to_array().map(f32::to_bits),
                    "{isa:?} pixel {pixel} filter again, index {i}"
                );
            }
        }
    }
}

#[test]
fn non_power_of_two_chunks_equal_the_pattern_values() {
    // Every index of non-power-of-two counts through the chunk fills (cycle-walking
    // permutation, divided cell split), on each instruction set: small and large strata,
    // grids with a power-of-two width (12), square (100, 400), strip (7, 37) and wide (262:
    // 2 × 131 rows) shapes, up to the 2^24 limit of the fast form and past it.
    for isa in Isa::available() {
        let pat = Pattern {
            seed: 11,
            kind: PatternKind::Stratified,
            cpu: isa.cpu(),
        };
        for pixel in [UVec2::new(1, 2), UVec2::new(300, 7)] {
            let px = pat.pixel(pixel);
            for count in [
                3u32,
                7,
                12,
                37,
                100,
                262,
                400,
                1000,
                (1 << 24) - 3,
                (1 << 24) + 3,
            ] {
                let first = if count > 5000 { count - 40 } else { 0 };
                for index in (first..count).chain([0, 17, count - 1]) {
                    for dim in [0u32, 5] {
                        assert_defined_values(&px, &pat, dim, index, count, &format!("{isa:?}"));
                    }
                }
            }
        }
    }
}

#[test]
fn deep_dimension_batches_serve_slot_sharing_dimensions_and_new_pixels() {
    // Dimensions past CACHED_DIMS keep a batch of values per slot (dim mod DEEP = 8): two dims that
    // share a slot, read in turn, and the same dims after a reset to another pixel, must each
    // still get their own pixel's values (a stale batch would serve the other's).
    for (pat, isa) in every_pattern(11) {
        let mut px = pat.pixel(UVec2::new(2, 2));
        for pixel in [UVec2::new(2, 2), UVec2::new(2, 3), UVec2::new(40, 3)] {
            pat.pixel_into(pixel, &mut px);
            for count in [16u32, 64, 37] {
                for index in 0..count + 2 {
                    for dim in [9u32, 25, 9, 41] {
                        assert_defined_values(
                            &px,
                            &pat,
                            dim,
                            index,
                            count,
                            &format!("{} {isa:?}", pat.kind),
                        );
                    }
                }
            }
        }
    }
}

//! Which pattern dimension each random decision of a path reads. Every value is a pure
//! function of (seed, pixel, dimension, sample index, count), so a decision's dimension is
//! part of the image: these numbers must not move (depth 0 keeps the dimensions direct
//! lighting always had).

/// Pattern dimension of the pixel-filter sample (index: the eye sample, count N).
pub const DIM_FILTER: u32 = 0;

/// Pattern dimension of the thin-lens sample (index: the eye sample, count N). The last
/// dimension, beyond those of any path vertex, so that adding it changed no other decision's
/// numbers (pinhole images are bit-identical to before); read only by cameras with a lens.
pub const DIM_LENS: u32 = u32::MAX;

/// Dimensions each path vertex takes, after [`DIM_FILTER`].
pub const DIMS_PER_VERTEX: u32 = 5;

/// The pattern dimensions of the decisions at one path vertex. At the camera ray's hit
/// (depth 0) the index is `eye · M + j` of N·M (eye sample, shadow-ray round j); at later
/// vertices, which take one light sample each, it is the eye sample of N.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VertexDims {
    /// Light-selection number (1D).
    pub light_select: u32,
    /// Point on the light (2D).
    pub light: u32,
    /// BSDF lobe choice (1D).
    pub lobe: u32,
    /// BSDF direction (2D).
    pub bsdf: u32,
    /// Russian roulette on the path throughput (1D).
    pub roulette: u32,
}

impl VertexDims {
    /// The dimensions of vertex `depth` (0: where camera rays hit).
    #[inline(always)]
    pub const fn at(depth: u32) -> Self {
        let base = DIM_FILTER + 1 + depth * DIMS_PER_VERTEX;
        Self {
            light_select: base,
            light: base + 1,
            lobe: base + 2,
            bsdf: base + 3,
            roulette: base + 4,
        }
    }
}

/// Rounds of light and BSDF samples at vertex `depth` when the first vertex takes `m`: N eye
/// rays × M shadow rays at the camera ray's hit, one sample per path at later vertices.
#[inline(always)]
pub const fn rounds_at(depth: u32, m: u32) -> u32 {
    if depth == 0 { m } else { 1 }
}

/// The pattern (index, count) of round `j` at vertex `depth` of eye sample `eye` of `n`, when
/// the first vertex takes `m` rounds: the rounds of all the pixel's paths are one jointly
/// stratified set (`eye · M + j` of N·M at depth 0, `eye` of N later).
#[inline(always)]
pub const fn sample_index(depth: u32, eye: u32, j: u32, n: u32, m: u32) -> (u32, u32) {
    let rounds = rounds_at(depth, m);
    (eye * rounds + j, n * rounds)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn depth_zero_keeps_the_direct_lighting_indices_and_later_vertices_take_one_round() {
        // Direct lighting's draws: index eye·M + j of N·M.
        assert_eq!(sample_index(0, 5, 2, 16, 3), (17, 48));
        assert_eq!(sample_index(0, 0, 0, 1, 1), (0, 1));
        // Later vertices: one sample per path, stratified over the pixel's N paths.
        assert_eq!(sample_index(1, 5, 0, 16, 3), (5, 16));
        assert_eq!(rounds_at(2, 4), 1);
    }

    #[test]
    fn depth_zero_keeps_the_direct_lighting_dimensions_and_depths_do_not_overlap() {
        let d = VertexDims::at(0);
        assert_eq!((d.light_select, d.light, d.lobe, d.bsdf), (1, 2, 3, 4));
        let mut seen = vec![DIM_FILTER];
        for depth in 0..8 {
            let d = VertexDims::at(depth);
            for dim in [d.light_select, d.light, d.lobe, d.bsdf, d.roulette] {
                assert!(!seen.contains(&dim), "dimension {dim} used twice");
                seen.push(dim);
            }
        }
    }
}

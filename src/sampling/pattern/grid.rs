//! `grid`: the centres of the strata of a near-square nx × ny grid ([`super::grid_dims`];
//! `count` strata in 1D), handed to the indices by a hashed permutation of the strata so that
//! reusing an index in another dimension does not correlate the two.

use glam::Vec2;

use super::sets::{SetKeys, Strata, in_stratum};
use crate::sampling::permutation::Permutation;

/// The keys of a `grid` set (from its `key`): the strata → index permutation.
#[inline(always)]
pub(super) fn keys(key: u64) -> SetKeys {
    SetKeys {
        key,
        perm: Permutation::new(key),
        ..Default::default()
    }
}

/// The 1D sample `index`: the centre of its stratum.
#[inline(always)]
pub(super) fn sample_1d(set: &SetKeys, index: u32, st: &Strata) -> f32 {
    in_stratum(set.perm.apply_in(index, &st.dom), 0.5, st.count)
}

/// The 2D sample `index`: the centre of its grid cell.
#[inline(always)]
pub(super) fn sample_2d(set: &SetKeys, index: u32, st: &Strata) -> Vec2 {
    let (sx, sy) = st.cell(set.perm.apply_in(index, &st.dom));
    Vec2::new(in_stratum(sx, 0.5, st.nx), in_stratum(sy, 0.5, st.ny))
}

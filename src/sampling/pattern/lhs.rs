//! `lhs`: Latin hypercube (N-rooks) — `count` strata on each axis, the x and y strata permuted
//! independently, jittered inside. In 1D a Latin hypercube is a jittered stratification.

use glam::Vec2;

use super::sets::{SetKeys, Strata, in_stratum};
use super::{TAG_JITTER, TAG_LHS_Y};
use crate::sampling::hash::{hash_keys, hash_step, uniform_pair};
use crate::sampling::permutation::Permutation;

/// The keys of an `lhs` set (from its `key`): one permutation per axis and the jitter stream.
#[inline(always)]
pub(super) fn keys(key: u64) -> SetKeys {
    SetKeys {
        key,
        perm: Permutation::new(key),
        perm_y: Permutation::new(hash_keys(&[key, TAG_LHS_Y])),
        jitter: hash_step(key, TAG_JITTER),
        ..Default::default()
    }
}

/// The 1D sample `index`: the `stratified` one.
#[inline(always)]
pub(super) fn sample_1d(set: &SetKeys, index: u32, st: &Strata) -> f32 {
    super::stratified::sample_1d(set, index, st)
}

/// The 2D sample `index`: its x and y strata of `count`, jittered.
#[inline(always)]
pub(super) fn sample_2d(set: &SetKeys, index: u32, st: &Strata) -> Vec2 {
    let sx = set.perm.apply_in(index, &st.dom);
    let sy = set.perm_y.apply_in(index, &st.dom);
    let (jx, jy) = uniform_pair(set.jitter, st.wrap(index));
    Vec2::new(in_stratum(sx, jx, st.count), in_stratum(sy, jy, st.count))
}

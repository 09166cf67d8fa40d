//! `stratified` (jittered): the strata of [`super::grid`], each with one uniformly jittered
//! point; the jitter is a hash of (set key, index mod count). The renderer's default, so it
//! also has fast forms: the integer form of `fast.rs` and the AVX-512 one of `avx512.rs`,
//! bit-identical to these definitions (tests/pat_golden.rs).

use glam::Vec2;

use super::TAG_JITTER;
use super::sets::{SetKeys, Strata, in_stratum};
use crate::sampling::hash::{HASH_INIT, hash_step, uniform_pair};
use crate::sampling::permutation::Permutation;

/// The keys of a `stratified` set (from its `key`): the strata permutation and the jitter
/// stream (also in the `jitter_fast` form the fast paths hash).
#[inline(always)]
pub(super) fn keys(key: u64) -> SetKeys {
    let jitter = hash_step(key, TAG_JITTER);
    SetKeys {
        key,
        perm: Permutation::new(key),
        jitter,
        jitter_fast: jitter.wrapping_add(HASH_INIT),
        ..Default::default()
    }
}

/// The 1D sample `index`: its stratum of `count`, jittered.
#[inline(always)]
pub(super) fn sample_1d(set: &SetKeys, index: u32, st: &Strata) -> f32 {
    let j = uniform_pair(set.jitter, st.wrap(index)).0;
    in_stratum(set.perm.apply_in(index, &st.dom), j, st.count)
}

/// The 2D sample `index`: its grid cell, jittered on both axes.
#[inline(always)]
pub(super) fn sample_2d(set: &SetKeys, index: u32, st: &Strata) -> Vec2 {
    let (sx, sy) = st.cell(set.perm.apply_in(index, &st.dom));
    let (jx, jy) = uniform_pair(set.jitter, st.wrap(index));
    Vec2::new(in_stratum(sx, jx, st.nx), in_stratum(sy, jy, st.ny))
}

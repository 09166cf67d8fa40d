//! `fixed`: every sample is the centre of its domain, 0.5 in 1D and (0.5, 0.5) in 2D — the
//! lecture's "same point on the light every time" (no key material at all).

use glam::Vec2;

use super::sets::{SetKeys, Strata};

/// The keys of a `fixed` set: none beyond the set key, which nothing reads.
#[inline(always)]
pub(super) fn keys(key: u64) -> SetKeys {
    SetKeys {
        key,
        ..Default::default()
    }
}

/// The 1D value of every index.
#[inline(always)]
pub(super) fn sample_1d(_set: &SetKeys, _index: u32, _st: &Strata) -> f32 {
    0.5
}

/// The 2D value of every index.
#[inline(always)]
pub(super) fn sample_2d(_set: &SetKeys, _index: u32, _st: &Strata) -> Vec2 {
    Vec2::splat(0.5)
}

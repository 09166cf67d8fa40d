//! `sobol`: Owen-scrambled Sobol points (sobol_burley), dimensions 0 and 1 of a sequence seeded
//! by a hash of the set key ("padding" by independent shuffles, which keeps every 2D
//! projection a (0,2)-sequence). sobol_burley holds 2^16 points per sequence; indices past
//! them continue in a differently seeded sequence.

use glam::Vec2;

use super::sets::{SetKeys, Strata};
use crate::sampling::hash::hash_keys;

/// The keys of a `sobol` set (from its `key`): the seed of its first 2^16 points (the set key
/// seeds the rest).
#[inline(always)]
pub(super) fn keys(key: u64) -> SetKeys {
    SetKeys {
        key,
        sobol0: sobol_seed(key, 0),
        ..Default::default()
    }
}

/// The seed of the sequence holding indices `hi · 2^16 ..` of the set `key`.
#[inline]
fn sobol_seed(key: u64, hi: u32) -> u32 {
    hash_keys(&[key, hi as u64]) as u32
}

/// Owen-scrambled Sobol dimension `d` (0 or 1) of sample `index`.
#[inline]
fn sobol(set: &SetKeys, index: u32, d: u32) -> f32 {
    let hi = index >> 16;
    let seed = if hi == 0 {
        set.sobol0
    } else {
        sobol_seed(set.key, hi)
    };
    sobol_burley::sample(index & 0xffff, d, seed)
}

/// The 1D sample `index`.
#[inline(always)]
pub(super) fn sample_1d(set: &SetKeys, index: u32, _st: &Strata) -> f32 {
    sobol(set, index, 0)
}

/// The 2D sample `index`.
#[inline(always)]
pub(super) fn sample_2d(set: &SetKeys, index: u32, _st: &Strata) -> Vec2 {
    Vec2::new(sobol(set, index, 0), sobol(set, index, 1))
}

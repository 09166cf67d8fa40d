//! `random`: independent uniform points, one SplitMix64 hash of (set key, index) per sample
//! ([`uniform_pair`]: its two 32-bit halves are the two coordinates). No stratification, so
//! the index does not wrap.

use glam::Vec2;

use super::TAG_JITTER;
use super::sets::{SetKeys, Strata};
use crate::sampling::hash::{hash_step, uniform_pair};

/// The keys of a `random` set (from its `key`): the stream key.
#[inline(always)]
pub(super) fn keys(key: u64) -> SetKeys {
    SetKeys {
        key,
        jitter: hash_step(key, TAG_JITTER),
        ..Default::default()
    }
}

/// The 1D sample `index`.
#[inline(always)]
pub(super) fn sample_1d(set: &SetKeys, index: u32, _st: &Strata) -> f32 {
    uniform_pair(set.jitter, index).0
}

/// The 2D sample `index`.
#[inline(always)]
pub(super) fn sample_2d(set: &SetKeys, index: u32, _st: &Strata) -> Vec2 {
    let (a, b) = uniform_pair(set.jitter, index);
    Vec2::new(a, b)
}

//! What every pattern definition reads: the keys of one (pixel, dim, 1D/2D) sample set
//! ([`SetKeys`], derived once per set by the pattern's own `keys`) and the shape of a set of
//! `count` points ([`Strata`], once per count), and the dispatch from a [`PatternKind`] to its
//! definition file.

use glam::Vec2;

use super::{PatternKind, fixed, grid, grid_dims, lhs, random, sobol, stratified};
use crate::sampling::ONE_MINUS_EPSILON;
use crate::sampling::permutation::{PermDomain, Permutation};

/// Everything derived from the key of one (pixel, dim, 1D/2D) sample set.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct SetKeys {
    /// Strata → index assignment (x axis for LHS).
    pub(super) perm: Permutation,
    /// LHS y-axis permutation.
    pub(super) perm_y: Permutation,
    /// Jitter / random stream key.
    pub(super) jitter: u64,
    /// `jitter` + [`HASH_INIT`](crate::sampling::hash::HASH_INIT):
    /// [`uniform_pair`](crate::sampling::hash::uniform_pair)`(jitter, i)` hashes
    /// `jitter_fast + i · HASH_INIT`.
    pub(super) jitter_fast: u64,
    /// Set key, for Sobol sequences past the first 2^16 points.
    pub(super) key: u64,
    /// Sobol seed of the first 2^16 points.
    pub(super) sobol0: u32,
}

impl SetKeys {
    /// The keys of the set `key`: only what `kind` needs.
    #[inline]
    pub(super) fn new(kind: PatternKind, key: u64) -> Self {
        // By value, built in place: filling a default through `&mut` cost Cornell +3.9 % Ir.
        match kind {
            PatternKind::Fixed => fixed::keys(key),
            PatternKind::Random => random::keys(key),
            PatternKind::Grid => grid::keys(key),
            PatternKind::Stratified => stratified::keys(key),
            PatternKind::Lhs => lhs::keys(key),
            PatternKind::Sobol => sobol::keys(key),
        }
    }

    /// The 1D sample `index` of a set of `st.count` under `kind`.
    #[inline(always)]
    pub(super) fn sample_1d(&self, kind: PatternKind, index: u32, st: &Strata) -> f32 {
        match kind {
            PatternKind::Fixed => fixed::sample_1d(self, index, st),
            PatternKind::Random => random::sample_1d(self, index, st),
            PatternKind::Grid => grid::sample_1d(self, index, st),
            PatternKind::Stratified => stratified::sample_1d(self, index, st),
            PatternKind::Lhs => lhs::sample_1d(self, index, st),
            PatternKind::Sobol => sobol::sample_1d(self, index, st),
        }
    }

    /// The 2D sample `index` of a set of `st.count` under `kind`.
    #[inline(always)]
    pub(super) fn sample_2d(&self, kind: PatternKind, index: u32, st: &Strata) -> Vec2 {
        match kind {
            PatternKind::Fixed => fixed::sample_2d(self, index, st),
            PatternKind::Random => random::sample_2d(self, index, st),
            PatternKind::Grid => grid::sample_2d(self, index, st),
            PatternKind::Stratified => stratified::sample_2d(self, index, st),
            PatternKind::Lhs => lhs::sample_2d(self, index, st),
            PatternKind::Sobol => sobol::sample_2d(self, index, st),
        }
    }
}

/// What a sample set of `count` points needs besides its keys (grid shape, permutation
/// width), computed once per count instead of for every sample.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Strata {
    pub(super) count: u32,
    pub(super) nx: u32,
    pub(super) ny: u32,
    /// log2(nx) when nx is a power of two (the common square counts), else `u32::MAX`.
    pub(super) nx_log2: u32,
    pub(super) dom: PermDomain,
}

impl Strata {
    #[inline]
    pub(super) fn new(count: u32) -> Self {
        let count = count.max(1);
        let (nx, ny) = grid_dims(count);
        Self {
            count,
            nx,
            ny,
            nx_log2: if nx.is_power_of_two() {
                nx.trailing_zeros()
            } else {
                u32::MAX
            },
            dom: PermDomain::new(count),
        }
    }

    /// `index` wrapped into [0, count).
    #[inline]
    pub(super) fn wrap(&self, index: u32) -> u32 {
        if index < self.count {
            index
        } else {
            index % self.count
        }
    }

    /// Grid cell (column, row) of stratum `s`.
    #[inline]
    pub(super) fn cell(&self, s: u32) -> (u32, u32) {
        if self.nx_log2 != u32::MAX {
            (s & (self.nx - 1), s >> self.nx_log2)
        } else {
            (s % self.nx, s / self.nx)
        }
    }
}

/// (stratum + jitter) / n, kept inside [0, 1).
#[inline]
pub(super) fn in_stratum(stratum: u32, jitter: f32, n: u32) -> f32 {
    ((stratum as f32 + jitter) / n as f32).min(ONE_MINUS_EPSILON)
}

//! The per-pixel cache: [`PixelSamples`] hashes the keys of each of one pixel's sample sets
//! once, at its first use, then evaluates the set 16 consecutive indices at a time
//! (integrators walk a pixel's indices in order), so most samples cost one compare and a load.
//! The first [`CACHED_DIMS`] dimensions have their own slots; later ones (a path's later
//! vertices) share [`DEEP`] slots.
//! Values are bit-identical to the pattern's `sample_1d` / `sample_2d` (tests/pat_golden.rs).

use glam::{UVec2, Vec2};
use std::cell::Cell;

use super::avx512::RawSets;
use super::fast::FastStrata;
use super::sets::{SetKeys, Strata};
use super::{CACHED_DIMS, Pattern, PatternKind};
use crate::isa::Isa;

impl Pattern {
    /// Whether [`PixelSamples`] of this pattern hold raw keys (see `PixelSamples::raw_mode`).
    fn raw_mode(&self) -> bool {
        cfg!(target_arch = "x86_64")
            && self.kind == PatternKind::Stratified
            && self.cpu.isa() == Isa::Avx512
    }

    /// The [`PixelSamples`] of `pixel` with no keys yet and empty caches.
    #[inline(always)]
    pub(super) fn pixel_empty(&self, pixel: UVec2) -> PixelSamples {
        PixelSamples {
            pattern: *self,
            pixel,
            prefix: self.pixel_hash(pixel),
            sets: Default::default(),
            keyed: Default::default(),
            raw_mode: self.raw_mode(),
            raw: Default::default(),
            learned: Default::default(),
            alone: [0; 2],
            strata: Cell::default(),
            fast: [Cell::new(FastStrata::NONE), Cell::new(FastStrata::NONE)],
            chunks_1d: Default::default(),
            chunks_2d: Default::default(),
            deep_1d: Default::default(),
            deep_2d: Default::default(),
            generation: Cell::new(1),
        }
    }
}

/// Indices per [`Chunk`]: a sample set's values are computed this many at a time.
pub(super) const CHUNK: usize = 16;

/// Precomputed values of consecutive indices [base, base + len) of one sample set for one
/// count: integrators walk a pixel's indices in order, so a batch evaluated in one tight loop
/// (keys read once, no per-request lookups) serves the next `len` requests with one compare.
#[derive(Clone, Debug)]
pub(super) struct Chunk<T: Copy> {
    /// The dimension the values belong to (read for the deep slots only, which several
    /// dimensions share: checking it here reads no other cache line than the values').
    dim: Cell<u32>,
    /// The count the values belong to.
    count: Cell<u32>,
    /// First index.
    base: Cell<u32>,
    /// Number of valid values (0 = empty).
    len: Cell<u32>,
    /// The values of indices base..base + len.
    v: [Cell<T>; CHUNK],
}

impl<T: Copy + Default> Default for Chunk<T> {
    fn default() -> Self {
        Self {
            dim: Cell::new(0),
            count: Cell::new(0),
            base: Cell::new(0),
            len: Cell::new(0),
            v: Default::default(),
        }
    }
}

impl<T: Copy> Chunk<T> {
    /// The value of `index` of `count`, if this chunk holds it (hot path).
    #[inline(always)]
    fn get(&self, index: u32, count: u32) -> Option<T> {
        let off = index.wrapping_sub(self.base.get());
        if self.count.get() == count && off < self.len.get() {
            return Some(self.v[off as usize % CHUNK].get());
        }
        None
    }

    /// Store the values `v` of the chunk of `index` (< count) and return `index`'s value.
    #[inline(always)]
    fn store(&self, index: u32, count: u32, v: &[T; CHUNK]) -> T {
        let base = index & !(CHUNK as u32 - 1);
        let len = (count - base).min(CHUNK as u32);
        for (c, &x) in self.v.iter().zip(v) {
            c.set(x);
        }
        self.count.set(count);
        self.base.set(base);
        self.len.set(len);
        v[(index - base) as usize % CHUNK]
    }

    /// Whether this chunk holds the values of the chunk at `base` of `count`.
    #[inline(always)]
    pub(super) fn holds(&self, base: u32, count: u32) -> bool {
        self.count.get() == count && self.base.get() == base && self.len.get() != 0
    }

    /// Where the values go: `v` as plain `T`s, for vector stores.
    #[inline(always)]
    pub(super) fn values_ptr(&self) -> *mut T {
        // `Cell<T>` has the layout of `T`, and a `Cell` may be written through a shared
        // reference: this pointer may be written while no reference to a value is live.
        self.v.as_ptr().cast::<T>().cast_mut()
    }

    /// Mark the values (written through [`Chunk::values_ptr`]) as those of the chunk at
    /// `base` (a multiple of [`CHUNK`], < count) of `count`.
    #[inline(always)]
    pub(super) fn mark(&self, base: u32, count: u32) {
        self.count.set(count);
        self.base.set(base);
        self.len.set((count - base).min(CHUNK as u32));
    }
}

/// One pixel's sample sets, each set's keys derived once, its values batched; returns exactly what the pattern's `sample_1d` / `sample_2d` return for this pixel.
#[derive(Clone, Debug)]
pub struct PixelSamples {
    pub(super) pattern: Pattern,
    pixel: UVec2,
    /// The pixel's [`Pattern::pixel_hash`], from which its sets' keys are derived.
    prefix: u64,
    /// The keys of the 1D and 2D sets of the cached dimensions, derived at a dimension's
    /// first chunk fill in this pixel (an integrator reads few of them: a diffuse scene's
    /// path tracer 6 of the 16), valid where `keyed` has the dimension's bit.
    sets: [[Cell<SetKeys>; CACHED_DIMS]; 2],
    /// Per 1D / 2D: the cached dimensions (bits) whose keys `sets` holds for this pixel.
    keyed: [Cell<u32>; 2],
    /// The `stratified` AVX-512 form: `raw` holds the keys instead of `sets` (which is then
    /// unused), and a miss fills a whole group of chunks (see `learned`).
    pub(super) raw_mode: bool,
    /// Raw keys of the 1D and 2D sets (raw mode).
    pub(super) raw: [RawSets; 2],
    /// Per 1D / 2D cached dimension: the count of its last chunk fill (0: never), kept from
    /// pixel to pixel. In raw mode a miss at (base, count) (count a multiple of 16) fills the
    /// chunks at (base, count) of every dimension whose last count was `count`: an integrator draws the same
    /// dimensions for each sample index, so the chunks of one 16-index block are computed
    /// together, their independent hash chains overlapping, with one call and one setup.
    pub(super) learned: [[Cell<u32>; CACHED_DIMS]; 2],
    /// Per 1D / 2D: the dimensions (bits) whose chunks are filled on their own, never in a
    /// group (see [`PixelSamples::read_ahead_2d`]); kept from pixel to pixel.
    pub(super) alone: [u32; 2],
    /// The two most recently used sample counts' [`Strata`] (an integrator asks for two: N for
    /// the pixel filter, N·M for the shading dimensions).
    strata: Cell<[Strata; 2]>,
    /// The same in the `stratified` fast form: two slots, most recent first.
    fast: [Cell<FastStrata>; 2],
    /// Batches of precomputed `stratified` values per cached 1D / 2D dimension.
    pub(super) chunks_1d: [Chunk<f32>; CACHED_DIMS],
    pub(super) chunks_2d: [Chunk<Vec2>; CACHED_DIMS],
    /// The 1D and 2D sets of dimensions past [`CACHED_DIMS`] (a path's later vertices):
    /// slot `dim % DEEP` holds the last such dim's keys and a batch of its values.
    deep_1d: [DeepSlot<f32>; DEEP],
    deep_2d: [DeepSlot<Vec2>; DEEP],
    /// Bumped by every reset to a new pixel, which so invalidates every deep slot's keys in
    /// one store.
    generation: Cell<u64>,
}

/// Slots of [`PixelSamples::deep_1d`] / `deep_2d`: more than the dimensions of one path vertex
/// (the stages take a wave's paths one depth at a time, so those are the ones in use).
const DEEP: usize = 8;

/// One deep slot: the keys of a set past [`CACHED_DIMS`], computed at its first use in the
/// pixel, and a batch of its values, as a cached dimension has. A later vertex's draws come
/// one per path, but all the paths of a pixel reach it in index order, so one fill of 16
/// serves them as it does at the first vertex. Tag, keys and batch side by side: a miss reads
/// neighbouring cache lines, not three arrays' (the wave's pixels do not all stay in cache).
#[derive(Clone, Debug, Default)]
struct DeepSlot<T: Copy> {
    /// (generation, dim) of `keys`.
    tag: Cell<(u64, u32)>,
    /// The set's keys.
    keys: Cell<SetKeys>,
    /// Its values, tagged with their dimension (emptied by a reset; a fill for another
    /// dimension of the slot retags it).
    chunk: Chunk<T>,
}

impl PixelSamples {
    /// Make these the samples of `pixel` under `pattern` except for the set keys (which the
    /// caller writes next): every chunk emptied, the per-count caches kept (they depend on
    /// the count only).
    #[inline]
    pub(super) fn reset(&mut self, pattern: Pattern, pixel: UVec2, prefix: u64) {
        self.pattern = pattern;
        self.pixel = pixel;
        self.prefix = prefix;
        self.keyed = Default::default();
        self.raw_mode = pattern.raw_mode();
        for c in &self.chunks_1d {
            c.len.set(0);
        }
        for c in &self.chunks_2d {
            c.len.set(0);
        }
        for d in &self.deep_1d {
            d.chunk.len.set(0);
        }
        for d in &self.deep_2d {
            d.chunk.len.set(0);
        }
        self.generation.set(self.generation.get() + 1);
    }

    /// Fill the 2D chunks of `dim` on their own, never with the group of the dimensions an
    /// integrator reads in step: for a dimension read ahead of the others (the pixel filter's,
    /// drawn for a whole wave of camera packets before any of them is shaded). Its block
    /// fills would otherwise also fill the shading dimensions' next blocks, evicting those
    /// they have still to read, and theirs would refill its. Values do not change; kept from
    /// pixel to pixel.
    pub fn read_ahead_2d(&mut self, dim: u32) {
        if (dim as usize) < CACHED_DIMS {
            self.alone[1] |= 1 << dim;
        }
    }

    /// The pixel these samples belong to.
    #[inline]
    pub fn pixel(&self) -> UVec2 {
        self.pixel
    }

    /// The [`Strata`] of `count`, from the two-entry cache.
    #[inline]
    fn strata(&self, count: u32) -> Strata {
        let count = count.max(1);
        let mut c = self.strata.get();
        if c[0].count == count {
            return c[0];
        }
        if c[1].count != count {
            c[1] = Strata::new(count);
        }
        c.swap(0, 1);
        self.strata.set(c);
        c[0]
    }

    /// The [`FastStrata`] of `count`, from the two-slot cache (most recent first).
    #[inline]
    pub(super) fn fast(&self, count: u32) -> FastStrata {
        let a = self.fast[0].get();
        if a.key == count as u64 {
            return a;
        }
        let b = self.fast[1].get();
        if b.key == count as u64 {
            return b;
        }
        let f = FastStrata::new(count);
        self.fast[1].set(a);
        self.fast[0].set(f);
        f
    }

    /// The 1D sample `index` of `count` for `dim`.
    #[inline(always)]
    pub fn sample_1d(&self, dim: u32, index: u32, count: u32) -> f32 {
        if let Some(c) = self.chunk(dim, &self.chunks_1d, &self.deep_1d)
            && let Some(v) = c.get(index, count)
        {
            return v;
        }
        self.sample_1d_miss(dim, index, count)
    }

    /// [`PixelSamples::sample_1d`] when no chunk holds the value (see [`PixelSamples::miss`]).
    #[inline(never)]
    fn sample_1d_miss(&self, dim: u32, index: u32, count: u32) -> f32 {
        #[cfg(target_arch = "x86_64")]
        if self.raw_mode
            && let Some(v) = self.miss_raw(0, dim, index, count)
        {
            // SAFETY: the 1D chunk of `dim` holds `index` now; it stores f32s.
            return unsafe {
                *self.chunks_1d[dim as usize]
                    .values_ptr()
                    .cast::<f32>()
                    .add(v)
            };
        }
        self.miss(
            self.set_keys(0, dim),
            (&self.chunks_1d, &self.deep_1d),
            Arity {
                dim,
                index,
                count,
                arity: 0,
                eval: |set: &SetKeys, kind, i, st: &Strata| set.sample_1d(kind, i, st),
                fast: |f: &FastStrata, set: &SetKeys, base| {
                    f.chunk_1d_on(self.pattern.cpu, set, base)
                },
            },
        )
    }

    /// The 2D sample `index` of `count` for `dim`.
    #[inline(always)]
    pub fn sample_2d(&self, dim: u32, index: u32, count: u32) -> Vec2 {
        if let Some(c) = self.chunk(dim, &self.chunks_2d, &self.deep_2d)
            && let Some(v) = c.get(index, count)
        {
            return v;
        }
        self.sample_2d_miss(dim, index, count)
    }

    /// [`PixelSamples::sample_2d`] when no chunk holds the value (see [`PixelSamples::miss`]).
    #[inline(never)]
    fn sample_2d_miss(&self, dim: u32, index: u32, count: u32) -> Vec2 {
        #[cfg(target_arch = "x86_64")]
        if self.raw_mode
            && let Some(v) = self.miss_raw(1, dim, index, count)
        {
            // SAFETY: the 2D chunk of `dim` holds `index` now.
            return unsafe { *self.chunks_2d[dim as usize].values_ptr().add(v) };
        }
        self.miss(
            self.set_keys(1, dim),
            (&self.chunks_2d, &self.deep_2d),
            Arity {
                dim,
                index,
                count,
                arity: 1,
                eval: |set: &SetKeys, kind, i, st: &Strata| set.sample_2d(kind, i, st),
                fast: |f: &FastStrata, set: &SetKeys, base| {
                    f.chunk_2d_on(self.pattern.cpu, set, base)
                },
            },
        )
    }

    /// The chunk that may hold `dim`'s values: a cached dimension's own, or the deep slot's
    /// batch if it is `dim`'s (looked up before the call to the miss path: a later vertex's
    /// draws mostly hit their slot's batch).
    #[inline(always)]
    fn chunk<'a, T: Copy>(
        &self,
        dim: u32,
        chunks: &'a [Chunk<T>; CACHED_DIMS],
        deep: &'a [DeepSlot<T>; DEEP],
    ) -> Option<&'a Chunk<T>> {
        let d = dim as usize;
        if d < CACHED_DIMS {
            return Some(&chunks[d]);
        }
        let c = &deep[d % DEEP].chunk;
        (c.dim.get() == dim).then_some(c)
    }

    /// The keys of the 1D (`arity` 0) or 2D (1) set of `dim`, if it is a cached dimension.
    #[inline]
    fn set_keys(&self, arity: usize, dim: u32) -> Option<SetKeys> {
        let d = dim as usize;
        if d >= CACHED_DIMS {
            return None;
        }
        if self.raw_mode {
            return Some(self.raw[arity].set(d));
        }
        let (slot, keyed) = (&self.sets[arity][d], &self.keyed[arity]);
        if keyed.get() & 1 << d == 0 {
            let tag = [super::TAG_1D, super::TAG_2D][arity];
            slot.set(self.pattern.set(self.prefix, dim, tag));
            keyed.set(keyed.get() | 1 << d);
        }
        Some(slot.get())
    }

    /// A value no chunk holds: refill the chunk of `index` (< count; the `stratified` fast form
    /// where it applies) or evaluate the general way (uncached dimension, wrapped index).
    /// Written once for 1D and 2D; inlined into each so that every loop is specialised.
    #[inline(always)]
    fn miss<T, E, F>(
        &self,
        set: Option<SetKeys>,
        (chunks, deep): (&[Chunk<T>; CACHED_DIMS], &[DeepSlot<T>; DEEP]),
        a: Arity<E, F>,
    ) -> T
    where
        T: Copy + Default,
        E: Fn(&SetKeys, PatternKind, u32, &Strata) -> T,
        F: Fn(&FastStrata, &SetKeys, u32) -> [T; CHUNK],
    {
        let Arity {
            dim,
            index,
            count,
            arity,
            eval,
            fast,
        } = a;
        let Some(set) = set else {
            // A dimension past the cached ones: its keys from the deep slots (what
            // `Pattern::sample_1d` / `sample_2d` derive from the pixel, dim and arity at
            // each call), then the same evaluation with the same strata.
            let i = dim as usize % DEEP;
            let (slot, tag) = (&deep[i].keys, &deep[i].tag);
            let want = (self.generation.get(), dim);
            if tag.get() != want {
                let set_tag = [super::TAG_1D, super::TAG_2D][arity];
                slot.set(self.pattern.set(self.prefix, dim, set_tag));
                tag.set(want);
            }
            let keys = slot.get();
            let kind = self.pattern.kind;
            // The slot's batch, filled the fast way as a cached dimension's chunk is (the same
            // values); other patterns and wrapped indices take the general evaluation.
            if kind == PatternKind::Stratified && index < count {
                let chunk = &deep[i].chunk;
                if chunk.dim.get() == dim
                    && let Some(v) = chunk.get(index, count)
                {
                    return v;
                }
                let f = self.fast(count);
                if f.valid {
                    let base = index & !(CHUNK as u32 - 1);
                    chunk.dim.set(dim);
                    return chunk.store(index, count, &fast(&f, &keys, base));
                }
            }
            return eval(&keys, kind, index, &self.strata(count));
        };
        let set = &set;
        let kind = self.pattern.kind;
        if index >= count {
            return eval(set, kind, index, &self.strata(count));
        }
        let base = index & !(CHUNK as u32 - 1);
        let f = if kind == PatternKind::Stratified {
            self.fast(count)
        } else {
            FastStrata::NONE
        };
        let v = if f.valid {
            fast(&f, set, base)
        } else {
            // Every other pattern and count: the general evaluation, batched the same way.
            let st = self.strata(count);
            let len = (count - base).min(CHUNK as u32) as usize;
            let batch = |kind| {
                let mut v = [T::default(); CHUNK];
                for (k, o) in v.iter_mut().enumerate().take(len) {
                    *o = eval(set, kind, base + k as u32, &st);
                }
                v
            };
            // One loop per kind, so that each loop body is that kind's arithmetic only.
            match kind {
                PatternKind::Fixed => batch(PatternKind::Fixed),
                PatternKind::Random => batch(PatternKind::Random),
                PatternKind::Grid => batch(PatternKind::Grid),
                PatternKind::Stratified => batch(PatternKind::Stratified),
                PatternKind::Lhs => batch(PatternKind::Lhs),
                PatternKind::Sobol => batch(PatternKind::Sobol),
            }
        };
        chunks[dim as usize].store(index, count, &v)
    }
}

/// What [`PixelSamples::miss`] needs of one request and of its dimension count (1D or 2D):
/// the request, which kind of set, the per-index evaluation and the fast chunk.
struct Arity<E, F> {
    dim: u32,
    index: u32,
    count: u32,
    /// 0: a 1D set, 1: a 2D set.
    arity: usize,
    eval: E,
    fast: F,
}

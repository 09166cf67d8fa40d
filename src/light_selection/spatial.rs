//! Spatial light selection: a uniform grid over the scene's bounds; each cell holds a table of
//! the lights most important to *any* point in the cell, using the conservative bound
//! [`importance_sphere`] of the cell's bounding sphere (distance, emission cone, subtended angle;
//! the receiver's normal is unknown at that level, so no cosine term).
//!
//! Cells are built lazily on first use, each in a `OnceLock`: the table is a pure function of
//! the cell, so whichever thread builds it, the result (and the image) is the same.
//!
//! Each cell keeps its [`SpatialConfig::max_lights`] most important lights. Unbiasedness: every
//! other light — and any light the bound misjudges — keeps probability through defensive
//! mixing with power selection, p = α·p_Φ + (1 − α)·p_cell with α = [`SpatialConfig::alpha`],
//! raised in cells where the left-out lights carry more than α of the bound. α is 0 by
//! default because `make_selector` mixes the grid with power selection again at a probed
//! share of at least 10 % ([`super::defensive`]): that is the floor every light keeps.

use super::importance::importance_sphere;
use super::power::PowerSelector;
use super::{FiniteSelector, LightSet, ONE_MINUS_EPS, ShadingPoint};
use crate::lights::LightBounds;
use crate::sampling::AliasTable;
use crate::scene::Scene;
use glam::{UVec3, Vec3};
use std::sync::OnceLock;

/// Parameters of the grid.
#[derive(Clone, Debug)]
pub struct SpatialConfig {
    /// Approximate number of cells (cells are near-cubic).
    pub cells: u32,
    /// Lights kept per cell.
    pub max_lights: usize,
    /// Share α of power selection mixed in everywhere (0 by default: see the module doc).
    pub alpha: f32,
}

impl Default for SpatialConfig {
    fn default() -> Self {
        Self {
            cells: 4096,
            max_lights: 512,
            alpha: 0.0,
        }
    }
}

/// A uniform grid of near-cubic cells over a box.
#[derive(Clone, Debug)]
pub struct Grid {
    lo: Vec3,
    size: Vec3,
    dims: UVec3,
}

impl Grid {
    /// About `target` cells over [lo, hi].
    pub fn new(lo: Vec3, hi: Vec3, target: u32) -> Self {
        let ext = (hi - lo).max(Vec3::splat(1e-6));
        // Edge of a cube cell: volume / target, ignoring flat axes (one cell thick).
        let flat = ext.cmplt(Vec3::splat(ext.max_element() * 1e-3));
        let mut vol = 1.0f64;
        let mut axes = 0;
        for a in 0..3 {
            if !flat.test(a) {
                vol *= ext[a] as f64;
                axes += 1;
            }
        }
        let edge = (vol / target.max(1) as f64).powf(1.0 / axes.max(1) as f64) as f32;
        let dims = UVec3::new(
            if flat.x {
                1
            } else {
                (ext.x / edge).ceil().clamp(1.0, 256.0) as u32
            },
            if flat.y {
                1
            } else {
                (ext.y / edge).ceil().clamp(1.0, 256.0) as u32
            },
            if flat.z {
                1
            } else {
                (ext.z / edge).ceil().clamp(1.0, 256.0) as u32
            },
        );
        Self {
            lo,
            size: ext / dims.as_vec3(),
            dims,
        }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        (self.dims.x * self.dims.y * self.dims.z) as usize
    }

    /// True if the grid has no cells (never: at least one).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Cell containing `p` (points outside are clamped to the nearest cell; NaN to cell 0).
    pub fn cell(&self, p: Vec3) -> usize {
        let c = ((p - self.lo) / self.size).floor();
        let clamp = |x: f32, d: u32| if x >= 0.0 { (x as u32).min(d - 1) } else { 0 };
        let (x, y, z) = (
            clamp(c.x, self.dims.x),
            clamp(c.y, self.dims.y),
            clamp(c.z, self.dims.z),
        );
        ((z * self.dims.y + y) * self.dims.x + x) as usize
    }

    /// Centre and bounding-sphere radius of cell `i`.
    pub fn sphere(&self, i: usize) -> (Vec3, f32) {
        let i = i as u32;
        let x = i % self.dims.x;
        let y = (i / self.dims.x) % self.dims.y;
        let z = i / (self.dims.x * self.dims.y);
        let lo = self.lo + UVec3::new(x, y, z).as_vec3() * self.size;
        (lo + 0.5 * self.size, 0.5 * self.size.length())
    }
}

/// The lights of one cell, sorted by index, and an alias table over their weights.
#[derive(Clone, Debug, Default)]
pub struct CellTable {
    ids: Vec<u32>,
    table: Option<AliasTable>,
    /// Fraction of the cell's total bound carried by lights left out of the table.
    pub rest: f32,
}

impl CellTable {
    /// A table ∝ `weights[i]` over lights `ids[i]`; pairs must be sorted by id.
    pub fn new(ids: Vec<u32>, weights: &[f32]) -> Self {
        let table = if ids.is_empty() {
            None
        } else {
            AliasTable::new(weights)
        };
        Self {
            ids,
            table,
            rest: 0.0,
        }
    }

    /// True if the table can be sampled.
    pub fn is_usable(&self) -> bool {
        self.table.is_some()
    }

    /// Pick a light of the table.
    pub fn pick(&self, u: f32) -> Option<(u32, f32)> {
        let (k, p) = self.table.as_ref()?.sample(u);
        Some((self.ids[k], p))
    }

    /// Probability of `light` in the table.
    pub fn prob(&self, light: u32) -> f32 {
        match (&self.table, self.ids.binary_search(&light)) {
            (Some(t), Ok(k)) => t.pmf(k),
            _ => 0.0,
        }
    }

    /// Number of lights in the table.
    pub fn len(&self) -> usize {
        self.ids.len()
    }

    /// True if empty.
    pub fn is_empty(&self) -> bool {
        self.ids.is_empty()
    }
}

/// Grid of per-cell tables with a power floor.
pub struct SpatialSelector {
    grid: Grid,
    cells: Vec<OnceLock<CellTable>>,
    bounds: Vec<LightBounds>,
    power: PowerSelector,
    cfg: SpatialConfig,
}

impl SpatialSelector {
    /// The grid over `scene`'s geometry and lights, with default parameters.
    pub fn new(scene: &Scene, set: &LightSet) -> Self {
        Self::with_config(scene, set, SpatialConfig::default())
    }

    /// The grid with explicit parameters.
    pub fn with_config(scene: &Scene, set: &LightSet, cfg: SpatialConfig) -> Self {
        let (mut lo, mut hi) = scene.geometry.bounds();
        for b in &set.bounds {
            lo = lo.min(b.min);
            hi = hi.max(b.max);
        }
        if !(lo.x <= hi.x && lo.is_finite() && hi.is_finite()) {
            (lo, hi) = (Vec3::splat(-1.0), Vec3::ONE);
        }
        let grid = Grid::new(lo, hi, cfg.cells);
        let cells = (0..grid.len()).map(|_| OnceLock::new()).collect();
        Self {
            grid,
            cells,
            bounds: set.bounds.clone(),
            power: PowerSelector::new(&set.bounds),
            cfg,
        }
    }

    /// The grid.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The table of cell `i`, built on first use.
    pub fn table(&self, i: usize) -> &CellTable {
        self.cells[i].get_or_init(|| self.build_cell(i))
    }

    fn build_cell(&self, i: usize) -> CellTable {
        let (c, r) = self.grid.sphere(i);
        cell_table(c, r, &self.bounds, self.cfg.max_lights)
    }

    /// Share of power selection in a cell: α, or more when the lights left out of the table
    /// carry more of the cell's bound (they are reached through power selection); all of it if
    /// the table is empty.
    fn alpha(&self, t: &CellTable) -> f32 {
        if t.is_usable() {
            self.cfg.alpha.max(t.rest.min(0.9))
        } else {
            1.0
        }
    }
}

/// The table of a cell with bounding sphere (`c`, `r`): its `max_lights` most important of
/// `bounds` by [`importance_sphere`], and the share of the cell's total bound left out.
fn cell_table(c: Vec3, r: f32, bounds: &[LightBounds], max_lights: usize) -> CellTable {
    let mut w: Vec<(u32, f32)> = bounds
        .iter()
        .enumerate()
        .map(|(l, b)| (l as u32, importance_sphere(c, r, Vec3::ZERO, b)))
        .filter(|&(_, w)| w > 0.0)
        .collect();
    let k = max_lights.max(1);
    let total: f64 = w.iter().map(|&(_, x)| x as f64).sum();
    if w.len() > k {
        w.select_nth_unstable_by(k, |a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        w.truncate(k);
    }
    let kept: f64 = w.iter().map(|&(_, x)| x as f64).sum();
    w.sort_unstable_by_key(|&(l, _)| l);
    let weights: Vec<f32> = w.iter().map(|&(_, x)| x).collect();
    // `iter`, not `into_iter`: collecting from `into_iter` reuses the candidate list's buffer
    // (all the scene's lights) and the cell would keep it for the whole render.
    let ids: Vec<u32> = w.iter().map(|&(l, _)| l).collect();
    let mut t = CellTable::new(ids, &weights);
    t.rest = if total > 0.0 {
        (1.0 - kept / total) as f32
    } else {
        0.0
    };
    t
}

impl FiniteSelector for SpatialSelector {
    fn sample(&self, ctx: &ShadingPoint, u: f32) -> Option<(u32, f32)> {
        let t = self.table(self.grid.cell(ctx.p));
        let a = self.alpha(t);
        let (i, _) = if u < a {
            self.power.pick(u / a)?
        } else {
            t.pick(((u - a) / (1.0 - a)).min(ONE_MINUS_EPS))?
        };
        Some((i, a * self.power.prob(i) + (1.0 - a) * t.prob(i)))
    }

    fn pmf(&self, ctx: &ShadingPoint, i: u32) -> f32 {
        let t = self.table(self.grid.cell(ctx.p));
        let a = self.alpha(t);
        a * self.power.prob(i) + (1.0 - a) * t.prob(i)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cell keeps at most `max_lights` ids, and must not keep the memory of the candidate
    /// list it chose them from: with a million lights that list is 8 MB per cell, and a render
    /// that touches a few thousand cells ran out of memory (> 9 GB at 160×120, 8 spp).
    #[test]
    fn cell_table_holds_no_more_memory_than_its_lights() {
        let bounds: Vec<LightBounds> = (0..20_000)
            .map(|i| {
                let p = Vec3::new((i % 200) as f32, (i / 200) as f32, 1.0);
                LightBounds {
                    min: p,
                    max: p + 0.01,
                    w: Vec3::NEG_Z,
                    phi: 1.0 + (i % 7) as f32,
                    cos_theta_o: 1.0,
                    cos_theta_e: 0.0,
                    two_sided: false,
                }
            })
            .collect();
        let t = cell_table(Vec3::new(100.0, 50.0, 0.0), 1.0, &bounds, 512);
        assert_eq!(t.len(), 512);
        assert!(
            t.ids.capacity() <= 2 * t.len(),
            "a cell of {} lights keeps room for {}",
            t.len(),
            t.ids.capacity()
        );
    }
}

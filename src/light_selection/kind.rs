//! The light-selection strategies by name: [`SelectorKind`], parsed once from
//! `--light-selection` (or a lab panel) and carried typed from there on.

use std::fmt;
use std::str::FromStr;

/// A light-selection strategy, one per file of `light_selection`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SelectorKind {
    /// Every light with probability 1/N.
    Uniform,
    /// Proportional to emitted power (alias table).
    Power,
    /// A grid of per-cell tables built from conservative bounds.
    Spatial,
    /// The spatial grid, trained per cell by eye rays.
    Adaptive,
    /// The spatial grid, trained per cell while the image renders, separately for camera-ray
    /// hits and later path vertices (`online.rs`).
    Online,
    /// One global distribution estimated from low-resolution eye rays (Wald et al. 2003).
    Wald,
    /// Light BVH with bounds and emission cones (Conty Estevez & Kulla 2018, pbrt-v4).
    Bvh,
    /// Every light's importance at every shading point, O(N): the yardstick.
    Exhaustive,
    /// Resampled importance sampling of K power-sampled candidates (`ris` or `ris:K`).
    Ris {
        /// K, the candidates per selection.
        candidates: u32,
    },
    /// Resampled importance sampling of K light-BVH-sampled candidates (`ris-bvh` or
    /// `ris-bvh:K`).
    RisBvh {
        /// K, the candidates per selection.
        candidates: u32,
    },
}

impl SelectorKind {
    /// Every strategy, in CLI order.
    pub const ALL: [SelectorKind; 10] = [
        SelectorKind::Uniform,
        SelectorKind::Power,
        SelectorKind::Spatial,
        SelectorKind::Adaptive,
        SelectorKind::Online,
        SelectorKind::Wald,
        SelectorKind::Bvh,
        SelectorKind::Exhaustive,
        SelectorKind::RIS,
        SelectorKind::RIS_BVH,
    ];

    /// `ris` with its default K.
    pub const RIS: SelectorKind = SelectorKind::Ris {
        candidates: super::ris::DEFAULT_CANDIDATES,
    };

    /// `ris-bvh` with its default K.
    pub const RIS_BVH: SelectorKind = SelectorKind::RisBvh {
        candidates: super::ris_bvh::DEFAULT_CANDIDATES,
    };

    /// Whether `sample`'s pmf is the exact probability of its choice (all but `ris` and
    /// `ris-bvh`, which return RIS's 1/W, and a deterministic `mis_pmf` for MIS: see `ris.rs`).
    pub fn exact_pmf(self) -> bool {
        !matches!(self, SelectorKind::Ris { .. } | SelectorKind::RisBvh { .. })
    }

    /// The selector used wherever none is named (`penumbra render`, `bench`, the lab,
    /// `RenderOptions::default()`, pbrt files): the light BVH, as in pbrt-v4. Over the built-in
    /// scenes it is the most efficient on average of uniform, power and bvh and never
    /// catastrophic (power and uniform lose 10-50× on spread-out and occluded light sets), and
    /// unlike the spatial grid it scales as O(log N) (docs/many-lights.md has the table).
    pub const DEFAULT: SelectorKind = SelectorKind::Bvh;

    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            SelectorKind::Uniform => "uniform",
            SelectorKind::Power => "power",
            SelectorKind::Spatial => "spatial",
            SelectorKind::Adaptive => "adaptive",
            SelectorKind::Online => "online",
            SelectorKind::Wald => "wald",
            SelectorKind::Bvh => "bvh",
            SelectorKind::Exhaustive => "exhaustive",
            SelectorKind::Ris { .. } => "ris",
            SelectorKind::RisBvh { .. } => "ris-bvh",
        }
    }
}

impl Default for SelectorKind {
    fn default() -> Self {
        Self::DEFAULT
    }
}

impl fmt::Display for SelectorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            SelectorKind::Ris { candidates } if candidates != super::ris::DEFAULT_CANDIDATES => {
                write!(f, "ris:{candidates}")
            }
            SelectorKind::RisBvh { candidates }
                if candidates != super::ris_bvh::DEFAULT_CANDIDATES =>
            {
                write!(f, "ris-bvh:{candidates}")
            }
            k => f.write_str(k.name()),
        }
    }
}

impl FromStr for SelectorKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        type Make = fn(u32) -> SelectorKind;
        let with_k: [(&str, Make); 2] = [
            ("ris", |candidates| SelectorKind::Ris { candidates }),
            ("ris-bvh", |candidates| SelectorKind::RisBvh { candidates }),
        ];
        for (name, make) in with_k {
            if let Some(k) = s
                .trim()
                .strip_prefix(name)
                .and_then(|r| r.strip_prefix(':'))
            {
                return match k.parse::<u32>() {
                    Ok(k) if (1..=super::ris::MAX_CANDIDATES).contains(&k) => Ok(make(k)),
                    _ => Err(format!(
                        "bad light selection '{s}': {name}:K needs 1 <= K <= {}",
                        super::ris::MAX_CANDIDATES
                    )),
                };
            }
        }
        Self::ALL
            .into_iter()
            .find(|k| k.name() == s.trim())
            .ok_or_else(|| {
                let names: Vec<&str> = Self::ALL.iter().map(|k| k.name()).collect();
                format!(
                    "unknown light selection '{s}' (expected one of: {})",
                    names.join(", ")
                )
            })
    }
}

//! Drawing a routine's samples and testing them with the chi-square harness of
//! [`crate::sampling::chi2`] — the same functions, grid and seed handling as the test suite.

use glam::{UVec2, Vec2, Vec3};

use super::registry::{Domain, Warp};
use crate::sampling::chi2::{
    Chi2Config, Chi2Result, chi2_directions, chi2_directions_from, chi2_points, chi2_points_from,
};
use crate::sampling::{PatternKind, make_pattern};

/// How to draw and test samples.
#[derive(Clone, Debug, PartialEq)]
pub struct RunConfig {
    /// Sampling attempts.
    pub count: usize,
    /// Seed of the harness's PCG stream, or of the pattern.
    pub seed: u64,
    /// `None`: the harness's own independent stream (exactly what the tests draw); otherwise
    /// the 2D points come from this pattern (pixel 0, dimension 0, index i of `count`).
    pub pattern: Option<PatternKind>,
    /// Significance level α of the test.
    pub significance: f64,
    /// Histogram grid; `None`: [`default_res`].
    pub res: Option<(usize, usize)>,
}

impl Default for RunConfig {
    fn default() -> Self {
        Self {
            count: 200_000,
            seed: Chi2Config::default().seed,
            pattern: None,
            significance: Chi2Config::default().significance,
            res: None,
        }
    }
}

/// The histogram grid the tests use for this kind of domain: (cos θ, φ) cells on the sphere,
/// (x, y) cells on the plane.
pub fn default_res(domain: Domain) -> (usize, usize) {
    match domain {
        Domain::Sphere => (32, 64),
        Domain::Plane { .. } => (32, 32),
    }
}

/// The harness configuration for `warp` under `cfg` (one test, no Šidák correction).
pub fn chi2_config(warp: &Warp, cfg: &RunConfig) -> Chi2Config {
    Chi2Config {
        samples: cfg.count,
        res: cfg.res.unwrap_or_else(|| default_res(warp.domain)),
        significance: cfg.significance,
        num_tests: 1,
        seed: cfg.seed,
        ..Chi2Config::default()
    }
}

/// Samples drawn and the harness's verdict on them.
#[derive(Clone, Debug)]
pub struct RunResult {
    /// Accepted samples (unit directions, or (x, y, 0) points), in drawing order.
    pub samples: Vec<Vec3>,
    /// Sampling attempts (rejected ones included).
    pub attempts: usize,
    /// The chi-square test.
    pub chi2: Chi2Result,
    /// Whether the samples are independent, as the chi-square test assumes.
    pub independent: bool,
}

impl RunResult {
    /// Fail when there were too few samples for the test to say anything: once the sparse
    /// cells are pooled, fewer than two categories are left, no degrees of freedom, and a
    /// "pass" would test nothing. (A rejection with 0 dof, e.g. samples outside the support,
    /// stays a rejection.) The suggestion fills every cell with the harness's minimum.
    pub fn check_enough_samples(&self) -> anyhow::Result<()> {
        let c = &self.chi2;
        if c.dof == 0 && c.passed {
            let cells = c.res.0 * c.res.1;
            let min = Chi2Config::default().min_expected;
            anyhow::bail!(
                "too few samples for a chi-square test: {} attempts over {}x{} cells leave 0 \
                 degrees of freedom once cells expecting fewer than {min} samples are pooled; \
                 use --count {} or more (or a coarser --res)",
                self.attempts,
                c.res.0,
                c.res.1,
                (cells as f64 * min).ceil() as usize
            );
        }
        Ok(())
    }
}

/// Draw `cfg.count` samples of `warp` and run the chi-square test on them.
///
/// Without a pattern the sampler is driven by the harness itself (`chi2_directions` /
/// `chi2_points`, with `uc = u[0]`, `u = (u[1], u[2])` as in tests/bsdf_chi2.rs), so the
/// statistic is exactly the one a test with the same seed gets.
pub fn run(warp: &Warp, cfg: &RunConfig) -> RunResult {
    let c = chi2_config(warp, cfg);
    let mut samples = Vec::new();
    let chi2 = match cfg.pattern {
        None => {
            let mut draw = |u: [f32; 3]| {
                let s = warp.sample(u[0], Vec2::new(u[1], u[2]));
                samples.extend(s);
                s
            };
            match warp.domain {
                Domain::Sphere => chi2_directions(&c, draw, |d| warp.pdf(d)),
                Domain::Plane { rect, .. } => chi2_points(
                    &c,
                    rect,
                    |u| draw(u).map(Vec3::truncate),
                    |p| warp.pdf(p.extend(0.0)),
                ),
            }
        }
        Some(kind) => {
            samples = pattern_samples(warp, kind, cfg.seed, cfg.count);
            test_samples(warp, &c, &samples, cfg.count)
        }
    };
    RunResult {
        samples,
        attempts: cfg.count,
        chi2,
        independent: matches!(cfg.pattern, None | Some(PatternKind::Random)),
    }
}

/// The accepted samples of `count` attempts whose inputs come from pattern `kind`: sample i
/// warps the 2D point `(pixel 0, dim 0, i, count)` and uses the 1D value of the same index.
pub fn pattern_samples(warp: &Warp, kind: PatternKind, seed: u64, count: usize) -> Vec<Vec3> {
    let pattern = make_pattern(kind, seed);
    let n = u32::try_from(count).unwrap_or(u32::MAX);
    (0..n)
        .filter_map(|i| {
            let uc = pattern.sample_1d(UVec2::ZERO, 0, i, n);
            warp.sample(uc, pattern.sample_2d(UVec2::ZERO, 0, i, n))
        })
        .collect()
}

/// Chi-square test of pre-drawn samples of `warp` out of `attempts` draws.
pub fn test_samples(warp: &Warp, c: &Chi2Config, samples: &[Vec3], attempts: usize) -> Chi2Result {
    match warp.domain {
        Domain::Sphere => chi2_directions_from(c, samples, attempts, |d| warp.pdf(d)),
        Domain::Plane { rect, .. } => {
            let points: Vec<Vec2> = samples.iter().map(|s| s.truncate()).collect();
            chi2_points_from(c, rect, &points, attempts, |p| warp.pdf(p.extend(0.0)))
        }
    }
}

/// Evaluate the pdf of `warp` at each row of `points` (directions are normalised first; a
/// zero or non-finite row gets density 0). Rows must have `warp.dim()` columns.
pub fn pdf_at(warp: &Warp, cols: usize, points: &[f32]) -> anyhow::Result<Vec<f64>> {
    if cols != warp.dim() {
        anyhow::bail!(
            "{} samples have {} coordinates per row, but the file has {cols}",
            warp.name,
            warp.dim()
        );
    }
    Ok(points
        .chunks_exact(cols)
        .map(|r| {
            let x = match warp.domain {
                Domain::Sphere => Vec3::new(r[0], r[1], r[2]).try_normalize(),
                Domain::Plane { .. } => Some(Vec3::new(r[0], r[1], 0.0)).filter(|p| p.is_finite()),
            };
            x.map_or(0.0, |x| warp.pdf(x))
        })
        .collect())
}

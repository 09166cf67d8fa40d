//! Chi-square goodness-of-fit harness: histogram samples of a warp on a grid over its domain,
//! integrate its pdf over each cell, pool sparse cells, and compute a p-value (statrs).
//! Used by the test suite and by `penumbra warp`.
//!
//! The test is a multinomial one over `attempts` draws: every grid cell is a category, plus one
//! "nowhere" category for samples that returned `None` or fell outside the domain, whose expected
//! probability is `1 − ∫pdf`. A pdf that integrates to an albedo below 1 is therefore tested
//! correctly, and a warp that silently loses samples is caught.

use glam::{Vec2, Vec3};
use statrs::distribution::{ChiSquared, ContinuousCDF};
use std::f64::consts::TAU;

use super::hash::{next_f32, pcg_from_keys};

/// Parameters of one chi-square test.
#[derive(Clone, Debug, PartialEq)]
pub struct Chi2Config {
    /// Number of sampling attempts.
    pub samples: usize,
    /// Grid cells (first coordinate, second coordinate): (cos θ, φ) for directions, (x, y) for points.
    pub res: (usize, usize),
    /// Cells with an expected count below this are pooled together.
    pub min_expected: f64,
    /// Overall significance level α of the family of tests.
    pub significance: f64,
    /// Number of tests in the family (Šidák correction of α).
    pub num_tests: usize,
    /// Seed of the PCG stream that feeds the sampling closure.
    pub seed: u64,
}

impl Default for Chi2Config {
    fn default() -> Self {
        Self {
            samples: 1_000_000,
            res: (64, 128),
            min_expected: 5.0,
            significance: 0.01,
            num_tests: 1,
            seed: 0x5eed_c0ff_ee00_0001,
        }
    }
}

/// Outcome of one chi-square test.
#[derive(Clone, Debug)]
pub struct Chi2Result {
    /// Pearson's statistic Σ (O − E)² / E over the pooled cells.
    pub statistic: f64,
    /// Degrees of freedom (pooled cells − 1).
    pub dof: usize,
    /// Probability of a statistic at least this large if the pdf is right.
    pub p_value: f64,
    /// Per-test significance after the Šidák correction.
    pub alpha: f64,
    /// `p_value >= alpha`.
    pub passed: bool,
    /// Grid resolution of `observed` / `expected`.
    pub res: (usize, usize),
    /// Observed counts, row-major `res.0 × res.1`.
    pub observed: Vec<f64>,
    /// Expected counts, row-major `res.0 × res.1`.
    pub expected: Vec<f64>,
    /// Samples that returned `None` or fell outside the domain.
    pub failures: usize,
}

impl Chi2Result {
    /// One-line human summary (for assertion messages and the CLI).
    pub fn summary(&self) -> String {
        format!(
            "chi2 = {:.2}, dof = {}, p = {:.3e}, alpha = {:.3e}, failures = {}, {}",
            self.statistic,
            self.dof,
            self.p_value,
            self.alpha,
            self.failures,
            if self.passed { "PASSED" } else { "REJECTED" }
        )
    }
}

/// Per-test significance after the Šidák correction for `num_tests` tests.
pub fn sidak_alpha(significance: f64, num_tests: usize) -> f64 {
    let n = num_tests.max(1) as f64;
    1.0 - (1.0 - significance).powf(1.0 / n)
}

/// Three uniform numbers in [0,1) from the harness's PCG stream.
fn draw<T>(cfg: &Chi2Config, mut sample: impl FnMut([f32; 3]) -> Option<T>) -> (Vec<T>, usize) {
    let mut rng = pcg_from_keys(&[cfg.seed, 0xc412]);
    let mut out = Vec::with_capacity(cfg.samples);
    for _ in 0..cfg.samples {
        let u = [next_f32(&mut rng), next_f32(&mut rng), next_f32(&mut rng)];
        if let Some(s) = sample(u) {
            out.push(s);
        }
    }
    (out, cfg.samples)
}

/// Chi-square test of a direction sampler on the unit sphere against a solid-angle pdf.
pub fn chi2_directions(
    cfg: &Chi2Config,
    sample: impl FnMut([f32; 3]) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f64,
) -> Chi2Result {
    let (samples, attempts) = draw(cfg, sample);
    chi2_directions_from(cfg, &samples, attempts, pdf)
}

/// Chi-square test of a point sampler in `domain = [x0, x1, y0, y1]` against an area pdf.
pub fn chi2_points(
    cfg: &Chi2Config,
    domain: [f32; 4],
    sample: impl FnMut([f32; 3]) -> Option<Vec2>,
    pdf: impl Fn(Vec2) -> f64,
) -> Chi2Result {
    let (samples, attempts) = draw(cfg, sample);
    chi2_points_from(cfg, domain, &samples, attempts, pdf)
}

/// Chi-square test of a discrete sampler of outcomes `0..pmf.len()` against `pmf`.
pub fn chi2_discrete(
    cfg: &Chi2Config,
    pmf: &[f64],
    sample: impl FnMut([f32; 3]) -> Option<usize>,
) -> Chi2Result {
    let (samples, attempts) = draw(cfg, sample);
    let n = pmf.len();
    let mut observed = vec![0.0; n];
    let mut binned = 0usize;
    for &i in &samples {
        if i < n {
            observed[i] += 1.0;
            binned += 1;
        }
    }
    let expected = pmf.iter().map(|&p| p.max(0.0) * attempts as f64).collect();
    finish(cfg, (1, n), observed, expected, attempts, binned)
}

/// Chi-square test of pre-drawn unit directions (`attempts` ≥ `samples.len()` draws).
pub fn chi2_directions_from(
    cfg: &Chi2Config,
    samples: &[Vec3],
    attempts: usize,
    pdf: impl Fn(Vec3) -> f64,
) -> Chi2Result {
    let (nz, nphi) = (cfg.res.0.max(1), cfg.res.1.max(1));
    let mut observed = vec![0.0; nz * nphi];
    let mut binned = 0usize;
    for &d in samples {
        // A direction that is not unit length is a bug in the warp, not a rounding artefact.
        if !d.is_finite() || (d.length_squared() - 1.0).abs() > 1e-3 {
            continue;
        }
        let d = d.as_dvec3().normalize();
        let iz = (((d.z + 1.0) * 0.5 * nz as f64) as usize).min(nz - 1);
        let mut phi = d.y.atan2(d.x);
        if phi < 0.0 {
            phi += TAU;
        }
        let iphi = ((phi / TAU * nphi as f64) as usize).min(nphi - 1);
        observed[iz * nphi + iphi] += 1.0;
        binned += 1;
    }
    // dω = dz dφ, so the (z, φ) parametrisation needs no Jacobian.
    let f = |z: f64, phi: f64| {
        let s = (1.0 - z * z).max(0.0).sqrt();
        let d = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32);
        pdf(d)
    };
    let expected = tabulate(cfg, [-1.0, 1.0, 0.0, TAU], attempts, &observed, f);
    finish(cfg, (nz, nphi), observed, expected, attempts, binned)
}

/// Chi-square test of pre-drawn points in `domain = [x0, x1, y0, y1]`.
pub fn chi2_points_from(
    cfg: &Chi2Config,
    domain: [f32; 4],
    samples: &[Vec2],
    attempts: usize,
    pdf: impl Fn(Vec2) -> f64,
) -> Chi2Result {
    let (nx, ny) = (cfg.res.0.max(1), cfg.res.1.max(1));
    let [x0, x1, y0, y1] = domain.map(f64::from);
    let mut observed = vec![0.0; nx * ny];
    let mut binned = 0usize;
    for &p in samples {
        let (x, y) = (p.x as f64, p.y as f64);
        if !(x >= x0 && x <= x1 && y >= y0 && y <= y1) {
            continue;
        }
        let ix = (((x - x0) / (x1 - x0) * nx as f64) as usize).min(nx - 1);
        let iy = (((y - y0) / (y1 - y0) * ny as f64) as usize).min(ny - 1);
        observed[ix * ny + iy] += 1.0;
        binned += 1;
    }
    let f = |x: f64, y: f64| pdf(Vec2::new(x as f32, y as f32));
    let expected = tabulate(cfg, [x0, x1, y0, y1], attempts, &observed, f);
    finish(cfg, (nx, ny), observed, expected, attempts, binned)
}

/// 4-point Gauss–Legendre nodes and weights on [-1, 1].
const GL_X: [f64; 4] = [
    -0.861_136_311_594_052_6,
    -0.339_981_043_584_856_3,
    0.339_981_043_584_856_3,
    0.861_136_311_594_052_6,
];
const GL_W: [f64; 4] = [
    0.347_854_845_137_453_9,
    0.652_145_154_862_546_1,
    0.652_145_154_862_546_1,
    0.347_854_845_137_453_9,
];

/// Most halvings of a cell (each along one axis). Along a pdf discontinuity the residual
/// error then falls far below the Poisson noise of a 1M-sample histogram.
const MAX_SPLITS: u32 = 20;

/// Quadrature of one rectangle: the integral, whether the pdf vanishes at some of the
/// probed points but not at others (the rectangle straddles the edge of the support), and
/// the largest probed value times the area (what a straddling estimate can be off by).
#[derive(Clone, Copy)]
struct Piece {
    integral: f64,
    straddles: bool,
    bound: f64,
}

/// Tensor Gauss–Legendre rule on a rectangle, plus a probe of its corners: a support edge
/// hiding between the Gauss nodes and the rectangle's border is then still noticed.
fn gauss(f: &impl Fn(f64, f64) -> f64, r: [f64; 4]) -> Piece {
    let (cx, hx) = (0.5 * (r[0] + r[1]), 0.5 * (r[1] - r[0]));
    let (cy, hy) = (0.5 * (r[2] + r[3]), 0.5 * (r[3] - r[2]));
    let (mut zero, mut positive) = (false, false);
    let mut peak = 0.0f64;
    let mut probe = |v: f64| {
        zero |= v == 0.0;
        positive |= v != 0.0;
        peak = peak.max(v.abs());
        // A NaN/inf pdf must surface as a failed test, not poison a neighbour silently.
        if v.is_finite() { v } else { f64::NAN }
    };
    let mut s = 0.0;
    for (xi, wi) in GL_X.iter().zip(GL_W) {
        let mut row = 0.0;
        for (yj, wj) in GL_X.iter().zip(GL_W) {
            row += wj * probe(f(cx + hx * xi, cy + hy * yj));
        }
        s += wi * row;
    }
    for (x, y) in [(r[0], r[2]), (r[1], r[2]), (r[0], r[3]), (r[1], r[3])] {
        probe(f(x, y));
    }
    Piece {
        integral: s * hx * hy,
        straddles: zero && positive,
        bound: peak * 4.0 * hx * hy,
    }
}

/// Anisotropic adaptive quadrature: try halving along each axis, keep the halving that
/// changes the estimate most, and recurse until the change is below `tol` and the piece no
/// longer straddles the support's edge by more than `tol` can absorb (or the depth limit is
/// hit): a straddling piece is off by at most about its peak × area, so once that is below
/// `tol` the edge is resolved well enough (before this bound a sharp rough-glass lobe took 567M
/// pdf evaluations instead of 44M, with the same statistic). Halving only across a
/// discontinuity (e.g. the rim of a cone, a line of constant z) costs O(depth) work, where
/// isotropic splitting would need O(2^depth).
fn adaptive(f: &impl Fn(f64, f64) -> f64, r: [f64; 4], whole: Piece, tol: f64, depth: u32) -> f64 {
    if depth >= MAX_SPLITS || !whole.integral.is_finite() {
        return whole.integral;
    }
    let (mx, my) = (0.5 * (r[0] + r[1]), 0.5 * (r[2] + r[3]));
    let xs = [[r[0], mx, r[2], r[3]], [mx, r[1], r[2], r[3]]];
    let ys = [[r[0], r[1], r[2], my], [r[0], r[1], my, r[3]]];
    let xv = xs.map(|q| gauss(f, q));
    let yv = ys.map(|q| gauss(f, q));
    let err = |v: &[Piece; 2]| (v[0].integral + v[1].integral - whole.integral).abs();
    let (ex, ey) = (err(&xv), err(&yv));
    // Split where the estimate moves most; on a tie (e.g. an undetected edge), alternate.
    let along_x = if ex == ey {
        depth.is_multiple_of(2)
    } else {
        ex > ey
    };
    let (halves, vals) = if along_x { (xs, xv) } else { (ys, yv) };
    if ex.max(ey) <= tol && (!whole.straddles || 2.0 * whole.bound <= tol) {
        return vals[0].integral + vals[1].integral;
    }
    adaptive(f, halves[0], vals[0], 0.5 * tol, depth + 1)
        + adaptive(f, halves[1], vals[1], 0.5 * tol, depth + 1)
}

/// Cells re-integrated on a fine pre-split when their count looks implausible (at most).
const MAX_REFINED_CELLS: usize = 512;
/// Pre-split (per axis) of a re-integrated cell.
const REFINE_SPLIT: usize = 32;

/// Integrate `f` over cell `r` for `attempts` samples, pre-splitting it `split × split` times
/// so that features thinner than the Gauss-node spacing are found.
fn integrate_cell(f: &impl Fn(f64, f64) -> f64, r: [f64; 4], n: f64, split: usize) -> f64 {
    let (wa, wb) = ((r[1] - r[0]) / split as f64, (r[3] - r[2]) / split as f64);
    let mut total = 0.0;
    for i in 0..split {
        for j in 0..split {
            let q = [
                r[0] + i as f64 * wa,
                r[0] + (i + 1) as f64 * wa,
                r[2] + j as f64 * wb,
                r[2] + (j + 1) as f64 * wb,
            ];
            let coarse = gauss(f, q);
            // Aim for an integration error of a few percent of the Poisson deviation.
            let tol = 0.02 * (coarse.integral.abs() * n).max(1.0).sqrt() / n / split as f64;
            total += adaptive(f, q, coarse, tol, 0);
        }
    }
    total
}

/// Expected counts `attempts × ∫cell pdf` on a `res` grid over `dom = [a0, a1, b0, b1]`.
///
/// Adaptive quadrature can step over a support sliver thinner than its node spacing, which
/// then looks like samples where the pdf claims no mass. So cells whose observed count is
/// implausible under the first estimate are integrated again on a much finer pre-split. This
/// only makes the quadrature more accurate (it still integrates the given pdf), so it cannot
/// hide a wrong pdf: where the pdf truly has no mass, the refined value stays zero.
fn tabulate(
    cfg: &Chi2Config,
    dom: [f64; 4],
    attempts: usize,
    observed: &[f64],
    f: impl Fn(f64, f64) -> f64,
) -> Vec<f64> {
    let (na, nb) = (cfg.res.0.max(1), cfg.res.1.max(1));
    let n = attempts.max(1) as f64;
    let (da, db) = ((dom[1] - dom[0]) / na as f64, (dom[3] - dom[2]) / nb as f64);
    let cell = |k: usize| {
        let (i, j) = (k / nb, k % nb);
        [
            dom[0] + i as f64 * da,
            dom[0] + (i + 1) as f64 * da,
            dom[2] + j as f64 * db,
            dom[2] + (j + 1) as f64 * db,
        ]
    };
    let mut out: Vec<f64> = (0..na * nb)
        .map(|k| n * integrate_cell(&f, cell(k), n, 1))
        .collect();
    // Suspicious cells: more than 3σ off, or samples where no mass was found.
    let mut suspects: Vec<(f64, usize)> = out
        .iter()
        .zip(observed)
        .enumerate()
        .map(|(k, (&e, &o))| ((o - e) * (o - e) / e.max(0.1), k))
        .filter(|&(score, _)| score > 9.0)
        .collect();
    suspects.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
    for &(_, k) in suspects.iter().take(MAX_REFINED_CELLS) {
        out[k] = n * integrate_cell(&f, cell(k), n, REFINE_SPLIT);
    }
    out
}

/// Pool sparse cells, add the "nowhere" category, and compute statistic and p-value.
fn finish(
    cfg: &Chi2Config,
    res: (usize, usize),
    observed: Vec<f64>,
    expected: Vec<f64>,
    attempts: usize,
    binned: usize,
) -> Chi2Result {
    let alpha = sidak_alpha(cfg.significance, cfg.num_tests);
    let failures = attempts - binned;
    let n = attempts as f64;
    let total_expected: f64 = expected.iter().sum();
    let mut cells: Vec<(f64, f64)> = observed
        .iter()
        .copied()
        .zip(expected.iter().copied())
        .collect();
    cells.push((failures as f64, (n - total_expected).max(0.0)));

    let reject = |statistic: f64, dof: usize| Chi2Result {
        statistic,
        dof,
        p_value: 0.0,
        alpha,
        passed: false,
        res,
        observed: observed.clone(),
        expected: expected.clone(),
        failures,
    };
    if cells.iter().any(|&(_, e)| !e.is_finite()) {
        return reject(f64::INFINITY, 0);
    }
    // Cells where the quadrature found no mass but samples landed are pooled like any sparse
    // cell rather than rejected outright: a sample exactly on a support boundary (a vertex
    // rounded across a cell edge) is legitimate. Real support violations still inflate the
    // pooled cell's (O − E)²/E enormously.

    // Pool sparse cells (sorted by expected count so that the pool is as small as possible).
    cells.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut pooled: Vec<(f64, f64)> = Vec::with_capacity(cells.len());
    let (mut po, mut pe) = (0.0, 0.0);
    for &(o, e) in &cells {
        if e < cfg.min_expected {
            po += o;
            pe += e;
            if pe >= cfg.min_expected {
                pooled.push((po, pe));
                (po, pe) = (0.0, 0.0);
            }
        } else {
            pooled.push((o, e));
        }
    }
    if pe > 0.0 || po > 0.0 {
        // Leftover pool too small to stand alone: merge it into the smallest regular cell.
        match pooled.iter_mut().min_by(|a, b| a.1.total_cmp(&b.1)) {
            Some(c) => {
                c.0 += po;
                c.1 += pe;
            }
            None => pooled.push((po, pe)),
        }
    }
    pooled.retain(|&(o, e)| e > 0.0 || o > 0.0);
    if pooled.iter().any(|&(o, e)| e == 0.0 && o > 0.0) {
        return reject(f64::INFINITY, 0);
    }

    let statistic: f64 = pooled.iter().map(|&(o, e)| (o - e) * (o - e) / e).sum();
    let dof = pooled.len().saturating_sub(1);
    let p_value = if dof == 0 {
        // A single category cannot disagree with itself.
        1.0
    } else {
        match ChiSquared::new(dof as f64) {
            Ok(dist) => dist.sf(statistic),
            Err(_) => 0.0,
        }
    };
    let p_value = if p_value.is_finite() { p_value } else { 0.0 };
    Chi2Result {
        statistic,
        dof,
        p_value,
        alpha,
        passed: p_value >= alpha,
        res,
        observed,
        expected,
        failures,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{
        cosine_hemisphere, cosine_hemisphere_pdf, cosine_power_hemisphere,
        cosine_power_hemisphere_pdf, uniform_hemisphere_pdf, uniform_sphere, uniform_sphere_pdf,
    };

    fn v2(u: [f32; 3]) -> Vec2 {
        Vec2::new(u[1], u[2])
    }

    #[test]
    fn chi2_harness_accepts_uniform_sphere() {
        let r = chi2_directions(
            &Chi2Config::default(),
            |u| Some(uniform_sphere(v2(u))),
            |_| uniform_sphere_pdf() as f64,
        );
        assert!(r.passed, "{}", r.summary());
        assert_eq!(r.failures, 0);
    }

    #[test]
    fn chi2_negative_cosine_vs_uniform_pdf() {
        let r = chi2_directions(
            &Chi2Config::default(),
            |u| Some(cosine_hemisphere(v2(u))),
            |d| uniform_hemisphere_pdf(d) as f64,
        );
        assert!(!r.passed, "harness failed to reject: {}", r.summary());
    }

    #[test]
    fn chi2_negative_cosine_power_10_vs_11() {
        let r = chi2_directions(
            &Chi2Config::default(),
            |u| Some(cosine_power_hemisphere(v2(u), 10.0)),
            |d| cosine_power_hemisphere_pdf(d, 11.0) as f64,
        );
        assert!(!r.passed, "harness failed to reject: {}", r.summary());
    }

    #[test]
    fn chi2_negative_lost_samples() {
        // A warp that silently drops 1% of samples while its pdf claims unit mass must fail.
        let r = chi2_directions(
            &Chi2Config::default(),
            |u| (u[0] >= 0.01).then(|| cosine_hemisphere(v2(u))),
            |d| cosine_hemisphere_pdf(d) as f64,
        );
        assert!(!r.passed, "harness failed to reject: {}", r.summary());
        assert!(r.failures > 9_000 && r.failures < 11_000, "{}", r.failures);
    }

    #[test]
    fn chi2_albedo_below_one_is_accepted() {
        // Rejecting 30% of samples and scaling the pdf by 0.7 is a valid sub-stochastic sampler.
        let r = chi2_directions(
            &Chi2Config::default(),
            |u| (u[0] < 0.7).then(|| cosine_hemisphere(v2(u))),
            |d| 0.7 * cosine_hemisphere_pdf(d) as f64,
        );
        assert!(r.passed, "{}", r.summary());
    }

    #[test]
    fn chi2_negative_sample_outside_support() {
        // Samples on the lower hemisphere where the pdf is zero must be rejected outright.
        let r = chi2_directions(
            &Chi2Config {
                samples: 100_000,
                ..Default::default()
            },
            |u| {
                let d = cosine_hemisphere(v2(u));
                Some(if u[0] < 0.001 { -d } else { d })
            },
            |d| cosine_hemisphere_pdf(d) as f64,
        );
        assert!(!r.passed, "{}", r.summary());
    }

    #[test]
    fn chi2_points_and_discrete_accept_and_reject() {
        let cfg = Chi2Config {
            res: (32, 32),
            ..Default::default()
        };
        // Density 2x on [0,1]²·(x only): x = sqrt(u).
        let good = chi2_points(
            &cfg,
            [0.0, 1.0, 0.0, 1.0],
            |u| Some(Vec2::new(u[1].sqrt(), u[2])),
            |p| 2.0 * p.x as f64,
        );
        assert!(good.passed, "{}", good.summary());
        let bad = chi2_points(
            &cfg,
            [0.0, 1.0, 0.0, 1.0],
            |u| Some(Vec2::new(u[1], u[2])),
            |p| 2.0 * p.x as f64,
        );
        assert!(!bad.passed, "{}", bad.summary());

        let pmf = [0.5, 0.25, 0.125, 0.125];
        let pick = |u: f32, p: &[f64]| {
            let mut c = 0.0;
            for (i, &pi) in p.iter().enumerate() {
                c += pi;
                if (u as f64) < c {
                    return i;
                }
            }
            p.len() - 1
        };
        let good = chi2_discrete(&cfg, &pmf, |u| Some(pick(u[0], &pmf)));
        assert!(good.passed, "{}", good.summary());
        let wrong = [0.49, 0.26, 0.125, 0.125];
        let bad = chi2_discrete(&cfg, &pmf, |u| Some(pick(u[0], &wrong)));
        assert!(!bad.passed, "{}", bad.summary());
    }

    #[test]
    fn chi2_sidak_correction() {
        assert!((sidak_alpha(0.01, 1) - 0.01).abs() < 1e-15);
        let a = sidak_alpha(0.01, 10);
        assert!((1.0 - (1.0 - a).powi(10) - 0.01).abs() < 1e-12);
    }

    #[test]
    fn chi2_deterministic() {
        let cfg = Chi2Config {
            samples: 10_000,
            ..Default::default()
        };
        let run = || {
            chi2_directions(
                &cfg,
                |u| Some(cosine_hemisphere(v2(u))),
                |d| cosine_hemisphere_pdf(d) as f64,
            )
        };
        let (a, b) = (run(), run());
        assert_eq!(a.statistic.to_bits(), b.statistic.to_bits());
        assert_eq!(a.observed, b.observed);
    }
}

//! Piecewise-constant 1D distribution on [0, 1), sampled by inverting its CDF (binary search).
//! Doubles as the "CDF + binary search" discrete distribution (see [`Distribution1D::sample_discrete`]).

use super::ONE_MINUS_EPSILON;
use super::error::{SamplingError, check_weights};

/// Piecewise-constant density over [0,1) with `n` equal bins proportional to `f`.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    /// The (non-negative) function values, one per bin.
    pub func: Vec<f32>,
    /// CDF at the n+1 bin edges (cdf[0] = 0, cdf[n] = 1).
    pub cdf: Vec<f32>,
    /// Integral of `func` over [0,1) (mean of the bins).
    pub integral: f32,
}

impl Distribution1D {
    /// Build from non-negative weights (all-zero weights give a uniform distribution).
    ///
    /// Never panics: negative or non-finite weights count as zero, and an empty slice gives one
    /// zero bin (uniform). Use [`Self::try_new`] to reject such input instead.
    pub fn new(f: &[f32]) -> Self {
        let func: Vec<f32> = if f.is_empty() {
            vec![0.0]
        } else {
            f.iter()
                .map(|&x| if x.is_finite() && x > 0.0 { x } else { 0.0 })
                .collect()
        };
        let n = func.len();
        // Accumulate in f64 so that long tables keep an accurate CDF.
        let mut acc = 0.0f64;
        let mut cdf64 = Vec::with_capacity(n + 1);
        cdf64.push(0.0);
        for &x in &func {
            acc += x as f64;
            cdf64.push(acc);
        }
        let cdf = if acc > 0.0 {
            cdf64.iter().map(|&c| (c / acc) as f32).collect()
        } else {
            (0..=n).map(|i| i as f32 / n as f32).collect::<Vec<_>>()
        };
        let mut cdf: Vec<f32> = cdf;
        cdf[n] = 1.0;
        Self {
            func,
            cdf,
            integral: (acc / n as f64) as f32,
        }
    }

    /// Like [`Self::new`] but rejects empty, negative, non-finite or all-zero weights.
    pub fn try_new(f: &[f32]) -> Result<Self, SamplingError> {
        check_weights(f)?;
        if !f.iter().any(|&x| x > 0.0) {
            return Err(SamplingError::ZeroSum);
        }
        Ok(Self::new(f))
    }

    /// Bin containing CDF value `u`: the last edge with cdf ≤ u, so zero-width bins are skipped.
    #[inline]
    fn find(&self, u: f32) -> usize {
        let n = self.func.len();
        self.cdf
            .partition_point(|&c| c <= u)
            .saturating_sub(1)
            .min(n - 1)
    }

    /// Sum of the weights (the pmf denominator); 0 means "uniform".
    #[inline]
    fn total(&self) -> f32 {
        self.integral * self.func.len() as f32
    }

    /// Continuous sample: (x in [0,1), pdf(x), bin index).
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let (i, _, du) = self.sample_discrete(u);
        let n = self.func.len();
        let mut x = ((i as f32 + du) / n as f32).min(ONE_MINUS_EPSILON);
        // (i + du)/n can round onto the next bin edge; step back so that pdf(x) is the density
        // of bin i, the one actually sampled.
        while x > 0.0 && self.bin_of(x) > i {
            x = f32::from_bits(x.to_bits() - 1);
        }
        while self.bin_of(x) < i {
            x = f32::from_bits(x.to_bits() + 1);
        }
        (x, self.pdf_bin(i), i)
    }

    /// Discrete sample of a bin: (index, pmf, remapped u in [0,1) for reuse).
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let u = u.clamp(0.0, ONE_MINUS_EPSILON);
        let i = self.find(u);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 {
            ((u - self.cdf[i]) / width).clamp(0.0, ONE_MINUS_EPSILON)
        } else {
            0.0
        };
        (i, self.pmf(i), du)
    }

    /// Probability of bin `i` in discrete sampling.
    pub fn pmf(&self, i: usize) -> f32 {
        let Some(&f) = self.func.get(i) else {
            return 0.0;
        };
        let total = self.total();
        if total > 0.0 {
            f / total
        } else {
            1.0 / self.func.len() as f32
        }
    }

    /// Density of bin `i` for continuous sampling.
    #[inline]
    fn pdf_bin(&self, i: usize) -> f32 {
        if self.integral > 0.0 {
            self.func[i] / self.integral
        } else {
            1.0
        }
    }

    /// Bin of x ∈ [0,1), computed exactly as [`Self::pdf`] does.
    #[inline]
    fn bin_of(&self, x: f32) -> usize {
        let n = self.func.len();
        ((x * n as f32) as usize).min(n - 1)
    }

    /// Density at x ∈ [0,1) for continuous sampling.
    pub fn pdf(&self, x: f32) -> f32 {
        if !(0.0..1.0).contains(&x) {
            return 0.0;
        }
        self.pdf_bin(self.bin_of(x))
    }

    /// Inverse of the continuous sample: the u that maps to x.
    pub fn inverse(&self, x: f32) -> f32 {
        let n = self.func.len();
        let x = x.clamp(0.0, 1.0);
        let i = ((x * n as f32) as usize).min(n - 1);
        let du = x * n as f32 - i as f32;
        (self.cdf[i] + du * (self.cdf[i + 1] - self.cdf[i])).min(ONE_MINUS_EPSILON)
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.func.len()
    }

    /// True when there are no bins.
    pub fn is_empty(&self) -> bool {
        self.func.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const W: [f32; 8] = [0.0, 3.0, 0.5, 0.0, 0.0, 9.0, 1.0, 0.25];

    #[test]
    fn distribution1d_pdf_integrates_to_one_and_pmf_sums_to_one() {
        let d = Distribution1D::new(&W);
        let m = 80_000;
        let integral: f64 = (0..m)
            .map(|k| d.pdf((k as f32 + 0.5) / m as f32) as f64)
            .sum::<f64>()
            / m as f64;
        assert!((integral - 1.0).abs() < 1e-5, "{integral}");
        let s: f32 = (0..d.len()).map(|i| d.pmf(i)).sum();
        assert!((s - 1.0).abs() < 1e-6);
        assert_eq!(d.pmf(1), 3.0 / 13.75);
        assert_eq!(d.pmf(99), 0.0);
    }

    #[test]
    fn distribution1d_never_samples_zero_bins_and_inverts() {
        let d = Distribution1D::new(&W);
        for k in 0..10_000 {
            let u = k as f32 / 10_000.0;
            let (x, pdf, i) = d.sample_continuous(u);
            assert!(W[i] > 0.0, "u = {u} picked empty bin {i}");
            assert!((0.0..1.0).contains(&x));
            assert_eq!(pdf, d.pdf(x));
            assert!((d.inverse(x) - u).abs() < 1e-5, "u {u} x {x}");
        }
        let (i, _, _) = d.sample_discrete(ONE_MINUS_EPSILON);
        assert_eq!(i, 7);
        let (i, _, _) = d.sample_discrete(0.0);
        assert_eq!(i, 1);
    }

    #[test]
    fn distribution1d_bad_input_is_handled() {
        assert!(Distribution1D::try_new(&[]).is_err());
        assert!(Distribution1D::try_new(&[1.0, -1.0]).is_err());
        assert!(Distribution1D::try_new(&[1.0, f32::NAN]).is_err());
        assert_eq!(
            Distribution1D::try_new(&[0.0, 0.0]).unwrap_err(),
            SamplingError::ZeroSum
        );
        // The lenient constructor degrades to something sane instead of panicking.
        let d = Distribution1D::new(&[]);
        assert_eq!(d.len(), 1);
        assert_eq!(d.sample_continuous(0.3).0, 0.3);
        let z = Distribution1D::new(&[0.0, 0.0, 0.0, 0.0]);
        assert_eq!(z.pdf(0.6), 1.0);
        assert_eq!(z.pmf(2), 0.25);
        let (x, pdf, i) = z.sample_continuous(0.6);
        assert!((x - 0.6).abs() < 1e-6 && pdf == 1.0 && i == 2);
        let nan = Distribution1D::new(&[f32::NAN, 1.0]);
        assert_eq!(nan.sample_discrete(0.1).0, 1);
    }
}

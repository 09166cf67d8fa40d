//! Discrete distributions: Walker/Vose alias table (O(1) sampling) with pmf lookup.

use super::error::{SamplingError, check_weights};

/// Alias table over n outcomes with probabilities ∝ the given weights.
#[derive(Clone, Debug)]
pub struct AliasTable {
    /// Normalised probability of each outcome.
    pub pmf: Vec<f32>,
    /// Probability of keeping bucket i rather than jumping to its alias.
    threshold: Vec<f32>,
    /// The outcome that fills the rest of bucket i.
    alias: Vec<u32>,
}

impl AliasTable {
    /// Build from non-negative weights; `None` if empty or the sum is not positive and finite.
    /// Negative or NaN weights also give `None` (see [`Self::try_new`] for the reason).
    pub fn new(weights: &[f32]) -> Option<Self> {
        Self::try_new(weights).ok()
    }

    /// Build from weights, explaining what is wrong with them if it fails.
    pub fn try_new(weights: &[f32]) -> Result<Self, SamplingError> {
        check_weights(weights)?;
        if weights.len() > u32::MAX as usize {
            return Err(SamplingError::Empty);
        }
        let sum: f64 = weights.iter().map(|&w| w as f64).sum();
        if !(sum > 0.0 && sum.is_finite()) {
            return Err(SamplingError::ZeroSum);
        }
        let n = weights.len();
        let pmf64: Vec<f64> = weights.iter().map(|&w| w as f64 / sum).collect();
        // Vose: scaled probabilities q = n·p; buckets below 1 are topped up by one above 1.
        let mut q: Vec<f64> = pmf64.iter().map(|&p| p * n as f64).collect();
        let mut threshold = vec![1.0f32; n];
        let mut alias: Vec<u32> = (0..n as u32).collect();
        let (mut small, mut large): (Vec<usize>, Vec<usize>) = (0..n).partition(|&i| q[i] < 1.0);
        while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
            small.pop();
            threshold[s] = q[s] as f32;
            alias[s] = l as u32;
            q[l] -= 1.0 - q[s];
            if q[l] < 1.0 {
                large.pop();
                small.push(l);
            }
        }
        // Leftovers are 1 up to rounding; a zero-weight leftover must still never be chosen,
        // so it hands its whole bucket to the most likely outcome.
        let heaviest = (0..n)
            .max_by(|&a, &b| pmf64[a].total_cmp(&pmf64[b]))
            .unwrap_or(0);
        for i in small.into_iter().chain(large) {
            if weights[i] > 0.0 {
                threshold[i] = 1.0;
                alias[i] = i as u32;
            } else {
                threshold[i] = 0.0;
                alias[i] = heaviest as u32;
            }
        }
        Ok(Self {
            pmf: pmf64.iter().map(|&p| p as f32).collect(),
            threshold,
            alias,
        })
    }

    /// Sample an outcome: (index, pmf).
    ///
    /// One uniform number picks the bucket (integer part of u·n) and the coin (fractional part),
    /// so with f32 input the coin has 2^24/n levels: fine for the table sizes used here.
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let n = self.pmf.len();
        let scaled = (u.clamp(0.0, 1.0) as f64) * n as f64;
        let bucket = (scaled as usize).min(n - 1);
        let coin = (scaled - bucket as f64) as f32;
        let i = if coin < self.threshold[bucket] {
            bucket
        } else {
            self.alias[bucket] as usize
        };
        (i, self.pmf[i])
    }

    /// Probability of outcome `i` (0 outside the table).
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf.get(i).copied().unwrap_or(0.0)
    }

    /// Number of outcomes.
    pub fn len(&self) -> usize {
        self.pmf.len()
    }

    /// True when there are no outcomes.
    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn alias_table_is_exact_on_a_fine_grid() {
        // Sweeping u over a fine grid, the fraction of u landing on each outcome is its pmf
        // up to the grid spacing: a deterministic check of the Vose construction.
        let w = [1.0, 0.0, 7.0, 0.5, 0.0, 2.5, 1e-3, 4.0];
        let t = AliasTable::new(&w).unwrap();
        let m = 1 << 20;
        let mut count = [0usize; 8];
        for k in 0..m {
            let (i, p) = t.sample(k as f32 / m as f32);
            assert_eq!(p, t.pmf(i));
            count[i] += 1;
        }
        let sum: f32 = w.iter().sum();
        for i in 0..8 {
            let expect = w[i] / sum;
            let got = count[i] as f32 / m as f32;
            assert!(
                (got - expect).abs() < 1e-5,
                "outcome {i}: {got} vs {expect}"
            );
            assert!((t.pmf(i) - expect).abs() < 1e-7);
        }
        assert_eq!(count[1] + count[4], 0);
    }

    #[test]
    fn alias_table_rejects_bad_weights() {
        assert!(AliasTable::new(&[]).is_none());
        assert!(AliasTable::new(&[0.0, 0.0]).is_none());
        assert!(AliasTable::new(&[1.0, -0.5]).is_none());
        assert!(AliasTable::new(&[1.0, f32::INFINITY]).is_none());
        assert!(matches!(
            AliasTable::try_new(&[1.0, f32::NAN]),
            Err(SamplingError::BadWeight { index: 1, .. })
        ));
        let t = AliasTable::new(&[2.0]).unwrap();
        assert_eq!(t.sample(0.999_999), (0, 1.0));
        assert_eq!(t.pmf(5), 0.0);
    }
}

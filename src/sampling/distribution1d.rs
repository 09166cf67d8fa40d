//! Piecewise-constant 1D distribution on [0, 1), sampled by inverting its CDF (binary search).
//! TODO(issue 2): implement.

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
    pub fn new(f: &[f32]) -> Self {
        let _ = f;
        todo!("issue 2")
    }
    /// Continuous sample: (x in [0,1), pdf(x), bin index).
    pub fn sample_continuous(&self, u: f32) -> (f32, f32, usize) {
        let _ = u;
        todo!("issue 2")
    }
    /// Discrete sample of a bin: (index, pmf, remapped u in [0,1) for reuse).
    pub fn sample_discrete(&self, u: f32) -> (usize, f32, f32) {
        let _ = u;
        todo!("issue 2")
    }
    /// Probability of bin `i` in discrete sampling.
    pub fn pmf(&self, i: usize) -> f32 {
        let _ = i;
        todo!("issue 2")
    }
    /// Density at x ∈ [0,1) for continuous sampling.
    pub fn pdf(&self, x: f32) -> f32 {
        let _ = x;
        todo!("issue 2")
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

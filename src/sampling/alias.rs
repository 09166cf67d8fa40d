//! Discrete distributions: Walker/Vose alias table (O(1) sampling) with pmf lookup.
//! TODO(issue 2): implement.

/// Alias table over n outcomes with probabilities ∝ the given weights.
#[derive(Clone, Debug)]
pub struct AliasTable {
    /// Normalised probability of each outcome.
    pub pmf: Vec<f32>,
}

impl AliasTable {
    /// Build from non-negative weights; `None` if empty or the sum is not positive and finite.
    pub fn new(weights: &[f32]) -> Option<Self> {
        let _ = weights;
        todo!("issue 2")
    }
    /// Sample an outcome: (index, pmf).
    pub fn sample(&self, u: f32) -> (usize, f32) {
        let _ = u;
        todo!("issue 2")
    }
    /// Probability of outcome `i`.
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf[i]
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

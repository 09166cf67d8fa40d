//! Piecewise-constant 2D distribution on [0,1)², sampled by marginal + conditional inversion
//! (the lecture's multidimensional inversion). Used by environment maps: the caller supplies the
//! sin θ weighting.

use glam::Vec2;

use super::Distribution1D;
use super::error::{SamplingError, check_weights};

/// 2D piecewise-constant distribution over an nu × nv grid (row-major: v rows of u columns).
#[derive(Clone, Debug)]
pub struct Distribution2D {
    /// One conditional distribution over u per row v.
    pub conditional: Vec<super::Distribution1D>,
    /// Marginal distribution over rows v.
    pub marginal: super::Distribution1D,
}

impl Distribution2D {
    /// Build from `f[v * nu + u]` (non-negative).
    ///
    /// Never panics: a zero dimension counts as 1, missing values as 0 and extra values are
    /// ignored; [`Self::try_new`] reports such input as an error instead.
    pub fn new(f: &[f32], nu: usize, nv: usize) -> Self {
        let (nu, nv) = (nu.max(1), nv.max(1));
        let conditional: Vec<Distribution1D> = (0..nv)
            .map(|v| {
                let row: Vec<f32> = (0..nu)
                    .map(|u| f.get(v * nu + u).copied().unwrap_or(0.0))
                    .collect();
                Distribution1D::new(&row)
            })
            .collect();
        let marginal_f: Vec<f32> = conditional.iter().map(|c| c.integral).collect();
        Self {
            marginal: Distribution1D::new(&marginal_f),
            conditional,
        }
    }

    /// Like [`Self::new`] but rejects a shape mismatch and negative, non-finite or all-zero values.
    pub fn try_new(f: &[f32], nu: usize, nv: usize) -> Result<Self, SamplingError> {
        if nu == 0 || nv == 0 || nu.checked_mul(nv) != Some(f.len()) {
            return Err(SamplingError::Shape {
                nu,
                nv,
                len: f.len(),
            });
        }
        check_weights(f)?;
        if !f.iter().any(|&x| x > 0.0) {
            return Err(SamplingError::ZeroSum);
        }
        Ok(Self::new(f, nu, nv))
    }

    /// Sample (u, v) ∈ [0,1)² and its pdf with respect to area in [0,1)².
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (y, pdf_v, row) = self.marginal.sample_continuous(u.y);
        let (x, pdf_u, _) = self.conditional[row].sample_continuous(u.x);
        (Vec2::new(x, y), pdf_u * pdf_v)
    }

    /// Pdf at a point of [0,1)².
    pub fn pdf(&self, p: Vec2) -> f32 {
        if !((0.0..1.0).contains(&p.x) && (0.0..1.0).contains(&p.y)) {
            return 0.0;
        }
        let nv = self.conditional.len();
        let row = &self.conditional[((p.y * nv as f32) as usize).min(nv - 1)];
        let nu = row.func.len();
        let iu = ((p.x * nu as f32) as usize).min(nu - 1);
        if self.marginal.integral > 0.0 {
            // f / ∫∫f: the product of conditional and marginal densities, without rounding twice.
            row.func[iu] / self.marginal.integral
        } else {
            1.0
        }
    }

    /// Inverse of [`Self::sample`]: the uniform pair that maps to `p`.
    pub fn inverse(&self, p: Vec2) -> Vec2 {
        let nv = self.conditional.len();
        let row = ((p.y.clamp(0.0, 1.0) * nv as f32) as usize).min(nv - 1);
        Vec2::new(
            self.conditional[row].inverse(p.x),
            self.marginal.inverse(p.y),
        )
    }

    /// Grid size (nu, nv).
    pub fn resolution(&self) -> (usize, usize) {
        (self.conditional[0].len(), self.conditional.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(nu: usize, nv: usize) -> Vec<f32> {
        (0..nv)
            .flat_map(|v| {
                (0..nu).map(move |u| {
                    let (x, y) = (u as f32 / nu as f32, v as f32 / nv as f32);
                    let blob = (-((x - 0.7).powi(2) + (y - 0.3).powi(2)) * 60.0).exp() * 50.0;
                    let stripes = if (u / 3 + v / 2) % 4 == 0 { 0.0 } else { 1.0 };
                    blob + stripes * (1.0 + x)
                })
            })
            .collect()
    }

    #[test]
    fn distribution2d_pdf_integrates_to_one_and_matches_sample() {
        let (nu, nv) = (37, 23);
        let d = Distribution2D::new(&image(nu, nv), nu, nv);
        let m = 400;
        let mut s = 0.0f64;
        for i in 0..m {
            for j in 0..m {
                let p = Vec2::new((i as f32 + 0.5) / m as f32, (j as f32 + 0.5) / m as f32);
                s += d.pdf(p) as f64;
            }
        }
        assert!(
            (s / (m * m) as f64 - 1.0).abs() < 2e-3,
            "{}",
            s / (m * m) as f64
        );
        for k in 0..5000 {
            let u = Vec2::new((k as f32 * 0.618_034).fract(), (k as f32 + 0.5) / 5000.0);
            let (p, pdf) = d.sample(u);
            assert!(pdf > 0.0);
            assert!(
                ((pdf - d.pdf(p)) / pdf).abs() < 1e-4,
                "{pdf} vs {}",
                d.pdf(p)
            );
            let back = d.inverse(p);
            assert!(
                (back - u).abs().max_element() < 2e-4,
                "{u} -> {p} -> {back}"
            );
        }
    }

    #[test]
    fn distribution2d_bad_input() {
        assert!(matches!(
            Distribution2D::try_new(&[1.0; 5], 2, 3),
            Err(SamplingError::Shape { .. })
        ));
        assert!(Distribution2D::try_new(&[1.0; 6], 0, 3).is_err());
        assert!(Distribution2D::try_new(&[0.0; 6], 2, 3).is_err());
        // Lenient constructor: no panic, still a valid distribution.
        let d = Distribution2D::new(&[1.0; 5], 2, 3);
        let (p, pdf) = d.sample(Vec2::new(0.2, 0.9));
        assert!(pdf > 0.0 && p.y >= 2.0 / 3.0 && p.x < 0.5, "{p}");
        assert_eq!(d.resolution(), (2, 3));
        let z = Distribution2D::new(&[], 0, 0);
        assert_eq!(z.sample(Vec2::new(0.25, 0.5)).1, 1.0);
    }
}

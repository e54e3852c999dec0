//! Discrete distributions for importance sampling: a 1D piecewise-constant distribution over
//! bins ([`Distribution1D`]) and a 2D one over a grid of cells ([`Distribution2D`]: a marginal
//! over rows, then the conditional over the columns of the chosen row).
//!
//! Weights must be finite and non-negative (checked by the caller when they come from user data).
//! Sums are accumulated in double precision, so a bright sun next to a dim sky keeps its share.

/// A distribution over `n` bins proportional to their weights.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    /// `n + 1` entries from 0 to 1.
    cdf: Vec<f32>,
    /// Probability of each bin.
    pmf: Vec<f32>,
    /// Sum of the weights.
    sum: f64,
}

impl Distribution1D {
    /// Build from non-negative weights. An all-zero (or empty) distribution is valid to build but
    /// cannot be sampled ([`Distribution1D::is_valid`] is false).
    pub fn new(weights: &[f32]) -> Distribution1D {
        let mut acc = 0.0f64;
        let mut cum = Vec::with_capacity(weights.len() + 1);
        cum.push(0.0f64);
        for &w in weights {
            debug_assert!(w >= 0.0 && w.is_finite(), "weight {w} must be finite and non-negative");
            acc += w.max(0.0) as f64;
            cum.push(acc);
        }
        let (cdf, pmf) = if acc > 0.0 {
            let cdf: Vec<f32> = cum.iter().map(|c| (c / acc) as f32).collect();
            let pmf = weights.iter().map(|&w| (w.max(0.0) as f64 / acc) as f32).collect();
            (cdf, pmf)
        } else {
            (vec![0.0; weights.len() + 1], vec![0.0; weights.len()])
        };
        Distribution1D { cdf, pmf, sum: acc }
    }

    /// Number of bins.
    pub fn len(&self) -> usize {
        self.pmf.len()
    }

    pub fn is_empty(&self) -> bool {
        self.pmf.is_empty()
    }

    /// True when some bin has positive probability.
    pub fn is_valid(&self) -> bool {
        self.sum > 0.0
    }

    /// Sum of the weights it was built from.
    pub fn sum(&self) -> f64 {
        self.sum
    }

    /// Probability of bin `i` (0 outside).
    #[inline]
    pub fn pmf(&self, i: usize) -> f32 {
        self.pmf.get(i).copied().unwrap_or(0.0)
    }

    /// Pick a bin for `u` in [0, 1): `(index, u rescaled to [0, 1) within the bin, probability)`.
    /// Never returns a bin of zero probability; `None` when the distribution is invalid.
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32, f32)> {
        if !self.is_valid() {
            return None;
        }
        let n = self.pmf.len();
        // The bin i with cdf[i] <= u < cdf[i + 1]; zero-probability bins cannot satisfy both.
        let mut i = self.cdf.partition_point(|&c| c <= u).saturating_sub(1).min(n - 1);
        while self.pmf[i] == 0.0 && i > 0 {
            i -= 1; // only reachable when rounding put u at or beyond the last cdf entry
        }
        let p = self.pmf[i];
        let rescaled = ((u - self.cdf[i]) / p).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        Some((i, rescaled, p))
    }
}

/// A distribution over a `width × height` grid of cells proportional to their weights.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    width: usize,
    /// Over rows, proportional to each row's sum.
    marginal: Distribution1D,
    /// Over the columns of each row.
    conditional: Vec<Distribution1D>,
}

impl Distribution2D {
    /// Build from `width · height` weights, row by row. `weights.len()` must equal `width · height`.
    pub fn new(weights: &[f32], width: usize, height: usize) -> Distribution2D {
        assert_eq!(weights.len(), width * height, "Distribution2D: weight count does not match the grid");
        let conditional: Vec<Distribution1D> = weights.chunks_exact(width.max(1)).map(Distribution1D::new).collect();
        let row_sums: Vec<f32> = conditional.iter().map(|d| d.sum() as f32).collect();
        Distribution2D { width, marginal: Distribution1D::new(&row_sums), conditional }
    }

    pub fn is_valid(&self) -> bool {
        self.marginal.is_valid()
    }

    /// Pick a cell: `(column, row, sample rescaled within the cell, probability of the cell)`.
    #[inline]
    pub fn sample(&self, u: glam::Vec2) -> Option<(usize, usize, glam::Vec2, f32)> {
        let (y, uy, py) = self.marginal.sample(u.y)?;
        let (x, ux, px) = self.conditional[y].sample(u.x)?;
        Some((x, y, glam::Vec2::new(ux, uy), px * py))
    }

    /// Probability of cell (x, y) (0 outside the grid).
    #[inline]
    pub fn pmf(&self, x: usize, y: usize) -> f32 {
        if x >= self.width {
            return 0.0;
        }
        match self.conditional.get(y) {
            Some(row) => self.marginal.pmf(y) * row.pmf(x),
            None => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_d_picks_bins_by_weight() {
        let d = Distribution1D::new(&[1.0, 0.0, 3.0]);
        assert!(d.is_valid());
        assert_eq!(d.pmf(0), 0.25);
        assert_eq!(d.pmf(1), 0.0);
        assert_eq!(d.sample(0.0).unwrap().0, 0);
        let (i, r, p) = d.sample(0.125).unwrap();
        assert_eq!((i, p), (0, 0.25));
        assert!((r - 0.5).abs() < 1e-6);
        // u = 0.25 is the start of bin 2 (bin 1 is empty).
        assert_eq!(d.sample(0.25).unwrap().0, 2);
        assert_eq!(d.sample(0.999_999_9).unwrap().0, 2);
        assert!(d.sample(1.0).unwrap().1 < 1.0);
    }

    #[test]
    fn trailing_zero_bins_are_never_picked() {
        let d = Distribution1D::new(&[1.0, 1.0, 0.0, 0.0]);
        assert_eq!(d.sample(1.0).unwrap().0, 1);
    }

    #[test]
    fn zero_distribution_is_invalid() {
        assert!(Distribution1D::new(&[0.0, 0.0]).sample(0.5).is_none());
        assert!(Distribution1D::new(&[]).sample(0.5).is_none());
        assert!(!Distribution2D::new(&[0.0; 6], 3, 2).is_valid());
    }

    #[test]
    fn two_d_pmf_matches_sampling_frequencies() {
        let w = [1.0, 2.0, 0.0, 4.0, 0.0, 1.0];
        let d = Distribution2D::new(&w, 3, 2);
        let total: f32 = w.iter().sum();
        let mut counts = [0u32; 6];
        let n = 200;
        for i in 0..n {
            for j in 0..n {
                let u = glam::Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
                let (x, y, r, p) = d.sample(u).unwrap();
                assert!((0.0..1.0).contains(&r.x) && (0.0..1.0).contains(&r.y));
                assert!((p - d.pmf(x, y)).abs() < 1e-6);
                counts[y * 3 + x] += 1;
            }
        }
        for k in 0..6 {
            let expected = w[k] / total;
            assert!((counts[k] as f32 / (n * n) as f32 - expected).abs() < 0.01, "cell {k}");
            assert!((d.pmf(k % 3, k / 3) - expected).abs() < 1e-6);
        }
    }
}

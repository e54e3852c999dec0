//! Discrete distributions for importance sampling: a 1D distribution over bins
//! ([`Distribution1D`]) and a 2D one over a grid of cells ([`Distribution2D`]: a marginal over
//! rows, then the conditional over the columns of the chosen row).
//!
//! Sampling takes constant time with Walker's alias method (Walker 1977, "An efficient method for
//! generating discrete random variables with general distributions", ACM TOMS 3(3); table built by
//! Vose 1991, IEEE TSE 17(9)): `u · n` picks a bin, its fractional part either keeps the bin or
//! moves to the bin's alias. The probability returned with a sample is the bin's stored
//! probability, the same number [`Distribution1D::pmf`] returns, so sampling and evaluation agree
//! exactly; the table reproduces those probabilities up to the rounding of its `f32` thresholds.
//!
//! Weights must be finite and non-negative (checked by the caller when they come from user data).
//! Sums are accumulated in double precision, so a bright sun next to a dim sky keeps its share.

/// A distribution over `n` bins proportional to their weights (the default has no bins).
#[derive(Clone, Debug, Default)]
pub struct Distribution1D {
    /// Probability of each bin.
    pmf: Vec<f32>,
    /// Per bin: the fraction of its slot it keeps (the rest goes to `alias`), and the alias.
    table: Vec<(f32, u32)>,
    /// Sum of the weights.
    sum: f64,
    /// The table's length as `f32` (the conversion done once).
    n_f: f32,
}

impl Distribution1D {
    /// Build from non-negative weights. An all-zero (or empty) distribution is valid to build but
    /// cannot be sampled ([`Distribution1D::is_valid`] is false).
    pub fn new(weights: &[f32]) -> Distribution1D {
        let acc: f64 = weights
            .iter()
            .map(|&w| {
                debug_assert!(w >= 0.0 && w.is_finite(), "weight {w} must be finite and non-negative");
                w.max(0.0) as f64
            })
            .sum();
        if acc <= 0.0 {
            return Distribution1D { pmf: vec![0.0; weights.len()], table: Vec::new(), sum: acc, n_f: 0.0 };
        }
        let pmf = weights.iter().map(|&w| (w.max(0.0) as f64 / acc) as f32).collect();
        Distribution1D { pmf, table: alias_table(weights, acc), sum: acc, n_f: weights.len() as f32 }
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

    /// Pick a bin for `u` in [0, 1): `(index, u rescaled to [0, 1) and uniform given the bin,
    /// probability)`. Never returns a bin of zero probability; `None` when the distribution is
    /// invalid.
    #[inline]
    pub fn sample(&self, u: f32) -> Option<(usize, f32, f32)> {
        if !self.is_valid() {
            return None;
        }
        let n = self.table.len();
        let x = u.clamp(0.0, 1.0) * self.n_f;
        // Through u32 (bins are indexed by u32): a cheaper saturating conversion, the same index.
        let slot = (x as u32 as usize).min(n - 1);
        // Below 1, so a slot that keeps all of its bin (keep = 1) always keeps it.
        let frac = (x - slot as f32).clamp(0.0, 1.0 - f32::EPSILON / 2.0);
        let (keep, alias) = self.table[slot];
        // A zero-probability bin keeps nothing (keep = 0), so it is never returned.
        let (i, rescaled) =
            if frac < keep { (slot, frac / keep) } else { (alias as usize, (frac - keep) / (1.0 - keep)) };
        Some((i, rescaled.clamp(0.0, 1.0 - f32::EPSILON / 2.0), self.pmf[i]))
    }
}

/// Vose's construction: every slot of mass 1/n holds a share `keep` of its own bin and the rest of
/// one other bin (its alias). Built in double precision.
fn alias_table(weights: &[f32], sum: f64) -> Vec<(f32, u32)> {
    let n = weights.len();
    let scaled: Vec<f64> = weights.iter().map(|&w| w.max(0.0) as f64 * n as f64 / sum).collect();
    let mut table: Vec<(f32, u32)> = (0..n as u32).map(|i| (1.0, i)).collect();
    let mut rest = scaled.clone();
    let (mut small, mut large): (Vec<u32>, Vec<u32>) = (0..n as u32).partition(|&i| scaled[i as usize] < 1.0);
    while let (Some(&s), Some(&l)) = (small.last(), large.last()) {
        small.pop();
        let (su, lu) = (s as usize, l as usize);
        table[su] = (rest[su] as f32, l);
        rest[lu] -= 1.0 - rest[su];
        if rest[lu] < 1.0 {
            large.pop();
            small.push(l);
        }
    }
    // What is left is 1 up to rounding: such slots keep their own bin entirely, unless the bin has
    // zero weight, which then hands its slot to a bin with weight.
    let positive = weights.iter().position(|&w| w > 0.0).unwrap_or(0) as u32;
    for (i, t) in table.iter_mut().enumerate() {
        if scaled[i] <= 0.0 {
            *t = (0.0, if t.1 as usize != i && scaled[t.1 as usize] > 0.0 { t.1 } else { positive });
        }
    }
    for &i in small.iter().chain(&large) {
        if scaled[i as usize] > 0.0 {
            table[i as usize] = (1.0, i);
        }
    }
    table
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
        // Stratified u: each bin is chosen in proportion to its weight, with its own probability,
        // and the rescaled sample is uniform within the bin (its mean is 1/2).
        let n = 100_000;
        let mut count = [0usize; 3];
        let mut mean = [0.0f64; 3];
        for k in 0..n {
            let (i, r, p) = d.sample((k as f32 + 0.5) / n as f32).unwrap();
            assert!((0.0..1.0).contains(&r));
            assert_eq!(p, d.pmf(i));
            count[i] += 1;
            mean[i] += r as f64;
        }
        assert_eq!(count[1], 0);
        assert!((count[0] as f64 / n as f64 - 0.25).abs() < 1e-3, "{count:?}");
        for i in [0, 2] {
            assert!((mean[i] / count[i] as f64 - 0.5).abs() < 1e-3, "{mean:?}");
        }
        assert!(d.sample(1.0).unwrap().1 < 1.0);
        assert!(d.sample(0.999_999_9).is_some());
    }

    /// Chi-square test of the alias table on skewed weights with zeros (a sun next to a dim sky):
    /// the frequency of every bin matches its pmf, and zero bins are never drawn.
    #[test]
    fn alias_table_chi2() {
        use crate::testing::chi2::chi2_discrete;
        let mut s = crate::sampler::Sampler::new(17, 0);
        let weights: Vec<f32> = (0..64)
            .map(|i| match i % 7 {
                0 => 0.0,
                1 => 500.0,
                _ => s.next_1d() * 3.0,
            })
            .collect();
        let d = Distribution1D::new(&weights);
        let mut counts = vec![0u64; weights.len()];
        for _ in 0..1_000_000 {
            let (i, _, p) = d.sample(s.next_1d()).unwrap();
            assert!(p > 0.0 && weights[i] > 0.0);
            counts[i] += 1;
        }
        let probs: Vec<f64> = (0..weights.len()).map(|i| d.pmf(i) as f64).collect();
        let r = chi2_discrete(&counts, 0, &probs, 0.01);
        assert!(r.passed, "{}", r.report);
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

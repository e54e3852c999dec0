//! Image comparison: MSE, relMSE, mean ratio, and a per-pixel Z-test with a Šidák-corrected level
//! when both images carry variances (the statistical check used by the reference regression tests).
//!
//! Variance channels: `var.R/G/B` (per-sample variance, with the sample count given separately) or
//! `m2.R/G/B` (second moment, Mitsuba's `moment` integrator; variance = m2 − mean²).

use crate::io::read::Bitmap;
use serde_json::json;

#[derive(Clone, Debug)]
pub struct CompareResult {
    pub width: usize,
    pub height: usize,
    pub mse: f64,
    pub rel_mse: f64,
    pub mean_a: [f64; 3],
    pub mean_b: [f64; 3],
    pub ratio: f64,
}

impl CompareResult {
    pub fn to_json(&self) -> serde_json::Value {
        json!({"width": self.width, "height": self.height, "mse": self.mse, "rel_mse": self.rel_mse,
               "mean_a": self.mean_a, "mean_b": self.mean_b, "mean_ratio": self.ratio})
    }
    pub fn to_text(&self) -> String {
        format!(
            "{}x{}\nMSE     {:.6e}\nrelMSE  {:.6e}\nmean A  {:?}\nmean B  {:?}\nratio A/B {:.5}\n",
            self.width, self.height, self.mse, self.rel_mse, self.mean_a, self.mean_b, self.ratio
        )
    }
}

/// RGB of every pixel.
pub fn rgb_of(b: &Bitmap) -> Result<Vec<[f32; 3]>, String> {
    let idx = |n: &str| b.channel(n);
    let n = b.channels.len();
    match (idx("R"), idx("G"), idx("B"), idx("Y")) {
        (Some(r), Some(g), Some(bb), _) => Ok(b.data.chunks(n).map(|p| [p[r], p[g], p[bb]]).collect()),
        (_, _, _, Some(y)) => Ok(b.data.chunks(n).map(|p| [p[y]; 3]).collect()),
        _ => Err("image has no R,G,B (or Y) channels".into()),
    }
}

/// Relative MSE of `a` against reference `b`: mean of (a−b)² / (b² + 1e-2) over pixels and channels.
pub fn rel_mse(a: &[[f32; 3]], b: &[[f32; 3]]) -> f64 {
    let mut s = 0.0f64;
    for (pa, pb) in a.iter().zip(b) {
        for c in 0..3 {
            let d = (pa[c] - pb[c]) as f64;
            s += d * d / ((pb[c] as f64).powi(2) + 1e-2);
        }
    }
    s / (3 * a.len().max(1)) as f64
}

pub fn compare(a: &Bitmap, b: &Bitmap) -> Result<CompareResult, String> {
    if a.width != b.width || a.height != b.height {
        return Err(format!("image sizes differ: {}x{} vs {}x{}", a.width, a.height, b.width, b.height));
    }
    let ra = rgb_of(a)?;
    let rb = rgb_of(b)?;
    let mut mse = 0.0f64;
    let mut ma = [0.0f64; 3];
    let mut mb = [0.0f64; 3];
    for (pa, pb) in ra.iter().zip(&rb) {
        for c in 0..3 {
            let d = (pa[c] - pb[c]) as f64;
            mse += d * d;
            ma[c] += pa[c] as f64;
            mb[c] += pb[c] as f64;
        }
    }
    let n = ra.len().max(1) as f64;
    mse /= 3.0 * n;
    for c in 0..3 {
        ma[c] /= n;
        mb[c] /= n;
    }
    let ratio = (ma[0] + ma[1] + ma[2]) / (mb[0] + mb[1] + mb[2]);
    Ok(CompareResult {
        width: a.width,
        height: a.height,
        mse,
        rel_mse: rel_mse(&ra, &rb),
        mean_a: ma,
        mean_b: mb,
        ratio,
    })
}

/// Outcome of a per-pixel two-sample Z-test.
#[derive(Clone, Debug)]
pub struct ZTest {
    pub tests: usize,
    /// Smallest two-sided p-value over all pixels and channels.
    pub min_p: f64,
    /// Šidák-corrected per-test level for family-wise level `alpha`.
    pub level: f64,
    pub passed: bool,
    /// (pixel index, channel, z) of the worst pixel.
    pub worst: (usize, usize, f64),
}

impl ZTest {
    pub fn to_json(&self) -> serde_json::Value {
        json!({"tests": self.tests, "min_p": self.min_p, "sidak_level": self.level, "passed": self.passed,
               "worst_pixel": self.worst.0, "worst_channel": self.worst.1, "worst_z": self.worst.2})
    }
    pub fn to_text(&self) -> String {
        format!(
            "Z-test  {} ({} tests, min p {:.3e}, Šidák level {:.3e} for α = 0.01; worst pixel {} channel {} z {:.2})\n",
            if self.passed { "passed" } else { "FAILED" },
            self.tests,
            self.min_p,
            self.level,
            self.worst.0,
            self.worst.1,
            self.worst.2
        )
    }
}

/// Variance of each pixel's mean: per-sample variance (ignoring the reconstruction filter's variance
/// factor, which `tests/references.rs` applies; for a Gaussian filter this overestimates the
/// variance inside the image and underestimates it in the corners) (`var.*`, or `m2.*` minus the squared mean)
/// divided by the sample count. `None` when the image has neither or `spp` is unknown.
pub fn variance_of_mean(b: &Bitmap, spp: Option<f64>) -> Option<Vec<[f32; 3]>> {
    let spp = spp.filter(|s| *s > 0.0)? as f32;
    let mean = rgb_of(b).ok()?;
    let n = b.channels.len();
    let ch = |p: &str| -> Option<[usize; 3]> {
        Some([b.channel(&format!("{p}.R"))?, b.channel(&format!("{p}.G"))?, b.channel(&format!("{p}.B"))?])
    };
    if let Some(v) = ch("var") {
        return Some(b.data.chunks(n).map(|p| [0, 1, 2].map(|c| p[v[c]].max(0.0) / spp)).collect());
    }
    let m2 = ch("m2")?;
    Some(b.data.chunks(n).zip(&mean).map(|(p, m)| [0, 1, 2].map(|c| (p[m2[c]] - m[c] * m[c]).max(0.0) / spp)).collect())
}

/// Two-sample Z-test of means `a`, `b` with variances of the means `va`, `vb` (per pixel and channel),
/// at family-wise level `alpha` with Šidák's correction over all tests.
pub fn z_test(a: &[[f32; 3]], va: &[[f32; 3]], b: &[[f32; 3]], vb: &[[f32; 3]], alpha: f64) -> ZTest {
    let mut min_p = 1.0f64;
    let mut worst = (0, 0, 0.0);
    let mut tests = 0;
    for i in 0..a.len() {
        for c in 0..3 {
            let var = va[i][c] as f64 + vb[i][c] as f64;
            let d = a[i][c] as f64 - b[i][c] as f64;
            let p = if var > 0.0 {
                let z = d / var.sqrt();
                let p = erfc(z.abs() / std::f64::consts::SQRT_2);
                if p < min_p {
                    worst = (i, c, z);
                }
                p
            } else if d.abs() > 1e-6 * (a[i][c].abs().max(b[i][c].abs()) as f64) + 1e-7 {
                // Both claim zero variance but differ: a certain failure.
                worst = (i, c, f64::INFINITY);
                0.0
            } else {
                1.0
            };
            min_p = min_p.min(p);
            tests += 1;
        }
    }
    let level = 1.0 - (1.0 - alpha).powf(1.0 / tests.max(1) as f64);
    ZTest { tests, min_p, level, passed: min_p >= level, worst }
}

/// Complementary error function (Numerical Recipes' erfcc, fractional error < 1.2e-7).
pub fn erfc(x: f64) -> f64 {
    let z = x.abs();
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t
        * (-z * z - 1.26551223
            + t * (1.00002368
                + t * (0.37409196
                    + t * (0.09678418
                        + t * (-0.18628806
                            + t * (0.27886807
                                + t * (-1.13520398 + t * (1.48851587 + t * (-0.82215223 + t * 0.17087277)))))))))
            .exp();
    if x >= 0.0 {
        r
    } else {
        2.0 - r
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn erfc_values() {
        assert!((erfc(0.0) - 1.0).abs() < 1e-6);
        assert!((erfc(1.0) - 0.157_299_207).abs() < 1e-6);
        assert!((erfc(3.0) - 2.209_049_7e-5).abs() < 1e-8);
    }
    #[test]
    fn z_test_detects_bias() {
        let n = 1000;
        let a = vec![[1.0f32; 3]; n];
        let b = vec![[1.05f32; 3]; n];
        let v = vec![[1e-6f32; 3]; n];
        assert!(!z_test(&a, &v, &b, &v, 0.01).passed);
        assert!(z_test(&a, &v, &a, &v, 0.01).passed);
    }
}

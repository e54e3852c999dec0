//! Chi-square goodness-of-fit tests for samplers (after Mitsuba's `ChiSquareTest`).
//!
//! [`chi2_sphere`] draws directions with a sampler, histograms them over (cos θ, φ) bins of the
//! unit sphere, integrates the claimed solid-angle pdf over every bin (adaptive Simpson), pools
//! the bins whose expected count is below 5, and compares with Pearson's statistic. Failed
//! samples (`None`) form one more cell, "missing mass", expected `n·(1 − ∫pdf)`: a sampler that
//! absorbs energy must fail exactly as often as its pdf integral says.
//!
//! [`chi2_discrete`] is the same test for a finite set of outcomes (e.g. reflect vs transmit
//! on a smooth dielectric, whose probabilities are the Fresnel terms).
//!
//! Both return a [`Chi2Result`] whose `report` explains a failure (the worst cells).
//!
//! ```
//! use snee::math::{warp, Vec3};
//! use snee::testing::chi2::chi2_sphere;
//! let r = chi2_sphere(
//!     |_, u| Some(warp::square_to_cosine_hemisphere(u)),
//!     |d: Vec3| warp::square_to_cosine_hemisphere_pdf(d),
//!     16, 32, 100_000, 0.01, 1,
//! );
//! assert!(r.passed, "{}", r.report);
//! ```

use crate::math::{Vec2, Vec3, PI};
use crate::sampler::Sampler;
use std::fmt::Write as _;

/// Outcome of a chi-square test.
#[derive(Clone, Debug)]
pub struct Chi2Result {
    /// Probability of a statistic at least this large if the sampler matches the pdf.
    pub p_value: f64,
    /// Pearson's statistic Σ (observed − expected)² / expected over the (pooled) cells.
    pub chi2: f64,
    /// Degrees of freedom (cells − 1).
    pub dof: usize,
    /// `p_value > significance` and no impossible observation (a sample where the pdf is 0).
    pub passed: bool,
    /// ∫ pdf over the sphere (for [`chi2_discrete`]: Σ probabilities).
    pub pdf_integral: f64,
    /// Human-readable summary, with the worst cells when the test fails.
    pub report: String,
}

/// Šidák-corrected significance level for one of `n_tests` independent tests, so that the whole
/// family fails with probability `significance` when every sampler is correct.
pub fn sidak(significance: f64, n_tests: usize) -> f64 {
    1.0 - (1.0 - significance).powf(1.0 / n_tests.max(1) as f64)
}

/// Chi-square goodness-of-fit of a direction sampler against its pdf over the sphere (Mitsuba's `ChiSquareTest` approach):
/// histogram over (cos θ, φ) bins of `n_samples` samples drawn by `sample(u1, u2)` (None = failed sample, counts as missing mass),
/// expected counts by integrating `pdf(dir)` (solid-angle density) over each bin numerically (adaptive/Simpson, fine enough),
/// pool bins with expected count < 5, and test at `significance` (e.g. 0.01) with a p-value from the regularized incomplete gamma.
///
/// Bins are uniform in cos θ ∈ [−1, 1] (row 0 holds cos θ near −1) and φ ∈ [0, 2π), so every bin
/// has the same solid angle; an even `res_theta` puts the equator on a bin edge. A sample that is not a unit vector
/// (|‖d‖ − 1| > 1e-3 or non-finite) fails the test.
pub fn chi2_sphere(
    mut sample: impl FnMut(f32, Vec2) -> Option<Vec3>,
    pdf: impl Fn(Vec3) -> f32,
    res_theta: usize,
    res_phi: usize,
    n_samples: usize,
    significance: f64,
    seed: u64,
) -> Chi2Result {
    let res_theta = res_theta.max(1);
    let res_phi = res_phi.max(1);
    let n_bins = res_theta * res_phi;

    // ---- Histogram of the sampler ----
    let mut observed = vec![0u64; n_bins];
    let mut n_failed = 0u64;
    let mut n_invalid = 0u64;
    let mut first_invalid = None;
    let mut rng = Sampler::new(seed, 0x5EED_C412);
    for _ in 0..n_samples {
        let u1 = rng.next_1d();
        let u2 = rng.next_2d();
        match sample(u1, u2) {
            None => n_failed += 1,
            Some(d) => {
                let len = d.length();
                if !len.is_finite() || (len - 1.0).abs() > 1e-3 {
                    n_invalid += 1;
                    first_invalid.get_or_insert(d);
                    continue;
                }
                let (i, j) = bin_of(d / len, res_theta, res_phi);
                observed[i * res_phi + j] += 1;
            }
        }
    }

    // ---- Expected counts: ∫ pdf over each bin, in (z = cos θ, φ) where dω = dz dφ ----
    let dz = 2.0 / res_theta as f64;
    let dphi = 2.0 * std::f64::consts::PI / res_phi as f64;
    let n = n_samples as f64;
    let pdf_zphi = |z: f64, phi: f64| -> f64 {
        let z = z.clamp(-1.0, 1.0);
        let r = (1.0 - z * z).max(0.0).sqrt();
        let d = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
        let p = pdf(d) as f64;
        if p.is_finite() {
            p
        } else {
            f64::NAN
        }
    };
    let mut expected = vec![0f64; n_bins];
    let mut pdf_integral = 0.0;
    let mut non_finite_pdf = false;
    for i in 0..res_theta {
        let z0 = -1.0 + i as f64 * dz;
        for j in 0..res_phi {
            let p0 = j as f64 * dphi;
            // Tolerance on the bin's integral: an error e in a cell with expected count E adds about
            // e²/E to the statistic; keep e ≤ 0.01 counts (0.01·√E for large E).
            let coarse = simpson_3x3(&pdf_zphi, z0, z0 + dz, p0, p0 + dphi);
            let tol_counts = 0.01 * (coarse * n).sqrt().max(1.0);
            let v = adaptive_simpson(&pdf_zphi, z0, z0 + dz, p0, p0 + dphi, coarse, tol_counts / n, 0);
            if !v.is_finite() {
                non_finite_pdf = true;
            }
            let v = if v.is_finite() { v.max(0.0) } else { 0.0 };
            expected[i * res_phi + j] = v * n;
            pdf_integral += v;
        }
    }

    // ---- Cells: the bins plus the missing mass of failed samples ----
    let mut cells: Vec<Cell> = (0..n_bins)
        .map(|k| Cell { observed: observed[k] as f64, expected: expected[k], label: CellLabel::Bin(k) })
        .collect();
    cells.push(Cell {
        observed: n_failed as f64,
        expected: (n * (1.0 - pdf_integral)).max(0.0),
        label: CellLabel::Missing,
    });

    let describe = |label: CellLabel| -> String {
        match label {
            CellLabel::Bin(k) => {
                let (i, j) = (k / res_phi, k % res_phi);
                let z0 = -1.0 + i as f64 * dz;
                let p0 = j as f64 * dphi;
                format!("bin cosθ∈[{:.3},{:.3}] φ∈[{:.3},{:.3}]", z0, z0 + dz, p0, p0 + dphi)
            }
            CellLabel::Missing => "missing mass (failed samples)".to_string(),
        }
    };
    let mut result = pearson(cells, significance, &describe);
    result.pdf_integral = pdf_integral;
    let mut head = format!(
        "chi2_sphere: {} samples, {}x{} bins, {} failed, ∫pdf = {:.6}\n",
        n_samples, res_theta, res_phi, n_failed, pdf_integral
    );
    if n_invalid > 0 {
        result.passed = false;
        let _ = writeln!(head, "FAIL: {} samples were not unit vectors (first: {:?})", n_invalid, first_invalid);
    }
    if non_finite_pdf {
        result.passed = false;
        let _ = writeln!(head, "FAIL: the pdf returned a non-finite value");
    }
    result.report = head + &result.report;
    result
}

/// Chi-square test of observed outcome counts against outcome probabilities (multinomial; with two
/// outcomes this is the binomial test of e.g. reflection vs transmission frequency). `probs` may sum to
/// less than 1; the remainder is an extra "other" outcome expected `n·(1 − Σ probs)` times, where
/// `n = Σ counts + other_count`.
pub fn chi2_discrete(counts: &[u64], other_count: u64, probs: &[f64], significance: f64) -> Chi2Result {
    let n = (counts.iter().sum::<u64>() + other_count) as f64;
    let total_p: f64 = probs.iter().sum();
    let mut cells: Vec<Cell> = counts
        .iter()
        .enumerate()
        .map(|(k, &c)| Cell {
            observed: c as f64,
            expected: probs.get(k).copied().unwrap_or(0.0).max(0.0) * n,
            label: CellLabel::Bin(k),
        })
        .collect();
    cells.push(Cell {
        observed: other_count as f64,
        expected: (n * (1.0 - total_p)).max(0.0),
        label: CellLabel::Missing,
    });
    let describe = |label: CellLabel| -> String {
        match label {
            CellLabel::Bin(k) => format!("outcome {}", k),
            CellLabel::Missing => "other outcomes".to_string(),
        }
    };
    let mut r = pearson(cells, significance, &describe);
    r.pdf_integral = total_p;
    let mut head =
        format!("chi2_discrete: {} samples, counts {:?} (+{} other), probs {:?}\n", n, counts, other_count, probs);
    if probs.len() != counts.len() {
        r.passed = false;
        let _ = writeln!(head, "FAIL: {} counts but {} probabilities", counts.len(), probs.len());
    }
    r.report = head + &r.report;
    r
}

#[derive(Clone, Copy, Debug)]
enum CellLabel {
    Bin(usize),
    Missing,
}

#[derive(Clone, Copy, Debug)]
struct Cell {
    observed: f64,
    expected: f64,
    label: CellLabel,
}

/// Pearson's statistic with Mitsuba's pooling: cells sorted by expected count, those below 5 pooled
/// into one cell (together with the next cells until the pool reaches 5); observations in a cell
/// with expected count 0 fail the test outright.
fn pearson(mut cells: Vec<Cell>, significance: f64, describe: &dyn Fn(CellLabel) -> String) -> Chi2Result {
    let mut report = String::new();
    let mut impossible = 0u64;
    let mut contrib: Vec<(f64, Cell)> = Vec::new();
    cells.sort_by(|a, b| a.expected.total_cmp(&b.expected));
    let (mut chi2, mut dof) = (0.0f64, 0usize);
    let (mut pooled_obs, mut pooled_exp, mut pooled_cells) = (0.0f64, 0.0f64, 0usize);
    for c in &cells {
        if c.expected <= 0.0 {
            if c.observed > 0.0 {
                impossible += c.observed as u64;
                if impossible as f64 == c.observed {
                    let _ = writeln!(
                        report,
                        "FAIL: {} samples in a cell with expected count 0: {}",
                        c.observed,
                        describe(c.label)
                    );
                }
            }
            continue;
        }
        if c.expected < 5.0 || (pooled_cells > 0 && pooled_exp < 5.0) {
            pooled_obs += c.observed;
            pooled_exp += c.expected;
            pooled_cells += 1;
        } else {
            let d = c.observed - c.expected;
            let term = d * d / c.expected;
            chi2 += term;
            dof += 1;
            contrib.push((term, *c));
        }
    }
    if pooled_cells > 0 && pooled_exp > 0.0 {
        let d = pooled_obs - pooled_exp;
        chi2 += d * d / pooled_exp;
        dof += 1;
    }
    let dof = dof.saturating_sub(1);
    let p_value = if dof == 0 { 1.0 } else { gamma_q(dof as f64 / 2.0, chi2 / 2.0) };
    let passed = impossible == 0 && p_value > significance;
    let _ = writeln!(
        report,
        "chi2 = {:.2}, dof = {}, p = {:.4e} ({} at significance {}); {} cells pooled (observed {}, expected {:.1})",
        chi2,
        dof,
        p_value,
        if passed { "pass" } else { "FAIL" },
        significance,
        pooled_cells,
        pooled_obs,
        pooled_exp
    );
    if !passed {
        contrib.sort_by(|a, b| b.0.total_cmp(&a.0));
        for (term, c) in contrib.iter().take(8) {
            let _ = writeln!(
                report,
                "  {:>10.2}  observed {:>9} expected {:>11.2}  {}",
                term,
                c.observed,
                c.expected,
                describe(c.label)
            );
        }
    }
    Chi2Result { p_value, chi2, dof, passed, pdf_integral: 0.0, report }
}

/// The (cos θ, φ) bin of a unit direction.
fn bin_of(d: Vec3, res_theta: usize, res_phi: usize) -> (usize, usize) {
    let z = d.z.clamp(-1.0, 1.0) as f64;
    let i = (((z + 1.0) * 0.5 * res_theta as f64) as usize).min(res_theta - 1);
    let mut phi = (d.y as f64).atan2(d.x as f64);
    if phi < 0.0 {
        phi += 2.0 * std::f64::consts::PI;
    }
    let j = ((phi / (2.0 * std::f64::consts::PI) * res_phi as f64) as usize).min(res_phi - 1);
    (i, j)
}

/// Simpson's rule on a 3×3 grid over the rectangle [z0, z1] × [p0, p1].
fn simpson_3x3(f: &dyn Fn(f64, f64) -> f64, z0: f64, z1: f64, p0: f64, p1: f64) -> f64 {
    const W: [f64; 3] = [1.0, 4.0, 1.0];
    let (zm, pm) = (0.5 * (z0 + z1), 0.5 * (p0 + p1));
    let zs = [z0, zm, z1];
    let ps = [p0, pm, p1];
    let mut s = 0.0;
    for (a, &z) in zs.iter().enumerate() {
        for (b, &p) in ps.iter().enumerate() {
            s += W[a] * W[b] * f(z, p);
        }
    }
    s * (z1 - z0) * (p1 - p0) / 36.0
}

/// Deepest refinement of a bin (a discontinuity crossing a bin costs about 72·2^MAX_DEPTH pdf evaluations).
const MAX_DEPTH: u32 = 10;
/// Every bin is refined at least this often (4^MIN_DEPTH sub-cells), so narrow peaks between nodes are seen.
const MIN_DEPTH: u32 = 2;

/// Adaptive 2D Simpson: split into 4 until the refined and coarse estimates agree within `tol`.
/// Refines at least [`MIN_DEPTH`] and at most [`MAX_DEPTH`] levels. Smooth pdfs converge fast; a pdf
/// that jumps inside a bin converges only as O(h), so put known discontinuities (the horizon) on bin edges.
#[allow(clippy::too_many_arguments)]
fn adaptive_simpson(
    f: &dyn Fn(f64, f64) -> f64,
    z0: f64,
    z1: f64,
    p0: f64,
    p1: f64,
    coarse: f64,
    tol: f64,
    depth: u32,
) -> f64 {
    let (zm, pm) = (0.5 * (z0 + z1), 0.5 * (p0 + p1));
    let q = [
        simpson_3x3(f, z0, zm, p0, pm),
        simpson_3x3(f, zm, z1, p0, pm),
        simpson_3x3(f, z0, zm, pm, p1),
        simpson_3x3(f, zm, z1, pm, p1),
    ];
    let fine: f64 = q.iter().sum();
    let err = (fine - coarse).abs();
    if !fine.is_finite() {
        return fine;
    }
    if depth >= MAX_DEPTH || (depth >= MIN_DEPTH && err <= 15.0 * tol) {
        return fine + (fine - coarse) / 15.0;
    }
    let t = tol * 0.5;
    adaptive_simpson(f, z0, zm, p0, pm, q[0], t, depth + 1)
        + adaptive_simpson(f, zm, z1, p0, pm, q[1], t, depth + 1)
        + adaptive_simpson(f, z0, zm, pm, p1, q[2], t, depth + 1)
        + adaptive_simpson(f, zm, z1, pm, p1, q[3], t, depth + 1)
}

/// ln Γ(x) for x > 0 (Lanczos, g = 7, 9 terms; ~1e-15 relative).
pub fn ln_gamma(x: f64) -> f64 {
    const G: f64 = 7.0;
    const C: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        // Reflection formula.
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = C[0];
    let t = x + G + 0.5;
    for (i, c) in C.iter().enumerate().skip(1) {
        a += c / (x + i as f64);
    }
    0.5 * (2.0 * std::f64::consts::PI).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

/// Regularized upper incomplete gamma Q(a, x) = Γ(a, x)/Γ(a): the chi-square survival function is
/// Q(dof/2, χ²/2). Series for x < a + 1, Lentz continued fraction otherwise (Numerical Recipes §6.2).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    if !x.is_finite() {
        return 0.0;
    }
    let ln_pre = -x + a * x.ln() - ln_gamma(a);
    if x < a + 1.0 {
        // P(a, x) by its series.
        let mut ap = a;
        let mut del = 1.0 / a;
        let mut sum = del;
        for _ in 0..100_000 {
            ap += 1.0;
            del *= x / ap;
            sum += del;
            if del.abs() < sum.abs() * 1e-15 {
                break;
            }
        }
        (1.0 - sum * ln_pre.exp()).clamp(0.0, 1.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..100_000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-15 {
                break;
            }
        }
        (ln_pre.exp() * h).clamp(0.0, 1.0)
    }
}

/// Spherical coordinates helper for tests: the unit direction at polar angle `theta` and azimuth `phi`.
pub fn spherical_direction(theta: f32, phi: f32) -> Vec3 {
    let (st, ct) = theta.sin_cos();
    let (sp, cp) = phi.sin_cos();
    Vec3::new(st * cp, st * sp, ct)
}

/// Degrees to radians (test parameters read better in degrees).
pub fn deg(x: f32) -> f32 {
    x * PI / 180.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::warp;

    #[test]
    fn gamma_q_known_values() {
        // Chi-square survival function: Q(k/2, x/2).
        // dof 1, x = 3.841458820694124 → p = 0.05; dof 10, x = 23.209251158954356 → p = 0.01.
        assert!((gamma_q(0.5, 3.841_458_820_694_124 / 2.0) - 0.05).abs() < 1e-10);
        assert!((gamma_q(5.0, 23.209_251_158_954_356 / 2.0) - 0.01).abs() < 1e-10);
        // dof 2: Q(1, x) = exp(-x).
        for x in [0.1, 1.0, 5.0, 30.0] {
            assert!((gamma_q(1.0, x) - (-x).exp()).abs() < 1e-12);
        }
        // Large dof: dof 1000 at its 99th percentile 1106.969.
        assert!((gamma_q(500.0, 1106.969 / 2.0) - 0.01).abs() < 2e-4);
        assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
        assert!((ln_gamma(0.5) - std::f64::consts::PI.sqrt().ln()).abs() < 1e-12);
    }

    /// A correct warp passes (16 × 32 cells, 200k samples, level 1 %) and its pdf integrates to 1.
    fn assert_warp_passes(warp: fn(Vec2) -> Vec3, pdf: impl Fn(Vec3) -> f32, seed: u64) {
        let r = chi2_sphere(|_, u| Some(warp(u)), pdf, 16, 32, 200_000, 0.01, seed);
        assert!(r.passed, "{}", r.report);
        assert!((r.pdf_integral - 1.0).abs() < 1e-6, "{}", r.pdf_integral);
    }

    #[test]
    fn uniform_sphere_passes() {
        assert_warp_passes(warp::square_to_uniform_sphere, |_| warp::square_to_uniform_sphere_pdf(), 7);
    }

    #[test]
    fn cosine_hemisphere_passes() {
        assert_warp_passes(warp::square_to_cosine_hemisphere, warp::square_to_cosine_hemisphere_pdf, 8);
    }

    #[test]
    fn wrong_pdf_fails() {
        // Cosine-weighted samples against a uniform-hemisphere pdf.
        let r = chi2_sphere(
            |_, u| Some(warp::square_to_cosine_hemisphere(u)),
            |d| {
                if d.z > 0.0 {
                    warp::square_to_uniform_hemisphere_pdf()
                } else {
                    0.0
                }
            },
            16,
            32,
            100_000,
            0.01,
            9,
        );
        assert!(!r.passed, "{}", r.report);
        assert!(r.p_value < 1e-10);
    }

    #[test]
    fn slightly_wrong_pdf_fails() {
        // pdf of a cone 2% too wide: a subtle error must still be caught.
        let cos_cut = 0.7f32;
        let r = chi2_sphere(
            |_, u| Some(warp::square_to_uniform_cone(u, cos_cut)),
            |d| warp::square_to_uniform_cone_pdf(d, cos_cut - 0.02),
            32,
            32,
            500_000,
            0.01,
            10,
        );
        assert!(!r.passed, "{}", r.report);
    }

    #[test]
    fn missing_mass_is_tested() {
        // A sampler that fails 30% of the time with a pdf scaled by 0.7 passes...
        let mut k = 0u32;
        let r = chi2_sphere(
            |u1, u| {
                k += 1;
                (u1 < 0.7).then(|| warp::square_to_uniform_sphere(u))
            },
            |_| 0.7 * warp::square_to_uniform_sphere_pdf(),
            8,
            16,
            100_000,
            0.01,
            11,
        );
        assert!(r.passed, "{}", r.report);
        assert!((r.pdf_integral - 0.7).abs() < 1e-6);
        // ... while claiming the full pdf fails.
        let r = chi2_sphere(
            |u1, u| (u1 < 0.7).then(|| warp::square_to_uniform_sphere(u)),
            |_| warp::square_to_uniform_sphere_pdf(),
            8,
            16,
            100_000,
            0.01,
            11,
        );
        assert!(!r.passed, "{}", r.report);
    }

    #[test]
    fn samples_where_pdf_is_zero_fail() {
        let r = chi2_sphere(
            |_, u| Some(warp::square_to_uniform_sphere(u)),
            |d| {
                if d.z > 0.0 {
                    2.0 * warp::square_to_uniform_sphere_pdf()
                } else {
                    0.0
                }
            },
            8,
            16,
            10_000,
            0.01,
            12,
        );
        assert!(!r.passed);
        assert!(r.report.contains("expected count 0"), "{}", r.report);
    }

    #[test]
    fn narrow_lobe_integrates() {
        // A narrow smooth lobe (von Mises-Fisher, κ = 2000: about 1.3° wide) in an oblique direction,
        // much smaller than a bin: the adaptive integration must find it, and the missing-mass cell
        // (expected n·(1 − ∫pdf), observed 0) checks that it integrates it accurately.
        let kappa = 2000.0f64;
        let frame = crate::math::Frame::from_normal(Vec3::new(0.5, -0.3, 0.6).normalize());
        let norm = kappa / (2.0 * std::f64::consts::PI * (1.0 - (-2.0 * kappa).exp()));
        let r = chi2_sphere(
            |_, u| {
                let u = u.as_dvec2();
                let w = 1.0 + (u.y + (1.0 - u.y) * (-2.0 * kappa).exp()).ln() / kappa;
                let r = (1.0 - w * w).max(0.0).sqrt();
                let phi = 2.0 * std::f64::consts::PI * u.x;
                let local = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, w as f32);
                Some(frame.to_world(local).normalize())
            },
            |d| (norm * (kappa * (d.dot(frame.n) as f64 - 1.0)).exp()) as f32,
            16,
            32,
            100_000,
            0.01,
            13,
        );
        assert!(r.passed, "{}", r.report);
        assert!((r.pdf_integral - 1.0).abs() < 1e-4, "{}", r.pdf_integral);
    }

    #[test]
    fn discrete() {
        let mut rng = Sampler::new(3, 4);
        let p = [0.04, 0.96];
        let mut c = [0u64; 2];
        for _ in 0..100_000 {
            c[(rng.next_1d() >= 0.04) as usize] += 1;
        }
        let r = chi2_discrete(&c, 0, &p, 0.01);
        assert!(r.passed, "{}", r.report);
        let r = chi2_discrete(&c, 0, &[0.05, 0.95], 0.01);
        assert!(!r.passed, "{}", r.report);
        // Probabilities summing to less than one, the rest as "other".
        let r = chi2_discrete(&[c[0]], c[1], &[0.04], 0.01);
        assert!(r.passed, "{}", r.report);
        assert!((sidak(0.01, 1) - 0.01).abs() < 1e-12 && sidak(0.01, 10) < 0.0011);
    }
}

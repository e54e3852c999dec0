//! Microfacet distributions (Beckmann and GGX), their visible-normal sampling and Smith
//! shadowing-masking, as in Mitsuba's `microfacet.h` (Walter et al. 2007; Heitz & d'Eon 2014;
//! Jakob's improved Beckmann visible-normal inversion; Heitz 2018 for GGX).
//!
//! All vectors are in the local shading frame (+Z = macro-surface normal). Alphas are clamped
//! to at least 1e-4 like Mitsuba does.

use crate::math::{safe_sqrt, warp, Vec2, Vec3, PI};
use crate::scene::desc::Props;
use crate::scene::Result;

/// The normal distribution function.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MicrofacetType {
    /// Gaussian random surface (Mitsuba's default for `roughdielectric`).
    Beckmann,
    /// GGX / Trowbridge-Reitz, long-tailed.
    Ggx,
}

/// The `distribution` parameter: `beckmann` (default) or `ggx`, case-insensitive as in Mitsuba.
pub fn read_distribution(props: &Props) -> Result<MicrofacetType> {
    match props.string_opt("distribution")? {
        None => Ok(MicrofacetType::Beckmann),
        Some(s) => {
            match s.to_ascii_lowercase().as_str() {
                "beckmann" => Ok(MicrofacetType::Beckmann),
                "ggx" => Ok(MicrofacetType::Ggx),
                _ => Err(props
                    .error("distribution", format!("invalid distribution \"{}\", must be \"beckmann\" or \"ggx\"", s))),
            }
        }
    }
}

/// A microfacet distribution with (possibly anisotropic) roughness.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MicrofacetDistribution {
    pub kind: MicrofacetType,
    /// Roughness along the tangent (local x).
    pub alpha_u: f32,
    /// Roughness along the bitangent (local y).
    pub alpha_v: f32,
    /// Sample the distribution of visible normals (Heitz & d'Eon) instead of D(m)·cos θm.
    pub sample_visible: bool,
}

const INV_SQRT_PI: f32 = 0.564_189_6;

impl MicrofacetDistribution {
    /// A distribution; alphas below 1e-4 are clamped (Mitsuba's `configure()`).
    pub fn new(kind: MicrofacetType, alpha_u: f32, alpha_v: f32, sample_visible: bool) -> Self {
        MicrofacetDistribution { kind, alpha_u: alpha_u.max(1e-4), alpha_v: alpha_v.max(1e-4), sample_visible }
    }

    #[inline]
    pub fn is_isotropic(&self) -> bool {
        self.alpha_u == self.alpha_v
    }

    /// Scale both roughness values (Walter's trick for non-visible sampling).
    #[inline]
    pub fn scale_alpha(&mut self, value: f32) {
        self.alpha_u *= value;
        self.alpha_v *= value;
    }

    /// The normal distribution D(m) (density of normals per projected area: ∫ D(m) cos θm dm = 1).
    #[inline]
    pub fn eval(&self, m: Vec3) -> f32 {
        let alpha_uv = self.alpha_u * self.alpha_v;
        let cos_theta = m.z;
        let cos_theta_2 = cos_theta * cos_theta;
        let xu = m.x / self.alpha_u;
        let yv = m.y / self.alpha_v;
        let result = match self.kind {
            MicrofacetType::Beckmann => {
                (-(xu * xu + yv * yv) / cos_theta_2).exp() / (PI * alpha_uv * cos_theta_2 * cos_theta_2)
            }
            MicrofacetType::Ggx => {
                let t = xu * xu + yv * yv + m.z * m.z;
                1.0 / (PI * alpha_uv * t * t)
            }
        };
        // Prevent numerical issues in other stages of the model (and m below the horizon).
        if result * cos_theta > 1e-20 {
            result
        } else {
            0.0
        }
    }

    /// Density of [`sample`](Self::sample) over microfacet normals (solid angle).
    #[inline]
    pub fn pdf(&self, wi: Vec3, m: Vec3) -> f32 {
        let d = self.eval(m);
        if self.sample_visible {
            d * self.smith_g1(wi, m) * wi.dot(m).abs() / wi.z
        } else {
            d * m.z
        }
    }

    /// Sample a microfacet normal (visible normals seen from `wi`, or D(m)·cos θm); returns
    /// `(m, pdf)`.
    pub fn sample(&self, wi: Vec3, sample: Vec2) -> (Vec3, f32) {
        if !self.sample_visible {
            // Azimuth (identical for Beckmann and GGX).
            let (sin_phi, cos_phi, alpha_2);
            if self.is_isotropic() {
                let (s, c) = crate::math::fast::sincos_2pi(sample.y);
                sin_phi = s;
                cos_phi = c;
                alpha_2 = self.alpha_u * self.alpha_u;
            } else {
                let ratio = self.alpha_v / self.alpha_u;
                let tmp = ratio * (2.0 * PI * sample.y).tan();
                let c = (1.0 / (tmp * tmp + 1.0).sqrt()).copysign((sample.y - 0.5).abs() - 0.25);
                cos_phi = c;
                sin_phi = c * tmp;
                let (a, b) = (cos_phi / self.alpha_u, sin_phi / self.alpha_v);
                alpha_2 = 1.0 / (a * a + b * b);
            }
            // Elevation.
            let (cos_theta, pdf) = match self.kind {
                MicrofacetType::Beckmann => {
                    let cos_theta = 1.0 / (1.0 - alpha_2 * (1.0 - sample.x).ln()).sqrt();
                    let cos_theta_3 = (cos_theta * cos_theta * cos_theta).max(1e-20);
                    (cos_theta, (1.0 - sample.x) / (PI * self.alpha_u * self.alpha_v * cos_theta_3))
                }
                MicrofacetType::Ggx => {
                    let tan_theta_m_2 = alpha_2 * sample.x / (1.0 - sample.x);
                    let cos_theta = 1.0 / (1.0 + tan_theta_m_2).sqrt();
                    let temp = 1.0 + tan_theta_m_2 / alpha_2;
                    let cos_theta_3 = (cos_theta * cos_theta * cos_theta).max(1e-20);
                    (cos_theta, 1.0 / (PI * self.alpha_u * self.alpha_v * cos_theta_3 * temp * temp))
                }
            };
            let sin_theta = (1.0 - cos_theta * cos_theta).sqrt();
            (Vec3::new(cos_phi * sin_theta, sin_phi * sin_theta, cos_theta), pdf)
        } else {
            // 1. Stretch wi to the alpha = 1 configuration.
            let wi_p = Vec3::new(self.alpha_u * wi.x, self.alpha_v * wi.y, wi.z).normalize();
            let (sin_phi, cos_phi) = sincos_phi(wi_p);
            let cos_theta = wi_p.z;
            // 2. Sample the slopes of visible normals for alpha = 1.
            let slope = self.sample_visible_11(cos_theta, sample);
            // 3. Rotate back and unstretch.
            let slope = Vec2::new(
                (cos_phi * slope.x - sin_phi * slope.y) * self.alpha_u,
                (sin_phi * slope.x + cos_phi * slope.y) * self.alpha_v,
            );
            // 4. Normal and density.
            let m = Vec3::new(-slope.x, -slope.y, 1.0).normalize();
            let pdf = self.eval(m) * self.smith_g1(wi, m) * wi.dot(m).abs() / wi.z;
            (m, pdf)
        }
    }

    /// Smith's separable shadowing-masking G(wi, wo, m) = G1(wi, m) G1(wo, m).
    #[inline]
    pub fn g(&self, wi: Vec3, wo: Vec3, m: Vec3) -> f32 {
        self.smith_g1(wi, m) * self.smith_g1(wo, m)
    }

    /// Smith's masking function for one direction `v` (0 when `v` sees the back of `m`).
    #[inline]
    pub fn smith_g1(&self, v: Vec3, m: Vec3) -> f32 {
        let (au, av) = (self.alpha_u * v.x, self.alpha_v * v.y);
        let xy_alpha_2 = au * au + av * av;
        let tan_theta_alpha_2 = xy_alpha_2 / (v.z * v.z);
        let mut result = match self.kind {
            MicrofacetType::Beckmann => {
                let a = 1.0 / tan_theta_alpha_2.sqrt();
                let a_sqr = a * a;
                // Rational approximation (< 0.35% relative error).
                if a >= 1.6 {
                    1.0
                } else {
                    (3.535 * a + 2.181 * a_sqr) / (1.0 + 2.276 * a + 2.577 * a_sqr)
                }
            }
            MicrofacetType::Ggx => 2.0 / (1.0 + (1.0 + tan_theta_alpha_2).sqrt()),
        };
        // Perpendicular incidence: no shadowing/masking.
        if xy_alpha_2 == 0.0 {
            result = 1.0;
        }
        // Consistent orientation: the back of a microfacet is never visible.
        if v.dot(m) * v.z <= 0.0 {
            result = 0.0;
        }
        result
    }

    /// Slopes of visible normals for alpha = 1 seen from elevation `cos_theta_i`.
    fn sample_visible_11(&self, cos_theta_i: f32, sample: Vec2) -> Vec2 {
        match self.kind {
            MicrofacetType::Beckmann => {
                // Numerical inversion of the CDF in the erf domain (Jakob 2014).
                let tan_theta_i = safe_sqrt(1.0 - cos_theta_i * cos_theta_i) / cos_theta_i;
                let cot_theta_i = 1.0 / tan_theta_i;
                let maxval = erf(cot_theta_i);
                let mut sample = sample.clamp(Vec2::splat(1e-6), Vec2::splat(1.0 - 1e-6));
                // Initial guess: the analytic solution for θi = π/2.
                let mut x = maxval - (maxval + 1.0) * erf((-sample.x.ln()).sqrt());
                // Normalisation of the CDF.
                sample.x *= 1.0 + maxval + INV_SQRT_PI * tan_theta_i * (-cot_theta_i * cot_theta_i).exp();
                for _ in 0..3 {
                    let slope = erfinv(x);
                    let value = 1.0 + x + INV_SQRT_PI * tan_theta_i * (-slope * slope).exp() - sample.x;
                    let derivative = 1.0 - slope * tan_theta_i;
                    x -= value / derivative;
                }
                Vec2::new(erfinv(x), erfinv(2.0 * sample.y - 1.0))
            }
            MicrofacetType::Ggx => {
                // Heitz 2018: a projected disk sample, rescaled to the visible half.
                let mut p = warp::square_to_uniform_disk_concentric(sample);
                let s = 0.5 * (1.0 + cos_theta_i);
                let h = safe_sqrt(1.0 - p.x * p.x);
                p.y = h + (p.y - h) * s;
                let (x, y) = (p.x, p.y);
                let z = safe_sqrt(1.0 - p.length_squared());
                let sin_theta_i = safe_sqrt(1.0 - cos_theta_i * cos_theta_i);
                let norm = 1.0 / (sin_theta_i * y + cos_theta_i * z);
                Vec2::new(cos_theta_i * y - sin_theta_i * z, x) * norm
            }
        }
    }
}

/// (sin φ, cos φ) of a direction; (0, 1) at the pole (Mitsuba's `Frame3f::sincos_phi`).
#[inline]
fn sincos_phi(v: Vec3) -> (f32, f32) {
    let sin_theta_2 = v.x * v.x + v.y * v.y;
    if sin_theta_2.abs() <= 4.0 * f32::EPSILON * 0.5 {
        return (0.0, 1.0);
    }
    let inv = 1.0 / sin_theta_2.sqrt();
    ((v.y * inv).clamp(-1.0, 1.0), (v.x * inv).clamp(-1.0, 1.0))
}

/// Error function, to f32 precision (absolute error < 2e-7; relative < 1e-7 near 0).
pub fn erf(x: f32) -> f32 {
    erf_f64(x as f64) as f32
}

fn erf_f64(x: f64) -> f64 {
    let z = x.abs();
    if z < 0.5 {
        // Taylor series: 2/√π (x − x³/3 + x⁵/10 − x⁷/42 + x⁹/216 − x¹¹/1320); next term < 2e-8.
        let x2 = x * x;
        let p = 1.0 + x2 * (-1.0 / 3.0 + x2 * (0.1 + x2 * (-1.0 / 42.0 + x2 * (1.0 / 216.0 - x2 / 1320.0))));
        return std::f64::consts::FRAC_2_SQRT_PI * x * p;
    }
    // Chebyshev fit of erfc (Numerical Recipes `erfcc`, fractional error < 1.2e-7).
    let t = 1.0 / (1.0 + 0.5 * z);
    let poly = -1.265_512_23
        + t * (1.000_023_68
            + t * (0.374_091_96
                + t * (0.096_784_18
                    + t * (-0.186_288_06
                        + t * (0.278_868_07
                            + t * (-1.135_203_98 + t * (1.488_515_87 + t * (-0.822_152_23 + t * 0.170_872_77))))))));
    let erfc = t * (-z * z + poly).exp();
    (1.0 - erfc).copysign(x)
}

/// Inverse error function on (−1, 1): Giles' single-precision approximation ("Approximating the
/// erfinv function", 2010), the one Dr.Jit uses; ±∞ at ±1.
pub fn erfinv(x: f32) -> f32 {
    if x <= -1.0 {
        return f32::NEG_INFINITY;
    }
    if x >= 1.0 {
        return f32::INFINITY;
    }
    let xf = x as f64;
    let mut w = -((1.0 - xf) * (1.0 + xf)).ln();
    let mut p;
    if w < 5.0 {
        w -= 2.5;
        p = 2.810_226_36e-08;
        for c in [
            3.432_739_39e-07,
            -3.523_387_7e-06,
            -4.391_506_54e-06,
            0.000_218_580_87,
            -0.001_253_725_03,
            -0.004_177_681_64,
            0.246_640_727,
            1.501_409_41,
        ] {
            p = c + p * w;
        }
    } else {
        w = w.sqrt() - 3.0;
        p = -0.000_200_214_257;
        for c in [
            0.000_100_950_558,
            0.001_349_343_22,
            -0.003_673_428_44,
            0.005_739_507_73,
            -0.007_622_461_3,
            0.009_438_870_47,
            1.001_674_06,
            2.832_976_82,
        ] {
            p = c + p * w;
        }
    }
    (p * xf) as f32
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Frame;
    use crate::sampler::Sampler;

    #[test]
    fn erf_and_inverse() {
        // Reference values of erf (Abramowitz & Stegun table 7.1 / high-precision values).
        for (x, e) in [
            (0.001, 0.001_128_378_790_969_3),
            (0.1, 0.112_462_916_018_284_9),
            (0.49, 0.511_668_261_487_947_9),
            (0.5, 0.520_499_877_813_046_5),
            (1.0, 0.842_700_792_949_714_9),
            (2.0, 0.995_322_265_018_952_7),
            (3.5, 0.999_999_256_901_627_7),
            (5.0, 0.999_999_999_998_462_5),
        ] {
            assert!((erf_f64(x) - e).abs() < 2e-7 * e.max(0.1), "erf({}) = {}", x, erf_f64(x));
            assert!((erf_f64(-x) + e).abs() < 2e-7 * e.max(0.1));
        }
        for k in -99..=99 {
            let x = k as f32 / 100.0;
            assert!((erf(erfinv(x)) - x).abs() < 1e-6, "{}", x);
            assert!((erfinv(erf(x)) - x).abs() < 1e-6 * x.abs().max(0.1), "{}", x);
        }
        assert_eq!(erf(f32::INFINITY), 1.0);
    }

    /// ∫ D(m) (m·n) dm = 1 and ∫ D(m) G1(wi, m) max(0, wi·m) dm = cos θi (projected area), by quadrature.
    #[test]
    fn normalisation_and_visible_area() {
        for kind in [MicrofacetType::Beckmann, MicrofacetType::Ggx] {
            for (au, av) in [(0.1, 0.1), (0.5, 0.5), (0.1, 0.4)] {
                let distr = MicrofacetDistribution::new(kind, au, av, true);
                let wi = Vec3::new(0.5, 0.2, 0.6).normalize();
                let (n_t, n_p) = (4000, 256);
                let (mut norm, mut proj) = (0.0f64, 0.0f64);
                for i in 0..n_t {
                    // θ in [0, π/2) with a substitution fine near the pole.
                    let u = (i as f64 + 0.5) / n_t as f64;
                    let theta = u * u * std::f64::consts::FRAC_PI_2;
                    let dtheta = 2.0 * u * std::f64::consts::FRAC_PI_2 / n_t as f64;
                    for j in 0..n_p {
                        let phi = (j as f64 + 0.5) / n_p as f64 * 2.0 * std::f64::consts::PI;
                        let m = Vec3::new(
                            (theta.sin() * phi.cos()) as f32,
                            (theta.sin() * phi.sin()) as f32,
                            theta.cos() as f32,
                        );
                        let dw = theta.sin() * dtheta * 2.0 * std::f64::consts::PI / n_p as f64;
                        let d = distr.eval(m) as f64;
                        norm += d * m.z as f64 * dw;
                        proj += d * distr.smith_g1(wi, m) as f64 * (wi.dot(m).max(0.0)) as f64 * dw;
                    }
                }
                assert!((norm - 1.0).abs() < 2e-3, "{:?} {} {}: {}", kind, au, av, norm);
                // Smith G1 is exact for GGX; the Beckmann rational fit has < 0.35% error.
                assert!((proj / wi.z as f64 - 1.0).abs() < 5e-3, "{:?} {} {}: {}", kind, au, av, proj);
            }
        }
    }

    /// Normals from `sample` follow `pdf` (chi-square over the hemisphere), both sampling modes.
    #[test]
    fn sampling_matches_pdf() {
        use crate::testing::chi2::chi2_sphere;
        for kind in [MicrofacetType::Beckmann, MicrofacetType::Ggx] {
            for visible in [true, false] {
                for (au, av) in [(0.2, 0.2), (0.1, 0.4)] {
                    let distr = MicrofacetDistribution::new(kind, au, av, visible);
                    let wi = Frame::from_normal(Vec3::Z).to_world(Vec3::new(0.6, -0.3, 0.5).normalize());
                    let r = chi2_sphere(
                        |_, u| Some(distr.sample(wi, u).0),
                        |m| distr.pdf(wi, m),
                        32,
                        64,
                        200_000,
                        0.01 / 8.0,
                        5,
                    );
                    assert!(r.passed, "{:?} visible={} {} {}\n{}", kind, visible, au, av, r.report);
                }
            }
        }
        // The returned pdf equals pdf(wi, m).
        let mut rng = Sampler::new(1, 2);
        for kind in [MicrofacetType::Beckmann, MicrofacetType::Ggx] {
            for visible in [true, false] {
                let distr = MicrofacetDistribution::new(kind, 0.3, 0.15, visible);
                let wi = Vec3::new(-0.4, 0.3, 0.7).normalize();
                for _ in 0..100 {
                    let (m, pdf) = distr.sample(wi, rng.next_2d());
                    let p = distr.pdf(wi, m);
                    assert!((pdf - p).abs() <= 1e-3 * p.max(1e-3), "{} vs {}", pdf, p);
                }
            }
        }
    }
}

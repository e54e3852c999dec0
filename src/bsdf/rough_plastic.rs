//! Rough plastic (`roughplastic`): a diffuse base under a rough dielectric coating (Mitsuba's
//! `roughplastic`, after Weidlich & Wilkie 2007 "Arbitrarily Layered Micro-Facet Surfaces").
//!
//! | Parameter              | Type                | Description                                            |
//! |------------------------|---------------------|--------------------------------------------------------|
//! | `distribution`         | string              | `beckmann` (default) or `ggx`                          |
//! | `alpha`                | float               | Roughness of the coating (default 0.1; isotropic only) |
//! | `sample_visible`       | boolean             | Sample visible normals (default true)                  |
//! | `diffuse_reflectance`  | spectrum or texture | Albedo of the base (default 0.5)                       |
//! | `specular_reflectance` | spectrum or texture | Factor on the coating's reflection (default 1)         |
//! | `int_ior`              | float or string     | Interior index of refraction (default `polypropylene` = 1.49) |
//! | `ext_ior`              | float or string     | Exterior index of refraction (default `air` = 1.000277) |
//! | `nonlinear`            | boolean             | Let internal scattering shift colours (default false)  |
//!
//! f·cos θo = F(wi·h) D(h) G(wi, wo, h) / (4 cos θi) · specular
//!          + ρ' T(cos θi) T(cos θo) cos θo / (π η²),
//! where T(μ) is the coating's directional transmittance at incidence cosine μ (refracted energy
//! that is not masked, ∫ (1 − F) G1 over visible normals), and ρ' = ρ / (1 − R_int) (ρ / (1 − ρ R_int) with `nonlinear`),
//! R_int being the coating's hemispherical reflectance from inside. As in Mitsuba 3.9, T is a table of
//! 64 values over μ ∈ [0, 1] (μ = 0 replaced by 1e-6), looked up by linear interpolation, and both T
//! and R_int are integrated at construction over visible-normal samples with a Gauss–Legendre rule
//! (32×32 nodes for η > 1, 128×128 for η < 1): T(wi) = ¼ Σ w_j w_k G1(wt, m) (1 − F(wi·m)) and
//! albedo(wi) = ¼ Σ w_j w_k G1(wo, m) F(wi·m), with m drawn at the nodes mapped to [0, 1]²,
//! wt = refract(wi, m), wo = reflect(wi, m); R_int = 2 · mean_μ(albedo(μ; 1/η) μ).
//!
//! Sampling picks the glossy lobe with probability ∝ (1 − T(cos θi))·s against T(cos θi)·(1 − s)
//! (s as in `plastic`), then a visible normal (or D(h) cos θh) or a cosine-weighted direction; the
//! density is the mixture of both lobes and the weight is eval / pdf. Components: 0 = glossy
//! reflection, 1 = diffuse reflection. One-sided.
//!
//! ```xml
//! <bsdf type="roughplastic">
//!     <string name="distribution" value="ggx"/>
//!     <float name="alpha" value="0.2"/>
//!     <rgb name="diffuse_reflectance" value="0.4, 0.3, 0.2"/>
//! </bsdf>
//! ```

use super::fresnel::{fresnel, refract_m};
use super::microfacet::{read_distribution, MicrofacetDistribution, MicrofacetType};
use super::plastic::{front_lobes, read_coating_eta, specular_sampling_weight};
use super::{flags, optional_texture, times_texture, BsdfContext, BsdfSample};
use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;
use crate::math::{reflect, warp, Vec2, Vec3, INV_PI};
use crate::scene::desc::Props;
use crate::scene::resolver::FileResolver;
use crate::scene::Result;
use crate::texture::Texture;
use rayon::prelude::*;
use std::sync::Arc;

/// Resolution of the transmittance table over cos θ (Mitsuba's `MI_ROUGH_TRANSMITTANCE_RES`).
pub const TRANSMITTANCE_RES: usize = 64;

/// Rough plastic.
#[derive(Clone, Debug)]
pub struct RoughPlastic {
    pub eta: f32,
    pub inv_eta_2: f32,
    pub distribution: MicrofacetType,
    pub alpha: f32,
    pub sample_visible: bool,
    pub diffuse_reflectance: Texture,
    pub specular_reflectance: Option<Texture>,
    pub nonlinear: bool,
    pub specular_sampling_weight: f32,
    /// T(μ) at μ = i / 63 (shared between clones).
    pub external_transmittance: Arc<[f32; TRANSMITTANCE_RES]>,
    /// Hemispherical reflectance of the coating from inside, R_int.
    pub internal_reflectance: f32,
}

#[inline]
pub(super) const fn component_flags(i: u32) -> u32 {
    match i {
        0 => flags::GLOSSY_REFLECTION | flags::FRONT_SIDE,
        1 => flags::DIFFUSE_REFLECTION | flags::FRONT_SIDE,
        _ => 0,
    }
}

impl RoughPlastic {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<RoughPlastic> {
        let eta = read_coating_eta(props)?;
        if eta == 1.0 {
            return Err(props.error(
                "int_ior",
                format!("{}: the interior and exterior indices of refraction must differ", props.describe_owner()),
            ));
        }
        let diffuse_reflectance =
            Texture::from_arg(&props.texture("diffuse_reflectance", Spectrum::splat(0.5))?, resolver)?;
        let specular_reflectance = optional_texture(props, "specular_reflectance", resolver)?;
        let nonlinear = props.bool("nonlinear", false)?;
        let distribution = read_distribution(props)?;
        let sample_visible = props.bool("sample_visible", true)?;
        let alpha = read_isotropic_alpha(props)?;
        let specular_sampling_weight = specular_sampling_weight(&diffuse_reflectance, &specular_reflectance);
        let (external_transmittance, internal_reflectance) = coating_tables(distribution, alpha, eta);
        Ok(RoughPlastic {
            eta,
            inv_eta_2: 1.0 / (eta * eta),
            distribution,
            alpha,
            sample_visible,
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            specular_sampling_weight,
            external_transmittance: Arc::new(external_transmittance),
            internal_reflectance,
        })
    }

    #[inline]
    fn distr(&self) -> MicrofacetDistribution {
        MicrofacetDistribution::new(self.distribution, self.alpha, self.alpha, self.sample_visible)
    }

    /// T(μ) by linear interpolation in the table (Mitsuba's `lerp_gather`).
    #[inline]
    pub fn transmittance(&self, mu: f32) -> f32 {
        let x = mu * (TRANSMITTANCE_RES - 1) as f32;
        let index = (x as u32).min(TRANSMITTANCE_RES as u32 - 2) as usize;
        let (v0, v1) = (self.external_transmittance[index], self.external_transmittance[index + 1]);
        let t = x - index as f32;
        v0 + (v1 - v0) * t
    }

    /// Probability of the glossy lobe.
    #[inline]
    fn prob_specular(&self, t_i: f32, has_specular: bool, has_diffuse: bool) -> f32 {
        if has_specular != has_diffuse {
            return if has_specular { 1.0 } else { 0.0 };
        }
        let ps = (1.0 - t_i) * self.specular_sampling_weight;
        let pd = t_i * (1.0 - self.specular_sampling_weight);
        ps / (ps + pd)
    }

    pub fn sample(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        sample1: f32,
        sample2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        let cos_theta_i = si.wi.z;
        let (has_specular, has_diffuse) = front_lobes(ctx, flags::GLOSSY_REFLECTION, cos_theta_i)?;
        let t_i = self.transmittance(cos_theta_i);
        let prob_specular = self.prob_specular(t_i, has_specular, has_diffuse);
        let (wo, sampled_type, sampled_component) = if sample1 < prob_specular {
            let m = self.distr().sample(si.wi, sample2).0;
            (reflect(si.wi, m), flags::GLOSSY_REFLECTION, 0)
        } else {
            (warp::square_to_cosine_hemisphere(sample2), flags::DIFFUSE_REFLECTION, 1)
        };
        let (value, pdf) = self.eval_pdf(ctx, si, wo);
        if !(pdf > 0.0) {
            return None;
        }
        let bs = BsdfSample { wo, pdf, eta: 1.0, sampled_type, sampled_component };
        Some((bs, value / pdf))
    }

    /// f·cos θo and the mixture density of `wo` (Mitsuba's `eval_pdf`).
    pub fn eval_pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> (Spectrum, f32) {
        let has_specular = ctx.is_enabled(flags::GLOSSY_REFLECTION, 0);
        let has_diffuse = ctx.is_enabled(flags::DIFFUSE_REFLECTION, 1);
        let wi = si.wi;
        let (cos_theta_i, cos_theta_o) = (wi.z, wo.z);
        if !(cos_theta_i > 0.0 && cos_theta_o > 0.0) || !(has_specular || has_diffuse) {
            return (Spectrum::ZERO, 0.0);
        }
        let t_i = self.transmittance(cos_theta_i);
        let prob_specular = self.prob_specular(t_i, has_specular, has_diffuse);
        let prob_diffuse = 1.0 - prob_specular;

        let h = (wo + wi).normalize();
        let distr = self.distr();
        let d = distr.eval(h);
        let g1_wi = distr.smith_g1(wi, h);
        let specular_pdf =
            if self.sample_visible { d * g1_wi / (4.0 * cos_theta_i) } else { distr.pdf(wi, h) / (4.0 * wo.dot(h)) };
        let pdf = prob_specular * specular_pdf + prob_diffuse * warp::square_to_cosine_hemisphere_pdf(wo);

        let mut value = Spectrum::ZERO;
        if has_specular {
            let f = fresnel(wi.dot(h), self.eta).0;
            let g = distr.smith_g1(wo, h) * g1_wi;
            value = times_texture(Spectrum::splat(f * d * g / (4.0 * cos_theta_i)), &self.specular_reflectance, si);
        }
        if has_diffuse {
            let t_o = self.transmittance(cos_theta_o);
            let rho = self.diffuse_reflectance.eval(si.uv);
            let denom = if self.nonlinear {
                Spectrum::ONE - rho * self.internal_reflectance
            } else {
                Spectrum::splat(1.0 - self.internal_reflectance)
            };
            value += rho / denom * (INV_PI * self.inv_eta_2 * cos_theta_o * t_i * t_o);
        }
        (value, pdf)
    }
}

/// `alpha` as a constant (default 0.1). `alpha_u`/`alpha_v` are accepted when equal, as Mitsuba
/// does; different values are an error (Mitsuba: anisotropy is not supported by `roughplastic`).
fn read_isotropic_alpha(props: &Props) -> Result<f32> {
    let check = |name: &str, a: f32| -> Result<f32> {
        if !a.is_finite() || a < 0.0 {
            return Err(props.error(name, format!("\"{}\" must be a non-negative number (got {})", name, a)));
        }
        Ok(a)
    };
    if props.has("alpha_u") || props.has("alpha_v") {
        if !props.has("alpha_u") || !props.has("alpha_v") {
            let given = if props.has("alpha_u") { "alpha_u" } else { "alpha_v" };
            return Err(props.error(given, "microfacet model: both \"alpha_u\" and \"alpha_v\" must be specified"));
        }
        if props.has("alpha") {
            return Err(props.error("alpha", "microfacet model: specify either \"alpha\" or \"alpha_u\"/\"alpha_v\""));
        }
        let au = check("alpha_u", props.float_req("alpha_u")?)?;
        let av = check("alpha_v", props.float_req("alpha_v")?)?;
        if au != av {
            return Err(props.error(
                "alpha_u",
                "the \"roughplastic\" plugin does not support anisotropic microfacet distributions (as in Mitsuba)",
            ));
        }
        return Ok(au);
    }
    check("alpha", props.float("alpha", 0.1)?)
}

/// Mitsuba's precomputation: the external transmittance table T(μ_i), μ_i = max(1e-6, i/63), and
/// the internal reflectance R_int.
pub fn coating_tables(kind: MicrofacetType, alpha: f32, eta: f32) -> ([f32; TRANSMITTANCE_RES], f32) {
    // The tables always use visible-normal sampling (Mitsuba requires it for the quadrature).
    let distr = MicrofacetDistribution::new(kind, alpha, alpha, true);
    let (nodes_ext, weights_ext) = gauss_legendre(if eta > 1.0 { 32 } else { 128 });
    let (nodes_int, weights_int) = gauss_legendre(if 1.0 / eta > 1.0 { 32 } else { 128 });
    // One row per incidence cosine, in parallel (the internal reflectance needs 128² samples each).
    let rows: Vec<(f32, f32)> = (0..TRANSMITTANCE_RES)
        .into_par_iter()
        .map(|i| {
            let mu = (i as f32 / (TRANSMITTANCE_RES - 1) as f32).max(1e-6);
            let wi = Vec3::new((1.0 - mu * mu).sqrt(), 0.0, mu);
            let t = transmittance(&distr, wi, eta, &nodes_ext, &weights_ext);
            (t, reflectance(&distr, wi, 1.0 / eta, &nodes_int, &weights_int) * mu)
        })
        .collect();
    let mut table = [0.0f32; TRANSMITTANCE_RES];
    let mut internal = 0.0f64;
    for (t, (ti, ri)) in table.iter_mut().zip(rows) {
        *t = ti;
        internal += ri as f64;
    }
    (table, (internal / TRANSMITTANCE_RES as f64) as f32 * 2.0)
}

/// Directional transmittance of the rough dielectric interface at `wi` (Mitsuba's
/// `eval_transmittance`): ¼ Σ_jk w_j w_k G1(wt, m) (1 − F(wi·m)), wt = refract(wi, m).
fn transmittance(distr: &MicrofacetDistribution, wi: Vec3, eta: f32, nodes: &[f32], weights: &[f32]) -> f32 {
    let mut sum = 0.0f64;
    for (&ny, &wy) in nodes.iter().zip(weights) {
        for (&nx, &wx) in nodes.iter().zip(weights) {
            let node = Vec2::new(nx * 0.5 + 0.5, ny * 0.5 + 0.5);
            let m = distr.sample(wi, node).0;
            let (f, cos_theta_t, _, eta_ti) = fresnel(wi.dot(m), eta);
            let wt = refract_m(wi, m, cos_theta_t, eta_ti);
            if wt.z * wi.z >= 0.0 {
                continue;
            }
            sum += (distr.smith_g1(wt, m) * (1.0 - f) * (wx * wy) * 0.25) as f64;
        }
    }
    sum as f32
}

/// Directional albedo of the rough dielectric reflection at `wi` (Mitsuba's `eval_reflectance`):
/// ¼ Σ_jk w_j w_k G1(wo, m) F(wi·m), m = sample(wi, (x_j, x_k)/2 + ½), wo = reflect(wi, m).
fn reflectance(distr: &MicrofacetDistribution, wi: Vec3, eta: f32, nodes: &[f32], weights: &[f32]) -> f32 {
    let mut sum = 0.0f64;
    for (&ny, &wy) in nodes.iter().zip(weights) {
        for (&nx, &wx) in nodes.iter().zip(weights) {
            let node = Vec2::new(nx * 0.5 + 0.5, ny * 0.5 + 0.5);
            let m = distr.sample(wi, node).0;
            let wo = reflect(wi, m);
            if wo.z <= 0.0 || wi.z <= 0.0 {
                continue;
            }
            let f = fresnel(wi.dot(m), eta).0;
            sum += (distr.smith_g1(wo, m) * f * (wx * wy) * 0.25) as f64;
        }
    }
    sum as f32
}

/// Gauss–Legendre nodes (ascending, in [−1, 1]) and weights for `n` points, computed in double
/// precision by Newton's method on the Legendre polynomial and rounded to f32 (as Mitsuba's
/// `quad::gauss_legendre`).
pub fn gauss_legendre(n: usize) -> (Vec<f32>, Vec<f32>) {
    let mut nodes = vec![0.0f32; n];
    let mut weights = vec![0.0f32; n];
    let m = n.div_ceil(2);
    for i in 0..m {
        // Initial guess (Tricomi), then Newton.
        let mut x = -(std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 0.0;
        for _ in 0..100 {
            let (p, d) = legendre(n, x);
            dp = d;
            let step = p / d;
            x -= step;
            if step.abs() <= 4.0 * f64::EPSILON * x.abs().max(1e-300) {
                break;
            }
        }
        let (_, d) = legendre(n, x);
        if d != 0.0 {
            dp = d;
        }
        let w = 2.0 / ((1.0 - x * x) * dp * dp);
        nodes[i] = x as f32;
        weights[i] = w as f32;
        nodes[n - 1 - i] = -x as f32;
        weights[n - 1 - i] = w as f32;
    }
    (nodes, weights)
}

/// Legendre polynomial P_n(x) and its derivative (three-term recurrence).
fn legendre(n: usize, x: f64) -> (f64, f64) {
    let (mut p0, mut p1) = (1.0, x);
    for k in 2..=n {
        let pk = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
        p0 = p1;
        p1 = pk;
    }
    let d = n as f64 * (x * p1 - p0) / (x * x - 1.0);
    (p1, d)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gauss_legendre_integrates_polynomials() {
        for n in [32, 128] {
            let (x, w) = gauss_legendre(n);
            assert!(x.windows(2).all(|p| p[0] < p[1]));
            let sum_w: f64 = w.iter().map(|&v| v as f64).sum();
            assert!((sum_w - 2.0).abs() < 1e-5, "{}", sum_w);
            // ∫ x⁴ dx over [−1, 1] = 2/5.
            let q: f64 = x.iter().zip(&w).map(|(&a, &b)| (a as f64).powi(4) * b as f64).sum();
            assert!((q - 0.4).abs() < 1e-5, "{}", q);
        }
    }

    /// T(1) for a very smooth coating approaches 1 − F(0) of the smooth interface.
    #[test]
    fn smooth_limit_of_transmittance() {
        let (t, r_int) = coating_tables(MicrofacetType::Ggx, 0.001, 1.5);
        let f0 = fresnel(1.0, 1.5).0;
        assert!((t[TRANSMITTANCE_RES - 1] - (1.0 - f0)).abs() < 2e-3, "{} vs {}", t[63], 1.0 - f0);
        // The internal hemispherical reflectance of a smooth interface (η = 1/1.5) is ≈ 0.596.
        assert!((r_int - 0.596).abs() < 0.02, "{}", r_int);
    }
}

//! Rough dielectric material (`roughdielectric`): a rough interface between two dielectrics
//! (ground or etched glass), after Walter et al. 2007 "Microfacet Models for Refraction through
//! Rough Surfaces", with visible-normal sampling (Heitz & d'Eon 2014).
//!
//! | Parameter                | Type              | Description                                        |
//! |--------------------------|-------------------|----------------------------------------------------|
//! | `int_ior`                | float or string   | Interior index of refraction (default `bk7` = 1.5046) |
//! | `ext_ior`                | float or string   | Exterior index of refraction (default `air` = 1.000277) |
//! | `specular_reflectance`   | spectrum/texture  | Factor on the reflection (default 1)               |
//! | `specular_transmittance` | spectrum/texture  | Factor on the transmission (default 1)             |
//! | `distribution`           | string            | `beckmann` (default) or `ggx`                      |
//! | `alpha`                  | float             | Isotropic roughness (default 0.1)                  |
//! | `alpha_u`, `alpha_v`     | float             | Anisotropic roughness along the tangent / bitangent (both or neither, not with `alpha`) |
//! | `sample_visible`         | boolean           | Sample visible normals (default true)              |
//!
//! Mitsuba also accepts textures for the roughness; snee supports constant roughness only and
//! reports a textured `alpha` as an error. Components: 0 = glossy reflection, 1 = glossy
//! transmission. The interior and exterior indices must differ.
//!
//! With f = F D G / (4 |cos θi cos θo|) in reflection and
//! f = (1 − F) D G η² |wi·m| |wo·m| / (|cos θi cos θo| (wi·m + η wo·m)²) in transmission
//! (η in the direction of travel; × 1/η² in radiance mode), `eval` returns f·|cos θo|.
//! Sampling picks a normal m (visible normals, or D(m) cos θm with Walter's roughness scaling
//! 1.2 − 0.2 √|cos θi| when `sample_visible` is false), then reflection with probability F.
//!
//! Two Mitsuba 3.9 behaviours are reproduced on purpose, so that renders agree:
//! - with `sample_visible = false` the sample weight is G·|wi·m| / (|cos θi| cos θm), which omits
//!   the factor D(m)/D'(m) between the true and the widened distribution: the weight is then
//!   eval/pdf · D'(m)/D(m), not eval/pdf (Mitsuba 0.5 had the factor);
//! - the Beckmann masking term is Mitsuba's rational fit (< 0.35% error) while visible normals are
//!   drawn by inverting the exact distribution, so the Beckmann visible-normal pdf integrates to
//!   G1_fit(wi)/G1_exact(wi) ≈ 1 instead of exactly 1.
//!
//! ```xml
//! <bsdf type="roughdielectric">
//!     <string name="distribution" value="ggx"/>
//!     <float name="alpha" value="0.2"/>
//!     <string name="int_ior" value="bk7"/>
//!     <string name="ext_ior" value="air"/>
//! </bsdf>
//! ```

use super::fresnel::{fresnel, refract_m};
use super::microfacet::{MicrofacetDistribution, MicrofacetType};
use super::{flags, optional_texture, read_iors, times_texture, BsdfContext, BsdfSample, TransportMode};
use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;
use crate::math::{reflect, Vec2, Vec3};
use crate::scene::desc::{Props, Value};
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};
use crate::texture::Texture;

/// Rough dielectric interface.
#[derive(Clone, Debug)]
pub struct RoughDielectric {
    /// Relative index of refraction `int_ior / ext_ior`.
    pub eta: f32,
    pub inv_eta: f32,
    pub distribution: MicrofacetType,
    pub alpha_u: f32,
    pub alpha_v: f32,
    pub sample_visible: bool,
    pub specular_reflectance: Option<Texture>,
    pub specular_transmittance: Option<Texture>,
}

/// A constant roughness value; a texture (accepted by Mitsuba) is reported as unsupported.
fn roughness(props: &Props, name: &str) -> Result<Option<f32>> {
    if let Some(p) = props.items().iter().find(|p| p.name == name) {
        if let Value::Object(o) = &p.value {
            props.get(name);
            return Err(Error::at(
                &p.pos,
                format!(
                    "{}: a {} \"{}\" for \"{}\" is not supported (only a constant <float name=\"{}\" .../>)",
                    props.describe_owner(),
                    o.kind.tag(),
                    o.plugin,
                    name,
                    name
                ),
            ));
        }
    }
    let v = props.float_opt(name)?;
    if let Some(a) = v {
        if a.is_nan() || a < 0.0 || a.is_infinite() {
            return Err(props.error(name, format!("\"{}\" must be a non-negative number (got {})", name, a)));
        }
    }
    Ok(v)
}

impl RoughDielectric {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<RoughDielectric> {
        let specular_reflectance = optional_texture(props, "specular_reflectance", resolver)?;
        let specular_transmittance = optional_texture(props, "specular_transmittance", resolver)?;
        let (int_ior, ext_ior) = read_iors(props)?;
        if int_ior == ext_ior {
            return Err(props.error(
                "int_ior",
                format!(
                    "{}: the interior and exterior indices of refraction must differ (both are {})",
                    props.describe_owner(),
                    int_ior
                ),
            ));
        }
        let distribution = match props.string_opt("distribution")? {
            None => MicrofacetType::Beckmann,
            Some(s) => match s.to_ascii_lowercase().as_str() {
                "beckmann" => MicrofacetType::Beckmann,
                "ggx" => MicrofacetType::Ggx,
                _ => {
                    return Err(props.error(
                        "distribution",
                        format!("invalid distribution \"{}\", must be \"beckmann\" or \"ggx\"", s),
                    ))
                }
            },
        };
        let sample_visible = props.bool("sample_visible", true)?;
        let (alpha_u, alpha_v) = if props.has("alpha_u") || props.has("alpha_v") {
            if !props.has("alpha_u") || !props.has("alpha_v") {
                let missing = if props.has("alpha_u") { "alpha_u" } else { "alpha_v" };
                let given = if missing == "alpha_u" { "alpha_v" } else { "alpha_u" };
                return Err(props.error(given, "microfacet model: both \"alpha_u\" and \"alpha_v\" must be specified"));
            }
            if props.has("alpha") {
                return Err(
                    props.error("alpha", "microfacet model: specify either \"alpha\" or \"alpha_u\"/\"alpha_v\"")
                );
            }
            (roughness(props, "alpha_u")?.unwrap_or(0.1), roughness(props, "alpha_v")?.unwrap_or(0.1))
        } else {
            let a = roughness(props, "alpha")?.unwrap_or(0.1);
            (a, a)
        };
        Ok(RoughDielectric {
            eta: int_ior / ext_ior,
            inv_eta: ext_ior / int_ior,
            distribution,
            alpha_u,
            alpha_v,
            sample_visible,
            specular_reflectance,
            specular_transmittance,
        })
    }

    pub fn component_flags(&self, i: u32) -> u32 {
        let extra = if self.alpha_u != self.alpha_v { flags::ANISOTROPIC } else { 0 };
        match i {
            0 => flags::GLOSSY_REFLECTION | flags::FRONT_SIDE | flags::BACK_SIDE | extra,
            1 => flags::GLOSSY_TRANSMISSION | flags::FRONT_SIDE | flags::BACK_SIDE | flags::NON_SYMMETRIC | extra,
            _ => 0,
        }
    }

    /// The microfacet distribution used for evaluation.
    #[inline]
    pub fn distr(&self) -> MicrofacetDistribution {
        MicrofacetDistribution::new(self.distribution, self.alpha_u, self.alpha_v, self.sample_visible)
    }

    /// The distribution normals are sampled from: Walter's widened roughness without visible sampling.
    #[inline]
    fn sample_distr(&self, cos_theta_i: f32) -> MicrofacetDistribution {
        let mut d = self.distr();
        if !self.sample_visible {
            d.scale_alpha(1.2 - 0.2 * cos_theta_i.abs().sqrt());
        }
        d
    }

    pub fn sample(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        sample1: f32,
        sample2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        let has_reflection = ctx.is_enabled(flags::GLOSSY_REFLECTION, 0);
        let has_transmission = ctx.is_enabled(flags::GLOSSY_TRANSMISSION, 1);
        let wi = si.wi;
        let cos_theta_i = wi.z;
        // Ignore perfectly grazing configurations.
        if cos_theta_i == 0.0 || !(has_reflection || has_transmission) {
            return None;
        }
        let distr = self.distr();

        // Sample a microfacet normal from the side wi is on (m is always in the upper hemisphere).
        let (m, m_pdf) = self.sample_distr(cos_theta_i).sample(mulsign(wi, cos_theta_i), sample2);
        if m_pdf == 0.0 {
            return None;
        }
        let (f, cos_theta_t, eta_it, eta_ti) = fresnel(wi.dot(m), self.eta);

        // Lobe selection.
        let (selected_r, mut pdf, mut weight) = if has_reflection && has_transmission {
            let selected_r = sample1 <= f;
            (selected_r, m_pdf * if selected_r { f } else { 1.0 - f }, Spectrum::ONE)
        } else {
            (has_reflection, m_pdf, Spectrum::splat(if has_reflection { f } else { 1.0 - f }))
        };

        let (wo, eta, dwh_dwo);
        if selected_r {
            // Mirror reflection about m.
            wo = reflect(wi, m);
            eta = 1.0;
            weight = times_texture(weight, &self.specular_reflectance, si);
            dwh_dwo = 1.0 / (4.0 * wo.dot(m));
        } else {
            // Refraction through m; radiance is compressed by 1/η² crossing the interface.
            wo = refract_m(wi, m, cos_theta_t, eta_ti);
            eta = eta_it;
            if ctx.mode == TransportMode::Radiance {
                weight *= eta_ti * eta_ti;
            }
            weight = times_texture(weight, &self.specular_transmittance, si);
            let denom = wi.dot(m) + eta * wo.dot(m);
            dwh_dwo = eta * eta * wo.dot(m) / (denom * denom);
        }

        if self.sample_visible {
            weight *= distr.smith_g1(wo, m);
        } else {
            weight *= distr.g(wi, wo, m) * wi.dot(m) / (cos_theta_i * m.z);
        }
        pdf *= dwh_dwo.abs();

        let bs = BsdfSample {
            wo,
            pdf,
            eta,
            sampled_type: if selected_r { flags::GLOSSY_REFLECTION } else { flags::GLOSSY_TRANSMISSION },
            sampled_component: if selected_r { 0 } else { 1 },
        };
        Some((bs, weight))
    }

    /// f·|cos θo| and the sampling density of `wo` (Mitsuba's `eval_pdf`).
    pub fn eval_pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> (Spectrum, f32) {
        let wi = si.wi;
        let (cos_theta_i, cos_theta_o) = (wi.z, wo.z);
        let has_reflection = ctx.is_enabled(flags::GLOSSY_REFLECTION, 0);
        let has_transmission = ctx.is_enabled(flags::GLOSSY_TRANSMISSION, 1);
        let is_reflection = cos_theta_i * cos_theta_o > 0.0;
        // Ignore perfectly grazing configurations and disabled lobes.
        if cos_theta_i == 0.0 || !((has_reflection && is_reflection) || (has_transmission && !is_reflection)) {
            return (Spectrum::ZERO, 0.0);
        }

        // Relative index along the path, and the half-vector in the upper hemisphere.
        let (eta, inv_eta) = if cos_theta_i > 0.0 { (self.eta, self.inv_eta) } else { (self.inv_eta, self.eta) };
        let m = (wi + wo * if is_reflection { 1.0 } else { eta }).normalize();
        let m = mulsign(m, m.z);
        let (dot_wi_m, dot_wo_m) = (wi.dot(m), wo.dot(m));

        // Micro- and macro-surface must agree on the side of both directions (as smith_g1 checks).
        if !(dot_wi_m * cos_theta_i > 0.0 && dot_wo_m * cos_theta_o > 0.0) {
            return (Spectrum::ZERO, 0.0);
        }

        let mut distr = self.distr();
        let d = distr.eval(m);
        let f = fresnel(dot_wi_m, self.eta).0;
        let g = distr.g(wi, wo, m);

        let value = if is_reflection {
            let v = Spectrum::splat(f * d * g / (4.0 * cos_theta_i.abs()));
            times_texture(v, &self.specular_reflectance, si)
        } else {
            let scale = if ctx.mode == TransportMode::Radiance { inv_eta * inv_eta } else { 1.0 };
            let denom = dot_wi_m + eta * dot_wo_m;
            let v = (scale * (1.0 - f) * d * g * eta * eta * dot_wi_m * dot_wo_m / (cos_theta_i * denom * denom)).abs();
            times_texture(Spectrum::splat(v), &self.specular_transmittance, si)
        };

        if !self.sample_visible {
            distr.scale_alpha(1.2 - 0.2 * cos_theta_i.abs().sqrt());
        }
        let mut pdf = distr.pdf(mulsign(wi, cos_theta_i), m);
        if has_reflection && has_transmission {
            pdf *= if is_reflection { f } else { 1.0 - f };
        }
        // Jacobian of the half-direction mapping.
        let dwh_dwo = if is_reflection {
            1.0 / (4.0 * dot_wo_m)
        } else {
            let denom = dot_wi_m + eta * dot_wo_m;
            eta * eta * dot_wo_m / (denom * denom)
        };
        (value, pdf * dwh_dwo.abs())
    }

    /// Sampling density of `wo` alone (Mitsuba's `pdf`: no D·G evaluation of the value).
    pub fn pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> f32 {
        let wi = si.wi;
        let (cos_theta_i, cos_theta_o) = (wi.z, wo.z);
        let has_reflection = ctx.is_enabled(flags::GLOSSY_REFLECTION, 0);
        let has_transmission = ctx.is_enabled(flags::GLOSSY_TRANSMISSION, 1);
        let is_reflection = cos_theta_i * cos_theta_o > 0.0;
        if cos_theta_i == 0.0 || !((has_reflection && is_reflection) || (has_transmission && !is_reflection)) {
            return 0.0;
        }
        let eta = if cos_theta_i > 0.0 { self.eta } else { self.inv_eta };
        let m = (wi + wo * if is_reflection { 1.0 } else { eta }).normalize();
        let m = mulsign(m, m.z);
        let (dot_wi_m, dot_wo_m) = (wi.dot(m), wo.dot(m));
        if !(dot_wi_m * cos_theta_i > 0.0 && dot_wo_m * cos_theta_o > 0.0) {
            return 0.0;
        }
        let mut pdf = self.sample_distr(cos_theta_i).pdf(mulsign(wi, cos_theta_i), m);
        if has_reflection && has_transmission {
            let f = fresnel(dot_wi_m, self.eta).0;
            pdf *= if is_reflection { f } else { 1.0 - f };
        }
        let dwh_dwo = if is_reflection {
            1.0 / (4.0 * dot_wo_m)
        } else {
            let denom = dot_wi_m + eta * dot_wo_m;
            eta * eta * dot_wo_m / (denom * denom)
        };
        pdf * dwh_dwo.abs()
    }
}

/// `v` times the sign of `s` (Dr.Jit's `mulsign`: the sign bit of `s`).
#[inline]
fn mulsign(v: Vec3, s: f32) -> Vec3 {
    if s.is_sign_negative() {
        -v
    } else {
        v
    }
}

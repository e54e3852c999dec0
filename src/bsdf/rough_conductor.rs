//! Rough conductor (`roughconductor`): a rough metal after Walter et al. 2007 "Microfacet Models
//! for Refraction through Rough Surfaces", with the conductor Fresnel term and visible-normal
//! sampling (Heitz & d'Eon 2014), isotropic or anisotropic.
//!
//! | Parameter              | Type                | Description                                            |
//! |------------------------|---------------------|--------------------------------------------------------|
//! | `material`             | string              | Named preset (`Au`, `Ag`, `Al`, `Cu`, `Cr`, ...); default `none` = η 0, k 1 |
//! | `eta`, `k`             | spectrum or texture | Complex index of refraction (defaults 0 and 1); not together with `material` |
//! | `distribution`         | string              | `beckmann` (default) or `ggx`                          |
//! | `alpha`                | float or texture    | Isotropic roughness (default 0.1)                      |
//! | `alpha_u`, `alpha_v`   | float or texture    | Anisotropic roughness along the tangent / bitangent (both or neither, not with `alpha`) |
//! | `sample_visible`       | boolean             | Sample visible normals (default true)                  |
//! | `specular_reflectance` | spectrum or texture | Factor on the reflection (default 1)                   |
//!
//! f(wi, wo) = F(wi·h) D(h) G(wi, wo, h) / (4 cos θi cos θo) with h = (wi + wo)/|wi + wo|; `eval`
//! returns f·cos θo. Sampling draws h (visible normals, or D(h) cos θh — unlike `roughdielectric`,
//! without Walter's roughness widening) and reflects wi about it; the weight is G1(wo, h)·F
//! (visible normals) or F·G·(wi·h)/(cos θi cos θh). A textured roughness is read as a scalar the way
//! Mitsuba's `eval_1` does (see [`eval_1`](super::eval_1)). One-sided; one component: 0 = glossy
//! reflection (flagged anisotropic when `alpha_u`/`alpha_v` are given, as in Mitsuba).
//!
//! Anisotropy follows the shading frame's tangent (local x = `alpha_u`), which is Mitsuba's dp/du
//! (`interaction::shading_frame`): a mesh's uv parametrisation (p1 − p0 without uvs), a sphere's
//! φ direction in its own rotated frame, a disk's radial direction (`tests/plugins/shading_frame.rs`,
//! scene `surfaces_anisotropic`).
//!
//! ```xml
//! <bsdf type="roughconductor">
//!     <string name="material" value="Al"/>
//!     <string name="distribution" value="ggx"/>
//!     <float name="alpha_u" value="0.05"/>
//!     <float name="alpha_v" value="0.3"/>
//! </bsdf>
//! ```

use super::conductor::ComplexIor;
use super::microfacet::{read_distribution, MicrofacetDistribution, MicrofacetType};
use super::{eval_1, flags, optional_texture, times_texture, BsdfContext, BsdfSample};
use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;
use crate::math::{reflect, Vec2, Vec3};
use crate::scene::desc::Props;
use crate::scene::resolver::FileResolver;
use crate::scene::Result;
use crate::texture::Texture;

/// Rough conductor.
#[derive(Clone, Debug)]
pub struct RoughConductor {
    pub ior: ComplexIor,
    pub distribution: MicrofacetType,
    pub alpha_u: Texture,
    pub alpha_v: Texture,
    /// `alpha_u`/`alpha_v` were given (Mitsuba's anisotropic flag).
    pub anisotropic: bool,
    pub sample_visible: bool,
    pub specular_reflectance: Option<Texture>,
}

impl RoughConductor {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<RoughConductor> {
        let ior = ComplexIor::from_props(props, resolver)?;
        let distribution = read_distribution(props)?;
        let sample_visible = props.bool("sample_visible", true)?;
        let (alpha_u, alpha_v, anisotropic) = read_roughness(props, resolver)?;
        let specular_reflectance = optional_texture(props, "specular_reflectance", resolver)?;
        Ok(RoughConductor { ior, distribution, alpha_u, alpha_v, anisotropic, sample_visible, specular_reflectance })
    }

    pub fn component_flags(&self, i: u32) -> u32 {
        let extra = if self.anisotropic { flags::ANISOTROPIC } else { 0 };
        match i {
            0 => flags::GLOSSY_REFLECTION | flags::FRONT_SIDE | extra,
            _ => 0,
        }
    }

    /// The distribution at the hit (roughness textures evaluated there).
    #[inline]
    fn distr(&self, si: &SurfaceInteraction) -> MicrofacetDistribution {
        MicrofacetDistribution::new(
            self.distribution,
            eval_1(&self.alpha_u, si.uv),
            eval_1(&self.alpha_v, si.uv),
            self.sample_visible,
        )
    }

    pub fn sample(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        _sample1: f32,
        sample2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        let wi = si.wi;
        let cos_theta_i = wi.z;
        if cos_theta_i <= 0.0 || !ctx.is_enabled(flags::GLOSSY_REFLECTION, 0) {
            return None;
        }
        let distr = self.distr(si);
        let (m, m_pdf) = distr.sample(wi, sample2);
        let wo = reflect(wi, m);
        if m_pdf == 0.0 || wo.z <= 0.0 {
            return None;
        }
        let weight = if self.sample_visible {
            distr.smith_g1(wo, m)
        } else {
            distr.g(wi, wo, m) * wi.dot(m) / (cos_theta_i * m.z)
        };
        // Jacobian of the half-direction mapping, dh/dwo = 1 / (4 wo·h) (Walter et al. 2007, Eq. 14).
        let pdf = m_pdf / (4.0 * wo.dot(m));
        let value = self.ior.fresnel(wi.dot(m), si) * weight;
        let value = times_texture(value, &self.specular_reflectance, si);
        let bs = BsdfSample { wo, pdf, eta: 1.0, sampled_type: flags::GLOSSY_REFLECTION, sampled_component: 0 };
        Some((bs, value))
    }

    /// f·cos θo and the density of `wo` (Mitsuba's `eval_pdf`).
    pub fn eval_pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> (Spectrum, f32) {
        let wi = si.wi;
        let (cos_theta_i, cos_theta_o) = (wi.z, wo.z);
        let h = (wo + wi).normalize();
        // Micro- and macro-surface must agree on the side (as smith_g1 checks).
        let valid = cos_theta_i > 0.0 && cos_theta_o > 0.0 && wi.dot(h) > 0.0 && wo.dot(h) > 0.0;
        if !(valid && ctx.is_enabled(flags::GLOSSY_REFLECTION, 0)) {
            return (Spectrum::ZERO, 0.0);
        }
        let distr = self.distr(si);
        let d = distr.eval(h);
        if d == 0.0 {
            return (Spectrum::ZERO, 0.0);
        }
        let g1_wi = distr.smith_g1(wi, h);
        let g = g1_wi * distr.smith_g1(wo, h);
        let value = self.ior.fresnel(wi.dot(h), si) * (d * g / (4.0 * cos_theta_i));
        let value = times_texture(value, &self.specular_reflectance, si);
        let pdf =
            if self.sample_visible { d * g1_wi / (4.0 * cos_theta_i) } else { distr.pdf(wi, h) / (4.0 * wo.dot(h)) };
        (value, pdf)
    }

    /// Density of `wo` alone.
    pub fn pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> f32 {
        let wi = si.wi;
        let h = (wo + wi).normalize();
        let valid = wi.z > 0.0 && wo.z > 0.0 && wi.dot(h) > 0.0 && wo.dot(h) > 0.0;
        if !(valid && ctx.is_enabled(flags::GLOSSY_REFLECTION, 0)) {
            return 0.0;
        }
        let distr = self.distr(si);
        if self.sample_visible {
            distr.eval(h) * distr.smith_g1(wi, h) / (4.0 * wi.z)
        } else {
            distr.pdf(wi, h) / (4.0 * wo.dot(h))
        }
    }
}

/// `alpha` or `alpha_u`/`alpha_v` as textures (default 0.1), with Mitsuba's consistency rules;
/// returns (alpha_u, alpha_v, anisotropic).
fn read_roughness(props: &Props, resolver: &FileResolver) -> Result<(Texture, Texture, bool)> {
    let read = |name: &str| -> Result<Texture> {
        let t = Texture::from_arg(&props.texture(name, Spectrum::splat(0.1))?, resolver)?;
        if let Texture::Const(c) = &t {
            if c.min_element() < 0.0 {
                return Err(props.error(name, format!("\"{}\" must be non-negative", name)));
            }
        }
        Ok(t)
    };
    if props.has("alpha_u") || props.has("alpha_v") {
        if !props.has("alpha_u") || !props.has("alpha_v") {
            let given = if props.has("alpha_u") { "alpha_u" } else { "alpha_v" };
            return Err(props.error(given, "microfacet model: both \"alpha_u\" and \"alpha_v\" must be specified"));
        }
        if props.has("alpha") {
            return Err(props.error("alpha", "microfacet model: specify either \"alpha\" or \"alpha_u\"/\"alpha_v\""));
        }
        Ok((read("alpha_u")?, read("alpha_v")?, true))
    } else {
        let a = read("alpha")?;
        Ok((a.clone(), a, false))
    }
}

//! Smooth plastic (`plastic`): a diffuse base under a smooth dielectric coating, with the
//! coating's internal scattering accounted for in closed form (Mitsuba's `plastic`, after Weidlich
//! & Wilkie 2007 "Arbitrarily Layered Micro-Facet Surfaces").
//!
//! | Parameter              | Type                | Description                                            |
//! |------------------------|---------------------|--------------------------------------------------------|
//! | `diffuse_reflectance`  | spectrum or texture | Albedo of the base (default 0.5)                       |
//! | `specular_reflectance` | spectrum or texture | Factor on the coating's reflection (default 1)         |
//! | `int_ior`              | float or string     | Interior index of refraction (default `polypropylene` = 1.49) |
//! | `ext_ior`              | float or string     | Exterior index of refraction (default `air` = 1.000277) |
//! | `nonlinear`            | boolean             | Let internal scattering shift colours (default false)  |
//!
//! With η = int_ior / ext_ior, F the dielectric Fresnel reflectance and F_dr the diffuse Fresnel
//! reflectance of the inside of the coating (`fresnel_diffuse_reflectance(1/η)`):
//! - component 0, delta reflection in the mirror direction with weight F(cos θi)·specular_reflectance;
//! - component 1, diffuse: f·cos θo = ρ' (1 − F(cos θi)) (1 − F(cos θo)) cos θo / (π η²), where
//!   ρ' = ρ / (1 − F_dr) (default) or ρ / (1 − ρ F_dr) with `nonlinear` (the geometric series of
//!   internal reflections between base and coating).
//!
//! The mirror lobe is chosen with probability ∝ F(cos θi)·s against (1 − F(cos θi))·(1 − s), where
//! s = mean(specular) / (mean(diffuse) + mean(specular)) steers samples toward the brighter lobe.
//! One-sided: light from below the shading normal is absorbed.
//!
//! ```xml
//! <bsdf type="plastic">
//!     <rgb name="diffuse_reflectance" value="0.1, 0.27, 0.36"/>
//!     <float name="int_ior" value="1.9"/>
//! </bsdf>
//! ```

use super::fresnel::{fresnel, fresnel_diffuse_reflectance, reflect_local};
use super::{flags, optional_texture, times_texture, BsdfContext, BsdfSample};
use crate::color::{luminance, Spectrum};
use crate::interaction::SurfaceInteraction;
use crate::math::{warp, Vec2, Vec3, INV_PI};
use crate::scene::desc::Props;
use crate::scene::resolver::FileResolver;
use crate::scene::Result;
use crate::texture::Texture;

/// Smooth plastic.
#[derive(Clone, Debug)]
pub struct Plastic {
    /// Relative index of refraction int_ior / ext_ior.
    pub eta: f32,
    pub inv_eta_2: f32,
    pub diffuse_reflectance: Texture,
    pub specular_reflectance: Option<Texture>,
    pub nonlinear: bool,
    /// Diffuse Fresnel reflectance of the coating seen from inside.
    pub fdr_int: f32,
    /// Prior probability weight of the specular lobe.
    pub specular_sampling_weight: f32,
}

#[inline]
pub(super) const fn component_flags(i: u32) -> u32 {
    match i {
        0 => flags::DELTA_REFLECTION | flags::FRONT_SIDE,
        1 => flags::DIFFUSE_REFLECTION | flags::FRONT_SIDE,
        _ => 0,
    }
}

/// `int_ior`/`ext_ior` of a coating (default polypropylene over air), non-negative.
pub(super) fn read_coating_eta(props: &Props) -> Result<f32> {
    let int_ior = props.ior("int_ior", "polypropylene")?;
    let ext_ior = props.ior("ext_ior", "air")?;
    for (name, v) in [("int_ior", int_ior), ("ext_ior", ext_ior)] {
        if !v.is_finite() || v < 0.0 {
            return Err(props.error(
                name,
                format!("{}: the interior and exterior indices of refraction must be positive", props.describe_owner()),
            ));
        }
    }
    Ok(int_ior / ext_ior)
}

/// Mitsuba's specular sampling weight: mean(specular) / (mean(diffuse) + mean(specular)), with
/// a texture's mean read as the luminance of its mean colour (Mitsuba's `Texture::mean`).
/// The lobes `ctx` enables (specular: component 0 with `specular_flag`, diffuse: component 1) for
/// light arriving from `cos_theta_i`; `None` where Mitsuba's plastics give nothing: from below the
/// surface, or with neither lobe enabled.
pub(super) fn front_lobes(ctx: &BsdfContext, specular_flag: u32, cos_theta_i: f32) -> Option<(bool, bool)> {
    let has_specular = ctx.is_enabled(specular_flag, 0);
    let has_diffuse = ctx.is_enabled(flags::DIFFUSE_REFLECTION, 1);
    (!(cos_theta_i <= 0.0) && (has_specular || has_diffuse)).then_some((has_specular, has_diffuse))
}

pub(super) fn specular_sampling_weight(diffuse: &Texture, specular: &Option<Texture>) -> f32 {
    let d_mean = texture_mean(diffuse);
    let s_mean = specular.as_ref().map_or(1.0, texture_mean);
    s_mean / (d_mean + s_mean)
}

/// Mitsuba's scalar `mean()` of a texture: a constant's channel mean, else the mean luminance.
fn texture_mean(t: &Texture) -> f32 {
    match t {
        Texture::Const(c) if c.x == c.y && c.y == c.z => c.x,
        Texture::Const(c) => (c.x + c.y + c.z) / 3.0,
        t => luminance(t.mean()),
    }
}

impl Plastic {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<Plastic> {
        let eta = read_coating_eta(props)?;
        let diffuse_reflectance =
            Texture::from_arg(&props.texture("diffuse_reflectance", Spectrum::splat(0.5))?, resolver)?;
        let specular_reflectance = optional_texture(props, "specular_reflectance", resolver)?;
        let nonlinear = props.bool("nonlinear", false)?;
        let specular_sampling_weight = specular_sampling_weight(&diffuse_reflectance, &specular_reflectance);
        Ok(Plastic {
            eta,
            inv_eta_2: 1.0 / (eta * eta),
            diffuse_reflectance,
            specular_reflectance,
            nonlinear,
            fdr_int: fresnel_diffuse_reflectance(1.0 / eta),
            specular_sampling_weight,
        })
    }

    /// Probability of choosing the mirror lobe given F(cos θi) and the enabled lobes.
    #[inline]
    fn prob_specular(&self, f_i: f32, has_specular: bool, has_diffuse: bool) -> f32 {
        if has_specular != has_diffuse {
            return if has_specular { 1.0 } else { 0.0 };
        }
        let ps = f_i * self.specular_sampling_weight;
        let pd = (1.0 - f_i) * (1.0 - self.specular_sampling_weight);
        ps / (ps + pd)
    }

    /// The diffuse lobe's albedo after internal scattering, ρ'.
    #[inline]
    fn diffuse_albedo(&self, si: &SurfaceInteraction) -> Spectrum {
        let rho = self.diffuse_reflectance.eval(si.uv);
        if self.nonlinear {
            rho / (Spectrum::ONE - rho * self.fdr_int)
        } else {
            rho / (1.0 - self.fdr_int)
        }
    }

    pub fn sample(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        sample1: f32,
        sample2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        let cos_theta_i = si.wi.z;
        let (has_specular, has_diffuse) = front_lobes(ctx, flags::DELTA_REFLECTION, cos_theta_i)?;
        let f_i = fresnel(cos_theta_i, self.eta).0;
        let prob_specular = self.prob_specular(f_i, has_specular, has_diffuse);
        if sample1 < prob_specular {
            let bs = BsdfSample {
                wo: reflect_local(si.wi),
                pdf: prob_specular,
                eta: 1.0,
                sampled_type: flags::DELTA_REFLECTION,
                sampled_component: 0,
            };
            let value = times_texture(Spectrum::splat(f_i / prob_specular), &self.specular_reflectance, si);
            Some((bs, value))
        } else {
            let prob_diffuse = 1.0 - prob_specular;
            let wo = warp::square_to_cosine_hemisphere(sample2);
            let bs = BsdfSample {
                wo,
                pdf: prob_diffuse * warp::square_to_cosine_hemisphere_pdf(wo),
                eta: 1.0,
                sampled_type: flags::DIFFUSE_REFLECTION,
                sampled_component: 1,
            };
            let f_o = fresnel(wo.z, self.eta).0;
            let value = self.diffuse_albedo(si) * (self.inv_eta_2 * (1.0 - f_i) * (1.0 - f_o) / prob_diffuse);
            Some((bs, value))
        }
    }

    pub fn eval_pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> (Spectrum, f32) {
        let (cos_theta_i, cos_theta_o) = (si.wi.z, wo.z);
        if !(cos_theta_i > 0.0 && cos_theta_o > 0.0 && ctx.is_enabled(flags::DIFFUSE_REFLECTION, 1)) {
            return (Spectrum::ZERO, 0.0);
        }
        let f_i = fresnel(cos_theta_i, self.eta).0;
        let f_o = fresnel(cos_theta_o, self.eta).0;
        let hemi_pdf = INV_PI * cos_theta_o;
        let value = self.diffuse_albedo(si) * (hemi_pdf * self.inv_eta_2 * (1.0 - f_i) * (1.0 - f_o));
        let has_specular = ctx.is_enabled(flags::DELTA_REFLECTION, 0);
        let prob_diffuse = 1.0 - self.prob_specular(f_i, has_specular, true);
        (value, hemi_pdf * prob_diffuse)
    }
}

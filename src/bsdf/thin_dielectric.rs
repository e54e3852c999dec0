//! Thin dielectric material (`thindielectric`): a very thin sheet of glass (a window pane),
//! modelled as two parallel interfaces with all the internal reflections summed up.
//!
//! | Parameter                | Type              | Description                                        |
//! |--------------------------|-------------------|----------------------------------------------------|
//! | `int_ior`                | float or string   | Interior index of refraction (default `bk7` = 1.5046) |
//! | `ext_ior`                | float or string   | Exterior index of refraction (default `air` = 1.000277) |
//! | `specular_reflectance`   | spectrum/texture  | Factor on the reflection (default 1)               |
//! | `specular_transmittance` | spectrum/texture  | Factor on the transmission (default 1)             |
//!
//! With R the single-interface Fresnel reflectance at |cos θi|, the sheet reflects
//! R' = R + T²R/(1 − R²) = 2R/(1 + R) (paths R, TRT, TR³T, ...) and transmits 1 − R'.
//! Transmission does not bend the ray: it is a `NULL` component (wo = −wi), so shadow rays
//! pass through with [`ThinDielectric::eval_null_transmission`]. Components: 0 = delta
//! reflection, 1 = null transmission.
//!
//! ```xml
//! <bsdf type="thindielectric">
//!     <string name="int_ior" value="bk7"/>
//! </bsdf>
//! ```

use super::dielectric::Dielectric;
use super::fresnel::{fresnel, reflect_local};
use super::{flags, times_texture, BsdfContext, BsdfSample};
use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;
use crate::math::Vec2;
use crate::scene::desc::Props;
use crate::scene::resolver::FileResolver;
use crate::scene::Result;
use crate::texture::Texture;

/// Thin dielectric sheet.
#[derive(Clone, Debug)]
pub struct ThinDielectric {
    /// Relative index of refraction `int_ior / ext_ior`.
    pub eta: f32,
    pub specular_reflectance: Option<Texture>,
    pub specular_transmittance: Option<Texture>,
}

#[inline]
pub(super) const fn component_flags(i: u32) -> u32 {
    match i {
        0 => flags::DELTA_REFLECTION | flags::FRONT_SIDE | flags::BACK_SIDE,
        1 => flags::NULL | flags::FRONT_SIDE | flags::BACK_SIDE,
        _ => 0,
    }
}

impl ThinDielectric {
    /// The parameters are `dielectric`'s.
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<ThinDielectric> {
        let Dielectric { eta, specular_reflectance, specular_transmittance } = Dielectric::from_props(props, resolver)?;
        Ok(ThinDielectric { eta, specular_reflectance, specular_transmittance })
    }

    /// Reflectance of the sheet R' = R + T²R/(1 − R²) = 2R/(1 + R), including internal reflections.
    #[inline]
    pub fn reflectance(&self, si: &SurfaceInteraction) -> f32 {
        let r = fresnel(si.wi.z.abs(), self.eta).0;
        r * 2.0 / (1.0 + r)
    }

    pub fn sample(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        sample1: f32,
        _sample2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        let has_reflection = ctx.is_enabled(flags::DELTA_REFLECTION, 0);
        let has_transmission = ctx.is_enabled(flags::NULL, 1);
        let r = self.reflectance(si);
        let t = 1.0 - r;
        let (selected_r, pdf, weight) = if has_reflection && has_transmission {
            let selected_r = sample1 <= r;
            (selected_r, if selected_r { r } else { t }, 1.0)
        } else if has_reflection || has_transmission {
            (has_reflection, 1.0, if has_reflection { r } else { t })
        } else {
            return None;
        };
        let bs = BsdfSample {
            wo: if selected_r { reflect_local(si.wi) } else { -si.wi },
            pdf,
            eta: 1.0,
            sampled_type: if selected_r { flags::DELTA_REFLECTION } else { flags::NULL },
            sampled_component: if selected_r { 0 } else { 1 },
        };
        let tex = if selected_r { &self.specular_reflectance } else { &self.specular_transmittance };
        Some((bs, times_texture(Spectrum::splat(weight), tex, si)))
    }

    /// Straight-through transmission 1 − R' (times `specular_transmittance`).
    pub fn eval_null_transmission(&self, si: &SurfaceInteraction) -> Spectrum {
        times_texture(Spectrum::splat(1.0 - self.reflectance(si)), &self.specular_transmittance, si)
    }
}

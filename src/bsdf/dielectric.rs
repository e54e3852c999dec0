//! Smooth dielectric material (`dielectric`): an ideally smooth interface between two
//! dielectrics, e.g. glass and air, with specular reflection and refraction weighted by the
//! Fresnel equations.
//!
//! | Parameter                | Type              | Description                                        |
//! |--------------------------|-------------------|----------------------------------------------------|
//! | `int_ior`                | float or string   | Interior index of refraction (default `bk7` = 1.5046) |
//! | `ext_ior`                | float or string   | Exterior index of refraction (default `air` = 1.000277) |
//! | `specular_reflectance`   | spectrum/texture  | Factor on the reflection (default 1; leave it)     |
//! | `specular_transmittance` | spectrum/texture  | Factor on the transmission (default 1; leave it)   |
//!
//! The exterior is the side the normal points to. Components: 0 = delta reflection,
//! 1 = delta transmission. With both enabled, reflection is chosen with probability F and the
//! weight is 1 (times the optional factors); with one enabled it is chosen with probability 1 and
//! the weight is F or 1 − F. In radiance mode the transmitted weight is scaled by 1/η² (η in the
//! direction of travel), in importance mode it is not.
//!
//! ```xml
//! <bsdf type="dielectric">
//!     <string name="int_ior" value="water"/>
//!     <string name="ext_ior" value="air"/>
//! </bsdf>
//! ```

use super::fresnel::{fresnel, reflect_local, refract};
use super::{flags, optional_texture, read_iors, times_texture, BsdfContext, BsdfSample, TransportMode};
use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;
use crate::math::Vec2;
use crate::scene::desc::Props;
use crate::scene::resolver::FileResolver;
use crate::scene::Result;
use crate::texture::Texture;

/// Smooth dielectric interface.
#[derive(Clone, Debug)]
pub struct Dielectric {
    /// Relative index of refraction `int_ior / ext_ior`.
    pub eta: f32,
    pub specular_reflectance: Option<Texture>,
    pub specular_transmittance: Option<Texture>,
}

#[inline]
pub(super) const fn component_flags(i: u32) -> u32 {
    match i {
        0 => flags::DELTA_REFLECTION | flags::FRONT_SIDE | flags::BACK_SIDE,
        1 => flags::DELTA_TRANSMISSION | flags::FRONT_SIDE | flags::BACK_SIDE | flags::NON_SYMMETRIC,
        _ => 0,
    }
}

impl Dielectric {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<Dielectric> {
        let (int_ior, ext_ior) = read_iors(props)?;
        Ok(Dielectric {
            eta: int_ior / ext_ior,
            specular_reflectance: optional_texture(props, "specular_reflectance", resolver)?,
            specular_transmittance: optional_texture(props, "specular_transmittance", resolver)?,
        })
    }

    /// Fresnel reflectance for the incident direction `si.wi`.
    #[inline]
    pub fn reflectance(&self, si: &SurfaceInteraction) -> f32 {
        fresnel(si.wi.z, self.eta).0
    }

    pub fn sample(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        sample1: f32,
        _sample2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        let has_reflection = ctx.is_enabled(flags::DELTA_REFLECTION, 0);
        let has_transmission = ctx.is_enabled(flags::DELTA_TRANSMISSION, 1);
        let cos_theta_i = si.wi.z;
        let (r_i, cos_theta_t, eta_it, eta_ti) = fresnel(cos_theta_i, self.eta);
        let t_i = 1.0 - r_i;

        // Lobe selection.
        let (selected_r, pdf, mut weight) = if has_reflection && has_transmission {
            let selected_r = sample1 <= r_i;
            (selected_r, if selected_r { r_i } else { t_i }, 1.0)
        } else if has_reflection || has_transmission {
            (has_reflection, 1.0, if has_reflection { r_i } else { t_i })
        } else {
            return None;
        };

        let bs = if selected_r {
            BsdfSample {
                wo: reflect_local(si.wi),
                pdf,
                eta: 1.0,
                sampled_type: flags::DELTA_REFLECTION,
                sampled_component: 0,
            }
        } else {
            // Solid-angle compression of radiance crossing the interface.
            if ctx.mode == TransportMode::Radiance {
                weight *= eta_ti * eta_ti;
            }
            BsdfSample {
                wo: refract(si.wi, cos_theta_t, eta_ti),
                pdf,
                eta: eta_it,
                sampled_type: flags::DELTA_TRANSMISSION,
                sampled_component: 1,
            }
        };
        let tex = if selected_r { &self.specular_reflectance } else { &self.specular_transmittance };
        Some((bs, times_texture(Spectrum::splat(weight), tex, si)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::testing::si_with_wi;

    #[test]
    fn directions_and_weights() {
        let d = Dielectric { eta: 1.5, specular_reflectance: None, specular_transmittance: None };
        let wi = Vec3::new(0.3, -0.4, 0.866_025_4).normalize();
        let si = si_with_wi(wi);
        let (r, ..) = fresnel(wi.z, 1.5);
        // Reflection: mirror direction, pdf F, weight 1.
        let (bs, w) = d.sample(&BsdfContext::default(), &si, 0.5 * r, Vec2::ZERO).unwrap();
        assert_eq!(bs.sampled_type, flags::DELTA_REFLECTION);
        assert!((bs.wo - Vec3::new(-wi.x, -wi.y, wi.z)).length() < 1e-6);
        assert!((bs.pdf - r).abs() < 1e-7 && w == Spectrum::ONE && bs.eta == 1.0);
        // Transmission in radiance mode: weight 1/η², Snell's law, eta = 1.5.
        let (bs, w) = d.sample(&BsdfContext::default(), &si, 0.99, Vec2::ZERO).unwrap();
        assert_eq!(bs.sampled_component, 1);
        assert!((bs.pdf - (1.0 - r)).abs() < 1e-6);
        assert!((w.x - 1.0 / 2.25).abs() < 1e-6 && bs.eta == 1.5);
        let sin_i = (1.0 - wi.z * wi.z).sqrt();
        let sin_t = (1.0 - bs.wo.z * bs.wo.z).sqrt();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-6 && bs.wo.z < 0.0);
        assert!((bs.wo.x / bs.wo.y - wi.x / wi.y).abs() < 1e-5 && bs.wo.x * wi.x < 0.0);
        // Importance mode: no 1/η².
        let ctx = BsdfContext::new(TransportMode::Importance);
        let (_, w) = d.sample(&ctx, &si, 0.99, Vec2::ZERO).unwrap();
        assert!((w.x - 1.0).abs() < 1e-7);
        // One component only: probability 1, Fresnel factor in the weight.
        let ctx = BsdfContext { component: 1, ..Default::default() };
        let (bs, w) = d.sample(&ctx, &si, 0.0, Vec2::ZERO).unwrap();
        assert!(bs.pdf == 1.0 && (w.x - (1.0 - r) / 2.25).abs() < 1e-6);
        let ctx = BsdfContext { type_mask: flags::DELTA_REFLECTION, ..Default::default() };
        let (bs, w) = d.sample(&ctx, &si, 0.99, Vec2::ZERO).unwrap();
        assert!(bs.pdf == 1.0 && (w.x - r).abs() < 1e-7 && bs.sampled_component == 0);
        // From inside: eta_it = 1/1.5, radiance weight η² = 2.25.
        let si_in = si_with_wi(Vec3::new(0.1, 0.2, -0.9).normalize());
        let (bs, w) = d.sample(&BsdfContext::default(), &si_in, 0.999, Vec2::ZERO).unwrap();
        assert!((bs.eta - 1.0 / 1.5).abs() < 1e-7 && (w.x - 2.25).abs() < 1e-5 && bs.wo.z > 0.0);
    }
}

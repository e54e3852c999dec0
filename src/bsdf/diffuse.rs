//! Smooth diffuse material (`diffuse`): an ideal Lambertian reflector.
//!
//! | Parameter     | Type                | Description                              |
//! |---------------|---------------------|------------------------------------------|
//! | `reflectance` | spectrum or texture | Albedo (default 0.5)                     |
//!
//! One-sided like every non-transmissive Mitsuba model: light arriving from below the shading
//! normal (cos θi ≤ 0) is absorbed; wrap it in `twosided` for a two-sided surface.
//! Sampling is cosine-weighted, so the sample weight is the reflectance.
//!
//! ```xml
//! <bsdf type="diffuse">
//!     <rgb name="reflectance" value="0.2, 0.25, 0.7"/>
//! </bsdf>
//! ```

use super::{flags, BsdfContext, BsdfSample};
use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;
use crate::math::{warp, Vec2, Vec3, INV_PI};
use crate::scene::desc::Props;
use crate::scene::resolver::FileResolver;
use crate::scene::Result;
use crate::texture::Texture;

/// Lambertian reflection.
#[derive(Clone, Debug)]
pub struct Diffuse {
    pub reflectance: Texture,
}

#[inline]
pub(super) const fn component_flags(i: u32) -> u32 {
    if i == 0 {
        flags::DIFFUSE_REFLECTION | flags::FRONT_SIDE
    } else {
        0
    }
}

impl Diffuse {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<Diffuse> {
        let reflectance = Texture::from_arg(&props.texture("reflectance", Spectrum::splat(0.5))?, resolver)?;
        Ok(Diffuse { reflectance })
    }

    /// Always inlined, so that `path`'s AVX2 loop (`path::li_avx2`) compiles the cosine warp and
    /// the reflectance lookup with its own target features instead of calling a baseline copy.
    #[inline(always)]
    pub fn sample(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        _sample1: f32,
        sample2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        if si.wi.z <= 0.0 || !ctx.is_enabled(flags::DIFFUSE_REFLECTION, 0) {
            return None;
        }
        let wo = warp::square_to_cosine_hemisphere(sample2);
        let pdf = warp::square_to_cosine_hemisphere_pdf(wo);
        if pdf <= 0.0 {
            return None;
        }
        let bs = BsdfSample { wo, pdf, eta: 1.0, sampled_type: flags::DIFFUSE_REFLECTION, sampled_component: 0 };
        Some((bs, self.reflectance.eval(si.uv)))
    }

    #[inline]
    pub fn eval(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> Spectrum {
        if !ctx.is_enabled(flags::DIFFUSE_REFLECTION, 0) || si.wi.z <= 0.0 || wo.z <= 0.0 {
            return Spectrum::ZERO;
        }
        self.reflectance.eval(si.uv) * (INV_PI * wo.z)
    }

    #[inline]
    pub fn pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> f32 {
        if !ctx.is_enabled(flags::DIFFUSE_REFLECTION, 0) || si.wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        warp::square_to_cosine_hemisphere_pdf(wo)
    }
}

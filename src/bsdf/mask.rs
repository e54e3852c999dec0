//! Opacity mask (`mask`): blends a nested BSDF with a null (pass-through) interface, for cut-out
//! geometry such as leaves (Mitsuba's `mask`).
//!
//! | Parameter | Type             | Description                                                        |
//! |-----------|------------------|--------------------------------------------------------------------|
//! | `opacity` | float or texture | Probability of interacting with the nested BSDF (default 0.5), clamped to [0, 1] |
//! | (nested)  | bsdf             | The material where the surface is opaque (exactly one)             |
//!
//! With opacity α (a texture is read as one number, as Mitsuba's `eval_1` does): `eval` is α times
//! the nested `eval`; `sample` passes straight through (wo = −wi, a null sample of probability
//! 1 − α and weight 1) when sample1 ≥ α, otherwise it samples the nested BSDF with sample1 / α and
//! returns its sample with α times its density and its weight unchanged (α cancels in the weight);
//! `pdf` is α times the nested density; the null transmission along a ray is 1 − α (1 − nested null transmission).
//! Components: the nested ones, then the null component (index = nested count).
//! As in Mitsuba 3.9, a context restricted to the null component sets α = 1 and one restricted to the
//! nested components sets α = 0 before sampling.
//!
//! ```xml
//! <bsdf type="mask">
//!     <texture type="bitmap" name="opacity">
//!         <string name="filename" value="leaf_mask.png"/>
//!     </texture>
//!     <bsdf type="diffuse"/>
//! </bsdf>
//! ```

use super::{eval_1, flags, Bsdf, BsdfContext, BsdfSample};
use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;
use crate::math::{Vec2, Vec3};
use crate::scene::desc::{PluginKind, Props};
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};
use crate::texture::Texture;

/// Opacity mask around a nested model.
#[derive(Clone, Debug)]
pub struct Mask {
    pub opacity: Texture,
    pub nested: Box<Bsdf>,
}

impl Mask {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<Mask> {
        let opacity = Texture::from_arg(&props.texture("opacity", Spectrum::splat(0.5))?, resolver)?;
        let nested = props.objects_of(PluginKind::Bsdf);
        if nested.len() > 1 {
            return Err(Error::at(&nested[1].1.pos, "mask: cannot specify more than one child BSDF"));
        }
        let Some((_, first)) = nested.first() else {
            return Err(Error::at(&props.owner_pos, "mask: a nested BSDF is required"));
        };
        Ok(Mask { opacity, nested: Box::new(Bsdf::from_desc(first, resolver)?) })
    }

    /// Index of the null component.
    #[inline]
    fn null_index(&self) -> u32 {
        self.nested.component_count()
    }

    pub fn component_count(&self) -> u32 {
        self.null_index() + 1
    }

    pub fn component_flags(&self, i: u32) -> u32 {
        let n = self.null_index();
        if i < n {
            self.nested.component_flags(i)
        } else if i == n {
            flags::NULL | flags::FRONT_SIDE | flags::BACK_SIDE
        } else {
            0
        }
    }

    /// α at the hit, clamped to [0, 1].
    #[inline]
    fn opacity(&self, si: &SurfaceInteraction) -> f32 {
        eval_1(&self.opacity, si.uv).clamp(0.0, 1.0)
    }

    /// (null component enabled, nested components enabled).
    #[inline]
    fn enabled(&self, ctx: &BsdfContext) -> (bool, bool) {
        let null_index = self.null_index();
        (ctx.is_enabled(flags::NULL, null_index), ctx.component == u32::MAX || ctx.component < null_index)
    }

    pub fn sample(
        &self,
        ctx: &BsdfContext,
        si: &SurfaceInteraction,
        sample1: f32,
        sample2: Vec2,
    ) -> Option<(BsdfSample, Spectrum)> {
        let (sample_transmission, sample_nested) = self.enabled(ctx);
        if !sample_transmission && !sample_nested {
            return None;
        }
        let mut opacity = self.opacity(si);
        if sample_transmission != sample_nested {
            opacity = if sample_transmission { 1.0 } else { 0.0 };
        }
        if sample1 < opacity {
            let (mut bs, weight) = self.nested.sample(ctx, si, sample1 / opacity, sample2)?;
            bs.pdf *= opacity;
            return Some((bs, weight));
        }
        let bs = BsdfSample {
            wo: -si.wi,
            pdf: 1.0 - opacity,
            eta: 1.0,
            sampled_type: flags::NULL,
            sampled_component: self.null_index(),
        };
        Some((bs, Spectrum::ONE))
    }

    pub fn eval_pdf(&self, ctx: &BsdfContext, si: &SurfaceInteraction, wo: Vec3) -> (Spectrum, f32) {
        let (sample_transmission, sample_nested) = self.enabled(ctx);
        let (value, mut pdf) = self.nested.eval_pdf(ctx, si, wo);
        let opacity = self.opacity(si);
        if !sample_nested {
            pdf = 0.0;
        }
        if sample_transmission {
            pdf *= opacity;
        }
        (value * opacity, pdf)
    }

    pub fn eval_null_transmission(&self, si: &SurfaceInteraction) -> Spectrum {
        let opacity = self.opacity(si);
        Spectrum::ONE - opacity * (Spectrum::ONE - self.nested.eval_null_transmission(si))
    }
}

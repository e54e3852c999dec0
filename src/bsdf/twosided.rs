//! Two-sided adapter (`twosided`): makes a one-sided model (e.g. `diffuse`) scatter on both
//! sides, or puts two models on the front and back.
//!
//! | Parameter            | Type    | Description                                                   |
//! |----------------------|---------|---------------------------------------------------------------|
//! | (nested)             | bsdf    | One model for both sides, or two: front, then back            |
//! | `allow_transmission` | boolean | Allow nested models with transmission (default false)         |
//!
//! A hit on the back (cos θi < 0 in the shading frame) is mirrored to the front (wi.z and wo.z
//! flipped), evaluated by the nested model, and the sampled direction is mirrored back.
//! Components are the front model's, then the back model's.
//!
//! Deviation from Mitsuba 3.9 (only in corner cases): Mitsuba uses slightly different code
//! when one model was given (`wi.z = +0` counts as front; `ctx.component` is passed unchanged
//! to the back side) and when two were given (`wi.z = 0` scatters nothing; the back side sees
//! `ctx.component − front.component_count()`). snee stores both sides in either case and
//! follows the one-model behaviour (the usual case); the two differ only for an exactly grazing
//! `wi` or a component-restricted context on the back side of two distinct models.
//!
//! ```xml
//! <bsdf type="twosided">
//!     <bsdf type="diffuse">
//!         <rgb name="reflectance" value="0.4"/>
//!     </bsdf>
//! </bsdf>
//! ```

use super::{flags, Bsdf, BsdfContext, BsdfSample};
use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;
use crate::math::{Vec2, Vec3};
use crate::scene::desc::{PluginKind, Props};
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};

pub(super) fn from_props(props: &Props, resolver: &FileResolver) -> Result<Bsdf> {
    let nested = props.objects_of(PluginKind::Bsdf);
    if nested.len() > 2 {
        return Err(Error::at(&nested[2].1.pos, "twosided: at most two nested BSDFs can be specified"));
    }
    let allow_transmission = props.bool("allow_transmission", false)?;
    let Some((_, first)) = nested.first() else {
        return Err(Error::at(&props.owner_pos, "twosided: a nested one-sided material is required"));
    };
    let front = Bsdf::from_desc(first, resolver)?;
    let back = match nested.get(1) {
        Some((_, o)) => Bsdf::from_desc(o, resolver)?,
        None => front.clone(),
    };
    let bsdf = Bsdf::TwoSided(Box::new(front), Box::new(back));
    if !allow_transmission && bsdf.flags() & flags::TRANSMISSION != 0 {
        let pos = nested
            .iter()
            .find(|(_, o)| matches!(o.plugin.as_str(), "dielectric" | "roughdielectric" | "thindielectric" | "null"));
        return Err(Error::at(
            pos.map(|(_, o)| &o.pos).unwrap_or(&props.owner_pos),
            "twosided: only materials without a transmission component can be nested (set allow_transmission to override)",
        ));
    }
    Ok(bsdf)
}

/// Front components lose BACK_SIDE and gain FRONT_SIDE; back components the opposite.
pub(super) fn component_flags(front: &Bsdf, back: &Bsdf, i: u32) -> u32 {
    let n0 = front.component_count();
    if i < n0 {
        (front.component_flags(i) & !flags::BACK_SIDE) | flags::FRONT_SIDE
    } else if i - n0 < back.component_count() {
        (back.component_flags(i - n0) & !flags::FRONT_SIDE) | flags::BACK_SIDE
    } else {
        0
    }
}

/// The side `wi` arrives on (sign bit of cos θi, as Dr.Jit's `mulsign`), and `wi` mirrored to the front.
#[inline]
fn to_front(si: &SurfaceInteraction) -> (bool, SurfaceInteraction) {
    let back_side = si.wi.z.is_sign_negative();
    let mut s = *si;
    s.wi.z = s.wi.z.abs();
    (back_side, s)
}

#[inline]
fn flip_z(v: Vec3, flip: bool) -> Vec3 {
    if flip {
        Vec3::new(v.x, v.y, -v.z)
    } else {
        v
    }
}

pub(super) fn sample(
    front: &Bsdf,
    back: &Bsdf,
    ctx: &BsdfContext,
    si: &SurfaceInteraction,
    sample1: f32,
    sample2: Vec2,
) -> Option<(BsdfSample, Spectrum)> {
    let (back_side, si_front) = to_front(si);
    let nested = if back_side { back } else { front };
    let (mut bs, weight) = nested.sample(ctx, &si_front, sample1, sample2)?;
    bs.wo = flip_z(bs.wo, back_side);
    Some((bs, weight))
}

pub(super) fn eval_pdf(
    front: &Bsdf,
    back: &Bsdf,
    ctx: &BsdfContext,
    si: &SurfaceInteraction,
    wo: Vec3,
) -> (Spectrum, f32) {
    let (back_side, si_front) = to_front(si);
    let nested = if back_side { back } else { front };
    nested.eval_pdf(ctx, &si_front, flip_z(wo, back_side))
}

#[cfg(test)]
mod tests {
    use super::super::Diffuse;
    use super::*;
    use crate::testing::si_with_wi;
    use crate::texture::Texture;

    fn diffuse(c: Spectrum) -> Bsdf {
        Bsdf::Diffuse(Diffuse { reflectance: Texture::Const(c) })
    }

    #[test]
    fn front_and_back_models() {
        let (red, blue) = (Spectrum::new(0.8, 0.1, 0.1), Spectrum::new(0.1, 0.1, 0.8));
        let b = Bsdf::TwoSided(Box::new(diffuse(red)), Box::new(diffuse(blue)));
        let ctx = BsdfContext::default();
        // Front: the first model, sampled into the upper hemisphere.
        let si = si_with_wi(Vec3::new(0.3, 0.1, 0.9).normalize());
        let (bs, w) = b.sample(&ctx, &si, 0.5, Vec2::new(0.2, 0.7)).unwrap();
        assert!(bs.wo.z > 0.0 && w == red);
        // Back: the second model, mirrored into the lower hemisphere, same pdf as the mirrored front.
        let si_back = si_with_wi(Vec3::new(0.3, 0.1, -0.9).normalize());
        let (bs_back, w) = b.sample(&ctx, &si_back, 0.5, Vec2::new(0.2, 0.7)).unwrap();
        assert!(w == blue && bs_back.wo == Vec3::new(bs.wo.x, bs.wo.y, -bs.wo.z));
        let (e, p) = b.eval_pdf(&ctx, &si_back, bs_back.wo);
        assert!((e - blue * bs.wo.z / crate::math::PI).abs().max_element() < 1e-6);
        assert!((p - bs.pdf).abs() < 1e-6);
        // Light leaving through the other side is not scattered.
        assert_eq!(b.eval(&ctx, &si_back, bs.wo), Spectrum::ZERO);
        assert_eq!(b.pdf(&ctx, &si, bs_back.wo), 0.0);
        // Components: front diffuse (front side), back diffuse (back side).
        assert_eq!(b.component_count(), 2);
        assert_eq!(b.component_flags(0), flags::DIFFUSE_REFLECTION | flags::FRONT_SIDE);
        assert_eq!(b.component_flags(1), flags::DIFFUSE_REFLECTION | flags::BACK_SIDE);
        assert_eq!(b.flags(), flags::DIFFUSE_REFLECTION | flags::FRONT_SIDE | flags::BACK_SIDE);
    }
}

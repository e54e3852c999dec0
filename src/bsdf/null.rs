//! Null material (`null`): an invisible surface; rays continue undeflected.
//!
//! No parameters. Its only component is a forward-facing delta lobe flagged `NULL`: `sample`
//! returns `wo = -wi` with pdf 1 and weight 1, `eval`/`pdf` are 0, and
//! `eval_null_transmission` is 1. Used to bound participating media without a refractive
//! boundary.
//!
//! ```xml
//! <shape type="sphere">
//!     <bsdf type="null"/>
//!     <medium type="homogeneous" name="interior"/>
//! </shape>
//! ```

use super::{flags, BsdfContext, BsdfSample};
use crate::color::Spectrum;
use crate::interaction::SurfaceInteraction;

#[inline]
pub(super) const fn component_flags(i: u32) -> u32 {
    if i == 0 {
        flags::NULL | flags::FRONT_SIDE | flags::BACK_SIDE
    } else {
        0
    }
}

/// Straight through, weight 1 (Mitsuba's `Null::sample`).
pub(super) fn sample(ctx: &BsdfContext, si: &SurfaceInteraction) -> Option<(BsdfSample, Spectrum)> {
    if !ctx.is_enabled(flags::NULL, 0) {
        return None;
    }
    let bs = BsdfSample { wo: -si.wi, pdf: 1.0, eta: 1.0, sampled_type: flags::NULL, sampled_component: 0 };
    Some((bs, Spectrum::ONE))
}

//! Mitsuba's `area` emitter: a shape that emits `radiance` from its front side (the side its
//! normal points to; one-sided, as Mitsuba's). It is nested in the `<shape>` it is bound to; the
//! scene keeps it as `SceneEmitter::Area { shape, radiance }`.
//!
//! | Parameter  | Type              | Default | Description                       |
//! |------------|-------------------|---------|-----------------------------------|
//! | `radiance` | spectrum/texture  | 1       | emitted radiance (untinted white) |
//!
//! Sampling is the shape's (`Shape::sample_direction`: by area, or by the subtended cone for a
//! sphere seen from outside), restricted to the front side.
//!
//! ```xml
//! <shape type="rectangle">
//!     <emitter type="area"><rgb name="radiance" value="10, 10, 10"/></emitter>
//! </shape>
//! ```

use crate::color::Spectrum;
use crate::interaction::{DirectionSample, SurfaceInteraction};
use crate::math::{Vec2, Vec3};
use crate::scene::desc::ObjectDesc;
use crate::scene::resolver::FileResolver;
use crate::scene::Result;
use crate::shape::Shape;
use crate::texture::Texture;

/// The `radiance` of an `<emitter type="area">`.
pub fn from_desc(obj: &ObjectDesc, resolver: &FileResolver) -> Result<Texture> {
    let props = &obj.props;
    // Mitsuba's default radiance is a uniform 1 (untinted).
    let radiance = Texture::from_arg(&props.texture("radiance", Vec3::ONE)?, resolver)?;
    props.finish()?;
    Ok(radiance)
}

/// Sample a direction from `ref_p` towards `shape`: (ds, radiance / pdf), zero towards its back.
#[inline(always)]
pub fn sample_direction(radiance: &Texture, shape: &Shape, ref_p: Vec3, sample: Vec2) -> (DirectionSample, Spectrum) {
    let ds = shape.sample_direction(ref_p, sample);
    // Emission only from the front side (Mitsuba's area emitter is one-sided).
    if ds.pdf > 0.0 && ds.d.dot(ds.n) < 0.0 {
        let w = radiance.eval(ds.uv) / ds.pdf;
        (ds, w)
    } else {
        (DirectionSample { pdf: 0.0, ..ds }, Spectrum::ZERO)
    }
}

/// Solid-angle density of [`sample_direction`] producing `ds` from `ref_p` (0 towards the back).
#[inline]
pub fn pdf_direction(shape: &Shape, ref_p: Vec3, ds: &DirectionSample) -> f32 {
    if ds.d.dot(ds.n) >= 0.0 {
        return 0.0;
    }
    shape.pdf_direction(ref_p, ds)
}

/// Radiance leaving the hit point `si` towards the previous vertex (`si.wi`): front side only.
#[inline]
pub fn eval(radiance: &Texture, si: &SurfaceInteraction) -> Spectrum {
    if si.wi.z > 0.0 {
        radiance.eval(si.uv)
    } else {
        Spectrum::ZERO
    }
}

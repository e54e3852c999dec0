//! Constant environment emitter (`constant`): the same radiance arrives from every direction.
//!
//! | parameter  | type     | meaning |
//! |------------|----------|---------|
//! | `radiance` | spectrum | emitted radiance (default 1); must not vary spatially |
//!
//! Directions are sampled uniformly on the sphere (as Mitsuba does), pdf 1/(4π).
//!
//! ```xml
//! <emitter type="constant">
//!     <rgb name="radiance" value="0.8, 0.9, 1.0"/>
//! </emitter>
//! ```

use super::BoundingSphere;
use crate::color::Spectrum;
use crate::interaction::DirectionSample;
use crate::math::warp::{square_to_uniform_sphere, square_to_uniform_sphere_pdf};
use crate::math::{Vec2, Vec3};
use crate::scene::desc::Props;
use crate::scene::Result;

#[derive(Clone, Debug)]
pub struct ConstantEmitter {
    pub radiance: Spectrum,
    pub bsphere: BoundingSphere,
}

impl ConstantEmitter {
    pub fn from_props(props: &Props) -> Result<ConstantEmitter> {
        if let Some(crate::scene::desc::TexArg::Texture(t)) = props.texture_opt("radiance")? {
            return Err(crate::scene::Error::at(
                &t.pos,
                "constant: expected a radiance that does not vary spatially (rgb, spectrum or float)",
            ));
        }
        let radiance = props.color("radiance", Spectrum::ONE)?;
        Ok(ConstantEmitter { radiance, bsphere: BoundingSphere::default() })
    }

    /// A uniformly distributed direction; weight = radiance · 4π.
    #[inline]
    pub fn sample_direction(&self, ref_p: Vec3, sample: Vec2) -> (DirectionSample, Spectrum) {
        let d = square_to_uniform_sphere(sample);
        let pdf = square_to_uniform_sphere_pdf();
        let ds = DirectionSample {
            p: ref_p + d * self.bsphere.far_distance(ref_p),
            n: -d,
            uv: Vec2::ZERO,
            d,
            dist: f32::INFINITY,
            pdf,
            delta: false,
            emitter: 0,
        };
        (ds, self.radiance / pdf)
    }
}

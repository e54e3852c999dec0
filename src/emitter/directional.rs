//! Distant directional emitter (`directional`): parallel light of a given irradiance arriving from
//! one direction, like the sun seen from the earth.
//!
//! | parameter    | type     | meaning |
//! |--------------|----------|---------|
//! | `irradiance` | spectrum | power per unit area received by a surface facing the light (default 1) |
//! | `direction`  | vector   | the direction in which the light *travels* (world space) |
//! | `to_world`   | transform| alternative to `direction`: the light travels along local +Z (default) |
//!
//! Only one of `direction` and `to_world` may be given. The light is a delta in direction: it is
//! sampled, never hit, and its weight from any point is the irradiance.
//!
//! ```xml
//! <emitter type="directional">
//!     <vector name="direction" x="0" y="-1" z="-1"/>
//!     <rgb name="irradiance" value="3.0"/>
//! </emitter>
//! ```

use super::{shortcut_or_to_world, BoundingSphere};
use crate::color::Spectrum;
use crate::interaction::DirectionSample;
use crate::math::{Vec2, Vec3};
use crate::scene::desc::Props;
use crate::scene::Result;

#[derive(Clone, Debug)]
pub struct DirectionalEmitter {
    pub irradiance: Spectrum,
    /// Unit direction in which the light travels (world space).
    pub d: Vec3,
    pub bsphere: BoundingSphere,
}

impl DirectionalEmitter {
    pub fn from_props(props: &Props) -> Result<DirectionalEmitter> {
        let d = shortcut_or_to_world(props, "direction", Props::vector_opt, |m| m.transform_vector3(Vec3::Z))?;
        let name = if props.has("direction") { "direction" } else { "to_world" };
        if !(d.is_finite() && d.length_squared() > 0.0) {
            return Err(props.error(name, "the light direction must be a finite non-zero vector"));
        }
        let irradiance = props.color("irradiance", Spectrum::ONE)?;
        Ok(DirectionalEmitter { irradiance, d: d.normalize(), bsphere: BoundingSphere::default() })
    }

    /// The one direction towards the light; weight = irradiance (pdf 1, delta).
    #[inline]
    pub fn sample_direction(&self, ref_p: Vec3) -> (DirectionSample, Spectrum) {
        let dist = self.bsphere.far_distance(ref_p);
        let ds = DirectionSample {
            p: ref_p - self.d * dist,
            n: self.d,
            uv: Vec2::ZERO,
            d: -self.d,
            dist: f32::INFINITY,
            pdf: 1.0,
            delta: true,
            emitter: 0,
        };
        (ds, self.irradiance)
    }
}

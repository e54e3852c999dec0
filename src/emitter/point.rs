//! Point light (`point`): radiates the same intensity into every direction from one point.
//!
//! | parameter   | type      | meaning |
//! |-------------|-----------|---------|
//! | `intensity` | spectrum  | radiant intensity, power per unit solid angle (default 1) |
//! | `position`  | point     | where the light is |
//! | `to_world`  | transform | alternative to `position`: the light sits at the local origin |
//!
//! Only one of `position` and `to_world` may be given. Seen from a point at distance r, the
//! weight of the (delta) sample is intensity / r².
//!
//! ```xml
//! <emitter type="point">
//!     <point name="position" x="0" y="2" z="0"/>
//!     <rgb name="intensity" value="10"/>
//! </emitter>
//! ```

use super::shortcut_or_to_world;
use crate::color::Spectrum;
use crate::interaction::DirectionSample;
use crate::math::{Vec2, Vec3};
use crate::scene::desc::Props;
use crate::scene::Result;

#[derive(Clone, Debug)]
pub struct PointEmitter {
    pub intensity: Spectrum,
    /// Position in world space.
    pub p: Vec3,
}

impl PointEmitter {
    pub fn from_props(props: &Props) -> Result<PointEmitter> {
        let p = shortcut_or_to_world(props, "position", Props::point_opt, |m| m.transform_point3(Vec3::ZERO))?;
        if !p.is_finite() {
            return Err(props.error("position", "the light position is not finite"));
        }
        let intensity = props.color("intensity", Spectrum::ONE)?;
        Ok(PointEmitter { intensity, p })
    }

    /// The direction towards the light; weight = intensity / r² (pdf 1, delta).
    #[inline]
    pub fn sample_direction(&self, ref_p: Vec3) -> (DirectionSample, Spectrum) {
        let to = self.p - ref_p;
        let dist = to.length();
        if dist <= 0.0 {
            return (DirectionSample { delta: true, ..Default::default() }, Spectrum::ZERO);
        }
        let inv_dist = 1.0 / dist;
        let ds = DirectionSample {
            p: self.p,
            n: Vec3::ZERO,
            uv: Vec2::splat(0.5),
            d: to * inv_dist,
            dist,
            pdf: 1.0,
            delta: true,
            emitter: 0,
        };
        (ds, self.intensity * (inv_dist * inv_dist))
    }
}

//! Mitsuba's `irradiancemeter`: a sensor nested in a shape that measures the average irradiance
//! over the shape's surface (on the side its normal faces). Use a 1×1 film with a box filter.
//!
//! ```xml
//! <shape type="rectangle">
//!     <bsdf type="null"/>
//!     <sensor type="irradiancemeter">
//!         <film type="hdrfilm"><integer name="width" value="1"/><integer name="height" value="1"/>
//!             <rfilter type="box"/></film>
//!     </sensor>
//! </shape>
//! ```
//! A ray starts at a point sampled uniformly by area (from the film position sample) and leaves in
//! a cosine-weighted direction about the normal (from the aperture sample); its weight is π, so the
//! mean is E = ∫ L cos θ dω.

use crate::interaction::offset_origin;
use crate::math::{warp, Frame, Ray, Vec2, PI};
use crate::shape::Shape;

#[derive(Clone, Debug)]
pub struct IrradianceMeter {
    /// The shape the meter is attached to (its own copy, in world space).
    pub shape: Shape,
}

impl IrradianceMeter {
    /// `pos` is a film position; only its fractional part is used (a 1×1 film gives [0, 1)²).
    pub fn sample_ray(&self, pos: Vec2, aperture_sample: Vec2) -> Ray {
        let u = pos - pos.floor();
        let ps = self.shape.sample_position(u);
        let local = warp::square_to_cosine_hemisphere(aperture_sample);
        let d = Frame::from_normal(ps.n).to_world(local);
        Ray::new(offset_origin(ps.p, ps.n, d), d)
    }

    /// Importance weight of every ray (π: cosine-weighted directions).
    pub const WEIGHT: f32 = PI;
}

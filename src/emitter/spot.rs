//! Spot light (`spot`): a point light that shines into a cone around its local +Z axis.
//!
//! | parameter      | type      | meaning |
//! |----------------|-----------|---------|
//! | `intensity`    | spectrum  | radiant intensity at the centre of the beam (default 1); not a texture |
//! | `cutoff_angle` | float     | angle (degrees) beyond which the light is black (default 20) |
//! | `beam_width`   | float     | angle (degrees) of the fully lit core (default 3/4 of `cutoff_angle`) |
//! | `texture`      | texture   | optional spatially varying texture projected along the beam |
//! | `to_world`     | transform | placement: the light sits at the local origin and points along +Z |
//!
//! Between `beam_width` and `cutoff_angle` the intensity falls off linearly in the angle θ:
//! `(cutoff − θ) / (cutoff − beam_width)` (Mitsuba's falloff curve). A projected texture is looked
//! up at uv = ½ + ½·(x, y) / (z · tan(cutoff)) of the local direction.
//!
//! ```xml
//! <emitter type="spot">
//!     <transform name="to_world">
//!         <lookat origin="1, 1, 1" target="1, 2, 1"/>
//!     </transform>
//!     <float name="cutoff_angle" value="30"/>
//!     <rgb name="intensity" value="50"/>
//! </emitter>
//! ```

use super::check_transform;
use crate::color::Spectrum;
use crate::interaction::DirectionSample;
use crate::math::{Mat4, Vec2, Vec3};
use crate::scene::desc::{Props, TexArg};
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};
use crate::texture::Texture;

#[derive(Clone, Debug)]
pub struct SpotEmitter {
    pub intensity: Spectrum,
    /// Projected texture (spatially varying), if any.
    pub texture: Option<Texture>,
    /// Light position in world space.
    pub p: Vec3,
    pub to_world: Mat4,
    pub to_local: Mat4,
    /// Angles in radians.
    pub cutoff_angle: f32,
    pub beam_width: f32,
    cos_cutoff_angle: f32,
    cos_beam_width: f32,
    inv_transition_width: f32,
    uv_factor: f32,
}

impl SpotEmitter {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<SpotEmitter> {
        let to_world = props.transform("to_world")?;
        let to_local = check_transform(props, "to_world", &to_world)?;
        if let Some(TexArg::Texture(t)) = props.texture_opt("intensity")? {
            return Err(Error::at(&t.pos, "spot: \"intensity\" cannot be a spatially varying texture"));
        }
        let intensity = props.color("intensity", Spectrum::ONE)?;
        let texture = match props.texture_opt("texture")? {
            None => None,
            Some(TexArg::Const(_)) => {
                return Err(props.error("texture", "spot: \"texture\" must be spatially varying (e.g. a bitmap)"))
            }
            Some(arg) => Some(Texture::from_arg(&arg, resolver)?),
        };
        let cutoff_deg = props.float("cutoff_angle", 20.0)?;
        let beam_deg = props.float("beam_width", cutoff_deg * 3.0 / 4.0)?;
        if !(cutoff_deg.is_finite() && cutoff_deg > 0.0 && cutoff_deg <= 180.0) {
            return Err(props.error("cutoff_angle", "spot: \"cutoff_angle\" must lie in (0, 180] degrees"));
        }
        if !(beam_deg.is_finite() && beam_deg >= 0.0) {
            return Err(props.error("beam_width", "spot: \"beam_width\" must be a non-negative angle"));
        }
        let (cutoff_angle, beam_width) = (cutoff_deg.to_radians(), beam_deg.to_radians());
        Ok(SpotEmitter {
            intensity,
            texture,
            p: to_world.transform_point3(Vec3::ZERO),
            to_world,
            to_local,
            cutoff_angle,
            beam_width,
            cos_cutoff_angle: cutoff_angle.cos(),
            cos_beam_width: beam_width.cos(),
            inv_transition_width: 1.0 / (cutoff_angle - beam_width),
            uv_factor: cutoff_angle.tan(),
        })
    }

    /// Fraction in [0, 1] of the central intensity emitted along the local direction `d`.
    #[inline]
    pub fn falloff(&self, d: Vec3) -> f32 {
        let cos_theta = d.normalize_or_zero().z;
        if cos_theta <= self.cos_cutoff_angle {
            0.0
        } else if cos_theta >= self.cos_beam_width {
            1.0
        } else {
            (self.cutoff_angle - cos_theta.acos()) * self.inv_transition_width
        }
    }

    /// Texture coordinates of the local direction `d` for the projected texture.
    #[inline]
    pub fn direction_to_uv(&self, d: Vec3) -> Vec2 {
        Vec2::new(0.5 + 0.5 * d.x / (d.z * self.uv_factor), 0.5 + 0.5 * d.y / (d.z * self.uv_factor))
    }

    /// Radiant intensity emitted along the world direction `d` (pointing away from the light).
    #[inline]
    pub fn intensity_towards(&self, d: Vec3) -> Spectrum {
        let local = self.to_local.transform_vector3(d);
        let falloff = self.falloff(local);
        if falloff <= 0.0 {
            return Spectrum::ZERO;
        }
        let mut i = self.intensity * falloff;
        if let Some(t) = &self.texture {
            i *= t.eval(self.direction_to_uv(local));
        }
        i
    }

    /// The direction towards the light; weight = intensity · falloff / r² (pdf 1, delta).
    #[inline]
    pub fn sample_direction(&self, ref_p: Vec3) -> (DirectionSample, Spectrum) {
        let to = self.p - ref_p;
        let dist = to.length();
        if dist <= 0.0 {
            return (DirectionSample { delta: true, ..Default::default() }, Spectrum::ZERO);
        }
        let inv_dist = 1.0 / dist;
        let d = to * inv_dist;
        let ds =
            DirectionSample { p: self.p, n: Vec3::ZERO, uv: Vec2::ZERO, d, dist, pdf: 1.0, delta: true, emitter: 0 };
        (ds, self.intensity_towards(-d) * (inv_dist * inv_dist))
    }
}

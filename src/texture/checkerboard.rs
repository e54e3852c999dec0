//! Checkerboard texture (`checkerboard`): two colours alternating on a 2 × 2 grid per unit square
//! of uv.
//!
//! | parameter          | type                  | meaning |
//! |--------------------|-----------------------|---------|
//! | `color0`, `color1` | spectrum or texture   | the two patch colours (default 0.4 and 0.2) |
//! | `to_uv`            | transform             | uv transform (3×3; of a 4×4 matrix the third row and column are ignored) |
//!
//! With (u', v') = to_uv·(u, v), the fractional parts decide: `color0` where both are > ½ or both
//! are ≤ ½, else `color1` (Mitsuba's rule). Nested textures are evaluated at the original uv.
//!
//! ```xml
//! <bsdf type="diffuse">
//!     <texture type="checkerboard" name="reflectance">
//!         <rgb name="color0" value="0.8"/>
//!         <rgb name="color1" value="0.1"/>
//!         <transform name="to_uv">
//!             <scale x="8" y="8"/>
//!         </transform>
//!     </texture>
//! </bsdf>
//! ```

use super::{uv_transform, Texture};
use crate::color::Spectrum;
use crate::math::{fast, Vec2};
use crate::scene::desc::Props;
use crate::scene::resolver::FileResolver;
use crate::scene::Result;
use glam::Affine2;

#[derive(Clone, Debug)]
pub struct Checkerboard {
    pub color0: Texture,
    pub color1: Texture,
    pub to_uv: Affine2,
}

impl Checkerboard {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<Checkerboard> {
        let color0 = Texture::from_arg(&props.texture("color0", Spectrum::splat(0.4))?, resolver)?;
        let color1 = Texture::from_arg(&props.texture("color1", Spectrum::splat(0.2))?, resolver)?;
        let to_uv = uv_transform(&props.transform("to_uv")?);
        Ok(Checkerboard { color0, color1, to_uv })
    }

    #[inline]
    pub fn eval(&self, uv: Vec2) -> Spectrum {
        let t = self.to_uv.transform_point2(uv);
        // `t − floor(t)` without a libm call (`fast::fract`, the same value).
        let mask_x = fast::fract(t.x) > 0.5;
        let mask_y = fast::fract(t.y) > 0.5;
        if mask_x == mask_y {
            self.color0.eval(uv)
        } else {
            self.color1.eval(uv)
        }
    }

    pub fn mean(&self) -> Spectrum {
        0.5 * (self.color0.mean() + self.color1.mean())
    }
}

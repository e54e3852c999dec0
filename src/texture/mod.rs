//! Textures: a spectrum as a function of surface `uv` (`checkerboard`, `bitmap`, or a constant).
//!
//! Nested textures follow Mitsuba: a checkerboard's colours may themselves be textures, evaluated
//! at the surface's own uv. [`Texture::mean`] gives the average value, which Mitsuba reports as a
//! scalar (the mean luminance); here it is the mean colour, whose luminance is Mitsuba's value.

pub mod bitmap;
pub mod checkerboard;

pub use bitmap::BitmapTexture;
pub use checkerboard::Checkerboard;

use crate::color::Spectrum;
use crate::math::{Mat4, Vec2};
use crate::scene::desc::{ObjectDesc, TexArg};
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};
use glam::{Affine2, Mat2};
use std::sync::Arc;

/// A texture, evaluated at surface uv. Small (16 bytes): the variants with data are behind pointers.
#[derive(Clone, Debug)]
pub enum Texture {
    Const(Spectrum),
    Checkerboard(Box<Checkerboard>),
    /// Shared: cloning a texture does not copy its pixels.
    Bitmap(Arc<BitmapTexture>),
}

/// The texture plugins [`Texture::from_arg`] accepts.
pub const SUPPORTED: &[&str] = &["bitmap", "checkerboard"];

impl Texture {
    /// Build from a property value (constant colour or nested `<texture>`).
    pub fn from_arg(arg: &TexArg, resolver: &FileResolver) -> Result<Texture> {
        match arg {
            TexArg::Const(c) => Ok(Texture::Const(*c)),
            TexArg::Texture(o) => Texture::from_desc(o, resolver),
        }
    }

    /// Build from a `<texture>` object; unknown or unused parameters are errors.
    pub fn from_desc(obj: &ObjectDesc, resolver: &FileResolver) -> Result<Texture> {
        let t = match obj.plugin.as_str() {
            "checkerboard" => Texture::Checkerboard(Box::new(Checkerboard::from_props(&obj.props, resolver)?)),
            "bitmap" => Texture::Bitmap(Arc::new(BitmapTexture::from_props(&obj.props, resolver)?)),
            other => {
                return Err(Error::at(
                    &obj.pos,
                    format!("unsupported texture type \"{}\" (expected one of: {})", other, SUPPORTED.join(", ")),
                ))
            }
        };
        obj.props.finish()?;
        Ok(t)
    }

    /// The value at `uv`. Constants (most reflectances and radiances) are read in place; the
    /// spatially varying textures are evaluated out of line, so that this stays small enough to
    /// inline at every BSDF and emitter evaluation.
    #[inline(always)]
    pub fn eval(&self, uv: Vec2) -> Spectrum {
        match self {
            Texture::Const(c) => *c,
            _ => self.eval_varying(uv),
        }
    }

    #[inline(never)]
    fn eval_varying(&self, uv: Vec2) -> Spectrum {
        match self {
            Texture::Const(c) => *c,
            Texture::Checkerboard(t) => t.eval(uv),
            Texture::Bitmap(t) => t.eval(uv),
        }
    }

    /// Mean value (Mitsuba's `Texture::mean`, as a colour), used for sampling weights.
    pub fn mean(&self) -> Spectrum {
        match self {
            Texture::Const(c) => *c,
            Texture::Checkerboard(t) => t.mean(),
            Texture::Bitmap(t) => t.mean(),
        }
    }

    /// False for constants (Mitsuba's `is_spatially_varying`).
    pub fn is_spatially_varying(&self) -> bool {
        !matches!(self, Texture::Const(_))
    }
}

/// Mitsuba's 3×3 uv transform from a `to_uv` 4×4 matrix: the upper-left 2×2 block and the
/// first two entries of the last column (the third row and column are ignored).
pub fn uv_transform(m: &Mat4) -> Affine2 {
    Affine2::from_mat2_translation(
        Mat2::from_cols(Vec2::new(m.x_axis.x, m.x_axis.y), Vec2::new(m.y_axis.x, m.y_axis.y)),
        Vec2::new(m.w_axis.x, m.w_axis.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_is_small() {
        assert!(std::mem::size_of::<Texture>() <= 16);
    }
}

//! Textures: a spectrum as a function of surface `uv` (`checkerboard`, `bitmap`, or a constant).

use crate::color::Spectrum;
use crate::math::Vec2;
use crate::scene::desc::TexArg;
use crate::scene::resolver::FileResolver;
use crate::scene::Result;

/// A texture, evaluated at surface uv.
#[derive(Clone, Debug)]
pub enum Texture {
    Const(Spectrum),
}

impl Texture {
    /// Build from a property value (constant colour or nested `<texture>`).
    pub fn from_arg(arg: &TexArg, _resolver: &FileResolver) -> Result<Texture> {
        match arg {
            TexArg::Const(c) => Ok(Texture::Const(*c)),
            TexArg::Texture(o) => Err(crate::scene::Error::at(
                &o.pos,
                format!("texture \"{}\" is not supported yet", o.plugin),
            )),
        }
    }

    #[inline]
    pub fn eval(&self, _uv: Vec2) -> Spectrum {
        match self {
            Texture::Const(c) => *c,
        }
    }

    /// Mean value (Mitsuba's `Texture::mean`), used for sampling weights.
    pub fn mean(&self) -> Spectrum {
        match self {
            Texture::Const(c) => *c,
        }
    }
}

//! Bitmap texture (`bitmap`): an image looked up at uv. Formats (those Mitsuba's `bitmap` reads,
//! decoded by [`read_image`]): OpenEXR, PNG, JPEG, BMP, TGA, Radiance RGBE (`.hdr`) and PFM.
//!
//! | parameter     | type      | meaning |
//! |---------------|-----------|---------|
//! | `filename`    | string    | the image, resolved against the scene's folders |
//! | `filter_type` | string    | `bilinear` (default) or `nearest` |
//! | `wrap_mode`   | string    | outside [0, 1]: `repeat` (default), `mirror` or `clamp` |
//! | `raw`         | boolean   | keep 8/16-bit data (PNG, JPEG, BMP, TGA) as stored instead of converting sRGB to linear (default false); float formats (EXR, RGBE, PFM) are always linear |
//! | `to_uv`       | transform | uv transform (3×3; of a 4×4 matrix the third row and column are ignored) |
//! | `format`, `accel` | string, boolean | Mitsuba's storage options; accepted and ignored (data is kept in f32) |
//!
//! Conventions (Mitsuba's, through Dr.Jit's textures): v is not flipped, so v = 0 is the top row
//! of the image; pixel centres sit at ((x + ½)/W, (y + ½)/H). Bilinear lookups interpolate
//! between the four nearest centres, each wrapped by the wrap mode; nearest lookups take the pixel
//! under `floor(uv · (W, H))`. RGB(A) images give colour (alpha is dropped), Y(A) images grey.
//!
//! ```xml
//! <bsdf type="diffuse">
//!     <texture type="bitmap" name="reflectance">
//!         <string name="filename" value="textures/wood.png"/>
//!         <string name="wrap_mode" value="mirror"/>
//!     </texture>
//! </bsdf>
//! ```

use super::uv_transform;
use crate::color::Spectrum;
use crate::io::read::read_image;
use crate::math::Vec2;
use crate::scene::desc::Props;
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result, SrcPos};
use glam::Affine2;

/// How pixel values are interpolated.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FilterType {
    Bilinear,
    Nearest,
}

/// How lookups outside [0, 1] are folded back into the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WrapMode {
    Repeat,
    Mirror,
    Clamp,
}

impl WrapMode {
    /// Fold an integer pixel coordinate into [0, n) (Dr.Jit's `tex_wrap`).
    #[inline]
    pub fn wrap(self, i: i64, n: usize) -> usize {
        let n = n as i64;
        let r = match self {
            WrapMode::Clamp => i.clamp(0, n - 1),
            WrapMode::Repeat => i.rem_euclid(n),
            WrapMode::Mirror => {
                let m = i.rem_euclid(2 * n);
                if m >= n {
                    2 * n - 1 - m
                } else {
                    m
                }
            }
        };
        r as usize
    }
}

/// The string property `filename` that `plugin` (`bitmap`, `envmap`) requires.
pub(crate) fn required_filename(props: &Props, plugin: &str) -> Result<String> {
    props
        .string_opt("filename")?
        .ok_or_else(|| props.error("filename", format!("{plugin} requires the string property \"filename\"")))
}

/// An image file named by a `filename` property, read as linear RGB.
pub(crate) struct FilenameImage {
    /// The resolved path as text, for error messages.
    pub file: String,
    /// Where the scene gives `filename`.
    pub pos: SrcPos,
    pub width: usize,
    pub height: usize,
    /// Row by row, row 0 at the top.
    pub pixels: Vec<Spectrum>,
}

/// Resolve `filename` (the value of the `filename` property) against the scene's folders, refuse
/// it beyond the size limits, and read it (sRGB → linear for 8/16-bit data when `to_linear`), with
/// errors at the property's position. Shared by the `bitmap` texture and the `envmap` emitter.
pub(crate) fn read_filename_image(
    props: &Props,
    filename: &str,
    resolver: &FileResolver,
    to_linear: bool,
) -> Result<FilenameImage> {
    let pos = props.pos_of("filename");
    let path = resolver.resolve_at(filename, &pos)?;
    crate::scene::limits::check_image(&path, "filename", &pos)?;
    let bitmap = read_image(&path, to_linear).map_err(|e| Error::at(&pos, e.to_string()))?;
    let file = path.display().to_string();
    let pixels = bitmap.to_rgb_pixels(&file).map_err(|e| Error::at(&pos, e.to_string()))?;
    Ok(FilenameImage { file, pos, width: bitmap.width, height: bitmap.height, pixels })
}

#[derive(Clone)]
pub struct BitmapTexture {
    pub filename: String,
    pub width: usize,
    pub height: usize,
    /// Linear colours, row 0 at the top (v = 0).
    data: Vec<Spectrum>,
    pub filter: FilterType,
    pub wrap: WrapMode,
    pub to_uv: Affine2,
    mean: Spectrum,
}

impl std::fmt::Debug for BitmapTexture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("BitmapTexture")
            .field("filename", &self.filename)
            .field("width", &self.width)
            .field("height", &self.height)
            .field("filter", &self.filter)
            .field("wrap", &self.wrap)
            .field("to_uv", &self.to_uv)
            .field("mean", &self.mean)
            .finish_non_exhaustive()
    }
}

impl BitmapTexture {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<BitmapTexture> {
        let filename = required_filename(props, "bitmap")?;
        let filter = match props.string("filter_type", "bilinear")?.as_str() {
            "bilinear" => FilterType::Bilinear,
            "nearest" => FilterType::Nearest,
            other => {
                return Err(props.error(
                    "filter_type",
                    format!("invalid filter type \"{other}\" (expected \"bilinear\" or \"nearest\")"),
                ))
            }
        };
        let wrap = match props.string("wrap_mode", "repeat")?.as_str() {
            "repeat" => WrapMode::Repeat,
            "mirror" => WrapMode::Mirror,
            "clamp" => WrapMode::Clamp,
            other => {
                return Err(props.error(
                    "wrap_mode",
                    format!("invalid wrap mode \"{other}\" (expected \"repeat\", \"mirror\" or \"clamp\")"),
                ))
            }
        };
        let raw = props.bool("raw", false)?;
        let to_uv = uv_transform(&props.transform("to_uv")?);
        let format = props.string("format", "auto")?;
        if !matches!(format.as_str(), "auto" | "variant" | "fp16") {
            return Err(props
                .error("format", format!("invalid format \"{format}\" (expected \"auto\", \"variant\" or \"fp16\")")));
        }
        props.bool("accel", true)?;

        let image = read_filename_image(props, &filename, resolver, !raw)?;
        Self::new(filename, &image.file, image.width, image.height, image.pixels, filter, wrap, to_uv)
            .map_err(|e| Error::at(&image.pos, e.msg))
    }

    /// Build from `width × height` linear colours (row 0 = top); `file` names the source in errors.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        filename: String,
        file: &str,
        width: usize,
        height: usize,
        pixels: Vec<Spectrum>,
        filter: FilterType,
        wrap: WrapMode,
        to_uv: Affine2,
    ) -> Result<BitmapTexture> {
        if width == 0 || height == 0 || pixels.len() != width * height {
            return Err(Error::msg(format!("{file}: expected {width}x{height} pixels, got {}", pixels.len())));
        }
        let mut sum = glam::DVec3::ZERO;
        for (i, p) in pixels.iter().enumerate() {
            if !p.is_finite() || p.min_element() < 0.0 {
                return Err(Error::msg(format!(
                    "{file}: pixel ({}, {}) has the value ({}, {}, {}); textures must be finite and non-negative",
                    i % width,
                    i / width,
                    p.x,
                    p.y,
                    p.z
                )));
            }
            sum += p.as_dvec3();
        }
        let mean = (sum / pixels.len() as f64).as_vec3();
        Ok(BitmapTexture { filename, width, height, data: pixels, filter, wrap, to_uv, mean })
    }

    #[inline]
    fn texel(&self, x: i64, y: i64) -> Spectrum {
        let x = self.wrap.wrap(x, self.width);
        let y = self.wrap.wrap(y, self.height);
        self.data[y * self.width + x]
    }

    #[inline]
    pub fn eval(&self, uv: Vec2) -> Spectrum {
        let uv = self.to_uv.transform_point2(uv);
        let res = Vec2::new(self.width as f32, self.height as f32);
        match self.filter {
            FilterType::Nearest => {
                let p = (uv * res).floor();
                self.texel(p.x as i64, p.y as i64)
            }
            FilterType::Bilinear => {
                let p = uv * res - 0.5;
                let i = p.floor();
                let w1 = p - i;
                let w0 = Vec2::ONE - w1;
                let (x, y) = (i.x as i64, i.y as i64);
                let v0 = w0.x * self.texel(x, y) + w1.x * self.texel(x + 1, y);
                let v1 = w0.x * self.texel(x, y + 1) + w1.x * self.texel(x + 1, y + 1);
                w0.y * v0 + w1.y * v1
            }
        }
    }

    /// Mean colour over all pixels (its luminance is Mitsuba's `mean()`).
    pub fn mean(&self) -> Spectrum {
        self.mean
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrap_modes_match_drjit() {
        // Dr.Jit's tex_wrap for a resolution of 4.
        let n = 4;
        let repeat: Vec<usize> = (-5..9).map(|i| WrapMode::Repeat.wrap(i, n)).collect();
        assert_eq!(repeat, vec![3, 0, 1, 2, 3, 0, 1, 2, 3, 0, 1, 2, 3, 0]);
        let mirror: Vec<usize> = (-5..9).map(|i| WrapMode::Mirror.wrap(i, n)).collect();
        assert_eq!(mirror, vec![3, 3, 2, 1, 0, 0, 1, 2, 3, 3, 2, 1, 0, 0]);
        let clamp: Vec<usize> = (-2..6).map(|i| WrapMode::Clamp.wrap(i, n)).collect();
        assert_eq!(clamp, vec![0, 0, 0, 1, 2, 3, 3, 3]);
    }

    #[test]
    fn bad_pixels_are_errors() {
        let px = vec![Spectrum::ONE, Spectrum::new(0.0, f32::INFINITY, 0.0)];
        let e = BitmapTexture::new(
            "t".into(),
            "t.png",
            2,
            1,
            px,
            FilterType::Bilinear,
            WrapMode::Repeat,
            Affine2::IDENTITY,
        )
        .unwrap_err();
        assert!(e.msg.contains("pixel (1, 0)"), "{}", e.msg);
    }
}

//! High dynamic range film (`<film type="hdrfilm">`): image size, crop window, pixel format and
//! reconstruction filter.
//!
//! | parameter                        | type    | default   |
//! |----------------------------------|---------|-----------|
//! | `width`, `height`                | integer | 768, 576  |
//! | `crop_offset_x`, `crop_offset_y` | integer | 0         |
//! | `crop_width`, `crop_height`      | integer | full film |
//! | `pixel_format`                   | string  | `rgb` (or `rgba`) |
//! | `component_format`               | string  | `float16` (`float32` accepted; output is always float32) |
//! | `file_format`                    | string  | `openexr` (`exr` accepted) |
//! | `sample_border`                  | boolean | false     |
//! | `banner`, `compensate`           | boolean | ignored, as in Mitsuba 3 |
//! | nested `<rfilter>`               |         | `gaussian` |
//!
//! Only the crop window is rendered; the camera still frames the full film. With
//! `sample_border`, samples are also taken in a band of [`RFilter::border_size`] pixels around
//! the crop window so that pixels at its edge receive the same filtered contributions as interior
//! pixels.
//!
//! ```xml
//! <film type="hdrfilm">
//!     <integer name="width" value="1920"/>
//!     <integer name="height" value="1080"/>
//!     <string name="pixel_format" value="rgba"/>
//!     <rfilter type="box"/>
//! </film>
//! ```

use super::image_block::ImageBlock;
use super::rfilter::RFilter;
use crate::scene::desc::{ObjectDesc, PluginKind, Props};
use crate::scene::error::{Error, Result};
use crate::scene::limits;

/// Largest accepted film side, to turn typos into errors instead of huge allocations.
const MAX_FILM_SIDE: i64 = 1 << 16;

/// Channels of the developed image (the weight channel is internal to [`ImageBlock`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PixelFormat {
    Rgb,
    Rgba,
}

impl PixelFormat {
    pub fn channel_names(self) -> &'static [&'static str] {
        match self {
            PixelFormat::Rgb => &["R", "G", "B"],
            PixelFormat::Rgba => &["R", "G", "B", "A"],
        }
    }
    pub fn channel_count(self) -> usize {
        self.channel_names().len()
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    pub width: u32,
    pub height: u32,
    pub crop_offset: (u32, u32),
    pub crop_size: (u32, u32),
    pub filter: RFilter,
    pub pixel_format: PixelFormat,
    /// Also sample a border of `filter.border_size()` pixels around the crop window (Mitsuba's).
    pub sample_border: bool,
}

impl Default for Film {
    /// Mitsuba's film when a sensor has none: 768×576 RGB with a Gaussian filter.
    fn default() -> Self {
        Film {
            width: 768,
            height: 576,
            crop_offset: (0, 0),
            crop_size: (768, 576),
            filter: RFilter::default(),
            pixel_format: PixelFormat::Rgb,
            sample_border: false,
        }
    }
}

/// A non-negative integer property no larger than `max`.
fn size_prop(props: &Props, name: &str, default: i64, max: i64) -> Result<u32> {
    let v = props.int(name, default)?;
    if !(0..=max).contains(&v) {
        return Err(props.error(name, format!("\"{name}\" must be between 0 and {max}, got {v}")));
    }
    Ok(v as u32)
}

impl Film {
    /// Parse a `<film>` object (only `hdrfilm`).
    pub fn from_desc(obj: &ObjectDesc) -> Result<Film> {
        if obj.plugin != "hdrfilm" {
            return Err(Error::at(
                &obj.pos,
                format!("film type \"{}\" is not supported (supported: hdrfilm)", obj.plugin),
            ));
        }
        let props = &obj.props;
        let width = size_prop(props, "width", 768, MAX_FILM_SIDE)?;
        let height = size_prop(props, "height", 576, MAX_FILM_SIDE)?;
        if width == 0 || height == 0 {
            return Err(Error::at(&obj.pos, format!("film size must be positive, got {width}x{height}")));
        }
        let crop_width = size_prop(props, "crop_width", width as i64, MAX_FILM_SIDE)?;
        let crop_height = size_prop(props, "crop_height", height as i64, MAX_FILM_SIDE)?;
        let crop_x = size_prop(props, "crop_offset_x", 0, MAX_FILM_SIDE)?;
        let crop_y = size_prop(props, "crop_offset_y", 0, MAX_FILM_SIDE)?;
        if crop_x + crop_width > width || crop_y + crop_height > height {
            return Err(Error::at(
                &obj.pos,
                format!(
                    "invalid crop window: crop_offset ({crop_x}, {crop_y}) + crop size ({crop_width}, {crop_height}) \
                     exceeds the film size ({width}, {height})"
                ),
            ));
        }
        if crop_width == 0 || crop_height == 0 {
            return Err(Error::at(&obj.pos, "the crop window is empty"));
        }
        let sample_border = props.bool("sample_border", false)?;

        let pixel_format = match props.string("pixel_format", "rgb")?.to_ascii_lowercase().as_str() {
            "rgb" => PixelFormat::Rgb,
            "rgba" => PixelFormat::Rgba,
            f @ ("luminance" | "luminance_alpha" | "xyz" | "xyza") => {
                return Err(props
                    .error("pixel_format", format!("pixel_format \"{f}\" is not supported (supported: rgb, rgba)")))
            }
            f => {
                return Err(props.error(
                    "pixel_format",
                    format!(
                        "invalid pixel_format \"{f}\" (expected rgb, rgba, luminance, luminance_alpha, xyz or xyza)"
                    ),
                ))
            }
        };
        match props.string("component_format", "float16")?.to_ascii_lowercase().as_str() {
            "float16" | "float32" => {}
            "uint32" => {
                return Err(props.error(
                    "component_format",
                    "component_format \"uint32\" is not supported (supported: float16, float32; images are written as float32)",
                ))
            }
            f => {
                return Err(props.error(
                    "component_format",
                    format!("invalid component_format \"{f}\" (expected float16, float32 or uint32)"),
                ))
            }
        }
        match props.string("file_format", "openexr")?.to_ascii_lowercase().as_str() {
            "openexr" | "exr" => {}
            f @ ("rgbe" | "pfm") => {
                return Err(
                    props.error("file_format", format!("file_format \"{f}\" is not supported (supported: openexr)"))
                )
            }
            f => {
                return Err(
                    props.error("file_format", format!("invalid file_format \"{f}\" (expected openexr, rgbe or pfm)"))
                )
            }
        }
        // Accepted and ignored by Mitsuba 3 (no banner; Kahan summation removed).
        props.get("banner");
        props.bool("compensate", false)?;

        let filter = match props.object_of(PluginKind::RFilter)? {
            Some(f) => RFilter::from_desc(&f)?,
            None => RFilter::default(),
        };
        let pixels = crop_width as u64 * crop_height as u64;
        let what = format!("the film (width x height {width} x {height}, crop {crop_width} x {crop_height})");
        limits::check(limits::film_bytes(pixels, pixel_format.channel_count() as u64), &what, &props.pos_of("width"))?;
        props.finish()?;
        Ok(Film {
            width,
            height,
            crop_offset: (crop_x, crop_y),
            crop_size: (crop_width, crop_height),
            filter,
            pixel_format,
            sample_border,
        })
    }

    /// Number of channels of the developed image (3 or 4).
    pub fn channel_count(&self) -> usize {
        self.pixel_format.channel_count()
    }

    /// Channel names of the developed image (`R, G, B[, A]`).
    pub fn channel_names(&self) -> &'static [&'static str] {
        self.pixel_format.channel_names()
    }

    /// The pixels to take samples in: the crop window, grown by the filter's border when
    /// `sample_border` is set. Returns (offset, size) in film pixels.
    pub fn sample_window(&self) -> ((i32, i32), (u32, u32)) {
        let b = if self.sample_border { self.filter.border_size() } else { 0 };
        (
            (self.crop_offset.0 as i32 - b as i32, self.crop_offset.1 as i32 - b as i32),
            (self.crop_size.0 + 2 * b, self.crop_size.1 + 2 * b),
        )
    }

    /// An empty block covering the crop window with `channels` value channels (tiles merge into it).
    pub fn create_block(&self, channels: usize) -> ImageBlock {
        ImageBlock::new((self.crop_offset.0 as i32, self.crop_offset.1 as i32), self.crop_size, self.filter, channels)
    }
}

//! Reading images (EXR, PNG) into float bitmaps with named channels.
//!
//! - OpenEXR: any compression the `exr` crate decodes (none, RLE, ZIP, ZIPS, PIZ, PXR24, B44),
//!   half / float / uint samples, any channel set (the first layer of a multi-layer file). Channels
//!   keep their names: Mitsuba writes half-float PIZ files whose channels are stored B, G, R, so
//!   callers look channels up by name ([`Bitmap::channel`], [`Bitmap::rgb`]), never by position.
//! - PNG: 8 or 16 bit, grey, grey+alpha, RGB, RGBA (palette images are expanded to RGB(A)).
//!   With `srgb_to_linear` the colour channels (not alpha) go through the sRGB transfer curve,
//!   as Mitsuba does for 8/16-bit images unless a texture asks for `raw` data.
//! - JPEG, BMP, TGA: 8-bit data, treated like PNG (sRGB-encoded unless `raw`).
//! - Radiance RGBE (`.hdr`, `.rgbe`) and PFM (`PF` colour / `Pf` grey, either byte order, rows
//!   stored bottom-up): linear floats, never converted (Mitsuba treats float formats as linear).
//!
//! Formats are recognised by their first bytes (TGA, which has no signature, by the `.tga` extension).
//!
//! Every failure is an [`Error::in_file`] naming the file.

use crate::color::Spectrum;
use crate::scene::{Error, Result};
use std::path::Path;

/// A decoded image: `channels.len()` interleaved float channels per pixel, row 0 at the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Bitmap {
    pub width: usize,
    pub height: usize,
    /// Channel names in storage order ("R", "G", "B", "A", "Y", or any EXR channel name).
    pub channels: Vec<String>,
    /// `width · height · channels.len()` samples, pixel (x, y) at `(y · width + x) · channels.len()`.
    pub data: Vec<f32>,
}

/// Where the colour of a pixel comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorLayout {
    /// Offsets of the R, G and B channels.
    Rgb([usize; 3]),
    /// Offset of a luminance channel `Y`, broadcast to grey.
    Y(usize),
}

impl Bitmap {
    /// Offset of the channel called `name` within a pixel.
    pub fn channel(&self, name: &str) -> Option<usize> {
        self.channels.iter().position(|c| c == name)
    }

    /// Where colour comes from: R, G, B when all three exist, else Y; `None` for other layouts.
    pub fn color_layout(&self) -> Option<ColorLayout> {
        if let (Some(r), Some(g), Some(b)) = (self.channel("R"), self.channel("G"), self.channel("B")) {
            return Some(ColorLayout::Rgb([r, g, b]));
        }
        self.channel("Y").map(ColorLayout::Y)
    }

    /// The colour layout, or an error naming `file` and the channels found.
    pub fn require_color(&self, file: &str) -> Result<ColorLayout> {
        self.color_layout().ok_or_else(|| {
            Error::in_file(
                file,
                format!(
                    "image has channels [{}]; expected R, G, B (optionally A) or a luminance channel Y",
                    self.channels.join(", ")
                ),
            )
        })
    }

    /// Colour of pixel (x, y): R, G, B, or Y broadcast to grey. Black when the image has neither
    /// (check [`Bitmap::color_layout`] when loading) or when (x, y) is outside the image.
    pub fn rgb(&self, x: usize, y: usize) -> Spectrum {
        if x >= self.width || y >= self.height {
            return Spectrum::ZERO;
        }
        let base = (y * self.width + x) * self.channels.len();
        let at = |c: usize| self.data.get(base + c).copied().unwrap_or(0.0);
        match self.color_layout() {
            Some(ColorLayout::Rgb([r, g, b])) => Spectrum::new(at(r), at(g), at(b)),
            Some(ColorLayout::Y(c)) => Spectrum::splat(at(c)),
            None => Spectrum::ZERO,
        }
    }

    /// All pixels as colours, row by row (see [`Bitmap::rgb`]); an error when there is no colour.
    pub fn to_rgb_pixels(&self, file: &str) -> Result<Vec<Spectrum>> {
        let layout = self.require_color(file)?;
        let n = self.channels.len();
        Ok(self
            .data
            .chunks_exact(n)
            .map(|p| match layout {
                ColorLayout::Rgb([r, g, b]) => Spectrum::new(p[r], p[g], p[b]),
                ColorLayout::Y(c) => Spectrum::splat(p[c]),
            })
            .collect())
    }
}

/// Read an image (OpenEXR, PNG, JPEG, BMP, TGA, RGBE or PFM; detected from its first bytes).
/// `srgb_to_linear` linearises the colour channels of 8/16-bit data; float formats are linear already.
pub fn read_image(path: &Path, srgb_to_linear: bool) -> Result<Bitmap> {
    let file = path.display().to_string();
    // Decoders allocate what the header declares: refuse sizes beyond memory first.
    crate::scene::limits::check_image(path, "", &crate::scene::SrcPos::file_only(&file))?;
    let bytes = std::fs::read(path).map_err(|e| Error::in_file(&file, format!("cannot read image: {e}")))?;
    let bitmap = if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        read_exr(&bytes, &file)?
    } else if bytes.starts_with(&[0x89, b'P', b'N', b'G', 0x0d, 0x0a, 0x1a, 0x0a]) {
        read_ldr(&bytes, &file, srgb_to_linear, image::ImageFormat::Png)?
    } else if bytes.starts_with(&[0xff, 0xd8, 0xff]) {
        read_ldr(&bytes, &file, srgb_to_linear, image::ImageFormat::Jpeg)?
    } else if bytes.starts_with(b"BM") {
        read_ldr(&bytes, &file, srgb_to_linear, image::ImageFormat::Bmp)?
    } else if bytes.starts_with(b"#?") {
        read_rgbe(&bytes, &file)?
    } else if bytes.starts_with(b"PF") || bytes.starts_with(b"Pf") {
        read_pfm(&bytes, &file)?
    } else if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("tga")) {
        read_ldr(&bytes, &file, srgb_to_linear, image::ImageFormat::Tga)?
    } else {
        return Err(Error::in_file(
            &file,
            "unsupported image format (expected OpenEXR, PNG, JPEG, BMP, TGA, RGBE/HDR or PFM)",
        ));
    };
    if bitmap.width == 0 || bitmap.height == 0 || bitmap.channels.is_empty() {
        return Err(Error::in_file(&file, "image is empty"));
    }
    Ok(bitmap)
}

fn read_exr(bytes: &[u8], file: &str) -> Result<Bitmap> {
    use exr::prelude::{read, FlatSamples, ReadChannels, ReadLayers, Vec2};
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_buffered(std::io::Cursor::new(bytes))
        .map_err(|e| Error::in_file(file, format!("cannot decode OpenEXR: {e}")))?;
    let layer = &image.layer_data;
    let (width, height) = (layer.size.width(), layer.size.height());
    let list = &layer.channel_data.list;
    let nc = list.len();
    let mut channels = Vec::with_capacity(nc);
    let mut data = vec![0.0f32; width * height * nc];
    for (c, ch) in list.iter().enumerate() {
        let name = ch.name.to_string();
        if ch.sampling != Vec2(1, 1) {
            return Err(Error::in_file(file, format!("channel \"{name}\" is subsampled, which is not supported")));
        }
        let samples: Vec<f32> = match &ch.sample_data {
            FlatSamples::F16(v) => v.iter().map(|h| h.to_f32()).collect(),
            FlatSamples::F32(v) => v.clone(),
            FlatSamples::U32(v) => v.iter().map(|&u| u as f32).collect(),
        };
        if samples.len() != width * height {
            return Err(Error::in_file(
                file,
                format!("channel \"{name}\" has {} samples, expected {}", samples.len(), width * height),
            ));
        }
        for (i, s) in samples.into_iter().enumerate() {
            data[i * nc + c] = s;
        }
        channels.push(name);
    }
    Ok(Bitmap { width, height, channels, data })
}

/// 8/16-bit formats decoded by the `image` crate.
fn read_ldr(bytes: &[u8], file: &str, srgb_to_linear: bool, format: image::ImageFormat) -> Result<Bitmap> {
    use image::DynamicImage as D;
    let name = format!("{format:?}").to_uppercase();
    let img = image::load_from_memory_with_format(bytes, format)
        .map_err(|e| Error::in_file(file, format!("cannot decode {name}: {e}")))?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    let (names, alpha, data): (&[&str], bool, Vec<f32>) = match img {
        D::ImageLuma8(i) => (&["Y"], false, unorm8(i.as_raw())),
        D::ImageLumaA8(i) => (&["Y", "A"], true, unorm8(i.as_raw())),
        D::ImageRgb8(i) => (&["R", "G", "B"], false, unorm8(i.as_raw())),
        D::ImageRgba8(i) => (&["R", "G", "B", "A"], true, unorm8(i.as_raw())),
        D::ImageLuma16(i) => (&["Y"], false, unorm16(i.as_raw())),
        D::ImageLumaA16(i) => (&["Y", "A"], true, unorm16(i.as_raw())),
        D::ImageRgb16(i) => (&["R", "G", "B"], false, unorm16(i.as_raw())),
        D::ImageRgba16(i) => (&["R", "G", "B", "A"], true, unorm16(i.as_raw())),
        other => {
            return Err(Error::in_file(file, format!("unsupported {name} pixel type {:?}", other.color())));
        }
    };
    let mut data = data;
    if srgb_to_linear {
        let n = names.len();
        let colour = if alpha { n - 1 } else { n };
        for px in data.chunks_exact_mut(n) {
            for v in &mut px[..colour] {
                *v = srgb_to_linear_value(*v);
            }
        }
    }
    Ok(Bitmap { width, height, channels: names.iter().map(|s| s.to_string()).collect(), data })
}

/// Radiance RGBE (`.hdr`): linear RGB floats.
fn read_rgbe(bytes: &[u8], file: &str) -> Result<Bitmap> {
    // The decoder only accepts the "#?RADIANCE" signature; Mitsuba (and others) write "#?RGBE",
    // which the format allows: normalise the first line.
    let mut owned;
    let mut bytes = bytes;
    if !bytes.starts_with(b"#?RADIANCE\n") {
        let end = bytes.iter().position(|&b| b == b'\n').unwrap_or(bytes.len());
        owned = b"#?RADIANCE".to_vec();
        owned.extend_from_slice(&bytes[end..]);
        bytes = &owned;
    }
    let img = image::load_from_memory_with_format(bytes, image::ImageFormat::Hdr)
        .map_err(|e| Error::in_file(file, format!("cannot decode RGBE: {e}")))?;
    let (width, height) = (img.width() as usize, img.height() as usize);
    let data = img.into_rgb32f().into_raw();
    Ok(Bitmap { width, height, channels: vec!["R".into(), "G".into(), "B".into()], data })
}

/// Portable float map: header "PF" (RGB) or "Pf" (grey), width height, scale (negative: little
/// endian), then rows of f32 from the bottom row up.
fn read_pfm(bytes: &[u8], file: &str) -> Result<Bitmap> {
    let bad = |msg: &str| Error::in_file(file, format!("cannot decode PFM: {msg}"));
    // Three whitespace-separated header fields after the magic, then one whitespace byte.
    let mut fields = Vec::new();
    let mut i = 2;
    while fields.len() < 3 {
        while i < bytes.len() && bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        let start = i;
        while i < bytes.len() && !bytes[i].is_ascii_whitespace() {
            i += 1;
        }
        if start == i {
            return Err(bad("truncated header"));
        }
        fields.push(std::str::from_utf8(&bytes[start..i]).map_err(|_| bad("invalid header"))?.to_string());
    }
    i += 1;
    let parse_usize = |s: &str| s.parse::<usize>().map_err(|_| bad(&format!("invalid size \"{s}\"")));
    let (width, height) = (parse_usize(&fields[0])?, parse_usize(&fields[1])?);
    let scale: f32 = fields[2].parse().map_err(|_| bad(&format!("invalid scale \"{}\"", fields[2])))?;
    if scale == 0.0 || !scale.is_finite() {
        return Err(bad("the scale must be non-zero"));
    }
    let nc = if bytes[1] == b'F' { 3 } else { 1 };
    let count = width.checked_mul(height).and_then(|n| n.checked_mul(nc)).ok_or_else(|| bad("image too large"))?;
    let body = bytes.get(i..).unwrap_or(&[]);
    if body.len() < count * 4 {
        return Err(bad(&format!("expected {} bytes of pixel data, found {}", count * 4, body.len())));
    }
    let mut data = vec![0.0f32; count];
    let row = width * nc;
    for (k, chunk) in body[..count * 4].chunks_exact(4).enumerate() {
        let b = [chunk[0], chunk[1], chunk[2], chunk[3]];
        let v = if scale < 0.0 { f32::from_le_bytes(b) } else { f32::from_be_bytes(b) };
        // Row k / row counts from the bottom.
        let (y, x) = (k / row, k % row);
        data[(height - 1 - y) * row + x] = v;
    }
    let channels = if nc == 3 { vec!["R".into(), "G".into(), "B".into()] } else { vec!["Y".into()] };
    Ok(Bitmap { width, height, channels, data })
}

fn unorm8(v: &[u8]) -> Vec<f32> {
    v.iter().map(|&b| b as f32 / 255.0).collect()
}

fn unorm16(v: &[u16]) -> Vec<f32> {
    v.iter().map(|&b| b as f32 / 65535.0).collect()
}

/// The sRGB electro-optical transfer function (IEC 61966-2-1), in double precision like Mitsuba's table.
pub fn srgb_to_linear_value(v: f32) -> f32 {
    let v = v as f64;
    (if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_endpoints() {
        assert_eq!(srgb_to_linear_value(0.0), 0.0);
        assert!((srgb_to_linear_value(1.0) - 1.0).abs() < 1e-6);
        assert!((srgb_to_linear_value(0.5) - 0.214_041_14).abs() < 1e-6);
    }

    #[test]
    fn rgb_falls_back_to_y() {
        let b = Bitmap { width: 1, height: 1, channels: vec!["A".into(), "Y".into()], data: vec![0.5, 2.0] };
        assert_eq!(b.rgb(0, 0), Spectrum::splat(2.0));
        assert_eq!(b.color_layout(), Some(ColorLayout::Y(1)));
        let b = Bitmap { width: 1, height: 1, channels: vec!["Z".into()], data: vec![1.0] };
        assert!(b.require_color("x.exr").is_err());
        assert_eq!(b.rgb(0, 0), Spectrum::ZERO);
    }
}

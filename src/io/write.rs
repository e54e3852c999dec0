//! Writing images: float32 EXR with any channel names (`R, G, B[, A]` plus extras such as
//! `var.R`) and optional text header attributes, and sRGB 8-bit PNG previews of linear RGB data.
//! Both are written atomically ([`super::atomic`]): an existing file is replaced whole or not at all.

use anyhow::{bail, Context};
use std::path::Path;

/// Write a float32 OpenEXR file (ZIP compressed). `data` holds `width × height` pixels, row 0
/// at the top, with one value per channel interleaved in the order of `channels`.
pub fn write_exr(path: &Path, width: usize, height: usize, channels: &[&str], data: &[f32]) -> anyhow::Result<()> {
    write_exr_with_attributes(path, width, height, channels, data, &[])
}

/// [`write_exr`] with extra text attributes `(name, value)` in the layer header (values are made
/// ASCII: other characters become JSON-style `\uXXXX` escapes, see [`super::meta::to_ascii`]).
pub fn write_exr_with_attributes(
    path: &Path,
    width: usize,
    height: usize,
    channels: &[&str],
    data: &[f32],
    attributes: &[(&str, &str)],
) -> anyhow::Result<()> {
    use exr::prelude::*;

    let n = channels.len();
    if n == 0 {
        bail!("cannot write {}: no channels", path.display());
    }
    if width == 0 || height == 0 {
        bail!("cannot write {}: empty image ({width}x{height})", path.display());
    }
    if data.len() != width * height * n {
        bail!(
            "cannot write {}: {} values for a {width}x{height} image with {n} channels (expected {})",
            path.display(),
            data.len(),
            width * height * n
        );
    }
    for (i, name) in channels.iter().enumerate() {
        if name.is_empty() || channels[..i].contains(name) {
            bail!("cannot write {}: channel name \"{name}\" is empty or repeated", path.display());
        }
    }

    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .iter()
        .enumerate()
        .map(|(c, name)| {
            let samples: Vec<f32> = data.iter().skip(c).step_by(n).copied().collect();
            AnyChannel::new(*name, FlatSamples::F32(samples))
        })
        .collect();
    let encoding = Encoding { compression: Compression::ZIP16, ..Encoding::default() };
    let mut layer_attributes = LayerAttributes::default();
    for (name, value) in attributes {
        let (Some(n), Some(v)) = (Text::new_or_none(name), Text::new_or_none(super::meta::to_ascii(value))) else {
            bail!("cannot write {}: attribute \"{name}\" is not representable", path.display());
        };
        layer_attributes.other.insert(n, AttributeValue::Text(v));
    }
    let layer = Layer::new((width, height), layer_attributes, encoding, AnyChannels::sort(list));
    super::atomic::write_with(path, |tmp| {
        Image::from_layer(layer).write().to_file(tmp).with_context(|| format!("writing {}", path.display()))
    })
}

/// The sRGB transfer function (linear → display), as Mitsuba applies it when converting to 8 bit.
#[inline]
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Write an 8-bit sRGB PNG preview of linear RGB data (3 values per pixel, row 0 at the top):
/// values are clamped to [0, 1] after the sRGB curve; non-finite values become 0.
pub fn write_png(path: &Path, width: usize, height: usize, rgb: &[f32]) -> anyhow::Result<()> {
    if width == 0 || height == 0 {
        bail!("cannot write {}: empty image ({width}x{height})", path.display());
    }
    if rgb.len() != width * height * 3 {
        bail!(
            "cannot write {}: {} values for a {width}x{height} RGB image (expected {})",
            path.display(),
            rgb.len(),
            width * height * 3
        );
    }
    let (Ok(w), Ok(h)) = (u32::try_from(width), u32::try_from(height)) else {
        bail!("cannot write {}: image too large ({width}x{height})", path.display());
    };
    let bytes: Vec<u8> = rgb
        .iter()
        .map(|&v| {
            let v = if v.is_finite() { v } else { 0.0 };
            (linear_to_srgb(v).clamp(0.0, 1.0) * 255.0 + 0.5) as u8
        })
        .collect();
    super::atomic::write_with(path, |tmp| {
        image::save_buffer_with_format(tmp, &bytes, w, h, image::ColorType::Rgb8, image::ImageFormat::Png)
            .with_context(|| format!("writing {}", path.display()))
    })
}

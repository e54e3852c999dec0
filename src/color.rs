//! RGB colour: [`Spectrum`] is a linear-sRGB triple (Mitsuba's RGB mode), plus helpers.

use glam::Vec3;

/// Linear sRGB radiance / reflectance triple.
pub type Spectrum = Vec3;

/// Luminance of linear sRGB (Mitsuba's `luminance` with Rec. 709 weights).
#[inline]
pub fn luminance(c: Spectrum) -> f32 {
    c.x * 0.212671 + c.y * 0.715160 + c.z * 0.072169
}

/// True when every channel is finite.
#[inline]
pub fn is_finite(c: Spectrum) -> bool {
    c.x.is_finite() && c.y.is_finite() && c.z.is_finite()
}

/// Largest channel.
#[inline]
pub fn max_value(c: Spectrum) -> f32 {
    c.max_element()
}

/// sRGB transfer function for the PNG preview.
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// Tint applied in RGB mode to a uniform `<spectrum>` on an emitter (Mitsuba converts
/// the uniform emission through its D65-normalised sRGB mapping).
pub const UNIFORM_EMITTER_TINT: Vec3 = Vec3::new(1.2048, 0.9483, 0.9089);

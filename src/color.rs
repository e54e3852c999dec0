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
    // c·0 is ±0 in every finite channel and NaN in an infinite or NaN one: one 4-lane multiply
    // and compare instead of three scalar tests.
    (glam::Vec3A::from(c) * 0.0).cmpeq(glam::Vec3A::ZERO).all()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn is_finite_rejects_any_infinite_or_nan_channel() {
        assert!(is_finite(Spectrum::new(0.0, -0.0, f32::MAX)));
        assert!(is_finite(Spectrum::new(f32::MIN_POSITIVE, -f32::MAX, 1e-45)));
        for bad in [f32::INFINITY, f32::NEG_INFINITY, f32::NAN] {
            for i in 0..3 {
                let mut c = Spectrum::ONE;
                c[i] = bad;
                assert!(!is_finite(c), "{c:?}");
            }
        }
    }
}

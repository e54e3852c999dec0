//! `<spectrum>` values: a uniform value, or a `wavelength:value` list that is converted to
//! linear sRGB exactly as Mitsuba 3.9 does in its RGB variants (`spectrum_list_to_srgb`): the
//! piecewise-linear spectrum is integrated against the CIE 1931 colour matching functions
//! (times the CIE D65 illuminant for reflectance-like values) at 1000 wavelengths spread over
//! 360–830 nm, and the XYZ result is converted to linear sRGB (BT.709 primaries) and clamped.
//!
//! The tables are Mitsuba's (`src/core/spectrum.cpp`, 5 nm steps, single precision); the D65
//! table is already multiplied by `MI_CIE_D65_NORMALIZATION`.

use super::number::{parse_float, tokenize, tokens};
use glam::DVec3;

/// Shortest wavelength of the tables (nm).
pub const CIE_MIN: f64 = 360.0;
/// Longest wavelength of the tables (nm).
pub const CIE_MAX: f64 = 830.0;
const CIE_SAMPLES: usize = 95;
/// Mitsuba's `MI_CIE_Y_NORMALIZATION`: a unit spectrum integrates to a luminance of 1.
const CIE_Y_NORMALIZATION: f64 = 1.0 / 106.750_259_399_414_06;

/// A parsed `<spectrum value="...">`.
#[derive(Clone, Debug, PartialEq)]
pub enum SpectrumSpec {
    Uniform(f64),
    /// Wavelengths (nm, strictly increasing, at least two) and values.
    List(Vec<f64>, Vec<f64>),
}

/// Parse the `value` attribute of `<spectrum>` like Mitsuba's `Properties::Spectrum(string)`.
pub fn parse_spectrum(value: &str) -> Result<SpectrumSpec, String> {
    let toks = tokens(value);
    if let [single] = toks.as_slice() {
        if !single.contains(':') {
            return parse_float(single)
                .map(SpectrumSpec::Uniform)
                .ok_or_else(|| format!("could not parse uniform spectrum value \"{single}\""));
        }
    }
    let mut wavelengths = Vec::with_capacity(toks.len());
    let mut values = Vec::with_capacity(toks.len());
    for tok in &toks {
        let pair = tokenize(tok, &[':']);
        let [w, v] = pair.as_slice() else {
            return Err(format!("invalid spectrum value \"{tok}\" (expected wavelength:value pairs)"));
        };
        match (parse_float(w), parse_float(v)) {
            (Some(w), Some(v)) => {
                wavelengths.push(w);
                values.push(v);
            }
            _ => return Err(format!("could not parse wavelength:value pair \"{tok}\"")),
        }
    }
    if wavelengths.len() < 2 {
        return Err("a spectrum needs at least two wavelength:value pairs (or a single uniform value)".into());
    }
    // Also rejects NaN wavelengths.
    if wavelengths.windows(2).any(|w| w[0].partial_cmp(&w[1]) != Some(std::cmp::Ordering::Less)) {
        return Err("wavelengths must be specified in increasing order".into());
    }
    Ok(SpectrumSpec::List(wavelengths, values))
}

/// Linear interpolation in a 5 nm table; zero outside [360, 830] nm.
fn lookup(table: &[f32; CIE_SAMPLES], w: f64) -> f64 {
    if !(CIE_MIN..=CIE_MAX).contains(&w) {
        return 0.0;
    }
    let t = (w - CIE_MIN) * ((CIE_SAMPLES - 1) as f64 / (CIE_MAX - CIE_MIN));
    let i0 = (t as usize).min(CIE_SAMPLES - 2);
    let w1 = t - i0 as f64;
    (1.0 - w1) * table[i0] as f64 + w1 * table[i0 + 1] as f64
}

/// CIE 1931 XYZ colour matching functions at wavelength `w` (nm), unnormalized.
pub fn cie1931_xyz(w: f64) -> DVec3 {
    DVec3::new(lookup(&CIE_X, w), lookup(&CIE_Y, w), lookup(&CIE_Z, w))
}

/// The CIE D65 illuminant, normalized as Mitsuba's `cie_d65`.
pub fn cie_d65(w: f64) -> f64 {
    lookup(&CIE_D65, w)
}

/// XYZ → linear sRGB with Mitsuba's (single precision) matrix.
pub fn xyz_to_srgb(xyz: DVec3) -> DVec3 {
    let m = |a: f32, b: f32, c: f32| a as f64 * xyz.x + b as f64 * xyz.y + c as f64 * xyz.z;
    DVec3::new(m(3.240479, -1.53715, -0.498535), m(-0.969256, 1.875991, 0.041556), m(0.055648, -0.204043, 1.057311))
}

/// Mitsuba's `spectrum_list_to_srgb(wavelengths, values, bounded, d65)`. Mitsuba's RGB variants
/// call it with `d65 = !emitter` and `bounded = !(emitter || unbounded parameter)`. Negative
/// results are clamped to 0, and to at most 1 when `bounded`. `wavelengths` must be increasing
/// with at least two entries (as [`parse_spectrum`] guarantees); otherwise the result is black.
pub fn spectrum_list_to_srgb(wavelengths: &[f64], values: &[f64], bounded: bool, d65: bool) -> DVec3 {
    let n = wavelengths.len().min(values.len());
    if n < 2 {
        return DVec3::ZERO;
    }
    let (first, last) = (wavelengths[0], wavelengths[n - 1]);
    let steps = 1000;
    let mut xyz = DVec3::ZERO;
    for i in 0..steps {
        let w = CIE_MIN + (i as f64 / (steps - 1) as f64) * (CIE_MAX - CIE_MIN);
        if w < first || w > last {
            continue;
        }
        // Interval [k, k+1] with wavelengths[k] <= w (clamped to the valid range).
        let k = wavelengths[..n].partition_point(|&x| x <= w).clamp(1, n - 1) - 1;
        let (w0, w1, v0, v1) = (wavelengths[k], wavelengths[k + 1], values[k], values[k + 1]);
        let v = ((w - w1) * v0 + (w0 - w) * v1) / (w0 - w1);
        xyz += cie1931_xyz(w) * (v * if d65 { cie_d65(w) } else { 1.0 });
    }
    xyz *= (CIE_MAX - CIE_MIN) / steps as f64 * CIE_Y_NORMALIZATION;
    let rgb = xyz_to_srgb(xyz);
    if bounded {
        rgb.clamp(DVec3::ZERO, DVec3::ONE)
    } else {
        rgb.max(DVec3::ZERO)
    }
}

const CIE_X: [f32; 95] = [
    0.0001299,
    0.0002321,
    0.0004149,
    0.0007416,
    0.001368,
    0.002236,
    0.004243,
    0.00765,
    0.01431,
    0.02319,
    0.04351,
    0.07763,
    0.13438,
    0.21477,
    0.2839,
    0.3285,
    0.34828,
    0.34806,
    0.3362,
    0.3187,
    0.2908,
    0.2511,
    0.19536,
    0.1421,
    0.09564,
    0.05795001,
    0.03201,
    0.0147,
    0.0049,
    0.0024,
    0.0093,
    0.0291,
    0.06327,
    0.1096,
    0.1655,
    0.2257499,
    0.2904,
    0.3597,
    0.4334499,
    0.5120501,
    0.5945,
    0.6784,
    0.7621,
    0.8425,
    0.9163,
    0.9786,
    1.0263,
    1.0567,
    1.0622,
    1.0456,
    1.0026,
    0.9384,
    0.8544499,
    0.7514,
    0.6424,
    0.5419,
    0.4479,
    0.3608,
    0.2835,
    0.2187,
    0.1649,
    0.1212,
    0.0874,
    0.0636,
    0.04677,
    0.0329,
    0.0227,
    0.01584,
    0.01135916,
    0.008110916,
    0.005790346,
    0.004109457,
    0.002899327,
    0.00204919,
    0.001439971,
    0.0009999493,
    0.0006900786,
    0.0004760213,
    0.0003323011,
    0.0002348261,
    0.0001661505,
    0.000117413,
    8.307527e-05,
    5.870652e-05,
    4.150994e-05,
    2.935326e-05,
    2.067383e-05,
    1.455977e-05,
    1.025398e-05,
    7.221456e-06,
    5.085868e-06,
    3.581652e-06,
    2.522525e-06,
    1.776509e-06,
    1.251141e-06,
];
const CIE_Y: [f32; 95] = [
    3.917e-06, 6.965e-06, 1.239e-05, 2.202e-05, 3.9e-05, 6.4e-05, 0.00012, 0.000217, 0.000396, 0.00064, 0.00121,
    0.00218, 0.004, 0.0073, 0.0116, 0.01684, 0.023, 0.0298, 0.038, 0.048, 0.06, 0.0739, 0.09098, 0.1126, 0.13902,
    0.1693, 0.20802, 0.2586, 0.323, 0.4073, 0.503, 0.6082, 0.71, 0.7932, 0.862, 0.9148501, 0.954, 0.9803, 0.9949501,
    1.0, 0.995, 0.9786, 0.952, 0.9154, 0.87, 0.8163, 0.757, 0.6949, 0.631, 0.5668, 0.503, 0.4412, 0.381, 0.321, 0.265,
    0.217, 0.175, 0.1382, 0.107, 0.0816, 0.061, 0.04458, 0.032, 0.0232, 0.017, 0.01192, 0.00821, 0.005723, 0.004102,
    0.002929, 0.002091, 0.001484, 0.001047, 0.00074, 0.00052, 0.0003611, 0.0002492, 0.0001719, 0.00012, 8.48e-05,
    6e-05, 4.24e-05, 3e-05, 2.12e-05, 1.499e-05, 1.06e-05, 7.4657e-06, 5.2578e-06, 3.7029e-06, 2.6078e-06, 1.8366e-06,
    1.2934e-06, 9.1093e-07, 6.4153e-07, 4.5181e-07,
];
const CIE_Z: [f32; 95] = [
    0.0006061,
    0.001086,
    0.001946,
    0.003486,
    0.006450001,
    0.01054999,
    0.02005001,
    0.03621,
    0.06785001,
    0.1102,
    0.2074,
    0.3713,
    0.6456,
    1.0390501,
    1.3856,
    1.62296,
    1.74706,
    1.7826,
    1.77211,
    1.7441,
    1.6692,
    1.5281,
    1.28764,
    1.0419,
    0.8129501,
    0.6162,
    0.46518,
    0.3533,
    0.272,
    0.2123,
    0.1582,
    0.1117,
    0.07824999,
    0.05725001,
    0.04216,
    0.02984,
    0.0203,
    0.0134,
    0.008749999,
    0.005749999,
    0.0039,
    0.002749999,
    0.0021,
    0.0018,
    0.001650001,
    0.0014,
    0.0011,
    0.001,
    0.0008,
    0.0006,
    0.00034,
    0.00024,
    0.00019,
    1e-04,
    4.999999e-05,
    3e-05,
    2e-05,
    1e-05,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
    0.0,
];
const CIE_D65: [f32; 95] = [
    0.47110626, 0.49863625, 0.52616626, 0.51549125, 0.5048162, 0.5284158, 0.55201644, 0.69397265, 0.8359299, 0.880027,
    0.92412513, 0.9339526, 0.9437802, 0.9096904, 0.8756016, 0.9674353, 1.05927, 1.1205949, 1.1819298, 1.1859906,
    1.1900512, 1.1751418, 1.1602424, 1.1656061, 1.17097, 1.1350498, 1.0991297, 1.1018672, 1.1046146, 1.0967761,
    1.0889375, 1.073725, 1.0585124, 1.0731492, 1.0877961, 1.0712098, 1.0546235, 1.0528052, 1.0509971, 1.0305623,
    1.0101273, 0.99161273, 0.9730981, 0.9703394, 0.9675808, 0.9317092, 0.89583755, 0.9025074, 0.9091773, 0.9071206,
    0.905065, 0.8954668, 0.88586855, 0.86359423, 0.84132093, 0.8433947, 0.8454686, 0.82692057, 0.8083726, 0.8093211,
    0.8102696, 0.8206901, 0.8311106, 0.8109403, 0.7907702, 0.7475215, 0.70427394, 0.71380854, 0.72334313, 0.7371808,
    0.7510196, 0.68664926, 0.62227887, 0.6641062, 0.7059336, 0.7322039, 0.7584743, 0.70042026, 0.6423673, 0.5556246,
    0.46888295, 0.5718513, 0.6748196, 0.65753335, 0.64024705, 0.64489967, 0.6495523, 0.6250456, 0.6005399, 0.5626955,
    0.5248521, 0.5525376, 0.58022326, 0.59472764, 0.6092331,
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parse_forms() {
        assert_eq!(parse_spectrum("0.5"), Ok(SpectrumSpec::Uniform(0.5)));
        assert_eq!(
            parse_spectrum("400:0.1 500:0.2, 600:0.4"),
            Ok(SpectrumSpec::List(vec![400.0, 500.0, 600.0], vec![0.1, 0.2, 0.4]))
        );
        for bad in ["400:0.1", "500:0.1, 400:0.2", "400:0.1,500", "0.1 0.2", "x", "400:a, 500:1", ""] {
            assert!(parse_spectrum(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn tables_interpolate_like_mitsuba() {
        // mi.cie1931_xyz(362.5)[1] and mi.cie_d65(560.0), Mitsuba 3.9.1.
        assert!((cie1931_xyz(362.5).y - 5.441e-06).abs() < 1e-12);
        assert!((cie_d65(560.0) - 1.010127305984497).abs() < 1e-7);
        assert_eq!(cie_d65(359.9), 0.0);
        assert_eq!(cie_d65(830.1), 0.0);
    }
}

//! Inlined math in place of libm calls: `exp` of an RGB triple in one SSE evaluation
//! (transmittance), `sincos(2π·u)` (the azimuth of sampled directions), and `acos` (the corner
//! angles of angle-weighted vertex normals at mesh load).
//!
//! Range reduction plus the minimax polynomials of Cephes' `expf`, `sinf` and `cosf` (Moshier
//! 1989), branch-free. Accuracy (tested below over the ranges the renderer uses): `exp3` within
//! 2 ulp of the correctly rounded value; `sincos_2pi` within 2e-7 absolute. `exp3` returns 0 below
//! −87.33 (where `f32` results become subnormal), as Dr.Jit's `exp` does. (A scalar `exp` or `ln`
//! of this kind is no cheaper than glibc's FMA variants, measured; so scalar calls stay libm's.)

use glam::Vec3;

/// `e^x` per channel, the three channels in one 4-lane evaluation. NaN stays NaN; 0 below
/// −87.33; +∞ above 88.72.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub fn exp3(v: Vec3) -> Vec3 {
    use std::arch::x86_64::*;
    const LOG2E: f32 = std::f32::consts::LOG2_E;
    // ln 2 split so that n·LN2_HI is exact for |n| < 2^9.
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    // 1.5·2^23: adding it rounds to the nearest integer (ties to even) in the low mantissa bits.
    const ROUND: f32 = 12_582_912.0;
    // SAFETY: SSE2 is part of x86_64; only lane arithmetic, no memory access.
    unsafe {
        let x = _mm_set_ps(0.0, v.z, v.y, v.x);
        let xc = _mm_min_ps(_mm_max_ps(x, _mm_set1_ps(-87.5)), _mm_set1_ps(88.75));
        let t = _mm_add_ps(_mm_mul_ps(xc, _mm_set1_ps(LOG2E)), _mm_set1_ps(ROUND));
        let n = _mm_sub_ps(t, _mm_set1_ps(ROUND));
        // r = x − n·ln 2 in [−ln2/2, ln2/2].
        let r = _mm_sub_ps(_mm_sub_ps(xc, _mm_mul_ps(n, _mm_set1_ps(LN2_HI))), _mm_mul_ps(n, _mm_set1_ps(LN2_LO)));
        let mad = |a: __m128, b: f32| _mm_add_ps(_mm_mul_ps(a, r), _mm_set1_ps(b));
        let p = mad(
            mad(mad(mad(mad(_mm_set1_ps(1.987_569_1e-4), 1.398_2e-3), 8.333_452e-3), 4.166_579_6e-2), 0.166_666_65),
            0.5,
        );
        let p = _mm_add_ps(_mm_add_ps(_mm_mul_ps(p, _mm_mul_ps(r, r)), r), _mm_set1_ps(1.0));
        // 2^n (n in [−126, 128], the integer in t's low bits) as two normal factors.
        let n_int = _mm_sub_epi32(_mm_castps_si128(t), _mm_set1_epi32(0x4B40_0000));
        let half = _mm_srai_epi32(n_int, 1);
        let pow2 = |k: __m128i| _mm_castsi128_ps(_mm_slli_epi32(_mm_add_epi32(k, _mm_set1_epi32(127)), 23));
        let y = _mm_mul_ps(_mm_mul_ps(p, pow2(half)), pow2(_mm_sub_epi32(n_int, half)));
        let y = _mm_andnot_ps(_mm_cmplt_ps(x, _mm_set1_ps(-87.336_54)), y);
        let over = _mm_cmpgt_ps(x, _mm_set1_ps(88.722_83));
        let y = _mm_or_ps(_mm_and_ps(over, _mm_set1_ps(f32::INFINITY)), _mm_andnot_ps(over, y));
        let nan = _mm_cmpunord_ps(x, x);
        let y = _mm_or_ps(_mm_and_ps(nan, x), _mm_andnot_ps(nan, y));
        let mut out = [0.0f32; 4];
        _mm_storeu_ps(out.as_mut_ptr(), y);
        Vec3::new(out[0], out[1], out[2])
    }
}

/// `e^x` per channel (libm off x86_64).
#[cfg(not(target_arch = "x86_64"))]
#[inline(always)]
pub fn exp3(v: Vec3) -> Vec3 {
    v.exp()
}

/// The parts of [`sincos_2pi`] before its quadrant switch: `(sin, cos)` of the rest of `u` after
/// its nearest quarter turn, and that quarter turn modulo 4. Shared with the lane-wise form in
/// `integrator::path_wide`, which does the switch with selects.
#[inline(always)]
pub fn sincos_2pi_parts(u: f32) -> (f32, f32, u32) {
    const ROUND: f32 = 12_582_912.0;
    // Nearest quarter turn q and the rest r in [−1/8, 1/8] (exact: u − q/4 is representable).
    let t = u * 4.0 + ROUND;
    let q = t - ROUND;
    let quadrant = t.to_bits() & 3;
    let x = (u - q * 0.25) * (2.0 * std::f32::consts::PI);
    let x2 = x * x;
    let s = ((-1.951_529_6e-4 * x2 + 8.332_161e-3) * x2 - 0.166_666_55) * x2 * x + x;
    let c = ((2.443_315_7e-5 * x2 - 1.388_731_6e-3) * x2 + 4.166_664_6e-2) * (x2 * x2) - 0.5 * x2 + 1.0;
    (s, c, quadrant)
}

/// `(sin 2πu, cos 2πu)` for `u` in [−1/8, 1] (a sampled angle as a fraction of a turn).
#[inline(always)]
pub fn sincos_2pi(u: f32) -> (f32, f32) {
    let (s, c, quadrant) = sincos_2pi_parts(u);
    match quadrant {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// `acos(x)` for x in [−1, 1] (clamped; NaN stays NaN) within 2 ulp, without a libm call:
/// Cephes' `asinf` polynomial (as Dr.Jit's `acos`, which Mitsuba's normals use), on
/// `asin(x)` for |x| ≤ 1/2 and on `2 asin(√((1 − |x|) / 2))` above.
#[inline(always)]
pub fn acos(x: f32) -> f32 {
    let x = x.clamp(-1.0, 1.0);
    let a = x.abs();
    let big = a > 0.5;
    let z = if big { 0.5 * (1.0 - a) } else { a * a };
    let s = if big { z.sqrt() } else { a };
    let p = (((4.216_32e-2 * z + 2.418_131_2e-2) * z + 4.547_002_6e-2) * z + 7.495_300_3e-2) * z + 1.666_675_2e-1;
    // asin(s) for s in [0, 1/2].
    let asin_s = s + s * z * p;
    if big {
        let r = 2.0 * asin_s;
        if x < 0.0 {
            std::f32::consts::PI - r
        } else {
            r
        }
    } else {
        std::f32::consts::FRAC_PI_2 - asin_s.copysign(x)
    }
}

/// `atan2(y, x)` in [−π, π] without a libm call, within 3e-7 (absolute): Cephes' `atanf`
/// polynomial on the ratio of the smaller to the larger magnitude (in [0, 1], reduced once more
/// around 1 by atan a = π/4 + atan((a − 1)/(a + 1))), then moved to the octant of (x, y). Signed
/// zeros as libm (atan2(±0, −0) = ±π, atan2(±0, +0) = ±0); NaN stays NaN; infinite arguments are
/// not handled (not needed: the arguments are unit-vector components).
#[inline(always)]
pub fn atan2(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = if ay > ax { (ax, ay) } else { (ay, ax) };
    // 0/0 (the origin) is 0, as libm's; a NaN argument stays NaN (`hi` is 0 or NaN in the else).
    let a = if hi > 0.0 { lo / hi } else { lo + hi };
    // tan(π/8): above it, atan a = π/4 + atan((a − 1)/(a + 1)), with the argument in [−0.172, 0.172].
    let reduce = a > 0.414_213_57;
    let t = if reduce { (a - 1.0) / (a + 1.0) } else { a };
    let z = t * t;
    let p = (((8.053_744_5e-2 * z - 1.387_768_6e-1) * z + 1.997_771_1e-1) * z - 3.333_295e-1) * z * t + t;
    let mut r = if reduce { FRAC_PI_4 + p } else { p };
    if ay > ax {
        r = FRAC_PI_2 - r;
    }
    if x.is_sign_negative() {
        r = PI - r;
    }
    r.copysign(y)
}

/// `v − floor(v)` without a libm call (the baseline x86-64 has no `roundss`): the same value for
/// every input (NaN and infinities give NaN; up to the sign of a zero result).
#[inline(always)]
pub fn fract(v: f32) -> f32 {
    if !(v.abs() < 8_388_608.0) {
        // Integers already (2^23 and above): 0; not finite: NaN.
        return if v.is_finite() { 0.0 } else { f32::NAN };
    }
    let i = v as i32 as f32;
    v - if i > v { i - 1.0 } else { i }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f32, b: f64) -> f64 {
        let b32 = b as f32;
        ((a as f64 - b) / (b32.next_up() as f64 - b32 as f64).abs()).abs()
    }

    #[test]
    fn exp3_within_two_ulp() {
        // Transmittances use −σt·t (≤ 0); cover the whole finite range, each lane.
        let mut worst = 0.0f64;
        let n = 400_000;
        for i in 0..=n {
            let x = -87.3 + (88.7 + 87.3) * i as f32 / n as f32;
            let v = exp3(Vec3::new(x, -x.abs(), 0.5 * x));
            for (got, arg) in [(v.x, x), (v.y, -x.abs()), (v.z, 0.5 * x)] {
                if arg < -87.336_54 {
                    assert_eq!(got, 0.0, "exp3({arg}) flushes to 0");
                    continue;
                }
                worst = worst.max(ulps(got, (arg as f64).exp()));
            }
        }
        assert!(worst <= 2.0, "exp3: worst error {worst} ulp");
        let special = exp3(Vec3::new(0.0, -100.0, f32::NEG_INFINITY));
        assert_eq!(special, Vec3::new(1.0, 0.0, 0.0));
        let special = exp3(Vec3::new(100.0, f32::NAN, f32::INFINITY));
        assert!(special.x == f32::INFINITY && special.y.is_nan() && special.z == f32::INFINITY);
    }

    #[test]
    fn sincos_2pi_accuracy() {
        let mut worst = 0.0f64;
        let n = 1 << 20;
        for i in -(n / 8)..=n {
            let u = i as f32 / n as f32;
            let (s, c) = sincos_2pi(u);
            let phi = 2.0 * std::f64::consts::PI * u as f64;
            worst = worst.max((s as f64 - phi.sin()).abs()).max((c as f64 - phi.cos()).abs());
        }
        assert!(worst < 2e-7, "sincos_2pi: worst absolute error {worst}");
    }

    /// The polynomial `acos` agrees with libm's within 2 ulp of π (on a fine grid and the ends).
    #[test]
    fn acos_matches_libm() {
        let n = 200_000;
        let mut worst = 0.0f32;
        for i in 0..=n {
            let x = -1.0 + 2.0 * i as f32 / n as f32;
            worst = worst.max((acos(x) - x.acos()).abs());
        }
        assert!(worst <= 2.0 * f32::EPSILON * std::f32::consts::PI, "max error {worst}");
        assert_eq!(acos(1.0), 0.0);
        assert_eq!(acos(-1.0), std::f32::consts::PI);
        assert!(acos(f32::NAN).is_nan());
    }

    /// The polynomial `atan2` agrees with f64 `atan2` within 3e-7 on every direction of a fine
    /// circle (at several radii) and on the axes' signed zeros as libm.
    #[test]
    fn atan2_accuracy() {
        let n = 1 << 20;
        let mut worst = 0.0f64;
        for i in 0..n {
            let phi = 2.0 * std::f64::consts::PI * (i as f64 + 0.5) / n as f64;
            for r in [1.0f64, 1e-3, 37.0] {
                let (y, x) = ((r * phi.sin()) as f32, (r * phi.cos()) as f32);
                worst = worst.max((atan2(y, x) as f64 - (y as f64).atan2(x as f64)).abs());
            }
        }
        assert!(worst <= 3e-7, "atan2: worst absolute error {worst}");
        for (y, x) in [
            (0.0f32, 0.0f32),
            (-0.0, 0.0),
            (0.0, -0.0),
            (-0.0, -0.0),
            (0.0, 1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (-1.0, -0.0),
        ] {
            assert_eq!(atan2(y, x).to_bits(), y.atan2(x).to_bits(), "atan2({y}, {x})");
        }
        assert!(atan2(f32::NAN, 1.0).is_nan() && atan2(1.0, f32::NAN).is_nan());
    }

    #[test]
    fn fract_is_v_minus_floor() {
        for i in -40_000..40_000 {
            let v = i as f32 * 0.000_731 + 1e-3;
            assert_eq!(fract(v), v - v.floor(), "fract({v})");
        }
        for v in [0.0f32, 1.0, -1.0, -1e-30, 0.999_999_94, -0.999_999_94, 8_388_607.5, -8_388_607.5, 1e10, -3e9] {
            assert_eq!(fract(v), v - v.floor(), "fract({v})");
        }
        assert!(fract(f32::NAN).is_nan() && fract(f32::INFINITY).is_nan());
    }
}

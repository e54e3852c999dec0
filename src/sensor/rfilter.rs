//! Reconstruction filters (`<rfilter>`): how much a sample at a film position contributes to each
//! nearby pixel. Filters are separable: a pixel whose centre lies at offset `(dx, dy)` from the
//! sample gets the weight `eval(dx) · eval(dy)`.
//!
//! | type       | parameters                     | radius       |
//! |------------|--------------------------------|--------------|
//! | `gaussian` | `stddev` (float, default 0.5)  | 4 · `stddev` |
//! | `box`      | none                           | 0.5          |
//! | `tent`     | `radius` (float, default 1)    | `radius`     |
//!
//! The Gaussian is Mitsuba's windowed Gaussian as Mitsuba 3.9 evaluates it on the CPU: a degree-9
//! Remez fit of `exp(-x/2)` in `x²/stddev²`, shifted so that it reaches 0 at the radius and
//! clamped at 0 (so `eval(0)` is 0.99925, not 1). The box filter is 1 on `[-0.5, 0.5)`.
//!
//! ```xml
//! <film type="hdrfilm">
//!     <rfilter type="gaussian">
//!         <float name="stddev" value="0.25"/>
//!     </rfilter>
//! </film>
//! ```

use crate::scene::desc::ObjectDesc;
use crate::scene::error::{Error, Result};

/// A reconstruction filter with Mitsuba's defaults: gaussian stddev 0.5 (radius 2), tent radius 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RFilter {
    Gaussian { stddev: f32 },
    Box,
    Tent { radius: f32 },
}

impl Default for RFilter {
    /// Mitsuba's default filter: a Gaussian with standard deviation 0.5 pixels.
    fn default() -> Self {
        RFilter::Gaussian { stddev: 0.5 }
    }
}

/// Remez fit of `exp(-x/2)` on `[0, 16]`, lowest degree first (Mitsuba's `gaussian.cpp`).
const GAUSSIAN_REMEZ: [f64; 10] = [
    9.992604880e-1,
    -4.977025247e-1,
    1.222248550e-1,
    -1.932406282e-2,
    2.136713061e-3,
    -1.679873860e-4,
    9.202145248e-6,
    -3.329417433e-7,
    7.128382794e-9,
    -6.821193280e-11,
];

impl RFilter {
    /// Parse an `<rfilter>` object (`gaussian`, `box` or `tent`).
    pub fn from_desc(obj: &ObjectDesc) -> Result<RFilter> {
        let props = &obj.props;
        let filter = match obj.plugin.as_str() {
            "gaussian" => {
                let stddev = props.float("stddev", 0.5)?;
                if !(stddev > 0.0 && stddev.is_finite()) {
                    return Err(props.error("stddev", format!("gaussian \"stddev\" must be positive, got {stddev}")));
                }
                RFilter::Gaussian { stddev }
            }
            "box" => RFilter::Box,
            "tent" => {
                let radius = props.float("radius", 1.0)?;
                if !(radius > 0.0 && radius.is_finite()) {
                    return Err(props.error("radius", format!("tent \"radius\" must be positive, got {radius}")));
                }
                RFilter::Tent { radius }
            }
            other => {
                return Err(Error::at(
                    &obj.pos,
                    format!("rfilter type \"{other}\" is not supported (supported: gaussian, box, tent)"),
                ))
            }
        };
        props.finish()?;
        Ok(filter)
    }

    /// Half-width of the filter support in pixels.
    pub fn radius(&self) -> f32 {
        match *self {
            RFilter::Gaussian { stddev } => 4.0 * stddev,
            RFilter::Box => 0.5,
            RFilter::Tent { radius } => radius,
        }
    }

    /// Pixels a block needs around its interior so that every pixel a sample inside the interior
    /// touches is stored: `ceil(radius - 0.5)` (0 for the box filter).
    pub fn border_size(&self) -> u32 {
        (self.radius() - 0.5).ceil().max(0.0) as u32
    }

    /// Mitsuba treats any filter with radius exactly 0.5 as a box filter when splatting: the
    /// sample goes to the one pixel that contains it, with weight 1.
    pub fn is_box_filter(&self) -> bool {
        self.radius() == 0.5
    }

    /// The filter value at offset `x` (pixels) from the sample, exactly as Mitsuba's `eval`.
    /// Builds the kernel on each call; hot loops should keep a [`FilterKernel`] instead.
    pub fn eval(&self, x: f32) -> f32 {
        FilterKernel::exact(self).eval(x)
    }
}

/// A filter prepared for fast evaluation (the Gaussian's polynomial coefficients precomputed).
#[derive(Clone, Copy, Debug)]
pub enum FilterKernel {
    /// One pixel, weight 1 (any filter of radius 0.5, as in Mitsuba's `ImageBlock`).
    Box,
    Gaussian {
        coeff: [f32; 10],
        radius: f32,
    },
    Tent {
        inv_radius: f32,
        radius: f32,
    },
}

impl FilterKernel {
    /// The kernel `ImageBlock` splats with: Mitsuba's semantics, so radius 0.5 becomes a box.
    pub fn for_splatting(filter: &RFilter) -> FilterKernel {
        if filter.is_box_filter() {
            FilterKernel::Box
        } else {
            FilterKernel::exact(filter)
        }
    }

    /// The kernel that evaluates exactly `filter.eval`.
    pub fn exact(filter: &RFilter) -> FilterKernel {
        match *filter {
            RFilter::Gaussian { stddev } => {
                FilterKernel::Gaussian { coeff: gaussian_coeffs(stddev), radius: 4.0 * stddev }
            }
            RFilter::Box => FilterKernel::Box,
            RFilter::Tent { radius } => FilterKernel::Tent { inv_radius: 1.0 / radius, radius },
        }
    }

    #[inline]
    pub fn radius(&self) -> f32 {
        match *self {
            FilterKernel::Box => 0.5,
            FilterKernel::Gaussian { radius, .. } | FilterKernel::Tent { radius, .. } => radius,
        }
    }

    #[inline]
    pub fn eval(&self, x: f32) -> f32 {
        match self {
            FilterKernel::Box => {
                if (-0.5..0.5).contains(&x) {
                    1.0
                } else {
                    0.0
                }
            }
            FilterKernel::Gaussian { coeff, .. } => gaussian(x, coeff),
            FilterKernel::Tent { inv_radius, .. } => (1.0 - (x * inv_radius).abs()).max(0.0),
        }
    }
}

impl FilterKernel {
    /// `out[i] = eval((first + i) as f32 + 0.5 - pos)`: the weights of consecutive pixels, whose
    /// centres are at `first + i + 0.5`, for a sample at `pos` (exactly as `eval` per pixel).
    #[inline]
    pub fn eval_taps(&self, first: i64, pos: f32, out: &mut [f32]) {
        match self {
            FilterKernel::Gaussian { coeff, .. } => {
                #[cfg(target_arch = "x86_64")]
                if std::arch::is_x86_feature_detected!("fma") {
                    // SAFETY: the CPU supports FMA (checked just above).
                    unsafe { gaussian_taps_fma(first, pos, coeff, out) };
                    return;
                }
                for (i, o) in out.iter_mut().enumerate() {
                    *o = estrin10((first + i as i64) as f32 + 0.5 - pos, coeff, fmadd).max(0.0);
                }
            }
            _ => {
                for (i, o) in out.iter_mut().enumerate() {
                    *o = self.eval((first + i as i64) as f32 + 0.5 - pos);
                }
            }
        }
    }
}

impl FilterKernel {
    /// The taps of both axes at once: lanes 0..8 are `eval_taps(first_x, pos_x)` for 8 pixels,
    /// lanes 8..16 `eval_taps(first_y, pos_y)` (same bits; one vectorised evaluation per sample).
    #[inline]
    pub fn eval_taps_xy(&self, (first_x, pos_x): (i64, f32), (first_y, pos_y): (i64, f32)) -> [f32; 16] {
        let mut out = [0.0f32; 16];
        if let FilterKernel::Gaussian { coeff, .. } = self {
            #[cfg(target_arch = "x86_64")]
            if std::arch::is_x86_feature_detected!("fma") {
                // SAFETY: the CPU supports FMA (checked just above).
                unsafe { gaussian_taps_xy_fma(first_x as f32, pos_x, first_y as f32, pos_y, coeff, &mut out) };
                return out;
            }
        }
        self.eval_taps(first_x, pos_x, &mut out[..8]);
        self.eval_taps(first_y, pos_y, &mut out[8..]);
        out
    }
}

/// [`gaussian_taps_fma`] for 8 taps of each axis, a fixed width the compiler vectorises whole.
/// `first_*` are pixel indices (exact in `f32` on any film), so `(first + i) + 0.5 - pos` is
/// computed as `eval_taps` does.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
fn gaussian_taps_xy_fma(first_x: f32, pos_x: f32, first_y: f32, pos_y: f32, coeff: &[f32; 10], out: &mut [f32; 16]) {
    for (i, o) in out.iter_mut().enumerate() {
        let (first, pos) = if i < 8 { (first_x, pos_x) } else { (first_y, pos_y) };
        *o = estrin10_fma((first + (i & 7) as f32) + 0.5 - pos, coeff).max(0.0);
    }
}

/// Coefficients of the Gaussian's polynomial in `x²` for a standard deviation, with the constant
/// term shifted so that the polynomial is 0 at the radius `4·stddev` (as Mitsuba computes them).
fn gaussian_coeffs(stddev: f32) -> [f32; 10] {
    let mut coeff = [0.0f32; 10];
    let inv_var = 1.0 / (stddev as f64 * stddev as f64);
    let mut scale = 1.0f64;
    for (c, remez) in coeff.iter_mut().zip(GAUSSIAN_REMEZ) {
        *c = (remez * scale) as f32;
        scale *= inv_var;
    }
    let radius = 4.0 * stddev;
    // Once per filter: the correctly rounded (if slow) fused multiply-add, as Mitsuba's scalar code.
    coeff[0] -= estrin10(radius, &coeff, f32::mul_add);
    coeff
}

/// The Gaussian at offset `x`: the polynomial in `x²`, clamped at 0. With hardware FMA (checked at
/// run time; std caches the answer) the fused multiply-adds are the CPU's, as in Mitsuba.
#[inline]
fn gaussian(x: f32, coeff: &[f32; 10]) -> f32 {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports FMA (checked just above).
        return unsafe { estrin10_fma(x, coeff) }.max(0.0);
    }
    estrin10(x, coeff, fmadd).max(0.0)
}

/// `gaussian` at `(first + i) + 0.5 - pos` for each `out[i]`, with hardware fused multiply-adds
/// (the compiler vectorizes across taps).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
fn gaussian_taps_fma(first: i64, pos: f32, coeff: &[f32; 10], out: &mut [f32]) {
    for (i, o) in out.iter_mut().enumerate() {
        *o = estrin10_fma((first + i as i64) as f32 + 0.5 - pos, coeff).max(0.0);
    }
}

/// The Gaussian's polynomial ([`estrin10`] with fused multiply-adds) in 8 lanes, not clamped:
/// lane by lane the bits of [`estrin10_fma`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,fma")]
#[inline]
pub(crate) fn gaussian8_fma(x: std::arch::x86_64::__m256, c: &[f32; 10]) -> std::arch::x86_64::__m256 {
    use std::arch::x86_64::*;
    let k = |i: usize| _mm256_set1_ps(c[i]);
    let x = _mm256_mul_ps(x, x);
    let x2 = _mm256_mul_ps(x, x);
    let x4 = _mm256_mul_ps(x2, x2);
    let x8 = _mm256_mul_ps(x4, x4);
    let a0 = _mm256_fmadd_ps(x, k(1), k(0));
    let a1 = _mm256_fmadd_ps(x, k(3), k(2));
    let a2 = _mm256_fmadd_ps(x, k(5), k(4));
    let a3 = _mm256_fmadd_ps(x, k(7), k(6));
    let a4 = _mm256_fmadd_ps(x, k(9), k(8));
    let b0 = _mm256_fmadd_ps(x2, a1, a0);
    let b1 = _mm256_fmadd_ps(x2, a3, a2);
    let c0 = _mm256_fmadd_ps(x4, b1, b0);
    _mm256_fmadd_ps(x8, a4, c0)
}

/// [`estrin10`] with the CPU's fused multiply-add (one rounding, exactly Dr.Jit's `fmadd`).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "fma")]
#[inline]
fn estrin10_fma(x: f32, coeff: &[f32; 10]) -> f32 {
    estrin10(x, coeff, f32::mul_add)
}

/// `a·b + c` rounded to f64 and then to f32: Dr.Jit's `fmadd` up to a double rounding in rare ties
/// (the f64 product of two f32 is exact), for CPUs without FMA (where `f32::mul_add` is a slow
/// library call). Near the radius the Gaussian polynomial cancels heavily, and rounding the
/// product separately would change `eval(1.9)` by 1.5%.
#[inline]
fn fmadd(a: f32, b: f32, c: f32) -> f32 {
    (a as f64 * b as f64 + c as f64) as f32
}

/// Estrin's scheme for the degree-9 polynomial in `x²`, in the order of Dr.Jit's `estrin_impl`,
/// with `fma(a, b, c) = a·b + c`.
#[inline(always)]
fn estrin10(x: f32, c: &[f32; 10], fma: impl Fn(f32, f32, f32) -> f32) -> f32 {
    let x = x * x;
    let x2 = x * x;
    let x4 = x2 * x2;
    let x8 = x4 * x4;
    let a0 = fma(x, c[1], c[0]);
    let a1 = fma(x, c[3], c[2]);
    let a2 = fma(x, c[5], c[4]);
    let a3 = fma(x, c[7], c[6]);
    let a4 = fma(x, c[9], c[8]);
    let b0 = fma(x2, a1, a0);
    let b1 = fma(x2, a3, a2);
    let c0 = fma(x4, b1, b0);
    fma(x8, a4, c0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gaussian_close_to_exp_and_zero_at_radius() {
        let f = RFilter::default();
        assert_eq!(f.radius(), 2.0);
        assert_eq!(f.border_size(), 2);
        for i in 0..40 {
            let x = i as f32 * 0.05;
            let exact = (-x * x / (2.0 * 0.25)).exp() - (-8.0f32).exp();
            assert!((f.eval(x) - exact).abs() < 2e-3, "x={x}: {} vs {exact}", f.eval(x));
        }
        assert!(f.eval(2.0).abs() < 1e-5);
        assert_eq!(f.eval(2.5), 0.0);
    }

    #[test]
    fn box_and_tent() {
        assert_eq!(RFilter::Box.eval(-0.5), 1.0);
        assert_eq!(RFilter::Box.eval(0.5), 0.0);
        assert_eq!(RFilter::Box.border_size(), 0);
        let t = RFilter::Tent { radius: 1.5 };
        assert!((t.eval(0.75) - 0.5).abs() < 1e-6);
        assert_eq!(t.eval(1.6), 0.0);
        assert_eq!(t.border_size(), 1);
        assert!(RFilter::Tent { radius: 0.5 }.is_box_filter());
    }

    /// Bit patterns of Mitsuba 3.9's `gaussian` (stddev 0.5) `eval`, from Python `scalar_rgb`;
    /// both our evaluation paths (hardware FMA where available, f64 emulation) must give them.
    #[test]
    fn gaussian_bits_match_mitsuba() {
        let want: [(f32, u32); 7] = [
            (0.0, 1065340585),
            (0.3, 1062585778),
            (0.77, 1050424133),
            (1.2, 1030002534),
            (1.5, 1009795892),
            (1.9, 969628831),
            (1.99, 939095241),
        ];
        let FilterKernel::Gaussian { coeff, .. } = FilterKernel::exact(&RFilter::default()) else { unreachable!() };
        for (x, bits) in want {
            assert_eq!(RFilter::default().eval(x).to_bits(), bits, "eval({x})");
            assert_eq!(estrin10(x, &coeff, fmadd).max(0.0).to_bits(), bits, "f64 path at {x}");
            let mut out = [0.0];
            FilterKernel::exact(&RFilter::default()).eval_taps(0, 0.5 - x, &mut out);
            assert_eq!(out[0].to_bits(), bits, "eval_taps at {x}");
            let taps = FilterKernel::exact(&RFilter::default()).eval_taps_xy((0, 0.5 - x), (-1, 0.5 - x));
            assert_eq!(taps[0].to_bits(), bits, "eval_taps_xy (x) at {x}");
            assert_eq!(taps[9].to_bits(), bits, "eval_taps_xy (y) at {x}");
        }
    }
}

//! Environment map emitter (`envmap`): radiance arriving from infinitely far away, read from a
//! latitude-longitude image (OpenEXR for high dynamic range, or PNG).
//!
//! | parameter          | type      | meaning |
//! |--------------------|-----------|---------|
//! | `filename`         | string    | the image (at least 2 × 3 pixels), resolved against the scene's folders |
//! | `scale`            | float     | factor applied to the radiance values (default 1) |
//! | `to_world`         | transform | rotation (or mirroring) from the map's frame to the world (default identity) |
//! | `mis_compensation` | boolean   | sample less where the map is darker than average (Karlík et al. 2019), for use with MIS only (default false) |
//!
//! Conventions (Mitsuba's): a world direction ω (pointing out to the environment) maps to the
//! local d = to_world⁻¹·ω and to u = atan2(d.x, −d.z)/2π, v = acos(d.y)/π. Row 0 of the image is
//! the +Y pole and the +Z direction is the centre column. Lookups are bilinear, with the image
//! shifted half a texel horizontally (x = u·W − ½, wrapping around) and its rows spanning the poles
//! exactly (y = v·(H − 1)).
//!
//! Sampling picks a cell of the bilinear grid (between four texel centres) with probability
//! proportional to the mean luminance of its corners times its solid angle, then a direction
//! uniformly in solid angle inside the cell. The density is therefore piecewise constant in solid
//! angle, with no 1/sin θ singularity at the poles. (Mitsuba uses a bilinear warp instead; the
//! values seen by rays agree exactly, only the noise differs.)
//!
//! ```xml
//! <emitter type="envmap">
//!     <string name="filename" value="textures/sky.exr"/>
//!     <float name="scale" value="2"/>
//!     <transform name="to_world">
//!         <rotate y="1" angle="90"/>
//!     </transform>
//! </emitter>
//! ```

use super::distribution::Distribution2D;
use super::{check_transform, BoundingSphere};
use crate::color::{luminance, Spectrum};
use crate::interaction::DirectionSample;
use crate::math::{fast, safe_sqrt, Mat4, Vec2, Vec3, INV_PI, INV_TWO_PI, PI};
use crate::scene::desc::Props;
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};
use crate::texture::bitmap::{read_filename_image, required_filename};
use std::sync::Arc;

#[derive(Clone)]
pub struct EnvironmentEmitter {
    /// The file name as given in the scene.
    pub filename: String,
    /// Image resolution (without the padding column).
    pub width: usize,
    pub height: usize,
    /// `(width + 1) × height` texels, row 0 at the +Y pole; the last column repeats the first.
    /// Stored as 16-byte `Vec3A` so the bilinear lookup runs in SIMD lanes (the same per-channel
    /// products and sums as on `Spectrum`).
    data: Arc<[glam::Vec3A]>,
    pub scale: f32,
    pub to_world: Mat4,
    pub to_local: Mat4,
    /// Over the `width × (height − 1)` cells of the bilinear grid.
    distr: Arc<Distribution2D>,
    /// cos θ of each row of texel centres (`height` entries, 1 down to −1).
    cos_theta: Arc<[f32]>,
    /// Solid angle of the cells in each row of the sampling grid (`height − 1` entries:
    /// [`EnvironmentEmitter::cell_solid_angle`] computed once, with the same operations).
    omega: Arc<[f32]>,
    /// `width` and `height − 1` as `f32`, and half a texel in u (`0.5 / width`): constants of
    /// every lookup, converted and divided once.
    width_f: f32,
    rows_f: f32,
    half_texel: f32,
    pub bsphere: BoundingSphere,
}

impl EnvironmentEmitter {
    pub fn from_props(props: &Props, resolver: &FileResolver) -> Result<EnvironmentEmitter> {
        let filename = required_filename(props, "envmap")?;
        let image = read_filename_image(props, &filename, resolver, true)?;

        let scale = props.float("scale", 1.0)?;
        if !(scale.is_finite() && scale >= 0.0) {
            return Err(props.error("scale", "envmap: \"scale\" must be finite and non-negative"));
        }
        let brightest = image.pixels.iter().fold(0.0f32, |m, p| m.max(p.abs().max_element()));
        if !(scale * brightest <= crate::scene::desc::MAX_EMISSION) {
            let msg = format!(
                "envmap: scale ({scale:e}) × the brightest pixel ({brightest}) is beyond {:e}",
                crate::scene::desc::MAX_EMISSION
            );
            return Err(props.error("scale", msg));
        }
        let to_world = props.transform("to_world")?;
        check_transform(props, "to_world", &to_world)?;
        if !is_orthogonal(&to_world) {
            return Err(props.error(
                "to_world",
                "envmap: \"to_world\" must be a rotation or mirroring (no scale or shear), as directions are not renormalised",
            ));
        }
        let mis_compensation = props.bool("mis_compensation", false)?;
        Self::new(filename, &image.file, image.width, image.height, &image.pixels, scale, to_world, mis_compensation)
            .map_err(|e| Error::at(&image.pos, e.msg))
    }

    /// Build from `width × height` linear RGB pixels (row 0 = +Y pole). `file` names the source
    /// in error messages. `to_world` must be orthogonal.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        filename: String,
        file: &str,
        width: usize,
        height: usize,
        pixels: &[Spectrum],
        scale: f32,
        to_world: Mat4,
        mis_compensation: bool,
    ) -> Result<EnvironmentEmitter> {
        if width < 2 || height < 3 {
            return Err(Error::msg(format!(
                "{file}: the environment map resolution must be at least 2x3 pixels (it is {width}x{height})"
            )));
        }
        if pixels.len() != width * height {
            return Err(Error::msg(format!("{file}: expected {} pixels, got {}", width * height, pixels.len())));
        }
        for (i, p) in pixels.iter().enumerate() {
            if !p.is_finite() || p.min_element() < 0.0 {
                return Err(Error::msg(format!(
                    "{file}: pixel ({}, {}) has the value ({}, {}, {}); environment maps must be finite and non-negative",
                    i % width,
                    i / width,
                    p.x,
                    p.y,
                    p.z
                )));
            }
        }
        let w1 = width + 1;
        // Padded copy: the last column repeats the first (periodic in u).
        let mut data = Vec::with_capacity(w1 * height);
        for row in pixels.chunks_exact(width) {
            data.extend_from_slice(row);
            data.push(row[0]);
        }

        // Per-texel luminance, optionally offset by its mean (MIS compensation).
        let mut lum: Vec<f32> = data.iter().map(|&c| luminance(c)).collect();
        if mis_compensation {
            let (mut sum, mut min) = (0.0f64, f32::INFINITY);
            for row in pixels.chunks_exact(width) {
                for &c in row {
                    let l = luminance(c);
                    sum += l as f64;
                    min = min.min(l);
                }
            }
            let mean = (sum / (width * height) as f64) as f32;
            if mean - min > 0.01 * mean {
                lum.iter_mut().for_each(|l| *l = (*l - mean).max(0.0));
            }
        }

        let cos_theta: Vec<f32> = (0..height).map(|j| (j as f32 * PI / (height - 1) as f32).cos()).collect();
        let mut weights = Vec::with_capacity(width * (height - 1));
        for j in 0..height - 1 {
            let band = (cos_theta[j] - cos_theta[j + 1]).max(0.0);
            for i in 0..width {
                let corners = lum[j * w1 + i] + lum[j * w1 + i + 1] + lum[(j + 1) * w1 + i] + lum[(j + 1) * w1 + i + 1];
                weights.push(0.25 * corners * band);
            }
        }
        let distr = Distribution2D::new(&weights, width, height - 1);
        let to_local = to_world.inverse();
        let width_f = width as f32;
        let omega: Vec<f32> = (0..height - 1).map(|j| 2.0 * PI / width_f * (cos_theta[j] - cos_theta[j + 1])).collect();
        Ok(EnvironmentEmitter {
            filename,
            width,
            height,
            data: data.iter().map(|&c| glam::Vec3A::from(c)).collect(),
            scale,
            to_world,
            to_local,
            distr: Arc::new(distr),
            cos_theta: cos_theta.into(),
            omega: omega.into(),
            width_f,
            rows_f: (height - 1) as f32,
            half_texel: 0.5 / width_f,
            bsphere: BoundingSphere::default(),
        })
    }

    /// Half a texel in u: the shift between the map's texel centres and the sampling grid.
    #[inline]
    fn half_texel(&self) -> f32 {
        self.half_texel
    }

    /// Mitsuba's latitude-longitude coordinates of a local direction.
    /// (Polynomial atan2 and acos, within 3e-7 and 2 ulp of π: `math::fast`.)
    #[inline]
    pub fn direction_to_uv(d: Vec3) -> Vec2 {
        Vec2::new(fast::atan2(d.x, -d.z) * INV_TWO_PI, fast::acos(d.y) * INV_PI)
    }

    /// Bilinear lookup at Mitsuba's uv (with `scale` applied).
    #[inline]
    pub fn eval_uv(&self, uv: Vec2) -> Spectrum {
        let (w, h) = (self.width, self.height);
        let uv = Vec2::new(fract_unit(uv.x - self.half_texel()), fract_unit(uv.y));
        let x = uv.x * self.width_f;
        let y = uv.y * self.rows_f;
        // Float → integer casts saturate (NaN → 0), so the indices stay in range; through u32
        // (a cheaper conversion than to usize, the same index: the map is narrower than 2^32).
        let px = (x as u32 as usize).min(w - 1);
        let py = (y as u32 as usize).min(h - 2);
        let (w1x, w1y) = (x - px as f32, y - py as f32);
        let (w0x, w0y) = (1.0 - w1x, 1.0 - w1y);
        let stride = w + 1;
        let i = py * stride + px;
        let v00 = self.data[i];
        let v10 = self.data[i + 1];
        let v01 = self.data[i + stride];
        let v11 = self.data[i + stride + 1];
        let v0 = w0x * v00 + w1x * v10;
        let v1 = w0x * v01 + w1x * v11;
        Spectrum::from((w0y * v0 + w1y * v1) * self.scale)
    }

    /// Radiance arriving from world direction `d` (pointing away from the scene).
    #[inline]
    pub fn eval(&self, d: Vec3) -> Spectrum {
        let local = self.to_local.transform_vector3(d).normalize_or_zero();
        self.eval_uv(Self::direction_to_uv(local))
    }

    /// Solid angle of the cells in row `j` of the sampling grid.
    #[inline]
    fn cell_solid_angle(&self, j: usize) -> f32 {
        self.omega[j]
    }

    /// The sampling cell that contains local direction `d`.
    #[inline]
    fn cell_of(&self, uv: Vec2) -> (usize, usize) {
        let u = uv.x - self.half_texel();
        let x = fract_unit(u) * self.width_f;
        let y = uv.y.clamp(0.0, 1.0) * self.rows_f;
        ((x as u32 as usize).min(self.width - 1), (y as u32 as usize).min(self.height - 2))
    }

    /// Sample a direction by luminance; weight = radiance / pdf (solid angle).
    pub fn sample_direction(&self, ref_p: Vec3, sample: Vec2) -> (DirectionSample, Spectrum) {
        let Some((i, j, r, p_cell)) = self.distr.sample(sample) else {
            return (DirectionSample::default(), Spectrum::ZERO);
        };
        // Uniform in solid angle within the cell: u linear, cos θ linear.
        let mut u = (i as f32 + 0.5 + r.x) / self.width_f;
        if u >= 1.0 {
            u -= 1.0;
        }
        let cos_t = self.cos_theta[j] + (self.cos_theta[j + 1] - self.cos_theta[j]) * r.y;
        let sin_t = safe_sqrt(1.0 - cos_t * cos_t);
        let (sin_p, cos_p) = fast::sincos_2pi(u);
        let local = Vec3::new(sin_p * sin_t, cos_t, -cos_p * sin_t);
        let pdf = p_cell / self.cell_solid_angle(j);
        // Positive and finite (one comparison each way: cheaper than `is_finite`).
        if !(pdf > 0.0 && pdf < f32::INFINITY) {
            return (DirectionSample::default(), Spectrum::ZERO);
        }
        let uv = Vec2::new(u, fast::acos(cos_t) * INV_PI);
        let d = self.to_world.transform_vector3(local).normalize();
        let ds = DirectionSample {
            p: ref_p + d * self.bsphere.far_distance(ref_p),
            n: -d,
            uv,
            d,
            dist: f32::INFINITY,
            pdf,
            delta: false,
            emitter: 0,
        };
        (ds, self.eval_uv(uv) / pdf)
    }

    /// Solid-angle density of [`EnvironmentEmitter::sample_direction`] for world direction `d`.
    #[inline]
    pub fn pdf_direction(&self, d: Vec3) -> f32 {
        let local = self.to_local.transform_vector3(d).normalize_or_zero();
        self.pdf_uv(Self::direction_to_uv(local))
    }

    /// [`EnvironmentEmitter::eval`] and, with `with_pdf`, [`EnvironmentEmitter::pdf_direction`]
    /// (else 0) of world direction `d`, mapping `d` to uv once (a ray that escapes after a
    /// non-delta scattering needs both). The same values as the two calls.
    #[inline(always)]
    pub fn eval_pdf(&self, d: Vec3, with_pdf: bool) -> (Spectrum, f32) {
        let local = self.to_local.transform_vector3(d).normalize_or_zero();
        let uv = Self::direction_to_uv(local);
        (self.eval_uv(uv), if with_pdf { self.pdf_uv(uv) } else { 0.0 })
    }

    /// [`EnvironmentEmitter::pdf_direction`] at Mitsuba's uv of the local direction.
    #[inline(always)]
    fn pdf_uv(&self, uv: Vec2) -> f32 {
        let (i, j) = self.cell_of(uv);
        let omega = self.cell_solid_angle(j);
        if omega > 0.0 {
            self.distr.pmf(i, j) / omega
        } else {
            0.0
        }
    }
}

impl std::fmt::Debug for EnvironmentEmitter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("EnvironmentEmitter")
            .field("filename", &self.filename)
            .field("width", &self.width)
            .field("height", &self.height)
            .field("scale", &self.scale)
            .field("to_world", &self.to_world)
            .field("bsphere", &self.bsphere)
            .finish_non_exhaustive()
    }
}

/// [`fast::fract`] with its common case first: a value in [0, 1) is its own fractional part
/// (`v − 0`, the same bits, −0 included), so only other values take the general path. The
/// lookups' u and v are in [0, 1) nearly always.
#[inline(always)]
fn fract_unit(v: f32) -> f32 {
    if (0.0..1.0).contains(&v) {
        v
    } else {
        fast::fract(v)
    }
}

/// True when the linear part of `m` is orthogonal (a rotation, possibly with mirroring).
fn is_orthogonal(m: &Mat4) -> bool {
    let a = crate::math::Mat3::from_mat4(*m);
    let g = a.transpose() * a;
    let e = g - crate::math::Mat3::IDENTITY;
    e.x_axis.abs().max_element().max(e.y_axis.abs().max_element()).max(e.z_axis.abs().max_element()) < 1e-3
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient_map(w: usize, h: usize) -> Vec<Spectrum> {
        (0..w * h).map(|i| Spectrum::new((i % w) as f32 + 1.0, (i / w) as f32 + 0.5, 1.0)).collect()
    }

    #[test]
    fn uv_conventions() {
        // +Z is the centre column, +Y the top row.
        let uv = EnvironmentEmitter::direction_to_uv(Vec3::Z);
        assert!((uv.x.abs() - 0.5).abs() < 1e-6 && (uv.y - 0.5).abs() < 1e-6);
        assert!(EnvironmentEmitter::direction_to_uv(Vec3::Y).y.abs() < 1e-6);
        let uv = EnvironmentEmitter::direction_to_uv(Vec3::X);
        assert!((uv.x - 0.25).abs() < 1e-6);
    }

    #[test]
    fn texel_centres_are_exact() {
        let (w, h) = (8, 5);
        let px = gradient_map(w, h);
        let env = EnvironmentEmitter::new("t".into(), "t", w, h, &px, 2.0, Mat4::IDENTITY, false).unwrap();
        for y in 0..h {
            for x in 0..w {
                // (v = 1 exactly wraps to the top row, as in Mitsuba: stay just inside.)
                let v = (y as f32 / (h - 1) as f32).min(1.0 - 1e-7);
                let uv = Vec2::new((x as f32 + 0.5) / w as f32, v);
                let v = env.eval_uv(uv);
                assert!((v - 2.0 * px[y * w + x]).abs().max_element() < 1e-4, "({x}, {y}): {v}");
            }
        }
    }

    #[test]
    fn errors_on_bad_pixels_and_sizes() {
        let mut px = gradient_map(4, 3);
        px[5].y = f32::NAN;
        let e = EnvironmentEmitter::new("t".into(), "t.exr", 4, 3, &px, 1.0, Mat4::IDENTITY, false).unwrap_err();
        assert!(e.msg.contains("pixel (1, 1)"), "{}", e.msg);
        px[5].y = -1.0;
        assert!(EnvironmentEmitter::new("t".into(), "t", 4, 3, &px, 1.0, Mat4::IDENTITY, false).is_err());
        let px = gradient_map(4, 2);
        let e = EnvironmentEmitter::new("t".into(), "t", 4, 2, &px, 1.0, Mat4::IDENTITY, false).unwrap_err();
        assert!(e.msg.contains("at least 2x3"), "{}", e.msg);
    }

    #[test]
    fn black_map_fails_to_sample() {
        let px = vec![Spectrum::ZERO; 12];
        let env = EnvironmentEmitter::new("t".into(), "t", 4, 3, &px, 1.0, Mat4::IDENTITY, false).unwrap();
        let (ds, w) = env.sample_direction(Vec3::ZERO, Vec2::new(0.3, 0.6));
        assert_eq!(ds.pdf, 0.0);
        assert_eq!(w, Spectrum::ZERO);
    }
}

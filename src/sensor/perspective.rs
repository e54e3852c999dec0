//! Perspective pinhole camera (`<sensor type="perspective">`).
//!
//! | parameter                    | type      | default |
//! |------------------------------|-----------|---------|
//! | `to_world`                   | transform | identity (no scale allowed) |
//! | `fov`                        | float     | (degrees, in (0, 180); exclusive with `focal_length`) |
//! | `fov_axis`                   | string    | `x` (`y`, `diagonal`, `smaller`, `larger`; only with `fov`) |
//! | `focal_length`               | string    | `50mm` (35 mm film equivalent, mapped to the diagonal) |
//! | `near_clip`, `far_clip`      | float     | 0.01, 10000 |
//! | `principal_point_offset_x/y` | float     | 0 (fractions of the film size) |
//! | `focus_distance`, `shutter_open`, `shutter_close` | float | accepted, no effect |
//!
//! In camera space the camera looks along +Z with +Y up, and +X points to the image's left;
//! image y grows downward. Rays start on the near plane and end on the far plane, as in
//! Mitsuba. The aspect ratio is that of the full film; a crop window selects pixels without
//! changing the framing.
//!
//! ```xml
//! <sensor type="perspective">
//!     <float name="fov" value="45"/>
//!     <transform name="to_world">
//!         <lookat origin="0, 1, 5" target="0, 0, 0" up="0, 1, 0"/>
//!     </transform>
//!     <film type="hdrfilm"/>
//! </sensor>
//! ```

use super::film::Film;
use crate::math::{Mat4, Ray, Vec2, Vec3};
use crate::scene::desc::Props;
use crate::scene::error::{Error, Result};

#[derive(Clone, Debug, PartialEq)]
pub struct Perspective {
    /// Camera to world (rotation and translation only).
    pub to_world: Mat4,
    /// Horizontal field of view in degrees.
    pub x_fov: f32,
    pub near_clip: f32,
    pub far_clip: f32,
    /// Principal point offset as a fraction of the film size.
    pub principal_point_offset: Vec2,
    /// Full film size in pixels.
    film_size: Vec2,
    /// tan(x_fov / 2) and tan(x_fov / 2) / aspect: the image half-extent at distance 1.
    half_extent: Vec2,
}

impl Perspective {
    /// Read the perspective parameters from a sensor's properties (the film is already parsed).
    /// Does not call `finish`: the sensor does, after reading its nested objects.
    pub fn from_props(props: &Props, film: &Film) -> Result<Perspective> {
        let aspect = film.width as f64 / film.height as f64;
        let x_fov = parse_fov(props, aspect)? as f32;

        let to_world = props.transform("to_world")?;
        if has_scale(&to_world) {
            return Err(props.error(
                "to_world",
                "scale factors in the camera-to-world transformation are not allowed (perspective sensor)",
            ));
        }
        let near_clip = props.float("near_clip", 1e-2)?;
        let far_clip = props.float("far_clip", 1e4)?;
        if near_clip.is_nan() || near_clip <= 0.0 {
            return Err(props.error("near_clip", format!("\"near_clip\" must be greater than zero, got {near_clip}")));
        }
        if far_clip.is_nan() || near_clip >= far_clip {
            return Err(props.error(
                "near_clip",
                format!("\"near_clip\" ({near_clip}) must be smaller than \"far_clip\" ({far_clip})"),
            ));
        }
        let principal_point_offset =
            Vec2::new(props.float("principal_point_offset_x", 0.0)?, props.float("principal_point_offset_y", 0.0)?);
        // Accepted by Mitsuba's projective cameras; a pinhole has no focus and we render one instant.
        props.float("focus_distance", far_clip)?;
        let shutter_open = props.float("shutter_open", 0.0)?;
        let shutter_close = props.float("shutter_close", 0.0)?;
        if shutter_close < shutter_open {
            return Err(props.error("shutter_close", "the shutter must not close before it opens"));
        }

        let tan_half = (0.5 * (x_fov as f64).to_radians()).tan();
        Ok(Perspective {
            to_world,
            x_fov,
            near_clip,
            far_clip,
            principal_point_offset,
            film_size: Vec2::new(film.width as f32, film.height as f32),
            half_extent: Vec2::new(tan_half as f32, (tan_half / aspect) as f32),
        })
    }

    /// The ray through film position `pos` (pixels of the full film, (0, 0) the top-left corner).
    #[inline]
    pub fn sample_ray(&self, pos: Vec2, _aperture_sample: Vec2) -> Ray {
        // Position relative to the film in [0, 1]², then on the plane z = 1 in camera space.
        let s = pos / self.film_size + self.principal_point_offset;
        let p = Vec3::new((1.0 - 2.0 * s.x) * self.half_extent.x, (1.0 - 2.0 * s.y) * self.half_extent.y, 1.0);
        let d = p.normalize();
        let inv_z = 1.0 / d.z;
        let near_t = self.near_clip * inv_z;
        let far_t = self.far_clip * inv_z;
        let d_world = self.to_world.transform_vector3(d);
        Ray { o: self.position() + d_world * near_t, d: d_world, tmax: far_t - near_t }
    }

    /// The pinhole's world position.
    #[inline]
    pub fn position(&self) -> Vec3 {
        self.to_world.w_axis.truncate()
    }
}

/// Mitsuba's `parse_fov`: the horizontal field of view in degrees from `fov` + `fov_axis` or
/// `focal_length`, for a film of aspect ratio `aspect` (width / height).
fn parse_fov(props: &Props, aspect: f64) -> Result<f64> {
    if props.has("fov") && props.has("focal_length") {
        return Err(props.error(
            "focal_length",
            "specify either a focal length (\"focal_length\") or a field of view (\"fov\"), not both",
        ));
    }
    let (fov, axis, axis_name) = if props.has("fov") {
        let fov = props.float_req("fov")? as f64;
        let axis = props.string("fov_axis", "x")?.to_ascii_lowercase();
        let resolved = match axis.as_str() {
            "smaller" => if aspect > 1.0 { "y" } else { "x" }.to_string(),
            "larger" => if aspect > 1.0 { "x" } else { "y" }.to_string(),
            _ => axis.clone(),
        };
        (fov, resolved, "fov_axis")
    } else {
        let f = props.string("focal_length", "50mm")?;
        let number = f.strip_suffix("mm").unwrap_or(&f);
        let value: f64 = match number.trim().parse() {
            Ok(v) if v > 0.0 => v,
            _ => {
                return Err(props.error(
                    "focal_length",
                    format!(
                        "could not parse the focal length \"{f}\" (expected the form <x>mm with <x> a positive number)"
                    ),
                ))
            }
        };
        let fov = 2.0 * ((36.0f64 * 36.0 + 24.0 * 24.0).sqrt() / (2.0 * value)).atan().to_degrees();
        (fov, "diagonal".to_string(), "focal_length")
    };

    let result = match axis.as_str() {
        "x" => fov,
        "y" => (2.0 * ((0.5 * fov.to_radians()).tan() * aspect).atan()).to_degrees(),
        "diagonal" => {
            let diagonal = 2.0 * (0.5 * fov.to_radians()).tan();
            let width = diagonal / (1.0 + 1.0 / (aspect * aspect)).sqrt();
            (2.0 * (width * 0.5).atan()).to_degrees()
        }
        other => {
            return Err(props.error(
                axis_name,
                format!("invalid fov_axis \"{other}\" (expected x, y, diagonal, smaller or larger)"),
            ))
        }
    };
    if !(result > 0.0 && result < 180.0) {
        return Err(Error::at(
            &props.pos_of(if props.has("fov") { "fov" } else { "focal_length" }),
            format!("the horizontal field of view must lie in (0, 180) degrees, got {result}"),
        ));
    }
    Ok(result)
}

/// Mitsuba's `Transform::has_scale`: the rows of the linear part are not orthonormal (within 1e-3).
fn has_scale(m: &Mat4) -> bool {
    let rows = [m.row(0).truncate(), m.row(1).truncate(), m.row(2).truncate()];
    for i in 0..3 {
        for j in i..3 {
            let expected = if i == j { 1.0 } else { 0.0 };
            if (rows[i].dot(rows[j]) - expected).abs() > 1e-3 {
                return true;
            }
        }
    }
    false
}

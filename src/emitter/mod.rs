//! Emitters that are not attached to shapes: `directional`, `envmap`, `constant`, `point`, `spot`
//! (the `area` emitter, bound to a shape, is in `area.rs`).
//!
//! All follow Mitsuba 3.9's plugins of the same names: parameters, defaults, and the weights of
//! `sample_direction` (radiance × geometry / pdf). Infinitely distant emitters (`directional`,
//! `envmap`, `constant`) place their sample points beyond the scene's bounding sphere, which the
//! builder passes once with [`Emitter::set_scene_bounds`].

pub mod area;
pub mod constant;
pub mod directional;
pub mod distribution;
pub mod envmap;
pub mod point;
pub mod spot;

pub use constant::ConstantEmitter;
pub use directional::DirectionalEmitter;
pub use envmap::EnvironmentEmitter;
pub use point::PointEmitter;
pub use spot::SpotEmitter;

use crate::color::Spectrum;
use crate::interaction::{DirectionSample, RAY_EPSILON};
use crate::math::{Vec2, Vec3};
use crate::scene::desc::ObjectDesc;
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};

/// An emitter that is not a shape.
#[derive(Clone, Debug)]
pub enum Emitter {
    Directional(DirectionalEmitter),
    Envmap(EnvironmentEmitter),
    Constant(ConstantEmitter),
    Point(PointEmitter),
    Spot(SpotEmitter),
}

/// The plugin names [`Emitter::from_desc`] accepts.
pub const SUPPORTED: &[&str] = &["directional", "envmap", "constant", "point", "spot"];

impl Emitter {
    /// Build from an `<emitter>` of type directional / envmap / constant / point / spot
    /// (the builder handles `area` itself). Unknown or unused parameters are errors.
    pub fn from_desc(obj: &ObjectDesc, resolver: &FileResolver) -> Result<Emitter> {
        let e = match obj.plugin.as_str() {
            "directional" => Emitter::Directional(DirectionalEmitter::from_props(&obj.props)?),
            "envmap" => Emitter::Envmap(EnvironmentEmitter::from_props(&obj.props, resolver)?),
            "constant" => Emitter::Constant(ConstantEmitter::from_props(&obj.props)?),
            "point" => Emitter::Point(PointEmitter::from_props(&obj.props)?),
            "spot" => Emitter::Spot(SpotEmitter::from_props(&obj.props, resolver)?),
            other => {
                return Err(Error::at(
                    &obj.pos,
                    format!("unsupported emitter type \"{}\" (expected one of: area, {})", other, SUPPORTED.join(", ")),
                ))
            }
        };
        obj.props.finish()?;
        Ok(e)
    }

    /// Called once after the scene is built with its bounding sphere (Mitsuba's `set_scene`).
    pub fn set_scene_bounds(&mut self, center: Vec3, radius: f32) {
        let bs = BoundingSphere::from_scene(center, radius);
        match self {
            Emitter::Directional(e) => e.bsphere = bs,
            Emitter::Envmap(e) => e.bsphere = bs,
            Emitter::Constant(e) => e.bsphere = bs,
            Emitter::Point(_) | Emitter::Spot(_) => {}
        }
    }

    /// Directional, point and spot lights: sampled deterministically, never hit by rays.
    #[inline]
    pub fn is_delta(&self) -> bool {
        matches!(self, Emitter::Directional(_) | Emitter::Point(_) | Emitter::Spot(_))
    }

    /// Envmap and constant: seen by rays that escape the scene.
    #[inline]
    pub fn is_environment(&self) -> bool {
        matches!(self, Emitter::Envmap(_) | Emitter::Constant(_))
    }

    /// Sample a direction from the reference point `ref_p` towards the emitter.
    /// Returns the sample (`pdf` in solid angle, 1 with `delta` for delta lights; `dist` infinite
    /// for directional and environment emitters) and the weight radiance × geometry / pdf, as
    /// Mitsuba's `sample_direction`. A failed sample has pdf 0 and weight 0.
    #[inline]
    pub fn sample_direction(&self, ref_p: Vec3, sample: Vec2) -> (DirectionSample, Spectrum) {
        match self {
            Emitter::Directional(e) => e.sample_direction(ref_p),
            Emitter::Envmap(e) => e.sample_direction(ref_p, sample),
            Emitter::Constant(e) => e.sample_direction(ref_p, sample),
            Emitter::Point(e) => e.sample_direction(ref_p),
            Emitter::Spot(e) => e.sample_direction(ref_p),
        }
    }

    /// Solid-angle density with which [`Emitter::sample_direction`] produces `ds.d` from `ref_p`
    /// (0 for delta emitters).
    #[inline]
    pub fn pdf_direction(&self, _ref_p: Vec3, ds: &DirectionSample) -> f32 {
        match self {
            Emitter::Envmap(e) => e.pdf_direction(ds.d),
            Emitter::Constant(_) => crate::math::warp::square_to_uniform_sphere_pdf(),
            Emitter::Directional(_) | Emitter::Point(_) | Emitter::Spot(_) => 0.0,
        }
    }

    /// [`Emitter::eval_environment`] and, with `with_pdf`, [`Emitter::pdf_direction`] (else 0) of
    /// an escaping ray's direction `d` at once (the envmap maps `d` to its image only once).
    /// Always inlined (with [`EnvironmentEmitter::eval_pdf`]), so that `path`'s AVX2 loop compiles the envmap
    /// lookup with its own target features instead of calling a baseline copy.
    #[inline(always)]
    pub fn eval_environment_pdf(&self, d: Vec3, with_pdf: bool) -> (Spectrum, f32) {
        match self {
            Emitter::Envmap(e) => e.eval_pdf(d, with_pdf),
            _ => {
                let ds = DirectionSample { d, dist: f32::INFINITY, ..Default::default() };
                // Infinitely distant: the density does not depend on the reference point.
                let pdf = if with_pdf { self.pdf_direction(Vec3::ZERO, &ds) } else { 0.0 };
                (self.eval_environment(d), pdf)
            }
        }
    }

    /// Radiance arriving along a ray that escapes the scene in world direction `d` (unit, pointing
    /// away from the scene): Mitsuba's `eval` with `si.wi = -d`. Zero for non-environment emitters.
    #[inline]
    pub fn eval_environment(&self, d: Vec3) -> Spectrum {
        match self {
            Emitter::Envmap(e) => e.eval(d),
            Emitter::Constant(e) => e.radiance,
            Emitter::Directional(_) | Emitter::Point(_) | Emitter::Spot(_) => Spectrum::ZERO,
        }
    }
}

/// The sphere that bounds the scene (Mitsuba's `m_bsphere`), used by infinitely distant emitters to
/// place their sample points beyond all geometry.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoundingSphere {
    pub center: Vec3,
    pub radius: f32,
}

impl Default for BoundingSphere {
    /// The unit sphere, as Mitsuba uses until `set_scene` is called.
    fn default() -> Self {
        BoundingSphere { center: Vec3::ZERO, radius: 1.0 }
    }
}

impl BoundingSphere {
    /// The scene's bounding sphere, enlarged by a relative ray epsilon as Mitsuba does.
    pub fn from_scene(center: Vec3, radius: f32) -> BoundingSphere {
        if !(center.is_finite() && radius.is_finite() && radius >= 0.0) {
            return BoundingSphere { center: Vec3::ZERO, radius: RAY_EPSILON };
        }
        BoundingSphere { center, radius: (radius * (1.0 + RAY_EPSILON)).max(RAY_EPSILON) }
    }

    /// Distance at which a sample point lies beyond the scene as seen from `p` (Mitsuba: twice the
    /// larger of the radius and the distance of `p` from the centre, for reference points outside).
    #[inline]
    pub fn far_distance(&self, p: Vec3) -> f32 {
        2.0 * self.radius.max((p - self.center).length())
    }
}

/// A position or direction given either by a shortcut parameter (`position`, `direction`; read
/// with `read`) or by `to_world` (mapped with `from_to_world`), never both (Mitsuba's rule; the
/// error is at the shortcut's position).
pub(crate) fn shortcut_or_to_world(
    props: &crate::scene::desc::Props,
    shortcut: &str,
    read: fn(&crate::scene::desc::Props, &str) -> Result<Option<glam::Vec3>>,
    from_to_world: fn(&glam::Mat4) -> glam::Vec3,
) -> Result<glam::Vec3> {
    if props.has(shortcut) && props.has("to_world") {
        return Err(props.error(
            shortcut,
            format!("only one of the parameters \"{shortcut}\" and \"to_world\" can be specified at the same time"),
        ));
    }
    match read(props, shortcut)? {
        Some(v) => Ok(v),
        None => {
            let m = props.transform("to_world")?;
            check_transform(props, "to_world", &m)?;
            Ok(from_to_world(&m))
        }
    }
}

/// Check that a transform is usable (finite and invertible); `name` is the property.
pub(crate) fn check_transform(props: &crate::scene::desc::Props, name: &str, m: &glam::Mat4) -> Result<glam::Mat4> {
    let inv = m.inverse();
    if !(m.is_finite() && inv.is_finite()) || m.determinant() == 0.0 {
        return Err(props.error(name, format!("\"{name}\" is not an invertible transform")));
    }
    Ok(inv)
}

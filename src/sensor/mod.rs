//! Sensors and film: the camera that generates primary rays, the film that collects filtered
//! samples ([`film`], [`rfilter`], [`image_block`]) and the sampler settings ([`sampler_desc`]).
//!
//! A `<sensor>` holds the camera parameters and, nested, at most one `<film>` (default: `hdrfilm`,
//! 768×576, Gaussian filter), one `<sampler>` (default: `independent`, 4 samples per pixel) and one
//! `<medium>` (the medium the camera sits in).
//!
//! Rendering a pixel the way Mitsuba does: for each pixel `(x, y)` of [`Film::sample_window`], take
//! `pos = (x, y) + sampler.next_2d()`, trace `camera.sample_ray(pos, aperture)` and splat the result
//! at `pos` into an [`ImageBlock`] (tiles from `ImageBlock::new`, merged into `film.create_block`;
//! with the box filter the sample lands in pixel `(x, y)`, as in Mitsuba). The developed block is
//! written with `io::write::write_exr(path, crop_w, crop_h, film.channel_names(), &block.develop())`.
//!
//! ```xml
//! <sensor type="perspective">
//!     <float name="fov" value="39.3"/>
//!     <transform name="to_world">
//!         <lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/>
//!     </transform>
//!     <sampler type="independent">
//!         <integer name="sample_count" value="64"/>
//!     </sampler>
//!     <film type="hdrfilm">
//!         <integer name="width" value="256"/>
//!         <integer name="height" value="256"/>
//!         <rfilter type="gaussian"/>
//!     </film>
//! </sensor>
//! ```

pub mod film;
pub mod image_block;
pub mod irradiance_meter;
pub mod perspective;
pub mod rfilter;
pub mod sampler_desc;

pub use film::{Film, PixelFormat};
pub use image_block::ImageBlock;
pub use perspective::Perspective;
pub use rfilter::{FilterKernel, RFilter};
pub use sampler_desc::{SamplerDesc, SamplerKind};

use crate::math::{Ray, Vec2, Vec3};
use crate::scene::desc::{ObjectDesc, PluginKind};
use crate::scene::error::{Error, Result};
use crate::scene::resolver::FileResolver;
use std::rc::Rc;

/// A sensor: camera model, film, sampler settings and the medium the camera is in.
#[derive(Clone, Debug)]
pub struct Sensor {
    pub camera: Camera,
    pub film: Film,
    pub sampler: SamplerDesc,
    /// The nested or referenced `<medium>`, built later by the scene builder.
    pub medium_ref: Option<Rc<ObjectDesc>>,
}

/// The camera models (closed set).
#[derive(Clone, Debug)]
#[allow(clippy::large_enum_variant)] // one camera per scene, never per sample: no need to box
pub enum Camera {
    Perspective(Perspective),
    IrradianceMeter(irradiance_meter::IrradianceMeter),
}

impl Sensor {
    /// Build a sensor from a `<sensor>` object. Unknown sensor, film, filter or sampler types
    /// and unused parameters are errors at their source position.
    pub fn from_desc(obj: &ObjectDesc, _resolver: &FileResolver) -> Result<Sensor> {
        let props = &obj.props;
        if obj.plugin != "perspective" {
            return Err(Error::at(
                &obj.pos,
                format!(
                    "sensor type \"{}\" is not supported here (supported: perspective; irradiancemeter inside a shape)",
                    obj.plugin
                ),
            ));
        }
        let (film, sampler, medium_ref) = Self::nested(obj)?;
        let camera = Camera::Perspective(Perspective::from_props(props, &film)?);
        props.finish()?;
        Ok(Sensor { camera, film, sampler, medium_ref })
    }

    /// An `irradiancemeter` nested in `shape` (a world-space copy of the shape it measures).
    pub fn irradiance_meter(obj: &ObjectDesc, shape: crate::shape::Shape) -> Result<Sensor> {
        if obj.plugin != "irradiancemeter" {
            return Err(Error::at(
                &obj.pos,
                format!("sensor type \"{}\" cannot be nested in a shape (supported: irradiancemeter)", obj.plugin),
            ));
        }
        let (film, sampler, medium_ref) = Self::nested(obj)?;
        obj.props.finish()?;
        Ok(Sensor {
            camera: Camera::IrradianceMeter(irradiance_meter::IrradianceMeter { shape }),
            film,
            sampler,
            medium_ref,
        })
    }

    /// The nested film (default hdrfilm), sampler (default independent) and medium of a sensor.
    fn nested(obj: &ObjectDesc) -> Result<(Film, SamplerDesc, Option<Rc<ObjectDesc>>)> {
        let props = &obj.props;
        let film = match props.object_of(PluginKind::Film)? {
            Some(f) => Film::from_desc(&f)?,
            None => Film::default(),
        };
        let sampler = match props.object_of(PluginKind::Sampler)? {
            Some(s) => SamplerDesc::from_desc(&s)?,
            None => SamplerDesc::default(),
        };
        let medium_ref = props.object_of(PluginKind::Medium)?;
        Ok((film, sampler, medium_ref))
    }
}

impl Camera {
    /// The primary ray through continuous film position `pos`, in pixels of the full film
    /// (`0..width`, `0..height`; e.g. pixel `(x, y)` plus a jitter in `[0, 1)²`).
    #[inline]
    pub fn sample_ray(&self, pos: Vec2, aperture_sample: Vec2) -> Ray {
        match self {
            Camera::Perspective(p) => p.sample_ray(pos, aperture_sample),
            Camera::IrradianceMeter(m) => m.sample_ray(pos, aperture_sample),
        }
    }

    /// Importance weight of every primary ray (1 for cameras, π for the irradiance meter).
    #[inline]
    pub fn ray_weight(&self) -> f32 {
        match self {
            Camera::Perspective(_) => 1.0,
            Camera::IrradianceMeter(_) => irradiance_meter::IrradianceMeter::WEIGHT,
        }
    }

    /// The camera's world position.
    #[inline]
    pub fn position(&self) -> Vec3 {
        match self {
            Camera::Perspective(p) => p.position(),
            Camera::IrradianceMeter(m) => m.shape.bounds().center(),
        }
    }
}

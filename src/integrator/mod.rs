//! Integrators, one file per XML type: `path` (surfaces only), `volpath`, `volpathmis`,
//! `volpath_snee` (volpath with subdivision NEE, the technique in `snee/`), and the `moment`
//! wrapper that also outputs the per-pixel second moment.
//!
//! - [`parse`] reads the `<integrator>` element into an [`IntegratorDesc`]; [`build`] turns it into
//!   the [`Integrator`] the scene keeps, with the tables it precomputes; [`Integrator::li`] is the
//!   one call the renderer makes per camera ray.
//! - `walk.rs` holds the walks through media and passable surfaces that every volumetric
//!   integrator shares; `technique.rs` documents how a connection technique plugs into the
//!   volpath loop.
//!
//! Common parameters (Mitsuba's `MonteCarloIntegrator`):
//!
//! | Parameter       | Type    | Default | Description                                            |
//! |-----------------|---------|---------|--------------------------------------------------------|
//! | `max_depth`     | integer | -1      | longest path (-1: unbounded, 0: black, 1: emitters seen directly) |
//! | `rr_depth`      | integer | 5       | depth from which Russian roulette runs                 |
//! | `hide_emitters` | boolean | false   | emitters seen directly are black                       |

pub mod classes;
pub mod cx;
pub mod desc;
pub mod enclosure;
pub mod manifold;
pub mod moment;
pub mod path;
pub mod path_wide;
pub mod snee;
pub mod splat;
pub mod stats;
pub mod technique;
pub mod volpath;
pub mod volpath_snee;
pub mod volpathmis;
pub mod walk;

pub use desc::{Integrator, IntegratorDesc, IntegratorKind};

use crate::color::Spectrum;
use crate::math::Ray;
use crate::sampler::Sampler;
use crate::scene::desc::ObjectDesc;
use crate::scene::world::Scene;
use crate::scene::{Error, Result};
use classes::{ClassValues, Classes, PathClass};
use stats::LocalStats;

/// The settings of an `<integrator>` element (its common parameters, and its own).
pub fn parse(obj: &ObjectDesc) -> Result<IntegratorDesc> {
    let props = &obj.props;
    let kind = match obj.plugin.as_str() {
        "moment" => return moment::parse(obj),
        "path" => IntegratorKind::Path,
        "volpath" => IntegratorKind::Volpath,
        "volpathmis" => IntegratorKind::Volpathmis,
        "volpath_snee" => IntegratorKind::VolpathSnee,
        other => {
            return Err(Error::at(
                &obj.pos,
                format!(
                    "integrator \"{}\" is not supported (supported: path, volpath, volpathmis, volpath_snee, moment)",
                    other
                ),
            ))
        }
    };
    let max_depth = props.int("max_depth", -1)?;
    if max_depth < -1 {
        return Err(props.error("max_depth", "max_depth must be -1 (unbounded) or non-negative"));
    }
    let rr_depth = props.int("rr_depth", 5)?;
    if rr_depth <= 0 {
        return Err(props.error("rr_depth", "rr_depth must be positive"));
    }
    let hide_emitters = props.bool("hide_emitters", false)?;
    let (snee, connection) = match kind {
        IntegratorKind::VolpathSnee => {
            // The transport branch read `connection` before the SNEE options (same error order).
            let connection = volpath_snee::parse_connection(props)?;
            let options = volpath_snee::parse_options(props)?;
            if options.chains && connection != manifold::Connection::Complete {
                return Err(
                    props.error("reflection_chains", "volpath_snee: reflection_chains needs connection = complete")
                );
            }
            (options, connection)
        }
        _ => Default::default(),
    };
    props.finish()?;
    let clamp = |v: i64| v.clamp(-1, i32::MAX as i64) as i32;
    Ok(IntegratorDesc {
        kind,
        max_depth: clamp(max_depth),
        rr_depth: clamp(rr_depth),
        hide_emitters,
        moment: false,
        classes: false,
        snee,
        connection,
    })
}

/// The camera ray through film position `pos` and its importance weight (the camera's own
/// sampling, except for an irradiance meter facing a rough boundary under `volpath_snee`
/// `connection = complete`: `manifold::meter_glint`).
#[inline]
pub fn primary_ray(scene: &Scene, pos: crate::math::Vec2, aperture: crate::math::Vec2) -> (Ray, f32) {
    if let (Integrator::VolpathSnee(_, snee), crate::sensor::Camera::IrradianceMeter(meter)) =
        (&scene.integrator, &scene.camera)
    {
        if let Some(glint) = &snee.meter_glint {
            return glint.sample_ray(meter, pos, aperture);
        }
    }
    (scene.camera.sample_ray(pos, aperture), scene.camera.ray_weight())
}

/// The integrator for `scene` (whose own `integrator` field is not read), with its tables.
pub fn build(desc: IntegratorDesc, scene: &Scene) -> Integrator {
    match desc.kind {
        IntegratorKind::Path => Integrator::Path(desc),
        IntegratorKind::Volpath => Integrator::Volpath(desc),
        IntegratorKind::Volpathmis => Integrator::Volpathmis(desc),
        IntegratorKind::VolpathSnee => {
            let snee = volpath_snee::build(scene, desc.snee, desc.connection);
            // The options as built (the curved connection's default top rate): every technique,
            // SNEE's weight included (`scene.integrator.snee`), must read the same rate.
            Integrator::VolpathSnee(IntegratorDesc { snee: snee.options, ..desc }, snee)
        }
    }
}

impl Integrator {
    /// Radiance along one camera ray (which starts in the sensor's medium), and whether the ray is
    /// "valid" (the alpha channel).
    #[inline]
    pub fn li(&self, scene: &Scene, sampler: &mut Sampler, ray: Ray, stats: &mut LocalStats) -> (Spectrum, bool) {
        let medium = scene.sensor_medium;
        match self {
            Integrator::Path(_) => path::li(scene, sampler, ray, stats),
            Integrator::Volpath(_) => volpath::li(scene, sampler, ray, medium, stats),
            Integrator::Volpathmis(_) => volpathmis::li(scene, sampler, ray, medium, stats),
            Integrator::VolpathSnee(_, snee) => volpath_snee::li(scene, snee, sampler, ray, medium, stats),
        }
    }

    /// [`Integrator::li`], also split by transport class (`classes.rs`; `path`: all `surface`).
    pub fn li_classes(
        &self,
        scene: &Scene,
        sampler: &mut Sampler,
        ray: Ray,
        stats: &mut LocalStats,
    ) -> (Spectrum, bool, ClassValues) {
        let medium = scene.sensor_medium;
        let mut tally = Classes::default();
        let (l, valid) = match self {
            Integrator::Path(_) => {
                let (l, valid) = path::li(scene, sampler, ray, stats);
                tally.values[PathClass::Surface as usize] = l;
                (l, valid)
            }
            Integrator::Volpath(_) => volpath::li_tally(scene, sampler, ray, medium, stats, None, &mut tally),
            Integrator::Volpathmis(_) => {
                let roulette = volpathmis::RouletteMis::Unbiased;
                volpathmis::li_tally(scene, sampler, ray, medium, stats, roulette, &mut tally)
            }
            Integrator::VolpathSnee(_, snee) if snee.forward_only => {
                volpath::li_tally(scene, sampler, ray, medium, stats, None, &mut tally)
            }
            Integrator::VolpathSnee(_, snee) => {
                let (l, valid) = volpath::li_tally(scene, sampler, ray, medium, stats, Some(snee), &mut tally);
                // Glints (`manifold/glint.rs`): class `surface`.
                let glint = manifold::glint::sample(scene, snee, sampler, &ray, stats);
                tally.values[PathClass::Surface as usize] += glint;
                manifold::camera_beam::sample(scene, snee, sampler, stats);
                (l + glint, valid)
            }
        };
        (l, valid, tally.values)
    }
}

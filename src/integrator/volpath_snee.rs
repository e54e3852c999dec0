//! `volpath_snee`: volpath with subdivision next-event estimation (Koerner et al. 2016, the
//! technique in `integrator/snee/`), combined with forward path tracing by multiple importance
//! sampling (`docs/snee.md`).
//!
//! | Parameter    | Type    | Description                                                        |
//! |--------------|---------|--------------------------------------------------------------------|
//! | `max_depth`, `rr_depth`, `hide_emitters` | | as `volpath`                                |
//! | `snee`       | string  | `mis` (default): SNEE and forward tracing by MIS; `snee`: SNEE alone where it applies; `forward`: forward alone (= volpath) |
//! | `transport`  | string  | `all` (default); `snee`: only paths whose last two scattering vertices before leaving through the boundary are medium vertices, in SNEE's support (the paper's Figure 3) |
//! | `connection` | string  | `paper` (default): the paper's estimator; `complete`: also manifold NEE through flat smooth boundaries (`manifold/`, docs/manifold.md) |
//! | `reflection_chains` | boolean | with `connection = complete`: also connect through an internal reflection then a refraction (two-vertex chains, `manifold/chain.rs`, docs/manifold.md §9) under a directional light; default `false` (its cost exceeds its gain on the paper's statue) |
//! | `split_glints` | boolean | with `connection = complete`: emitter splitting at smooth dielectric vertices (`manifold/split.rs`, docs/manifold.md §12): the emitter seen along the lobe that BSDF sampling did not pick is found by one more ray and both lobes are counted with their Fresnel weights, where forward tracing alone makes that suffix (glints of area lights and environments); default `true` |
//! | `beams` | boolean | with `connection = complete`: light-traced internal-reflection segments (beams) under a directional light behind a smooth `dielectric` boundary, connected to every camera medium vertex inside it (`manifold/beam.rs`, docs/beams.md); default `true` |
//! | `snee_rate`  | float   | probability `r` of running SNEE at a scattering vertex (default: chosen per medium from its boundary and the lights, see [`snee::auto_rate`], revised under `connection = complete` by `snee::rate::complete_rates`); MIS counts SNEE's density as `r · pdf_snee`, so any `r` is unbiased |
//! | `connection_rate` | float | with `connection = complete`: the top rate `q_top` in (0, 1] of the curved area-light connection (`manifold/curved_finite.rs`): at a medium vertex `x_j` whose emitter sample picked an area light at `y` it runs with probability `q = q_top · max(e^{−σ_t t0}, 1e-3)`, `t0` the distance from `x_j` to the boundary towards `y`; default `min(0.05, (1/256) / m(τ))` (`curved_finite::RATE`, `curved_finite::default_top_rate`: `m(τ) = (1 − e^{−τ})/τ` of the medium's optical size `τ`, so thin media run it less often; docs/manifold.md §8.2); part of its density, so any `q_top` is unbiased |
//!
//! ```xml
//! <integrator type="volpath_snee">
//!     <integer name="max_depth" value="-1"/>
//!     <string name="snee" value="mis"/>
//!     <string name="transport" value="all"/>
//! </integrator>
//! ```

use super::manifold::{self, Connection};
use super::snee::{self, Snee, SneeOptions, SneeTechnique, SneeTransport};
use super::stats::LocalStats;
use super::volpath;
use crate::bsdf::Bsdf;
use crate::color::Spectrum;
use crate::emitter::Emitter;
use crate::interaction::offset_origin;
use crate::math::{Ray, Vec2};
use crate::sampler::Sampler;
use crate::scene::desc::Props;
use crate::scene::world::{Scene, SceneEmitter};
use crate::scene::Result;
use crate::sensor::Camera;
use manifold::meter_glint::MeterGlint;

/// Radiance along a camera ray: volpath's loop with SNEE as one stage.
pub fn li(
    scene: &Scene,
    snee: &Snee,
    sampler: &mut Sampler,
    ray: Ray,
    medium: Option<u32>,
    stats: &mut LocalStats,
) -> (Spectrum, bool) {
    if snee.forward_only {
        return volpath::li(scene, sampler, ray, medium, stats);
    }
    let (l, valid) = volpath::li_with(scene, sampler, ray, medium, stats, Some(snee));
    // Glints from the camera (`connection = complete`, docs/manifold.md §10); zero, drawing nothing,
    // elsewhere, and without a directional light (which only they take): not even its camera map
    // is built then.
    if !snee.has_directional {
        return (l, valid);
    }
    let l = l + manifold::glint::sample(scene, snee, sampler, &ray, stats);
    // Camera beams (docs/beams.md): splats into other pixels, none into this sample's value.
    manifold::camera_beam::sample(scene, snee, sampler, stats);
    (l, valid)
}

/// Has `scene` a `directional` emitter (the only emitters the camera's glints take)?
#[inline]
fn has_directional(scene: &Scene) -> bool {
    scene.emitters.iter().any(|e| matches!(e, SceneEmitter::Other(Emitter::Directional(_))))
}

/// The `snee`, `snee_rate` and `transport` parameters.
pub fn parse_options(props: &Props) -> Result<SneeOptions> {
    let technique = match props.string("snee", "mis")?.as_str() {
        "mis" => SneeTechnique::Mis,
        "snee" => SneeTechnique::Snee,
        "forward" => SneeTechnique::Forward,
        other => {
            return Err(
                props.error("snee", format!("volpath_snee: snee = \"{}\" is not one of mis, snee, forward", other))
            )
        }
    };
    let rate = props.float_opt("snee_rate")?;
    if let Some(r) = rate {
        if !(0.0..=1.0).contains(&r) {
            return Err(props.error("snee_rate", "volpath_snee: snee_rate must be in [0, 1]"));
        }
    }
    let transport = match props.string("transport", "all")?.as_str() {
        "all" => SneeTransport::All,
        "snee" => SneeTransport::Snee,
        other => {
            return Err(
                props.error("transport", format!("volpath_snee: transport = \"{}\" is not one of all, snee", other))
            )
        }
    };
    let chains = props.bool("reflection_chains", false)?;
    let connection_rate = props.float_opt("connection_rate")?;
    if let Some(q) = connection_rate {
        if !(q > 0.0 && q <= 1.0) {
            return Err(props.error("connection_rate", "volpath_snee: connection_rate must be in (0, 1]"));
        }
    }
    let split_glints = props.bool("split_glints", true)?;
    let beams = props.bool("beams", true)?;
    let camera_beams = props.bool("camera_beams", false)?;
    let max = manifold::camera_beam::MAX_CAMERA_REFLECTIONS as i64;
    let camera_reflections = props.int("camera_reflections", 0)?;
    if !(0..=max).contains(&camera_reflections) {
        return Err(
            props.error("camera_reflections", format!("volpath_snee: camera_reflections must be in [0, {max}]"))
        );
    }
    let camera_reflections = camera_reflections as u32;
    let inner_glints = props.bool("inner_glints", false)?;
    Ok(SneeOptions {
        technique,
        transport,
        rate,
        chains,
        connection_rate,
        split_glints,
        beams,
        camera_beams,
        camera_reflections,
        inner_glints,
    })
}

/// The `connection` parameter (manifold NEE, `integrator/manifold/`).
pub fn parse_connection(props: &Props) -> Result<Connection> {
    match props.string("connection", "paper")?.as_str() {
        "paper" => Ok(Connection::Paper),
        "complete" => Ok(Connection::Complete),
        other => Err(props
            .error("connection", format!("volpath_snee: connection = \"{}\" is not one of paper, complete", other))),
    }
}

/// SNEE's tables for `scene` (per-medium rates, emitter mixture), and with `connection =
/// complete` the manifold connection's flat boundaries, built once at scene load.
pub fn build(scene: &Scene, options: SneeOptions, connection: Connection) -> Snee {
    let mut snee = snee::rate::build(scene, options);
    snee.has_directional = has_directional(scene);
    if connection == Connection::Complete {
        snee.flat = manifold::flat::flat_boundaries(scene);
        snee.rough = manifold::rough::rough_boundaries(scene);
        snee.curved = manifold::curved::curved_boundaries(scene, &snee.flat);
        snee.records = manifold::stage::records(scene, &snee);
        snee::rate::complete_rates(scene, &mut snee);
        // Only a top rate below `RATE` is stored: elsewhere `RATE` itself stands, bit for bit.
        if snee.options.connection_rate.is_none() {
            let q_top = manifold::curved_finite::default_top_rate(scene, &snee.curved);
            snee.options.connection_rate = q_top.filter(|&q| q < manifold::curved_finite::RATE).map(|q| q as f32);
        }
        snee.meter_glint = meter_glint(scene);
        if let Camera::Perspective(p) = &scene.camera {
            snee.camera = Some(manifold::glint::CameraMap::new(p, scene.film.width, scene.film.height));
        }
        snee.split = manifold::split::tables(scene, snee.options);
        if snee.options.beams && snee.options.keeps_all() && snee.has_directional {
            snee.beams = manifold::beam::beam_boundaries(scene);
            snee.camera_beams = manifold::camera_beam::applies(scene, &snee);
        }
    }
    snee.forward_only = forward_only(scene, &snee, connection);
    snee
}

/// The irradiance meter's glint mixture (`manifold::meter_glint`, docs/manifold.md §11) for
/// `scene`, or `None` where it does not apply: no meter, the probe ray from the centre of the
/// meter's shape along its normal does not hit an isotropic `roughdielectric`, or no directional
/// light is in front of that surface.
fn meter_glint(scene: &Scene) -> Option<MeterGlint> {
    let Camera::IrradianceMeter(meter) = &scene.camera else { return None };
    let centre = meter.shape.sample_position(Vec2::splat(0.5));
    let si = scene.ray_intersect(&Ray::new(offset_origin(centre.p, centre.n, centre.n), centre.n))?;
    let bsdf = scene.bsdf(&si);
    let Bsdf::RoughDielectric(r) = bsdf else { return None };
    if r.alpha_u != r.alpha_v {
        return None;
    }
    let n_ref = if si.n.dot(centre.n) < 0.0 { si.n } else { -si.n };
    let wide_alpha = match manifold::rough_lobe::widened(bsdf) {
        Some(Bsdf::RoughDielectric(w)) => Some(w.alpha_u),
        _ => None,
    };
    let lights = scene.emitters.iter().filter_map(|e| match e {
        SceneEmitter::Other(Emitter::Directional(d)) => Some(-d.d.normalize()),
        _ => None,
    });
    MeterGlint::new(n_ref, r.distribution, r.alpha_u, wide_alpha, manifold::rough_lobe::WIDE_SHARE, lights)
}

/// Does nothing of `volpath_snee` run in `scene`? Then its loop would compute volpath's estimate
/// (every MIS weight comes out as volpath's; bit for bit where its stages draw no numbers), only
/// slower: it would still track every medium vertex and boundary crossing. That holds when all
/// transport is kept, SNEE never runs (`snee = forward`, or every medium's rate is 0 or SNEE does
/// not apply), and with `connection = complete` no connection serves the scene: no flat or rough
/// boundary, no directional light (the camera's glints), and curved boundaries lit only by
/// emitters that no curved technique takes
/// ([`curved_serves`]: environments; area lights only where `connection_rate` would be 0, which
/// neither the parameter nor `curved_finite::default_top_rate` gives; docs/manifold.md §8.2, §10).
pub fn forward_only(scene: &Scene, snee: &Snee, connection: Connection) -> bool {
    let options = &snee.options;
    let no_snee = options.technique == SneeTechnique::Forward || snee.rates.iter().all(|r| r.is_none_or(|r| r == 0.0));
    let no_connection = match connection {
        Connection::Paper => true,
        Connection::Complete => {
            let directional = snee.has_directional;
            snee.flat.iter().all(Option::is_none)
                && snee.rough.iter().all(Option::is_none)
                // The camera's glints (`manifold::glint`) take directional lights on any medium's
                // smooth boundary, whether or not the curved connection serves that medium.
                && !directional
                && (snee.curved.iter().all(|c| !c) || scene.emitters.iter().all(|e| !curved_serves(e, options)))
        }
    };
    options.keeps_all() && no_snee && no_connection && snee.meter_glint.is_none()
}

/// Can a technique through curved boundaries take emitter `e`? Directional lights (§8, chains,
/// glints), area lights when the curved area-light connection runs (§8.2, top rate above 0), and,
/// conservatively, point and spot lights; environments (`envmap`, `constant`) never.
fn curved_serves(e: &SceneEmitter, options: &SneeOptions) -> bool {
    match e {
        SceneEmitter::Area { .. } => manifold::curved_finite::rate(*options) > 0.0,
        SceneEmitter::Other(Emitter::Envmap(_) | Emitter::Constant(_)) => false,
        SceneEmitter::Other(_) => true,
    }
}

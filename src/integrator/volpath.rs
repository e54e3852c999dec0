//! Mitsuba's `volpath`: volumetric path tracing with next-event estimation at surfaces and at
//! medium scattering vertices, combined with BSDF / phase sampling by the power heuristic.
//!
//! ```xml
//! <integrator type="volpath"><integer name="max_depth" value="64"/></integrator>
//! ```
//!
//! The estimator is Mitsuba 3's, so our images agree with its references in expectation:
//! - RGB mode: one colour channel is picked per path; free-flight distances are sampled in that
//!   channel and the throughput is weighted by `Tr / pdf[channel]` (spectral transmittance ratio).
//! - `depth` counts every real medium scatter and every non-null surface event; Russian roulette
//!   applies when `depth > rr_depth` with q = min(max(β)·η², 0.95).
//! - Shadow rays pass `null` and `thindielectric` interfaces (their null transmission) and media
//!   (track-length transmittance estimate in the path's channel); dielectrics block them.
//! - "Specular chains" (paths whose last non-null event was a delta lobe, or a medium vertex that
//!   does not sample emitters) count an emitter they hit at full weight.
//!
//! The loop ([`trace`]) is shared with `volpathmis`: what differs, how the path's weight is carried
//! and how MIS weighs emitter sampling against BSDF / phase sampling, is a [`PathWeight`]
//! ([`Beta`] here: the throughput and the power heuristic). `volpath_snee` is this loop with SNEE
//! as one more stage ([`SneeStage`]), and with `connection = complete` manifold NEE as another
//! ([`ManifoldStage`], `manifold/stage.rs`).

use super::classes::{End, NoClasses, Tally};
use super::cx::ForwardWeight;
pub use super::cx::{Cx, EmitterHit, Scatter, Stages};
use super::manifold::split::GlintSplit;
use super::manifold::ManifoldStage;
use super::snee::{ForwardTechnique, LightSample, Snee, SneeStage};
use super::stats::LocalStats;
use super::walk::{
    free_flight, is_medium_transition, shadow_crossing, shadow_ray, target_medium, PathSetup, RefPoint, MAX_SEGMENTS,
};
use crate::bsdf::{flags, BsdfContext};
use crate::bsdf::{Bsdf, BsdfSample};
use crate::color::Spectrum;
use crate::emitter::Emitter;
use crate::interaction::offset_origin;
use crate::interaction::{DirectionSample, SurfaceInteraction};
use crate::math::INV_FOUR_PI;
use crate::math::{mis_weight, Ray, RayA};
use crate::math::{Vec2, Vec3};
use crate::medium::Homogeneous;
use crate::sampler::Sampler;
use crate::scene::world::{Scene, SceneEmitter};
use crate::shape::mesh::MeshPlane;
use crate::shape::Geometry;
use crate::texture::Texture;

/// Sample an emitter from `r` and estimate the transmittance to it (Mitsuba's
/// `VolumetricPathIntegrator::sample_emitter`). Returns (emitted · transmittance / pdf, ds).
pub fn sample_emitter(
    scene: &Scene,
    r: RefPoint,
    medium: Option<u32>,
    channel: usize,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> (Spectrum, DirectionSample) {
    let (ds, emitted) = scene.sample_emitter_direction(r.p(), None, sampler.next_2d(), false);
    if ds.pdf == 0.0 || emitted == Spectrum::ZERO {
        return (Spectrum::ZERO, ds);
    }
    let (ray, medium) = shadow_ray(scene, r, medium, &ds);
    let tr = shadow_transmittance(scene, ray.to_a(), medium, channel, sampler, stats);
    (emitted * tr, ds)
}

/// [`sample_emitter`] from a medium point `p` where it is known to return 0 (a medium whose
/// enclosure blocks every shadow ray, `integrator/enclosure.rs`): no ray is traced, but the same
/// samples are drawn: the emitter sample, and when it is usable the one distance sample of the
/// segment to the enclosing surface (which either ends it by a collision or blocks it).
///
/// Whether the emitter sample is usable is decided without sampling where [`surely_usable`] can
/// tell (a constant sphere light seen from outside, away from its cone's rim); elsewhere the
/// emitter is sampled as the shadow ray would. Either way the same samples are drawn.
#[inline]
pub fn skip_sample_emitter(scene: &Scene, p: Vec3, sampler: &mut Sampler) {
    let u = sampler.next_2d();
    let usable = surely_usable(scene, p, u) || {
        let (ds, emitted) = scene.sample_emitter_direction(p, None, u, false);
        ds.pdf != 0.0 && emitted != Spectrum::ZERO
    };
    if usable {
        let _ = sampler.next_1d();
    }
}

/// True when `Scene::sample_emitter_direction(p, None, u, false)` certainly returns a usable
/// sample (`pdf > 0` and a finite, non-zero weight); false when that is not sure (the caller then
/// samples). Certain, with margins far above `f32` rounding, for the emitter `u.x` selects being
/// - an `area` emitter of constant, finite radiance (some channel ≥ 1e-10) on a sphere with outward
///   normals (decided at build, `constant_sphere_lights`), seen from a point `p`
///   - outside it by 1 % of `r²` (`Sphere::sample_direction` samples the subtended cone),
///   - with the cone sample `u.y` away from the rim: `1 − u.y > 10⁻³`, so the direction hits the
///     sphere with |cos| ≥ ~0.03 at the hit (the one-sided emitter's front faces it), and
///     `(1 − u.y) r² > 2·10⁻⁵ |c − p|²`, so `cos θ − cos α = (1 − u.y)(1 − cos α) > 10⁻⁵` (the cone
///     pdf is positive and finite, as `1 − cos α ≥ r² / 2|c − p|²`);
/// - a `constant` environment (a uniform direction of density 1/4π, weight `radiance · 4π · n`);
/// - an `area` emitter of constant radiance on a flat mesh ([`MeshPlane`]), seen from a point in
///   front of it, whatever point area sampling picks ([`surely_usable_plane`]).
#[inline]
fn surely_usable(scene: &Scene, p: Vec3, u: Vec2) -> bool {
    let Some((index, _)) = scene.select_emitter(u) else { return false };
    if let Some((center, r2)) = scene.constant_sphere_lights[index] {
        let dist2 = (center - p).length_squared();
        let rim = 1.0 - u.y;
        return dist2 > r2 * 1.01 && rim > 1e-3 && rim * r2 > 2e-5 * dist2;
    }
    let n = scene.emitters.len() as f64;
    match &scene.emitters[index] {
        SceneEmitter::Other(Emitter::Constant(c)) => {
            usable_weight(c.radiance, f64::from(INV_FOUR_PI) / n, f64::from(INV_FOUR_PI) / n)
        }
        SceneEmitter::Area { shape, radiance: Texture::Const(le) } => match &scene.shapes[*shape as usize].geometry {
            Geometry::Mesh(m) => m.plane.is_some_and(|plane| surely_usable_plane(m, &plane, *le, p, n)),
            _ => false,
        },
        _ => false,
    }
}

/// [`surely_usable`] for a flat emitting mesh seen from `p` at height `h = n · p − c` in front of
/// its one-sided emission, `h > 10⁻⁴ · (scale + |p|)` and `h > 10⁻⁴ · D`, where `D` bounds the
/// distance to any point of the mesh (its bounding sphere): the sampled point lies in the plane up
/// to ~10⁻⁶ of that scale and each triangle's normal within 10⁻⁵ of the plane's, so the direction
/// to it leaves the emitter's front (`d · n < 0`) with `|cos| ≥ h / 2D`, and the solid-angle pdf
/// `dist² / (|cos| A)` lies in `[h² / 2A, 2 D³ / (h A)]` (`usable_weight` checks that range).
#[inline]
fn surely_usable_plane(m: &crate::shape::mesh::Mesh, plane: &MeshPlane, le: Spectrum, p: Vec3, n: f64) -> bool {
    let h = plane.n.dot(p) - plane.c;
    let d_max = (p - plane.center).length() + plane.radius;
    let s = plane.scale + p.abs().max_element();
    if !(h > 1e-4 * s && h > 1e-4 * d_max) {
        return false;
    }
    let (h, d_max) = (f64::from(h), f64::from(d_max) * 1.01);
    let pdf_area = f64::from(1.0 / m.surface_area());
    usable_weight(le, 0.5 * pdf_area * h * h / n, 2.0 * pdf_area * d_max * d_max * d_max / h / n)
}

/// Whether an emitter sample of radiance `le`, selected among `n` emitters with a density
/// (selection included) certainly within `[pdf_lo, pdf_hi]`, has a density above 0 and a finite,
/// non-zero weight `le / pdf` in `f32` (with wide margins: `[1e-30, 1e30]`).
#[inline]
fn usable_weight(le: Spectrum, pdf_lo: f64, pdf_hi: f64) -> bool {
    let le_max = f64::from(le.abs().max_element());
    crate::color::is_finite(le) && pdf_lo > 1e-30 && pdf_hi < 1e30 && le_max / pdf_hi > 1e-30 && le_max / pdf_lo < 1e30
}

/// Per emitter, decided at scene build for [`surely_usable`]: the centre and `r²` of an `area`
/// emitter of constant, finite radiance (some channel ≥ 1e-10) on a sphere with outward normals;
/// `None` for any other emitter (`Scene::constant_sphere_lights`).
pub fn constant_sphere_lights(scene: &Scene) -> Vec<Option<(Vec3, f32)>> {
    let light = |e: &SceneEmitter| {
        let SceneEmitter::Area { shape, radiance: Texture::Const(le) } = e else { return None };
        let Geometry::Sphere(sphere) = &scene.shapes[*shape as usize].geometry else { return None };
        if sphere.flip_normals || !crate::color::is_finite(*le) || !(le.abs().max_element() >= 1e-10) {
            return None;
        }
        Some((sphere.center, sphere.radius * sphere.radius))
    };
    scene.emitters.iter().map(light).collect()
}

/// Transmittance along a shadow ray up to `ray.tmax`, through null / thin-dielectric interfaces
/// and homogeneous media (track-length estimate in `channel`, as Mitsuba's RGB mode does).
///
/// Distance first, as Mitsuba: in a medium the free-flight distance `t` is sampled before the
/// segment is traced, and the ray is traced only up to `t` (a surface hit before it ends the
/// segment; none means a real collision, and a homogeneous medium, without null density, gives 0).
/// The walk is `walk_segments`'s, with the same samples in the same order. The ray comes as a
/// [`RayA`] (this function does not inline; see `RayA`).
pub fn shadow_transmittance(
    scene: &Scene,
    mut ray: RayA,
    mut medium: Option<u32>,
    channel: usize,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> Spectrum {
    if scene.surfaces_block_shadow_rays {
        return shadow_transmittance_opaque(scene, ray, medium, channel, sampler, stats);
    }
    let mut tr = Spectrum::ONE;
    let mut remaining = ray.tmax;
    // The first segment is written out before the loop: most walks end in it, and the loop's
    // set-up (the scene's fields it keeps at hand) is then paid only by walks of two or more.
    if shadow_segment(scene, &mut ray, &mut medium, &mut remaining, &mut tr, channel, sampler, stats) {
        for _ in 1..MAX_SEGMENTS {
            if !shadow_segment(scene, &mut ray, &mut medium, &mut remaining, &mut tr, channel, sampler, stats) {
                break;
            }
        }
    }
    tr
}

/// One segment of [`shadow_transmittance`]'s walk: the distance sample, the trace up to it, the
/// segment's transmittance into `tr` and the crossing of the surface that ends it. Returns whether
/// the walk goes on (`false`: it ended, with its value in `tr`).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn shadow_segment(
    scene: &Scene,
    ray: &mut RayA,
    medium: &mut Option<u32>,
    remaining: &mut f32,
    tr: &mut Spectrum,
    channel: usize,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> bool {
    if !(*remaining > 0.0) {
        return false;
    }
    let m = medium.map(|m| &scene.media[m as usize]);
    let t = m.map_or(f32::INFINITY, |m| m.sample_distance(sampler.next_1d(), channel));
    // Up to and including `t`: a surface exactly at `t` is crossed, as with `t < seg` below.
    ray.tmax = if t < *remaining { t.next_up() } else { *remaining };
    stats.rays += 1;
    // The hit alone (`Scene::ray_intersect`'s query); the crossing below builds what it needs of it.
    let hit = scene.accel.intersect_a(&scene.shapes, ray);
    let seg = hit.as_ref().map_or(*remaining, |h| h.t);
    if let Some(m) = m {
        if t < seg {
            // A real collision: homogeneous media have no null density, the estimate is 0.
            *tr = Spectrum::ZERO;
            return false;
        }
        if seg.is_finite() {
            let t_seg = m.transmittance(seg);
            let p = t_seg[channel];
            if !(p > 0.0) {
                *tr = Spectrum::ZERO;
                return false;
            }
            *tr *= t_seg / p;
        }
    }
    let Some(hit) = hit else { return false };
    let d = Vec3::from(ray.d);
    let (p, n, null_transmission) = shadow_crossing(scene, &hit, &ray.ray());
    *tr *= null_transmission;
    if *tr == Spectrum::ZERO {
        return false;
    }
    // `is_medium_transition` and `target_medium` on the crossing's shape and normal.
    let s = &scene.shapes[hit.shape as usize];
    if s.interior.is_some() || s.exterior.is_some() {
        *medium = if d.dot(n) > 0.0 { s.exterior } else { s.interior };
    }
    *remaining -= hit.t;
    ray.o = offset_origin(p, n, d).into();
    true
}

/// [`shadow_transmittance`] in a scene where every surface blocks shadow rays
/// (`Scene::surfaces_block_shadow_rays`): the walk has one segment, which a surface ends with 0, so
/// an any-hit query up to the sampled distance decides it. The same samples, the same value (the
/// full walk multiplies by a zero null transmission at the first surface), one ray counted.
#[inline]
fn shadow_transmittance_opaque(
    scene: &Scene,
    mut ray: RayA,
    medium: Option<u32>,
    channel: usize,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> Spectrum {
    let remaining = ray.tmax;
    if !(remaining > 0.0) {
        return Spectrum::ONE;
    }
    let m = medium.map(|m| &scene.media[m as usize]);
    let t = m.map_or(f32::INFINITY, |m| m.sample_distance(sampler.next_1d(), channel));
    ray.tmax = if t < remaining { t.next_up() } else { remaining };
    stats.rays += 1;
    // A non-finite ray has no hit in `ray_intersect` (the full walk's query); `ray_test` reports it blocked.
    if (ray.o + ray.d).is_finite() && scene.accel.occluded_a(&scene.shapes, &ray) {
        return Spectrum::ZERO;
    }
    let Some(m) = m else { return Spectrum::ONE };
    if t < remaining {
        // A real collision before the end of the ray.
        return Spectrum::ZERO;
    }
    if !remaining.is_finite() {
        return Spectrum::ONE;
    }
    let t_seg = m.transmittance(remaining);
    let p = t_seg[channel];
    if !(p > 0.0) {
        return Spectrum::ZERO;
    }
    t_seg / p
}

/// Radiance along a camera ray starting in `medium`; also whether the ray is "valid" (alpha).
pub fn li(
    scene: &Scene,
    sampler: &mut Sampler,
    ray: Ray,
    medium: Option<u32>,
    stats: &mut LocalStats,
) -> (Spectrum, bool) {
    li_with(scene, sampler, ray, medium, stats, None)
}

/// volpath's loop; with `snee`, the `volpath_snee` integrator. With `None` this is Mitsuba's volpath.
pub fn li_with(
    scene: &Scene,
    sampler: &mut Sampler,
    ray: Ray,
    medium: Option<u32>,
    stats: &mut LocalStats,
    snee: Option<&Snee>,
) -> (Spectrum, bool) {
    // A camera ray outside media that finds no surface, in a scene without an environment, ends
    // the path in the loop's first iteration with nothing added and `valid_ray` false, after the
    // hero channel's and the first roulette's samples (the roulette of `beta = 1` at depth 0
    // passes; the stages of `snee` see an escape and do nothing). Those two samples are drawn here
    // without entering the loop; a surface the ray finds is handed to the loop, which then does
    // not trace it again. Same samples, same result.
    if medium.is_none() && scene.environment.is_none() && scene.integrator.max_depth != 0 {
        stats.rays += 1;
        let si = scene.ray_intersect(&ray);
        if si.is_none() {
            let _ = sampler.next_1d();
            let _ = sampler.next_1d();
            return (Spectrum::ZERO, false);
        }
        let weight = Beta { beta: Spectrum::ONE, last_scatter_pdf: 1.0 };
        let stage = snee.map(SneeStage::new);
        return trace_from::<_, _, true>(scene, sampler, ray, medium, stats, weight, stage, &mut NoClasses, si);
    }
    li_tally(scene, sampler, ray, medium, stats, snee, &mut NoClasses)
}

/// [`li_with`], also adding every contribution to `tally` (transport classes, `classes.rs`).
pub fn li_tally<T: Tally>(
    scene: &Scene,
    sampler: &mut Sampler,
    ray: Ray,
    medium: Option<u32>,
    stats: &mut LocalStats,
    snee: Option<&Snee>,
    tally: &mut T,
) -> (Spectrum, bool) {
    let weight = Beta { beta: Spectrum::ONE, last_scatter_pdf: 1.0 };
    trace(scene, sampler, ray, medium, stats, weight, snee.map(SneeStage::new), tally)
}

/// volpath_snee's connection stages as forward tracing's MIS sees them ([`ForwardWeight`]).
struct ConnectionStages<'s, 'a> {
    snee: &'s SneeStage<'a>,
    manifold: Option<&'s ManifoldStage<'a>>,
}

impl ForwardWeight for ConnectionStages<'_, '_> {
    #[inline]
    fn emitter_hit_weight(&self, cx: &mut Cx, hit: &EmitterHit, p_light: &dyn Fn() -> f32, w: f32) -> f32 {
        let (scene, channel, stats) = (cx.scene, cx.channel, &mut *cx.stats);
        let light = || LightSample::hit(hit.ray_d, hit.light_p, hit.ds.dist, p_light());
        let w = self.snee.weight(scene, ForwardTechnique::Bsdf, light, w, channel, stats);
        // An escape right after leaving x_j's medium is shared with the manifold connection.
        self.manifold.and_then(|m| m.weight(scene, self.snee, hit.ray_d, channel, stats)).unwrap_or(w)
    }

    #[inline]
    fn emitter_sampling_weight(&self, cx: &mut Cx, ds: &DirectionSample, w: f32) -> f32 {
        let (scene, channel, stats) = (cx.scene, cx.channel, &mut *cx.stats);
        // Forward NEE at a rough x_k right after x_j is shared with the manifold connection.
        if let Some(w) = self.manifold.and_then(|m| m.nee_weight(scene, ds, channel, stats)) {
            return w;
        }
        self.snee.weight(scene, ForwardTechnique::Nee, || LightSample::sampled(ds), w, channel, stats)
    }
}

/// What the path loop asks of its estimator at each event (`volpath`: [`Beta`]; `volpathmis`: its
/// spectral-MIS densities). Each method draws exactly the samples its estimator draws.
pub trait PathWeight {
    /// Russian roulette and the weight-dependent end of the path at the loop head; `false` ends it.
    fn roulette(&mut self, depth: u32, setup: &PathSetup, eta: f32, sampler: &mut Sampler) -> bool;
    /// A free flight in `m` of sampled length `t` ended at `min(t, t_surface)`, by a real collision
    /// when `scatter`.
    fn flight(&mut self, m: &Homogeneous, t: f32, t_surface: f32, scatter: bool, channel: usize);
    /// A real collision (albedo and the null-or-real decision).
    fn real_scatter(&mut self, m: &Homogeneous);
    /// Emitter sampling at the medium vertex `p` (in `cx.medium`): its contribution.
    fn medium_emitter_sampling(&mut self, cx: &mut Cx, m: &Homogeneous, p: Vec3, wi: Vec3) -> Spectrum;
    /// Phase sampling gave `(weight, pdf)`; `false` ends the path.
    fn phase_sampled(&mut self, phase_weight: f32, phase_pdf: f32) -> bool;
    /// The contribution of an emitter hit by the path.
    fn emitter_hit(&mut self, cx: &mut Cx, hit: &EmitterHit) -> Spectrum;
    /// Emitter sampling at a surface `s` with a smooth BSDF: its contribution and the direction
    /// towards the emitter sample.
    fn surface_emitter_sampling(&mut self, cx: &mut Cx, s: &SurfaceInteraction, bsdf: &Bsdf) -> (Spectrum, Vec3);
    /// Is this BSDF sample usable? (Else the path ends, as a failed sample does.)
    fn accepts(&self, bs: &BsdfSample) -> bool;
    /// The path's `valid_ray` after BSDF sampling failed at `bsdf`.
    fn valid_after_failed_sample(&self, bsdf: &Bsdf, valid_ray: bool) -> bool;
    /// BSDF sampling chose `bs` with `weight` = f·cos/pdf (`non_null`: a real scattering event).
    fn bsdf_sampled(&mut self, bs: &BsdfSample, weight: Spectrum, non_null: bool);
    /// The throughput at the current vertex (for a stage such as SNEE).
    fn beta(&self) -> Spectrum;
}

/// volpath's path weight: the throughput `beta` (Tr / pdf[channel] per flight, as Mitsuba's RGB
/// mode), and the density of the last BSDF / phase sample for the power heuristic.
#[derive(Clone, Copy, Debug)]
pub struct Beta {
    pub beta: Spectrum,
    pub last_scatter_pdf: f32,
}

impl PathWeight for Beta {
    #[inline]
    fn roulette(&mut self, depth: u32, setup: &PathSetup, eta: f32, sampler: &mut Sampler) -> bool {
        let beta_max = self.beta.max_element();
        if !(beta_max > 0.0) || !self.beta.is_finite() {
            return false;
        }
        let q = (beta_max * eta * eta).min(0.95);
        let u_rr = sampler.next_1d();
        if depth > setup.rr_depth {
            if u_rr >= q {
                return false;
            }
            self.beta /= q;
        }
        true
    }

    #[inline]
    fn flight(&mut self, m: &Homogeneous, t: f32, t_surface: f32, scatter: bool, channel: usize) {
        // Spectral transmittance ratio: Tr / pdf[channel].
        let dist = t.min(t_surface);
        if dist.is_finite() {
            let tr = m.transmittance(dist);
            let pdf = if scatter { tr * m.sigma_t } else { tr };
            let p = pdf[channel];
            self.beta *= if p > 0.0 { tr / p } else { Spectrum::ZERO };
        }
    }

    #[inline]
    fn real_scatter(&mut self, m: &Homogeneous) {
        self.beta *= m.sigma_s();
    }

    #[inline(always)]
    fn medium_emitter_sampling(&mut self, cx: &mut Cx, m: &Homogeneous, p: Vec3, wi: Vec3) -> Spectrum {
        let (scene, channel, medium) = (cx.scene, cx.channel, cx.medium);
        let (sampler, stats) = (&mut *cx.sampler, &mut *cx.stats);
        if !m.sample_emitters {
            return Spectrum::ZERO;
        }
        if medium.is_some_and(|mi| scene.emitters_unreachable[mi as usize]) {
            skip_sample_emitter(scene, p, sampler);
            return Spectrum::ZERO;
        }
        let (emitted, ds) = sample_emitter(scene, RefPoint::Medium(p), medium, channel, sampler, stats);
        if emitted == Spectrum::ZERO {
            return Spectrum::ZERO;
        }
        let phase_val = m.phase.eval(wi, ds.d);
        let w = mis_weight(ds.pdf, if ds.delta { 0.0 } else { phase_val });
        w * self.beta * phase_val * emitted
    }

    #[inline]
    fn phase_sampled(&mut self, phase_weight: f32, phase_pdf: f32) -> bool {
        if !(phase_pdf > 0.0) {
            return false;
        }
        self.last_scatter_pdf = phase_pdf;
        self.beta *= phase_weight;
        true
    }

    #[inline]
    fn emitter_hit(&mut self, cx: &mut Cx, hit: &EmitterHit) -> Spectrum {
        let scene = cx.scene;
        // An emitter with zero radiance toward us is no hit (nor a suffix for SNEE to weigh).
        if hit.le == Spectrum::ZERO {
            return Spectrum::ZERO;
        }
        // The emitter-sampling density of this direction, computed at most once.
        let p_light = std::cell::OnceCell::new();
        let p_light = || *p_light.get_or_init(|| scene.pdf_emitter_direction(hit.from, &hit.ds));
        let mut w = if hit.count_direct { 1.0 } else { mis_weight(self.last_scatter_pdf, p_light()) };
        if let Some(stages) = cx.stages.forward {
            w = stages.emitter_hit_weight(cx, hit, &p_light, w);
        }
        self.beta * hit.le * w
    }

    #[inline]
    fn surface_emitter_sampling(&mut self, cx: &mut Cx, s: &SurfaceInteraction, bsdf: &Bsdf) -> (Spectrum, Vec3) {
        let (scene, channel, medium) = (cx.scene, cx.channel, cx.medium);
        let (sampler, stats) = (&mut *cx.sampler, &mut *cx.stats);
        if scene.emitters.is_empty() {
            return (Spectrum::ZERO, Vec3::ZERO);
        }
        let (emitted, ds) = sample_emitter(scene, RefPoint::Surface(s), medium, channel, sampler, stats);
        if emitted == Spectrum::ZERO {
            return (Spectrum::ZERO, ds.d);
        }
        let (bsdf_val, bsdf_pdf) = bsdf.eval_pdf(&BsdfContext::default(), s, s.to_local(ds.d));
        let mut w = mis_weight(ds.pdf, if ds.delta { 0.0 } else { bsdf_pdf });
        if let Some(stages) = cx.stages.forward {
            w = stages.emitter_sampling_weight(cx, &ds, w);
        }
        (self.beta * bsdf_val * w * emitted, ds.d)
    }

    #[inline]
    fn accepts(&self, _: &BsdfSample) -> bool {
        true
    }

    #[inline]
    fn valid_after_failed_sample(&self, bsdf: &Bsdf, valid_ray: bool) -> bool {
        valid_ray | (bsdf.flags() & !flags::NULL != 0)
    }

    #[inline]
    fn bsdf_sampled(&mut self, bs: &BsdfSample, weight: Spectrum, non_null: bool) {
        self.beta *= weight;
        if non_null {
            self.last_scatter_pdf = bs.pdf;
        }
    }

    #[inline]
    fn beta(&self) -> Spectrum {
        self.beta
    }
}

/// The volumetric path loop of `volpath`, `volpathmis` and `volpath_snee` (Mitsuba's volpath):
/// Russian roulette, a free flight through the medium, at a real collision emitter sampling, SNEE
/// and phase sampling; at a surface the emitter hit, emitter sampling and BSDF sampling. `weight`
/// carries the estimator's weights, `snee` the SNEE stage (`volpath_snee` only); every
/// contribution also goes to `tally` (transport classes; [`NoClasses`] does nothing).
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn trace<W: PathWeight, T: Tally>(
    scene: &Scene,
    sampler: &mut Sampler,
    ray: Ray,
    medium: Option<u32>,
    stats: &mut LocalStats,
    weight: W,
    snee: Option<SneeStage>,
    tally: &mut T,
) -> (Spectrum, bool) {
    trace_from::<W, T, false>(scene, sampler, ray, medium, stats, weight, snee, tally, None)
}

/// [`trace`]; with `TRACED`, the caller has traced the first ray already (one starting outside
/// media, which the loop would trace first) and `first_hit` is its `ray_intersect`. A separate
/// copy of the loop, so that [`trace`]'s own is the same as without this option.
#[allow(clippy::too_many_arguments)]
fn trace_from<W: PathWeight, T: Tally, const TRACED: bool>(
    scene: &Scene,
    sampler: &mut Sampler,
    ray: Ray,
    medium: Option<u32>,
    stats: &mut LocalStats,
    mut weight: W,
    mut snee: Option<SneeStage>,
    tally: &mut T,
    first_hit: Option<SurfaceInteraction>,
) -> (Spectrum, bool) {
    debug_assert!(!TRACED || medium.is_none());
    let desc = &scene.integrator;
    let ctx = BsdfContext::default();

    // ---- Path state ----
    let mut ray = ray;
    let mut medium = medium;
    let mut result = Spectrum::ZERO;
    let mut eta = 1.0f32;
    let mut depth = 0u32;
    let mut valid_ray = !desc.hide_emitters && scene.environment.is_some();
    let mut specular_chain = !desc.hide_emitters;
    let setup = PathSetup::new(scene, sampler);
    let PathSetup { max_depth, channel, .. } = setup;
    let mut last_scatter_p = ray.o;
    // The surface hit along the current ray, when already traced.
    let mut needs_intersection = !TRACED;
    let mut si: Option<SurfaceInteraction> = if TRACED { first_hit } else { None };
    // Contributions outside SNEE's suffixes are dropped with transport = snee.
    let keep_all = snee.as_ref().is_none_or(|s| s.keeps_all());
    // Manifold NEE through flat boundaries (volpath_snee with connection = complete).
    let mut manifold = snee.as_ref().and_then(|s| ManifoldStage::new(scene, s.tables()));
    // Emitter splitting at smooth dielectric vertices (connection = complete, manifold/split.rs).
    let mut split = manifold.as_ref().and_then(|_| GlintSplit::new(snee.as_ref()?.tables()));

    loop {
        // ---- Russian roulette and depth limit ----
        if !weight.roulette(depth, &setup, eta, sampler) || depth >= max_depth {
            break;
        }

        // ---- Sample the medium along the ray ----
        let mut escaped_medium = false;
        if let Some(mi) = medium {
            let m = &scene.media[mi as usize];
            let flight = free_flight(scene, m, &ray, channel, &mut si, &mut needs_intersection, sampler, stats);
            let t_surface = si.as_ref().map_or(f32::INFINITY, |s| s.t);
            weight.flight(m, flight.t, t_surface, flight.scatter, channel);
            if flight.scatter {
                // Null-or-real decision (a homogeneous medium is all real: prob_scatter = 1).
                let _ = sampler.next_1d();
                let p = ray.at(flight.t);
                depth += 1;
                last_scatter_p = p;
                if depth >= max_depth {
                    break;
                }
                weight.real_scatter(m);
                let wi = -ray.d;
                valid_ray = true;
                specular_chain = !m.sample_emitters;
                tally.medium_vertex(p, mi);
                if let Some(split) = &mut split {
                    split.at_scatter();
                }

                // ---- Emitter sampling at the medium vertex ----
                let c = weight.medium_emitter_sampling(
                    &mut Cx { scene, channel, medium, sampler, stats, stages: Stages::default() },
                    m,
                    p,
                    wi,
                );
                if keep_all {
                    result += c;
                    tally.add(scene, c, End::MediumNee);
                }

                // ---- Subdivision next-event estimation (volpath_snee) ----
                if let Some(snee) = &mut snee {
                    let v = Scatter { medium: mi, p, wi, depth, max_depth, beta: weight.beta() };
                    let cx = &mut Cx { scene, channel, medium, sampler, stats, stages: Stages::default() };
                    let c = snee.at_scatter(cx, &v);
                    result += c;
                    tally.add(scene, c, End::Snee);

                    // ---- Manifold next-event estimation (connection = complete) ----
                    if let Some(manifold) = &mut manifold {
                        let c = manifold.at_scatter(cx, snee, &v);
                        result += c;
                        tally.add(scene, c, End::Manifold);
                        let c = manifold.chain_at_scatter(cx, &v);
                        result += c;
                        tally.add(scene, c, End::Chain);
                        let c = manifold.beams_at_scatter(cx, &v);
                        result += c;
                        tally.add(scene, c, End::Beam);
                    }
                }

                // ---- Phase function sampling ----
                let (wo, phase_weight, phase_pdf) = m.phase.sample(wi, sampler.next_2d());
                if !weight.phase_sampled(phase_weight, phase_pdf) {
                    break;
                }
                ray = Ray::new(p, wo);
                needs_intersection = true;
                continue;
            }
            escaped_medium = true;
        }

        // ---- Surface interaction ----
        if needs_intersection && !escaped_medium {
            stats.rays += 1;
            si = scene.ray_intersect(&ray);
        }
        needs_intersection = true;
        if let Some(snee) = &mut snee {
            snee.at_surface(scene, si.as_ref(), ray.d);
        }
        if let Some(manifold) = &mut manifold {
            manifold.at_surface(si.as_ref());
        }

        // ---- Emitters hit by the ray (area lights, or the environment on escape) ----
        let count_direct = depth == 0 || specular_chain;
        let hide = depth == 0 && desc.hide_emitters;
        let hit = match &si {
            Some(s) if scene.shapes[s.shape as usize].emitter.is_some() => Some(EmitterHit {
                le: scene.eval_area_emitter(s),
                ds: scene.direction_sample_for_hit(last_scatter_p, s),
                from: last_scatter_p,
                light_p: s.p,
                ray_d: ray.d,
                count_direct,
            }),
            None => scene.environment.map(|env| EmitterHit {
                le: scene.eval_environment(ray.d),
                ds: scene.environment_direction_sample(env, ray.d),
                from: last_scatter_p,
                light_p: last_scatter_p,
                ray_d: ray.d,
                count_direct,
            }),
            _ => None,
        };
        let connection = snee.as_ref().map(|snee| ConnectionStages { snee, manifold: manifold.as_ref() });
        let stages = Stages { forward: connection.as_ref().map(|c| c as &dyn ForwardWeight) };
        if let (false, Some(hit)) = (hide, hit) {
            let mut c = weight.emitter_hit(&mut Cx { scene, channel, medium, sampler, stats, stages }, &hit);
            if let Some(split) = &mut split {
                c *= split.take_hit_scale();
            }
            result += c;
            tally.add(scene, c, End::Hit);
        }
        let Some(s) = si else { break };
        let bsdf = scene.bsdf(&s);

        // ---- Emitter sampling at the surface ----
        if bsdf.flags() & flags::SMOOTH != 0 && depth + 1 < max_depth {
            let cx = &mut Cx { scene, channel, medium, sampler, stats, stages };
            let (c, light_d) = weight.surface_emitter_sampling(cx, &s, bsdf);
            result += c;
            tally.add(scene, c, End::SurfaceNee { s: &s, d: ray.d, light_d });
        }

        // ---- BSDF sampling ----
        let s1 = sampler.next_1d();
        let s2 = sampler.next_2d();
        let sample = bsdf.sample(&ctx, &s, s1, s2).filter(|(bs, _)| weight.accepts(bs));
        let Some((bs, bsdf_weight)) = sample else {
            valid_ray = weight.valid_after_failed_sample(bsdf, valid_ray);
            break;
        };
        eta *= bs.eta;
        let wo = s.to_world(bs.wo);
        if let Some(split) = &mut split {
            let beta = weight.beta();
            if let Some((c, d)) = split.at_bsdf_sample(scene, &s, bsdf, &bs, wo, medium, beta, depth, max_depth, stats)
            {
                result += c;
                tally.add(scene, c, End::SurfaceNee { s: &s, d: ray.d, light_d: d });
            }
        }
        let non_null = bs.sampled_type & flags::NULL == 0;
        if non_null {
            tally.surface_vertex(&s, ray.d, bs.sampled_type & flags::TRANSMISSION != 0);
        }
        ray = s.spawn_ray(wo);
        weight.bsdf_sampled(&bs, bsdf_weight, non_null);
        if let Some(snee) = &mut snee {
            snee.after_bsdf(scene, &s, &bs, wo);
        }
        if let Some(manifold) = &mut manifold {
            manifold.after_bsdf(scene, &s, &bs, wo);
        }
        if non_null {
            depth += 1;
            last_scatter_p = s.p;
            valid_ray = true;
            if bs.sampled_type & flags::DELTA != 0 {
                specular_chain = true;
            }
        }
        if bs.sampled_type & flags::SMOOTH != 0 {
            specular_chain = false;
        }
        if is_medium_transition(scene, &s) {
            medium = target_medium(scene, &s, wo);
        }
        si = None;
    }
    (result, valid_ray)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::build::build_scene;
    use crate::scene::xml::parse_file;
    use std::path::Path;

    /// `skip_sample_emitter` decided without sampling (`surely_usable`: here a constant environment
    /// and a rectangle light) draws exactly what the emitter sample would make it draw, at points
    /// inside the glass sphere, around the light's plane (both sides, down to 1e-6 from it) and far away.
    #[test]
    fn skip_decides_as_the_emitter_sample_does_for_flat_lights_and_environments() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR"));
        let parsed = parse_file(&root.join("scenes/media_rough_glass.xml"), &[]).expect("parse");
        let scene = build_scene(&parsed).expect("build");
        let plane = scene
            .shapes
            .iter()
            .find_map(|s| match (&s.geometry, s.emitter) {
                (Geometry::Mesh(m), Some(_)) => m.plane,
                _ => None,
            })
            .expect("the rectangle light is flat");
        let mut points = Sampler::new(13, 0);
        let (mut usable, mut unusable, mut surely) = (0, 0, 0);
        for i in 0..100_000u64 {
            let u = Vec3::new(points.next_1d(), points.next_1d(), points.next_1d());
            let p = match i % 4 {
                0 => Vec3::new(0.0, 0.65, 0.0) + (u * 2.0 - Vec3::ONE) * 0.6,
                1 => plane.center + (u * 2.0 - Vec3::ONE) * 3.0,
                2 => {
                    let h = (points.next_1d() - 0.5) * 10f32.powf(-6.0 * points.next_1d());
                    plane.center + (u * 2.0 - Vec3::ONE) * plane.radius * 2.0 + plane.n * h
                }
                _ => (u * 2.0 - Vec3::ONE) * 1e6,
            };
            let mut skip = Sampler::new(17, i);
            let mut full = skip.clone();
            let sure = surely_usable(&scene, p, full.clone().next_2d());
            skip_sample_emitter(&scene, p, &mut skip);
            let (ds, emitted) = scene.sample_emitter_direction(p, None, full.next_2d(), false);
            if ds.pdf != 0.0 && emitted != Spectrum::ZERO {
                let _ = full.next_1d();
                usable += 1;
                surely += sure as u32;
            } else {
                unusable += 1;
                assert!(!sure, "an unusable sample decided usable at {p} ({i})");
            }
            assert_eq!(skip.next_1d(), full.next_1d(), "sample streams diverge at {p} ({i})");
        }
        // Both outcomes occur (behind the one-sided light no sample is usable), and most usable
        // samples are decided without sampling.
        assert!(usable > 1000 && unusable > 1000, "{usable} usable, {unusable} not");
        assert!(surely > usable / 2, "{surely} of {usable} decided without sampling");
    }
}

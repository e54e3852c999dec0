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

use super::manifold; // manifold NEE hook
use super::snee::{self, ForwardTechnique, LightSample, SneeOptions, SneeSuffix, SneeTechnique, SneeVertex};
use super::stats::LocalStats;
use crate::bsdf::{flags, BsdfContext};
use crate::color::Spectrum;
use crate::interaction::{offset_origin, spawn_ray_between, DirectionSample, SurfaceInteraction};
use crate::math::{mis_weight, Ray, Vec3};
use crate::sampler::Sampler;
use crate::scene::world::Scene;

/// Upper bound on surface crossings of one shadow ray (guards against degenerate geometry).
const MAX_SHADOW_SEGMENTS: u32 = 256;

/// The medium on the side of `si` that direction `d` points into (Mitsuba's `target_medium`).
#[inline]
pub fn target_medium(scene: &Scene, si: &SurfaceInteraction, d: Vec3) -> Option<u32> {
    let s = &scene.shapes[si.shape as usize];
    if d.dot(si.n) > 0.0 {
        s.exterior
    } else {
        s.interior
    }
}

/// True when the shape of `si` separates two media (Mitsuba's `is_medium_transition`).
#[inline]
pub fn is_medium_transition(scene: &Scene, si: &SurfaceInteraction) -> bool {
    let s = &scene.shapes[si.shape as usize];
    s.interior.is_some() || s.exterior.is_some()
}

/// Where a shadow ray starts: a surface point (offset along its normal) or a medium point.
#[derive(Clone, Copy, Debug)]
pub enum RefPoint<'a> {
    Surface(&'a SurfaceInteraction),
    Medium(Vec3),
}

impl RefPoint<'_> {
    #[inline]
    pub fn p(&self) -> Vec3 {
        match self {
            RefPoint::Surface(si) => si.p,
            RefPoint::Medium(p) => *p,
        }
    }
}

/// Sample an emitter from `r` and estimate the transmittance to it (Mitsuba's
/// `VolumetricPathIntegrator::sample_emitter`). Returns (emitted · transmittance / pdf, ds).
pub fn sample_emitter(
    scene: &Scene,
    r: RefPoint,
    mut medium: Option<u32>,
    channel: usize,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> (Spectrum, DirectionSample) {
    let (ds, emitted) = scene.sample_emitter_direction(r.p(), None, sampler.next_2d(), false);
    if ds.pdf == 0.0 || emitted == Spectrum::ZERO {
        return (Spectrum::ZERO, ds);
    }
    let mut ray = match r {
        RefPoint::Surface(si) => {
            let o = offset_origin(si.p, si.n, ds.d);
            if is_medium_transition(scene, si) {
                medium = target_medium(scene, si, ds.d);
            }
            if ds.dist.is_finite() {
                spawn_ray_between(o, ds.p)
            } else {
                Ray::new(o, ds.d)
            }
        }
        RefPoint::Medium(p) => {
            if ds.dist.is_finite() {
                spawn_ray_between(p, ds.p)
            } else {
                Ray::new(p, ds.d)
            }
        }
    };
    let tr = shadow_transmittance(scene, &mut ray, medium, channel, sampler, stats);
    (emitted * tr, ds)
}

/// Transmittance along a shadow ray up to `ray.tmax`, through null / thin-dielectric interfaces
/// and homogeneous media (track-length estimate in `channel`, as Mitsuba's RGB mode does).
pub fn shadow_transmittance(
    scene: &Scene,
    ray: &mut Ray,
    mut medium: Option<u32>,
    channel: usize,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> Spectrum {
    let mut tr = Spectrum::ONE;
    let mut remaining = ray.tmax;
    for _ in 0..MAX_SHADOW_SEGMENTS {
        if !(remaining > 0.0) {
            break;
        }
        ray.tmax = remaining;
        stats.rays += 1;
        let si = scene.ray_intersect(ray);
        let seg = si.as_ref().map_or(remaining, |s| s.t);
        if let Some(m) = medium {
            let m = &scene.media[m as usize];
            let t = m.sample_distance(sampler.next_1d(), channel);
            if t < seg {
                // A real collision: homogeneous media have no null density, the estimate is 0.
                return Spectrum::ZERO;
            }
            if seg.is_finite() {
                let t_seg = m.transmittance(seg);
                let p = t_seg[channel];
                if !(p > 0.0) {
                    return Spectrum::ZERO;
                }
                tr *= t_seg / p;
            }
        }
        let Some(si) = si else { break };
        let bsdf = scene.bsdf(&si);
        tr *= bsdf.eval_null_transmission(&si);
        if tr == Spectrum::ZERO {
            return tr;
        }
        if is_medium_transition(scene, &si) {
            medium = target_medium(scene, &si, ray.d);
        }
        remaining -= si.t;
        ray.o = offset_origin(si.p, si.n, ray.d);
    }
    tr
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

/// The weight of a forward contribution that may end a SNEE suffix (docs/snee.md §3): volpath's
/// `w_volpath` without SNEE; otherwise the joint MIS weight for suffixes in SNEE's support, and
/// `w_volpath` (transport = all) or 0 (transport = snee) for the others.
#[allow(clippy::too_many_arguments)]
#[inline]
fn suffix_weight(
    scene: &Scene,
    snee: Option<SneeOptions>,
    suffix: Option<&SneeSuffix>,
    light: impl FnOnce() -> LightSample,
    technique: ForwardTechnique,
    w_volpath: f32,
    channel: usize,
    stats: &mut LocalStats,
) -> f32 {
    let Some(opts) = snee else { return w_volpath };
    let w = match suffix {
        Some(s) if opts.needs_suffix_pdf() => {
            snee::forward_weight(scene, opts, s, &light(), technique, w_volpath, channel, stats)
        }
        _ => None,
    };
    match w {
        Some(w) => w,
        None if opts.keeps_all() => w_volpath,
        None => 0.0,
    }
}

/// volpath's loop; with `snee`, the `volpath_snee` integrator (SNEE as one stage, and the MIS
/// weights of forward suffixes that SNEE can also produce). With `None` this is Mitsuba's volpath.
pub fn li_with(
    scene: &Scene,
    sampler: &mut Sampler,
    ray: Ray,
    medium: Option<u32>,
    stats: &mut LocalStats,
    snee: Option<SneeOptions>,
) -> (Spectrum, bool) {
    let desc = &scene.integrator;
    let max_depth = if desc.max_depth < 0 { u32::MAX } else { desc.max_depth as u32 };
    let rr_depth = desc.rr_depth as u32;
    let ctx = BsdfContext::default();

    // ---- Path state ----
    let mut ray = ray;
    let mut medium = medium;
    let mut beta = Spectrum::ONE;
    let mut result = Spectrum::ZERO;
    let mut eta = 1.0f32;
    let mut depth = 0u32;
    let mut valid_ray = !desc.hide_emitters && scene.environment.is_some();
    let mut specular_chain = !desc.hide_emitters;
    let channel = ((sampler.next_1d() * 3.0) as usize).min(2);
    let mut last_scatter_p = ray.o;
    let mut last_scatter_pdf = 1.0f32;
    // The surface hit along the current ray, when already traced.
    let mut si: Option<SurfaceInteraction> = None;
    let mut needs_intersection = true;
    // ---- SNEE state (docs/snee.md §3) ----
    // Contributions outside SNEE's suffixes are dropped with transport = snee.
    let keep_all = snee.is_none_or(|o| o.keeps_all());
    // x_i: the last real scatter, when SNEE runs there and no surface event followed.
    let mut snee_x_i: Option<SneeVertex> = None;
    // (x_i, x_j): the scatter x_j directly after a SNEE vertex x_i.
    let mut snee_chain: Option<(SneeVertex, Vec3)> = None;
    // The suffix x_i → x_j → x_k at the current boundary vertex, and after BSDF sampling there.
    let mut snee_at_k: Option<SneeSuffix>;
    let mut snee_pending: Option<SneeSuffix> = None;
    let mut manifold_tracker = manifold::Tracker::default(); // manifold NEE hook

    loop {
        // ---- Russian roulette and depth limit ----
        let beta_max = beta.max_element();
        if !(beta_max > 0.0) || !beta.is_finite() {
            break;
        }
        let q = (beta_max * eta * eta).min(0.95);
        let u_rr = sampler.next_1d();
        if depth > rr_depth {
            if u_rr >= q {
                break;
            }
            beta /= q;
        }
        if depth >= max_depth {
            break;
        }

        // ---- Sample the medium along the ray ----
        let mut escaped_medium = false;
        if let Some(mi) = medium {
            let m = &scene.media[mi as usize];
            let t = m.sample_distance(sampler.next_1d(), channel);
            if needs_intersection {
                let mut r = ray;
                r.tmax = if t.is_finite() { t } else { f32::INFINITY };
                stats.rays += 1;
                si = scene.ray_intersect(&r);
                needs_intersection = false;
            }
            let t_surface = si.as_ref().map_or(f32::INFINITY, |s| s.t);
            let scatter = t < t_surface;
            // Spectral transmittance ratio: Tr / pdf[channel].
            let dist = t.min(t_surface);
            if dist.is_finite() {
                let tr = m.transmittance(dist);
                let pdf = if scatter { tr * m.sigma_t } else { tr };
                let p = pdf[channel];
                beta *= if p > 0.0 { tr / p } else { Spectrum::ZERO };
            }
            if scatter {
                // Null-or-real decision (a homogeneous medium is all real: prob_scatter = 1).
                let _ = sampler.next_1d();
                let p = ray.at(t);
                depth += 1;
                last_scatter_p = p;
                if depth >= max_depth {
                    break;
                }
                beta *= m.sigma_s();
                let wi = -ray.d;

                // ---- Emitter sampling at the medium vertex ----
                valid_ray = true;
                specular_chain = !m.sample_emitters;
                if m.sample_emitters {
                    let (emitted, ds) = sample_emitter(scene, RefPoint::Medium(p), medium, channel, sampler, stats);
                    if emitted != Spectrum::ZERO && keep_all {
                        let phase_val = m.phase.eval(wi, ds.d);
                        let w = mis_weight(ds.pdf, if ds.delta { 0.0 } else { phase_val });
                        result += w * beta * phase_val * emitted;
                    }
                }

                // ---- Subdivision next-event estimation (volpath_snee) ----
                if let Some(opts) = snee {
                    snee_chain = snee_x_i.take().map(|x_i| (x_i, p));
                    snee_x_i = snee::snee_vertex(scene, opts, mi, p, wi, depth, max_depth);
                    if let (Some(x_i), true) = (&snee_x_i, opts.technique != SneeTechnique::Forward) {
                        result += snee::sample(scene, x_i, beta, channel, opts.technique, sampler, stats);
                    }
                    // manifold NEE hook (2 lines): the connection through the boundary from x_j.
                    let (x_j, x_i) = (manifold::MediumVertex { p, wi, medium: mi }, snee_chain.as_ref().map(|c| &c.0));
                    result +=
                        manifold_tracker.sample(scene, opts, x_i, x_j, beta, depth, max_depth, channel, sampler, stats);
                }

                // ---- Phase function sampling ----
                let (wo, phase_weight, phase_pdf) = m.phase.sample(wi, sampler.next_2d());
                if !(phase_pdf > 0.0) {
                    break;
                }
                ray = Ray::new(p, wo);
                needs_intersection = true;
                last_scatter_pdf = phase_pdf;
                beta *= phase_weight;
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
        // A surface event ends SNEE chains; it is x_k when it follows x_i → x_j on an enclosing boundary.
        snee_x_i = None;
        snee_at_k = match (snee_chain.take(), &si) {
            (Some((x_i, x_j)), Some(s)) if snee::encloses(scene, s, x_i.medium, ray.d) => {
                Some(SneeSuffix { x_i, x_j, si_k: *s })
            }
            _ => None,
        };
        let pending = snee_pending.take();
        let manifold_pending = manifold_tracker.surface_event(); // manifold NEE hook

        // ---- Emitters hit by the ray (area lights, or the environment on escape) ----
        let count_direct = depth == 0 || specular_chain;
        let hide = depth == 0 && desc.hide_emitters;
        // The emitter hit, as (radiance, direction sample from the last scattering vertex, the point
        // used for SNEE's light record). An area light with zero radiance toward us is no hit.
        let hit = match &si {
            Some(s) if scene.shapes[s.shape as usize].emitter.is_some() => {
                let le = scene.eval_area_emitter(s);
                (le != Spectrum::ZERO).then(|| (le, scene.direction_sample_for_hit(last_scatter_p, s), s.p))
            }
            None => scene.environment.map(|env| {
                (scene.eval_environment(ray.d), scene.environment_direction_sample(env, ray.d), last_scatter_p)
            }),
            _ => None,
        };
        if let (false, Some((le, ds, light_p))) = (hide, hit) {
            // The emitter-sampling density of this direction, computed at most once.
            let p_light = std::cell::OnceCell::new();
            let p_light = || *p_light.get_or_init(|| scene.pdf_emitter_direction(last_scatter_p, &ds));
            let w = if count_direct { 1.0 } else { mis_weight(last_scatter_pdf, p_light()) };
            let light = || LightSample {
                omega_l: ray.d,
                p: light_p,
                dist: ds.dist,
                p_light: p_light(),
                delta: false,
                le: Spectrum::ZERO,
            };
            let w = suffix_weight(scene, snee, pending.as_ref(), light, ForwardTechnique::Bsdf, w, channel, stats);
            // manifold NEE hook (2 lines): an escape right after leaving x_j's medium is shared with it.
            let (mp, escaped) = (manifold_pending.as_ref(), si.is_none());
            let w = manifold::forward_weight(scene, snee, mp, pending.as_ref(), escaped, ray.d, channel, stats)
                .unwrap_or(w);
            result += beta * le * w;
        }
        let Some(s) = si else { break };
        let bsdf = scene.bsdf(&s);

        // ---- Emitter sampling at the surface ----
        if bsdf.flags() & flags::SMOOTH != 0 && depth + 1 < max_depth && !scene.emitters.is_empty() {
            let (emitted, ds) = sample_emitter(scene, RefPoint::Surface(&s), medium, channel, sampler, stats);
            if emitted != Spectrum::ZERO {
                let wo = s.to_local(ds.d);
                let (bsdf_val, bsdf_pdf) = bsdf.eval_pdf(&ctx, &s, wo);
                let w = mis_weight(ds.pdf, if ds.delta { 0.0 } else { bsdf_pdf });
                let light = || LightSample {
                    omega_l: ds.d,
                    p: ds.p,
                    dist: ds.dist,
                    p_light: ds.pdf,
                    delta: ds.delta,
                    le: Spectrum::ZERO,
                };
                let w = suffix_weight(scene, snee, snee_at_k.as_ref(), light, ForwardTechnique::Nee, w, channel, stats);
                result += beta * bsdf_val * w * emitted;
            }
        }

        // ---- BSDF sampling ----
        let s1 = sampler.next_1d();
        let s2 = sampler.next_2d();
        let Some((bs, weight)) = bsdf.sample(&ctx, &s, s1, s2) else {
            valid_ray |= bsdf.flags() & !flags::NULL != 0;
            break;
        };
        beta *= weight;
        eta *= bs.eta;
        let wo = s.to_world(bs.wo);
        ray = s.spawn_ray(wo);
        let non_null = bs.sampled_type & flags::NULL == 0;
        if bs.sampled_type & flags::TRANSMISSION != 0 && non_null && wo.dot(s.n) > 0.0 {
            snee_pending = snee_at_k;
        } else if !non_null && snee::passable(scene, &s) {
            // A light segment x_k → emitter may cross passable interfaces (docs/snee.md §1).
            snee_pending = pending;
        }
        if non_null {
            depth += 1;
            last_scatter_p = s.p;
            last_scatter_pdf = bs.pdf;
            valid_ray = true;
            if bs.sampled_type & flags::DELTA != 0 {
                specular_chain = true;
            }
        }
        if bs.sampled_type & flags::SMOOTH != 0 {
            specular_chain = false;
        }
        manifold_tracker.after_bsdf(scene, &s, bs.sampled_type, wo, manifold_pending); // manifold NEE hook
        if is_medium_transition(scene, &s) {
            medium = target_medium(scene, &s, wo);
        }
        si = None;
    }
    (result, valid_ray)
}

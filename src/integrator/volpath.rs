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

use super::snee::{ForwardTechnique, LightSample, Snee, SneeStage};
use super::stats::LocalStats;
use super::walk::{free_flight, is_medium_transition, shadow_ray, target_medium, walk_segments, PathSetup, RefPoint};
use crate::bsdf::{flags, BsdfContext};
use crate::color::Spectrum;
use crate::interaction::{DirectionSample, SurfaceInteraction};
use crate::math::{mis_weight, Ray};
use crate::sampler::Sampler;
use crate::scene::world::Scene;

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
    let tr = shadow_transmittance(scene, ray, medium, channel, sampler, stats);
    (emitted * tr, ds)
}

/// Transmittance along a shadow ray up to `ray.tmax`, through null / thin-dielectric interfaces
/// and homogeneous media (track-length estimate in `channel`, as Mitsuba's RGB mode does).
pub fn shadow_transmittance(
    scene: &Scene,
    ray: Ray,
    medium: Option<u32>,
    channel: usize,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> Spectrum {
    let mut tr = Spectrum::ONE;
    walk_segments(scene, ray, medium, stats, |medium, seg, si| {
        if let Some(m) = medium {
            let m = &scene.media[m as usize];
            let t = m.sample_distance(sampler.next_1d(), channel);
            if t < seg {
                // A real collision: homogeneous media have no null density, the estimate is 0.
                tr = Spectrum::ZERO;
                return false;
            }
            if seg.is_finite() {
                let t_seg = m.transmittance(seg);
                let p = t_seg[channel];
                if !(p > 0.0) {
                    tr = Spectrum::ZERO;
                    return false;
                }
                tr *= t_seg / p;
            }
        }
        let Some(si) = si else { return false };
        tr *= scene.bsdf(si).eval_null_transmission(si);
        tr != Spectrum::ZERO
    });
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

/// volpath's loop; with `snee`, the `volpath_snee` integrator (SNEE as one stage,
/// [`SneeStage`], which also weighs the forward suffixes SNEE can produce). With `None` this is
/// Mitsuba's volpath.
pub fn li_with(
    scene: &Scene,
    sampler: &mut Sampler,
    ray: Ray,
    medium: Option<u32>,
    stats: &mut LocalStats,
    snee: Option<&Snee>,
) -> (Spectrum, bool) {
    let desc = &scene.integrator;
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
    let PathSetup { max_depth, rr_depth, channel } = PathSetup::new(scene, sampler);
    let mut last_scatter_p = ray.o;
    let mut last_scatter_pdf = 1.0f32;
    // The surface hit along the current ray, when already traced.
    let mut si: Option<SurfaceInteraction> = None;
    let mut needs_intersection = true;
    // ---- Connection techniques beside emitter and BSDF / phase sampling ----
    let mut snee = snee.map(SneeStage::new);
    // Contributions outside SNEE's suffixes are dropped with transport = snee.
    let keep_all = snee.as_ref().is_none_or(|s| s.keeps_all());

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
            let flight = free_flight(scene, m, &ray, channel, &mut si, &mut needs_intersection, sampler, stats);
            let t_surface = si.as_ref().map_or(f32::INFINITY, |s| s.t);
            // Spectral transmittance ratio: Tr / pdf[channel].
            let dist = flight.t.min(t_surface);
            if dist.is_finite() {
                let tr = m.transmittance(dist);
                let pdf = if flight.scatter { tr * m.sigma_t } else { tr };
                let p = pdf[channel];
                beta *= if p > 0.0 { tr / p } else { Spectrum::ZERO };
            }
            if flight.scatter {
                // Null-or-real decision (a homogeneous medium is all real: prob_scatter = 1).
                let _ = sampler.next_1d();
                let p = ray.at(flight.t);
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
                if let Some(snee) = &mut snee {
                    result += snee.at_scatter(scene, mi, p, wi, depth, max_depth, beta, channel, sampler, stats);
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
        if let Some(snee) = &mut snee {
            snee.at_surface(scene, si.as_ref(), ray.d);
        }

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
            let mut w = if count_direct { 1.0 } else { mis_weight(last_scatter_pdf, p_light()) };
            if let Some(snee) = &snee {
                let light = || LightSample::hit(ray.d, light_p, ds.dist, p_light());
                w = snee.weight(scene, ForwardTechnique::Bsdf, light, w, channel, stats);
            }
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
                let mut w = mis_weight(ds.pdf, if ds.delta { 0.0 } else { bsdf_pdf });
                if let Some(snee) = &snee {
                    w = snee.weight(scene, ForwardTechnique::Nee, || LightSample::sampled(&ds), w, channel, stats);
                }
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
        if let Some(snee) = &mut snee {
            snee.after_bsdf(scene, &s, &bs, wo);
        }
        if bs.sampled_type & flags::NULL == 0 {
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
        if is_medium_transition(scene, &s) {
            medium = target_medium(scene, &s, wo);
        }
        si = None;
    }
    (result, valid_ray)
}

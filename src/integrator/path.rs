//! Mitsuba's `path` integrator: unidirectional path tracing with next-event estimation and BSDF
//! sampling combined by the power heuristic, Russian roulette from `rr_depth`, `max_depth`
//! (-1 unbounded, 1 = directly visible emitters only) and `hide_emitters`. Ignores media.
//!
//! ```xml
//! <integrator type="path"><integer name="max_depth" value="8"/></integrator>
//! ```

use super::stats::LocalStats;
use crate::bsdf::{flags, BsdfContext};
use crate::color::Spectrum;
use crate::math::{mis_weight, Ray};
use crate::sampler::Sampler;
use crate::scene::world::{Scene, SceneEmitter};

/// Radiance along `ray` (one sample), and whether the camera ray hit a surface (the alpha channel).
pub fn li(scene: &Scene, sampler: &mut Sampler, ray: Ray, stats: &mut LocalStats) -> (Spectrum, bool) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports AVX2 and FMA (checked just above).
        return unsafe { li_avx2(scene, sampler, ray, stats) };
    }
    li_impl(scene, sampler, ray, stats)
}

/// [`li`] compiled for AVX2 and FMA (three-operand vector code for the loop and what is built
/// into it: emitter and diffuse sampling, the shadow-ray setup). Rust never fuses a separate
/// multiply and add, so the numbers are those of the baseline build.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn li_avx2(scene: &Scene, sampler: &mut Sampler, ray: Ray, stats: &mut LocalStats) -> (Spectrum, bool) {
    li_impl(scene, sampler, ray, stats)
}

/// The loop of [`li`], built whole into each of its two variants.
#[inline(always)]
fn li_impl(scene: &Scene, sampler: &mut Sampler, ray: Ray, stats: &mut LocalStats) -> (Spectrum, bool) {
    let desc = &scene.integrator;
    let max_depth = if desc.max_depth < 0 { u32::MAX } else { desc.max_depth as u32 };
    let rr_depth = desc.rr_depth.max(0) as u32;
    let ctx = BsdfContext::default();

    // ---- Path state ----
    let mut ray = ray;
    let mut beta = Spectrum::ONE;
    let mut result = Spectrum::ZERO;
    let mut eta = 1.0f32;
    let mut depth = 0u32;
    // Previous vertex (for MIS when an emitter is hit by BSDF sampling).
    let mut prev_p = ray.o;
    let mut prev_bsdf_pdf = 1.0f32;
    let mut prev_bsdf_delta = true;

    // Mitsuba's `valid_ray`: a path that never scatters off a non-null surface (and sees no
    // environment) contributes nothing, not even the emission of null surfaces it crossed.
    let mut valid = !desc.hide_emitters && scene.environment.is_some();
    if max_depth == 0 {
        return (result, valid);
    }
    loop {
        stats.rays += 1;
        let si = scene.ray_intersect(&ray);

        // ---- Emission: environment (on escape) or area emitter (on hit) ----
        let hide = desc.hide_emitters && depth == 0;
        match &si {
            None => {
                if !hide {
                    if let Some(SceneEmitter::Other(env)) = scene.environment.map(|e| &scene.emitters[e as usize]) {
                        // Radiance and (after non-delta scattering) the emitter-sampling density of
                        // the escape direction, which the envmap maps to its image once for both.
                        let (le, pdf) = env.eval_environment_pdf(ray.d, !prev_bsdf_delta);
                        let mis = if prev_bsdf_delta {
                            1.0
                        } else {
                            mis_weight(prev_bsdf_pdf, pdf * scene.emitter_selection_pdf())
                        };
                        result += beta * le * mis;
                    }
                }
                break;
            }
            Some(si) => {
                if !hide && scene.shapes[si.shape as usize].emitter.is_some() {
                    let le = scene.eval_area_emitter(si);
                    if le != Spectrum::ZERO {
                        let mis = if prev_bsdf_delta {
                            1.0
                        } else {
                            let ds = scene.direction_sample_for_hit(prev_p, si);
                            mis_weight(prev_bsdf_pdf, scene.pdf_emitter_direction(prev_p, &ds))
                        };
                        result += beta * le * mis;
                    }
                }
            }
        }
        let Some(si) = si else { break };
        if depth + 1 >= max_depth {
            break;
        }
        let bsdf = scene.bsdf(&si);
        let bsdf_flags = bsdf.flags();

        // ---- Emitter sampling (next-event estimation) ----
        let em_sample = sampler.next_2d();
        if bsdf_flags & flags::SMOOTH != 0 && !scene.emitters.is_empty() {
            stats.rays += 1;
            let (ds, em_weight) = scene.sample_emitter_direction_inline(si.p, Some(si.n), em_sample, false);
            if ds.pdf > 0.0 && em_weight != Spectrum::ZERO {
                let wo = si.to_local(ds.d);
                let (bsdf_val, bsdf_pdf) = bsdf.eval_pdf_inline(&ctx, &si, wo);
                // A zero BSDF value (e.g. the light below a diffuse surface) adds nothing whether
                // or not the light is visible: the shadow ray is traced for non-zero values only.
                if bsdf_val != Spectrum::ZERO && scene.emitter_visible_inline(si.p, Some(si.n), &ds) {
                    let mis = if ds.delta { 1.0 } else { mis_weight(ds.pdf, bsdf_pdf) };
                    result += beta * em_weight * bsdf_val * mis;
                }
            }
        }

        // ---- BSDF sampling ----
        let s1 = sampler.next_1d();
        let s2 = sampler.next_2d();
        let Some((bs, bsdf_weight)) = bsdf.sample_inline(&ctx, &si, s1, s2) else {
            // A failed (zero-weight) sample of a non-null BSDF still makes the path valid (Mitsuba).
            valid |= bsdf_flags & !flags::NULL != 0;
            break;
        };
        beta *= bsdf_weight;
        eta *= bs.eta;
        valid |= bs.sampled_type & flags::NULL == 0;
        let wo_world = si.to_world(bs.wo);
        ray = si.spawn_ray(wo_world);
        prev_p = si.p;
        prev_bsdf_pdf = bs.pdf;
        prev_bsdf_delta = bs.sampled_type & flags::DELTA != 0;
        depth += 1;

        // ---- Russian roulette ----
        let beta_max = beta.max_element();
        // Not positive, NaN or infinite (one comparison each way: cheaper than `is_finite`).
        if !(beta_max > 0.0 && beta_max < f32::INFINITY) {
            break;
        }
        if depth >= rr_depth {
            let q = (beta_max * eta * eta).min(0.95);
            if sampler.next_1d() >= q {
                break;
            }
            beta /= q;
        }
    }
    (if valid { result } else { Spectrum::ZERO }, valid)
}

//! SNEE's sampling at `x_i` (docs/snee.md §2): the probe to `x_k` (Eq. 5), the emitter sample at
//! `x_k`, the subdivision vertex `x_j` top-to-bottom (Eq. 6) or bottom-to-top (Eq. 7), and the
//! throughput of the suffix `x_i → x_j → x_k → emitter` (§1), weighted by MIS (§3).

use super::distance::DistanceSampler;
use super::light::{light_along, sample_light, segment_clear};
use super::mis::suffix_weights;
use super::options::Snee;
use super::pdf::suffix_pdfs;
use super::rate::mixture;
use super::{encloses, with_wi, Boundary, SneeSuffix, SneeVertex};
use crate::bsdf::fresnel::{fresnel, refract};
use crate::bsdf::{flags, BsdfContext, TransportMode};
use crate::color::Spectrum;
use crate::integrator::manifold;
use crate::integrator::stats::LocalStats;
use crate::interaction::offset_origin;
use crate::math::{warp, Ray, Vec2};
use crate::sampler::Sampler;
use crate::scene::world::Scene;

/// The SNEE stage at `x_i`: one subdivision sample, MIS-weighted against forward tracing.
/// `beta` is the path throughput at `x_i` (including `sigma_s(x_i)`).
pub fn sample(
    scene: &Scene,
    x_i: &SneeVertex,
    beta: Spectrum,
    channel: usize,
    snee: &Snee,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> Spectrum {
    // Fixed sample budget per SNEE call.
    let u_rate = sampler.next_1d();
    let u_probe = sampler.next_2d();
    let u_strategy = sampler.next_1d();
    let u_light = sampler.next_2d();
    let u_dir1 = sampler.next_1d();
    let u_dir = sampler.next_2d();
    let u_t = sampler.next_1d();
    // SNEE runs with probability r; its density in MIS is r · pdf_snee (pdf_snee includes r).
    if !(u_rate < x_i.rate) {
        return Spectrum::ZERO;
    }
    let f = sample_impl(scene, snee, x_i, channel, [u_probe, u_light, u_dir], [u_strategy, u_dir1, u_t], stats);
    let c = beta * f;
    if !crate::color::is_finite(c) {
        stats.rejected_samples += 1;
        return Spectrum::ZERO;
    }
    c
}

/// The SNEE estimate `w_snee · f / pdf_snee` (without `beta`), or zero for a failed sample.
fn sample_impl(
    scene: &Scene,
    snee: &Snee,
    x_i: &SneeVertex,
    channel: usize,
    u2: [Vec2; 3],
    u1: [f32; 3],
    stats: &mut LocalStats,
) -> Spectrum {
    let [u_probe, u_light, u_dir] = u2;
    let [u_strategy, u_dir1, u_t] = u1;
    let m = &scene.media[x_i.medium as usize];
    let st = m.sigma_t[channel];

    // ---- Probe: x_k (Eq. 5) ----
    stats.snee_attempts += 1;
    let omega_ik = warp::square_to_uniform_sphere(u_probe);
    stats.rays += 1;
    let probe = scene
        .ray_intersect(&Ray::new(x_i.p, omega_ik))
        .filter(|si_k| encloses(scene, si_k, x_i.medium, omega_ik))
        .and_then(|si_k| Boundary::of(scene.bsdf(&si_k)).map(|b| (si_k, b)));
    let Some((si_k, boundary)) = probe else {
        stats.snee_probe_failures += 1;
        return Spectrum::ZERO;
    };
    let bsdf = scene.bsdf(&si_k);
    let (c_down, _) = mixture(snee, boundary);
    let down = u_strategy < c_down;

    // ---- Emitter sample at x_k (↓, and ↑ at a rough boundary) ----
    let mut light = None;
    if down || matches!(boundary, Boundary::Rough) {
        light = sample_light(scene, &si_k, u_light, stats);
        if light.is_none() {
            return Spectrum::ZERO;
        }
    }

    // ---- Subdivision: x_j (↓ Eq. 6 or ↑ Eq. 7) ----
    let x_j = if down {
        let Some(l) = light else { return Spectrum::ZERO };
        let omega_in = match boundary {
            Boundary::Smooth { eta } => {
                let wl = si_k.to_local(l.omega_l);
                let (f, cos_t, _, eta_ti) = fresnel(wl.z, eta);
                if f >= 1.0 {
                    return Spectrum::ZERO;
                }
                si_k.to_world(refract(wl, cos_t, eta_ti))
            }
            Boundary::Rough => {
                let si = with_wi(&si_k, l.omega_l);
                let ctx = BsdfContext::new(TransportMode::Importance);
                let Some((bs, _)) = bsdf.sample(&ctx, &si, u_dir1, u_dir) else { return Spectrum::ZERO };
                if bs.sampled_type & flags::TRANSMISSION == 0 {
                    return Spectrum::ZERO;
                }
                si_k.to_world(bs.wo)
            }
        };
        if omega_in.dot(si_k.n) >= 0.0 {
            return Spectrum::ZERO;
        }
        let Some(ds) = DistanceSampler::new(si_k.p, omega_in, x_i.p, st) else { return Spectrum::ZERO };
        si_k.p + ds.sample(u_t) * omega_in
    } else {
        let (omega_ij, _, _) = m.phase.sample(x_i.wi, u_dir);
        let Some(ds) = DistanceSampler::new(x_i.p, omega_ij, si_k.p, st) else { return Spectrum::ZERO };
        x_i.p + ds.sample(u_t) * omega_ij
    };
    if !x_j.is_finite() {
        return Spectrum::ZERO;
    }

    // ---- Connection x_i → x_j → x_k inside the medium ----
    let v_jk = si_k.p - x_j;
    let d_jk = v_jk.length();
    let omega_jk = v_jk / d_jk;
    if !(d_jk > 0.0) || omega_jk.dot(si_k.n) <= 0.0 {
        return Spectrum::ZERO;
    }
    let inner_k = offset_origin(si_k.p, si_k.n, -omega_jk);
    if !segment_clear(scene, x_i.p, x_j, stats) || !segment_clear(scene, x_j, inner_k, stats) {
        return Spectrum::ZERO;
    }
    let si_kj = with_wi(&si_k, -omega_jk);

    // ---- ↑ at a smooth boundary: the emitter along the refracted direction ----
    let light = match light {
        Some(l) => l,
        None => {
            let Boundary::Smooth { eta } = boundary else { return Spectrum::ZERO };
            let (f, cos_t, _, eta_ti) = fresnel(si_kj.wi.z, eta);
            if f >= 1.0 {
                return Spectrum::ZERO;
            }
            let omega_l = si_k.to_world(refract(si_kj.wi, cos_t, eta_ti));
            if omega_l.dot(si_k.n) <= 0.0 {
                return Spectrum::ZERO;
            }
            let Some(l) = light_along(scene, &si_k, omega_l, stats) else { return Spectrum::ZERO };
            l
        }
    };

    // ---- Throughput f of the suffix (docs/snee.md §1) ----
    let v_ij = x_j - x_i.p;
    let t_ij = v_ij.length();
    if !(t_ij > 0.0) {
        return Spectrum::ZERO;
    }
    let omega_ij = v_ij / t_ij;
    let phase_i = m.phase.eval(x_i.wi, omega_ij);
    let phase_j = m.phase.eval(-omega_ij, omega_jk);
    let cos_k = omega_jk.dot(si_k.n).abs();
    let tr = m.transmittance(t_ij + d_jk);
    let f_k = match boundary {
        Boundary::Smooth { .. } => {
            let ctx = BsdfContext { component: 1, ..BsdfContext::default() };
            match bsdf.sample(&ctx, &si_kj, 0.5, Vec2::ZERO) {
                Some((_, w)) => w,
                None => return Spectrum::ZERO,
            }
        }
        Boundary::Rough => bsdf.eval(&BsdfContext::default(), &si_kj, si_k.to_local(light.omega_l)),
    };
    let f = phase_i * phase_j * cos_k / (t_ij * t_ij * d_jk * d_jk) * tr * m.sigma_s() * f_k * light.le;

    // ---- Density and MIS weight ----
    let suffix = SneeSuffix { x_i: *x_i, x_j, si_k };
    let pdfs = suffix_pdfs(scene, snee, &suffix, &light, channel);
    if !(pdfs.snee > 0.0) {
        return Spectrum::ZERO;
    }
    let technique = snee.options.technique;
    let w = suffix_weights(technique, pdfs).snee;
    // With `connection = complete`, the manifold connection shares this suffix (docs/manifold.md §4).
    let w = manifold::snee_weight(scene, technique, &suffix, &light, channel, pdfs.snee).unwrap_or(w);
    f * (w / pdfs.snee) as f32
}

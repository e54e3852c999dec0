//! MIS of the manifold connection to a NON-DELTA light (an environment, or an area / sphere light)
//! with the other techniques that make the same suffix `x_j → x_k → light` (docs/manifold.md §4.2):
//! forward tracing (phase sampling at `x_j`, free flight surviving to `x_k`, the refraction chosen
//! with probability `1 − F`, escape), and SNEE at `x_i` when `x_i → x_j → x_k` is in its support.
//! All three densities are taken in the solid angle of `omega_jk` at `x_j` (conditioned on `x_j`):
//!
//! | technique | density |
//! |---|---|
//! | manifold | environment: `p_env(omega_l) · dω_l/dω_in = p_env · η² cos θ_in / cos θ_l`; area light: `p_sel p_A(y) / (G cos θ_y)` ([`area_density`]) |
//! | forward  | `f_p(wi_j, omega_jk) · e^{−σ_t d_jk} · (1 − F)` |
//! | SNEE     | `pdf_snee / (p_V(x_j | x_i) · cos θ_k / d_jk²)` (its `dV(x_j) dA(x_k)` density over forward's density of `x_j`, and `dA(x_k) = d_jk²/cos θ_k dω_jk`) |

use super::flat::{Plane, Refraction};
use super::pdf;
use super::MediumVertex;
use crate::integrator::snee::{self, LightSample, SneeOptions, SneeSuffix, SneeTechnique, SneeTransport, SneeVertex};
use crate::integrator::stats::LocalStats;
use crate::interaction::{offset_origin, spawn_ray_between, SurfaceInteraction};
use crate::math::Vec3;
use crate::scene::world::Scene;

/// The three densities of one environment suffix (solid angle of `omega_jk` at `x_j`).
#[derive(Clone, Copy, Debug, Default)]
pub struct EnvPdfs {
    pub manifold: f64,
    pub forward: f64,
    /// 0 outside SNEE's support.
    pub snee: f64,
}

/// The light record of an environment direction seen from `x_k` (SNEE's convention).
pub fn env_light(scene: &Scene, si_k: &SurfaceInteraction, omega_l: Vec3) -> Option<LightSample> {
    let env = scene.environment?;
    let ds = scene.environment_direction_sample(env, omega_l);
    Some(LightSample {
        omega_l,
        p: si_k.p,
        dist: f32::INFINITY,
        p_light: scene.pdf_emitter_direction(si_k.p, &ds),
        delta: false,
        le: crate::color::Spectrum::ZERO,
    })
}

/// Forward density of `x_j` from `x_i` in volume measure (phase sampling, free flight in `channel`).
pub(super) fn p_volume(scene: &Scene, x_i: &SneeVertex, x_j: Vec3, channel: usize) -> f64 {
    let m = &scene.media[x_i.medium as usize];
    let v = x_j - x_i.p;
    let t = v.length();
    pdf::manifold_density(1.0, m.phase.eval(x_i.wi, v / t), m.sigma_t[channel], t, 1.0)
}

/// The manifold connection's density of an environment direction (solid angle at `x_j`).
#[inline]
pub fn env_density(light: &LightSample, plane: &Plane, r: &Refraction) -> f64 {
    let eta2 = (plane.eta as f64) * (plane.eta as f64);
    light.p_light as f64 * eta2 * r.cos_in as f64 / r.cos_l as f64
}

/// The manifold connection's density of a light point `y` on an area light (solid angle at
/// `x_j`): `p_y / (G cos θ_y)`, `p_y = p_sel p_A(y)` the density of the point it samples (by
/// area), `G` the generalized geometry term (`pdf::plane_geometry`).
#[inline]
pub fn area_density(p_y: f64, g: f64, cos_y: f32) -> f64 {
    p_y / (g * cos_y.abs() as f64)
}

/// The densities of `x_j → x_k → light` (plus `x_i` before, when given), the manifold
/// connection's (`manifold`: [`env_density`] or [`area_density`]) given. `check_support`:
/// test that `x_k` is visible from `x_i` (SNEE's probe); the caller passes `false` when it knows.
#[allow(clippy::too_many_arguments)]
pub fn suffix_pdfs(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    si_k: &SurfaceInteraction,
    r: &Refraction,
    light: &LightSample,
    manifold: f64,
    channel: usize,
    check_support: bool,
    stats: &mut LocalStats,
) -> EnvPdfs {
    let v = si_k.p - x_j.p;
    let d_jk = v.length();
    let refraction = (r.fresnel as f64, r.cos_in as f64);
    pdfs_at(scene, opts, x_i, x_j, si_k, v / d_jk, d_jk, refraction, light, manifold, channel, check_support, stats)
}

/// [`suffix_pdfs`] for any smooth boundary point `x_k` (flat or curved): the suffix leaves `x_j`
/// along `omega_jk` over `d_jk`, and `refraction = (F, cos_k)` is the Fresnel reflectance of the
/// refraction at `x_k` and the |cos| of `omega_jk` there.
#[allow(clippy::too_many_arguments)]
pub fn pdfs_at(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    si_k: &SurfaceInteraction,
    omega_jk: Vec3,
    d_jk: f32,
    refraction: (f64, f64),
    light: &LightSample,
    manifold: f64,
    channel: usize,
    check_support: bool,
    stats: &mut LocalStats,
) -> EnvPdfs {
    let (f, cos_k) = refraction;
    let m = &scene.media[x_j.medium as usize];
    let st = m.sigma_t[channel] as f64;
    let forward = m.phase.eval(x_j.wi, omega_jk) as f64 * (-st * d_jk as f64).exp() * (1.0 - f);
    let snee = snee_solid_angle_pdf(scene, opts, x_i, x_j, si_k, light, channel, check_support, cos_k, d_jk, stats);
    let finite = |x: f64| if x.is_finite() && x > 0.0 { x } else { 0.0 };
    EnvPdfs { manifold: finite(manifold), forward: finite(forward), snee: finite(snee) }
}

/// SNEE's own density `pdf_snee` of the suffix `x_i → x_j → x_k → light` (its `dV(x_j) dA(x_k)`
/// measure) and its vertex `x_i`; `None` where SNEE cannot make it: no SNEE vertex `x_i` in the
/// same medium, `snee = forward`, density 0, or, with `check_support`, `x_k` hidden from `x_i` (one
/// shadow ray, cast only when the density is positive).
#[allow(clippy::too_many_arguments)]
pub fn snee_suffix_pdf<'a>(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&'a SneeVertex>,
    x_j: &MediumVertex,
    si_k: &SurfaceInteraction,
    light: &LightSample,
    channel: usize,
    check_support: bool,
    stats: &mut LocalStats,
) -> Option<(f64, &'a SneeVertex)> {
    let x_i = x_i.filter(|x| opts.technique != SneeTechnique::Forward && x.medium == x_j.medium)?;
    let tables = super::tables(scene)?;
    let suffix = SneeSuffix { x_i: *x_i, x_j: x_j.p, si_k: *si_k };
    let pdf_snee = snee::pdf_snee(scene, tables, &suffix, light, channel);
    if !(pdf_snee > 0.0) {
        return None;
    }
    if check_support {
        stats.rays += 1;
        let inner_k = offset_origin(si_k.p, si_k.n, x_i.p - si_k.p);
        if scene.ray_test(&spawn_ray_between(x_i.p, inner_k)) {
            return None;
        }
    }
    Some((pdf_snee, x_i))
}

/// SNEE's density of the suffix in the solid angle of `omega_jk` at `x_j` conditioned on `x_j`
/// (docs/manifold.md §4.2: [`snee_suffix_pdf`] divided by forward's volume density of `x_j` and by
/// `dA(x_k)/dω_jk = d_jk²/cos_k`); 0 where SNEE cannot make it. `cos_k`: |cos| of `omega_jk` at `x_k`.
#[allow(clippy::too_many_arguments)]
pub fn snee_solid_angle_pdf(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    si_k: &SurfaceInteraction,
    light: &LightSample,
    channel: usize,
    check_support: bool,
    cos_k: f64,
    d_jk: f32,
    stats: &mut LocalStats,
) -> f64 {
    let Some((pdf_snee, x_i)) = snee_suffix_pdf(scene, opts, x_i, x_j, si_k, light, channel, check_support, stats)
    else {
        return 0.0;
    };
    per_solid_angle(scene, x_i, x_j, pdf_snee, channel, cos_k, d_jk)
}

/// `pdf_snee` (SNEE's density of a suffix from `x_i`) divided by forward's volume density of `x_j`
/// and by `dA(x_k)/dω_jk = d_jk²/cos_k` ([`snee_solid_angle_pdf`]); 0 where that factor is not positive.
fn per_solid_angle(
    scene: &Scene,
    x_i: &SneeVertex,
    x_j: &MediumVertex,
    pdf_snee: f64,
    channel: usize,
    cos_k: f64,
    d_jk: f32,
) -> f64 {
    let to_sa = p_volume(scene, x_i, x_j.p, channel) * cos_k / (d_jk as f64 * d_jk as f64);
    if to_sa > 0.0 {
        pdf_snee / to_sa
    } else {
        0.0
    }
}

/// [`snee_solid_angle_pdf`] of a suffix whose `snee::pdf_snee` the caller already has (SNEE's
/// sample, which computed it for the same suffix and light, positive, with `x_k` visible from
/// `x_i`): the same vertex tests and conversion, without recomputing it.
#[allow(clippy::too_many_arguments)]
pub fn snee_solid_angle_pdf_known(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    pdf_snee: f64,
    channel: usize,
    cos_k: f64,
    d_jk: f32,
) -> f64 {
    let Some(x_i) = x_i.filter(|x| opts.technique != SneeTechnique::Forward && x.medium == x_j.medium) else {
        return 0.0;
    };
    if super::tables(scene).is_none() || !(pdf_snee > 0.0) {
        return 0.0;
    }
    per_solid_angle(scene, x_i, x_j, pdf_snee, channel, cos_k, d_jk)
}

/// Which technique made the suffix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EnvTechnique {
    Manifold,
    Forward,
    Snee,
}

/// Weight of `technique` for a suffix with densities `p`: the power heuristic over the three
/// (`snee = mis`); `snee = snee`: SNEE takes what it can make, the other two share the rest;
/// `snee = forward`: SNEE's density is 0. `transport = snee`: suffixes outside SNEE's support get 0.
pub fn env_weight(opts: SneeOptions, technique: EnvTechnique, p: EnvPdfs) -> f64 {
    let own = match technique {
        EnvTechnique::Manifold => Some(p.manifold),
        EnvTechnique::Forward => Some(p.forward),
        EnvTechnique::Snee => None,
    };
    power_weight(opts, own, &[p.manifold, p.forward], p.snee)
}

/// The power heuristic over a set of techniques one of which is SNEE, with the conventions of
/// the `snee` and `transport` options (shared by [`env_weight`] and `rough::rough_weight`):
/// `own` is the density of the technique that made the suffix (`None`: SNEE made it), `others`
/// the densities of the techniques other than SNEE, `snee` SNEE's. `snee = forward`: SNEE's density
/// is 0; `snee = snee`: SNEE takes what it can make; `transport = snee`: suffixes outside SNEE's
/// support get 0.
pub fn power_weight(opts: SneeOptions, own: Option<f64>, others: &[f64], snee: f64) -> f64 {
    let s = if opts.technique == SneeTechnique::Forward { 0.0 } else { snee };
    if opts.transport == SneeTransport::Snee && s == 0.0 {
        return 0.0;
    }
    if opts.technique == SneeTechnique::Snee && s > 0.0 {
        return if own.is_none() { 1.0 } else { 0.0 };
    }
    let own = own.unwrap_or(s);
    if !(own > 0.0) {
        return 0.0;
    }
    // Ratios against the own density avoid overflow of the squares.
    let sum = others.iter().fold(0.0, |acc, p| acc + (p / own) * (p / own)) + (s / own) * (s / own);
    let w = 1.0 / sum;
    if w.is_finite() {
        w
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn env_weights_partition_unity() {
        for technique in [SneeTechnique::Mis, SneeTechnique::Snee, SneeTechnique::Forward] {
            let opts = SneeOptions { technique, ..SneeOptions::default() };
            for p in [
                EnvPdfs { manifold: 1.0, forward: 2.0, snee: 3.0 },
                EnvPdfs { manifold: 1e-20, forward: 5.0, snee: 0.0 },
                EnvPdfs { manifold: 4.0, forward: 0.0, snee: 1e10 },
            ] {
                let sum: f64 = [EnvTechnique::Manifold, EnvTechnique::Forward, EnvTechnique::Snee]
                    .iter()
                    .filter(|t| **t != EnvTechnique::Snee || technique != SneeTechnique::Forward)
                    .map(|t| env_weight(opts, *t, p))
                    .sum();
                assert!((sum - 1.0).abs() < 1e-12, "{technique:?} {p:?}: {sum}");
            }
        }
    }
}

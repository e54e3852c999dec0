//! The light segment `x_k → emitter` (docs/snee.md §1): through passable surfaces (`null`,
//! `thindielectric`) to an emitter, sampled from `x_k` (↓) or followed along a direction (↑), and
//! the visibility tests of the segments inside the medium.

use super::LightSample;
use crate::color::Spectrum;
use crate::integrator::stats::LocalStats;
use crate::integrator::walk::{is_medium_transition, walk_segments, WalkEnd};
use crate::interaction::{offset_origin, spawn_ray_between, SurfaceInteraction, SHADOW_EPSILON};
use crate::math::{Ray, Vec2, Vec3};
use crate::scene::world::Scene;

/// A surface the light segment `x_k → emitter` may cross: null-transmissive (`null`,
/// `thindielectric`) and not a medium transition. Deterministic, so that SNEE and forward tracing
/// agree on SNEE's support (docs/snee.md §1).
#[inline]
pub fn passable(scene: &Scene, si: &SurfaceInteraction) -> bool {
    !is_medium_transition(scene, si) && scene.bsdf(si).eval_null_transmission(si) != Spectrum::ZERO
}

/// Walk from `x_k` along `omega_l` up to `tmax` through passable surfaces. Returns the product of
/// their null transmissions and the first surface that stops the walk (not passable, or an
/// emitter when `stop_at_emitters`), `None` when the walk reached `tmax` or escaped.
fn walk_light_segment(
    scene: &Scene,
    si_k: &SurfaceInteraction,
    omega_l: Vec3,
    tmax: f32,
    stop_at_emitters: bool,
    stats: &mut LocalStats,
) -> (Spectrum, Option<SurfaceInteraction>) {
    let ray = Ray { tmax, ..Ray::new(offset_origin(si_k.p, si_k.n, omega_l), omega_l) };
    let mut tr = Spectrum::ONE;
    let mut stop = None;
    // No medium: x_k's outside has none, and passable surfaces are no medium transitions.
    let end = walk_segments(scene, ray, None, stats, |_, _, hit| {
        let Some(hit) = hit else { return false };
        let is_emitter = scene.shapes[hit.shape as usize].emitter.is_some();
        if (stop_at_emitters && is_emitter) || !passable(scene, hit) {
            stop = Some(*hit);
            return false;
        }
        tr *= scene.bsdf(hit).eval_null_transmission(hit);
        true
    });
    match end {
        WalkEnd::Done => (tr, stop),
        WalkEnd::Exhausted => (Spectrum::ZERO, None),
    }
}

/// Transmission of the segment from `x_k` towards a sampled emitter point through passable
/// surfaces; zero when the segment is blocked (then the path is outside SNEE's support).
pub fn light_transmission(
    scene: &Scene,
    si_k: &SurfaceInteraction,
    light: &LightSample,
    stats: &mut LocalStats,
) -> Spectrum {
    let tmax = if light.dist.is_finite() {
        let o = offset_origin(si_k.p, si_k.n, light.omega_l);
        (light.p - o).length() * (1.0 - SHADOW_EPSILON)
    } else {
        f32::INFINITY
    };
    if scene.surfaces_block_shadow_rays {
        // Every surface stops the walk (none is passable): one any-hit query decides it, with the
        // walk's value (1 or 0) and its ray count.
        let ray = Ray { tmax, ..Ray::new(offset_origin(si_k.p, si_k.n, light.omega_l), light.omega_l) };
        if !(tmax > 0.0) {
            return Spectrum::ONE;
        }
        stats.rays += 1;
        // A non-finite ray has no hit in `ray_intersect` (the walk's query); `ray_test` reports it blocked.
        let blocked = (ray.o + ray.d).is_finite() && scene.ray_test(&ray);
        return if blocked { Spectrum::ZERO } else { Spectrum::ONE };
    }
    match walk_light_segment(scene, si_k, light.omega_l, tmax, false, stats) {
        (tr, None) => tr,
        _ => Spectrum::ZERO,
    }
}

/// True when the open segment `a → b` crosses no surface.
pub fn segment_clear(scene: &Scene, a: Vec3, b: Vec3, stats: &mut LocalStats) -> bool {
    // An empty segment (x_j sampled onto x_i in f32) crosses nothing; a ray along it would have a
    // NaN direction.
    if !(a.distance_squared(b) > 0.0) {
        return true;
    }
    stats.rays += 1;
    !scene.ray_test(&spawn_ray_between(a, b))
}

/// Emitter sample from `x_k` (↓ step 1), pointing outside and unoccluded; `le` includes the
/// transmission of passable surfaces on the way.
pub fn sample_light(scene: &Scene, si_k: &SurfaceInteraction, u: Vec2, stats: &mut LocalStats) -> Option<LightSample> {
    let (ds, weight) = scene.sample_emitter_direction(si_k.p, None, u, false);
    if !(ds.pdf > 0.0) || weight == Spectrum::ZERO || ds.d.dot(si_k.n) <= 0.0 {
        return None;
    }
    let mut light =
        LightSample { omega_l: ds.d, p: ds.p, dist: ds.dist, p_light: ds.pdf, delta: ds.delta, le: weight * ds.pdf };
    let tr = light_transmission(scene, si_k, &light, stats);
    light.le *= tr;
    (tr != Spectrum::ZERO).then_some(light)
}

/// The emitter seen from `x_k` along `omega_l` through passable surfaces (an area emitter, or
/// the environment on escape); `le` includes the transmission on the way.
pub fn light_along(
    scene: &Scene,
    si_k: &SurfaceInteraction,
    omega_l: Vec3,
    stats: &mut LocalStats,
) -> Option<LightSample> {
    let (tr, hit) = walk_light_segment(scene, si_k, omega_l, f32::INFINITY, true, stats);
    if tr == Spectrum::ZERO {
        return None;
    }
    match hit {
        Some(hit) => {
            scene.shapes[hit.shape as usize].emitter?;
            let le = scene.eval_area_emitter(&hit) * tr;
            let ds = scene.direction_sample_for_hit(si_k.p, &hit);
            let p_light = scene.pdf_emitter_direction(si_k.p, &ds);
            (le != Spectrum::ZERO).then_some(LightSample {
                omega_l,
                p: hit.p,
                dist: ds.dist,
                p_light,
                delta: false,
                le,
            })
        }
        None => {
            let env = scene.environment?;
            let ds = scene.environment_direction_sample(env, omega_l);
            let p_light = scene.pdf_emitter_direction(si_k.p, &ds);
            let le = scene.eval_environment(omega_l) * tr;
            (le != Spectrum::ZERO).then_some(LightSample {
                omega_l,
                p: si_k.p,
                dist: f32::INFINITY,
                p_light,
                delta: false,
                le,
            })
        }
    }
}

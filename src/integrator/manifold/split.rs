//! Emitter splitting at smooth dielectric vertices (`volpath_snee`, `connection = complete`,
//! option `split_glints`, docs/manifold.md §12): the direct emission along BOTH deterministic lobes
//! of a smooth `dielectric`, weighted by their Fresnel probabilities, in place of the one lobe that
//! forward tracing picks.
//!
//! At a smooth dielectric vertex `s` the path loop (Mitsuba's `dielectric`) picks reflection with
//! probability `F` and refraction with `1 − F`; the lobe's weight `w_l` (f·cos / pdf) is 1 for
//! reflection and the radiance scaling `1/η²` for refraction (times the optional
//! `specular_reflectance` / `specular_transmittance`). The emitter hit by the ray leaving `s` is
//! the estimate `β w_l Le(ray_l)` of its expectation over the lobe choice,
//!
//! ```text
//! E = β [ F · w_R Le(ray_R) + (1 − F) · w_T Le(ray_T) ]
//! ```
//!
//! whose relative variance is about `1/F` for a glint (a light seen in the reflection only, found
//! by one camera sample in `1/F ≈ 25` on glass). Splitting computes `E` exactly: for each lobe `l`
//! of a set `S` (below), the sampled lobe's hit is counted with the factor `p_l` (its probability,
//! [`GlintSplit::take_hit_scale`]) and the other lobe's hit is found by one extra ray and counted as
//! `β p_l w_l Le(ray_l)` ([`GlintSplit::at_bsdf_sample`]). Per lobe `l ∈ S` the expectation is
//! `p_l · p_l X_l + (1 − p_l) · p_l X_l = p_l X_l`, the term it replaces; lobes outside `S` keep
//! the forward estimate. The lobe choice still draws its number, so the sample stream is unchanged.
//! What the split counts is the emitter at the FIRST surface the lobe's ray reaches (or the
//! environment when it escapes): a hit behind a null surface is made later by the path, as
//! without splitting.
//! The path's Russian roulette at the next vertex divides by its survival probability, so the
//! sampled lobe's scaled hit keeps its expectation; the split lobe counts only where the hit
//! would (`depth + 1 < max_depth`).
//!
//! **The set `S` (MIS).** Splitting changes only how forward BSDF sampling's own estimate is formed,
//! so it is unbiased where forward tracing's weight of the hit is 1 under every technique: the hit
//! after a delta lobe has weight 1 in `volpath`, and no other technique of `complete` makes the
//! suffix `s → light`, when
//! - the lobe leaves into vacuum (no medium behind it: a ray through a medium contributes only
//!   behind a transmittance, which forward tracing samples), and
//! - it is a reflection, or a refraction at a vertex that is NOT the first surface event after a
//!   medium vertex `x_j`: the refraction out at that `x_k` is the suffix `x_j → x_k → light` that
//!   SNEE (`snee::stage`), the flat, rough and curved manifold connections (`manifold::track`,
//!   `rough`, `curved_finite`) share with forward tracing under MIS; every one of them starts its
//!   record only there (a reflection never carries one).
//!
//! On the paper's statue this covers the glints of the sphere light on the outer surface
//! (`surface`, no medium vertex), light that left the statue and reflects off it (`other`,
//! `V–S_t–S_r–L`), and the refraction out after an internal reflection.
//!
//! **Cost.** The extra ray is cast only for the lobe that was not sampled, and only where it can
//! reach an emitter: without an environment, the ray is first tested against the bounds of the
//! area emitters (a sphere light's sphere, padded; an axis-aligned box otherwise), and the BVH is
//! queried only when it meets one. Delta lights (point, spot, directional) are never hit.
//!
//! **Classes.** The split lobe's contribution closes the path as emitter sampling at `s` towards
//! the lobe's direction would (`End::SurfaceNee`): the event at `s` is that lobe.

use crate::bsdf::fresnel::reflect_local;
use crate::bsdf::{flags, Bsdf, BsdfContext, BsdfSample};
use crate::color::Spectrum;
use crate::integrator::manifold::split_bounds::{LightBound, SplitTables};
use crate::integrator::snee::options::{Snee, SneeOptions};
use crate::integrator::stats::LocalStats;
use crate::integrator::walk::{is_medium_transition, target_medium};
use crate::interaction::SurfaceInteraction;
use crate::math::{Aabb, Vec2, Vec3};
use crate::scene::world::{Scene, SceneEmitter};
use crate::shape::Geometry;

/// Relative padding of an emitter's bound, so that rounding never skips a ray the BVH would hit.
const PAD: f32 = 1e-3;

/// The splitting tables of `scene` under `opts` (with `connection = complete`), `None` where it
/// does not run: `split_glints` off, `transport = snee` (it keeps no surface paths), no smooth
/// `dielectric`, or no emitter that a ray can hit.
pub fn tables(scene: &Scene, opts: SneeOptions) -> Option<SplitTables> {
    if !opts.split_glints || !opts.keeps_all() || !scene.bsdfs.iter().any(|b| matches!(b, Bsdf::Dielectric(_))) {
        return None;
    }
    let lights: Vec<LightBound> = scene
        .emitters
        .iter()
        .filter_map(|e| match e {
            SceneEmitter::Area { shape, .. } => Some(light_bound(scene, *shape)),
            SceneEmitter::Other(_) => None,
        })
        .collect();
    let environment = scene.environment.is_some();
    (environment || !lights.is_empty()).then_some(SplitTables { lights, environment })
}

/// The padded bound of shape `shape`: relative to its size, plus an absolute margin relative to
/// the scene's size (the rounding of a hit's distance grows with it).
fn light_bound(scene: &Scene, shape: u32) -> LightBound {
    let margin = 1e-5 * scene.bounds.extent().max_element().max(1.0);
    let shape = &scene.shapes[shape as usize];
    match &shape.geometry {
        Geometry::Sphere(s) => {
            let r = s.radius * (1.0 + PAD) + margin;
            LightBound::Sphere { center: s.center, radius2: r * r }
        }
        _ => {
            let b = shape.bounds();
            let pad = Vec3::splat(PAD * b.extent().max_element() + margin);
            LightBound::Box(Aabb { min: b.min - pad, max: b.max + pad })
        }
    }
}

/// The lobe of a smooth dielectric that BSDF sampling did NOT pick: its sample and weight
/// (`None` where there is none: total internal reflection, or a BSDF other than `dielectric`).
/// `dielectric` picks reflection when its number is at most `F`, so 0 forces reflection and 1
/// forces refraction (when `F < 1`).
#[inline]
pub fn other_lobe(bsdf: &Bsdf, s: &SurfaceInteraction, sampled: &BsdfSample) -> Option<(BsdfSample, Spectrum)> {
    let Bsdf::Dielectric(d) = bsdf else { return None };
    let reflected = sampled.sampled_type & flags::REFLECTION != 0;
    let (bo, w) = d.sample(&BsdfContext::default(), s, if reflected { 1.0 } else { 0.0 }, Vec2::ZERO)?;
    (bo.sampled_type != sampled.sampled_type && bo.pdf > 0.0).then_some((bo, w))
}

/// Splitting's state along one path.
#[derive(Clone, Debug)]
pub struct GlintSplit<'a> {
    tables: &'a SplitTables,
    /// The last event was a real scatter in a medium (the next surface event may be its `x_k`).
    after_medium_vertex: bool,
    /// The factor of the next emitter hit: the probability of the lobe the ray follows when that
    /// lobe is split, else 1.
    hit_scale: f32,
}

impl<'a> GlintSplit<'a> {
    /// The state for a path of `volpath_snee` built with `snee`, `None` where splitting does not run.
    #[inline]
    pub fn new(snee: &'a Snee) -> Option<Self> {
        let tables = snee.split.as_ref()?;
        Some(GlintSplit { tables, after_medium_vertex: false, hit_scale: 1.0 })
    }

    /// A real scatter in a medium.
    #[inline]
    pub fn at_scatter(&mut self) {
        self.after_medium_vertex = true;
    }

    /// The factor of the emitter hit the loop is about to count (1 unless the ray follows a split
    /// lobe); once per surface step.
    #[inline]
    pub fn take_hit_scale(&mut self) -> f32 {
        std::mem::replace(&mut self.hit_scale, 1.0)
    }

    /// BSDF sampling at `s` (reached along `d`, in `medium`, throughput `beta` before the sample,
    /// `depth` before it counts) picked `bs` towards world `wo`. Sets the next hit's factor and
    /// returns the split contribution of the other lobe with its world direction (for the class
    /// tally), `None` where there is none.
    #[allow(clippy::too_many_arguments)]
    pub fn at_bsdf_sample(
        &mut self,
        scene: &Scene,
        s: &SurfaceInteraction,
        bsdf: &Bsdf,
        bs: &BsdfSample,
        wo: Vec3,
        medium: Option<u32>,
        beta: Spectrum,
        depth: u32,
        max_depth: u32,
        stats: &mut LocalStats,
    ) -> Option<(Spectrum, Vec3)> {
        self.hit_scale = 1.0;
        // A null crossing is not a surface event: the next real one may still be the `x_k` of the
        // last medium vertex (SNEE and the connections carry their suffix across passable surfaces).
        if bs.sampled_type & flags::NULL != 0 {
            return None;
        }
        let after_medium_vertex = std::mem::replace(&mut self.after_medium_vertex, false);
        if bs.sampled_type & flags::DELTA == 0 || !matches!(bsdf, Bsdf::Dielectric(_)) || depth + 1 >= max_depth {
            return None;
        }
        // Does a ray along `wo` leave into vacuum?
        let vacuum = |wo: Vec3| {
            let next_medium = if is_medium_transition(scene, s) { target_medium(scene, s, wo) } else { medium };
            next_medium.is_none()
        };
        let reflected = bs.sampled_type & flags::REFLECTION != 0;
        if vacuum(wo) && (reflected || !after_medium_vertex) {
            self.hit_scale = bs.pdf;
        }
        // The other lobe, where it is in the set: a refraction only away from an `x_k`, and a
        // reflection only into vacuum (tested on its direction before the lobe is computed).
        if (reflected && after_medium_vertex) || (!reflected && !vacuum(s.to_world(reflect_local(s.wi)))) {
            return None;
        }
        let (bo, weight) = other_lobe(bsdf, s, bs)?;
        let wo_other = s.to_world(bo.wo);
        if !vacuum(wo_other) {
            return None;
        }
        stats.split_lobes += 1;
        let ray = s.spawn_ray(wo_other);
        if !self.tables.may_hit_emitter(&ray) {
            return None;
        }
        stats.split_rays += 1;
        stats.rays += 1;
        let le = match scene.ray_intersect(&ray) {
            Some(y) if scene.shapes[y.shape as usize].emitter.is_some() => scene.eval_area_emitter(&y),
            Some(_) => return None,
            None => scene.eval_environment(ray.d),
        };
        if le == Spectrum::ZERO {
            return None;
        }
        Some((beta * weight * bo.pdf * le, wo_other))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::Dielectric;
    use crate::testing::si_with_wi;

    /// Over random incident directions (both sides, total internal reflection included) and both
    /// lobe choices, the sampled lobe's hit times its probability plus the other lobe's `p w Le`
    /// equals the expectation of forward BSDF sampling's hit over the lobe choice, with a radiance
    /// `Le` that differs per lobe: the split estimate has no variance left from the lobe choice.
    #[test]
    fn split_equals_the_expectation_over_the_lobe_choice() {
        let le = |wo: Vec3| Spectrum::new(1.0 + wo.x.abs(), 2.0 + wo.z, 0.5 + wo.y * wo.y);
        let mut rng = crate::sampler::Sampler::new(5, 1);
        for eta in [1.5f32, 1.0 / 1.33, 1.0] {
            let bsdf = Bsdf::Dielectric(Dielectric { eta, specular_reflectance: None, specular_transmittance: None });
            let Bsdf::Dielectric(d) = &bsdf else { unreachable!() };
            for _ in 0..500 {
                let u = rng.next_2d();
                let z = 2.0 * u.x - 1.0;
                let r = (1.0 - z * z).max(0.0).sqrt();
                let phi = std::f32::consts::TAU * u.y;
                let si = si_with_wi(Vec3::new(r * phi.cos(), r * phi.sin(), z));
                // The expectation by quadrature over the lobe choice: 4096 strata of the number.
                let n = 4096;
                let mut expected = Spectrum::ZERO;
                for k in 0..n {
                    let (bs, w) =
                        d.sample(&BsdfContext::default(), &si, (k as f32 + 0.5) / n as f32, Vec2::ZERO).unwrap();
                    expected += w * le(bs.wo) / n as f32;
                }
                for s1 in [rng.next_1d(), 0.0, 0.999_999] {
                    let (bs, w) = d.sample(&BsdfContext::default(), &si, s1, Vec2::ZERO).unwrap();
                    let mut split = w * bs.pdf * le(bs.wo);
                    if let Some((bo, wo)) = other_lobe(&bsdf, &si, &bs) {
                        split += wo * bo.pdf * le(bo.wo);
                    }
                    let tol = 2e-3 * expected.max_element().max(1e-3);
                    assert!(
                        (split - expected).abs().max_element() <= tol,
                        "eta {eta} wi {:?} s1 {s1}: split {split:?} expected {expected:?}",
                        si.wi
                    );
                }
            }
        }
    }
}

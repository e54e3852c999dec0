//! The walks every volumetric integrator shares, written once (in the spirit of pbrt-v4's
//! `SampleT_maj`: the walk owns the geometry, a closure per segment owns the weights):
//! - [`walk_segments`]: along a ray up to `ray.tmax` through the surfaces it may cross, segment by
//!   segment, tracking the medium across medium transitions. `volpath` and `volpathmis` estimate
//!   shadow-ray transmittance with it (their own weights in the closure), SNEE walks its light
//!   segment `x_k → emitter` with it.
//! - [`free_flight`]: the path's next event in a medium: a sampled distance in the hero channel
//!   against the next surface, which is traced at most once per ray.
//! - [`PathSetup`]: the settings every path starts from (depth limits, hero channel).

use super::stats::LocalStats;
use crate::bsdf::Bsdf;
use crate::color::Spectrum;
use crate::interaction::{offset_origin, spawn_ray_between, DirectionSample, SurfaceInteraction};
use crate::math::{Ray, Vec3};
use crate::medium::Homogeneous;
use crate::sampler::Sampler;
use crate::scene::world::Scene;
use crate::shape::accel::Hit;
use crate::shape::Geometry;

/// Upper bound on the surfaces one walk crosses (guards against degenerate geometry).
pub const MAX_SEGMENTS: u32 = 256;

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

/// How a walk ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WalkEnd {
    /// It reached `ray.tmax`, escaped, or its closure stopped it.
    Done,
    /// It crossed [`MAX_SEGMENTS`] surfaces without ending.
    Exhausted,
}

/// Walk `ray` from `ray.o` up to `ray.tmax`, starting in `medium`. For every segment,
/// `segment(medium, length, hit)` is called with the medium the segment runs through, its length
/// (the rest of `tmax` when no surface ends it) and the surface that ends it (`None`: the walk
/// reached `tmax` or escaped, and ends). The closure returns whether the walk crosses that surface;
/// the walk then enters the medium behind it (at medium transitions) and goes on from there.
#[inline]
pub fn walk_segments(
    scene: &Scene,
    mut ray: Ray,
    mut medium: Option<u32>,
    stats: &mut LocalStats,
    mut segment: impl FnMut(Option<u32>, f32, Option<&SurfaceInteraction>) -> bool,
) -> WalkEnd {
    let mut remaining = ray.tmax;
    for _ in 0..MAX_SEGMENTS {
        if !(remaining > 0.0) {
            return WalkEnd::Done;
        }
        ray.tmax = remaining;
        stats.rays += 1;
        let si = scene.ray_intersect(&ray);
        let length = si.as_ref().map_or(remaining, |s| s.t);
        if !segment(medium, length, si.as_ref()) {
            return WalkEnd::Done;
        }
        let Some(si) = si else { return WalkEnd::Done };
        if is_medium_transition(scene, &si) {
            medium = target_medium(scene, &si, ray.d);
        }
        remaining -= si.t;
        ray.o = offset_origin(si.p, si.n, ray.d);
    }
    WalkEnd::Exhausted
}

/// The outcome of a free flight along the path's ray in a medium.
#[derive(Clone, Copy, Debug)]
pub struct Flight {
    /// The sampled distance (in the hero channel).
    pub t: f32,
    /// True when `t` ends before the next surface: a real collision in the medium.
    pub scatter: bool,
}

/// Sample a free-flight distance in medium `m` along `ray` in `channel`, and trace the ray up to it
/// unless `si` already holds the surface ahead (`*needs_intersection` false; a ray is traced at
/// most once). The surface hit, if any, is left in `si`.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn free_flight(
    scene: &Scene,
    m: &Homogeneous,
    ray: &Ray,
    channel: usize,
    si: &mut Option<SurfaceInteraction>,
    needs_intersection: &mut bool,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> Flight {
    let t = m.sample_distance(sampler.next_1d(), channel);
    if *needs_intersection {
        let mut r = *ray;
        r.tmax = if t.is_finite() { t } else { f32::INFINITY };
        stats.rays += 1;
        *si = scene.ray_intersect(&r);
        *needs_intersection = false;
    }
    let t_surface = si.as_ref().map_or(f32::INFINITY, |s| s.t);
    Flight { t, scatter: t < t_surface }
}

/// What every path of `volpath`, `volpathmis` and `volpath_snee` starts from.
#[derive(Clone, Copy, Debug)]
pub struct PathSetup {
    /// `max_depth` with -1 (unbounded) as `u32::MAX`.
    pub max_depth: u32,
    pub rr_depth: u32,
    /// The hero channel: distances are sampled in it (RGB mode, as Mitsuba's).
    pub channel: usize,
}

impl PathSetup {
    /// The integrator's depth limits, and a hero channel picked uniformly (one sample).
    #[inline]
    pub fn new(scene: &Scene, sampler: &mut Sampler) -> PathSetup {
        let desc = &scene.integrator;
        PathSetup {
            max_depth: if desc.max_depth < 0 { u32::MAX } else { desc.max_depth as u32 },
            rr_depth: desc.rr_depth as u32,
            // Through `u32` (`u · 3` lies in [0, 3)): a cheaper conversion than to `usize`, the same index.
            channel: ((sampler.next_1d() * 3.0) as u32).min(2) as usize,
        }
    }
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

/// The shadow ray from `r` to the emitter sample `ds`, and the medium it starts in (`medium` at a
/// medium point; at a surface, the medium on the side `ds.d` leaves into).
#[inline]
pub fn shadow_ray(scene: &Scene, r: RefPoint, medium: Option<u32>, ds: &DirectionSample) -> (Ray, Option<u32>) {
    let (o, medium) = match r {
        RefPoint::Surface(si) => {
            let medium = if is_medium_transition(scene, si) { target_medium(scene, si, ds.d) } else { medium };
            (offset_origin(si.p, si.n, ds.d), medium)
        }
        RefPoint::Medium(p) => (p, medium),
    };
    let ray = if ds.dist.is_finite() { spawn_ray_between(o, ds.p) } else { Ray::new(o, ds.d) };
    (ray, medium)
}

/// Where a shadow ray crosses the surface of `hit` (found along `ray`): the point, the geometric
/// normal, and the surface's null transmission (Mitsuba's `eval_null_transmission`), which is all a
/// shadow walk needs of it. A mesh with a `null` BSDF (an index-matched medium boundary) transmits 1
/// and needs only the point and the face normal (`Mesh::point_and_normal`, which
/// `Mesh::interaction` also uses), not its shading frame; anything else gets the full
/// `SurfaceInteraction`.
#[inline]
pub fn shadow_crossing(scene: &Scene, hit: &Hit, ray: &Ray) -> (Vec3, Vec3, Spectrum) {
    let shape = &scene.shapes[hit.shape as usize];
    if let (Geometry::Mesh(m), Bsdf::Null) = (&shape.geometry, &scene.bsdfs[shape.bsdf as usize]) {
        let (p, n) = m.point_and_normal(hit.prim, hit.b1, hit.b2);
        return (p, n, Spectrum::ONE);
    }
    let mut si = shape.interaction(hit.prim, hit.b1, hit.b2, hit.t, ray);
    si.shape = hit.shape;
    (si.p, si.n, scene.bsdf(&si).eval_null_transmission(&si))
}

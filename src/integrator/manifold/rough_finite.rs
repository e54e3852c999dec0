//! Manifold NEE through a ROUGH boundary to an AREA light at a finite distance (sphere, rectangle,
//! mesh, disk; docs/manifold.md §7.2): the finite-light counterpart of [`rough`](super::rough)'s
//! connection to directional lights and environments.
//!
//! From the medium vertex `x_j` the connection samples the light point `y` as NEE from `x_j`
//! would (`Scene::sample_emitter_direction`: by the subtended cone for a sphere, by area
//! otherwise, front side only), then a reference ([`point_reference`]: a shading frame and the
//! direction `omega_ref` from the refined boundary point towards `y`, a deterministic function
//! of `(x_j, y)`), then the inner direction `omega_in ~ bsdf.sample(wi = omega_ref)` in
//! importance mode in that frame (on a curved boundary mixed with a wider lobe,
//! `rough_lobe::sample_inner_ref`, whose density `p_imp` below then is), `omega_jk = −omega_in`,
//! and traces `x_j → x_k`. The value uses the TRUE BSDF at `x_k` (its own shading frame) and the
//! real emitter direction `omega_l = (y − x_k)/|y − x_k|`, with the light segment `x_k → y`
//! through passable surfaces.
//!
//! Density, in the measure of the other techniques (`rough_lobe::rough_pdfs`: solid angle of `omega_jk`
//! at `x_j` times solid angle of `omega_l` at `x_k`), conditioned on `x_j`:
//!
//! ```text
//! p_man = p_A(y | x_j) · p_imp(omega_in | omega_ref(x_j, y), F(x_j, y)) · d_ky² / |cos θ_y|
//! p_A(y | x_j) = p_dir(x_j → y) · |cos θ_y(x_j)| / d_jy²      (emitter sampling from x_j, by area)
//! ```
//!
//! `cos θ_y` at `y` with the light's normal there, computed from `y` itself for a sphere
//! ([`light_normal`]) so that every place that evaluates `p_man` gets the same number. The
//! estimate is `f_p T(d_jk) f_s(x_k; ω_kj → ω_l) L_e(y) tr / p_man`, MIS-weighted by
//! `rough_lobe::rough_weight` over the four techniques (this, forward NEE at `x_k`, forward BSDF
//! sampling at `x_k` hitting the light, SNEE), computed from the same densities at the four places
//! ([`sample_plane`], [`nee_weight`], [`bsdf_hit_weight`], [`snee_weight`]).

use super::planes::RoughPlane;
use super::rough_lobe::{self, on_boundary, on_plane, Known, Reference, RoughPdfs, RoughTechnique, REFINE_STEPS};
use super::MediumVertex;
use crate::bsdf::fresnel::{fresnel, refract};
use crate::bsdf::{Bsdf, BsdfContext};
use crate::color::Spectrum;
use crate::integrator::snee::light::light_transmission;
use crate::integrator::snee::{with_wi, LightSample, SneeOptions, SneeSuffix, SneeTechnique, SneeVertex};
use crate::integrator::stats::LocalStats;
use crate::interaction::{DirectionSample, SurfaceInteraction};
use crate::math::{Frame, Ray, Vec2, Vec3};
use crate::scene::world::{Scene, SceneEmitter};
use crate::shape::Geometry;

/// The light end of a suffix: a point `y` on the area emitter `emitter` (shape `shape`), its
/// normal `n_y` ([`light_normal`]) and texture coordinates.
#[derive(Clone, Copy, Debug)]
pub struct LightEnd {
    pub y: Vec3,
    pub n_y: Vec3,
    pub uv: Vec2,
    pub emitter: u32,
}

/// The normal of the emitting shape `shape` at its point `y`: for a sphere from `y` itself (so
/// that a sampled point, a ray hit and SNEE's light record give the same normal for the same `y`),
/// otherwise `n_hint` (a triangle's or disk's face normal, exact for any point on it).
pub fn light_normal(scene: &Scene, shape: u32, y: Vec3, n_hint: Vec3) -> Vec3 {
    match &scene.shapes[shape as usize].geometry {
        Geometry::Sphere(s) => {
            let n = (y - s.center).normalize();
            if s.flip_normals {
                -n
            } else {
                n
            }
        }
        _ => n_hint,
    }
}

/// Is `emitter` an area emitter (the lights this connection handles)?
#[inline]
pub fn is_area(scene: &Scene, emitter: u32) -> bool {
    matches!(scene.emitters.get(emitter as usize), Some(SceneEmitter::Area { .. }))
}

/// The light end of an emitter sample `ds` (an area light), or `None`.
pub fn end_of_sample(scene: &Scene, ds: &DirectionSample) -> Option<LightEnd> {
    let SceneEmitter::Area { shape, .. } = scene.emitters.get(ds.emitter as usize)? else { return None };
    let n_y = light_normal(scene, *shape, ds.p, ds.n);
    Some(LightEnd { y: ds.p, n_y, uv: ds.uv, emitter: ds.emitter })
}

/// The light end of an emitter hit `hit` (any point `y`, e.g. SNEE's light point, with the hit
/// giving the shape), or `None` when `hit` is not on an area light.
pub fn end_of_hit(scene: &Scene, hit: &SurfaceInteraction, y: Vec3) -> Option<LightEnd> {
    let emitter = scene.shapes[hit.shape as usize].emitter?;
    is_area(scene, emitter).then(|| LightEnd { y, n_y: light_normal(scene, hit.shape, y, hit.n), uv: hit.uv, emitter })
}

/// `p_A(y | x_j)`: the density by area with which emitter sampling from `p_j` picks `y`
/// (selection included; 0 where `y` faces away from `p_j`, e.g. the far side of a sphere).
pub fn y_density(scene: &Scene, p_j: Vec3, end: &LightEnd) -> f64 {
    let v = end.y - p_j;
    let d_jy = v.length();
    if !(d_jy > 0.0) {
        return 0.0;
    }
    let d = v / d_jy;
    let ds = DirectionSample {
        p: end.y,
        n: end.n_y,
        uv: end.uv,
        d,
        dist: d_jy,
        pdf: 0.0,
        delta: false,
        emitter: end.emitter,
    };
    let p_dir = scene.pdf_emitter_direction(p_j, &ds) as f64;
    let d_jy = d_jy as f64;
    let p = p_dir * end.n_y.dot(d).abs() as f64 / (d_jy * d_jy);
    if p.is_finite() && p > 0.0 {
        p
    } else {
        0.0
    }
}

/// The reverse of `omega` (unit, towards the light) refracted smoothly into the medium about the
/// normal of `frame` with relative index `eta` (interior over exterior): the direction from a
/// point inside towards where the α → 0 refraction happens. `None` behind the frame or under
/// total internal reflection.
fn refracted_reverse(frame: Frame, eta: f32, omega: Vec3) -> Option<Vec3> {
    let wl = frame.to_local(omega);
    let (f, cos_t, _, eta_ti) = fresnel(wl.z, eta);
    if !(wl.z > 0.0) || f >= 1.0 {
        return None;
    }
    Some(-frame.to_world(refract(wl, cos_t, eta_ti)).normalize())
}

/// The index of the rough dielectric `bsdf` (1 for anything else).
fn eta_of(bsdf: &Bsdf) -> f32 {
    match bsdf {
        Bsdf::RoughDielectric(r) => r.eta,
        _ => 1.0,
    }
}

/// The reference in which the connection from `p_j` (inside `medium`) towards the light point
/// `y` samples the inner direction, and `omega_ref`, the unit direction from the reference point
/// towards `y`. A deterministic function of `(p_j, y)` (and `plane`), re-evaluated from each
/// path's own `x_j` and `y` by every technique (up to [`REFINE_STEPS`] + 1 rays):
/// - `plane = Some(P)` (a flat orientation): the frame is `P`'s; starting from `y − p_j`, the
///   direction towards `y` is refracted smoothly about `P`'s normal and followed back from `p_j`;
///   its first hit, if on `P`, gives the next point, and `omega_ref` is the direction from the
///   last point reached towards `y`.
/// - `plane = None` (curved): as `rough_lobe::curved_reference` with `omega_l` replaced at each point by
///   the direction towards `y`: `x_0` = first hit of `(p_j, y − p_j)` (must be the enclosing
///   rough boundary met from inside, else `None`: density 0 for every suffix from `p_j` to `y`),
///   then refine; the reference is the last point's shading frame and BSDF.
pub fn point_reference(
    scene: &Scene,
    medium: u32,
    plane: Option<&RoughPlane>,
    p_j: Vec3,
    y: Vec3,
    stats: &mut LocalStats,
) -> Option<(Reference, Vec3)> {
    point_reference_gated(scene, medium, plane, p_j, y, None, stats)?
}

/// [`point_reference`] with the connection's rate decided after the first ray (curved only, as
/// `rough_lobe::curved_reference_gated`): `Some(None)` when `u_rate` is at or above the depth
/// factor of `x_0`'s distance (the connection skips), `None` when there is no reference.
pub fn point_reference_gated(
    scene: &Scene,
    medium: u32,
    plane: Option<&RoughPlane>,
    p_j: Vec3,
    y: Vec3,
    u_rate: Option<f32>,
    stats: &mut LocalStats,
) -> Option<Option<(Reference, Vec3)>> {
    let towards = |p: Vec3| (y - p).normalize();
    let omega_0 = towards(p_j);
    if !omega_0.is_finite() {
        return None;
    }
    match plane {
        Some(plane) => {
            // A sample that reflects in any frame: no refinement (the connection returns none).
            if u_rate.is_some_and(|u| super::rough_rate::reflects(scene, medium, u, 1.0)) {
                return Some(None);
            }
            let reference = Reference::of_plane(plane);
            let eta = eta_of(&scene.bsdfs[plane.bsdf as usize]);
            let mut omega = omega_0;
            for _ in 0..REFINE_STEPS {
                let Some(d) = refracted_reverse(reference.frame, eta, omega) else { break };
                stats.rays += 1;
                match scene.ray_intersect(&Ray::new(p_j, d)) {
                    Some(si) if on_plane(scene, &si, medium, d, plane) => omega = towards(si.p),
                    _ => break,
                }
            }
            Some(Some((reference, omega)))
        }
        None => {
            stats.rays += 1;
            let mut si = scene.ray_intersect(&Ray::new(p_j, omega_0))?;
            if !on_boundary(scene, &si, medium, omega_0) {
                return None;
            }
            let q = super::rough_rate::depth_rate(scene, medium, si.t);
            if u_rate.is_some_and(|u| u as f64 >= q) {
                return Some(None);
            }
            // A sample that reflects in any frame: no refinement (the connection returns none).
            if u_rate.is_some_and(|u| super::rough_rate::reflects(scene, medium, u, q)) {
                return Some(None);
            }
            for _ in 0..REFINE_STEPS {
                let eta = eta_of(scene.bsdf(&si));
                let Some(d) = refracted_reverse(si.sh_frame, eta, towards(si.p)) else { break };
                stats.rays += 1;
                match scene.ray_intersect(&Ray::new(p_j, d)) {
                    Some(next) if on_boundary(scene, &next, medium, d) => si = next,
                    _ => break,
                }
            }
            let reference = Reference { q, ..Reference::of_point(scene, &si) };
            Some(Some((reference, towards(si.p))))
        }
    }
}

/// `p_man` from its parts: `p_A(y | x_j)`, the inner direction's density in the reference, and
/// the conversion from area at `y` to solid angle at `x_k` (`d_ky² / |cos θ_y|`).
fn combine(p_y: f64, p_imp: f64, si_k: &SurfaceInteraction, end: &LightEnd) -> f64 {
    let v = end.y - si_k.p;
    let d_ky2 = v.length_squared() as f64;
    let cos_y = end.n_y.dot(v.normalize()).abs() as f64;
    let p = p_y * p_imp * d_ky2 / cos_y;
    if p.is_finite() && p > 0.0 {
        p
    } else {
        0.0
    }
}

/// The connection's density `p_man` (module header) of the suffix `x_j → x_k → y` that left `x_j`
/// along `omega_jk` (the path's own direction) and reached `x_k = si_k` on `plane` (`None`:
/// curved) and the light at `end`; 0 where the connection cannot make it.
pub fn density(
    scene: &Scene,
    plane: Option<&RoughPlane>,
    x_j: &MediumVertex,
    omega_jk: Vec3,
    si_k: &SurfaceInteraction,
    end: &LightEnd,
    stats: &mut LocalStats,
) -> f64 {
    let p_y = y_density(scene, x_j.p, end);
    if !(p_y > 0.0) {
        return 0.0;
    }
    let Some((r, omega_ref)) = point_reference(scene, x_j.medium, plane, x_j.p, end.y, stats) else { return 0.0 };
    let p_imp = rough_lobe::pdf_inner_ref(scene, &r, omega_ref, omega_jk);
    super::rough_rate::of_vertex(scene, x_j.medium, r.q) * combine(p_y, p_imp, si_k, end)
}

/// SNEE's light record of the light end `end` seen from `x_k` (densities only): `p_light` is
/// emitter sampling's solid-angle density from `x_k`.
pub fn light_record(scene: &Scene, si_k: &SurfaceInteraction, end: &LightEnd) -> LightSample {
    let v = end.y - si_k.p;
    let dist = v.length();
    let d = v / dist;
    let ds =
        DirectionSample { p: end.y, n: end.n_y, uv: end.uv, d, dist, pdf: 0.0, delta: false, emitter: end.emitter };
    LightSample::hit(d, end.y, dist, scene.pdf_emitter_direction(si_k.p, &ds))
}

/// The four densities of the suffix (`rough_lobe::rough_pdfs` with the connection's `p_man`).
#[allow(clippy::too_many_arguments)]
fn pdfs(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    path: (&SurfaceInteraction, Vec3, f32),
    light: &LightSample,
    manifold: f64,
    channel: usize,
    check_support: bool,
    known: Known,
    stats: &mut LocalStats,
) -> RoughPdfs {
    let p = rough_lobe::rough_pdfs(scene, opts, x_i, x_j, path, None, light, channel, check_support, known, stats);
    RoughPdfs { manifold, ..p }
}

/// One verified connection (the weight-consistency test reads its parts).
#[derive(Clone, Copy, Debug)]
pub struct FiniteRoughConnection {
    /// `beta`-free contribution `w · f / p_man`.
    pub value: Spectrum,
    /// Its MIS weight.
    pub weight: f64,
    pub si_k: SurfaceInteraction,
    pub omega_jk: Vec3,
    pub end: LightEnd,
    pub light: LightSample,
    pub pdfs: RoughPdfs,
}

/// The connection from `x_j` through `plane` (`None`: a curved boundary) to the area-light sample
/// `ds` (sampled from `x_j`) with the numbers `(u1, u2)` for the inner direction: sample, trace,
/// verify (the first hit is the boundary from inside, on `plane`; `y` in front of its light and
/// the light segment passable), value and MIS-weight. Counts solutions and failures (a sampled
/// reflection is neither).
#[allow(clippy::too_many_arguments)]
pub fn connect(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    plane: Option<&RoughPlane>,
    ds: &DirectionSample,
    (u1, u2): (f32, Vec2),
    channel: usize,
    stats: &mut LocalStats,
) -> Option<FiniteRoughConnection> {
    let fail = |stats: &mut LocalStats| {
        stats.manifold_failures += 1;
        None
    };
    let end = end_of_sample(scene, ds)?;
    let SceneEmitter::Area { radiance, .. } = &scene.emitters[end.emitter as usize] else { return None };
    let p_y = y_density(scene, x_j.p, &end);
    if !(p_y > 0.0) {
        return None;
    }
    // The depth factor of the rate (`rough_rate::depth_rate`) decided by u1 after x_0.
    let (reference, omega_ref) = match point_reference_gated(scene, x_j.medium, plane, x_j.p, end.y, Some(u1), stats) {
        Some(Some(r)) => r,
        Some(None) => return None,
        None => return fail(stats),
    };
    // u1 < q: rescaled, uniform again.
    let u1 = super::rough_rate::rescale(u1, reference.q);
    let omega_jk = rough_lobe::sample_inner_ref(scene, &reference, omega_ref, u1, u2)?;
    let Some(si_k) = rough_lobe::trace_inner(scene, x_j, plane, omega_jk, stats) else {
        return fail(stats);
    };
    let light = light_record(scene, &si_k, &end);
    // In front of the (one-sided) emitter, and seen from x_k through passable surfaces only.
    if !(end.n_y.dot(light.omega_l) < 0.0) || !(light.p_light > 0.0) {
        return fail(stats);
    }
    let tr = light_transmission(scene, &si_k, &light, stats);
    let le = radiance.eval(end.uv);
    if tr == Spectrum::ZERO || le == Spectrum::ZERO {
        return fail(stats);
    }
    let p_imp = rough_lobe::pdf_inner_ref(scene, &reference, omega_ref, omega_jk);
    // The caller ran the connection with probability q (`rough_rate.rs`).
    let q = super::rough_rate::of_vertex(scene, x_j.medium, reference.q);
    let p_man = q * combine(p_y, p_imp, &si_k, &end);
    if !(p_man > 0.0) {
        return fail(stats);
    }
    stats.manifold_solutions += 1;
    let si_kj = with_wi(&si_k, -omega_jk);
    // The value and forward BSDF sampling's density of omega_l from one evaluation.
    let (f_s, p_bsdf) = scene.bsdf(&si_k).eval_pdf(&BsdfContext::default(), &si_kj, si_k.to_local(light.omega_l));
    let m = &scene.media[x_j.medium as usize];
    let f = m.phase.eval(x_j.wi, omega_jk) * m.transmittance(si_k.t) * f_s * le * tr;
    let known = Known { bsdf: Some(p_bsdf), pdf_snee: None };
    let p = pdfs(scene, opts, x_i, x_j, (&si_k, omega_jk, si_k.t), &light, p_man, channel, true, known, stats);
    let weight = rough_lobe::rough_weight(opts, RoughTechnique::Manifold, p);
    let value = f * (weight / p_man) as f32;
    Some(FiniteRoughConnection { value, weight, si_k, omega_jk, end, light, pdfs: p })
}

/// The weight of forward NEE at a rough `x_k = si_k` (reached right after `x_j`, on `plane`)
/// towards the area-light sample `ds` (sampled from `x_k`); `None` when `ds` is not an area light.
#[allow(clippy::too_many_arguments)]
pub fn nee_weight(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    plane: Option<&RoughPlane>,
    (si_k, omega_jk, d_jk): (&SurfaceInteraction, Vec3, f32),
    ds: &DirectionSample,
    channel: usize,
    stats: &mut LocalStats,
) -> Option<f32> {
    let end = end_of_sample(scene, ds)?;
    let light = LightSample::sampled(ds);
    let p_man = density(scene, plane, x_j, omega_jk, si_k, &end, stats);
    let p = pdfs(scene, opts, x_i, x_j, (si_k, omega_jk, d_jk), &light, p_man, channel, true, Known::default(), stats);
    Some(rough_lobe::rough_weight(opts, RoughTechnique::FwdNee, p) as f32)
}

/// The weight of forward BSDF sampling for a path that left through the rough `x_k` right after
/// `x_j` (`rp`) and hit the area light at `hit` along `omega_l`; `None` when `hit` is not on an
/// area light.
pub fn bsdf_hit_weight(
    scene: &Scene,
    opts: SneeOptions,
    rp: &rough_lobe::RoughPending,
    hit: &SurfaceInteraction,
    channel: usize,
    stats: &mut LocalStats,
) -> Option<f32> {
    let end = end_of_hit(scene, hit, hit.p)?;
    let si_k = &rp.si_k;
    let omega_jk = -si_k.to_world(si_k.wi).normalize();
    let d_jk = (si_k.p - rp.x_j.p).length();
    let light = light_record(scene, si_k, &end);
    let p_man = density(scene, rp.plane.as_ref(), &rp.x_j, omega_jk, si_k, &end, stats);
    let x_i = rp.x_i.as_ref();
    let known = Known::default();
    let p = pdfs(scene, opts, x_i, &rp.x_j, (si_k, omega_jk, d_jk), &light, p_man, channel, true, known, stats);
    Some(rough_lobe::rough_weight(opts, RoughTechnique::FwdBsdf, p) as f32)
}

/// SNEE's weight for a suffix it made through a rough `x_k` (on `plane`) towards the point
/// `light.p` of an area light; `None` when that point is not on an area light seen from `x_k`
/// (SNEE's own weight stands). No rays are counted (SNEE's sample has no statistics here): one
/// ray finds the light's shape, up to three the reference. `pdf_snee`: SNEE's own density of the
/// suffix and light, when its caller has it (`None`: computed here).
pub fn snee_weight(
    scene: &Scene,
    technique: SneeTechnique,
    plane: Option<&RoughPlane>,
    s: &SneeSuffix,
    light: &LightSample,
    channel: usize,
    pdf_snee: Option<f64>,
) -> Option<f64> {
    let hit = super::finite::area_point_hit(scene, &s.si_k, light.omega_l)?;
    let end = end_of_hit(scene, &hit, light.p)?;
    let v_ij = s.x_j - s.x_i.p;
    let t_ij = v_ij.length();
    let v_jk = s.si_k.p - s.x_j;
    let d_jk = v_jk.length();
    if !(t_ij > 0.0) || !(d_jk > 0.0) {
        return None;
    }
    let x_j = MediumVertex { p: s.x_j, wi: -v_ij / t_ij, medium: s.x_i.medium };
    let omega_jk = v_jk / d_jk;
    let opts = SneeOptions { technique, ..scene.integrator.snee };
    let mut no_rays = LocalStats::default();
    let p_man = density(scene, plane, &x_j, omega_jk, &s.si_k, &end, &mut no_rays);
    let path = (&s.si_k, omega_jk, d_jk);
    let known = Known { bsdf: None, pdf_snee };
    let p = pdfs(scene, opts, Some(&s.x_i), &x_j, path, light, p_man, channel, false, known, &mut no_rays);
    Some(rough_lobe::rough_weight(opts, RoughTechnique::Snee, p))
}

//! What the rough-boundary techniques share (docs/manifold.md §7, §7.1, §7.2): the [`Reference`]
//! frame in which the connection samples the inner direction ([`curved_reference`] on a curved
//! boundary), that sampling and its density ([`sample_inner_in`], [`pdf_inner_in`]), the tests of
//! where a hit lies ([`on_plane`], [`on_boundary`]), the four techniques' densities of one suffix
//! ([`rough_pdfs`]), their power heuristic ([`rough_weight`]) and a forward path's pending suffix
//! ([`RoughPending`]). The connections to distant lights (`rough.rs`) and to area lights
//! (`rough_finite.rs`) both build on these; neither depends on the other's internals.

use super::planes::{RoughPlane, SAME_NORMAL};
use super::MediumVertex;
use crate::bsdf::fresnel::{fresnel, refract};
use crate::bsdf::rough_dielectric::RoughDielectric;
use crate::bsdf::{flags, Bsdf, BsdfContext, TransportMode};
use crate::integrator::snee::{with_wi, LightSample, SneeOptions, SneeVertex};
use crate::integrator::stats::LocalStats;
use crate::interaction::SurfaceInteraction;
use crate::math::{Frame, Ray, Vec2, Vec3};
use crate::scene::world::Scene;

/// Where the connection samples the inner direction: a shading frame and a `roughdielectric`
/// (index into `Scene::bsdfs`). Flat: the plane's ([`Reference::of_plane`]); curved: the shading
/// frame where the straight line from `x_j` towards the light meets the boundary
/// ([`curved_reference`]). `wide`: the connection samples the mixture with a wider lobe
/// ([`sample_inner_ref`], docs/manifold.md §7.1 "Defensive lobe"), set for curved boundaries
/// only (on a plane the frame is `x_k`'s own).
#[derive(Clone, Copy, Debug)]
pub struct Reference {
    pub frame: Frame,
    pub bsdf: u32,
    pub wide: bool,
    /// The depth factor of the connection's rate at this `x_j` (`rough_rate::depth_rate`; 1 on a
    /// plane), a factor of `p_man` with the medium's rate.
    pub q: f64,
}

impl Reference {
    /// The frame of a flat orientation (any tangent: the roughness is isotropic).
    #[inline]
    pub fn of_plane(plane: &RoughPlane) -> Self {
        Reference { frame: Frame::from_normal(plane.n), bsdf: plane.bsdf, wide: false, q: 1.0 }
    }

    /// The shading frame and BSDF of the boundary point `si` of a curved boundary (`wide`).
    #[inline]
    pub fn of_point(scene: &Scene, si: &SurfaceInteraction) -> Self {
        Reference { frame: si.sh_frame, bsdf: scene.shapes[si.shape as usize].bsdf, wide: true, q: 1.0 }
    }
}

/// The reference of the connection from `p_j` (inside `medium`) towards a light in the direction
/// `omega_l` through a CURVED rough boundary (docs/manifold.md §7.1): `x_0`, the first hit of the
/// ray `(p_j, omega_l)`, must be `medium`'s enclosing rough boundary met from inside (else `None`:
/// the connection's density is 0 for every suffix from `p_j` towards `omega_l`); then `x_1`, the
/// first hit along the reverse of `omega_l` refracted smoothly about `x_0`'s shading normal (where
/// the α → 0 solution about lands); the reference is `x_1`'s shading frame and BSDF, or `x_0`'s
/// when that refraction is total or `x_1` is not on the boundary. A deterministic function of
/// `(p_j, omega_l)`: every technique that evaluates the connection's density recomputes it from
/// the path's own `x_j` (two rays).
pub fn curved_reference(
    scene: &Scene,
    medium: u32,
    p_j: Vec3,
    omega_l: Vec3,
    stats: &mut LocalStats,
) -> Option<Reference> {
    curved_reference_gated(scene, medium, p_j, omega_l, None, stats)?
}

/// [`curved_reference`], with the connection's rate decided after the first ray: `u_rate`
/// (uniform) at or above the depth factor `q` of `x_0`'s distance (`rough_rate::depth_rate`)
/// returns `Some(None)` (the connection skips this vertex) before the refinement rays; `None`
/// (never skip) for the places that only evaluate the density. `None`: no reference.
pub fn curved_reference_gated(
    scene: &Scene,
    medium: u32,
    p_j: Vec3,
    omega_l: Vec3,
    u_rate: Option<f32>,
    stats: &mut LocalStats,
) -> Option<Option<Reference>> {
    stats.rays += 1;
    let si0 = scene.ray_intersect(&Ray::new(p_j, omega_l))?;
    if !on_boundary(scene, &si0, medium, omega_l) {
        return None;
    }
    let q = super::rough_rate::depth_rate(scene, medium, si0.t);
    if u_rate.is_some_and(|u| u as f64 >= q) {
        return Some(None);
    }
    // A sample that reflects in any frame (`rough_rate::reflects`): the connection returns none
    // whatever the refinement finds.
    if u_rate.is_some_and(|u| super::rough_rate::reflects(scene, medium, u, q)) {
        return Some(None);
    }
    let of = |si: &SurfaceInteraction| Reference { q, ..Reference::of_point(scene, si) };
    let mut si = si0;
    for _ in 0..REFINE_STEPS {
        let Bsdf::RoughDielectric(b) = scene.bsdf(&si) else { break };
        let wl = si.to_local(omega_l);
        let (f, cos_t, _, eta_ti) = fresnel(wl.z, b.eta);
        if !(wl.z > 0.0) || f >= 1.0 {
            break;
        }
        let d = -si.to_world(refract(wl, cos_t, eta_ti)).normalize();
        stats.rays += 1;
        match scene.ray_intersect(&Ray::new(p_j, d)) {
            Some(next) if on_boundary(scene, &next, medium, d) => si = next,
            _ => break,
        }
    }
    Some(Some(of(&si)))
}

/// Refinement steps of [`curved_reference`] (each one ray at every evaluation of the density).
pub(super) const REFINE_STEPS: usize = 2;

/// A surface interaction in the shading frame `sh_frame` whose incident direction is `wi`.
fn frame_si(sh_frame: Frame, wi: Vec3) -> SurfaceInteraction {
    SurfaceInteraction {
        t: 0.0,
        p: Vec3::ZERO,
        n: sh_frame.n,
        sh_frame,
        uv: Vec2::ZERO,
        wi: sh_frame.to_local(wi),
        shape: 0,
        prim: 0,
    }
}

/// Sample the direction `omega_jk` (from `x_j` towards the boundary, `= −omega_in`) through a plane
/// of normal `n` with the rough dielectric `bsdf` lit from `omega_l`: `omega_in ~ bsdf.sample` with
/// `wi = omega_l` in importance mode; `None` when the light is behind the plane or a reflection
/// was sampled. Density: [`pdf_inner`].
pub fn sample_inner(bsdf: &Bsdf, n: Vec3, omega_l: Vec3, u1: f32, u2: Vec2) -> Option<Vec3> {
    sample_inner_in(bsdf, Frame::from_normal(n), omega_l, u1, u2)
}

/// [`sample_inner`] in the shading frame `frame` (its normal `frame.n` takes the plane's place).
pub fn sample_inner_in(bsdf: &Bsdf, frame: Frame, omega_l: Vec3, u1: f32, u2: Vec2) -> Option<Vec3> {
    let n = frame.n;
    if !(n.dot(omega_l) > 0.0) {
        return None;
    }
    let si = frame_si(frame, omega_l);
    let (bs, _) = bsdf.sample(&BsdfContext::new(TransportMode::Importance), &si, u1, u2)?;
    if bs.sampled_type & flags::TRANSMISSION == 0 || !(bs.pdf > 0.0) {
        return None;
    }
    let omega_in = si.to_world(bs.wo).normalize();
    (omega_in.dot(n) < 0.0).then_some(-omega_in)
}

/// Solid-angle density of [`sample_inner`]'s `omega_jk` (the `1 − F` of choosing the
/// transmission included: the directions integrate to the transmitted fraction).
pub fn pdf_inner(bsdf: &Bsdf, n: Vec3, omega_l: Vec3, omega_jk: Vec3) -> f64 {
    pdf_inner_in(bsdf, Frame::from_normal(n), omega_l, omega_jk)
}

/// [`pdf_inner`] in the shading frame `frame`: the density of [`sample_inner_in`].
pub fn pdf_inner_in(bsdf: &Bsdf, frame: Frame, omega_l: Vec3, omega_jk: Vec3) -> f64 {
    inner_local(frame, omega_l, omega_jk).map_or(0.0, |(si, wo)| inner_pdf(bsdf, &si, wo))
}

/// The record and local direction in which [`pdf_inner_in`] evaluates a density in `frame`, or
/// `None` where it is 0 (`omega_l` or `omega_jk` below the frame's normal).
fn inner_local(frame: Frame, omega_l: Vec3, omega_jk: Vec3) -> Option<(SurfaceInteraction, Vec3)> {
    let n = frame.n;
    if !(n.dot(omega_l) > 0.0) || !(omega_jk.dot(n) > 0.0) {
        return None;
    }
    let si = frame_si(frame, omega_l);
    let wo = si.to_local(-omega_jk);
    Some((si, wo))
}

/// `bsdf`'s importance-mode density of `wo` at `si` ([`inner_local`]), 0 where not finite and positive.
fn inner_pdf(bsdf: &Bsdf, si: &SurfaceInteraction, wo: Vec3) -> f64 {
    let p = bsdf.pdf(&BsdfContext::new(TransportMode::Importance), si, wo) as f64;
    if p.is_finite() && p > 0.0 {
        p
    } else {
        0.0
    }
}

/// Share of the wide lobe in the defensive mixture of a curved reference (docs/manifold.md §7.1,
/// "Defensive lobe").
pub const WIDE_SHARE: f32 = 0.5;
/// The wide lobe's roughness: the reference BSDF's `alpha` times this, at most [`WIDE_MAX_ALPHA`].
pub const WIDE_SCALE: f32 = 8.0;
/// Cap of the wide lobe's roughness.
pub const WIDE_MAX_ALPHA: f32 = 0.5;

/// The wide lobe of `bsdf` (a `roughdielectric`; `None` for anything else or when widening
/// changes nothing): the same distribution and index, roughness `min(alpha · WIDE_SCALE,
/// WIDE_MAX_ALPHA)`. The textures are left out: they weigh the value, not the density.
pub fn widened(bsdf: &Bsdf) -> Option<Bsdf> {
    let Bsdf::RoughDielectric(r) = bsdf else { return None };
    let a = (r.alpha_u * WIDE_SCALE).min(WIDE_MAX_ALPHA);
    if !(a > r.alpha_u) {
        return None;
    }
    Some(Bsdf::RoughDielectric(RoughDielectric {
        eta: r.eta,
        inv_eta: r.inv_eta,
        distribution: r.distribution,
        alpha_u: a,
        alpha_v: a,
        sample_visible: r.sample_visible,
        specular_reflectance: None,
        specular_transmittance: None,
    }))
}

/// The one-sample mixture `(1 − s) · lobe + s · wide lobe` (`s` = [`WIDE_SHARE`], the wide lobe
/// [`widened`]) of [`sample_inner_in`] in `frame`: `u2.x` picks the component and is reused.
/// [`sample_inner_in`] itself where there is no wider lobe. Density: [`pdf_inner_mixture`].
pub fn sample_inner_mixture(bsdf: &Bsdf, frame: Frame, omega_l: Vec3, u1: f32, u2: Vec2) -> Option<Vec3> {
    let Some(wide) = widened(bsdf) else { return sample_inner_in(bsdf, frame, omega_l, u1, u2) };
    let s = WIDE_SHARE;
    let below = 1.0 - f32::EPSILON;
    if u2.x < s {
        sample_inner_in(&wide, frame, omega_l, u1, Vec2::new((u2.x / s).min(below), u2.y))
    } else {
        sample_inner_in(bsdf, frame, omega_l, u1, Vec2::new(((u2.x - s) / (1.0 - s)).min(below), u2.y))
    }
}

/// Solid-angle density of [`sample_inner_mixture`]'s `omega_jk`.
pub fn pdf_inner_mixture(bsdf: &Bsdf, frame: Frame, omega_l: Vec3, omega_jk: Vec3) -> f64 {
    let Some(wide) = widened(bsdf) else { return pdf_inner_in(bsdf, frame, omega_l, omega_jk) };
    // `pdf_inner_in` of either component: the tests, frame and local direction built once for both.
    let Some((si, wo)) = inner_local(frame, omega_l, omega_jk) else { return 0.0 };
    let s = WIDE_SHARE as f64;
    (1.0 - s) * inner_pdf(bsdf, &si, wo) + s * inner_pdf(&wide, &si, wo)
}

/// The connection's inner-direction sample in `reference` towards the light along `omega_l`:
/// [`sample_inner_mixture`] for a `wide` (curved) reference, [`sample_inner_in`] on a plane.
/// Density: [`pdf_inner_ref`].
pub fn sample_inner_ref(scene: &Scene, reference: &Reference, omega_l: Vec3, u1: f32, u2: Vec2) -> Option<Vec3> {
    let bsdf = &scene.bsdfs[reference.bsdf as usize];
    if reference.wide {
        sample_inner_mixture(bsdf, reference.frame, omega_l, u1, u2)
    } else {
        sample_inner_in(bsdf, reference.frame, omega_l, u1, u2)
    }
}

/// Solid-angle density of [`sample_inner_ref`]'s `omega_jk`.
pub fn pdf_inner_ref(scene: &Scene, reference: &Reference, omega_l: Vec3, omega_jk: Vec3) -> f64 {
    let bsdf = &scene.bsdfs[reference.bsdf as usize];
    if reference.wide {
        pdf_inner_mixture(bsdf, reference.frame, omega_l, omega_jk)
    } else {
        pdf_inner_in(bsdf, reference.frame, omega_l, omega_jk)
    }
}

/// The first hit from `x_j` along `omega_jk` (one ray, counted) when it is a point of `x_j`'s rough
/// boundary met from inside: on `plane` (flat) or anywhere on a curved boundary (`plane = None`).
pub(super) fn trace_inner(
    scene: &Scene,
    x_j: &MediumVertex,
    plane: Option<&RoughPlane>,
    omega_jk: Vec3,
    stats: &mut LocalStats,
) -> Option<SurfaceInteraction> {
    stats.rays += 1;
    let si = scene.ray_intersect(&Ray::new(x_j.p, omega_jk))?;
    let on = match plane {
        Some(plane) => on_plane(scene, &si, x_j.medium, omega_jk, plane),
        None => on_boundary(scene, &si, x_j.medium, omega_jk),
    };
    on.then_some(si)
}

/// Is `si` (hit from inside `medium` along `d`) on the orientation `plane` of its rough boundary?
pub(super) fn on_plane(scene: &Scene, si: &SurfaceInteraction, medium: u32, d: Vec3, plane: &RoughPlane) -> bool {
    let s = &scene.shapes[si.shape as usize];
    s.interior == Some(medium)
        && s.exterior.is_none()
        && d.dot(si.n) > 0.0
        && s.bsdf == plane.bsdf
        && si.n.dot(plane.n) > SAME_NORMAL
}

/// Is `si` (hit along `d`) a point of `medium`'s enclosing rough boundary, met from inside?
pub(super) fn on_boundary(scene: &Scene, si: &SurfaceInteraction, medium: u32, d: Vec3) -> bool {
    let s = &scene.shapes[si.shape as usize];
    s.interior == Some(medium)
        && s.exterior.is_none()
        && d.dot(si.n) > 0.0
        && matches!(scene.bsdfs[s.bsdf as usize], Bsdf::RoughDielectric(_))
}

/// The four techniques' densities of one suffix `x_j → x_k → light` through a rough plane (solid
/// angle of `omega_jk` at `x_j`, conditioned on `x_j`; for a non-delta light also per solid angle
/// of `omega_l`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RoughPdfs {
    pub manifold: f64,
    pub fwd_nee: f64,
    pub fwd_bsdf: f64,
    /// 0 outside SNEE's support.
    pub snee: f64,
}

/// Densities of one suffix that the caller has already computed, each the same function of the
/// same inputs as [`rough_pdfs`] computes it (so passing them changes no bit): `None` computes it.
#[derive(Clone, Copy, Debug, Default)]
pub struct Known {
    /// `bsdf.pdf(ω_kj → ω_l)` at `x_k` in radiance mode, with `wi = −omega_jk` (the `.1` of the
    /// `eval_pdf` whose `.0` is the connection's `f_s`).
    pub bsdf: Option<f32>,
    /// `snee::pdf_snee` of the suffix with this light (SNEE's own, from its sample).
    pub pdf_snee: Option<f64>,
}

/// The densities of the suffix `x_j → x_k → light` (plus `x_i` before, when it is the SNEE vertex
/// just before `x_j`), with `omega_jk` the direction the path took from `x_j` and `d_jk` its
/// length. The direction is passed rather than recomputed from the points: at small roughness the
/// lobe is narrower than the error of `(x_k − x_j)/d` for a vertex `x_j` close to the surface.
/// `check_support`: test that `x_k` is visible from `x_i` (SNEE's probe); the caller passes
/// `false` when it knows. `reference`: the frame the connection samples this suffix in (`None`:
/// the connection cannot make it, its density is 0). The light segment is the caller's business. `known`: the densities the caller already has, taken as given.
#[allow(clippy::too_many_arguments)]
pub fn rough_pdfs(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    (si_k, omega_jk, d_jk): (&SurfaceInteraction, Vec3, f32),
    reference: Option<&Reference>,
    light: &LightSample,
    channel: usize,
    check_support: bool,
    known: Known,
    stats: &mut LocalStats,
) -> RoughPdfs {
    let m = &scene.media[x_j.medium as usize];
    let st = m.sigma_t[channel] as f64;
    // Forward: phase sampling at x_j, a free flight that survives to x_k.
    let fwd = m.phase.eval(x_j.wi, omega_jk) as f64 * (-st * d_jk as f64).exp();
    let fwd_nee = fwd * light.p_light as f64;
    let fwd_bsdf = if light.delta {
        0.0
    } else {
        let p = known.bsdf.unwrap_or_else(|| {
            let si_kj = with_wi(si_k, -omega_jk);
            scene.bsdf(si_k).pdf(&BsdfContext::default(), &si_kj, si_k.to_local(light.omega_l))
        });
        fwd * p as f64
    };
    let manifold = match reference {
        Some(r) if !light.dist.is_finite() => {
            // The connection runs at x_j with probability q (`rough_rate.rs`).
            let q = super::rough_rate::of_vertex(scene, x_j.medium, r.q);
            q * light.p_light as f64 * pdf_inner_ref(scene, r, light.omega_l, omega_jk)
        }
        _ => 0.0,
    };
    let cos_k = omega_jk.dot(si_k.n).abs() as f64;
    let snee = match known.pdf_snee {
        Some(pdf_snee) => super::mis::snee_solid_angle_pdf_known(scene, opts, x_i, x_j, pdf_snee, channel, cos_k, d_jk),
        None => super::mis::snee_solid_angle_pdf(
            scene,
            opts,
            x_i,
            x_j,
            si_k,
            light,
            channel,
            check_support,
            cos_k,
            d_jk,
            stats,
        ),
    };
    let finite = |x: f64| if x.is_finite() && x > 0.0 { x } else { 0.0 };
    RoughPdfs { manifold: finite(manifold), fwd_nee: finite(fwd_nee), fwd_bsdf: finite(fwd_bsdf), snee: finite(snee) }
}

/// Which technique made a suffix through a rough plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoughTechnique {
    Manifold,
    FwdNee,
    FwdBsdf,
    Snee,
}

/// Weight of `technique` for a suffix with densities `p`: the power heuristic over the four
/// (`snee = mis`); `snee = snee`: SNEE takes what it can make, the others share the rest;
/// `snee = forward`: SNEE's density is 0. `transport = snee`: suffixes outside SNEE's support get 0.
pub fn rough_weight(opts: SneeOptions, technique: RoughTechnique, p: RoughPdfs) -> f64 {
    let own = match technique {
        RoughTechnique::Manifold => Some(p.manifold),
        RoughTechnique::FwdNee => Some(p.fwd_nee),
        RoughTechnique::FwdBsdf => Some(p.fwd_bsdf),
        RoughTechnique::Snee => None,
    };
    super::mis::power_weight(opts, own, &[p.manifold, p.fwd_nee, p.fwd_bsdf], p.snee)
}

/// A forward path that refracted out through a rough plane at `x_k` right after the medium vertex
/// `x_j` (`x_i`: the SNEE vertex before `x_j`, if any), until it escapes to the environment
/// (carried across passable surfaces only, as the connection's light segment).
#[derive(Clone, Copy, Debug)]
pub struct RoughPending {
    pub x_i: Option<SneeVertex>,
    pub x_j: MediumVertex,
    /// `x_k`, its `wi` pointing back to `x_j` along the path.
    pub si_k: SurfaceInteraction,
    /// The orientation of `x_k` (`None`: a curved boundary).
    pub plane: Option<RoughPlane>,
}

//! Manifold NEE through a ROUGH boundary (`roughdielectric`, GGX or Beckmann, isotropic, any
//! `alpha`): from a medium vertex `x_j`, connect to a DIRECTIONAL light or the ENVIRONMENT through a
//! microfacet refraction at the boundary (docs/manifold.md §7, §7.1).
//!
//! The inner direction is sampled from the light side without knowing where `x_k` is:
//! `omega_in ~ bsdf.sample` with `wi = omega_l` in importance mode, in a [`Reference`] frame (a
//! visible microfacet normal seen from the light, refracted; a sampled reflection fails), then
//! `x_k` is the first hit from `x_j` along `omega_jk = −omega_in`. On a FLAT boundary the frame is
//! each plane orientation's (one sample per orientation; `x_k` must lie on that plane); on a
//! CURVED one (interpolated normals, spheres) it is the shading frame where the straight line from
//! `x_j` towards the light meets the boundary ([`curved_reference`], one ray), a deterministic
//! function of `(x_j, omega_l)`, so the density stays evaluable for any path; there half the
//! samples come from a wider lobe (`rough_lobe::sample_inner_ref`, docs/manifold.md §7.1
//! "Defensive lobe"), and `p_imp` below is that mixture's density. Conditioned on `x_j`,
//! the density of `omega_jk` (solid angle at `x_j`) is
//!
//! ```text
//! p_man = p_light · p_imp(omega_in | omega_l, reference)     (p_imp = bsdf.pdf in importance mode)
//! ```
//!
//! (`p_light`: `p_sel` for a directional light, `p_env(omega_l)` for the environment, whose
//! densities are then also per solid angle of `omega_l`)
//!
//! and the estimate `f_p(wi_j, ω_jk) T(d_jk) f_s(x_k; ω_kj → ω_l) tr_light · E / p_man`, with
//! `f_s` Mitsuba's radiance-mode `eval` in the TRUE shading frame at `x_k` (cosine of `ω_l`
//! included). The competitors for the same suffix `x_j → x_k → light`, in the same measure
//! ([`rough_pdfs`]): forward NEE at `x_k` (`f_p e^{−σ_t d_jk} p_light`), forward BSDF sampling
//! (`f_p e^{−σ_t d_jk} bsdf.pdf(ω_kj → ω_l)`, 0 for a delta light, [`bsdf_hit_weight`]) and SNEE
//! from the vertex `x_i` before `x_j` (its `dV(x_j) dA(x_k)` density over forward's density of
//! `x_j` and `dA(x_k)/dω_jk`). The power heuristic over the four, [`rough_weight`], is computed
//! by the same function at the places that make such a suffix: this connection ([`sample`]),
//! forward NEE at `x_k` ([`nee_weight`], through the manifold stage), forward BSDF sampling
//! ([`bsdf_hit_weight`]) and SNEE ([`snee_weight`], through `manifold::snee_weight`); each
//! recomputes the connection's reference from the path's own `x_j`. Where the connection's density
//! is 0 (outside its support, see docs/manifold.md §7.1) the others' weights sum to 1.
//!
//! Scope: directional lights and the environment here; AREA lights at a finite distance (sphere,
//! rectangle, mesh, disk) in [`rough_finite`](super::rough_finite) (docs/manifold.md §7.2), reached
//! from [`sample`], [`nee_weight`], [`emitter_hit_weight`] and [`snee_weight`]; point and spot
//! lights through a rough boundary keep the paper's estimator (the connection contributes nothing
//! for them, so its density is 0 and their weights are unchanged); isotropic roughness.

use super::planes::{MAX_PLANES, SAME_NORMAL};
use super::{light_segment, MediumVertex};
use crate::bsdf::{Bsdf, BsdfContext};
use crate::color::Spectrum;
use crate::integrator::cx::{Cx, Scatter};
use crate::integrator::snee::SneeVertex;
use crate::integrator::snee::{with_wi, LightSample, SneeOptions, SneeSuffix, SneeTechnique};
use crate::integrator::stats::LocalStats;
use crate::interaction::{DirectionSample, SurfaceInteraction};
use crate::math::{Vec2, Vec3};
use crate::scene::world::Scene;
use crate::shape::Geometry;

pub use super::planes::{RoughBoundary, RoughPlane};
pub use super::rough_lobe::{
    curved_reference, pdf_inner, pdf_inner_in, pdf_inner_mixture, pdf_inner_ref, rough_pdfs, rough_weight,
    sample_inner, sample_inner_in, sample_inner_mixture, sample_inner_ref, Known, Reference, RoughPdfs, RoughPending,
    RoughTechnique,
};
use super::rough_lobe::{on_boundary, on_plane, trace_inner};

/// Per medium of `scene`: its rough boundary, or `None` (no emitter, the medium does not sample
/// emitters, or some enclosing shape is not a mesh or sphere with an isotropic `roughdielectric`).
/// Flat-shaded meshes with at most [`MAX_PLANES`] orientations enumerate their planes; anything else
/// (interpolated normals, spheres, more orientations) is `curved` (docs/manifold.md §7.1).
pub fn rough_boundaries(scene: &Scene) -> Vec<Option<RoughBoundary>> {
    let lit = !scene.emitters.is_empty();
    (0..scene.media.len() as u32).map(|m| if lit { rough_boundary(scene, m) } else { None }).collect()
}

fn rough_boundary(scene: &Scene, medium: u32) -> Option<RoughBoundary> {
    if !scene.media[medium as usize].sample_emitters {
        return None;
    }
    let mut planes: Vec<RoughPlane> = Vec::new();
    let mut reflect_below = f64::INFINITY;
    let mut enclosed = false;
    let mut curved = false;
    for s in scene.shapes.iter().filter(|s| s.interior == Some(medium) && s.exterior.is_none()) {
        match &scene.bsdfs[s.bsdf as usize] {
            Bsdf::RoughDielectric(r) if r.alpha_u == r.alpha_v => {
                reflect_below = reflect_below.min(super::rough_rate::reflect_below(r.eta));
            }
            Bsdf::RoughDielectric(_) | Bsdf::Dielectric(_) => return None,
            _ => continue,
        }
        enclosed = true;
        let mesh = match &s.geometry {
            Geometry::Mesh(mesh) => mesh,
            Geometry::Sphere(_) => {
                curved = true;
                continue;
            }
            _ => return None,
        };
        for (prim, idx) in mesh.indices.iter().enumerate() {
            if curved {
                break;
            }
            let n = match super::flat::flat_face_normal(mesh, prim, idx) {
                super::flat::FaceNormal::Flat(n) => n,
                super::flat::FaceNormal::Degenerate => continue,
                super::flat::FaceNormal::Curved => {
                    curved = true;
                    break;
                }
            };
            if !planes.iter().any(|q| q.bsdf == s.bsdf && q.n.dot(n) > SAME_NORMAL) {
                planes.push(RoughPlane { n, bsdf: s.bsdf });
                curved |= planes.len() > MAX_PLANES;
            }
        }
    }
    let q = super::rough_rate::rate(scene, medium);
    if curved {
        return enclosed.then_some(RoughBoundary { planes: Vec::new(), curved: true, q, reflect_below });
    }
    (enclosed && !planes.is_empty()).then_some(RoughBoundary { planes, curved: false, q, reflect_below })
}

/// The rough boundary of `medium` (built with `connection = complete`).
#[inline]
pub fn boundary_of(scene: &Scene, medium: u32) -> Option<&RoughBoundary> {
    super::tables(scene)?.rough.get(medium as usize)?.as_ref()
}

/// The reference in which the connection at `x_j` would have sampled a suffix towards `omega_l`
/// whose boundary point is on `plane` (flat) or anywhere on a curved boundary (`plane = None`).
fn reference_of(
    scene: &Scene,
    plane: Option<&RoughPlane>,
    x_j: &MediumVertex,
    omega_l: Vec3,
    stats: &mut LocalStats,
) -> Option<Reference> {
    match plane {
        Some(p) => Some(Reference::of_plane(p)),
        None => curved_reference(scene, x_j.medium, x_j.p, omega_l, stats),
    }
}

/// Is `si` (hit along `d`) on the boundary `rb` of `medium`, and on which plane (`Some(None)`: a
/// curved boundary, `None`: not on it)?
fn locate(
    scene: &Scene,
    rb: &RoughBoundary,
    si: &SurfaceInteraction,
    medium: u32,
    d: Vec3,
) -> Option<Option<RoughPlane>> {
    if rb.curved {
        return on_boundary(scene, si, medium, d).then_some(None);
    }
    let plane = rb.plane_at(si.n, scene.shapes[si.shape as usize].bsdf)?;
    on_plane(scene, si, medium, d, plane).then_some(Some(*plane))
}

/// One verified connection through a rough plane.
struct RoughConnection {
    si_k: SurfaceInteraction,
    omega_jk: Vec3,
    /// `f_p · T · f_s · tr_light` (without the light's `E / p_sel` and the density).
    f: Spectrum,
    /// Forward BSDF sampling's density of `omega_l` at `x_k` (`eval_pdf` with `f_s`).
    p_bsdf: f32,
}

/// Sample `omega_jk` in `reference` ([`sample_inner_in`]), find `x_k` (the first hit from `x_j`
/// must lie on `plane` of the boundary, or anywhere on a curved boundary (`plane = None`), seen
/// from inside) and the light segment. The value takes the BSDF and shading frame of the `x_k`
/// found. Counts solutions and failures (a sampled reflection is neither).
#[allow(clippy::too_many_arguments)]
fn connect(
    scene: &Scene,
    x_j: &MediumVertex,
    reference: &Reference,
    plane: Option<&RoughPlane>,
    omega_l: Vec3,
    u1: f32,
    u2: Vec2,
    stats: &mut LocalStats,
) -> Option<RoughConnection> {
    let omega_jk = sample_inner_ref(scene, reference, omega_l, u1, u2)?;
    let Some(si_k) = trace_inner(scene, x_j, plane, omega_jk, stats) else {
        stats.manifold_failures += 1;
        return None;
    };
    let tr = light_segment(scene, &si_k, omega_l, stats);
    if tr == Spectrum::ZERO {
        stats.manifold_failures += 1;
        return None;
    }
    stats.manifold_solutions += 1;
    let si_kj = with_wi(&si_k, -omega_jk);
    let (f_s, p_bsdf) = scene.bsdf(&si_k).eval_pdf(&BsdfContext::default(), &si_kj, si_k.to_local(omega_l));
    let m = &scene.media[x_j.medium as usize];
    let f = m.phase.eval(x_j.wi, omega_jk) * m.transmittance(si_k.t) * f_s * tr;
    Some(RoughConnection { si_k, omega_jk, f, p_bsdf })
}

/// The manifold stage at a real scatter `v` inside the rough boundary `rb`: one emitter sample and,
/// per orientation, one sampled refraction (a 1-D and a 2-D sample each, drawn whatever the light),
/// each MIS-weighted ([`rough_weight`]). A directional light, the environment and area lights
/// (`rough_finite::connect`) are connected; `None` when the depth budget leaves no room for `x_k`
/// (then the connection does not run at `x_j`).
pub fn sample(
    cx: &mut Cx,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    v: &Scatter,
    rb: &RoughBoundary,
) -> Option<Spectrum> {
    let (scene, channel, sampler, stats) = (cx.scene, cx.channel, &mut *cx.sampler, &mut *cx.stats);
    let u: Vec2 = sampler.next_2d();
    if v.depth.saturating_add(1) >= v.max_depth {
        return None;
    }
    // The rate q (`rough_rate.rs`): skip the connection at this vertex with probability 1 − q,
    // consuming its numbers; its density is q · p_man at every place that weighs it.
    if rb.q < 1.0 && sampler.next_1d() as f64 >= rb.q {
        for _ in 0..rb.planes.len() + rb.curved as usize {
            let _ = (sampler.next_1d(), sampler.next_2d());
        }
        return Some(Spectrum::ZERO);
    }
    stats.manifold_attempts += 1;
    let (ds, weight) = scene.sample_emitter_direction(v.p, None, u, false);
    // A directional light or the environment (infinitely far: omega_l is the same at every x_k).
    let distant = ds.pdf > 0.0
        && !ds.dist.is_finite()
        && weight != Spectrum::ZERO
        && (ds.delta || scene.environment == Some(ds.emitter));
    // An area light at a finite distance: `rough_finite.rs` (docs/manifold.md §7.2).
    let area = ds.pdf > 0.0
        && ds.dist.is_finite()
        && !ds.delta
        && weight != Spectrum::ZERO
        && super::rough_finite::is_area(scene, ds.emitter);
    let x_j = MediumVertex { p: v.p, wi: v.wi, medium: v.medium };
    let light =
        LightSample { omega_l: ds.d, p: ds.p, dist: ds.dist, p_light: ds.pdf, delta: ds.delta, le: Spectrum::ZERO };
    let mut result = Spectrum::ZERO;
    // Flat: one sample per orientation, in its plane's frame; curved: one sample in the reference
    // frame found from x_j (docs/manifold.md §7.1).
    for plane in rb.planes.iter().map(Some).chain(rb.curved.then_some(None)) {
        let (u1, u2) = (sampler.next_1d(), sampler.next_2d());
        if area {
            let c = super::rough_finite::connect(scene, opts, x_i, &x_j, plane, &ds, (u1, u2), channel, stats);
            if let Some(c) = c {
                super::add_finite(&mut result, v.beta * c.value, stats);
            }
            continue;
        }
        if !distant {
            continue;
        }
        let reference = match plane {
            Some(p) => Reference::of_plane(p),
            // The depth factor of the rate (`rough_rate::depth_rate`) decided by u1 after x_0.
            None => match super::rough_lobe::curved_reference_gated(scene, x_j.medium, x_j.p, ds.d, Some(u1), stats) {
                Some(Some(r)) => r,
                Some(None) => continue,
                None => {
                    stats.manifold_failures += 1;
                    continue;
                }
            },
        };
        // u1 < q: rescaled, uniform again.
        let u1 = super::rough_rate::rescale(u1, reference.q);
        let Some(c) = connect(scene, &x_j, &reference, plane, ds.d, u1, u2, stats) else { continue };
        let path = (&c.si_k, c.omega_jk, c.si_k.t);
        let known = Known { bsdf: Some(c.p_bsdf), pdf_snee: None };
        let r = Some(&reference);
        let p = rough_pdfs(scene, opts, x_i, &x_j, path, r, &light, channel, true, known, stats);
        let w = rough_weight(opts, RoughTechnique::Manifold, p);
        if !(w > 0.0) || !(p.manifold > 0.0) {
            continue;
        }
        // E / p_sel or L / p_env (weight) · w / p_imp, with p_man = p_light · p_imp.
        super::add_finite(&mut result, v.beta * c.f * weight * (w * ds.pdf as f64 / p.manifold) as f32, stats);
    }
    Some(result)
}

/// The weight of forward NEE at a rough `x_k` reached right after the medium vertex `x_j` (where the
/// connection ran; `x_i`: the SNEE vertex just before `x_j`, if any) towards the emitter sample
/// `ds` (an area light: `rough_finite::nee_weight`); `None` where the connection cannot make the
/// path (the caller's weight stands).
#[allow(clippy::too_many_arguments)]
pub fn nee_weight(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    si_k: &SurfaceInteraction,
    ds: &DirectionSample,
    channel: usize,
    stats: &mut LocalStats,
) -> Option<f32> {
    let area = ds.dist.is_finite() && !ds.delta;
    if !area && (ds.dist.is_finite() || !(ds.delta || scene.environment == Some(ds.emitter))) {
        return None;
    }
    let rb = boundary_of(scene, x_j.medium)?;
    // The direction the forward path took (the ray's, not recomputed from the points).
    let omega_jk = -si_k.to_world(si_k.wi).normalize();
    let d_jk = (si_k.p - x_j.p).length();
    let plane = locate(scene, rb, si_k, x_j.medium, omega_jk)?;
    if area {
        let path = (si_k, omega_jk, d_jk);
        return super::rough_finite::nee_weight(scene, opts, x_i, x_j, plane.as_ref(), path, ds, channel, stats);
    }
    if light_segment(scene, si_k, ds.d, stats) == Spectrum::ZERO {
        return None;
    }
    let reference = reference_of(scene, plane.as_ref(), x_j, ds.d, stats);
    let light = LightSample::sampled(ds);
    let path = (si_k, omega_jk, d_jk);
    let (r, known) = (reference.as_ref(), Known::default());
    let p = rough_pdfs(scene, opts, x_i, x_j, path, r, &light, channel, true, known, stats);
    Some(rough_weight(opts, RoughTechnique::FwdNee, p) as f32)
}

/// SNEE's weight for a suffix it made through a rough boundary towards a directional light, the
/// environment or an area light (`rough_finite::snee_weight`), or `None` (another light: SNEE's
/// own weight stands). `pdf_snee`: SNEE's own density of the suffix and light, when the caller has
/// it (`None`: computed here).
pub fn snee_weight(
    scene: &Scene,
    technique: SneeTechnique,
    rb: &RoughBoundary,
    s: &SneeSuffix,
    light: &LightSample,
    channel: usize,
    pdf_snee: Option<f64>,
) -> Option<f64> {
    let area = light.dist.is_finite() && !light.delta;
    if !area && (light.dist.is_finite() || !(light.delta || scene.environment.is_some())) {
        return None;
    }
    let si_k = &s.si_k;
    let v_jk = si_k.p - s.x_j;
    let d_jk = v_jk.length();
    let plane = locate(scene, rb, si_k, s.x_i.medium, v_jk / d_jk)?;
    if area {
        return super::rough_finite::snee_weight(scene, technique, plane.as_ref(), s, light, channel, pdf_snee);
    }
    let v_ij = s.x_j - s.x_i.p;
    let t_ij = v_ij.length();
    if !(t_ij > 0.0) {
        return None;
    }
    let x_j = MediumVertex { p: s.x_j, wi: -v_ij / t_ij, medium: s.x_i.medium };
    let path = (si_k, v_jk / d_jk, d_jk);
    let opts = SneeOptions { technique, ..scene.integrator.snee };
    // SNEE made it: x_k is visible from x_i and the light segment is clear; no rays counted (a
    // curved boundary's reference costs one, SNEE's sample has no statistics to count it in).
    let mut no_rays = LocalStats::default();
    let reference = reference_of(scene, plane.as_ref(), &x_j, light.omega_l, &mut no_rays);
    let (r, known) = (reference.as_ref(), Known { bsdf: None, pdf_snee });
    let p = rough_pdfs(scene, opts, Some(&s.x_i), &x_j, path, r, light, channel, false, known, &mut no_rays);
    Some(rough_weight(opts, RoughTechnique::Snee, p))
}

/// The pending suffix when BSDF sampling at `s` (reached right after `x_j`) refracted out through a
/// rough plane of `x_j`'s boundary; `None` otherwise.
pub fn pending(
    scene: &Scene,
    x_i: Option<SneeVertex>,
    x_j: MediumVertex,
    s: &SurfaceInteraction,
) -> Option<RoughPending> {
    let rb = boundary_of(scene, x_j.medium)?;
    let omega_jk = -s.to_world(s.wi);
    let plane = locate(scene, rb, s, x_j.medium, omega_jk)?;
    Some(RoughPending { x_i, x_j, si_k: *s, plane })
}

/// The weight of forward BSDF sampling for a path that left through the rough boundary right after
/// `x_j` (`rp`) and reached an emitter along `omega_l`: the environment (`hit = None`,
/// [`bsdf_hit_weight`]) or an area light at `hit` (`rough_finite::bsdf_hit_weight`); `None` where
/// the connection does not share the path.
pub fn emitter_hit_weight(
    scene: &Scene,
    opts: SneeOptions,
    rp: &RoughPending,
    hit: Option<&SurfaceInteraction>,
    omega_l: Vec3,
    channel: usize,
    stats: &mut LocalStats,
) -> Option<f32> {
    match hit {
        None => bsdf_hit_weight(scene, opts, rp, omega_l, channel, stats),
        Some(y) => super::rough_finite::bsdf_hit_weight(scene, opts, rp, y, channel, stats),
    }
}

/// The weight of forward BSDF sampling for a path that left through a rough plane right after `x_j`
/// and escaped along `omega_l` to the environment; `None` without an environment.
pub fn bsdf_hit_weight(
    scene: &Scene,
    opts: SneeOptions,
    rp: &RoughPending,
    omega_l: Vec3,
    channel: usize,
    stats: &mut LocalStats,
) -> Option<f32> {
    let light = super::mis::env_light(scene, &rp.si_k, omega_l)?;
    let omega_jk = -rp.si_k.to_world(rp.si_k.wi).normalize();
    let d_jk = (rp.si_k.p - rp.x_j.p).length();
    let path = (&rp.si_k, omega_jk, d_jk);
    let reference = reference_of(scene, rp.plane.as_ref(), &rp.x_j, omega_l, stats);
    let x_i = rp.x_i.as_ref();
    let (r, known) = (reference.as_ref(), Known::default());
    let p = rough_pdfs(scene, opts, x_i, &rp.x_j, path, r, &light, channel, true, known, stats);
    Some(rough_weight(opts, RoughTechnique::FwdBsdf, p) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bsdf::microfacet::MicrofacetType;
    use crate::bsdf::rough_dielectric::RoughDielectric;
    use crate::math::Frame;
    use crate::testing::chi2::{chi2_sphere, sidak};

    /// A frame about `n` whose tangent is turned by `angle` from `Frame::from_normal`'s.
    fn rotated_frame(n: Vec3, angle: f32) -> Frame {
        let base = Frame::from_normal(n);
        let (c, s) = (angle.cos(), angle.sin());
        Frame { s: base.s * c + base.t * s, t: base.t * c - base.s * s, n }
    }

    fn rough(kind: MicrofacetType, alpha: f32, eta: f32) -> Bsdf {
        Bsdf::RoughDielectric(RoughDielectric {
            eta,
            inv_eta: 1.0 / eta,
            distribution: kind,
            alpha_u: alpha,
            alpha_v: alpha,
            sample_visible: true,
            specular_reflectance: None,
            specular_transmittance: None,
        })
    }

    /// The directions `omega_jk` of [`sample_inner`] follow [`pdf_inner`] (chi-square over the
    /// sphere; the sampled reflections are the missing mass), GGX and Beckmann, three roughnesses,
    /// two indices, oblique light on a tilted plane. Sample counts chosen before the first run.
    #[test]
    fn inner_direction_sampling_matches_pdf() {
        let n = Vec3::new(0.2, -0.3, 0.9).normalize();
        let cases: Vec<(MicrofacetType, f32, f32)> = [MicrofacetType::Ggx, MicrofacetType::Beckmann]
            .into_iter()
            .flat_map(|k| [(k, 0.5, 1.33), (k, 0.2, 1.5), (k, 0.08, 1.33), (k, 0.2, 1.0 / 1.33)])
            .collect();
        let level = sidak(0.01, cases.len());
        for (kind, alpha, eta) in cases {
            let bsdf = rough(kind, alpha, eta);
            let omega_l = (n + Vec3::new(0.5, 0.4, -0.1)).normalize();
            let r = chi2_sphere(
                |u1, u2| sample_inner(&bsdf, n, omega_l, u1, u2),
                |d| pdf_inner(&bsdf, n, omega_l, d) as f32,
                32,
                64,
                400_000,
                level,
                7,
            );
            assert!(r.passed, "{kind:?} alpha {alpha} eta {eta}\n{}", r.report);
        }
    }

    /// The same in a shading frame with a rotated tangent (the reference frame of a curved
    /// boundary, docs/manifold.md §7.1), GGX α = 0.2 and 0.04 (the statue's), light from 0° to
    /// 70° off the frame's normal. Sample counts chosen before the first run.
    #[test]
    fn inner_direction_sampling_in_a_shading_frame_matches_pdf() {
        let frame = rotated_frame(Vec3::new(-0.4, 0.1, 0.9).normalize(), 0.6);
        let cases = [(0.2, 0.0), (0.2, 1.2), (0.04, 0.5), (0.04, 1.2)];
        let level = sidak(0.01, cases.len());
        for (alpha, theta) in cases {
            let bsdf = rough(MicrofacetType::Ggx, alpha, 1.5);
            let omega_l = frame.to_world(Vec3::new(f32::sin(theta), 0.0, f32::cos(theta)));
            let r = chi2_sphere(
                |u1, u2| sample_inner_in(&bsdf, frame, omega_l, u1, u2),
                |d| pdf_inner_in(&bsdf, frame, omega_l, d) as f32,
                32,
                64,
                400_000,
                level,
                11,
            );
            assert!(r.passed, "alpha {alpha} theta {theta}\n{}", r.report);
        }
    }

    /// The defensive mixture of a curved reference (docs/manifold.md §7.1, "Defensive lobe"):
    /// [`sample_inner_mixture`] follows [`pdf_inner_mixture`] (chi-square over the sphere; the
    /// sampled reflections are the missing mass), GGX α = 0.04 and 0.2 (the statue's; wide lobes
    /// 0.32 and the cap 0.5) and Beckmann α = 0.02, light 0°–70° off the frame's normal, in a
    /// frame with a rotated tangent. Sample counts chosen before the first run.
    #[test]
    fn defensive_mixture_sampling_matches_pdf() {
        let frame = rotated_frame(Vec3::new(0.3, 0.2, 0.9).normalize(), 1.1);
        let cases = [
            (MicrofacetType::Ggx, 0.04, 1.5, 0.0),
            (MicrofacetType::Ggx, 0.04, 1.5, 1.2),
            (MicrofacetType::Ggx, 0.2, 1.33, 0.6),
            (MicrofacetType::Beckmann, 0.02, 1.5, 0.9),
        ];
        let level = sidak(0.01, cases.len());
        for (kind, alpha, eta, theta) in cases {
            let bsdf = rough(kind, alpha, eta);
            assert!(super::super::rough_lobe::widened(&bsdf).is_some());
            let omega_l = frame.to_world(Vec3::new(f32::sin(theta), 0.0, f32::cos(theta)));
            let r = chi2_sphere(
                |u1, u2| sample_inner_mixture(&bsdf, frame, omega_l, u1, u2),
                |d| pdf_inner_mixture(&bsdf, frame, omega_l, d) as f32,
                32,
                64,
                400_000,
                level,
                13,
            );
            assert!(r.passed, "{kind:?} alpha {alpha} theta {theta}\n{}", r.report);
        }
    }

    #[test]
    fn rough_weights_partition_unity() {
        let all = [RoughTechnique::Manifold, RoughTechnique::FwdNee, RoughTechnique::FwdBsdf, RoughTechnique::Snee];
        for technique in [SneeTechnique::Mis, SneeTechnique::Snee, SneeTechnique::Forward] {
            let opts = SneeOptions { technique, ..SneeOptions::default() };
            for p in [
                RoughPdfs { manifold: 1.0, fwd_nee: 2.0, fwd_bsdf: 3.0, snee: 4.0 },
                RoughPdfs { manifold: 1e-20, fwd_nee: 5.0, fwd_bsdf: 0.0, snee: 0.0 },
                RoughPdfs { manifold: 1e12, fwd_nee: 1e-3, fwd_bsdf: 0.0, snee: 1e10 },
                RoughPdfs { manifold: 0.0, fwd_nee: 1.0, fwd_bsdf: 1.0, snee: 1.0 },
            ] {
                let sum: f64 = all
                    .iter()
                    .filter(|t| **t != RoughTechnique::Snee || technique != SneeTechnique::Forward)
                    .map(|t| rough_weight(opts, *t, p))
                    .sum();
                assert!((sum - 1.0).abs() < 1e-12, "{technique:?} {p:?}: {sum}");
            }
        }
    }
}

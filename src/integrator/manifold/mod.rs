//! Manifold next-event estimation through a flat smooth boundary (`volpath_snee`,
//! `connection = complete`): from every real scattering vertex inside a medium enclosed by a
//! smooth `dielectric`, connect to a light (directional, environment, area, sphere, point, spot)
//! through the refraction at the boundary. Derivation, densities and what is left out: `docs/manifold.md`.
//!
//! | Parameter    | Type   | Description                                                              |
//! |--------------|--------|--------------------------------------------------------------------------|
//! | `connection` | string | `paper` (default): the paper's `volpath_snee` (SNEE + forward tracing); `complete`: also the manifold connection at every medium vertex, combined with SNEE by MIS |
//!
//! ```xml
//! <integrator type="volpath_snee">
//!     <string name="connection" value="complete"/>
//! </integrator>
//! ```
//!
//! Inside a refractive boundary the ordinary NEE shadow ray is always blocked and returns 0; this
//! technique takes its place. Under a delta light (directional, point, spot) it makes suffixes no
//! forward technique can make (a delta light behind a delta interface) and shares V–V–S_t–L
//! suffixes with SNEE; under an environment or an area light it also shares them with forward
//! tracing ([`mis`]). Lights at a finite distance: [`finite`]. Scope (docs/manifold.md §6):
//! boundaries made of flat facets ([`flat`]); ROUGH boundaries, flat or curved, under a
//! directional light or an environment ([`rough`], §7) and under area lights ([`rough_finite`],
//! §7.2); curved smooth boundaries under a
//! directional light ([`curved`], Newton and specular manifold sampling in [`newton`], §8) and
//! under area and sphere lights ([`curved_finite`], [`newton_point`], §8.2); with
//! `reflection_chains`, two-vertex chains under a directional light ([`chain`], §9); with
//! `beams` (default on), light-traced internal-reflection segments under a directional light
//! connected to every medium vertex inside a smooth boundary ([`beam`], docs/beams.md); elsewhere
//! it draws no samples and `volpath_snee` is the paper's estimator.
//!
//! The interface the volpath loop uses: a [`ManifoldStage`] per path next to SNEE's
//! (`stage.rs`: [`sample`] at a medium vertex, the [`Tracker`] at surfaces, [`forward_weight`] for
//! an escaping forward path), and [`snee_weight`] for SNEE's side of the MIS (one call in
//! `snee/sample.rs`). The flat boundaries are built at scene load into `volpath_snee`'s tables
//! ([`Snee::flat`], read through [`tables`]).

pub mod beam;
pub mod beam_boundary;
pub mod camera_beam;
pub mod chain;
pub mod chain_seed;
pub mod curved;
pub mod curved_finite;
pub mod finite;
pub mod flat;
pub mod glint;
pub mod locate;
pub mod meter_glint;
pub mod mis;
pub mod newton;
pub mod newton_point;
pub mod pdf;
pub mod planes;
pub mod rough;
pub mod rough_finite;
pub mod rough_lobe;
pub mod rough_rate;
pub mod split;
pub mod split_bounds;
pub mod stage;
pub mod track;

use super::cx::Cx;
use super::cx::Scatter;
use super::desc::Integrator;
use super::snee::{self, LightSample, Snee, SneeOptions, SneeSuffix, SneeTechnique, SneeTransport, SneeVertex};
use super::stats::LocalStats;
use crate::color::Spectrum;
pub use crate::integrator::snee::options::Connection;
use crate::interaction::{offset_origin, spawn_ray_between, SurfaceInteraction};
use crate::math::{Ray, Vec2, Vec3};
use crate::scene::world::Scene;
use flat::{on_plane, refract_into, FlatBoundary, Plane, Refraction};
pub use stage::ManifoldStage;
pub use track::Tracker;

/// A medium vertex the connection starts from (`x_j` in docs/manifold.md).
#[derive(Clone, Copy, Debug)]
pub struct MediumVertex {
    pub p: Vec3,
    /// Direction back to the previous vertex (the phase function's `wi`).
    pub wi: Vec3,
    pub medium: u32,
}

/// The deterministic part of a connection: the boundary point and the refraction there.
#[derive(Clone, Copy, Debug)]
pub struct ManifoldSuffix {
    pub si_k: SurfaceInteraction,
    pub refraction: Refraction,
    pub plane: Plane,
    /// Distance `x_j → x_k`.
    pub d_jk: f32,
    /// `dV(x_j) / (dA(x_k) dt)` for a delta light: `cos θ_in` (directional), `pdf::point_jacobian`
    /// (point, spot).
    pub jacobian: f32,
}

/// One solution of the connection: its contribution `f / p_sel` without the path throughput and
/// without MIS weight (the caller's business), and the suffix for the weight.
#[derive(Clone, Copy, Debug)]
pub struct ManifoldConnection {
    pub value: Spectrum,
    pub suffix: ManifoldSuffix,
}

/// Does the manifold connection run at all in this render?
#[inline]
pub fn enabled(scene: &Scene) -> bool {
    scene.integrator.connection == Connection::Complete
}

/// `volpath_snee`'s tables as built at scene load (SNEE's, with the flat boundaries in
/// [`Snee::flat`]), when that is the scene's integrator.
#[inline]
pub fn tables(scene: &Scene) -> Option<&Snee> {
    match &scene.integrator {
        Integrator::VolpathSnee(_, snee) => Some(snee),
        _ => None,
    }
}

/// The flat boundary of `medium` where the connection applies (built with `connection = complete`).
#[inline]
pub fn boundary_of(scene: &Scene, medium: u32) -> Option<&FlatBoundary> {
    tables(scene)?.flat.get(medium as usize)?.as_ref()
}

/// The two-vertex chain (reflection, then refraction; `reflection_chains`, docs/manifold.md §9) at
/// a real scatter `v`, where the curved connection runs (after [`sample`]); zero elsewhere. Its
/// suffix is V–S_r–S_t–L, the class `internal_reflection`.
pub fn sample_chain(cx: &mut Cx, opts: SneeOptions, v: &Scatter) -> Spectrum {
    let scene = cx.scene;
    if !opts.chains
        || !enabled(scene)
        || rough::boundary_of(scene, v.medium).is_some()
        || boundary_of(scene, v.medium).is_some()
    {
        return Spectrum::ZERO;
    }
    chain::sample(cx, opts, v)
}

/// Upper bound on the interfaces crossed by one light segment.
const MAX_LIGHT_SEGMENTS: u32 = 64;

/// Transmission of the light segment from `x_k` along `omega_l` to infinity through passable
/// surfaces (`snee::passable`: the same definition as SNEE's, so both techniques have the same
/// support); zero when anything else blocks it.
pub(super) fn light_segment(
    scene: &Scene,
    si_k: &SurfaceInteraction,
    omega_l: Vec3,
    stats: &mut LocalStats,
) -> Spectrum {
    let mut ray = Ray::new(offset_origin(si_k.p, si_k.n, omega_l), omega_l);
    let mut tr = Spectrum::ONE;
    for _ in 0..MAX_LIGHT_SEGMENTS {
        stats.rays += 1;
        let Some(hit) = scene.ray_intersect(&ray) else { return tr };
        if !snee::passable(scene, &hit) {
            return Spectrum::ZERO;
        }
        tr *= scene.bsdf(&hit).eval_null_transmission(&hit);
        ray = Ray::new(offset_origin(hit.p, hit.n, omega_l), omega_l);
    }
    Spectrum::ZERO
}

/// Solve the connection from `x_j` through `plane` to a light in the fixed direction `omega_l`
/// (unit, towards the light: a directional light with `weight = E / p_sel`, or a sampled
/// environment direction with `weight = L / p_env`): refract, trace back from `x_j` along
/// `−omega_in`, verify the first hit lies on that plane of the enclosing boundary, and the light
/// segment. The value is the same for both (docs/manifold.md §3). Counts solutions and failures.
pub fn connect(
    scene: &Scene,
    x_j: &MediumVertex,
    plane: &Plane,
    omega_l: Vec3,
    weight: Spectrum,
    stats: &mut LocalStats,
) -> Option<ManifoldConnection> {
    let refraction = refract_into(plane, omega_l)?;
    let d = -refraction.omega_in;
    stats.rays += 1;
    let hit = scene.ray_intersect(&Ray::new(x_j.p, d));
    let si_k = match hit {
        Some(si) if on_plane(scene, &si, x_j.medium, d, plane) => si,
        _ => {
            stats.manifold_failures += 1;
            return None;
        }
    };
    let tr_out = verified_light_segment(scene, &si_k, omega_l, stats)?;
    let m = &scene.media[x_j.medium as usize];
    let d_jk = si_k.t;
    let value = m.phase.eval(x_j.wi, d)
        * m.transmittance(d_jk)
        * pdf::beam_factor(refraction.fresnel, refraction.cos_l, refraction.cos_in)
        * tr_out
        * weight;
    let jacobian = refraction.cos_in;
    Some(ManifoldConnection { value, suffix: ManifoldSuffix { si_k, refraction, plane: *plane, d_jk, jacobian } })
}

/// The manifold stage at a real scatter `v` (`x_j = v.p`): one emitter sample, every plane's
/// solution, each MIS-weighted against SNEE run at the previous vertex `x_i` (when that was a
/// SNEE vertex and no surface event came between) and, for an environment or an area light,
/// against forward tracing. `None` when the connection does not run here (then its density is 0
/// for suffixes from `x_j`); it draws one 2-D sample whenever it runs.
pub fn sample(cx: &mut Cx, opts: SneeOptions, x_i: Option<&SneeVertex>, v: &Scatter) -> Option<Spectrum> {
    if !enabled(cx.scene) {
        return None;
    }
    // A flat rough boundary: its own connection (`rough.rs`).
    if let Some(rb) = rough::boundary_of(cx.scene, v.medium) {
        return rough::sample(cx, opts, x_i, v, rb);
    }
    let (scene, channel, sampler, stats) = (cx.scene, cx.channel, &mut *cx.sampler, &mut *cx.stats);
    let x_j = MediumVertex { p: v.p, wi: v.wi, medium: v.medium };
    let (beta, depth, max_depth) = (v.beta, v.depth, v.max_depth);
    let Some(boundary) = boundary_of(scene, x_j.medium) else {
        // Curved boundary: one refraction (with `reflection_chains` the two-vertex chain runs
        // after it, [`sample_chain`], returned apart so that `--classes` tallies it apart).
        return curved::sample(cx, opts, x_i, v);
    };
    let u: Vec2 = sampler.next_2d();
    // Same depth budget as forward tracing through x_k to an emitter (and as a SNEE vertex's).
    if depth.saturating_add(1) >= max_depth {
        return None;
    }
    stats.manifold_attempts += 1;
    match finite::pick(scene, u) {
        finite::Pick::Nothing => return Some(Spectrum::ZERO),
        finite::Pick::Finite(lp) => {
            return Some(sample_finite(scene, opts, x_i, &x_j, boundary, &lp, beta, channel, stats))
        }
        finite::Pick::Distant => {}
    }
    let (ds, weight) = scene.sample_emitter_direction(x_j.p, None, u, false);
    // Directional lights (delta, infinitely far) and environments (non-delta, infinitely far).
    if !(ds.pdf > 0.0) || ds.dist.is_finite() || weight == Spectrum::ZERO {
        return Some(Spectrum::ZERO);
    }
    let environment = !ds.delta;
    if environment && scene.environment != Some(ds.emitter) {
        return Some(Spectrum::ZERO);
    }
    let mut result = Spectrum::ZERO;
    for plane in &boundary.planes {
        let Some(c) = connect(scene, &x_j, plane, ds.d, weight, stats) else { continue };
        let w = if environment {
            let Some(light) = mis::env_light(scene, &c.suffix.si_k, ds.d) else { continue };
            let (si_k, r) = (&c.suffix.si_k, &c.suffix.refraction);
            let p_man = mis::env_density(&light, plane, r);
            let p = mis::suffix_pdfs(scene, opts, x_i, &x_j, si_k, r, &light, p_man, channel, true, stats);
            mis::env_weight(opts, mis::EnvTechnique::Manifold, p)
        } else {
            let light =
                LightSample { omega_l: ds.d, p: ds.p, dist: ds.dist, p_light: ds.pdf, delta: true, le: Spectrum::ZERO };
            weight_against_snee(scene, opts, x_i, &x_j, &c.suffix, &light, channel, stats)
        };
        add_finite(&mut result, beta * c.value * w as f32, stats);
    }
    Some(result)
}

/// The light segment from a verified `x_k` ([`light_segment`]): counts the connection as a
/// solution, or as a failure (`None`) when the segment is blocked.
pub(super) fn verified_light_segment(
    scene: &Scene,
    si_k: &SurfaceInteraction,
    omega_l: Vec3,
    stats: &mut LocalStats,
) -> Option<Spectrum> {
    let tr_out = light_segment(scene, si_k, omega_l, stats);
    if tr_out == Spectrum::ZERO {
        stats.manifold_failures += 1;
        return None;
    }
    stats.manifold_solutions += 1;
    Some(tr_out)
}

/// Adds a connection's `contribution` to `result`, or counts it as a rejected sample when it is
/// not finite (no NaN or Inf reaches the film).
pub(crate) fn add_finite(result: &mut Spectrum, contribution: Spectrum, stats: &mut LocalStats) {
    if crate::color::is_finite(contribution) {
        *result += contribution;
    } else {
        stats.rejected_samples += 1;
    }
}

/// The manifold stage's connections to a light point at a finite distance (`lp`), one per
/// supporting plane of the boundary (docs/manifold.md §3.2), MIS-weighted: an area light against
/// forward tracing and SNEE (three-way, [`mis::env_weight`]), a point or spot light against SNEE.
#[allow(clippy::too_many_arguments)]
fn sample_finite(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    boundary: &FlatBoundary,
    lp: &finite::LightPoint,
    beta: Spectrum,
    channel: usize,
    stats: &mut LocalStats,
) -> Spectrum {
    let mut result = Spectrum::ZERO;
    for s in &boundary.supports {
        let Some(c) = finite::connect(scene, x_j, s, lp, stats) else { continue };
        let w = if lp.area.is_some() {
            let p_man = mis::area_density(lp.p_y, c.g, c.cos_y);
            let p =
                mis::suffix_pdfs(scene, opts, x_i, x_j, &c.si_k, &c.refraction, &c.light, p_man, channel, true, stats);
            mis::env_weight(opts, mis::EnvTechnique::Manifold, p)
        } else {
            let jacobian = pdf::point_jacobian(c.light.dist, c.refraction.cos_l, s.plane.eta, c.g);
            let suffix =
                ManifoldSuffix { si_k: c.si_k, refraction: c.refraction, plane: s.plane, d_jk: c.d_jk, jacobian };
            weight_against_snee(scene, opts, x_i, x_j, &suffix, &c.light, channel, stats)
        };
        add_finite(&mut result, beta * c.value * w as f32, stats);
    }
    result
}

impl Tracker {
    /// [`sample`], remembering `x_j` when the connection ran there (for forward paths' weights).
    pub fn sample(&mut self, cx: &mut Cx, opts: SneeOptions, x_i: Option<&SneeVertex>, v: &Scatter) -> Spectrum {
        let r = sample(cx, opts, x_i, v);
        self.x_j = r.map(|_| MediumVertex { p: v.p, wi: v.wi, medium: v.medium });
        r.unwrap_or(Spectrum::ZERO)
    }
}

/// The weight of a forward path that reached a light along `omega_l` right after leaving `x_j`'s
/// medium through a flat plane (`pending`): the environment (`hit` is `None`: it escaped) or an
/// area light (`hit` on it), against the manifold connection and SNEE (docs/manifold.md §4.2);
/// `None` where the manifold connection cannot make the path (the caller's weight stands).
/// `snee_pending`: SNEE's record of the same path, when `x_i` was a SNEE vertex.
#[allow(clippy::too_many_arguments)]
pub fn forward_weight(
    scene: &Scene,
    opts: Option<SneeOptions>,
    pending: Option<&track::Pending>,
    snee_pending: Option<&SneeSuffix>,
    hit: Option<&SurfaceInteraction>,
    omega_l: Vec3,
    channel: usize,
    stats: &mut LocalStats,
) -> Option<f32> {
    let (opts, pending) = (opts?, pending?);
    if !enabled(scene) {
        return None;
    }
    let r = refract_into(&pending.plane, omega_l)?;
    let si_k = &pending.si_k;
    let (light, p_man) = match hit {
        None => {
            let light = mis::env_light(scene, si_k, omega_l)?;
            let p_man = mis::env_density(&light, &pending.plane, &r);
            (light, p_man)
        }
        Some(y) => {
            scene.shapes[y.shape as usize].emitter?;
            boundary_of(scene, pending.x_j.medium)?.support_at(si_k.p, si_k.n, pending.plane.eta)?;
            let d_ky = (y.p - si_k.p).length();
            let ds = scene.direction_sample_for_hit(si_k.p, y);
            let light = LightSample::hit(omega_l, y.p, d_ky, scene.pdf_emitter_direction(si_k.p, &ds));
            let (p_y, cos_y) = finite::area_point_density(scene, y, omega_l);
            let d_jk = (si_k.p - pending.x_j.p).length();
            let g = pdf::plane_geometry(d_jk, d_ky, r.cos_in, r.cos_l, pending.plane.eta);
            (light, mis::area_density(p_y, g, cos_y))
        }
    };
    let x_i = snee_pending.filter(|s| s.x_j == pending.x_j.p).map(|s| &s.x_i);
    let p = mis::suffix_pdfs(scene, opts, x_i, &pending.x_j, si_k, &r, &light, p_man, channel, true, stats);
    Some(mis::env_weight(opts, mis::EnvTechnique::Forward, p) as f32)
}

/// The manifold connection's MIS weight for a suffix it made at `x_j` (docs/manifold.md §4).
#[allow(clippy::too_many_arguments)]
fn weight_against_snee(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    s: &ManifoldSuffix,
    light: &LightSample,
    channel: usize,
    stats: &mut LocalStats,
) -> f64 {
    let p_snee = x_i.map_or(0.0, |x_i| snee_density(scene, opts, x_i, x_j, s, light, channel, stats));
    if p_snee == 0.0 {
        // Outside SNEE's support: the manifold connection is the only technique.
        return if opts.transport == SneeTransport::All { 1.0 } else { 0.0 };
    }
    let x_i = x_i.expect("p_snee > 0 needs x_i");
    let m = &scene.media[x_j.medium as usize];
    let v_ij = x_j.p - x_i.p;
    let t_ij = v_ij.length();
    let p_man =
        pdf::manifold_density(light.p_light, m.phase.eval(x_i.wi, v_ij / t_ij), m.sigma_t[channel], t_ij, s.jacobian);
    pdf::manifold_weight(opts.technique, p_man, p_snee)
}

/// SNEE's density (measure `dt dA(x_k)`) of the suffix `x_i → x_j → x_k → light`, 0 outside its
/// support: SNEE ran at `x_i` (not `snee = forward`), `x_k` is visible from `x_i` (the probe's
/// first hit), and `x_i → x_j` is clear (it is: forward sampled it inside the medium).
#[allow(clippy::too_many_arguments)]
fn snee_density(
    scene: &Scene,
    opts: SneeOptions,
    x_i: &SneeVertex,
    x_j: &MediumVertex,
    s: &ManifoldSuffix,
    light: &LightSample,
    channel: usize,
    stats: &mut LocalStats,
) -> f64 {
    if opts.technique == SneeTechnique::Forward || x_i.medium != x_j.medium {
        return 0.0;
    }
    let inner_k = offset_origin(s.si_k.p, s.si_k.n, x_i.p - s.si_k.p);
    stats.rays += 1;
    if scene.ray_test(&spawn_ray_between(x_i.p, inner_k)) {
        return 0.0;
    }
    let Some(tables) = tables(scene) else { return 0.0 };
    let suffix = SneeSuffix { x_i: *x_i, x_j: x_j.p, si_k: s.si_k };
    let pdf_snee = snee::pdf_snee(scene, tables, &suffix, light, channel);
    let ratio = pdf::solid_angle_ratio(s.refraction.cos_l, s.refraction.cos_in, s.plane.eta);
    pdf::snee_density(pdf_snee, s.d_jk, ratio)
}

/// SNEE's full MIS weight for a suffix SNEE made that the manifold connection can also make, or
/// `None` (SNEE's own weight stands). Delta lights (directional, point, spot): only SNEE and the
/// manifold connection make it (forward tracing cannot), two-way power heuristic in `dt dA(x_k)`;
/// environments and area lights: the three-way weight of [`mis::env_weight`].
pub fn snee_weight(
    scene: &Scene,
    technique: SneeTechnique,
    s: &SneeSuffix,
    light: &LightSample,
    channel: usize,
    pdf_snee: f64,
) -> Option<f64> {
    if !enabled(scene) {
        return None;
    }
    if let Some(rb) = rough::boundary_of(scene, s.x_i.medium) {
        // SNEE computed its own density of this suffix and light: passed, not recomputed.
        return rough::snee_weight(scene, technique, rb, s, light, channel, Some(pdf_snee));
    }
    if let Some(w) = curved_finite::snee_weight(scene, technique, s, light, channel) {
        return Some(w);
    }
    let boundary = boundary_of(scene, s.x_i.medium)?;
    let si_k = &s.si_k;
    let crate::bsdf::Bsdf::Dielectric(d) = scene.bsdf(si_k) else { return None };
    let plane = boundary.planes.iter().find(|p| si_k.n.dot(p.n) > flat::SAME_NORMAL && d.eta == p.eta)?;
    let finite = light.dist.is_finite();
    if finite {
        // The connection to a finite light enumerates supporting planes (none when too many).
        boundary.support_at(si_k.p, si_k.n, d.eta)?;
    }
    let r = refract_into(plane, light.omega_l)?;
    let m = &scene.media[s.x_i.medium as usize];
    let v_ij = s.x_j - s.x_i.p;
    let t_ij = v_ij.length();
    let t_kj = (s.x_j - si_k.p).length();
    if !light.delta {
        let p_man = if finite {
            let (p_y, cos_y) = finite::area_point(scene, si_k, light.omega_l)?;
            let g = pdf::plane_geometry(t_kj, light.dist, r.cos_in, r.cos_l, plane.eta);
            mis::area_density(p_y, g, cos_y)
        } else {
            scene.environment?;
            mis::env_density(light, plane, &r)
        };
        let opts = SneeOptions { technique, ..scene.integrator.snee };
        let x_j = MediumVertex { p: s.x_j, wi: -v_ij / t_ij, medium: s.x_i.medium };
        // No support check: no rays traced, nothing to count.
        let mut no_rays = LocalStats::default();
        let p = mis::suffix_pdfs(scene, opts, Some(&s.x_i), &x_j, si_k, &r, light, p_man, channel, false, &mut no_rays);
        return Some(mis::env_weight(opts, mis::EnvTechnique::Snee, p));
    }
    // The manifold connection runs at x_j if x_j's depth leaves room for x_k: the same condition
    // as x_i being a SNEE vertex, which it is here.
    let jacobian = if finite {
        let g = pdf::plane_geometry(t_kj, light.dist, r.cos_in, r.cos_l, plane.eta);
        pdf::point_jacobian(light.dist, r.cos_l, plane.eta, g)
    } else {
        r.cos_in
    };
    let p_man =
        pdf::manifold_density(light.p_light, m.phase.eval(s.x_i.wi, v_ij / t_ij), m.sigma_t[channel], t_ij, jacobian);
    let p_snee = pdf::snee_density(pdf_snee, t_kj, pdf::solid_angle_ratio(r.cos_l, r.cos_in, plane.eta));
    Some(pdf::snee_weight(technique, p_snee, p_man))
}

//! Manifold NEE to SPHERE and AREA lights through a CURVED smooth boundary (`connection =
//! complete`; docs/manifold.md §8.2): sample a point `y` on the light by area (as `finite.rs`
//! does for flat boundaries), seed deterministically from `(x_j, y)` and solve for `x_k` by
//! Newton iteration ([`newton_point`]), and value the solution with the generalized geometry term
//! `G = dω/dA⊥(y)`:
//!
//! ```text
//! f_p(wi_j, ω_jk) T(d_jk) (1 − F) η² L_e(y) G |cos θ_y| tr_light / (p_sel p_A(y))
//! ```
//!
//! **MIS with forward tracing and SNEE, unbiased without Bernoulli trials.** Forward tracing
//! (phase sampling at `x_j`, refraction, the light hit) and SNEE make the same suffixes. Because
//! the seeds are a function of `(x_j, y)` only, the connection's density of ANY suffix
//! `x_j → x_k → y` is evaluable: `p_man = p_sel p_A(y) / (G |cos θ_y|)` (solid angle of `ω_jk` at
//! `x_j`) if Newton from the seed set `S(x_j, y)` finds this `ω_jk` (verified as the technique
//! verifies it; every distinct solution found is one sample, their contributions summed), else 0 ([`density`], "re-solve from that path's seed"). Solutions the seed set misses
//! have `p_man = 0`, and forward tracing (or SNEE) covers them with weight 1. The three-way power
//! heuristic is `mis::env_weight`, computed from the same three densities at the three places
//! that make such a suffix: the connection ([`sample`]), a forward path that left through the
//! boundary right after `x_j` and hit the light ([`forward_weight`], through the stage's
//! [`Pending`]), and SNEE's sample ([`snee_weight`]).

use super::finite::{self, LightPoint};
use super::locate::{boundary_patch, SceneLocate};
use super::mis::{self, EnvPdfs, EnvTechnique};
use super::newton_point::{self, PointSolution};
use super::{add_finite, MediumVertex};
use crate::bsdf::fresnel::fresnel;
use crate::color::Spectrum;
use crate::integrator::snee::light::light_transmission;
use crate::integrator::snee::{LightSample, SneeOptions, SneeSuffix, SneeTechnique, SneeVertex};
use crate::integrator::stats::LocalStats;
use crate::interaction::SurfaceInteraction;
use crate::math::{DVec3, Ray, Vec3};
use crate::scene::world::{Scene, SceneEmitter};
use crate::shape::Geometry;

/// The connection's top rate `q_top`: the probability that it runs at a medium vertex whose
/// emitter sample picked an area light, when the straight line from the vertex towards the light
/// point leaves the medium at once; deeper vertices run at [`rate_at`]'s lower rate
/// (docs/manifold.md §8.2, "Cost"; the former constant rate's value, kept).
pub const RATE: f64 = 0.05;

/// The smallest factor [`rate_at`] applies to the top rate (deep vertices keep a positive rate).
pub const MIN_DEPTH_FACTOR: f64 = 1e-3;

/// The connection's default top rate in `scene` (when `connection_rate` is not given): over the
/// media it serves (`curved`, per medium), the largest of `min(RATE, q̄ / m(τ))`, with `q̄` =
/// `snee::rate::CONNECTION_MEAN_RATE`, `τ` the medium's optical size (`snee::rate::optical_size`)
/// and `m(τ) = (1 − e^{−τ})/τ` the mean of [`rate_at`]'s depth factor `e^{−σ_t t0}` over depths
/// spread evenly along a chord of optical length `τ` (`snee::rate::mean_depth_factor`); `None`
/// where it serves no medium (the caller then keeps `RATE`). So the connection runs at about `q̄`
/// attempts per medium vertex whatever the medium's thickness (docs/manifold.md §8.2, "Thin
/// media"): in a thin medium every vertex is shallow and the depth factor does not thin the
/// attempts (an attempt costs ~100 ray casts), so the top rate falls; in a thick one (`τ` ≥ ~15)
/// it is `RATE`. A function of the scene only, decided at load.
pub fn default_top_rate(scene: &Scene, curved: &[bool]) -> Option<f64> {
    use crate::integrator::snee::rate::{mean_depth_factor, optical_size, CONNECTION_MEAN_RATE};
    (0u32..)
        .zip(curved)
        .filter(|(_, &c)| c)
        .map(|(m, _)| (CONNECTION_MEAN_RATE / mean_depth_factor(optical_size(scene, m) as f64)).min(RATE))
        .reduce(f64::max)
}

/// The connection's top rate under `opts`: `connection_rate`, else [`RATE`] (`volpath_snee::build`
/// sets it from [`default_top_rate`] when not given).
#[inline]
pub fn rate(opts: SneeOptions) -> f64 {
    opts.connection_rate.map_or(RATE, |q| q as f64)
}

/// The connection's rate `q(x_j, y) = q_top · max(e^{−σ_t t0}, MIN_DEPTH_FACTOR)` at `x_j` in a
/// medium of smallest extinction `sigma_t`, with `t0` the distance along the straight line
/// `x_j → y` to the boundary ([`newton_point::seed_line`]; `None`: factor 1). Proportional to the
/// transmittance the connection's value carries (`d_jk ≈ t0`), so that the connection runs where it
/// brings light and its density keeps its ratio to forward tracing's `f_p e^{−σ_t d_jk} (1 − F)`;
/// a function of `(x_j, y)`, evaluated the same way at the three places that weigh the suffix.
#[inline]
pub fn rate_at(q_top: f64, sigma_t: f64, t0: Option<f64>) -> f64 {
    let factor = t0.map_or(1.0, |t| (-sigma_t * t).exp());
    q_top * factor.clamp(MIN_DEPTH_FACTOR, 1.0)
}

/// The straight line `x_j → y` (one ray cast, counted): [`rate_at`]'s rate and the first seed.
fn seed_line(
    scene: &Scene,
    opts: SneeOptions,
    x_j: &MediumVertex,
    y: Vec3,
    stats: &mut LocalStats,
) -> (f64, Option<DVec3>) {
    let mut locate = SceneLocate { scene, medium: x_j.medium, rays: 0 };
    let (t0, first) = newton_point::seed_line(&mut locate, x_j.p.as_dvec3(), y.as_dvec3());
    stats.rays += locate.rays;
    let sigma_t = scene.media[x_j.medium as usize].sigma_t.min_element() as f64;
    (rate_at(rate(opts), sigma_t, t0), first)
}

/// The deterministic procedure from `x_j` towards `y` (`first`: [`seed_line`]'s seed;
/// [`newton_point::solve_distinct`]: every distinct solution from a fixed set of seeds), each
/// solution verified in the renderer's precision (the f32 hit along it is the enclosing boundary
/// from inside, at the solved point with the solved shading normal, and `y` lies outside both
/// normals there); the verified ones. Counts the Newton work.
fn resolve(
    scene: &Scene,
    x_j: &MediumVertex,
    y: Vec3,
    first: Option<DVec3>,
    stats: &mut LocalStats,
) -> Vec<(PointSolution, SurfaceInteraction)> {
    let mut locate = SceneLocate { scene, medium: x_j.medium, rays: 0 };
    let (p, y64) = (x_j.p.as_dvec3(), y.as_dvec3());
    let d = newton_point::solve_distinct(&mut locate, p, y64, first, newton_point::SEEDS);
    stats.rays += locate.rays;
    stats.manifold_newton_solves += d.solves as u64;
    stats.manifold_newton_iterations += d.iterations as u64;
    stats.manifold_newton_lost += d.lost as u64;
    stats.manifold_newton_failures += d.not_converged as u64;
    let verify = |sol: PointSolution, stats: &mut LocalStats| {
        let omega = sol.omega.as_vec3().normalize();
        stats.rays += 1;
        let si = scene.ray_intersect(&Ray::new(x_j.p, omega))?;
        let to_y = y - si.p;
        let ok = boundary_patch(scene, &si, x_j.medium, omega).is_some()
            && si.n.dot(to_y) > 0.0
            && si.sh_frame.n.dot(to_y) > 0.0
            && (si.p.as_dvec3() - sol.refracted.x_k).length() <= 1e-3 * (1.0 + sol.refracted.t)
            && si.sh_frame.n.as_dvec3().dot(sol.refracted.n_s) > 1.0 - 1e-4;
        ok.then_some((sol, si))
    };
    d.solutions.into_iter().filter_map(|sol| verify(sol, stats)).collect()
}

/// The densities of `x_j → x_k → y` (solid angle of `ω_jk` at `x_j`): the connection's `p_man`
/// given, forward tracing's `f_p e^{−σ_t d_jk} (1 − F)`, SNEE's (0 outside its support; with
/// `check_support` one shadow ray `x_i → x_k`).
#[allow(clippy::too_many_arguments)]
fn pdfs(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    si_k: &SurfaceInteraction,
    omega_jk: Vec3,
    d_jk: f32,
    light: &LightSample,
    manifold: f64,
    channel: usize,
    check_support: bool,
    stats: &mut LocalStats,
) -> EnvPdfs {
    let Some(dielectric) = (match scene.bsdf(si_k) {
        crate::bsdf::Bsdf::Dielectric(d) => Some(d),
        _ => None,
    }) else {
        return EnvPdfs::default();
    };
    // Fresnel about the shading normal (the normal the dielectric refracts about), from outside.
    let f = fresnel(si_k.sh_frame.n.dot(light.omega_l), dielectric.eta).0 as f64;
    let cos_k = omega_jk.dot(si_k.n).abs() as f64;
    mis::pdfs_at(
        scene,
        opts,
        x_i,
        x_j,
        si_k,
        omega_jk,
        d_jk,
        (f, cos_k),
        light,
        manifold,
        channel,
        check_support,
        stats,
    )
}

/// The light's normal at its point `y` as every technique here evaluates it (the connection, a
/// forward hit, SNEE's sample): on an analytic sphere, `(y − center)/radius` (times −1 with
/// `flip_normals`) computed from `y` itself, so that all three weigh the same suffix with the same
/// `cos θ_y` (SNEE's light record carries no normal, and the normal of an f32 ray hit near `y`
/// differs from the sampled one by enough to move `p_man` by ~1.5 % at grazing `θ_y`); elsewhere
/// (rectangles, meshes: a flat triangle's normal does not depend on where on it `y` lies) the
/// given normal `n`.
pub fn light_normal(scene: &Scene, shape: u32, y: Vec3, n: Vec3) -> Vec3 {
    match &scene.shapes[shape as usize].geometry {
        Geometry::Sphere(sp) => {
            let d = (y.as_dvec3() - sp.center.as_dvec3()).normalize();
            let d = if sp.flip_normals { -d } else { d };
            d.as_vec3()
        }
        _ => n,
    }
}

/// Does the light's front at `y` (normal `n_y`) face `x_j`? The connection solves only then (a
/// function of `(x_j, y)`, part of its density: saves the solves towards the back half of a sphere
/// light; the few suffixes near the silhouette it excludes are forward tracing's and SNEE's).
#[inline]
fn faces(n_y: Vec3, y: Vec3, x_j: Vec3) -> bool {
    n_y.dot(x_j - y) > 0.0
}

/// The connection's density of the suffix `x_j → x_k → y` that another technique made along
/// `omega_jk`: re-solve from the path's own seed `(x_j, y)` and keep `q(x_j, y) p_sel p_A(y) / (G
/// |cos θ_y|)` ([`rate_at`]) when the set of solutions holds this `omega_jk` (the nearest solution within
/// `tolerance` radians), else 0 (and 0 when [`faces`] is false). `p_y`: `p_sel p_A(y)`; `n_y`,
/// `cos_y` at `y`.
#[allow(clippy::too_many_arguments)]
fn density(
    scene: &Scene,
    opts: SneeOptions,
    x_j: &MediumVertex,
    omega_jk: Vec3,
    y: Vec3,
    n_y: Vec3,
    p_y: f64,
    cos_y: f32,
    tolerance: f64,
    stats: &mut LocalStats,
) -> f64 {
    if !faces(n_y, y, x_j.p) {
        return 0.0;
    }
    stats.manifold_resolves += 1;
    let (q, first) = seed_line(scene, opts, x_j, y, stats);
    let solutions = resolve(scene, x_j, y, first, stats);
    let w = omega_jk.as_dvec3();
    let nearest = solutions
        .iter()
        .map(|s| ((s.0.omega - w).length(), s))
        .filter(|(d, _)| *d < tolerance)
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, s)| s);
    match nearest {
        Some((sol, _)) => {
            stats.manifold_resolve_matches += 1;
            q * mis::area_density(p_y, sol.g, cos_y)
        }
        None => 0.0,
    }
}

/// One verified connection: its value `f / p` (without the path throughput), its MIS weight, and
/// the suffix (for the weights' consistency test).
#[derive(Clone, Copy, Debug)]
pub struct PointConnection {
    pub value: Spectrum,
    pub weight: f64,
    pub si_k: SurfaceInteraction,
    /// Unit direction `x_j → x_k`.
    pub omega: Vec3,
    pub light: LightSample,
}

/// The connection at `x_j` to the area-light point `lp` (its `area` is `Some`), run with
/// probability `q(x_j, y)` ([`rate_at`]: it runs when the uniform `u_rate` is below it; the straight
/// line's ray is cast only when `u_rate` is below the top rate [`rate`]): solve from the
/// deterministic seeds, verify, and value (divided by `q`) and MIS-weight against forward tracing
/// and SNEE EVERY distinct solution found (their sum is the estimate: each suffix of the set is
/// one sample of the technique, docs/manifold.md §8.2). Counts solutions and failures.
#[allow(clippy::too_many_arguments)]
pub fn connect(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    lp: &LightPoint,
    u_rate: f64,
    channel: usize,
    stats: &mut LocalStats,
) -> Vec<PointConnection> {
    let (Some((n_y, uv)), SceneEmitter::Area { radiance, shape, .. }) = (lp.area, &scene.emitters[lp.emitter as usize])
    else {
        return Vec::new();
    };
    let n_y = light_normal(scene, *shape, lp.y, n_y);
    if u_rate >= rate(opts) {
        return Vec::new();
    }
    if !faces(n_y, lp.y, x_j.p) {
        stats.manifold_failures += 1;
        return Vec::new();
    }
    let (q, first) = seed_line(scene, opts, x_j, lp.y, stats);
    if u_rate >= q {
        return Vec::new();
    }
    let solutions = resolve(scene, x_j, lp.y, first, stats);
    if solutions.is_empty() {
        stats.manifold_failures += 1;
    }
    let mut out = Vec::with_capacity(solutions.len());
    for (sol, si_k) in solutions {
        let to_y = lp.y - si_k.p;
        let d_ky = to_y.length();
        let omega_l = to_y / d_ky;
        let cos_y = -n_y.dot(omega_l);
        if !(cos_y > 0.0) {
            continue; // the back of a one-sided emitter
        }
        let ds = lp.direction_sample(n_y, uv, omega_l, d_ky);
        let light = LightSample::hit(omega_l, lp.y, d_ky, scene.pdf_emitter_direction(si_k.p, &ds));
        let tr = light_transmission(scene, &si_k, &light, stats);
        let le = radiance.eval(uv);
        if tr == Spectrum::ZERO || le == Spectrum::ZERO {
            continue;
        }
        stats.manifold_solutions += 1;
        let m = &scene.media[x_j.medium as usize];
        let omega = sol.omega.as_vec3().normalize();
        let d_jk = si_k.t;
        let eta = sol.patch.eta as f32;
        let f = fresnel(sol.refracted.cos_out as f32, eta).0;
        let geometric = ((1.0 - f) * eta * eta) as f64 * sol.g * cos_y as f64 / (q * lp.p_y);
        let value = m.phase.eval(x_j.wi, omega) * m.transmittance(d_jk) * le * tr * geometric as f32;
        let p_man = q * mis::area_density(lp.p_y, sol.g, cos_y);
        let p = pdfs(scene, opts, x_i, x_j, &si_k, omega, d_jk, &light, p_man, channel, true, stats);
        let weight = mis::env_weight(opts, EnvTechnique::Manifold, p);
        out.push(PointConnection { value, weight, si_k, omega, light });
    }
    out
}

/// The connection's weighted contribution at `x_j` (with `beta`; `u_rate` uniform, [`connect`]):
/// the sum over the solutions it found, zero when it does not run or finds none.
#[allow(clippy::too_many_arguments)]
pub fn sample(
    scene: &Scene,
    opts: SneeOptions,
    x_i: Option<&SneeVertex>,
    x_j: &MediumVertex,
    lp: &LightPoint,
    u_rate: f64,
    beta: Spectrum,
    channel: usize,
    stats: &mut LocalStats,
) -> Spectrum {
    let mut result = Spectrum::ZERO;
    for c in connect(scene, opts, x_i, x_j, lp, u_rate, channel, stats) {
        add_finite(&mut result, beta * c.value * c.weight as f32, stats);
    }
    result
}

/// A forward path that left `x_j`'s curved boundary at `si_k` right after the medium vertex `x_j`
/// (along `omega_jk`), until it hits an emitter (carried across passable surfaces only).
#[derive(Clone, Copy, Debug)]
pub struct Pending {
    pub x_i: Option<SneeVertex>,
    pub x_j: MediumVertex,
    pub si_k: SurfaceInteraction,
    pub omega_jk: Vec3,
}

/// The record of a refraction out at `s` right after the medium vertex `x_j` (the ray leaving
/// `x_j`'s curved boundary there; `None` where the curved connection does not apply or no patch of
/// the boundary holds `s`).
pub fn pending(scene: &Scene, x_i: Option<SneeVertex>, x_j: MediumVertex, s: &SurfaceInteraction) -> Option<Pending> {
    if !super::locate::applies(scene, x_j.medium) {
        return None;
    }
    let omega_jk = s.p - x_j.p;
    let omega_jk = omega_jk / omega_jk.length();
    boundary_patch(scene, s, x_j.medium, omega_jk)?;
    Some(Pending { x_i, x_j, si_k: *s, omega_jk })
}

/// The weight of a forward path `p` that hit the area light at `y` (along `omega_l`): the
/// three-way power heuristic with the connection's density evaluated by re-solving from the
/// path's seed.
pub fn forward_weight(
    scene: &Scene,
    opts: SneeOptions,
    p: &Pending,
    y: &SurfaceInteraction,
    omega_l: Vec3,
    channel: usize,
    stats: &mut LocalStats,
) -> Option<f32> {
    scene.shapes[y.shape as usize].emitter?;
    let (p_y, _) = finite::area_point_density(scene, y, omega_l);
    let n_y = light_normal(scene, y.shape, y.p, y.n);
    let cos_y = n_y.dot(omega_l).abs();
    let d_jk = (p.si_k.p - p.x_j.p).length();
    let p_man = density(scene, opts, &p.x_j, p.omega_jk, y.p, n_y, p_y, cos_y, newton_point::SAME_SOLUTION, stats);
    let ds = scene.direction_sample_for_hit(p.si_k.p, y);
    let light = LightSample::hit(omega_l, y.p, ds.dist, scene.pdf_emitter_direction(p.si_k.p, &ds));
    let pd = pdfs(scene, opts, p.x_i.as_ref(), &p.x_j, &p.si_k, p.omega_jk, d_jk, &light, p_man, channel, true, stats);
    Some(mis::env_weight(opts, EnvTechnique::Forward, pd) as f32)
}

/// How far (radians) SNEE's direction `x_j → x_k`, rebuilt from two `f32` points, may lie from
/// the `f64` solution it is: [`newton_point::SAME_SOLUTION`], or more when `x_k` is so close to
/// `x_j` that the points' rounding (a few ulps of their coordinates) turns the direction by more.
/// The look-up takes the nearest solution within it, so distinct solutions stay apart.
fn direction_tolerance(s: &SneeSuffix, d_jk: f32) -> f64 {
    let ulp = f32::EPSILON as f64 * (s.x_j.abs().max_element().max(s.si_k.p.abs().max_element())) as f64;
    newton_point::SAME_SOLUTION.max(8.0 * ulp / d_jk as f64)
}

/// SNEE's weight for a suffix it made towards a point `light.p` of an area light through a curved
/// boundary (the three-way weight), or `None` where the connection does not apply. No rays are
/// counted (SNEE's sample has no statistics here).
pub fn snee_weight(
    scene: &Scene,
    technique: SneeTechnique,
    s: &SneeSuffix,
    light: &LightSample,
    channel: usize,
) -> Option<f64> {
    if light.delta || !light.dist.is_finite() || !super::locate::applies(scene, s.x_i.medium) {
        return None;
    }
    let opts = SneeOptions { technique, ..scene.integrator.snee };
    let mut no_stats = LocalStats::default();
    let hit = finite::area_point_hit(scene, &s.si_k, light.omega_l)?;
    let (p_y, _) = finite::area_point_density(scene, &hit, light.omega_l);
    // The normal at SNEE's own light point, not at the f32 hit ([`light_normal`]).
    let n_y = light_normal(scene, hit.shape, light.p, hit.n);
    let cos_y = n_y.dot(light.omega_l).abs();
    let v_ij = s.x_j - s.x_i.p;
    let x_j = MediumVertex { p: s.x_j, wi: -v_ij / v_ij.length(), medium: s.x_i.medium };
    let v_jk = s.si_k.p - s.x_j;
    let d_jk = v_jk.length();
    let omega_jk = v_jk / d_jk;
    let p_man =
        density(scene, opts, &x_j, omega_jk, light.p, n_y, p_y, cos_y, direction_tolerance(s, d_jk), &mut no_stats);
    let p = pdfs(scene, opts, Some(&s.x_i), &x_j, &s.si_k, omega_jk, d_jk, light, p_man, channel, false, &mut no_stats);
    Some(mis::env_weight(opts, EnvTechnique::Snee, p))
}

//! Manifold NEE through a CURVED smooth boundary (`connection = complete`): media enclosed by
//! smooth `dielectric` triangle meshes with interpolated shading normals (e.g. the paper's statue)
//! or analytic spheres, under a DIRECTIONAL light (docs/manifold.md §8).
//!
//! From the medium vertex `x_j` the connection seeds the direction from the straight line towards
//! the light (Hanika et al. 2015 §3; [`newton::refracted_seed`]), solves the refraction constraint by Newton
//! iteration on the boundary ([`newton::solve`]; the walk across triangles is the ray cast of
//! each step), verifies the solution (the first hit from `x_j` is `x_k` on the enclosing
//! boundary, seen from inside, the light leaves on the outside of both the geometric and the
//! shading normal, the light segment is passable) and returns
//!
//! ```text
//! f_p(wi_j, omega) · T(d_jk) · (1 − F) η² · dω/dω_l · tr_light · E / p_sel
//! ```
//!
//! (the radiance through the interface is `(1 − F) η² L`, docs/manifold.md §3; integrating the
//! Dirac `δ(o(omega) − omega_l)` over the directions at `x_j` gives `1/|det dω_l/dω|`, the beam
//! spread through the curved surface; on a flat facet it is `cos θ_l / (η² cos θ_in)`).
//!
//! **MIS: a partition.** Under a directional light behind a smooth boundary only SNEE (at the
//! previous vertex `x_i`) and this connection make a suffix `x_j → x_k → light`. The connection
//! finds one solution per seed and has no closed-form density, so instead of the power heuristic
//! the suffixes are partitioned: SNEE keeps every suffix in its support (its density `pdf_snee >
//! 0`: `x_i` a SNEE vertex in the same medium, `x_k` visible from `x_i`), with its own weight
//! unchanged; the connection takes the rest (single scattering, a surface event before `x_j`,
//! `x_k` hidden from `x_i`, SNEE's depth budget), and all of them with `snee = forward`. Unbiased
//! whenever each technique is unbiased on its part; what the single Newton seed misses is
//! measured in the tests (docs/manifold.md §8). Environments, area and point lights through a
//! curved boundary are not connected (weight 0 here: the other techniques' weights stand).

use super::locate::{applies, boundary_patch, SceneLocate};
use super::newton;
use super::{verified_light_segment, MediumVertex};
use crate::bsdf::fresnel::fresnel;
use crate::bsdf::Bsdf;
use crate::color::Spectrum;
use crate::emitter::Emitter;
use crate::integrator::cx::{Cx, Scatter};
use crate::integrator::snee::{LightSample, SneeOptions, SneeVertex};
use crate::integrator::stats::LocalStats;
use crate::interaction::SurfaceInteraction;
use crate::math::{Ray, Vec2, Vec3};
use crate::sampler::Sampler;
use crate::scene::world::{Scene, SceneEmitter};
use crate::shape::Geometry;

/// Per medium of `scene`: does the curved connection apply (a smooth `dielectric` boundary made
/// of meshes and spheres, not flat — flat boundaries take the closed form of `flat.rs`)?
/// Only scenes with a directional or an area (sphere, rectangle, mesh) light: elsewhere the
/// connection would draw samples and contribute nothing (and `complete` renders bit for bit what
/// `paper` renders).
pub fn curved_boundaries(scene: &Scene, flat: &[Option<super::planes::FlatBoundary>]) -> Vec<bool> {
    let lit = scene
        .emitters
        .iter()
        .any(|e| matches!(e, SceneEmitter::Other(Emitter::Directional(_)) | SceneEmitter::Area { .. }));
    (0..scene.media.len())
        .map(|m| lit && flat.get(m).is_none_or(|f| f.is_none()) && curved_boundary(scene, m as u32))
        .collect()
}

fn curved_boundary(scene: &Scene, medium: u32) -> bool {
    if !scene.media[medium as usize].sample_emitters {
        return false;
    }
    let mut enclosed = false;
    for s in scene.shapes.iter().filter(|s| s.interior == Some(medium) && s.exterior.is_none()) {
        match &scene.bsdfs[s.bsdf as usize] {
            Bsdf::Dielectric(_) => {}
            Bsdf::RoughDielectric(_) => return false,
            _ => continue,
        }
        match &s.geometry {
            Geometry::Mesh(_) | Geometry::Sphere(_) => enclosed = true,
            _ => return false,
        }
    }
    enclosed
}

/// The largest relative index `η = η_int / η_ext` of the smooth dielectrics enclosing `medium`
/// (where the connection applies, every enclosing shape is one): bounds how far a solution turns
/// from the light's direction ([`newton::max_turn`]).
pub fn largest_eta(scene: &Scene, medium: u32) -> f64 {
    scene
        .shapes
        .iter()
        .filter(|s| s.interior == Some(medium) && s.exterior.is_none())
        .filter_map(|s| match &scene.bsdfs[s.bsdf as usize] {
            Bsdf::Dielectric(d) => Some(d.eta as f64),
            _ => None,
        })
        .fold(0.0, f64::max)
}

/// A verified connection: its value (without the path throughput and the MIS weight) and `x_k`.
#[derive(Clone, Copy, Debug)]
pub struct CurvedConnection {
    pub value: Spectrum,
    pub si_k: SurfaceInteraction,
    pub omega: Vec3,
}

/// Sample one solution of the connection from `x_j` to a light in the direction `omega_l`
/// (weight `E / p_sel`) with specular manifold sampling's unbiased `1/p` estimate
/// ([`newton::sample_solution`]), verify it, and return `f(s) · N` (docs/manifold.md §8). Counts
/// solves, iterations, failures.
pub fn connect(
    scene: &Scene,
    x_j: &MediumVertex,
    omega_l: Vec3,
    weight: Spectrum,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> Option<CurvedConnection> {
    let mut locate = SceneLocate { scene, medium: x_j.medium, rays: 0 };
    let mut counts = newton::SolveCounts::default();
    let mut u = || sampler.next_1d() as f64;
    let turn = newton::max_turn(largest_eta(scene, x_j.medium));
    let sampled = newton::sample_solution(&mut locate, x_j.p.as_dvec3(), omega_l.as_dvec3(), turn, &mut u, &mut counts);
    stats.rays += locate.rays;
    stats.manifold_newton_solves += counts.solves;
    stats.manifold_newton_iterations += counts.iterations;
    stats.manifold_newton_failures += counts.no_convergence;
    stats.manifold_newton_lost += counts.lost;
    stats.manifold_trials_capped += counts.capped;
    let Some((sol, trials)) = sampled else {
        stats.manifold_failures += 1;
        return None;
    };
    value(scene, x_j, &sol, omega_l, weight, trials as f64, stats)
}

/// Verify a Newton solution `sol` from `x_j` towards `omega_l` in the renderer's own precision
/// (the first hit along it is `x_k`, on the enclosing boundary from inside, with the solved
/// shading normal; the light leaves outside both normals there; the light segment is passable)
/// and return its value `f(s)` times `scale` (the caller's estimate of `1/p(s)`). Counts the
/// connection as a solution or a failure.
pub fn value(
    scene: &Scene,
    x_j: &MediumVertex,
    sol: &newton::Solution,
    omega_l: Vec3,
    weight: Spectrum,
    scale: f64,
    stats: &mut LocalStats,
) -> Option<CurvedConnection> {
    let omega = sol.omega.as_vec3().normalize();
    stats.rays += 1;
    let verified = scene.ray_intersect(&Ray::new(x_j.p, omega)).filter(|si| {
        boundary_patch(scene, si, x_j.medium, omega).is_some()
            && si.n.dot(omega_l) > 0.0
            && si.sh_frame.n.dot(omega_l) > 0.0
            && (si.p.as_dvec3() - sol.refracted.x_k).length() <= 1e-3 * (1.0 + sol.refracted.t)
            && si.sh_frame.n.as_dvec3().dot(sol.refracted.n_s) > 1.0 - 1e-4
    });
    let Some(si_k) = verified else {
        stats.manifold_failures += 1;
        return None;
    };
    let tr_out = verified_light_segment(scene, &si_k, omega_l, stats)?;
    let m = &scene.media[x_j.medium as usize];
    let eta = sol.patch.eta as f32;
    let f = fresnel(sol.refracted.cos_out as f32, eta).0;
    let spread = ((1.0 - f) * eta * eta) as f64 * sol.d_omega_d_omega_l;
    let value = m.phase.eval(x_j.wi, omega) * m.transmittance(si_k.t) * tr_out * weight * (spread * scale) as f32;
    Some(CurvedConnection { value, si_k, omega })
}

/// The curved connection at a real scatter `v` (`x_j = v.p`), or `None` where it does not run
/// (then the caller's flat connection did not run either). Draws one 2-D sample when it runs.
pub fn sample(cx: &mut Cx, opts: SneeOptions, x_i: Option<&SneeVertex>, v: &Scatter) -> Option<Spectrum> {
    let (scene, channel, sampler, stats) = (cx.scene, cx.channel, &mut *cx.sampler, &mut *cx.stats);
    if !applies(scene, v.medium) {
        return None;
    }
    let x_j = MediumVertex { p: v.p, wi: v.wi, medium: v.medium };
    let u: Vec2 = sampler.next_2d();
    if v.depth.saturating_add(1) >= v.max_depth {
        return None;
    }
    stats.manifold_attempts += 1;
    // Where every emitter is an area light the pick below always takes the area-light connection,
    // which runs only if `u_rate` is below its top rate (`curved_finite::connect`): that number is
    // drawn and tested first, so that a vertex where the connection does not run picks no light
    // point. The same numbers in the same order, so the same decisions and images, bit for bit.
    let early_rate = if scene.only_area_emitters {
        let u_rate = sampler.next_1d() as f64;
        if u_rate >= super::curved_finite::rate(opts) {
            return Some(Spectrum::ZERO);
        }
        Some(u_rate)
    } else {
        None
    };
    // The same emitter choice as the flat connection: directional lights here, area and sphere
    // lights in `curved_finite.rs` (docs/manifold.md §8.2), nothing else.
    match super::finite::pick(scene, u) {
        super::finite::Pick::Distant => {}
        super::finite::Pick::Finite(lp) if lp.area.is_some() => {
            let u_rate = early_rate.unwrap_or_else(|| sampler.next_1d() as f64);
            return Some(super::curved_finite::sample(scene, opts, x_i, &x_j, &lp, u_rate, v.beta, channel, stats));
        }
        _ => return Some(Spectrum::ZERO),
    }
    let (ds, weight) = scene.sample_emitter_direction(x_j.p, None, u, false);
    if !(ds.pdf > 0.0) || ds.dist.is_finite() || !ds.delta || weight == Spectrum::ZERO {
        return Some(Spectrum::ZERO);
    }
    let Some(c) = connect(scene, &x_j, ds.d, weight, sampler, stats) else { return Some(Spectrum::ZERO) };
    let light = LightSample { omega_l: ds.d, p: ds.p, dist: ds.dist, p_light: ds.pdf, delta: true, le: Spectrum::ZERO };
    if !opts.keeps_all()
        || super::mis::snee_suffix_pdf(scene, opts, x_i, &x_j, &c.si_k, &light, channel, true, stats).is_some()
    {
        return Some(Spectrum::ZERO);
    }
    let mut result = Spectrum::ZERO;
    super::add_finite(&mut result, v.beta * c.value, stats);
    Some(result)
}

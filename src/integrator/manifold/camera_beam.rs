//! Camera beams: internal reflections of a directional light's beam, seen by the camera through
//! ONE refraction with a single medium vertex on the path (`volpath_snee`, `connection =
//! complete`, `camera_beams`; docs/beams.md, "Camera beams"):
//!
//! ```text
//! camera → x_c (refraction in) → x_b (medium vertex on a beam) → r_k … r_1 (reflections) → x_in → sun
//! ```
//!
//! Beams (`beam.rs`) make these paths only when `x_b`'s predecessor is a camera medium vertex;
//! with `x_b` the camera path's FIRST vertex, `x_b` would have to lie on the camera ray (a set of
//! measure zero), and the two-vertex chain of docs/manifold.md §9 finds them on the statue only
//! with tiny probability (many solutions, tiny basins). Here the light side makes them: per
//! camera sample one light subpath (`beam::trace`), on each reflected beam one point `x_b`
//! (distance sampled in the medium's mean extinction, truncated to the beam), and the camera
//! connection through the boundary solved in the FILM position `u` (2 unknowns): the pinhole ray
//! through `u` refracts in at `x_c(u)` and must pass through `x_b`. The constraint is written on
//! the plane through `x_b` perpendicular to a fixed direction `l` (as `newton_point.rs`):
//!
//! ```text
//! Φ_l(u) = x_c + d_in · ((x_b − x_c)·l / (d_in·l)),   C(u) = P_l (Φ_l(u) − x_b) = 0
//! ```
//!
//! At the solution, with `l = d_in`, `J = dC/du` is `dA⊥(x_b)/du` (area perpendicular to the
//! refracted ray at `x_b` per pixel², a central difference of the closed-form patch map).
//!
//! **The value** (docs/beams.md derives it from the camera side's estimator): the pixel `P`
//! holds `I_P = ∫_P du w(u) ∫ ds T(s) ε(x(u, s), −d_in)` with `w` the radiance-mode refraction
//! weight `(1 − F) τ / η²`, `ε` the in-scattered emission; `dV = |det J| du ds`, and the beams
//! estimate `∫ ε g dV` as `Σ_k Φ_k T(t) / p(t) · σ_s f_p · g` (photon beams). So one light
//! subpath contributes, at the film position `u_s` of each solution,
//!
//! ```text
//! C = Φ_k T(t)/p(t) · σ_s f_p(x_b; ω_bc, −d_k) · T(|x_b − x_c|) · w(x_c) / |det J|
//! ```
//!
//! splatted (`integrator::splat`) and scaled by the render loop by `1 / pixels`.
//!
//! Seed: the film position of the straight line `camera → x_b`; one solve per point, so where
//! several refraction solutions exist only the one Newton reaches from that seed is counted
//! (a bias; on a convex boundary the solution is unique; `--stats` counts solves and splats).
//! Weight 1: under a delta light behind a delta boundary no other technique of `complete` makes
//! these paths except the optional chain, which skips the camera's first medium vertex wherever
//! camera beams run (`ManifoldStage::chain_at_scatter`), so the two partition them.
//!
//! Scope: as the camera's glints (`glint::chains`): a `perspective` sensor in vacuum with a `box`
//! filter, and the media where beams run (`Snee::beams`). The camera ray's first hit must be the
//! boundary (a null surface in front of it is not handled).

use super::beam::{self, Beam};
use super::glint::{agrees, outer_patch, refract_in, CameraMap, GlintLocate, SceneGlint};
use super::newton::{central_jacobian, tangents, Patch};
use crate::bsdf::{flags, BsdfContext, TransportMode};
use crate::color::Spectrum;
use crate::integrator::snee::Snee;
use crate::integrator::splat::{self, Splat};
use crate::integrator::stats::LocalStats;
use crate::interaction::{offset_origin, SurfaceInteraction};
use crate::math::{DVec3, Ray, Vec3};
use crate::sampler::Sampler;
use crate::scene::world::Scene;
use crate::sensor::rfilter::RFilter;
use crate::sensor::Camera;
use glam::DVec2;

/// Newton steps at most per solve.
pub const MAX_ITERATIONS: u32 = 24;
/// Converged when `|C| < TOLERANCE · |x_b − camera|`.
pub const TOLERANCE: f64 = 1e-10;
/// Finite-difference step of the Jacobian (pixels).
const FD_STEP: f64 = 1e-4;

/// Do camera beams run for `scene` (decided at load into `Snee::camera_beams`)? `snee.beams` built.
pub fn applies(scene: &Scene, snee: &Snee) -> bool {
    // The camera glints' conditions (`glint::chains`), read from the options being built.
    snee.options.camera_beams
        && snee.options.keeps_all()
        && matches!(scene.camera, Camera::Perspective(_))
        && matches!(scene.film.filter, RFilter::Box)
        && scene.sensor_medium.is_none()
        && snee.beams.iter().any(Option::is_some)
}

/// The refraction of the camera ray through film position `u` at patch `p1`: `(x_c, d_in, d)`,
/// `d` the camera direction.
#[inline]
fn inner_line(p1: &Patch, cam: &CameraMap, u: DVec2) -> Option<(DVec3, DVec3, DVec3)> {
    let d = cam.direction(u);
    let (_, x_c, n_c) = p1.hit(cam.origin, d)?;
    let cos_1 = -d.dot(n_c);
    if !(cos_1 > 0.0) {
        return None;
    }
    Some((x_c, refract_in(d, n_c, cos_1, p1.eta)?, d))
}

/// `C(u)` in the tangent coordinates of `l` through the fixed patch `p1`.
#[inline]
fn residual(p1: &Patch, cam: &CameraMap, u: DVec2, x_b: DVec3, l: DVec3, lt: (DVec3, DVec3)) -> Option<[f64; 2]> {
    let (x_c, d_in, _) = inner_line(p1, cam, u)?;
    let denom = d_in.dot(l);
    let s = (x_b - x_c).dot(l) / denom;
    if !(denom > 0.0) || !(s > 0.0) {
        return None;
    }
    let v = x_c + d_in * s - x_b;
    Some([v.dot(lt.0), v.dot(lt.1)])
}

/// A converged camera connection to `x_b`.
#[derive(Clone, Copy, Debug)]
pub struct CameraSolution {
    /// Film position (pixels of the full film).
    pub u: DVec2,
    /// Camera direction, refraction point, refracted direction (towards `x_b`).
    pub d: DVec3,
    pub x_c: DVec3,
    pub d_in: DVec3,
    /// `|det dA⊥(x_b)/du|`, m² per pixel².
    pub area_per_pixel: f64,
    pub iterations: u32,
}

/// Solve `C(u) = 0` from `seed` by damped Newton (steps halved until `|C|` decreases, at most 10
/// halvings), relocating the patch by a ray cast at every accepted step.
pub fn solve(locate: &mut impl GlintLocate, cam: &CameraMap, x_b: DVec3, seed: DVec2) -> (Option<CameraSolution>, u32) {
    let tol = TOLERANCE * (x_b - cam.origin).length();
    let mut u = seed;
    let Some((mut p1, _)) = locate.first(cam.origin, cam.direction(u)) else { return (None, 0) };
    for it in 0..=MAX_ITERATIONS {
        let Some((x_c, d_in, d)) = inner_line(&p1, cam, u) else { return (None, it) };
        let (l, lt) = (d_in, tangents(d_in));
        let Some(r) = residual(&p1, cam, u, x_b, l, lt) else { return (None, it) };
        let norm = (r[0] * r[0] + r[1] * r[1]).sqrt();
        let jac = |p1: &Patch| central_jacobian(FD_STEP, |a, b| residual(p1, cam, u + DVec2::new(a, b), x_b, l, lt));
        let Some(j) = jac(&p1) else { return (None, it) };
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if norm < tol {
            if !(det.abs() > 0.0 && det.is_finite()) {
                return (None, it);
            }
            let s = CameraSolution { u, d, x_c, d_in, area_per_pixel: det.abs(), iterations: it };
            return (Some(s), it);
        }
        if it == MAX_ITERATIONS || !(det.abs() > 1e-300) {
            return (None, it);
        }
        let step = -DVec2::new(j[1][1] * r[0] - j[0][1] * r[1], -j[1][0] * r[0] + j[0][0] * r[1]) / det;
        let mut accepted = None;
        let mut scale = 1.0;
        for _ in 0..10 {
            let cand = u + step * scale;
            if let Some((p, _)) = locate.first(cam.origin, cam.direction(cand)) {
                let better = residual(&p, cam, cand, x_b, l, lt).map(|c| (c[0] * c[0] + c[1] * c[1]).sqrt() < norm);
                if better == Some(true) {
                    accepted = Some((cand, p));
                    break;
                }
            }
            scale *= 0.5;
        }
        let Some((cand, p)) = accepted else { return (None, it + 1) };
        u = cand;
        p1 = p;
    }
    (None, MAX_ITERATIONS)
}

/// The point on `beam` for the uniform number `v`: distance sampled in the medium's mean
/// extinction `σ̄`, truncated to the beam, `p(t) = σ̄ e^{−σ̄ t} / (1 − e^{−σ̄ L})`. Returns `(t, 1/p(t))`.
fn beam_point(sigma_mean: f32, len: f32, v: f32) -> Option<(f32, f32)> {
    if !(len > 0.0) || !len.is_finite() {
        return None;
    }
    if !(sigma_mean * len > 1e-6) {
        // Optically thin: uniform on the beam.
        return Some((v * len, len));
    }
    let norm = -(-sigma_mean * len).exp_m1(); // 1 − e^{−σ̄L}
    let t = (-(-v * norm).ln_1p() / sigma_mean).min(len);
    let pdf = sigma_mean * (-sigma_mean * t).exp() / norm;
    (pdf > 0.0 && pdf.is_finite()).then_some((t, 1.0 / pdf))
}

/// Verify a solution with the renderer's f32 rays (the camera ray's first hit is the boundary of
/// `medium` at the solved point and normal, the refracted segment reaches `x_b` unblocked) and
/// return the camera-side factor `w(x_c) T(s) / |det J|` and the direction `x_b → x_c`.
fn verify(
    scene: &Scene,
    cam: &CameraMap,
    medium: u32,
    s: &CameraSolution,
    x_b: Vec3,
    stats: &mut LocalStats,
) -> Option<(Spectrum, Vec3)> {
    let d = s.d.as_vec3().normalize();
    stats.rays += 1;
    let si = scene.ray_intersect(&Ray::new(cam.origin.as_vec3(), d))?;
    let t_c = (s.x_c - cam.origin).length();
    let (patch, m) = outer_patch(scene, &si, d)?;
    let (_, _, n_s) = patch.hit(cam.origin, s.d)?;
    if m != medium || !agrees(&si, s.x_c, n_s, t_c) {
        return None;
    }
    // The camera side's refraction, as the camera path samples it (radiance mode).
    let (wi, d_in) = (si.to_local(-d), s.d_in.as_vec3().normalize());
    let local = SurfaceInteraction { wi, ..si };
    let ctx = BsdfContext { mode: TransportMode::Radiance, type_mask: flags::ALL, component: 1 };
    let (bs, weight) = scene.bsdf(&local).sample(&ctx, &local, 0.5, crate::math::Vec2::splat(0.5))?;
    let wo = local.to_world(bs.wo);
    if !(wo.dot(d_in) > 1.0 - 1e-4) || !(d_in.dot(si.n) < 0.0) || !(bs.wo.z < 0.0) {
        return None;
    }
    // The segment x_c → x_b inside the medium: its first hit lies beyond x_b.
    let o = offset_origin(si.p, si.n, d_in);
    let dist = (x_b - o).length();
    stats.rays += 1;
    if scene.ray_intersect(&Ray::new(o, d_in)).is_some_and(|h| h.t < dist) {
        return None;
    }
    let tr = scene.media[medium as usize].transmittance((x_b - si.p).length());
    Some((weight * tr * (1.0 / s.area_per_pixel) as f32, -d_in))
}

/// Seeds of the camera solve, offsets (pixels) from the film position of the straight line
/// `camera → x_b`: that position first, then a fixed ring around it. Every distinct converged
/// solution is counted once (solutions within [`SAME_SOLUTION`] pixels are one).
const SEED_OFFSETS: [(f64, f64); 5] = [(0.0, 0.0), (4.0, 0.0), (-4.0, 0.0), (0.0, 4.0), (0.0, -4.0)];
/// Two solutions closer than this on the film (pixels) are the same.
const SAME_SOLUTION: f64 = 1e-3;

/// One point on `beam` connected to the camera: a splat per distinct verified solution.
fn connect(scene: &Scene, cam: &CameraMap, medium: u32, beam: &Beam, v: f32, stats: &mut LocalStats) {
    let m = &scene.media[medium as usize];
    let sigma_mean = m.sigma_t.to_array().iter().sum::<f32>() / 3.0;
    let Some((t, inv_pdf)) = beam_point(sigma_mean, beam.len, v) else { return };
    let x_b = beam.o + beam.d * t;
    let Some(u0) = cam.film_position(x_b.as_dvec3() - cam.origin) else { return };
    let mut found: [Option<DVec2>; SEED_OFFSETS.len()] = [None; SEED_OFFSETS.len()];
    for (k, &(dx, dy)) in SEED_OFFSETS.iter().enumerate() {
        let mut locate = SceneGlint { scene, rays: 0 };
        let (sol, it) = solve(&mut locate, cam, x_b.as_dvec3(), u0 + DVec2::new(dx, dy));
        stats.rays += locate.rays;
        stats.camera_beam_solves += 1;
        stats.camera_beam_iterations += it as u64;
        let Some(s) = sol else {
            stats.camera_beam_unsolved += 1;
            continue;
        };
        if found.iter().flatten().any(|u| (*u - s.u).length() < SAME_SOLUTION) {
            continue;
        }
        found[k] = Some(s.u);
        let Some((camera_side, w_bc)) = verify(scene, cam, medium, &s, x_b, stats) else { continue };
        let f_p = m.phase.eval(w_bc, -beam.d);
        let value = beam.flux * m.transmittance(t) * m.sigma_s() * camera_side * (f_p * inv_pdf);
        stats.camera_beam_splats += 1;
        if value.is_finite() {
            splat::push(Splat { pos: s.u, value });
        } else {
            stats.rejected_samples += 1;
        }
    }
}

/// The camera beams of one camera sample: one light subpath per medium where beams run, one point
/// per beam within the depth budget (`x_c`, `x_b`, `k` reflections and the refraction out), each
/// connected to the camera and splatted. Draws nothing where camera beams do not run.
pub fn sample(scene: &Scene, snee: &Snee, sampler: &mut Sampler, stats: &mut LocalStats) {
    if !snee.camera_beams {
        return;
    }
    let Camera::Perspective(p) = &scene.camera else { return };
    let cam = CameraMap::new(p, scene.film.width, scene.film.height);
    let max_depth = u32::try_from(scene.integrator.max_depth).unwrap_or(u32::MAX);
    for (medium, b) in snee.beams.iter().enumerate() {
        let Some(b) = b else { continue };
        let set = beam::trace(scene, medium as u32, b, sampler, stats);
        for beam in set.beams() {
            // Depth after the refraction out: x_c (1), x_b (2), k reflections, the refraction (3 + k).
            if 3 + beam.reflections >= max_depth {
                continue;
            }
            let v = sampler.next_1d();
            stats.camera_beam_points += 1;
            connect(scene, &cam, medium as u32, beam, v, stats);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The truncated exponential's density integrates to 1 over the beam and its samples follow
    /// it (χ² over 32 equal-probability bins, 10⁵ samples, below the 0.999 quantile of χ²(31) ≈ 61.1).
    #[test]
    fn beam_point_density_matches_its_samples() {
        for (sigma, len) in [(2.0f32, 1.5f32), (34.0, 0.3), (1e-8, 2.0)] {
            let cells = 1 << 16;
            let dt = len as f64 / cells as f64;
            let pdf = |t: f64| {
                let s = sigma as f64;
                if s * len as f64 > 1e-6 {
                    s * (-s * t).exp() / (1.0 - (-s * len as f64).exp())
                } else {
                    1.0 / len as f64
                }
            };
            let total: f64 = (0..cells).map(|i| pdf((i as f64 + 0.5) * dt) * dt).sum();
            assert!((total - 1.0).abs() < 1e-6, "∫ pdf = {total}");
            let mut rng = Sampler::new(11, 4);
            let bins = 32usize;
            let mut counts = vec![0u64; bins];
            // Bin edges at the quantiles: F(t) = (1 − e^{−σt}) / (1 − e^{−σL}).
            let n = 100_000;
            for _ in 0..n {
                let (t, inv) = beam_point(sigma, len, rng.next_1d()).expect("point");
                assert!((0.0..=len).contains(&t));
                assert!(((1.0 / inv as f64) / pdf(t as f64) - 1.0).abs() < 1e-3, "1/p at {t}");
                let s = sigma as f64;
                let f = if s * len as f64 > 1e-6 {
                    (1.0 - (-s * t as f64).exp()) / (1.0 - (-s * len as f64).exp())
                } else {
                    t as f64 / len as f64
                };
                counts[((f * bins as f64) as usize).min(bins - 1)] += 1;
            }
            let e = n as f64 / bins as f64;
            let chi2: f64 = counts.iter().map(|&c| (c as f64 - e).powi(2) / e).sum();
            assert!(chi2 < 61.1, "χ² {chi2} (σ {sigma}, L {len})");
        }
    }
}

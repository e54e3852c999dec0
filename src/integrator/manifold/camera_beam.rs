//! Camera beams: internal reflections of a directional light's beam whose only medium vertex is
//! the camera path's first (`volpath_snee`, `connection = complete`, `camera_beams`, opt-in;
//! docs/beams.md, "Camera beams"):
//!
//! ```text
//! camera → x_c (refraction in) → [j internal reflections] → x_b (on a beam) → r_k … r_1 → x_in → sun
//! ```
//!
//! (`j` ≤ `camera_reflections`, default 0). Beams (`beam.rs`) make these paths only when `x_b`'s
//! predecessor is a camera medium vertex; with `x_b` the camera path's FIRST vertex, `x_b` would
//! have to lie on the camera ray (a set of measure zero), and the two-vertex chain of
//! docs/manifold.md §9 finds them on the statue only with tiny probability. Here the light side
//! makes them: per camera sample one light subpath (`beam::trace`), on each reflected beam one
//! point `x_b` (distance sampled in the medium's mean extinction, truncated to the beam), and the
//! camera connection through the boundary solved in the FILM position `u` (2 unknowns): the pinhole
//! ray through `u` refracts in at `x_c(u)`, reflects `j` times, and its last segment (point `x_l`,
//! direction `d_l`) must pass through `x_b`. The constraint is written on the plane through `x_b`
//! perpendicular to a fixed direction `l` (as `newton_point.rs`):
//!
//! ```text
//! Φ_l(u) = x_l + d_l · ((x_b − x_l)·l / (d_l·l)),   C(u) = P_l (Φ_l(u) − x_b) = 0
//! ```
//!
//! At the solution, with `l = d_l`, `J = dC/du` is `dA⊥(x_b)/du` (area perpendicular to the last
//! segment at `x_b` per pixel², a central difference of the closed-form patch map).
//!
//! **The value** (docs/beams.md derives it from the camera side's estimator): the pixel `P`
//! holds `I_P = ∫_P du w(u) ∫ ds T ε(x(u, s), −d_l)` with `w` the radiance-mode weights of the
//! refraction (`(1 − F) τ / η²`) and reflections, `ε` the in-scattered emission; `dV = |det J| du
//! ds`, and the beams estimate `∫ ε g dV` as `Σ_k Φ_k T(t) / p(t) · σ_s f_p · g` (photon beams).
//! So one light subpath contributes, at the film position `u_s` of each solution,
//!
//! ```text
//! C = Φ_k T(t)/p(t) · σ_s f_p(x_b; ω_bc, −d_k) · T(x_c → x_b) · w / |det J|
//! ```
//!
//! splatted (`integrator::splat`) and scaled by the render loop by `1 / pixels`.
//!
//! Seeds: the film position of the straight line `camera → x_b`; on a curved boundary also four
//! points 4 px around it and (with no camera reflection) the film positions of the solutions of
//! the point connection's deterministic procedure from `x_b` towards the pinhole
//! (`newton_point::solve_distinct`); every distinct converged solution counts once. Solutions no
//! seed reaches are missing (a bias: on a flat or convex boundary the refraction has one solution;
//! on the statue about half of the class is found, docs/beams.md; `--stats` counts solves,
//! failures and splats). Weight 1: under a delta
//! light behind a delta boundary no other technique of `complete` makes these paths except the
//! optional chain, which skips such first medium vertices wherever camera beams run
//! (`ManifoldStage::chain_at_scatter`), so the two partition them.
//!
//! Scope: as the camera's glints (`glint::chains`): a `perspective` sensor in vacuum with a `box`
//! filter, and the media where beams run (`Snee::beams`). The camera ray's first hit must be the
//! boundary (a null surface in front of it is not handled).

use super::beam::{self, Beam};
use super::glint::{camera_hit, damped, mirror, newton_step, next_inside, nudge, outer_patch, refract_in, CameraMap};
use super::locate::SceneLocate;
use super::newton::{central_jacobian, tangents, Patch};
use super::newton_point;
use crate::bsdf::TransportMode;
use crate::color::Spectrum;
use crate::integrator::snee::Snee;
use crate::integrator::splat::{self, Splat};
use crate::integrator::stats::LocalStats;
use crate::interaction::offset_origin;
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

/// Most internal reflections of the camera ray between its refraction in and `x_b` that the
/// `camera_reflections` parameter may ask for.
pub const MAX_CAMERA_REFLECTIONS: usize = 2;

/// The located boundary patches of a camera chain: the refraction in at `x_c`, then `j` internal
/// reflections.
#[derive(Clone, Copy, Debug)]
pub struct Chain {
    pub p1: Patch,
    pub refl: [Option<Patch>; MAX_CAMERA_REFLECTIONS],
    pub j: usize,
}

/// The chain's closed-form map at film position `u` through its fixed patches.
#[derive(Clone, Copy, Debug)]
pub struct ChainMap {
    /// Camera direction.
    pub d: DVec3,
    /// Refraction point and its outward shading normal, then the reflection points and normals.
    pub x: [DVec3; MAX_CAMERA_REFLECTIONS + 1],
    pub n: [DVec3; MAX_CAMERA_REFLECTIONS + 1],
    /// Direction of the segment after the last interface (towards `x_b` at a solution).
    pub dir: DVec3,
    /// Inner length from `x_c` to the last interface.
    pub len: f64,
}

/// The map of `chain` at `u`, or `None` when an interface is missed or met from the wrong side.
pub fn chain_map(chain: &Chain, cam: &CameraMap, u: DVec2) -> Option<ChainMap> {
    let d = cam.direction(u);
    let (_, x_c, n_c) = chain.p1.hit(cam.origin, d)?;
    let cos_1 = -d.dot(n_c);
    if !(cos_1 > 0.0) {
        return None;
    }
    let mut dir = refract_in(d, n_c, cos_1, chain.p1.eta)?;
    let mut m =
        ChainMap { d, x: [x_c; MAX_CAMERA_REFLECTIONS + 1], n: [n_c; MAX_CAMERA_REFLECTIONS + 1], dir, len: 0.0 };
    let mut at = x_c;
    for i in 0..chain.j {
        let q = chain.refl[i]?;
        let e = nudge(at);
        let (t, x, n) = q.hit(at + dir * e, dir)?;
        let c = dir.dot(n);
        if !(t > 0.0) || !(c > 0.0) {
            return None;
        }
        m.len += t + e;
        dir = mirror(dir, n, c);
        at = x;
        m.x[i + 1] = x;
        m.n[i + 1] = n;
    }
    m.dir = dir;
    Some(m)
}

/// The chain's patches at `u`, located by ray casts in the scene (`j` internal reflections of the
/// camera ray inside `medium`'s boundary, each the first hit of the previous segment).
pub fn locate(scene: &Scene, cam: &CameraMap, u: DVec2, j: usize, medium: u32, rays: &mut u64) -> Option<Chain> {
    let d = cam.direction(u);
    *rays += 1;
    let df = d.as_vec3().normalize();
    let si = scene.ray_intersect(&Ray::new(cam.origin.as_vec3(), df))?;
    let (p1, m) = outer_patch(scene, &si, df)?;
    if m != medium {
        return None;
    }
    let mut chain = Chain { p1, refl: [None; MAX_CAMERA_REFLECTIONS], j: 0 };
    let mut n_geo = si.n;
    for i in 0..j {
        let map = chain_map(&chain, cam, u)?;
        let (x, dir) = (map.x[i].as_vec3(), map.dir.as_vec3().normalize());
        *rays += 1;
        let hit = scene.ray_intersect(&Ray::new(offset_origin(x, n_geo, dir), dir))?;
        chain.refl[i] = Some(super::locate::boundary_patch(scene, &hit, medium, dir)?);
        chain.j = i + 1;
        n_geo = hit.n;
    }
    Some(chain)
}

/// `C(u)` in the tangent coordinates of `l` through the fixed patches of `chain`.
#[inline]
fn residual(chain: &Chain, cam: &CameraMap, u: DVec2, x_b: DVec3, l: DVec3, lt: (DVec3, DVec3)) -> Option<[f64; 2]> {
    let m = chain_map(chain, cam, u)?;
    let last = m.x[chain.j];
    let denom = m.dir.dot(l);
    let s = (x_b - last).dot(l) / denom;
    if !(denom > 0.0) || !(s > 0.0) {
        return None;
    }
    let v = last + m.dir * s - x_b;
    Some([v.dot(lt.0), v.dot(lt.1)])
}

/// A converged camera connection to `x_b`.
#[derive(Clone, Copy, Debug)]
pub struct CameraSolution {
    /// Film position (pixels of the full film).
    pub u: DVec2,
    pub chain: Chain,
    pub map: ChainMap,
    /// `|det dA⊥(x_b)/du|`, m² per pixel².
    pub area_per_pixel: f64,
    pub iterations: u32,
}

/// Solve `C(u) = 0` from `seed` by damped Newton (steps halved until `|C|` decreases, at most 10
/// halvings), the patches relocated by `relocate` at every accepted step.
pub fn solve(
    relocate: &mut impl FnMut(DVec2) -> Option<Chain>,
    cam: &CameraMap,
    x_b: DVec3,
    seed: DVec2,
) -> (Option<CameraSolution>, u32) {
    let tol = TOLERANCE * (x_b - cam.origin).length();
    let mut u = seed;
    let Some(mut chain) = relocate(u) else { return (None, 0) };
    for it in 0..=MAX_ITERATIONS {
        let Some(map) = chain_map(&chain, cam, u) else { return (None, it) };
        let (l, lt) = (map.dir, tangents(map.dir));
        let Some(r) = residual(&chain, cam, u, x_b, l, lt) else { return (None, it) };
        let norm = (r[0] * r[0] + r[1] * r[1]).sqrt();
        let jac = central_jacobian(FD_STEP, |a, b| residual(&chain, cam, u + DVec2::new(a, b), x_b, l, lt));
        let Some(j) = jac else { return (None, it) };
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if norm < tol {
            if !(det.abs() > 0.0 && det.is_finite()) {
                return (None, it);
            }
            let s = CameraSolution { u, chain, map, area_per_pixel: det.abs(), iterations: it };
            return (Some(s), it);
        }
        if it == MAX_ITERATIONS || !(det.abs() > 1e-300) {
            return (None, it);
        }
        let accepted = damped(u, newton_step(j, r, det), |cand| {
            let c = relocate(cand)?;
            let better = residual(&c, cam, cand, x_b, l, lt).map(|v| (v[0] * v[0] + v[1] * v[1]).sqrt() < norm);
            (better == Some(true)).then_some(c)
        });
        let Some((cand, c)) = accepted else { return (None, it + 1) };
        u = cand;
        chain = c;
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
/// `medium` at the solved point and normal, each reflection the first hit of the segment before
/// it, the last segment reaches `x_b` unblocked) and return the camera-side factor
/// `w T / |det J|` (`w`: the refraction's and reflections' radiance-mode weights, `T`: the
/// transmittance from `x_c` to `x_b`) and the direction from `x_b` back along the last segment.
fn verify(
    scene: &Scene,
    cam: &CameraMap,
    medium: u32,
    s: &CameraSolution,
    x_b: Vec3,
    stats: &mut LocalStats,
) -> Option<(Spectrum, Vec3)> {
    let m = &s.map;
    let mut d = m.d.as_vec3().normalize();
    let (mut si, hit_medium) = camera_hit(scene, cam, d, m.x[0], m.n[0], stats)?;
    if hit_medium != medium {
        return None;
    }
    let mut weight = Spectrum::ONE;
    for i in 0..=s.chain.j {
        // The camera path's own lobe there (radiance mode): refraction in, then reflections.
        let (wo, w) = beam::delta_lobe(scene, &si, d, if i == 0 { 1 } else { 0 }, TransportMode::Radiance)?;
        let want = if i == s.chain.j { m.dir } else { m.x[i + 1] - m.x[i] }.as_vec3().normalize();
        if !(wo.dot(want) > 1.0 - 1e-4) {
            return None;
        }
        weight *= w;
        d = wo;
        if i < s.chain.j {
            si = next_inside(scene, &si, d, medium, (m.x[i + 1], m.n[i + 1], m.len), stats)?;
        }
    }
    // The last segment inside the medium: its first hit lies beyond x_b.
    let o = offset_origin(si.p, si.n, d);
    let dist = (x_b - o).length();
    stats.rays += 1;
    if scene.ray_intersect(&Ray::new(o, d)).is_some_and(|h| h.t < dist) {
        return None;
    }
    let length = m.len as f32 + (x_b - si.p).length();
    let tr = scene.media[medium as usize].transmittance(length);
    Some((weight * tr * (1.0 / s.area_per_pixel) as f32, -d))
}

/// Seeds of the camera solve, offsets (pixels) from the film position of the straight line
/// `camera → x_b`: that position first, then a fixed ring around it. Every distinct converged
/// solution is counted once (solutions within [`SAME_SOLUTION`] pixels are one).
const SEED_OFFSETS: [(f64, f64); 5] = [(0.0, 0.0), (4.0, 0.0), (-4.0, 0.0), (0.0, 4.0), (0.0, -4.0)];
/// Two solutions closer than this on the film (pixels) are the same.
const SAME_SOLUTION: f64 = 1e-3;

/// The point `x_b = o + t d` on `beam` ([`beam_point`]'s `t` and `1/p(t)`).
#[derive(Clone, Copy, Debug)]
struct BeamPoint {
    x_b: Vec3,
    t: f32,
    inv_pdf: f32,
}

/// One point on `beam` connected to the camera through `j` internal reflections of the camera
/// ray: a splat per distinct verified solution.
/// `curved`: the boundary is curved (`Snee::curved`); on a flat one the straight-line seed alone
/// (its solution is unique there, and the other seeds found none more on the cube of docs/beams.md).
#[allow(clippy::too_many_arguments)]
fn connect(
    scene: &Scene,
    cam: &CameraMap,
    medium: u32,
    curved: bool,
    beam: &Beam,
    point: BeamPoint,
    j: usize,
    stats: &mut LocalStats,
) {
    let m = &scene.media[medium as usize];
    let BeamPoint { x_b, t, inv_pdf } = point;
    let Some(u0) = cam.film_position(x_b.as_dvec3() - cam.origin) else { return };
    let offsets = if curved { &SEED_OFFSETS[..] } else { &SEED_OFFSETS[..1] };
    let mut seeds: Vec<DVec2> = offsets.iter().map(|&(dx, dy)| u0 + DVec2::new(dx, dy)).collect();
    if j == 0 && curved {
        // The light side's seeds: the film positions of the solutions of the point connection's
        // deterministic procedure from x_b towards the pinhole (`newton_point`, docs/manifold.md §8.2).
        let mut loc = SceneLocate { scene, medium, rays: 0 };
        let (xb, y) = (x_b.as_dvec3(), cam.origin);
        let first = newton_point::seed_line(&mut loc, xb, y).1;
        let light = newton_point::solve_distinct(&mut loc, xb, y, first, newton_point::SEEDS);
        stats.rays += loc.rays;
        stats.camera_beam_solves += light.solves as u64;
        stats.camera_beam_iterations += light.iterations as u64;
        seeds.extend(light.solutions.iter().filter_map(|s| cam.film_position(s.refracted.x_k - cam.origin)));
    }
    let mut found: Vec<DVec2> = Vec::with_capacity(seeds.len());
    for seed in seeds {
        let mut rays = 0;
        let mut relocate = |u: DVec2| locate(scene, cam, u, j, medium, &mut rays);
        let (sol, it) = solve(&mut relocate, cam, x_b.as_dvec3(), seed);
        stats.rays += rays;
        stats.camera_beam_solves += 1;
        stats.camera_beam_iterations += it as u64;
        let Some(s) = sol else {
            stats.camera_beam_unsolved += 1;
            continue;
        };
        if found.iter().any(|u| (*u - s.u).length() < SAME_SOLUTION) {
            continue;
        }
        found.push(s.u);
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
    let Some(cam) = &snee.camera else { return };
    let max_depth = u32::try_from(scene.integrator.max_depth).unwrap_or(u32::MAX);
    for (medium, b) in snee.beams.iter().enumerate() {
        let Some(b) = b else { continue };
        let set = beam::trace(scene, medium as u32, b, sampler, stats);
        let j_max = snee.options.camera_reflections as usize;
        let curved = snee.curved.get(medium).copied().unwrap_or(true);
        let sigma_mean = scene.media[medium].sigma_t.to_array().iter().sum::<f32>() / 3.0;
        for beam in set.beams() {
            // Depth after the refraction out: x_c (1), j reflections, x_b (2 + j), k reflections,
            // the refraction out (3 + j + k).
            if 3 + beam.reflections >= max_depth {
                continue;
            }
            let v = sampler.next_1d();
            stats.camera_beam_points += 1;
            let Some((t, inv_pdf)) = beam_point(sigma_mean, beam.len, v) else { continue };
            let point = BeamPoint { x_b: beam.o + beam.d * t, t, inv_pdf };
            for j in 0..=j_max.min(MAX_CAMERA_REFLECTIONS) {
                if 3 + j as u32 + beam.reflections < max_depth {
                    connect(scene, cam, medium as u32, curved, beam, point, j, stats);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::manifold::glint::tests::camera;
    use crate::integrator::manifold::newton::Surface;

    fn ball() -> Patch {
        Patch { surface: Surface::Sphere { center: DVec3::ZERO, radius: 1.0, outward: 1.0 }, eta: 1.5 }
    }

    fn chain(j: usize) -> Chain {
        Chain { p1: ball(), refl: [Some(ball()); MAX_CAMERA_REFLECTIONS], j }
    }

    /// On the ball, for `j` = 0, 1, 2 internal reflections and points `x_b` inside: the solution's
    /// last segment passes through `x_b`, Snell's law holds at `x_c` and the law of reflection at
    /// each reflection point, and `|det J|` equals the area ratio measured by re-solving for a
    /// small square of points around `x_b` in the plane perpendicular to the last segment
    /// (relative 1e-3).
    #[test]
    fn solutions_obey_the_interface_laws_and_the_area_ratio_matches_re_solving() {
        let cam = camera();
        let mut solved = 0;
        for j in 0..=MAX_CAMERA_REFLECTIONS {
            for x_b in [DVec3::new(0.1, -0.2, 0.3), DVec3::new(-0.4, 0.1, -0.2), DVec3::new(0.2, 0.5, 0.1)] {
                let mut relocate = |_u: DVec2| Some(chain(j));
                // Seeds over the film: keep the first that converges.
                let seeds = (0..64).map(|i| DVec2::new(3.0 + 6.0 * (i % 8) as f64, 4.0 + 8.0 * (i / 8) as f64));
                let Some(s) = seeds.filter_map(|u| solve(&mut relocate, &cam, x_b, u).0).next() else { continue };
                solved += 1;
                let m = s.map;
                // The last segment passes through x_b.
                let last = m.x[j];
                let off = (x_b - last) - m.dir * (x_b - last).dot(m.dir);
                assert!(off.length() < 1e-8, "j {j}: {off}");
                // Snell at x_c: η sin θ_t = sin θ_i, in the plane of d and n.
                let (d, n) = (m.d, m.n[0]);
                let d_in = if j == 0 { m.dir } else { (m.x[1] - m.x[0]).normalize() };
                let sin_i = d.cross(n).length();
                let sin_t = d_in.cross(n).length();
                assert!((1.5 * sin_t - sin_i).abs() < 1e-9, "Snell j {j}");
                assert!(d.cross(n).dot(d_in.cross(n)) > 0.0, "refraction in the plane of incidence");
                // Reflection at each x_{i+1}: incoming and outgoing mirror about n.
                for i in 0..j {
                    let w_in = (m.x[i + 1] - m.x[i]).normalize();
                    let w_out = if i + 1 == j { m.dir } else { (m.x[i + 2] - m.x[i + 1]).normalize() };
                    let n = m.n[i + 1];
                    let mirrored = w_in - n * (2.0 * w_in.dot(n));
                    assert!((mirrored - w_out).length() < 1e-9, "reflection j {j} i {i}");
                }
                // |det J| against re-solving for a square of side h around x_b.
                let (t1, t2) = tangents(m.dir);
                let h = 1e-5;
                let mut corner = |a: f64, b: f64| {
                    let y = x_b + t1 * a + t2 * b;
                    solve(&mut relocate, &cam, y, s.u).0.expect("re-solve near the solution").u
                };
                let (u00, u10, u01) = (corner(0.0, 0.0), corner(h, 0.0), corner(0.0, h));
                let (e1, e2) = (u10 - u00, u01 - u00);
                let pixels = (e1.x * e2.y - e1.y * e2.x).abs();
                let ratio = h * h / pixels;
                assert!((ratio / s.area_per_pixel - 1.0).abs() < 1e-3, "j {j}: {ratio} vs {}", s.area_per_pixel);
            }
        }
        assert!(solved >= 7, "solved {solved} of 9");
    }

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

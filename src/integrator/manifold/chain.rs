//! Two-vertex chains through a CURVED smooth boundary under a DIRECTIONAL light
//! (`connection = complete`, docs/manifold.md §9): from a medium vertex `x_j`, the suffix
//!
//! ```text
//! x_j → x_1 (internal reflection) → x_2 (refraction out) → light in the direction omega_l
//! ```
//!
//! the class `internal_reflection` (V–S_r–S_t–L) that no other technique makes under a delta light
//! (forward tracing cannot hit a delta light, SNEE and the one-refraction connection of `curved.rs`
//! end in a single refraction).
//!
//! The unknown is the direction `omega` at `x_j` (2 degrees of freedom), as in `newton.rs`: the
//! ray `(x_j, omega)` meets the boundary at `x_1`, reflects about the interpolated shading normal
//! there, meets the boundary again at `x_2` and refracts out into `o(omega)`; the constraint is
//! `C(omega) = P_l (o(omega) − omega_l) = 0` (Jakob & Marschner 2012, §4: one half-vector
//! condition per specular vertex, here composed into one map of the direction). Each Newton step
//! is two ray casts; within the two located patches the map is in closed form (f64) and its 2×2
//! Jacobian is a central difference of that closed form. At a solution `1/|det dω_l/dω|` is the
//! beam spread through the reflection and the refraction (Hanika et al. 2015, §4.3, distant limit).
//!
//! The value (radiance mode: reflection weight `F(x_1)`, transmission `(1 − F(x_2)) η²`):
//!
//! ```text
//! f_p(wi_j, omega) · T(d_j1) T(d_12) · F(x_1) (1 − F(x_2)) η² · |det dω_l/dω|⁻¹ · tr_light · E / p_sel
//! ```
//!
//! Several or no solutions: specular manifold sampling's unbiased `1/p` (Zeltner et al. 2020,
//! §4.3), seeds from the light side mixed with uniform directions (`chain_seed.rs`: every solution
//! has a positive probability; no deterministic seed is known for a reflection point), Bernoulli
//! trials capped at [`MAX_TRIALS`] (capped connections counted in `--stats` as
//! `chain_trials_capped`).

use super::chain_seed::{self, ChainSeeds};
use super::newton::{
    bernoulli_trials_capped, central_jacobian, damped_step, moved, tangents, Failure, Patch, Refracted,
};
use super::MediumVertex;
use crate::bsdf::fresnel::fresnel;
use crate::color::Spectrum;
use crate::integrator::cx::{Cx, Scatter};
use crate::integrator::snee::SneeOptions;
use crate::integrator::stats::LocalStats;
use crate::interaction::{offset_origin, SurfaceInteraction};
use crate::math::{DVec3, Ray, Vec2, Vec3};
use crate::sampler::Sampler;
use crate::scene::world::Scene;

/// Newton steps at most per solve.
pub const MAX_ITERATIONS: u32 = 32;
/// Converged when `|o − omega_l| < TOLERANCE` (f64, radians).
pub const TOLERANCE: f64 = 1e-8;
/// Finite-difference step for the Jacobian (radians).
const FD_STEP: f64 = 1e-6;
/// Largest number of Bernoulli trials (SMS's cap, as the one-refraction connection's, §8.1): a
/// solution of probability `p` keeps the share `1 − (1 − p)^MAX_TRIALS` of its contribution, and the
/// expected number of draws per connection stays below `1 + (number of solutions)` whatever the cap.
pub const MAX_TRIALS: u32 = super::newton::DIRECTIONAL_MAX_TRIALS;

/// Where the chain's rays meet the boundary; declared beside the seeds, which cast the same rays.
pub use super::chain_seed::ChainLocate;

/// The closed-form chain through two fixed patches at `omega`.
#[derive(Clone, Copy, Debug)]
pub struct ChainMap {
    pub x_1: DVec3,
    /// Outward shading normal at `x_1`, `omega · n_1 = cos_1 > 0`.
    pub n_1: DVec3,
    pub cos_1: f64,
    /// Distance `x_j → x_1`.
    pub t_1: f64,
    /// Reflected direction `x_1 → x_2`.
    pub d_12: DVec3,
    /// The refraction at `x_2` (`t`: distance `x_1 → x_2`).
    pub out: Refracted,
}

/// The chain `x_j → x_1 → x_2 → o` through `p1` (reflection) and `p2` (refraction), or `None`
/// when `omega` meets `p1` from outside, or `p2` from outside, or is totally reflected at `p2`.
pub fn chain_map(p1: &Patch, p2: &Patch, x_j: DVec3, omega: DVec3) -> Option<ChainMap> {
    let (t_1, x_1, n_1) = p1.hit(x_j, omega)?;
    let cos_1 = omega.dot(n_1);
    if !(cos_1 > 0.0) {
        return None;
    }
    // Mirror reflection about the shading normal (stays inside: d_12 · n_1 = −cos_1).
    let d_12 = omega - n_1 * (2.0 * cos_1);
    // Start just past x_1 along the ray (selects the far root on a sphere; the line is unchanged).
    let nudge = 1e-7 * (1.0 + x_1.abs().max_element());
    let mut out = p2.refract(x_1 + d_12 * nudge, d_12)?;
    out.t += nudge;
    Some(ChainMap { x_1, n_1, cos_1, t_1, d_12, out })
}

#[inline]
fn residual(c: &ChainMap, l: (DVec3, DVec3), omega_l: DVec3) -> [f64; 2] {
    let v = c.out.o - omega_l;
    [v.dot(l.0), v.dot(l.1)]
}

/// `dC/d(a, b)` through the fixed patches, by central differences of the closed form.
fn jacobian(
    p1: &Patch,
    p2: &Patch,
    x_j: DVec3,
    omega: DVec3,
    omega_l: DVec3,
    l: (DVec3, DVec3),
) -> Option<[[f64; 2]; 2]> {
    let t = tangents(omega);
    central_jacobian(FD_STEP, |a, b| Some(residual(&chain_map(p1, p2, x_j, moved(omega, t, a, b))?, l, omega_l)))
}

/// Locate both patches along `omega` (two ray casts) and evaluate the chain through them.
fn locate_chain(locate: &mut impl ChainLocate, x_j: DVec3, omega: DVec3) -> Option<(Patch, Patch, ChainMap)> {
    let (p1, n_geo) = locate.first(x_j, omega)?;
    let (_, x_1, n_1) = p1.hit(x_j, omega)?;
    let cos_1 = omega.dot(n_1);
    if !(cos_1 > 0.0) {
        return None;
    }
    let d_12 = omega - n_1 * (2.0 * cos_1);
    let p2 = locate.second(x_1, n_geo, d_12)?;
    let c = chain_map(&p1, &p2, x_j, omega)?;
    Some((p1, p2, c))
}

/// A converged, located chain.
#[derive(Clone, Copy, Debug)]
pub struct ChainSolution {
    pub omega: DVec3,
    pub map: ChainMap,
    pub p1: Patch,
    pub p2: Patch,
    /// `|det dω_l/dω|⁻¹`: solid angle at `x_j` per solid angle of outgoing directions.
    pub d_omega_d_omega_l: f64,
    pub iterations: u32,
}

/// Solve `o(omega) = omega_l` from `seed` (damped Newton as `newton::solve`: steps capped at
/// [`MAX_STEP`], halved until `|o − omega_l|` decreases, at most 10 halvings).
pub fn solve(
    locate: &mut impl ChainLocate,
    x_j: DVec3,
    omega_l: DVec3,
    seed: DVec3,
) -> Result<ChainSolution, (Failure, u32)> {
    let omega_l = omega_l.normalize();
    let l = tangents(omega_l);
    let mut omega = seed.normalize();
    let (mut p1, mut p2, mut c) = locate_chain(locate, x_j, omega).ok_or((Failure::Lost, 0))?;
    for it in 0..=MAX_ITERATIONS {
        let norm = (c.out.o - omega_l).length();
        let j = jacobian(&p1, &p2, x_j, omega, omega_l, l).ok_or((Failure::Lost, it))?;
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if norm < TOLERANCE {
            if !(det.abs() > 0.0) || !det.is_finite() {
                return Err((Failure::NoConvergence, it));
            }
            return Ok(ChainSolution { omega, map: c, p1, p2, d_omega_d_omega_l: 1.0 / det.abs(), iterations: it });
        }
        if it == MAX_ITERATIONS || !(det.abs() > 1e-300) {
            break;
        }
        let r = residual(&c, l, omega_l);
        let step = damped_step(omega, j, r, det, |cand| {
            locate_chain(locate, x_j, cand).filter(|(_, _, cc)| (cc.out.o - omega_l).length() < norm)
        });
        let Some((cand, (q1, q2, cc))) = step else {
            return Err((Failure::NoConvergence, it + 1));
        };
        (omega, p1, p2, c) = (cand, q1, q2, cc);
    }
    Err((Failure::NoConvergence, MAX_ITERATIONS))
}

/// Statistics of one [`sample_solution`] call (for `--stats`).
#[derive(Clone, Copy, Debug, Default)]
pub struct ChainCounts {
    pub solves: u64,
    pub iterations: u64,
    pub failures: u64,
    pub capped: u64,
}

/// Specular manifold sampling's unbiased estimate (Zeltner et al. 2020, §4.3) for the chain: one
/// solution `s` from a seed drawn from `seeds` (`chain_seed.rs`), and the number `N` of seeds drawn
/// from the same distribution until `s` is found again (`E[N | s] = 1/p(s)`, capped at `cap`);
/// `f(s) · N` estimates `Σ_s f(s)`.
pub fn sample_solution(
    locate: &mut impl ChainLocate,
    x_j: DVec3,
    omega_l: DVec3,
    seeds: ChainSeeds,
    cap: u32,
    u: &mut impl FnMut() -> f64,
    counts: &mut ChainCounts,
) -> Option<(ChainSolution, u32)> {
    let omega_l = omega_l.normalize();
    let draw = |locate: &mut _, u: &mut dyn FnMut() -> f64, counts: &mut ChainCounts| {
        let seed = chain_seed::draw(seeds, locate, x_j, omega_l, u);
        let r = solve(locate, x_j, omega_l, seed);
        counts.solves += 1;
        match &r {
            Ok(s) => counts.iterations += s.iterations as u64,
            Err((_, it)) => {
                counts.iterations += *it as u64;
                counts.failures += 1;
            }
        }
        r.ok()
    };
    let s = draw(locate, u, counts)?;
    let (n, capped) = bernoulli_trials_capped(s.omega, cap, || draw(locate, u, counts).map(|t| t.omega));
    counts.capped += capped as u64;
    Some((s, n))
}

/// The geometric and Fresnel weight of a solution: `F(x_1) (1 − F(x_2)) η² |det dω_l/dω|⁻¹`.
pub fn geometric_weight(s: &ChainSolution) -> f64 {
    let f_1 = fresnel(-s.map.cos_1 as f32, s.p1.eta as f32).0 as f64;
    let eta = s.p2.eta;
    let f_2 = fresnel(s.map.out.cos_out as f32, eta as f32).0 as f64;
    f_1 * (1.0 - f_2) * eta * eta * s.d_omega_d_omega_l
}

/// The scene as the chain's walk sees it (rays cast in `medium`, counted in `rays`).
pub struct SceneChain<'a> {
    pub scene: &'a Scene,
    pub medium: u32,
    pub rays: u64,
}

impl ChainLocate for SceneChain<'_> {
    fn first(&mut self, x_j: DVec3, d: DVec3) -> Option<(Patch, DVec3)> {
        self.rays += 1;
        let d = d.as_vec3().normalize();
        let si = self.scene.ray_intersect(&Ray::new(x_j.as_vec3(), d))?;
        let patch = super::locate::boundary_patch(self.scene, &si, self.medium, d)?;
        Some((patch, si.n.as_dvec3()))
    }

    fn second(&mut self, x_1: DVec3, n_1: DVec3, d: DVec3) -> Option<Patch> {
        self.rays += 1;
        let d = d.as_vec3().normalize();
        let o = offset_origin(x_1.as_vec3(), n_1.as_vec3(), d);
        let si = self.scene.ray_intersect(&Ray::new(o, d))?;
        super::locate::boundary_patch(self.scene, &si, self.medium, d)
    }
}

/// Does the renderer's own (f32) hit `si` agree with the solved point and shading normal?
fn agrees(si: &SurfaceInteraction, x: DVec3, n_s: DVec3, t: f64) -> bool {
    (si.p.as_dvec3() - x).length() <= 1e-3 * (1.0 + t) && si.sh_frame.n.as_dvec3().dot(n_s) > 1.0 - 1e-4
}

/// Sample one chain from `x_j` to a light in the direction `omega_l` (weight `E / p_sel`), verify
/// it in the renderer's precision, and return `f(s) · N` without the path throughput.
pub fn connect(
    scene: &Scene,
    x_j: &MediumVertex,
    omega_l: Vec3,
    weight: Spectrum,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> Option<Spectrum> {
    let mut locate = SceneChain { scene, medium: x_j.medium, rays: 0 };
    let mut counts = ChainCounts::default();
    let mut u = || sampler.next_1d() as f64;
    let sampled = sample_solution(
        &mut locate,
        x_j.p.as_dvec3(),
        omega_l.as_dvec3(),
        ChainSeeds::LightSide,
        MAX_TRIALS,
        &mut u,
        &mut counts,
    );
    stats.rays += locate.rays;
    stats.chain_solves += counts.solves;
    stats.chain_iterations += counts.iterations;
    stats.chain_trials_capped += counts.capped;
    let (sol, trials) = sampled?;
    // Verify: the first hit along omega is x_1 on the boundary, the reflected ray's first hit is
    // x_2 on the boundary, both from inside; the light leaves outside both normals at x_2.
    let omega = sol.omega.as_vec3().normalize();
    stats.rays += 2;
    let si_1 = scene.ray_intersect(&Ray::new(x_j.p, omega)).filter(|si| {
        super::locate::boundary_patch(scene, si, x_j.medium, omega).is_some()
            && agrees(si, sol.map.x_1, sol.map.n_1, sol.map.t_1)
    })?;
    let d_12 = sol.map.d_12.as_vec3().normalize();
    if !(d_12.dot(si_1.n) < 0.0) {
        return None;
    }
    let si_2 = scene.ray_intersect(&Ray::new(offset_origin(si_1.p, si_1.n, d_12), d_12)).filter(|si| {
        super::locate::boundary_patch(scene, si, x_j.medium, d_12).is_some()
            && si.n.dot(omega_l) > 0.0
            && si.sh_frame.n.dot(omega_l) > 0.0
            && agrees(si, sol.map.out.x_k, sol.map.out.n_s, sol.map.out.t)
    })?;
    let tr_out = super::light_segment(scene, &si_2, omega_l, stats);
    if tr_out == Spectrum::ZERO {
        return None;
    }
    stats.chain_solutions += 1;
    let m = &scene.media[x_j.medium as usize];
    let factor = geometric_weight(&sol) * trials as f64;
    let value = m.phase.eval(x_j.wi, omega)
        * m.transmittance(sol.map.t_1 as f32)
        * m.transmittance(sol.map.out.t as f32)
        * tr_out
        * weight
        * factor as f32;
    Some(value)
}

/// The chain at a real scatter `v` (`x_j = v.p`) inside a curved smooth boundary: one emitter
/// sample (uniform selection, as `curved::sample`); only a directional light is connected. No
/// other technique makes these suffixes (docs/manifold.md §9), so the weight is 1 (0 with
/// `transport = snee`). Draws one 2-D sample and the seeds whenever it runs.
pub fn sample(cx: &mut Cx, opts: SneeOptions, v: &Scatter) -> Spectrum {
    let (scene, sampler, stats) = (cx.scene, &mut *cx.sampler, &mut *cx.stats);
    if !super::locate::applies(scene, v.medium) {
        return Spectrum::ZERO;
    }
    let u: Vec2 = sampler.next_2d();
    // Two surface events after x_j before the light.
    if v.depth.saturating_add(2) >= v.max_depth || !opts.keeps_all() {
        return Spectrum::ZERO;
    }
    stats.chain_attempts += 1;
    if !matches!(super::finite::pick(scene, u), super::finite::Pick::Distant) {
        return Spectrum::ZERO;
    }
    let (ds, weight) = scene.sample_emitter_direction(v.p, None, u, false);
    if !(ds.pdf > 0.0) || ds.dist.is_finite() || !ds.delta || weight == Spectrum::ZERO {
        return Spectrum::ZERO;
    }
    let x_j = MediumVertex { p: v.p, wi: v.wi, medium: v.medium };
    let Some(value) = connect(scene, &x_j, ds.d, weight, sampler, stats) else { return Spectrum::ZERO };
    let mut result = Spectrum::ZERO;
    super::add_finite(&mut result, v.beta * value, stats);
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::manifold::newton::{sphere_seed, Surface};

    /// The whole boundary is one analytic sphere (unit radius at the origin).
    struct Ball {
        eta: f64,
    }

    impl Ball {
        fn patch(&self) -> Patch {
            Patch { surface: Surface::Sphere { center: DVec3::ZERO, radius: 1.0, outward: 1.0 }, eta: self.eta }
        }
    }

    impl ChainLocate for Ball {
        fn first(&mut self, _x_j: DVec3, _d: DVec3) -> Option<(Patch, DVec3)> {
            Some((self.patch(), DVec3::ZERO))
        }
        fn second(&mut self, _x_1: DVec3, _n_1: DVec3, _d: DVec3) -> Option<Patch> {
            Some(self.patch())
        }
    }

    /// A seeded solve that converges (the first of up to 4096 uniform seeds).
    fn some_solution(ball: &mut Ball, x_j: DVec3, omega_l: DVec3, u: &mut impl FnMut() -> f64) -> ChainSolution {
        for _ in 0..4096 {
            if let Ok(s) = solve(ball, x_j, omega_l, sphere_seed(u(), u())) {
                return s;
            }
        }
        panic!("no chain solution at {x_j:?} {omega_l:?}");
    }

    /// `dω/dω_l` against the solid angle of the re-solved solutions for a small square of light
    /// directions; the solution obeys the law of reflection at `x_1` and Snell's law at `x_2`.
    #[test]
    fn jacobian_matches_re_solving_on_a_ball() {
        let mut rng = crate::sampler::Sampler::new(3, 1);
        let mut u = move || rng.next_1d() as f64;
        for eta in [1.5, 1.33] {
            let mut ball = Ball { eta };
            for (x_j, omega_l) in [
                (DVec3::new(0.1, -0.2, 0.3), DVec3::new(0.3, 0.2, 0.9)),
                (DVec3::new(-0.5, 0.1, -0.2), DVec3::new(0.0, 0.0, 1.0)),
                (DVec3::new(0.4, 0.4, 0.5), DVec3::new(-0.5, 0.6, 0.4)),
            ] {
                let omega_l = omega_l.normalize();
                let s = some_solution(&mut ball, x_j, omega_l, &mut u);
                let c = &s.map;
                assert!((c.out.o - omega_l).length() < 1e-7);
                // Reflection: omega, d_12 and n_1 coplanar, equal angles.
                assert!((c.d_12.dot(c.n_1) + s.omega.dot(c.n_1)).abs() < 1e-9);
                assert!(c.n_1.cross(s.omega).dot(c.d_12).abs() < 1e-9);
                let sin_in = (1.0 - c.out.cos_in * c.out.cos_in).sqrt();
                let sin_out = (1.0 - c.out.cos_out * c.out.cos_out).sqrt();
                assert!((eta * sin_in - sin_out).abs() < 1e-7);
                let h = 1e-4;
                let (l1, l2) = tangents(omega_l);
                let mut corner = |a: f64, b: f64| {
                    let w = (omega_l + l1 * a + l2 * b).normalize();
                    solve(&mut ball, x_j, w, s.omega).expect("perturbed solves").omega
                };
                let (p00, p10, p11, p01) = (corner(-h, -h), corner(h, -h), corner(h, h), corner(-h, h));
                let area = 0.5 * ((p10 - p00).cross(p11 - p00).length() + (p11 - p00).cross(p01 - p00).length());
                let fd = area / (4.0 * h * h);
                let rel = (fd / s.d_omega_d_omega_l - 1.0).abs();
                assert!(rel < 2e-3, "eta {eta}: dω/dω_l {} vs re-solved {fd} (rel {rel})", s.d_omega_d_omega_l);
            }
        }
    }

    /// The SMS estimate against the limit of a shrinking cone of light directions, on a glass ball:
    /// `Σ_s g(s) |det dω_l/dω|⁻¹ = lim ∫ g(ω) 1[angle(o(ω), ω_l) < θ] dω / Ω(θ)` with
    /// `g = F(x_1) (1 − F(x_2)) η²`. The right side by uniform directions through the closed-form
    /// map (no Newton, no seeds): it checks the solutions found, the beam spread and the
    /// Bernoulli `1/p` (including the cap's truncation) together. Sample counts fixed before the
    /// first run: 2²⁴ directions (θ = 0.03 rad) and 4096 SMS estimates per point.
    #[test]
    fn sms_estimate_matches_the_cone_limit_on_a_ball() {
        let mut rng = crate::sampler::Sampler::new(11, 1);
        let mut u = move || rng.next_1d() as f64;
        let theta: f64 = 0.03;
        let cone = std::f64::consts::TAU * (1.0 - theta.cos());
        let eta = 1.5;
        let mut ball = Ball { eta };
        let p = ball.patch();
        for (x_j, omega_l) in [
            (DVec3::new(0.1, -0.2, 0.3), DVec3::new(0.3, 0.2, 0.9)),
            (DVec3::new(-0.5, 0.1, -0.2), DVec3::new(0.0, 0.0, 1.0)),
            (DVec3::new(0.2, 0.6, -0.1), DVec3::new(-0.5, 0.6, 0.4)),
        ] {
            let omega_l = omega_l.normalize();
            // The cone limit.
            let m = 1u64 << 24;
            let (mut sum, mut sq) = (0.0, 0.0);
            for _ in 0..m {
                let w = sphere_seed(u(), u());
                let Some(c) = chain_map(&p, &p, x_j, w) else { continue };
                if c.out.o.dot(omega_l) < theta.cos() {
                    continue;
                }
                let f_1 = fresnel(-c.cos_1 as f32, eta as f32).0 as f64;
                let f_2 = fresnel(c.out.cos_out as f32, eta as f32).0 as f64;
                let g = f_1 * (1.0 - f_2) * eta * eta * 4.0 * std::f64::consts::PI / cone;
                sum += g;
                sq += g * g;
            }
            let cone_mean = sum / m as f64;
            let cone_se = ((sq / m as f64 - cone_mean * cone_mean) / m as f64).sqrt();
            // SMS, with either seed distribution.
            for seeds in [ChainSeeds::Uniform, ChainSeeds::LightSide] {
                let mut counts = ChainCounts::default();
                let runs = 4096;
                let (mut s_sum, mut s_sq) = (0.0, 0.0);
                for _ in 0..runs {
                    let e = sample_solution(&mut ball, x_j, omega_l, seeds, MAX_TRIALS, &mut u, &mut counts)
                        .map_or(0.0, |(s, n)| geometric_weight(&s) * n as f64);
                    s_sum += e;
                    s_sq += e * e;
                }
                let sms_mean = s_sum / runs as f64;
                let sms_se = ((s_sq / runs as f64 - sms_mean * sms_mean) / runs as f64).sqrt();
                let z = (sms_mean - cone_mean) / (sms_se * sms_se + cone_se * cone_se).sqrt();
                eprintln!(
                    "x_j {x_j:?} {seeds:?}: SMS {sms_mean:.5} ± {sms_se:.5}, cone limit {cone_mean:.5} ± \
                     {cone_se:.5}, z {z:.2}; capped {} of {runs}; {counts:?}",
                    counts.capped
                );
                assert!(z.abs() < 4.0, "{seeds:?}: SMS {sms_mean} ± {sms_se} vs cone limit {cone_mean} ± {cone_se}");
            }
        }
    }

    /// Every chain solution on the glass ball (η = 1.5) that 4096 uniform seeds find is also found
    /// by 4096 light-side seeds (`chain_seed.rs`), at the three points of the cone-limit test; the
    /// light-side seeds' convergence rate is reported next to the uniform seeds'. Counts fixed before
    /// the first run.
    #[test]
    fn light_side_seeds_find_every_solution_on_a_ball() {
        let mut rng = crate::sampler::Sampler::new(17, 1);
        let mut u = move || rng.next_1d() as f64;
        let mut ball = Ball { eta: 1.5 };
        for (x_j, omega_l) in [
            (DVec3::new(0.1, -0.2, 0.3), DVec3::new(0.3, 0.2, 0.9)),
            (DVec3::new(-0.5, 0.1, -0.2), DVec3::new(0.0, 0.0, 1.0)),
            (DVec3::new(0.2, 0.6, -0.1), DVec3::new(-0.5, 0.6, 0.4)),
        ] {
            let omega_l = omega_l.normalize();
            // Distinct solutions and how often each seed distribution reaches them.
            let mut found: Vec<(DVec3, [u32; 2])> = Vec::new();
            let mut converged = [0u32; 2];
            let draws = 4096;
            for (k, seeds) in [ChainSeeds::Uniform, ChainSeeds::LightSide].into_iter().enumerate() {
                for _ in 0..draws {
                    let seed = chain_seed::draw(seeds, &mut ball, x_j, omega_l, &mut u);
                    let Ok(s) = solve(&mut ball, x_j, omega_l, seed) else { continue };
                    converged[k] += 1;
                    match found.iter_mut().find(|(o, _)| (*o - s.omega).length() < 1e-4) {
                        Some((_, n)) => n[k] += 1,
                        None => found.push((s.omega, if k == 0 { [1, 0] } else { [0, 1] })),
                    }
                }
            }
            eprintln!(
                "x_j {x_j:?}: {} solutions; converged uniform {} light-side {} of {draws}; per solution {:?}",
                found.len(),
                converged[0],
                converged[1],
                found.iter().map(|(_, n)| *n).collect::<Vec<_>>()
            );
            assert!(!found.is_empty());
            for (o, n) in &found {
                assert!(n[0] == 0 || n[1] > 0, "light-side seeds never reach the solution {o:?} ({n:?})");
            }
        }
    }
}

//! Newton iteration on the refraction constraint through a CURVED smooth surface towards a light
//! POINT `y` at a finite distance (sphere and area lights; docs/manifold.md §8.2; Hanika, Droske,
//! Fascione 2015, §3–4), and the generalized geometry term of the solution (Jakob & Marschner
//! 2012, §4).
//!
//! As in [`super::newton`] the unknown is the direction `omega` from the medium vertex `x_j`; its
//! first hit `x_k(omega)` refracts about the interpolated shading normal into `o(omega)`. The
//! constraint "the refracted ray passes through `y`" is written on a plane through `y`
//! perpendicular to a fixed direction `l` (the direction towards `y` from the seed's boundary
//! point):
//!
//! ```text
//! Φ_l(omega) = x_k + o · s,   s = (y − x_k)·l / (o·l) > 0;      C(omega) = P_l (Φ_l(omega) − y) = 0
//! ```
//!
//! (a distance, so the tolerance is relative to `|y − x_j|`; `s > 0` excludes the spurious roots
//! behind `x_k`). `dC/d(a, b)` is taken by central differences of the closed-form patch map (as in
//! `newton.rs`), damped Newton as there.
//!
//! **Geometry term.** At the solution, with `l = o` the same map's Jacobian is `dA⊥(y)/dω`, the
//! area perpendicular to the ray at `y` per solid angle at `x_j`; its inverse is the generalized
//! geometry term `G = dω/dA⊥(y)` (`pdf::plane_geometry` in closed form on a plane; the unit tests
//! check it against re-solving for a small square of points `y` and against the closed form).
//!
//! **Deterministic seed** ([`point_seed`]; Hanika et al. 2015 §3, refined as `newton::refracted_seed`):
//! the straight line `x_j → y` meets the boundary at `x_k⁰` with shading normal `n⁰`; refract the
//! direction `y − x_k⁰` into the medium there and reverse it. A function of `(x_j, y)` only, so the
//! technique's density of a given suffix can be evaluated by re-solving from that seed.

use super::newton::{
    central_jacobian, damped_step, moved, tangents, Failure, Locate, Patch, Refracted, Surface, MAX_ITERATIONS,
};
use crate::math::DVec3;

/// Converged when `|Φ − y| < TOLERANCE · |y − x_j|`.
pub const TOLERANCE: f64 = 1e-10;
/// Finite-difference step (radians) for the Jacobian.
const FD_STEP: f64 = 1e-6;

/// A converged solution towards the point `y`.
#[derive(Clone, Copy, Debug)]
pub struct PointSolution {
    /// Unit direction `x_j → x_k`.
    pub omega: DVec3,
    pub refracted: Refracted,
    pub patch: Patch,
    /// The generalized geometry term `G = dω/dA⊥(y)` (solid angle at `x_j` per area at `y`
    /// perpendicular to the outgoing ray).
    pub g: f64,
    pub iterations: u32,
}

/// The refraction at `omega` and where the refracted ray meets the plane through `y`
/// perpendicular to `l` (`None`: no refraction, or the plane is not ahead of `x_k`).
#[inline]
fn beam(patch: &Patch, x_j: DVec3, omega: DVec3, y: DVec3, l: DVec3) -> Option<(Refracted, DVec3)> {
    let r = patch.refract(x_j, omega)?;
    let denom = r.o.dot(l);
    if !(denom > 0.0) {
        return None;
    }
    let s = (y - r.x_k).dot(l) / denom;
    (s > 0.0).then_some((r, r.x_k + r.o * s))
}

/// `C = P_l (Φ − y)` in the tangent coordinates `lt` of `l`.
#[inline]
fn residual(p: DVec3, y: DVec3, lt: (DVec3, DVec3)) -> [f64; 2] {
    let v = p - y;
    [v.dot(lt.0), v.dot(lt.1)]
}

/// `dC/d(a, b)` at `omega` on `patch` (columns a, b), central differences of the closed form.
fn jacobian(patch: &Patch, x_j: DVec3, omega: DVec3, y: DVec3, l: DVec3) -> Option<[[f64; 2]; 2]> {
    let t = tangents(omega);
    let lt = tangents(l);
    central_jacobian(FD_STEP, |a, b| Some(residual(beam(patch, x_j, moved(omega, t, a, b), y, l)?.1, y, lt)))
}

/// `dC/d(a, b)` for a Newton step: forward differences from the residual `c` at `omega` (two
/// evaluations of the closed form instead of [`jacobian`]'s four). Its relative error, of the order
/// of `FD_STEP`, only slows the quadratic convergence by that factor per step; `G` keeps the
/// central differences.
fn step_jacobian(
    patch: &Patch,
    x_j: DVec3,
    omega: DVec3,
    y: DVec3,
    l: DVec3,
    lt: (DVec3, DVec3),
    c: [f64; 2],
) -> Option<[[f64; 2]; 2]> {
    let t = tangents(omega);
    let mut j = [[0.0; 2]; 2];
    for (col, (a, b)) in [(FD_STEP, 0.0), (0.0, FD_STEP)].into_iter().enumerate() {
        let r = residual(beam(patch, x_j, moved(omega, t, a, b), y, l)?.1, y, lt);
        for row in 0..2 {
            j[row][col] = (r[row] - c[row]) / FD_STEP;
        }
    }
    Some(j)
}

/// The generalized geometry term `G = dω/dA⊥(y)` at a solution `omega` (refracting into `o`):
/// the inverse determinant of the map `omega ↦ Φ_o(omega)` (`l = o`: the plane perpendicular to
/// the outgoing ray at `y`).
pub fn geometry_term(patch: &Patch, x_j: DVec3, omega: DVec3, y: DVec3, o: DVec3) -> Option<f64> {
    let j = jacobian(patch, x_j, omega, y, o)?;
    let det = (j[0][0] * j[1][1] - j[0][1] * j[1][0]).abs();
    let g = 1.0 / det;
    (g.is_finite() && g > 0.0).then_some(g)
}

/// The straight line `x_j → y` (one ray cast): the distance `t0` to its first hit of the
/// enclosing boundary (`None` when it does not meet it from inside) and the deterministic seed
/// there (Hanika et al. 2015 §3, refined): refract `normalize(y − x_k⁰)` into the medium about the
/// shading normal at the hit `x_k⁰` and reverse it (`None` also when `y` is behind that normal).
pub fn seed_line(locate: &mut impl Locate, x_j: DVec3, y: DVec3) -> (Option<f64>, Option<DVec3>) {
    let d0 = (y - x_j).normalize();
    let Some(patch) = locate.locate(x_j, d0) else { return (None, None) };
    let Some((t0, x_k0, n_s)) = patch.hit(x_j, d0) else { return (None, None) };
    let omega_l = (y - x_k0).normalize();
    let cos_l = omega_l.dot(n_s);
    if !(cos_l > 0.0) {
        return (Some(t0), None);
    }
    // η_ext sin θ_l = η_int sin θ_in: the tangential part shrinks by 1/η.
    let tangential = (omega_l - n_s * cos_l) / patch.eta;
    let cos_in = (1.0 - tangential.length_squared()).max(0.0).sqrt();
    (Some(t0), Some((tangential + n_s * cos_in).normalize()))
}

/// The refracted seed along the direction `d` from `x_j` (one ray cast): at the boundary hit
/// `x_k` of `d` with shading normal `n_s`, the direction `y − x_k` refracted into the medium and
/// reversed ([`seed_line`]'s construction at another boundary point). `None` when `d` does not meet
/// the enclosing boundary from inside or `y` is behind `n_s`.
pub fn refracted_seed_along(locate: &mut impl Locate, x_j: DVec3, y: DVec3, d: DVec3) -> Option<DVec3> {
    let patch = locate.locate(x_j, d)?;
    refracted_seed_on(&patch, x_j, y, d)
}

/// [`refracted_seed_along`] on the patch `locate` gave for `d` (no ray cast).
fn refracted_seed_on(patch: &Patch, x_j: DVec3, y: DVec3, d: DVec3) -> Option<DVec3> {
    let (_, x_k, n_s) = patch.hit(x_j, d)?;
    super::newton::seed_from_light((y - x_k).normalize(), n_s, patch.eta)
}

/// The deterministic seed for the light point `y`: [`seed_line`]'s.
pub fn point_seed(locate: &mut impl Locate, x_j: DVec3, y: DVec3) -> Option<DVec3> {
    seed_line(locate, x_j, y).1
}

/// Solve "the ray from `x_j` along `omega`, refracted at its first boundary hit, passes through
/// `y`" from `seed` (damped Newton; ray casts through `locate`). Returns the iterations spent on
/// failure as well.
pub fn solve_point(
    locate: &mut impl Locate,
    x_j: DVec3,
    y: DVec3,
    seed: DVec3,
) -> Result<PointSolution, (Failure, u32)> {
    match converge(locate, x_j, y, seed, None, &[]) {
        Ok(Converged::New(s)) => Ok(s),
        Ok(Converged::Known { iterations }) => Err((Failure::NoConvergence, iterations)),
        Err(e) => Err(e),
    }
}

/// How [`converge`] ended: a solution (with its `G`), or an iterate within [`MERGE`] of a solution
/// already `known`, where it stopped. (A return value only, never stored: its size does not matter.)
#[allow(clippy::large_enum_variant)]
enum Converged {
    New(PointSolution),
    Known { iterations: u32 },
}

/// Is the candidate direction `d` from `x_j` inside the triangle of `patch` (barycentrics in
/// `[0, 1]`, the hit ahead of `x_j`)? Then a Newton step stays on that triangle without a ray cast
/// ([`converge`]'s line search); spheres always cast.
fn stays_on(patch: &Patch, x_j: DVec3, d: DVec3) -> bool {
    let Surface::Triangle { p, .. } = patch.surface else { return false };
    let Some((_, b1, b2)) = super::newton::triangle_plane_hit(&p, x_j, d) else { return false };
    b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0
}

/// Newton iterates closer than this (radians) to a solution already found stop there
/// ([`solve_distinct`]): from so close the iteration converges to that solution (quadratic
/// convergence from a step of at most `MERGE` on a well-conditioned map), so finishing it and its
/// `G` would only find the same solution again. A rule on `(x_j, y)`'s own seeds and iterates, so
/// the procedure stays a function of `(x_j, y)`; two distinct solutions closer than this keep only
/// the first.
pub const MERGE: f64 = 1e-3;

/// [`solve_point`]'s damped Newton from `seed`, with three savings that keep it a function of its
/// arguments: the seed's boundary patch may be given (`seed_patch`: the caller already cast that
/// ray); a line-search candidate that stays inside the current triangle ([`stays_on`]) takes that
/// triangle without a ray cast (the connection verifies every solution with the renderer's own
/// ray cast afterwards); and an iterate within [`MERGE`] of a `known` solution stops
/// ([`Converged::Known`]). `G` only for a new solution.
fn converge(
    locate: &mut impl Locate,
    x_j: DVec3,
    y: DVec3,
    seed: DVec3,
    seed_patch: Option<Patch>,
    known: &[PointSolution],
) -> Result<Converged, (Failure, u32)> {
    let scale = (y - x_j).length();
    let mut omega = seed.normalize();
    let mut patch = match seed_patch {
        Some(p) => p,
        None => locate.locate(x_j, omega).ok_or((Failure::Lost, 0))?,
    };
    let r0 = patch.refract(x_j, omega).ok_or((Failure::Lost, 0))?;
    // The constraint's plane: perpendicular to the direction towards y from the seed's x_k.
    let l = (y - r0.x_k).normalize();
    let lt = tangents(l);
    let (mut r, mut p) = beam(&patch, x_j, omega, y, l).ok_or((Failure::Lost, 0))?;
    for it in 0..=MAX_ITERATIONS {
        let c = residual(p, y, lt);
        let norm = (p - y).length();
        if norm < TOLERANCE * scale {
            if known.iter().any(|k| (k.omega - omega).length() < SAME_SOLUTION) {
                return Ok(Converged::Known { iterations: it });
            }
            let g = geometry_term(&patch, x_j, omega, y, r.o).ok_or((Failure::NoConvergence, it))?;
            return Ok(Converged::New(PointSolution { omega, refracted: r, patch, g, iterations: it }));
        }
        if known.iter().any(|k| (k.omega - omega).length() < MERGE) {
            return Ok(Converged::Known { iterations: it });
        }
        if it == MAX_ITERATIONS {
            break;
        }
        let j = step_jacobian(&patch, x_j, omega, y, l, lt, c).ok_or((Failure::Lost, it))?;
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if !(det.abs() > 1e-300) || !det.is_finite() {
            break;
        }
        let step = damped_step(omega, j, c, det, |cand| {
            let pc = if stays_on(&patch, x_j, cand) { patch } else { locate.locate(x_j, cand)? };
            let (rc, qc) = beam(&pc, x_j, cand, y, l)?;
            ((qc - y).length() < norm).then_some((pc, rc, qc))
        });
        let Some((cand, (pc, rc, qc))) = step else {
            return Err((Failure::NoConvergence, it + 1));
        };
        (omega, patch, r, p) = (cand, pc, rc, qc);
    }
    Err((Failure::NoConvergence, MAX_ITERATIONS))
}

/// [`point_seed`] then [`solve_point`]: the first seed of [`solve_distinct`]. `Err((Lost, 0))`
/// when there is no seed.
pub fn solve_from_seed(locate: &mut impl Locate, x_j: DVec3, y: DVec3) -> Result<PointSolution, (Failure, u32)> {
    let seed = point_seed(locate, x_j, y).ok_or((Failure::Lost, 0))?;
    solve_point(locate, x_j, y, seed)
}

/// How many seeds the connection's deterministic procedure ([`solve_distinct`]) follows along the
/// chain of refracted seeds: the first is [`point_seed`]'s, each next one the refracted seed along
/// the previous ([`refracted_seed_along`]).
pub const CHAIN_SEEDS: usize = 4;
/// How many seeds of [`solve_distinct`] lie on a ring of angular radius [`RING`] around the first
/// seed (after the chain).
pub const RING_SEEDS: usize = 8;
/// How many seeds of [`solve_distinct`] lie on a second, wider ring of angular radius [`RING2`]
/// around the first seed (after the first ring).
pub const RING2_SEEDS: usize = 8;
/// All seeds of the procedure.
pub const SEEDS: usize = CHAIN_SEEDS + RING_SEEDS + RING2_SEEDS;
/// Angular radius (radians) of the ring of seeds around the first seed.
pub const RING: f64 = 0.1;
/// Angular radius (radians) of the second ring.
pub const RING2: f64 = 0.25;

/// Two directions are the same solution when they differ by less than this (radians).
pub const SAME_SOLUTION: f64 = 1e-4;

/// What [`solve_distinct`] found: every distinct converged solution, and the Newton work.
#[derive(Clone, Debug, Default)]
pub struct Distinct {
    pub solutions: Vec<PointSolution>,
    /// Newton solves started, iterations spent in all.
    pub solves: u32,
    pub iterations: u32,
    /// Solves that failed, by cause.
    pub lost: u32,
    pub not_converged: u32,
    /// Solves that stopped at (or converged to) a solution already found ([`MERGE`]).
    pub merged: u32,
}

/// The connection's deterministic procedure (docs/manifold.md §8.2, "Several solutions per
/// vertex"): Newton ([`converge`]) from each of `max_seeds` seeds — the chain of [`CHAIN_SEEDS`]
/// refracted seeds starting at `first` ([`seed_line`]'s seed, computed by the caller), each
/// the refracted seed along the previous one, then [`RING_SEEDS`] seeds on a ring of radius
/// [`RING`] around `first`, then [`RING2_SEEDS`] on a ring of radius [`RING2`] — keeping every
/// DISTINCT converged solution (directions apart by [`SAME_SOLUTION`] or more; a solve whose
/// iterate comes within [`MERGE`] of one already kept stops). A function of `(x_j, y)` only, so the
/// set is evaluable for any suffix by running the procedure again; an estimator summing over the
/// set is unbiased with density `q p_y / (G |cos θ_y|) · [the set holds the suffix]`. No seed at
/// all without `first`.
pub fn solve_distinct(
    locate: &mut impl Locate,
    x_j: DVec3,
    y: DVec3,
    first: Option<DVec3>,
    max_seeds: usize,
) -> Distinct {
    let mut out = Distinct::default();
    let Some(first) = first else { return out };
    let ring = tangents(first);
    let mut chain = Some(first);
    for k in 0..max_seeds {
        // A chain seed's ray is cast once: its patch serves both its own solve and the next seed.
        let (seed, seed_patch) = if k < CHAIN_SEEDS {
            let Some(seed) = chain else { continue };
            let patch = locate.locate(x_j, seed);
            chain = match &patch {
                Some(p) if k + 1 < CHAIN_SEEDS => refracted_seed_on(p, x_j, y, seed),
                _ => None,
            };
            out.solves += 1;
            let Some(patch) = patch else {
                out.lost += 1;
                continue;
            };
            (seed, Some(patch))
        } else {
            let (i, n, radius) = if k < CHAIN_SEEDS + RING_SEEDS {
                (k - CHAIN_SEEDS, RING_SEEDS, RING)
            } else {
                (k - CHAIN_SEEDS - RING_SEEDS, RING2_SEEDS, RING2)
            };
            let phi = i as f64 * std::f64::consts::TAU / n as f64;
            out.solves += 1;
            (moved(first, ring, radius * phi.cos(), radius * phi.sin()), None)
        };
        match converge(locate, x_j, y, seed, seed_patch, &out.solutions) {
            Ok(Converged::New(s)) => {
                out.iterations += s.iterations;
                out.solutions.push(s);
            }
            Ok(Converged::Known { iterations }) => {
                out.iterations += iterations;
                out.merged += 1;
            }
            Err((f, it)) => {
                out.iterations += it;
                match f {
                    Failure::Lost => out.lost += 1,
                    Failure::NoConvergence => out.not_converged += 1,
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::newton::tests::{Ball, Bump};
    use super::super::newton::Surface;
    use super::*;

    /// A flat facet (constant normal +z at height 1).
    struct Flat {
        eta: f64,
    }
    impl Locate for Flat {
        fn locate(&mut self, _o: DVec3, _d: DVec3) -> Option<Patch> {
            let p = [DVec3::new(-50.0, -50.0, 1.0), DVec3::new(50.0, -50.0, 1.0), DVec3::new(0.0, 50.0, 1.0)];
            Some(Patch { surface: Surface::Triangle { p, n: [DVec3::Z; 3] }, eta: self.eta })
        }
    }

    /// The solution refracts through `y` (Snell about the shading normal).
    fn check_solution(s: &PointSolution, x_j: DVec3, y: DVec3) {
        let r = s.patch.refract(x_j, s.omega).unwrap();
        let to_y = (y - r.x_k).normalize();
        assert!((r.o - to_y).length() < 1e-8, "{:?} vs {to_y:?}", r.o);
        let sin_in = (1.0 - r.cos_in * r.cos_in).sqrt();
        let sin_out = (1.0 - r.cos_out * r.cos_out).sqrt();
        assert!((s.patch.eta * sin_in - sin_out).abs() < 1e-8);
    }

    /// Solid angle of a small spherical triangle (Van Oosterom & Strackee 1983).
    fn tri_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
        2.0 * a.dot(b.cross(c)).abs().atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a))
    }

    /// `G` against re-solving: move `y` over a small triangle perpendicular to the outgoing ray,
    /// re-solve from the unperturbed solution, and compare the solid angle of the solutions with
    /// `G` times the triangle's area.
    fn check_geometry(locate: &mut impl Locate, x_j: DVec3, y: DVec3, tol: f64) {
        let s = solve_from_seed(locate, x_j, y).expect("solves");
        check_solution(&s, x_j, y);
        let (t1, t2) = tangents(s.refracted.o);
        let h = 1e-4 * (y - s.refracted.x_k).length();
        let offs = [(h, 0.0), (-0.5 * h, 0.8 * h), (-0.4 * h, -0.9 * h)];
        let dirs: Vec<DVec3> = offs
            .iter()
            .map(|&(a, b)| solve_point(locate, x_j, y + t1 * a + t2 * b, s.omega).expect("re-solves").omega)
            .collect();
        let area = 0.5
            * ((offs[1].0 - offs[0].0) * (offs[2].1 - offs[0].1) - (offs[2].0 - offs[0].0) * (offs[1].1 - offs[0].1))
                .abs();
        let fd = tri_solid_angle(dirs[0], dirs[1], dirs[2]) / area;
        let rel = (fd / s.g - 1.0).abs();
        assert!(rel < tol, "G {} vs re-solved {fd} (rel {rel})", s.g);
    }

    #[test]
    fn geometry_term_matches_re_solving_on_a_sphere() {
        for eta in [1.5, 1.33, 1.0, 1.0 / 1.33] {
            let mut ball = Ball { eta };
            for (x_j, y) in [
                (DVec3::new(0.1, -0.2, 0.3), DVec3::new(1.0, 0.8, 3.0)),
                (DVec3::new(-0.5, 0.1, -0.2), DVec3::new(0.0, 0.0, 5.0)),
                (DVec3::new(0.4, 0.4, 0.5), DVec3::new(-20.0, 30.0, 25.0)),
            ] {
                check_geometry(&mut ball, x_j, y, 2e-3);
            }
        }
    }

    #[test]
    fn geometry_term_matches_re_solving_on_interpolated_normals() {
        for eta in [1.5, 1.33] {
            let mut bump = Bump { eta };
            for (x_j, y) in [
                (DVec3::new(0.1, -0.2, 0.3), DVec3::new(0.5, 0.4, 3.0)),
                (DVec3::new(-0.5, 0.1, -0.2), DVec3::new(0.0, 0.0, 2.0)),
                (DVec3::new(0.4, 0.4, 0.5), DVec3::new(-3.0, 2.0, 6.0)),
            ] {
                check_geometry(&mut bump, x_j, y, 2e-3);
            }
        }
    }

    /// On a flat facet `G` is the closed form of docs/manifold.md §3.2 (`pdf::plane_geometry`).
    #[test]
    fn flat_limit_is_the_closed_form() {
        let mut solved = 0;
        for eta in [1.5, 1.33, 1.0 / 1.33] {
            let mut flat = Flat { eta };
            for (x_j, y) in [
                (DVec3::new(0.1, 0.2, -1.0), DVec3::new(0.3, -0.2, 3.0)),
                (DVec3::new(-0.5, 0.4, 0.2), DVec3::new(2.0, 1.0, 2.5)),
                (DVec3::new(0.0, 0.0, -3.0), DVec3::new(-4.0, 0.5, 2.0)),
            ] {
                let Ok(s) = solve_from_seed(&mut flat, x_j, y) else { continue };
                check_solution(&s, x_j, y);
                solved += 1;
                let r = s.refracted;
                let closed = super::super::pdf::plane_geometry(
                    r.t as f32,
                    (y - r.x_k).length() as f32,
                    r.cos_in as f32,
                    r.cos_out as f32,
                    eta as f32,
                );
                assert!((s.g / closed - 1.0).abs() < 1e-4, "eta {eta}: G {} vs closed {closed}", s.g);
            }
        }
        // Every configuration has a solution except where the light is beyond the critical angle
        // of the rarer inside (η = 1/1.33).
        assert!(solved >= 7, "only {solved} of 9 solved");
    }

    /// pdf integration on a glass ball: the technique's density of the direction `omega` at
    /// `x_j`, `q(x_j, y) p_A(y) / (G cos θ_y) · [the procedure from (x_j, y(omega)) converges to
    /// omega]`, integrates over all directions to the probability that a uniformly sampled point
    /// `y` of a rectangle light yields a solution and the connection runs, `E_y[q(x_j, y) ·
    /// solution(y)]`; with the constant rate `q = 1` and with the connection's rate
    /// (`curved_finite::rate_at`, top rate 0.2, σ_t 3, from the straight line's `t0`). Both sides
    /// by quadrature (a Fibonacci lattice of 400 000 directions; a 600 × 600 grid on the
    /// rectangle), within 1 %.
    #[test]
    fn seeded_density_integrates_to_the_success_probability() {
        use super::super::curved_finite::rate_at;
        for eta in [1.5, 1.33] {
            let mut ball = Ball { eta };
            let x_j = DVec3::new(0.2, -0.3, 0.1);
            // Rectangle [−1.5, 1] × [−1, 1.2] at height 2.5, facing down.
            let (x0, x1, y0, y1, hgt) = (-1.5f64, 1.0, -1.0, 1.2, 2.5);
            let area = (x1 - x0) * (y1 - y0);
            // The procedure and its rate at (x_j, y): (q, the solution).
            let mut technique = |y: DVec3| {
                let (t0, first) = seed_line(&mut ball, x_j, y);
                (rate_at(0.2, 3.0, t0), solve_distinct(&mut ball, x_j, y, first, SEEDS))
            };
            let n_dir = 400_000u32;
            let mut integral = [0.0; 2];
            for i in 0..n_dir {
                let z = 1.0 - (2.0 * i as f64 + 1.0) / n_dir as f64;
                let phi = i as f64 * 2.399963229728653;
                let rz = (1.0 - z * z).sqrt();
                let w = DVec3::new(rz * phi.cos(), rz * phi.sin(), z);
                let Some(r) = Ball { eta }.locate(x_j, w).and_then(|p| p.refract(x_j, w)) else { continue };
                if !(r.o.z > 0.0) {
                    continue;
                }
                let y = r.x_k + r.o * ((hgt - r.x_k.z) / r.o.z);
                if !(y.x > x0 && y.x < x1 && y.y > y0 && y.y < y1) {
                    continue;
                }
                let (q, d) = technique(y);
                let Some(s) = d.solutions.iter().find(|s| (s.omega - w).length() < SAME_SOLUTION) else { continue };
                let p = (1.0 / area) / (s.g * r.o.z);
                integral[0] += p;
                integral[1] += q * p;
            }
            let n_grid = 600;
            let mut found = [0.0; 2];
            let mut most = 0;
            for a in 0..n_grid {
                for b in 0..n_grid {
                    let y = DVec3::new(
                        x0 + (x1 - x0) * (a as f64 + 0.5) / n_grid as f64,
                        y0 + (y1 - y0) * (b as f64 + 0.5) / n_grid as f64,
                        hgt,
                    );
                    let (q, d) = technique(y);
                    let n = d.solutions.len() as f64;
                    found[0] += n;
                    found[1] += q * n;
                    most = most.max(d.solutions.len());
                }
            }
            for k in 0..2 {
                let integral = integral[k] * 4.0 * std::f64::consts::PI / n_dir as f64;
                let p_found = found[k] / (n_grid * n_grid) as f64;
                eprintln!("eta {eta}, rate {k}: ∫ p_man dω = {integral:.5}, E[q · solutions] = {p_found:.5} (at most {most} per y)");
                assert!(p_found > [0.5, 0.01][k], "the seed should usually converge here");
                assert!((integral / p_found - 1.0).abs() < 1e-2, "eta {eta}: {integral} vs {p_found}");
            }
        }
    }
}

//! Newton iteration on the refraction constraint through a CURVED smooth surface (triangle meshes
//! with interpolated shading normals, analytic spheres), for a light in a fixed direction
//! (docs/manifold.md §8; Hanika, Droske, Fascione 2015, §3–4).
//!
//! The unknown is the direction `omega` from the medium vertex `x_j` (2 degrees of freedom); the
//! boundary point `x_k(omega)` is the first hit of the ray `(x_j, omega)`, so "the first hit from
//! `x_j` towards `x_k` is `x_k`" holds by construction and the walk across triangles is the ray
//! cast itself (no adjacency table needed). At `x_k` the ray refracts about the interpolated
//! shading normal `n_s(x_k)` (the normal Mitsuba's `dielectric` refracts about) into the outgoing
//! direction `o(omega)`. The constraint (Jakob & Marschner 2012, §4: the generalized half-vector
//! `η_int (−omega) + η_ext o` is parallel to `n_s`, i.e. Snell's law) is solved as
//!
//! ```text
//! C(omega) = P_l (o(omega) − omega_l) = 0,      P_l: projection on the tangent plane of omega_l
//! ```
//!
//! in the 2-D coordinates `(a, b)` of `omega' = normalize(omega + a t1 + b t2)` (`t1, t2` ⟂ omega).
//! Within one triangle `x_k` is the hit of the triangle's supporting plane and `n_s` the
//! normalized barycentric interpolation of the vertex normals, both smooth in `omega`; the
//! Jacobian `dC/d(a, b)` is taken by central differences of that closed-form map in f64
//! (step 1e-6 rad, truncation ~1e-12). At a solution the same 2×2 matrix is the solid-angle
//! Jacobian `dω_l/dω` of the map `omega ↦ o` (both coordinate pairs are orthonormal tangent
//! coordinates at `omega` and `omega_l`): the beam spread of the curved interface, which
//! `curved.rs` uses in the value (Hanika et al. 2015 §4.3, the distant-light limit of the
//! generalized geometry term). Checked by re-solving with perturbed `omega_l` (unit tests below).

use crate::math::DVec3;

/// Newton steps at most per solve.
pub const MAX_ITERATIONS: u32 = 24;
/// Converged when `|o − omega_l| < TOLERANCE` (f64, radians).
pub const TOLERANCE: f64 = 1e-8;
/// Largest step (radians) per Newton iteration.
const MAX_STEP: f64 = 0.25;
/// Finite-difference step for the Jacobian (radians).
const FD_STEP: f64 = 1e-6;

/// The smooth surface around the current boundary hit, in closed form (f64).
#[derive(Clone, Copy, Debug)]
pub enum Surface {
    /// A triangle's supporting plane with its (outward) vertex shading normals.
    Triangle { p: [DVec3; 3], n: [DVec3; 3] },
    /// An analytic sphere; `outward`: +1 (normal points away from the centre) or −1 (`flip_normals`).
    Sphere { center: DVec3, radius: f64, outward: f64 },
}

/// One boundary patch: the surface and `η = η_int / η_ext` of its dielectric.
#[derive(Clone, Copy, Debug)]
pub struct Patch {
    pub surface: Surface,
    pub eta: f64,
}

/// Where a ray from `x_j` first meets the boundary (the caller's ray cast): the patch there, or
/// `None` when the first hit is not on the medium's enclosing smooth boundary, seen from inside.
pub trait Locate {
    fn locate(&mut self, o: DVec3, d: DVec3) -> Option<Patch>;
}

/// The closed-form map of one patch at `omega`: the point, outward shading normal, refraction.
#[derive(Clone, Copy, Debug)]
pub struct Refracted {
    pub x_k: DVec3,
    pub n_s: DVec3,
    /// Outgoing direction after refraction (outside, towards the light at a solution).
    pub o: DVec3,
    /// `omega · n_s > 0` (inside) and `o · n_s > 0` (outside).
    pub cos_in: f64,
    pub cos_out: f64,
    /// Distance `x_j → x_k`.
    pub t: f64,
}

/// Where the ray `(x, d)` meets the plane of the triangle `p`: the distance `t > 0` and the
/// barycentrics `(b1, b2)` of the hit in that plane (extended beyond the triangle's edges); `None`
/// when the ray is parallel to the plane or the plane lies behind `x`.
pub fn triangle_plane_hit(p: &[DVec3; 3], x: DVec3, d: DVec3) -> Option<(f64, f64, f64)> {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let ng = e1.cross(e2);
    let denom = d.dot(ng);
    if denom == 0.0 {
        return None;
    }
    let t = (p[0] - x).dot(ng) / denom;
    if !(t > 0.0) {
        return None;
    }
    let q = x + d * t - p[0];
    let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
    let (q1, q2) = (q.dot(e1), q.dot(e2));
    let det = d11 * d22 - d12 * d12;
    let b1 = (d22 * q1 - d12 * q2) / det;
    let b2 = (d11 * q2 - d12 * q1) / det;
    Some((t, b1, b2))
}

impl Patch {
    /// Hit of the ray `(x, d)` with the extended surface and the shading normal there.
    pub fn hit(&self, x: DVec3, d: DVec3) -> Option<(f64, DVec3, DVec3)> {
        match self.surface {
            Surface::Triangle { p, n } => {
                let (t, b1, b2) = triangle_plane_hit(&p, x, d)?;
                let n_s = (n[0] * (1.0 - b1 - b2) + n[1] * b1 + n[2] * b2).normalize_or_zero();
                (n_s != DVec3::ZERO).then_some((t, x + d * t, n_s))
            }
            Surface::Sphere { center, radius, outward } => {
                let oc = x - center;
                let b = oc.dot(d);
                let c = oc.dot(oc) - radius * radius;
                let disc = b * b - c;
                if !(disc >= 0.0) {
                    return None;
                }
                let s = disc.sqrt();
                let t = if -b - s > 0.0 { -b - s } else { -b + s };
                if !(t > 0.0) {
                    return None;
                }
                let y = x + d * t;
                Some((t, y, (y - center) / radius * outward))
            }
        }
    }

    /// Refract the ray `(x_j, omega)` out through the patch (Snell about the shading normal);
    /// `None` when it meets the surface from outside or is totally reflected.
    pub fn refract(&self, x_j: DVec3, omega: DVec3) -> Option<Refracted> {
        let (t, x_k, n_s) = self.hit(x_j, omega)?;
        let cos_in = omega.dot(n_s);
        if !(cos_in > 0.0) {
            return None;
        }
        // η_int sin θ_in = η_ext sin θ_out.
        let cos_out2 = 1.0 - self.eta * self.eta * (1.0 - cos_in * cos_in);
        if !(cos_out2 > 0.0) {
            return None;
        }
        let cos_out = cos_out2.sqrt();
        let o = ((omega - n_s * cos_in) * self.eta + n_s * cos_out).normalize();
        Some(Refracted { x_k, n_s, o, cos_in, cos_out, t })
    }
}

/// An orthonormal tangent basis of the unit vector `n` (Duff et al. 2017, as `Frame::from_normal`).
pub fn tangents(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x), DVec3::new(b, sign + n.y * n.y * a, -n.y))
}

/// `omega` moved by `(a, b)` in its tangent coordinates.
#[inline]
pub fn moved(omega: DVec3, t: (DVec3, DVec3), a: f64, b: f64) -> DVec3 {
    (omega + t.0 * a + t.1 * b).normalize()
}

/// The damped Newton step of every solver here (`solve`, `newton_point`, `chain`): the step
/// `δ = −J⁻¹ C` (Jacobian `j` with determinant `det`, residual `c`) in `omega`'s tangent
/// coordinates, capped at `MAX_STEP` and halved (at most 10 times) until `accept` takes the moved
/// direction; `None` when it never does.
pub fn damped_step<T>(
    omega: DVec3,
    j: [[f64; 2]; 2],
    c: [f64; 2],
    det: f64,
    mut accept: impl FnMut(DVec3) -> Option<T>,
) -> Option<(DVec3, T)> {
    let mut da = -(j[1][1] * c[0] - j[0][1] * c[1]) / det;
    let mut db = -(-j[1][0] * c[0] + j[0][0] * c[1]) / det;
    let len = da.hypot(db);
    if len > MAX_STEP {
        da *= MAX_STEP / len;
        db *= MAX_STEP / len;
    }
    let t = tangents(omega);
    for _ in 0..10 {
        let cand = moved(omega, t, da, db);
        if let Some(v) = accept(cand) {
            return Some((cand, v));
        }
        da *= 0.5;
        db *= 0.5;
    }
    None
}

/// Specular manifold sampling's Bernoulli trials (Zeltner et al. 2020, §4.3) after a first solution
/// `omega`: draw solutions until one equal to it comes back. The number of draws `n` (counting the
/// first) has `E[n] = 1/p`; returns `(n, capped)`, `capped` when [`MAX_TRIALS`] stopped it.
pub fn bernoulli_trials(omega: DVec3, draw: impl FnMut() -> Option<DVec3>) -> (u32, bool) {
    bernoulli_trials_capped(omega, MAX_TRIALS, draw)
}

/// [`bernoulli_trials`] with the cap `cap`: `E[min(n, cap) | p] = (1 − (1 − p)^cap) / p`, so a
/// solution of probability `p` is under-counted by the factor `1 − (1 − p)^cap ≥ 1 − e^{−p cap}`.
pub fn bernoulli_trials_capped(omega: DVec3, cap: u32, mut draw: impl FnMut() -> Option<DVec3>) -> (u32, bool) {
    let mut n = 1;
    loop {
        if n >= cap {
            return (n, true);
        }
        match draw() {
            Some(o) if (o - omega).length() < SAME_SOLUTION => return (n, false),
            _ => n += 1,
        }
    }
}

/// The constraint `C = P_l (o − omega_l)` in the tangent coordinates `l` of `omega_l`.
#[inline]
fn residual(r: &Refracted, omega_l: DVec3, l: (DVec3, DVec3)) -> [f64; 2] {
    let v = r.o - omega_l;
    [v.dot(l.0), v.dot(l.1)]
}

/// The 2×2 Jacobian of a residual `r(a, b)` at `(0, 0)` by central differences with step `h`:
/// column 0 is `(r(h, 0) − r(−h, 0)) / 2h`, column 1 `(r(0, h) − r(0, −h)) / 2h`; `None` when `r` is
/// undefined at one of the four points. Shared by every Newton solve of the manifold connections.
pub fn central_jacobian(h: f64, mut r: impl FnMut(f64, f64) -> Option<[f64; 2]>) -> Option<[[f64; 2]; 2]> {
    let mut j = [[0.0; 2]; 2];
    for (col, (a, b)) in [(h, 0.0), (0.0, h)].into_iter().enumerate() {
        let plus = r(a, b)?;
        let minus = r(-a, -b)?;
        for row in 0..2 {
            j[row][col] = (plus[row] - minus[row]) / (2.0 * h);
        }
    }
    Some(j)
}

/// `dC/d(a, b)` at `omega` on `patch` (columns: a, b), by central differences of the closed form.
fn jacobian(patch: &Patch, x_j: DVec3, omega: DVec3, omega_l: DVec3, l: (DVec3, DVec3)) -> Option<[[f64; 2]; 2]> {
    let t = tangents(omega);
    central_jacobian(FD_STEP, |a, b| Some(residual(&patch.refract(x_j, moved(omega, t, a, b))?, omega_l, l)))
}

/// A converged, located solution.
#[derive(Clone, Copy, Debug)]
pub struct Solution {
    /// Unit direction `x_j → x_k`.
    pub omega: DVec3,
    pub refracted: Refracted,
    pub patch: Patch,
    /// `dω/dω_l`: solid angle at `x_j` per solid angle of outgoing directions (the beam spread).
    pub d_omega_d_omega_l: f64,
    pub iterations: u32,
}

/// Why a solve failed (counted in `--stats`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Failure {
    /// The seed ray (or every damped step) left the boundary, met it from outside or was totally
    /// reflected.
    Lost,
    /// No convergence within [`MAX_ITERATIONS`] (or a singular Jacobian).
    NoConvergence,
}

/// The seed of a solve (Hanika et al. 2015 §3, with one refinement): follow the straight line
/// from `x_j` towards the light to the boundary, and refract `omega_l` into the medium about the
/// shading normal there; the seed is the reverse of that inner direction (exact on a flat facet,
/// and never totally reflected, unlike the straight line itself). `None` when the straight line
/// leaves the boundary or the light is behind the normal there.
pub fn refracted_seed(locate: &mut impl Locate, x_j: DVec3, omega_l: DVec3) -> Option<DVec3> {
    let omega_l = omega_l.normalize();
    let patch = locate.locate(x_j, omega_l)?;
    let (_, _, n_s) = patch.hit(x_j, omega_l)?;
    seed_from_light(omega_l, n_s, patch.eta)
}

/// The seed direction at a boundary point with shading normal `n_s` (outwards) and relative index
/// `eta` for the light direction `omega_l` (unit, outwards): the inner direction, pointing at the
/// boundary from inside, that refracts out along `omega_l`. `None` when the light is behind `n_s`.
pub fn seed_from_light(omega_l: DVec3, n_s: DVec3, eta: f64) -> Option<DVec3> {
    let cos_l = omega_l.dot(n_s);
    if !(cos_l > 0.0) {
        return None;
    }
    // η_ext sin θ_l = η_int sin θ_in: the tangential part shrinks by 1/η.
    let tangential = (omega_l - n_s * cos_l) / eta;
    let cos_in = (1.0 - tangential.length_squared()).max(0.0).sqrt();
    Some((tangential + n_s * cos_in).normalize())
}

/// Solve `o(omega) = omega_l` from the seed direction `seed` at `x_j`; the ray casts go through
/// `locate` (a new patch whenever the walk crosses into another triangle). Damped Newton: a step
/// is halved until the residual decreases (at most 10 halvings). Returns the iterations spent on
/// failure as well.
pub fn solve(locate: &mut impl Locate, x_j: DVec3, omega_l: DVec3, seed: DVec3) -> Result<Solution, (Failure, u32)> {
    // A unit vector in f64 (an f32 direction is unit only to ~1e-8, the tolerance's size).
    let omega_l = omega_l.normalize();
    let l = tangents(omega_l);
    let mut omega = seed.normalize();
    let mut patch = locate.locate(x_j, omega).ok_or((Failure::Lost, 0))?;
    let mut r = patch.refract(x_j, omega).ok_or((Failure::Lost, 0))?;
    let mut c = residual(&r, omega_l, l);
    for it in 0..=MAX_ITERATIONS {
        // The full distance |o − omega_l| (the projected C also vanishes at o = −omega_l).
        let norm = (r.o - omega_l).length();
        let j = jacobian(&patch, x_j, omega, omega_l, l).ok_or((Failure::Lost, it))?;
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if norm < TOLERANCE {
            if !(det.abs() > 0.0) || !det.is_finite() {
                return Err((Failure::NoConvergence, it));
            }
            return Ok(Solution { omega, refracted: r, patch, d_omega_d_omega_l: 1.0 / det.abs(), iterations: it });
        }
        if it == MAX_ITERATIONS || !(det.abs() > 1e-300) {
            break;
        }
        let step = damped_step(omega, j, c, det, |cand| {
            let p = locate.locate(x_j, cand)?;
            let rc = p.refract(x_j, cand)?;
            ((rc.o - omega_l).length() < norm).then_some((p, rc))
        });
        let Some((cand, (p, rc))) = step else {
            return Err((Failure::NoConvergence, it + 1));
        };
        c = residual(&rc, omega_l, l);
        (omega, patch, r) = (cand, p, rc);
    }
    Err((Failure::NoConvergence, MAX_ITERATIONS))
}

/// Largest number of Bernoulli trials of [`bernoulli_trials`] (SMS's cap: beyond it the estimate of
/// `1/p` is truncated, a bias bounded by `(1 − p)^CAP` of that solution's contribution).
pub const MAX_TRIALS: u32 = 64;
/// Largest number of Bernoulli trials in [`sample_solution`] (the one-refraction connection under
/// a directional light, docs/manifold.md §8.1): a solution of probability `p` keeps the share
/// `1 − (1 − p)^CAP` of its contribution (above `1 − 1.6e-7` for `p ≥ 1/256`). The expected number
/// of draws per connection does not depend on the cap beyond `1 + (number of solutions)` (each
/// solution `s` is drawn first with probability `p(s)` and then costs `1/p(s)` draws).
pub const DIRECTIONAL_MAX_TRIALS: u32 = 4096;
/// Two solutions are the same when their directions differ by less than this (radians).
const SAME_SOLUTION: f64 = 1e-4;
/// Probability of the deterministic seed ([`refracted_seed`]) in the seed mixture, when its solve
/// converged (else 0: the mixture is chosen after that one solve, a function of `(x_j, omega_l)`).
const P_DETERMINISTIC: f64 = 0.25;
/// Probability, among the random seeds, of the refracted random seed ([`random_seed`]).
pub const P_REFRACTED_RANDOM: f64 = 0.5;

/// Statistics of one [`sample_solution`] call (for `--stats`).
#[derive(Clone, Copy, Debug, Default)]
pub struct SolveCounts {
    pub solves: u64,
    pub iterations: u64,
    pub no_convergence: u64,
    pub lost: u64,
    pub capped: u64,
}

impl SolveCounts {
    fn count(&mut self, r: &Result<Solution, (Failure, u32)>) {
        self.solves += 1;
        match r {
            Ok(s) => self.iterations += s.iterations as u64,
            Err((f, it)) => {
                self.iterations += *it as u64;
                match f {
                    Failure::Lost => self.lost += 1,
                    Failure::NoConvergence => self.no_convergence += 1,
                }
            }
        }
    }
}

/// A direction uniform on the sphere (in `f64`; `warp::square_to_uniform_sphere` is the `f32` one):
/// `z = 1 − 2 u1`, `φ = 2π u2`.
pub fn sphere_seed(u1: f64, u2: f64) -> DVec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u2;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// The largest angle between a refraction solution `omega` and `omega_l` through interfaces of
/// relative index at most `eta_max` (`η = η_int / η_ext`): the light turns by `θ_l − θ_in`, largest
/// at grazing incidence, `π/2 − asin(1/η)` for `η > 1`; `π/2` otherwise (a refracted ray turns by
/// less than 90°).
pub fn max_turn(eta_max: f64) -> f64 {
    if eta_max > 1.0 {
        std::f64::consts::FRAC_PI_2 - (1.0 / eta_max).asin()
    } else {
        std::f64::consts::FRAC_PI_2
    }
}

/// A direction uniform in the cone of half-angle `turn` around `omega_l`.
pub fn cone_seed(omega_l: DVec3, turn: f64, u1: f64, u2: f64) -> DVec3 {
    let z = 1.0 - u1 * (1.0 - turn.cos());
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * u2;
    let (t1, t2) = tangents(omega_l);
    (t1 * (r * phi.cos()) + t2 * (r * phi.sin()) + omega_l * z).normalize()
}

/// One random seed of [`sample_solution`]: a direction `w` uniform in the cone of half-angle
/// `turn` around `omega_l` (every solution lies there, [`max_turn`]); with probability
/// `p_refracted`, `w` is then replaced by the reverse of `omega_l` refracted about the shading
/// normal where `w` meets the boundary (a random boundary point's own "refracted seed", as
/// [`refracted_seed`] is the straight line's; `w` itself when that fails). Every direction of the
/// cone keeps a positive density (the uniform part), so every solution a seed in its basin of
/// convergence reaches has a positive probability.
pub fn random_seed(
    locate: &mut impl Locate,
    x_j: DVec3,
    omega_l: DVec3,
    turn: f64,
    p_refracted: f64,
    u: &mut dyn FnMut() -> f64,
) -> DVec3 {
    let refracted = u() < p_refracted;
    let w = cone_seed(omega_l, turn, u(), u());
    if !refracted {
        return w;
    }
    let Some(patch) = locate.locate(x_j, w) else { return w };
    let Some((_, _, n_s)) = patch.hit(x_j, w) else { return w };
    let cos_l = omega_l.dot(n_s);
    if !(cos_l > 0.0) {
        return w;
    }
    let tangential = (omega_l - n_s * cos_l) / patch.eta;
    let cos_in = (1.0 - tangential.length_squared()).max(0.0).sqrt();
    (tangential + n_s * cos_in).normalize()
}

/// Specular manifold sampling's estimate (Zeltner, Georgiev, Jakob 2020, §4.3): one solution `s`
/// from a random seed, and the number `N` of seeds drawn until `s` is found again
/// (`E[N | s] = 1/p(s)`, capped at [`DIRECTIONAL_MAX_TRIALS`]). `f(s) · N` is then an estimate of
/// `Σ_s f(s)` over all solutions whatever their number. The seed distribution is a function of
/// `(x_j, omega_l)` only: the deterministic [`refracted_seed`] is solved first; when it converged,
/// each draw takes it with probability [`P_DETERMINISTIC`] (solved once, reused), else a
/// [`random_seed`] in the cone of half-angle `turn` ([`max_turn`] of the boundary's largest
/// index), so every solution has a positive probability. `u` supplies uniform numbers in [0, 1).
pub fn sample_solution(
    locate: &mut impl Locate,
    x_j: DVec3,
    omega_l: DVec3,
    turn: f64,
    u: &mut impl FnMut() -> f64,
    counts: &mut SolveCounts,
) -> Option<(Solution, u32)> {
    let omega_l = omega_l.normalize();
    let det = refracted_seed(locate, x_j, omega_l)
        .ok_or((Failure::Lost, 0))
        .and_then(|seed| solve(locate, x_j, omega_l, seed));
    counts.count(&det);
    let deterministic = det.ok();
    let p_det = if deterministic.is_some() { P_DETERMINISTIC } else { 0.0 };
    let draw = |locate: &mut _, u: &mut dyn FnMut() -> f64, counts: &mut SolveCounts| -> Option<Solution> {
        if u() < p_det {
            deterministic
        } else {
            let seed = random_seed(locate, x_j, omega_l, turn, P_REFRACTED_RANDOM, u);
            let r = solve(locate, x_j, omega_l, seed);
            counts.count(&r);
            r.ok()
        }
    };
    let s = draw(locate, u, counts)?;
    let (n, capped) =
        bernoulli_trials_capped(s.omega, DIRECTIONAL_MAX_TRIALS, || draw(locate, u, counts).map(|t| t.omega));
    counts.capped += capped as u64;
    Some((s, n))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    /// The whole boundary is one analytic sphere (unit radius at the origin).
    pub(in super::super) struct Ball {
        pub(in super::super) eta: f64,
    }

    impl Locate for Ball {
        fn locate(&mut self, _o: DVec3, _d: DVec3) -> Option<Patch> {
            Some(Patch { surface: Surface::Sphere { center: DVec3::ZERO, radius: 1.0, outward: 1.0 }, eta: self.eta })
        }
    }

    /// A smooth-shaded "bump": one large triangle whose vertex normals tilt outwards, so the
    /// shading normal varies linearly across a flat facet (curvature from the normals alone).
    pub(in super::super) struct Bump {
        pub(in super::super) eta: f64,
    }

    impl Locate for Bump {
        fn locate(&mut self, _o: DVec3, _d: DVec3) -> Option<Patch> {
            let p = [DVec3::new(-3.0, -3.0, 1.0), DVec3::new(3.0, -3.0, 1.0), DVec3::new(0.0, 3.0, 1.0)];
            let n = [
                DVec3::new(-0.4, -0.3, 1.0).normalize(),
                DVec3::new(0.5, -0.2, 1.0).normalize(),
                DVec3::new(0.1, 0.6, 1.0).normalize(),
            ];
            Some(Patch { surface: Surface::Triangle { p, n }, eta: self.eta })
        }
    }

    /// The solution obeys Snell's law about the shading normal and reaches `omega_l`.
    fn check_solution(s: &Solution, x_j: DVec3, omega_l: DVec3) {
        let r = s.patch.refract(x_j, s.omega).unwrap();
        assert!((r.o - omega_l).length() < 1e-7, "{:?} vs {omega_l:?}", r.o);
        let sin_in = (1.0 - r.cos_in * r.cos_in).sqrt();
        let sin_out = (1.0 - r.cos_out * r.cos_out).sqrt();
        assert!((s.patch.eta * sin_in - sin_out).abs() < 1e-7);
        // omega, o and n_s coplanar.
        assert!(r.n_s.cross(s.omega).dot(r.o).abs() < 1e-7);
    }

    /// `dω/dω_l` against the solid angle of the solutions for a small cone of light directions
    /// (re-solved by Newton from the unperturbed solution): the Jacobian by re-solving.
    fn check_jacobian(locate: &mut impl Locate, x_j: DVec3, omega_l: DVec3, tol: f64) {
        let seed = refracted_seed(locate, x_j, omega_l).expect("seeds");
        let s = solve(locate, x_j, omega_l, seed).expect("solves");
        check_solution(&s, x_j, omega_l);
        let h = 1e-4;
        let (l1, l2) = tangents(omega_l);
        let mut corner = |a: f64, b: f64| {
            let w = (omega_l + l1 * a + l2 * b).normalize();
            solve(locate, x_j, w, s.omega).expect("perturbed solves").omega
        };
        // Solid angle of the image of the square [-h, h]² (two triangles, small: |a × b| / 2).
        let (p00, p10, p11, p01) = (corner(-h, -h), corner(h, -h), corner(h, h), corner(-h, h));
        let area = 0.5 * ((p10 - p00).cross(p11 - p00).length() + (p11 - p00).cross(p01 - p00).length());
        let source = 4.0 * h * h;
        let fd = area / source;
        let rel = (fd / s.d_omega_d_omega_l - 1.0).abs();
        assert!(rel < tol, "dω/dω_l {} vs re-solved {fd} (rel {rel})", s.d_omega_d_omega_l);
    }

    #[test]
    fn jacobian_matches_re_solving_on_a_sphere() {
        for eta in [1.5, 1.33, 1.0, 1.0 / 1.33] {
            let mut ball = Ball { eta };
            for (x_j, omega_l) in [
                (DVec3::new(0.1, -0.2, 0.3), DVec3::new(0.3, 0.2, 0.9)),
                (DVec3::new(-0.5, 0.1, -0.2), DVec3::new(0.0, 0.0, 1.0)),
                (DVec3::new(0.4, 0.4, 0.5), DVec3::new(-0.5, 0.6, 0.4)),
            ] {
                check_jacobian(&mut ball, x_j, omega_l.normalize(), 2e-3);
            }
        }
    }

    #[test]
    fn jacobian_matches_re_solving_on_interpolated_normals() {
        for eta in [1.5, 1.33] {
            let mut bump = Bump { eta };
            for (x_j, omega_l) in [
                (DVec3::new(0.1, -0.2, 0.3), DVec3::new(0.3, 0.2, 0.9)),
                (DVec3::new(-0.5, 0.1, -0.2), DVec3::new(0.0, 0.0, 1.0)),
                (DVec3::new(0.4, 0.4, 0.5), DVec3::new(-0.4, 0.3, 0.8)),
            ] {
                check_jacobian(&mut bump, x_j, omega_l.normalize(), 2e-3);
            }
        }
    }

    /// On a flat facet with constant normal the beam spread is the closed form
    /// `dω_in/dω_l = cos θ_l / (η² cos θ_in)` of docs/manifold.md §3.
    #[test]
    fn flat_limit_is_the_closed_form() {
        struct Flat;
        impl Locate for Flat {
            fn locate(&mut self, _o: DVec3, _d: DVec3) -> Option<Patch> {
                let p = [DVec3::new(-9.0, -9.0, 1.0), DVec3::new(9.0, -9.0, 1.0), DVec3::new(0.0, 9.0, 1.0)];
                Some(Patch { surface: Surface::Triangle { p, n: [DVec3::Z; 3] }, eta: 1.5 })
            }
        }
        let omega_l = DVec3::new(0.5, 0.1, 0.7).normalize();
        let seed = refracted_seed(&mut Flat, DVec3::ZERO, omega_l).unwrap();
        assert_eq!(solve(&mut Flat, DVec3::ZERO, omega_l, seed).unwrap().iterations, 0);
        let s = solve(&mut Flat, DVec3::ZERO, omega_l, omega_l).unwrap();
        let closed = s.refracted.cos_out / (1.5 * 1.5 * s.refracted.cos_in);
        assert!((s.d_omega_d_omega_l / closed - 1.0).abs() < 1e-6, "{} vs {closed}", s.d_omega_d_omega_l);
    }
}

/// The Bernoulli trials' count against its known expectation: a draw returns the first solution
/// with probability `p`, so `E[min(N, cap)] = (1 − (1 − p)^cap) / p` (`1/p` up to `e^{−p cap}`).
/// 200 000 runs per case, chosen before the first run; within 5 standard errors.
#[cfg(test)]
mod trials {
    use super::*;

    #[test]
    fn bernoulli_count_has_expectation_one_over_p() {
        let mut rng = crate::sampler::Sampler::new(3, 1);
        let mut u = move || rng.next_1d() as f64;
        for (p, cap) in
            [(0.5, DIRECTIONAL_MAX_TRIALS), (0.01, DIRECTIONAL_MAX_TRIALS), (0.001, DIRECTIONAL_MAX_TRIALS), (0.1, 8)]
        {
            let runs = 200_000;
            let (mut s, mut s2) = (0.0, 0.0);
            for _ in 0..runs {
                let (n, _) = bernoulli_trials_capped(DVec3::X, cap, || Some(if u() < p { DVec3::X } else { DVec3::Y }));
                s += n as f64;
                s2 += (n as f64) * (n as f64);
            }
            let mean = s / runs as f64;
            let se = ((s2 / runs as f64 - mean * mean) / runs as f64).sqrt();
            let expected = (1.0 - (1.0 - p).powi(cap as i32)) / p;
            assert!((mean - expected).abs() < 5.0 * se, "p {p} cap {cap}: {mean} ± {se} vs {expected}");
        }
    }

    /// The cone seeds stay within `max_turn` of `omega_l` and fill it uniformly in `cos`.
    #[test]
    fn cone_seeds_fill_the_cone() {
        let omega_l = DVec3::new(0.3, -0.5, 0.8).normalize();
        let turn = max_turn(1.5);
        let mut rng = crate::sampler::Sampler::new(4, 1);
        let mut below = 0;
        let n = 100_000;
        let mid = 0.5 * (1.0 + turn.cos());
        for _ in 0..n {
            let w = cone_seed(omega_l, turn, rng.next_1d() as f64, rng.next_1d() as f64);
            assert!(w.dot(omega_l) >= turn.cos() - 1e-12);
            below += (w.dot(omega_l) < mid) as u32;
        }
        let frac = below as f64 / n as f64;
        assert!((frac - 0.5).abs() < 5.0 * (0.25 / n as f64).sqrt(), "{frac}");
    }
}

/// On a glass ball (n = 1.5) the refracted beam overlaps itself (rays from opposite sides of the
/// axis cross, and the caustic), so a point `x_j` can have several solutions: at random `x_j`
/// (uniform in the ball) and light directions, every solution is collected from 256 random seeds,
/// and (1) the share of the geometric weight `(1 − F) η² dω/dω_l` the deterministic seed alone
/// finds is printed (not asserted), (2) [`sample_solution`]'s `f(s) · N` averaged over 256 runs per
/// point must match the sum over all solutions, pooled over the points, within 4 standard errors.
#[cfg(test)]
mod coverage {
    use super::*;

    struct Ball;
    impl Locate for Ball {
        fn locate(&mut self, _o: DVec3, _d: DVec3) -> Option<Patch> {
            Some(Patch { surface: Surface::Sphere { center: DVec3::ZERO, radius: 1.0, outward: 1.0 }, eta: 1.5 })
        }
    }

    fn weight(s: &Solution) -> f64 {
        let (ci, eta) = (s.refracted.cos_out as f32, s.patch.eta as f32);
        let f = crate::bsdf::fresnel::fresnel(ci, eta).0 as f64;
        // Bounded per point (the caustic's divergence would make the pooled mean heavy-tailed).
        ((1.0 - f) * s.patch.eta * s.patch.eta * s.d_omega_d_omega_l).min(20.0)
    }

    fn uniform_dir(u: &mut impl FnMut() -> f64) -> DVec3 {
        sphere_seed(u(), u())
    }

    #[test]
    fn sms_estimate_finds_every_solution_on_a_ball() {
        let mut rng = crate::sampler::Sampler::new(7, 1);
        let mut u = move || rng.next_1d() as f64;
        let (mut total, mut deterministic, mut several) = (0.0, 0.0, 0);
        let (mut sms_sum, mut sms_sq, mut n_runs) = (0.0, 0.0, 0.0);
        let mut counts = SolveCounts::default();
        let points = 200;
        for _ in 0..points {
            let x_j = loop {
                let p = DVec3::new(2.0 * u() - 1.0, 2.0 * u() - 1.0, 2.0 * u() - 1.0);
                if p.length() < 0.999 {
                    break p;
                }
            };
            let omega_l = uniform_dir(&mut u);
            let mut all: Vec<Solution> = Vec::new();
            for _ in 0..256 {
                let seed = uniform_dir(&mut u);
                if let Ok(s) = solve(&mut Ball, x_j, omega_l, seed) {
                    if !all.iter().any(|a| (a.omega - s.omega).length() < SAME_SOLUTION) {
                        all.push(s);
                    }
                }
            }
            several += (all.len() > 1) as u32;
            let exact: f64 = all.iter().map(weight).sum();
            total += exact;
            let det =
                refracted_seed(&mut Ball, x_j, omega_l).and_then(|seed| solve(&mut Ball, x_j, omega_l, seed).ok());
            deterministic += det.map_or(0.0, |s| weight(&s));
            // Per point: the SMS estimate's error against the exact sum.
            for _ in 0..256 {
                let e = sample_solution(&mut Ball, x_j, omega_l, max_turn(1.5), &mut u, &mut counts)
                    .map_or(0.0, |(s, n)| weight(&s) * n as f64);
                sms_sum += e - exact;
                sms_sq += (e - exact) * (e - exact);
                n_runs += 1.0;
            }
        }
        let mean_err = sms_sum / n_runs;
        let se = ((sms_sq / n_runs - mean_err * mean_err) / n_runs).sqrt();
        let mean_total = total / points as f64;
        eprintln!(
            "ball n = 1.5: {several} of {points} points have > 1 solution; the deterministic seed alone finds {:.1} % of the weight; \
             SMS error {:.4} ± {:.4} (relative {:.3} % ± {:.3} %); {counts:?}",
            100.0 * deterministic / total,
            mean_err,
            se,
            100.0 * mean_err / mean_total,
            100.0 * se / mean_total
        );
        assert!(mean_err.abs() < 4.0 * se + 1e-12, "SMS estimate off by {mean_err} ± {se}");
    }
}

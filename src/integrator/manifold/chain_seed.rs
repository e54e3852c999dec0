//! Seeds of the two-vertex chains (`chain.rs`, docs/manifold.md §9) from the LIGHT side.
//!
//! A chain `x_j → x_1 (reflection) → x_2 (refraction out) → omega_l` is hard to seed from `x_j`:
//! on a mesh with interpolated normals the reflection doubles the variation of the normals, and a
//! direction uniform on the sphere at `x_j` lands in a solution's basin of convergence with a tiny
//! probability. Followed backwards from the light, the path is easy to make: the sun enters at a
//! lit boundary point `x_2` and refracts inwards, deterministically, to `x_1`. Only the last
//! reflection (at `x_1`, towards `x_j`) is unknown. So a light-side seed is
//!
//! 1. a direction `w` uniform on the sphere at `x_j`, whose first boundary hit is the candidate
//!    `x_2` (a boundary point by solid angle from `x_j`);
//! 2. `−omega_l` refracted inwards about the shading normal at `x_2` (when the light is above it),
//!    traced to its first boundary hit `x_1`;
//! 3. the seed `omega = normalize(x_1 − x_j)`; Newton then moves `x_1` (and with it `x_2`) until
//!    the reflection at `x_1` meets `x_j`.
//!
//! Of [`CANDIDATES`] such constructions (independent `w`) the seed keeps the one whose light ray,
//! reflected at `x_1` about the shading normal, misses the direction `x_1 → x_j` by the smallest
//! angle (a deterministic choice among independent draws: still one fixed distribution). When
//! every construction fails (no boundary, the light below the normal, no second hit) the seed is
//! the first `w` itself.
//! Each seed is a uniform direction with probability [`P_UNIFORM`] and a light-side seed
//! otherwise: the mixture is one fixed distribution of `(x_j, omega_l)`, the same for the first
//! seed and every Bernoulli trial, so SMS's count `N` keeps `E[N | s] = 1/p(s)` (Zeltner et al.
//! 2020, §4.3), and the uniform part gives every solution a positive probability (density at least
//! `P_UNIFORM / 4π`).

use super::newton::sphere_seed;
use super::newton::Patch;
use crate::math::DVec3;

/// Where the chain's rays meet the boundary (the caller's ray casts).
pub trait ChainLocate {
    /// First hit from the medium vertex `x_j` along `d`: the patch and the geometric normal there;
    /// `None` unless it is the medium's enclosing smooth boundary, met from inside.
    fn first(&mut self, x_j: DVec3, d: DVec3) -> Option<(Patch, DVec3)>;
    /// First hit from `x_1` (on the boundary, geometric normal `n_1`) along the reflected `d`.
    fn second(&mut self, x_1: DVec3, n_1: DVec3, d: DVec3) -> Option<Patch>;
}

/// Probability of a seed uniform on the sphere in the mixture (the rest: light-side seeds).
pub const P_UNIFORM: f64 = 0.25;
/// Candidate exit points per light-side seed; the seed is the candidate whose reflected light ray
/// passes closest (in angle) to `x_j`.
pub const CANDIDATES: usize = 4;

/// Which seed distribution the chain's SMS uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChainSeeds {
    /// Uniform on the sphere of directions at `x_j` (the first version of §9).
    Uniform,
    /// The mixture of [`P_UNIFORM`] uniform directions and light-side seeds (the default).
    LightSide,
}

/// One seed drawn from `seeds` at `x_j` for a light in the direction `omega_l`.
pub fn draw(
    seeds: ChainSeeds,
    locate: &mut impl ChainLocate,
    x_j: DVec3,
    omega_l: DVec3,
    u: &mut dyn FnMut() -> f64,
) -> DVec3 {
    match seeds {
        ChainSeeds::Uniform => sphere_seed(u(), u()),
        ChainSeeds::LightSide => {
            let uniform = u() < P_UNIFORM;
            let w = sphere_seed(u(), u());
            if uniform {
                return w;
            }
            let mut best: Option<(f64, DVec3)> = None;
            for i in 0..CANDIDATES {
                let w_i = if i == 0 { w } else { sphere_seed(u(), u()) };
                if let Some((seed, miss)) = light_side_seed(locate, x_j, omega_l, w_i) {
                    if best.is_none_or(|(m, _)| miss < m) {
                        best = Some((miss, seed));
                    }
                }
            }
            best.map_or(w, |(_, seed)| seed)
        }
    }
}

/// The light-side seed through the candidate exit point where the ray `(x_j, w)` meets the
/// boundary; `None` when that construction fails.
pub fn light_side_seed(locate: &mut impl ChainLocate, x_j: DVec3, omega_l: DVec3, w: DVec3) -> Option<(DVec3, f64)> {
    let (p2, n_geo) = locate.first(x_j, w)?;
    let (_, x_2, n_s) = p2.hit(x_j, w)?;
    let cos_l = omega_l.dot(n_s);
    if !(cos_l > 0.0) {
        return None;
    }
    // The inner direction that refracts out into omega_l (η_ext sin θ_l = η_int sin θ_in); the light
    // travels inwards along its reverse.
    let tangential = (omega_l - n_s * cos_l) / p2.eta;
    let cos_in = (1.0 - tangential.length_squared()).max(0.0).sqrt();
    let inwards = -(tangential + n_s * cos_in).normalize();
    let p1 = locate.second(x_2, n_geo, inwards)?;
    // Start just past x_2 (selects the far root on a sphere; the line is unchanged).
    let nudge = 1e-7 * (1.0 + x_2.abs().max_element());
    let (_, x_1, n_1) = p1.hit(x_2 + inwards * nudge, inwards)?;
    let omega = (x_1 - x_j).try_normalize()?;
    // How far the light's reflection at x_1 misses x_j (1 − cos of the angle).
    let r = inwards - n_1 * (2.0 * inwards.dot(n_1));
    let miss = 1.0 + r.dot(omega);
    Some((omega, miss))
}

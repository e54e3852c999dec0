//! The rate `q` of the rough-boundary connection (docs/manifold.md §7.2 "Rate"): the probability that
//! the connection (`rough.rs`, `rough_finite.rs`) runs at a medium vertex behind a rough boundary.
//!
//! `q` has two factors, both from scene quantities only: one per medium, decided when the tables
//! are built from its optical size ([`rate`], `snee::rate::optical_size`), and on a curved
//! boundary one per vertex, from the optical depth from `x_j` to `x_0`, the boundary point on the
//! straight line towards the light ([`depth_rate`], decided after the reference's first ray and
//! carried in `Reference::q`). Both are known at every place that evaluates the connection's
//! density: that density is `q · p_man` everywhere
//! (the connection divides its value by it, forward NEE, forward BSDF sampling and SNEE weigh
//! against it), so the weights still sum to 1 and the combination stays unbiased for any
//! `q ∈ (0, 1]`. Where the draw says "skip", the connection consumes its sample numbers and
//! returns nothing.
//!
//! Why: in an optically thin medium most of the variance left is transport the connection does
//! not make (internal reflection, glints: 73 % and 18 % at the statue's `sphere_ggx004_st02`),
//! while each connection costs up to six rays (reference, trace, light segment, SNEE's support);
//! running it at a fraction of the vertices keeps most of what it brings to single scattering and
//! pays a fraction of the rays.

use crate::integrator::snee::rate::optically_thin;
use crate::scene::world::Scene;

/// The rate in an optically thin medium (`snee::rate::optically_thin`: where SNEE, too, stops
/// running under `connection = complete`, `snee::rate::complete_rates`).
pub const THIN_RATE: f64 = 0.25;

/// The rate `q` of the connection through `medium`'s rough boundary: 1 where the medium is
/// optically thick, [`THIN_RATE`] where it is thin (`snee::rate::optically_thin`).
pub fn rate(scene: &Scene, medium: u32) -> f64 {
    if optically_thin(scene, medium) {
        THIN_RATE
    } else {
        1.0
    }
}

/// The rate of the connection from a vertex in `medium` (1 where no rough boundary is built:
/// then the densities that use it are 0 anyway).
#[inline]
pub fn rate_of(scene: &Scene, medium: u32) -> f64 {
    super::tables(scene).and_then(|t| t.rough.get(medium as usize)?.as_ref()).map_or(1.0, |rb| rb.q)
}

/// The whole rate `q` of the connection from a vertex in `medium` whose reference carries the depth
/// factor `depth` (`Reference::q`): the medium's rate ([`rate_of`]) times it. The factor of `p_man`
/// at every place that evaluates the connection's density.
#[inline]
pub fn of_vertex(scene: &Scene, medium: u32, depth: f64) -> f64 {
    rate_of(scene, medium) * depth
}

/// Optical depth from `x_j` to `x_0` (the boundary along the straight line towards the light)
/// within which the connection always runs.
pub const DEPTH_TAU: f64 = 3.0;
/// Floor of [`depth_rate`].
pub const DEPTH_MIN_RATE: f64 = 0.02;

/// The depth factor of the rate at a vertex `x_j` of `medium` whose straight line towards the
/// light meets the boundary at `x_0` after the distance `d_0` (curved boundaries;
/// docs/manifold.md §7.2 "Rate"): with `tau = sigma_t,min · d_0`, 1 for `tau <= DEPTH_TAU`, else
/// `exp(DEPTH_TAU − tau)`, at least [`DEPTH_MIN_RATE`]. The connection's value carries
/// `exp(−sigma_t d_jk)` and `x_k` lands near `x_0`, so its expected contribution falls about as
/// the rate; `f / p_man` then stays about `exp(−DEPTH_TAU)` times the value of a vertex at the
/// surface. A function of `(x_j, light)` known at every place that evaluates the density
/// (they all trace `x_0`).
pub fn depth_rate(scene: &Scene, medium: u32, d_0: f32) -> f64 {
    let tau = scene.media[medium as usize].sigma_t.min_element() as f64 * d_0 as f64;
    if !(tau > DEPTH_TAU) {
        return 1.0;
    }
    (DEPTH_TAU - tau).exp().max(DEPTH_MIN_RATE)
}

/// A lower bound of the unpolarized Fresnel reflectance (`bsdf::fresnel::fresnel`) of a dielectric
/// interface of relative index `eta` at every angle, from either side: its normal-incidence value
/// `((eta − 1)/(eta + 1))²` (the minimum over angles; in f32 within 3.4e-6 of it relatively for
/// `eta` from 1.05 to 2.4), less 0.1 %. Where the connection's `u1` (rescaled by the rate) lies
/// below it, the rough dielectric's `sample` picks the reflection (`u1 <= F`) whatever the
/// microfacet normal, so the sample fails in any reference frame: the connection stops before the
/// reference's refinement rays with the result it would have had after them (none).
pub fn reflect_below(eta: f32) -> f64 {
    let e = eta as f64;
    let f0 = ((e - 1.0) / (e + 1.0)).powi(2);
    if f0.is_finite() {
        f0 * (1.0 - 1e-3)
    } else {
        0.0
    }
}

/// Does the connection's `u1` at a vertex of `medium` whose rate is `q` (depth factor included)
/// sample a reflection whatever the reference ([`reflect_below`])?
#[inline]
pub fn reflects(scene: &Scene, medium: u32, u1: f32, q: f64) -> bool {
    let boundary = super::tables(scene).and_then(|t| t.rough.get(medium as usize)?.as_ref());
    let below = boundary.map_or(0.0, |rb| rb.reflect_below);
    (rescale(u1, q) as f64) < below
}

/// `u / q` for a uniform `u < q` (uniform on [0, 1) again), kept below 1.
#[inline]
pub fn rescale(u: f32, q: f64) -> f32 {
    if q >= 1.0 {
        return u;
    }
    ((u as f64 / q) as f32).min(1.0 - f32::EPSILON)
}

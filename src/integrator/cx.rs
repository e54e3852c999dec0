//! What every estimator call gets from the path loop (`volpath.rs`): the context [`Cx`] (scene, hero
//! channel, current medium, sample stream, statistics, and the connection stages that weigh forward
//! contributions), and the records the loop hands to its techniques ([`Scatter`] at a medium vertex,
//! [`EmitterHit`] when the ray finds an emitter). The stages appear here only as a trait
//! ([`ForwardWeight`]), so the techniques can take a `Cx` without importing the loop.

use super::stats::LocalStats;
use crate::color::Spectrum;
use crate::interaction::DirectionSample;
use crate::math::Vec3;
use crate::sampler::Sampler;
use crate::scene::world::Scene;

/// An emitter the path's ray (along `ray_d`) hit: its radiance, the direction sample from the
/// last scattering vertex `from` (for MIS densities), the point SNEE's light record uses, and
/// whether it counts at full weight (`count_direct`: seen directly or after a specular chain).
#[derive(Clone, Copy, Debug)]
pub struct EmitterHit {
    pub le: Spectrum,
    pub ds: DirectionSample,
    pub from: Vec3,
    pub light_p: Vec3,
    pub ray_d: Vec3,
    pub count_direct: bool,
}

/// A real scatter of the path as the stages at medium vertices see it (SNEE's and the manifold
/// connection's `at_scatter`).
#[derive(Clone, Copy, Debug)]
pub struct Scatter {
    pub medium: u32,
    pub p: Vec3,
    /// Direction back to the previous vertex (the phase function's `wi`).
    pub wi: Vec3,
    pub depth: u32,
    pub max_depth: u32,
    /// The throughput at `p`, including `sigma_s`.
    pub beta: Spectrum,
}

/// The MIS weight that connection techniques (SNEE, manifold NEE) give a contribution that forward
/// tracing made: an emitter hit after BSDF or phase sampling, or emitter sampling at a surface.
/// `w` is forward tracing's own weight (BSDF vs emitter sampling); the result replaces it.
pub trait ForwardWeight {
    /// `p_light`: the emitter-sampling density of the hit's direction, computed on demand.
    fn emitter_hit_weight(&self, cx: &mut Cx, hit: &EmitterHit, p_light: &dyn Fn() -> f32, w: f32) -> f32;
    fn emitter_sampling_weight(&self, cx: &mut Cx, ds: &DirectionSample, w: f32) -> f32;
}

/// The connection stages of `volpath_snee` that weigh forward contributions (none elsewhere).
#[derive(Clone, Copy, Default)]
pub struct Stages<'s> {
    pub forward: Option<&'s dyn ForwardWeight>,
}

/// What an estimator's call needs besides its own arguments: the scene, the hero channel, the
/// medium the path is in, the path's sample stream, the statistics, and the connection stages
/// that weigh forward contributions at surfaces.
pub struct Cx<'a, 's> {
    pub scene: &'a Scene,
    pub channel: usize,
    pub medium: Option<u32>,
    pub sampler: &'a mut Sampler,
    pub stats: &'a mut LocalStats,
    pub stages: Stages<'s>,
}

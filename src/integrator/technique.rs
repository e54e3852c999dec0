//! Connection techniques beside emitter and BSDF / phase sampling: the interface through which the
//! volpath loop uses them, and where the next one plugs in.
//!
//! The loop owns the path (throughput, depth, Russian roulette, the walk through media and
//! passable surfaces, `walk.rs`). A technique that closes a path at a medium vertex answers two
//! questions ([`Technique`]):
//! - `sample`: make one connection at the vertex `x_i` and return its MIS-weighted contribution;
//! - `pdf`: the density with which it would have made a suffix `x_i → x_j → x_k → emitter` that
//!   another technique made (0 outside its support), in the common measure of docs/snee.md §1.
//!
//! MIS is one function over all techniques' densities of the same suffix:
//! `snee::mis::suffix_weights` over `snee::pdf::SuffixPdfs` (power heuristic; forward NEE and forward BSDF
//! sampling at `x_k` report their densities through `snee::pdf::suffix_pdfs`). A technique's
//! per-path bookkeeping (which vertices are `x_i`, `x_j`, `x_k` of the current path) lives in its
//! own stage type, called once per loop event (`snee::stage`), never in the loop's variables.
//!
//! Adding a technique: implement [`Technique`] for its built tables, add its density as a field of
//! `SuffixPdfs` and its weight to `suffix_weights`, and call its `sample` from the stage at a
//! scatter. Manifold NEE through flat boundaries (`manifold/`, `connection = complete`) is a stage
//! of its own next to SNEE's (`manifold::ManifoldStage`, tables in `Snee::flat`): it connects from
//! `x_j` rather than `x_i`, so its densities live in another measure and its MIS weights are its
//! own (`manifold/pdf.rs`, `manifold/mis.rs`), with one call in `snee/sample.rs` for SNEE's side.
//! Through a flat rough boundary (`manifold/rough.rs`) it shares suffixes with forward NEE at a rough
//! `x_k` too: the loop asks the manifold stage first for that weight (`ManifoldStage::nee_weight`).

use super::snee::{self, LightSample, Snee, SneeSuffix, SneeVertex};
use super::stats::LocalStats;
use crate::color::Spectrum;
use crate::sampler::Sampler;
use crate::scene::world::Scene;

/// A connection technique at a medium vertex (static dispatch; the set is closed).
pub trait Technique {
    /// One connection at `x_i`: its MIS-weighted contribution (with `beta`, the throughput at
    /// `x_i` including `sigma_s`), zero when the sample fails.
    #[allow(clippy::too_many_arguments)]
    fn sample(
        &self,
        scene: &Scene,
        x_i: &SneeVertex,
        beta: Spectrum,
        channel: usize,
        sampler: &mut Sampler,
        stats: &mut LocalStats,
    ) -> Spectrum;

    /// The density with which this technique makes the suffix `s` ending at `light` (including the
    /// probability that it runs at `x_i`); 0 outside its support. Visibility is the caller's.
    fn pdf(&self, scene: &Scene, s: &SneeSuffix, light: &LightSample, channel: usize) -> f64;
}

/// SNEE (`snee/`): `sample` is `snee::sample`, `pdf` is `snee::pdf_snee`.
impl Technique for Snee {
    #[inline]
    fn sample(
        &self,
        scene: &Scene,
        x_i: &SneeVertex,
        beta: Spectrum,
        channel: usize,
        sampler: &mut Sampler,
        stats: &mut LocalStats,
    ) -> Spectrum {
        snee::sample(scene, x_i, beta, channel, self, sampler, stats)
    }

    #[inline]
    fn pdf(&self, scene: &Scene, s: &SneeSuffix, light: &LightSample, channel: usize) -> f64 {
        snee::pdf_snee(scene, self, s, light, channel)
    }
}

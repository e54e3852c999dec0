//! Per-render counters, summed over threads: rays traced, rejected (non-finite) samples, and
//! SNEE attempts and probe failures, manifold connections, solutions and failures. Each counter
//! is named once, in [`counters!`]'s list below; the thread-local struct, the shared atomics, the
//! flush, the snapshot and the names in the render statistics' JSON all come from it.

use std::sync::atomic::{AtomicU64, Ordering};

/// Declares the counters once: [`LocalStats`] (thread-local `u64`s, with their docs), [`Stats`]
/// (the shared `AtomicU64`s), [`Stats::add`], [`Stats::snapshot`] and [`LocalStats::named`].
macro_rules! counters {
    ($($(#[$doc:meta])* $name:ident,)*) => {
        /// Thread-local counters, flushed into [`Stats`] once per tile.
        #[derive(Default, Clone, Copy, Debug)]
        pub struct LocalStats {
            $($(#[$doc])* pub $name: u64,)*
        }

        /// The counters of a whole render, summed over threads.
        #[derive(Default, Debug)]
        pub struct Stats {
            $(pub $name: AtomicU64,)*
        }

        impl Stats {
            pub fn add(&self, l: &LocalStats) {
                $(self.$name.fetch_add(l.$name, Ordering::Relaxed);)*
            }
            /// The sums so far.
            pub fn snapshot(&self) -> LocalStats {
                LocalStats { $($name: self.$name.load(Ordering::Relaxed),)* }
            }
        }

        impl LocalStats {
            /// Every counter with its name (the keys of the render statistics' JSON).
            pub fn named(&self) -> Vec<(&'static str, u64)> {
                vec![$((stringify!($name), self.$name),)*]
            }
        }
    };
}

counters! {
    rays,
    rejected_samples,
    /// SNEE stages run (volpath_snee).
    snee_attempts,
    /// SNEE probes that did not reach the enclosing dielectric boundary.
    snee_probe_failures,
    /// Manifold connections run (one emitter sample at a medium vertex, `connection = complete`).
    manifold_attempts,
    /// Refraction solutions found and verified (boundary point on its plane, light segment clear).
    manifold_solutions,
    /// Candidate planes facing the light whose solution failed verification (another surface
    /// first, or the light segment blocked).
    manifold_failures,
    /// Newton solves on curved boundaries (`manifold/curved.rs`), one per seed.
    manifold_newton_solves,
    /// Newton iterations summed over the solves.
    manifold_newton_iterations,
    /// Solves that did not converge (iteration limit, no descent, singular Jacobian).
    manifold_newton_failures,
    /// Solves whose walk left the enclosing boundary (another surface first, total internal
    /// reflection, or the boundary met from outside).
    manifold_newton_lost,
    /// Specular manifold sampling's Bernoulli trials stopped at the cap (`newton::MAX_TRIALS`).
    manifold_trials_capped,
    /// Two-vertex chains run (`manifold/chain.rs`, one emitter sample at a medium vertex).
    chain_attempts,
    /// Newton solves of the chain, one per seed.
    chain_solves,
    /// Newton iterations of the chain summed over its solves.
    chain_iterations,
    /// Chains found and verified (both boundary points, the light segment).
    chain_solutions,
    /// The chain's Bernoulli trials stopped at the cap (`newton::MAX_TRIALS`, as for the one-refraction connection).
    chain_trials_capped,
    /// Re-solves from a path's own seed to evaluate the curved finite-light connection's density
    /// for a suffix forward tracing or SNEE made (`curved_finite.rs`), and those that found it.
    manifold_resolves,
    manifold_resolve_matches,
    /// Glint solves from the camera (`manifold/glint.rs`, one per seed), their Newton iterations,
    /// the glints found and verified, and the Bernoulli trials stopped at `glint::MAX_TRIALS`.
    glint_solves,
    glint_iterations,
    glint_solutions,
    glint_trials_capped,
    /// Emitter splitting at smooth dielectric vertices (`manifold/split.rs`): lobes that BSDF
    /// sampling did not pick and that were split (the emitter's bounds tested), and of them the
    /// rays cast (also counted in `rays`).
    split_lobes,
    split_rays,
    /// Beams (`manifold/beam.rs`): light subpaths traced from a directional light (one per camera
    /// sample that reached a medium vertex where beams apply), beams recorded (reflected
    /// segments), connections of a beam to a camera medium vertex, and of them those whose
    /// segment `x_a → x_b` was blocked.
    beam_subpaths,
    beams,
    beam_connections,
    beam_blocked,
    /// Camera beams (`manifold/camera_beam.rs`): points on beams connected to the camera, Newton
    /// solves (one per point), the solves that did not converge, their iterations, and the
    /// verified connections splatted.
    camera_beam_points,
    camera_beam_solves,
    camera_beam_unsolved,
    camera_beam_iterations,
    camera_beam_splats,
}

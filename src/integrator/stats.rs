//! Per-render counters, summed over threads: rays traced, rejected (non-finite) samples, and
//! SNEE attempts and probe failures, manifold connections, solutions and failures.

use std::sync::atomic::{AtomicU64, Ordering};

#[derive(Default, Debug)]
pub struct Stats {
    pub rays: AtomicU64,
    pub rejected_samples: AtomicU64,
    pub snee_attempts: AtomicU64,
    pub snee_probe_failures: AtomicU64,
    pub manifold_attempts: AtomicU64,
    pub manifold_solutions: AtomicU64,
    pub manifold_failures: AtomicU64,
    pub manifold_newton_solves: AtomicU64,
    pub manifold_newton_iterations: AtomicU64,
    pub manifold_newton_failures: AtomicU64,
    pub manifold_newton_lost: AtomicU64,
    pub manifold_trials_capped: AtomicU64,
    pub chain_attempts: AtomicU64,
    pub chain_solves: AtomicU64,
    pub chain_iterations: AtomicU64,
    pub chain_solutions: AtomicU64,
    pub chain_trials_capped: AtomicU64,
    pub manifold_resolves: AtomicU64,
    pub manifold_resolve_matches: AtomicU64,
}

/// Thread-local counters, flushed into [`Stats`] once per tile.
#[derive(Default, Clone, Copy, Debug)]
pub struct LocalStats {
    pub rays: u64,
    pub rejected_samples: u64,
    /// SNEE stages run (volpath_snee).
    pub snee_attempts: u64,
    /// SNEE probes that did not reach the enclosing dielectric boundary.
    pub snee_probe_failures: u64,
    /// Manifold connections run (one emitter sample at a medium vertex, `connection = complete`).
    pub manifold_attempts: u64,
    /// Refraction solutions found and verified (boundary point on its plane, light segment clear).
    pub manifold_solutions: u64,
    /// Candidate planes facing the light whose solution failed verification (another surface
    /// first, or the light segment blocked).
    pub manifold_failures: u64,
    /// Newton solves on curved boundaries (`manifold/curved.rs`), one per seed.
    pub manifold_newton_solves: u64,
    /// Newton iterations summed over the solves.
    pub manifold_newton_iterations: u64,
    /// Solves that did not converge (iteration limit, no descent, singular Jacobian).
    pub manifold_newton_failures: u64,
    /// Solves whose walk left the enclosing boundary (another surface first, total internal
    /// reflection, or the boundary met from outside).
    pub manifold_newton_lost: u64,
    /// Specular manifold sampling's Bernoulli trials stopped at the cap (`newton::MAX_TRIALS`).
    pub manifold_trials_capped: u64,
    /// Two-vertex chains run (`manifold/chain.rs`, one emitter sample at a medium vertex).
    pub chain_attempts: u64,
    /// Newton solves of the chain, one per seed.
    pub chain_solves: u64,
    /// Newton iterations of the chain summed over its solves.
    pub chain_iterations: u64,
    /// Chains found and verified (both boundary points, the light segment).
    pub chain_solutions: u64,
    /// The chain's Bernoulli trials stopped at the cap (`newton::MAX_TRIALS`, as for the one-refraction connection).
    pub chain_trials_capped: u64,
    /// Re-solves from a path's own seed to evaluate the curved finite-light connection's density
    /// for a suffix forward tracing or SNEE made (`curved_finite.rs`), and those that found it.
    pub manifold_resolves: u64,
    pub manifold_resolve_matches: u64,
}

impl Stats {
    pub fn add(&self, l: &LocalStats) {
        self.rays.fetch_add(l.rays, Ordering::Relaxed);
        self.rejected_samples.fetch_add(l.rejected_samples, Ordering::Relaxed);
        self.snee_attempts.fetch_add(l.snee_attempts, Ordering::Relaxed);
        self.snee_probe_failures.fetch_add(l.snee_probe_failures, Ordering::Relaxed);
        self.manifold_attempts.fetch_add(l.manifold_attempts, Ordering::Relaxed);
        self.manifold_solutions.fetch_add(l.manifold_solutions, Ordering::Relaxed);
        self.manifold_failures.fetch_add(l.manifold_failures, Ordering::Relaxed);
        self.manifold_newton_solves.fetch_add(l.manifold_newton_solves, Ordering::Relaxed);
        self.manifold_newton_iterations.fetch_add(l.manifold_newton_iterations, Ordering::Relaxed);
        self.manifold_newton_failures.fetch_add(l.manifold_newton_failures, Ordering::Relaxed);
        self.manifold_newton_lost.fetch_add(l.manifold_newton_lost, Ordering::Relaxed);
        self.manifold_trials_capped.fetch_add(l.manifold_trials_capped, Ordering::Relaxed);
        self.chain_attempts.fetch_add(l.chain_attempts, Ordering::Relaxed);
        self.chain_solves.fetch_add(l.chain_solves, Ordering::Relaxed);
        self.chain_iterations.fetch_add(l.chain_iterations, Ordering::Relaxed);
        self.chain_solutions.fetch_add(l.chain_solutions, Ordering::Relaxed);
        self.chain_trials_capped.fetch_add(l.chain_trials_capped, Ordering::Relaxed);
        self.manifold_resolves.fetch_add(l.manifold_resolves, Ordering::Relaxed);
        self.manifold_resolve_matches.fetch_add(l.manifold_resolve_matches, Ordering::Relaxed);
    }
}

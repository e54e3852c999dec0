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
    }
}

//! Per-render counters, summed over threads: rays traced, rejected (non-finite) samples, and
//! SNEE attempts and probe failures.

use std::sync::atomic::{AtomicU64, Ordering};

#[derive(Default, Debug)]
pub struct Stats {
    pub rays: AtomicU64,
    pub rejected_samples: AtomicU64,
    pub snee_attempts: AtomicU64,
    pub snee_probe_failures: AtomicU64,
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
}

impl Stats {
    pub fn add(&self, l: &LocalStats) {
        self.rays.fetch_add(l.rays, Ordering::Relaxed);
        self.rejected_samples.fetch_add(l.rejected_samples, Ordering::Relaxed);
        self.snee_attempts.fetch_add(l.snee_attempts, Ordering::Relaxed);
        self.snee_probe_failures.fetch_add(l.snee_probe_failures, Ordering::Relaxed);
    }
}

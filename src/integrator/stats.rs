//! Per-render counters, summed over threads: rays traced and rejected (non-finite) samples.

use std::sync::atomic::{AtomicU64, Ordering};

#[derive(Default, Debug)]
pub struct Stats {
    pub rays: AtomicU64,
    pub rejected_samples: AtomicU64,
}

/// Thread-local counters, flushed into [`Stats`] once per tile.
#[derive(Default, Clone, Copy, Debug)]
pub struct LocalStats {
    pub rays: u64,
    pub rejected_samples: u64,
}

impl Stats {
    pub fn add(&self, l: &LocalStats) {
        self.rays.fetch_add(l.rays, Ordering::Relaxed);
        self.rejected_samples.fetch_add(l.rejected_samples, Ordering::Relaxed);
    }
}

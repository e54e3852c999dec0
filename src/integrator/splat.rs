//! Light-tracing splats: contributions that a camera sample's light subpath makes to OTHER pixels
//! (`manifold/camera_beam.rs`), collected per render job and added to the image by the render loop.
//!
//! A render job (one tile of one pass, `render.rs`) opens a collector on its thread, renders its
//! samples, and takes the splats back in the order they were made; the loop adds them to the
//! image in tile order, so the image does not depend on the thread count. A job never hands work
//! to another thread, so the thread-local collector sees exactly that job's samples. Outside a
//! render job (direct calls of `Integrator::li` in tests and tools) no collector is open and
//! splats are dropped.
//!
//! A splat is `(film position, value)`: the value is the light-tracing estimate of ONE light
//! subpath (one per camera sample), and the render loop scales it by `1 / pixels` (docs/beams.md,
//! "Camera beams": with `M = pixels · spp` light subpaths, a pixel's estimate is `Σ C / M`, which
//! is `Σ C / pixels` in the pixel's weighted sum over its `spp` box-filtered samples).

use crate::color::Spectrum;
use glam::DVec2;
use std::cell::RefCell;

/// One light-tracing contribution: film position (pixels of the full film) and its value.
#[derive(Clone, Copy, Debug)]
pub struct Splat {
    pub pos: DVec2,
    pub value: Spectrum,
}

thread_local! {
    static COLLECTOR: RefCell<Option<Vec<Splat>>> = const { RefCell::new(None) };
}

/// Open this thread's collector (empty).
pub fn open() {
    COLLECTOR.with(|c| *c.borrow_mut() = Some(Vec::new()));
}

/// Close this thread's collector and return its splats in the order they were made.
pub fn take() -> Vec<Splat> {
    COLLECTOR.with(|c| c.borrow_mut().take()).unwrap_or_default()
}

/// How many splats this thread's collector holds (0 when none is open).
pub fn len() -> usize {
    COLLECTOR.with(|c| c.borrow().as_ref().map_or(0, Vec::len))
}

/// Drop this thread's splats after the first `n`: those of samples that were only replayed (to
/// bring a pixel's stream to the start of a sample range), which belong to another range.
pub fn truncate(n: usize) {
    COLLECTOR.with(|c| {
        if let Some(v) = c.borrow_mut().as_mut() {
            v.truncate(n);
        }
    });
}

/// Add a splat to this thread's collector (dropped when none is open).
pub fn push(s: Splat) {
    COLLECTOR.with(|c| {
        if let Some(v) = c.borrow_mut().as_mut() {
            v.push(s);
        }
    });
}

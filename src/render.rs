//! The render loop: rayon over 16×16 tiles in passes of samples per pixel, filtered accumulation
//! into the film, a progress bar, a time budget, Ctrl-C, and render statistics.
//!
//! Determinism: every (pixel, pass) has its own sampler stream derived from the seed, so an image
//! depends only on the seed and the sample count, never on the thread count or tile order.

use crate::color::Spectrum;
use crate::integrator::stats::{LocalStats, Stats};
use crate::integrator::{path, snee, volpath, volpathmis, IntegratorKind};
use crate::math::Vec2;
use crate::sampler::Sampler;
use crate::scene::world::Scene;
use crate::sensor::film::PixelFormat;
use crate::sensor::image_block::ImageBlock;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

const TILE: u32 = 16;

#[derive(Clone, Debug, Default)]
pub struct RenderOptions {
    /// Samples per pixel; `None` = the scene's sampler `sample_count` (unbounded with a time budget).
    pub spp: Option<u32>,
    pub seed: u64,
    /// Stop after this many seconds (the image of the samples done is returned).
    pub time_budget: Option<f64>,
    pub progress: bool,
}

/// A rendered image with its channels and the render statistics.
#[derive(Clone, Debug)]
pub struct RenderOutput {
    pub width: usize,
    pub height: usize,
    pub channels: Vec<String>,
    /// Interleaved channels, row 0 = top.
    pub data: Vec<f32>,
    pub stats: RenderStats,
}

#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    pub seconds: f64,
    /// Samples per pixel completed (all pixels).
    pub spp: u32,
    pub samples: u64,
    pub rays: u64,
    pub rejected_samples: u64,
    pub snee_attempts: u64,
    pub snee_probe_failures: u64,
    /// Which `volpath_snee` estimator ran (`paper`, `complete`; empty for other integrators).
    pub connection: &'static str,
    pub manifold_attempts: u64,
    pub manifold_solutions: u64,
    pub manifold_failures: u64,
}

impl RenderStats {
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "seconds": self.seconds,
            "spp": self.spp,
            "samples": self.samples,
            "samples_per_second": self.samples as f64 / self.seconds.max(1e-9),
            "rays": self.rays,
            "rays_per_second": self.rays as f64 / self.seconds.max(1e-9),
            "rejected_samples": self.rejected_samples,
            "snee_attempts": self.snee_attempts,
            "snee_probe_failures": self.snee_probe_failures,
            "connection": self.connection,
            "manifold_attempts": self.manifold_attempts,
            "manifold_solutions": self.manifold_solutions,
            "manifold_failures": self.manifold_failures,
        })
    }
}

/// Radiance for one camera ray, dispatching on the integrator.
#[inline]
fn sample_li(scene: &Scene, sampler: &mut Sampler, ray: crate::math::Ray, stats: &mut LocalStats) -> (Spectrum, bool) {
    match scene.integrator.kind {
        IntegratorKind::Path => path::li(scene, sampler, ray, stats),
        IntegratorKind::Volpath => volpath::li(scene, sampler, ray, scene.sensor_medium, stats),
        IntegratorKind::Volpathmis => volpathmis::li(scene, sampler, ray, scene.sensor_medium, stats),
        IntegratorKind::VolpathSnee => snee::li(scene, sampler, ray, scene.sensor_medium, stats),
    }
}

/// Render the scene. `cancel` stops early (Ctrl-C); the samples done so far are kept.
pub fn render(scene: &Scene, opts: &RenderOptions, cancel: &AtomicBool) -> RenderOutput {
    render_with(scene, opts, cancel, None)
}

/// Called after every pass that ends on a power-of-two sample count, with the render time so far
/// (seconds, not counting the callback), the samples per pixel done, and the developed image
/// (channels interleaved as in [`RenderOutput`]).
pub type PassCallback<'a> = &'a mut dyn FnMut(f64, u32, &[f32]);

/// [`render`] with a callback at doubling sample counts (for convergence curves).
pub fn render_with(
    scene: &Scene,
    opts: &RenderOptions,
    cancel: &AtomicBool,
    mut on_pass: Option<PassCallback>,
) -> RenderOutput {
    let film = &scene.film;
    let (cw, ch) = film.crop_size;
    // Samples are taken in the sample window (the crop window, plus the filter border with `sample_border`).
    let ((sx, sy), (sw, sh)) = film.sample_window();
    let rgba = matches!(film.pixel_format, PixelFormat::Rgba);
    let moment = scene.integrator.moment;
    // Channels: RGB, [A], [second moment of RGB].
    let mut channels: Vec<String> = vec!["R".into(), "G".into(), "B".into()];
    if rgba {
        channels.push("A".into());
    }
    if moment {
        for c in ["R", "G", "B"] {
            channels.push(format!("m2.{}", c));
        }
    }
    let nch = channels.len();
    let ray_weight = scene.camera.ray_weight();
    let total_spp = match (opts.spp, opts.time_budget) {
        (Some(s), _) => s,
        (None, Some(_)) => u32::MAX,
        (None, None) => scene.sampler.sample_count,
    };

    let mut tiles = Vec::new();
    for ty in (0..sh).step_by(TILE as usize) {
        for tx in (0..sw).step_by(TILE as usize) {
            tiles.push((sx + tx as i32, sy + ty as i32, TILE.min(sw - tx), TILE.min(sh - ty)));
        }
    }
    let mut full = film.create_block(nch);
    let stats = Stats::default();
    let start = Instant::now();
    let pixels = sw as u64 * sh as u64;
    let bar = if opts.progress {
        let len = if total_spp == u32::MAX { 0 } else { total_spp as u64 * pixels };
        let b = indicatif::ProgressBar::new(len);
        b.set_style(
            indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent}% ({eta} left) {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };

    let mut spp_done = 0u32;
    let mut pass = 0u64;
    let mut samples_done = 0u64;
    // Time spent in `on_pass`, excluded from the reported render time.
    let mut callback_seconds = 0.0f64;
    while spp_done < total_spp && !cancel.load(Ordering::Relaxed) {
        // Pass sizes 1, 1, 2, 4, ... 64 spp, so that passes end on every power of two; with a time budget, a pass is cut to what
        // the measured rate says fits in the remaining time, and none starts that would end
        // more than half a sample per pixel past the budget.
        let mut pass_spp = (1u32 << pass.saturating_sub(1).min(6)).min(total_spp - spp_done);
        if let Some(t) = opts.time_budget {
            let elapsed = start.elapsed().as_secs_f64();
            if spp_done > 0 {
                let per_spp = elapsed / spp_done as f64;
                let remaining = t - elapsed;
                if remaining < 0.5 * per_spp {
                    break;
                }
                let fits = (remaining / per_spp).round().max(1.0);
                pass_spp = pass_spp.min(fits.min(u32::MAX as f64) as u32);
            }
        }
        let first_sample = spp_done;
        let completed = std::sync::atomic::AtomicU64::new(0);
        // Tiles render in parallel; their blocks merge in tile order so the floating-point sums (and
        // so the image) do not depend on the thread count.
        let blocks: Vec<Option<ImageBlock>> = tiles
            .par_iter()
            .map(|&(x0, y0, w, h)| {
                if cancel.load(Ordering::Relaxed) {
                    return None;
                }
                let mut block = ImageBlock::new((x0, y0), (w, h), film.filter, nch);
                let mut local = LocalStats::default();
                let mut values = vec![0.0f32; nch];
                for y in y0..y0 + h as i32 {
                    for x in x0..x0 + w as i32 {
                        // Unique per film pixel (the border may lie outside the film: offset it).
                        let pixel_index = (y + 64) as u64 * (film.width as u64 + 128) + (x + 64) as u64;
                        let mut sampler = Sampler::new(
                            opts.seed,
                            pixel_index.wrapping_mul(0x1_0000_0000).wrapping_add(first_sample as u64),
                        );
                        for _ in 0..pass_spp {
                            let pos = Vec2::new(x as f32, y as f32) + sampler.next_2d();
                            let aperture = sampler.next_2d();
                            let ray = scene.camera.sample_ray(pos, aperture);
                            let (mut l, valid) = sample_li(scene, &mut sampler, ray, &mut local);
                            l *= ray_weight;
                            if !l.is_finite() {
                                local.rejected_samples += 1;
                                l = Spectrum::ZERO;
                            }
                            values[..3].copy_from_slice(&l.to_array());
                            let mut k = 3;
                            if rgba {
                                values[3] = if valid { 1.0 } else { 0.0 };
                                k = 4;
                            }
                            if moment {
                                values[k..k + 3].copy_from_slice(&(l * l).to_array());
                            }
                            block.put(pos, &values);
                        }
                    }
                }
                stats.add(&local);
                let n = w as u64 * h as u64 * pass_spp as u64;
                completed.fetch_add(n, Ordering::Relaxed);
                bar.inc(n);
                Some(block)
            })
            .collect();
        for block in blocks.iter().flatten() {
            full.merge(block);
        }
        samples_done += completed.load(Ordering::Relaxed);
        if cancel.load(Ordering::Relaxed) {
            break;
        }
        spp_done += pass_spp;
        pass += 1;
        if let Some(cb) = on_pass.as_mut() {
            if spp_done.is_power_of_two() {
                let t = start.elapsed().as_secs_f64() - callback_seconds;
                let t0 = Instant::now();
                cb(t, spp_done, &full.develop());
                callback_seconds += t0.elapsed().as_secs_f64();
            }
        }
        if total_spp == u32::MAX {
            bar.set_message(format!("{} spp", spp_done));
        }
    }
    bar.finish_and_clear();
    let seconds = start.elapsed().as_secs_f64() - callback_seconds;
    let data = full.develop();
    RenderOutput {
        width: cw as usize,
        height: ch as usize,
        channels,
        data,
        stats: RenderStats {
            seconds,
            spp: spp_done,
            samples: samples_done,
            rays: stats.rays.load(Ordering::Relaxed),
            rejected_samples: stats.rejected_samples.load(Ordering::Relaxed),
            snee_attempts: stats.snee_attempts.load(Ordering::Relaxed),
            snee_probe_failures: stats.snee_probe_failures.load(Ordering::Relaxed),
            connection: if scene.integrator.kind == IntegratorKind::VolpathSnee {
                scene.integrator.connection.name()
            } else {
                ""
            },
            manifold_attempts: stats.manifold_attempts.load(Ordering::Relaxed),
            manifold_solutions: stats.manifold_solutions.load(Ordering::Relaxed),
            manifold_failures: stats.manifold_failures.load(Ordering::Relaxed),
        },
    }
}

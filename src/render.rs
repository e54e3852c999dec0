//! The render loop: rayon over 16×16 tiles in passes of samples per pixel, filtered accumulation
//! into the film, a progress bar, a time budget, Ctrl-C, and render statistics.
//!
//! Determinism: the samples of a pixel are cut into fixed chunks — `[0,1) [1,2) [2,4) [4,8) …
//! [32,64)`, then every 64 samples — and each (pixel, chunk) has its own sampler stream derived
//! from the seed and the chunk's first sample index ([`chunk_start`]). The random numbers of
//! sample `i` of a pixel therefore depend only on the pixel, `i` and the seed: never on the
//! thread count, the tile order, the time budget, or which process renders it. A render of the
//! sample range `START..END` ([`render_range`]) takes exactly the samples `START..END` of the
//! full run (a range that starts inside a chunk replays the chunk's earlier samples without
//! recording them, so ranges on chunk boundaries cost nothing extra), and ranges merge into the
//! full image up to float summation order (`merge`).
//!
//! Each (tile, pass) is one parallel job with a block of its own; blocks merge into the image
//! pass by pass in tile order. Without a pass callback or a time budget, consecutive passes run in
//! one parallel loop (no barrier between passes), with the same merge order, so the same image.

use crate::color::Spectrum;
use crate::integrator::classes::{ClassValues, PathClass, N_CLASSES};
use crate::integrator::path_wide::{self, Pixel};
use crate::integrator::stats::{LocalStats, Stats};
use crate::integrator::IntegratorKind;
use crate::math::Vec2;
use crate::sampler::Sampler;
use crate::scene::world::Scene;
use crate::sensor::film::PixelFormat;
use crate::sensor::image_block::ImageBlock;
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

const TILE: u32 = 16;
/// Most bytes of tile blocks held at once when several passes render together (`render_range`):
/// small and medium films fuse all their passes, large ones (over 32 MB of blocks per pass) render
/// pass by pass, one parallel loop each.
const FUSED_BLOCK_BYTES: usize = 64 << 20;

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
    /// Accumulated reconstruction-filter weight per pixel (row 0 = top): the developed value
    /// times this weight is the pixel's sum of weighted samples, which is what merging adds up.
    pub weights: Vec<f32>,
    /// Index of the first sample per pixel in this image: it holds samples
    /// `first_sample..first_sample + stats.spp` of every pixel.
    pub first_sample: u32,
    pub stats: RenderStats,
}

#[derive(Clone, Debug, Default)]
pub struct RenderStats {
    pub seconds: f64,
    /// Samples per pixel completed (all pixels).
    pub spp: u32,
    pub samples: u64,
    /// Which `volpath_snee` estimator ran (`paper`, `complete`; empty for other integrators).
    pub connection: &'static str,
    /// Rays, rejected samples, SNEE and manifold counters (`integrator/stats.rs`), read as fields
    /// of `RenderStats` through `Deref`.
    pub counters: LocalStats,
}

impl RenderStats {
    pub fn to_json(&self) -> serde_json::Value {
        let mut json = serde_json::json!({
            "seconds": self.seconds,
            "spp": self.spp,
            "samples": self.samples,
            "samples_per_second": self.samples as f64 / self.seconds.max(1e-9),
            "rays_per_second": self.rays as f64 / self.seconds.max(1e-9),
            "connection": self.connection,
        });
        for (name, value) in self.counters.named() {
            json[name] = serde_json::json!(value);
        }
        json
    }
}

impl std::ops::Deref for RenderStats {
    type Target = LocalStats;
    fn deref(&self) -> &LocalStats {
        &self.counters
    }
}

/// Radiance for one camera ray, dispatching on the integrator.
#[inline]
fn sample_li(scene: &Scene, sampler: &mut Sampler, ray: crate::math::Ray, stats: &mut LocalStats) -> (Spectrum, bool) {
    scene.integrator.li(scene, sampler, ray, stats)
}

/// First sample index of the chunk that contains sample `i` (chunks: `[0,1) [1,2) [2,4) … [32,64)`,
/// then `[64k, 64k+64)`). Every (pixel, chunk) has one sampler stream, and a pass never spans
/// two chunks.
pub fn chunk_start(i: u32) -> u32 {
    match i {
        0 => 0,
        1..=63 => 1 << (31 - i.leading_zeros()),
        _ => i & !63,
    }
}

/// One past the last sample index of the chunk that contains sample `i`.
pub fn chunk_end(i: u32) -> u32 {
    match i {
        0 => 1,
        1..=63 => 2 * chunk_start(i),
        _ => chunk_start(i).saturating_add(64),
    }
}

/// Samples per pixel of a full run: `--spp`, else the scene's `sample_count`; `u32::MAX`
/// (unbounded) when only a time budget is given.
pub fn total_spp(scene: &Scene, opts: &RenderOptions) -> u32 {
    match (opts.spp, opts.time_budget) {
        (Some(s), _) => s,
        (None, Some(_)) => u32::MAX,
        (None, None) => scene.sampler.sample_count,
    }
}

/// The state of a render after a complete pass, given to [`render_range`]'s callback.
pub struct PassState<'a> {
    /// Render time so far in seconds (time spent in callbacks not counted).
    pub seconds: f64,
    /// The image holds samples `samples.0..samples.1` of every pixel.
    pub samples: (u32, u32),
    /// Channel names of the image.
    pub channels: &'a [String],
    block: &'a ImageBlock,
}

impl PassState<'_> {
    /// The developed image (channels interleaved as in [`RenderOutput`]).
    pub fn develop(&self) -> Vec<f32> {
        self.block.develop()
    }
    /// Accumulated filter weight per pixel (see [`RenderOutput::weights`]).
    pub fn weights(&self) -> Vec<f32> {
        block_weights(self.block)
    }
}

fn block_weights(block: &ImageBlock) -> Vec<f32> {
    let (w, h) = block.size();
    (0..h).flat_map(|y| (0..w).map(move |x| block.weight(x, y))).collect()
}

/// Called after every complete pass of [`render_range`].
pub type ProgressCallback<'a> = &'a mut dyn FnMut(&PassState);

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
    on_pass: Option<PassCallback>,
) -> RenderOutput {
    match on_pass {
        None => render_range(scene, opts, None, cancel, None),
        Some(cb) => {
            let mut at_powers_of_two = |state: &PassState| {
                if state.samples.1.is_power_of_two() {
                    cb(state.seconds, state.samples.1, &state.develop());
                }
            };
            render_range(scene, opts, None, cancel, Some(&mut at_powers_of_two))
        }
    }
}

/// Render samples `range.0..range.1` of every pixel (all of [`total_spp`] when `None`; the end is
/// clipped to it), calling `on_pass` after every complete pass. Only complete passes enter the
/// image: a render stopped by `cancel` or the time budget holds samples
/// `range.0..range.0 + stats.spp` exactly.
pub fn render_range(
    scene: &Scene,
    opts: &RenderOptions,
    range: Option<(u32, u32)>,
    cancel: &AtomicBool,
    mut on_pass: Option<ProgressCallback>,
) -> RenderOutput {
    let film = &scene.film;
    let (cw, ch) = film.crop_size;
    // Samples are taken in the sample window (the crop window, plus the filter border with `sample_border`).
    let ((sx, sy), (sw, sh)) = film.sample_window();
    let rgba = matches!(film.pixel_format, PixelFormat::Rgba);
    let moment = scene.integrator.moment;
    let classes = scene.integrator.classes;
    // Channels: RGB, [A], [second moment of RGB], [per transport class: RGB, [second moment]].
    let mut channels: Vec<String> = vec!["R".into(), "G".into(), "B".into()];
    if rgba {
        channels.push("A".into());
    }
    if moment {
        for c in ["R", "G", "B"] {
            channels.push(format!("m2.{}", c));
        }
    }
    if classes {
        for class in PathClass::ALL {
            for prefix in if moment { ["", "m2."].as_slice() } else { [""].as_slice() } {
                for c in ["R", "G", "B"] {
                    channels.push(format!("{}.{prefix}{c}", class.name()));
                }
            }
        }
    }
    let nch = channels.len();
    let total_spp = total_spp(scene, opts);
    let (start_sample, end_sample) = match range {
        Some((s, e)) => (s.min(total_spp), e.min(total_spp)),
        None => (0, total_spp),
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
        let len = if end_sample == u32::MAX { 0 } else { (end_sample - start_sample) as u64 * pixels };
        let b = indicatif::ProgressBar::new(len);
        b.set_style(
            indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {percent}% ({eta} left) {msg}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        b
    } else {
        indicatif::ProgressBar::hidden()
    };

    // One camera sample: film position, radiance (zero and counted when not finite), validity;
    // with `split`, also the radiance by transport class.
    let take_sample =
        |sampler: &mut Sampler, local: &mut LocalStats, x: i32, y: i32, split: Option<&mut ClassValues>| {
            let pos = Vec2::new(x as f32, y as f32) + sampler.next_2d();
            let aperture = sampler.next_2d();
            let (ray, ray_weight) = crate::integrator::primary_ray(scene, pos, aperture);
            let finite = |l: Spectrum| l.is_finite() && (!moment || (l * l).is_finite());
            match split {
                None => {
                    let (mut l, valid) = sample_li(scene, sampler, ray, local);
                    l *= ray_weight;
                    // With `moment`, a sample whose square overflows (|l| > ~1.8e19) would write inf into m2.*.
                    if !finite(l) {
                        local.rejected_samples += 1;
                        l = Spectrum::ZERO;
                    }
                    (pos, l, valid)
                }
                Some(split) => {
                    let (mut l, valid, values) = scene.integrator.li_classes(scene, sampler, ray, local);
                    l *= ray_weight;
                    *split = values.map(|v| v * ray_weight);
                    if !finite(l) || !split.iter().all(|&v| finite(v)) {
                        local.rejected_samples += 1;
                        l = Spectrum::ZERO;
                        *split = [Spectrum::ZERO; N_CLASSES];
                    }
                    (pos, l, valid)
                }
            }
        };

    // A sample's channels in `channels`' order: RGB, [alpha from `valid`], [its square],
    // [per class: RGB, [its square]].
    let pack = |values: &mut [f32], l: Spectrum, valid: bool, split: &ClassValues| {
        values[..3].copy_from_slice(&l.to_array());
        let mut k = 3;
        if rgba {
            values[3] = if valid { 1.0 } else { 0.0 };
            k = 4;
        }
        if moment {
            values[k..k + 3].copy_from_slice(&(l * l).to_array());
            k += 3;
        }
        if classes {
            for v in split {
                values[k..k + 3].copy_from_slice(&v.to_array());
                k += 3;
                if moment {
                    values[k..k + 3].copy_from_slice(&(*v * *v).to_array());
                    k += 3;
                }
            }
        }
    };

    // `path` on diffuse scenes renders several pixels at once (`integrator/path_wide.rs`).
    let wide = path_wide::applies(scene);
    // One tile's samples `next..pass_end` of every pixel (the chunk starting at `chunk` replayed
    // up to `next`), splatted into a block of its own with the samples' count; `None` when
    // cancelled before it started.
    let render_tile = |&(x0, y0, w, h): &(i32, i32, u32, u32), chunk: u32, next: u32, pass_end: u32| {
        let (replay, pass_spp) = (next - chunk, pass_end - next);
        if cancel.load(Ordering::Relaxed) {
            return None;
        }
        let mut block = ImageBlock::new((x0, y0), (w, h), film.filter, nch);
        // Light-tracing splats of this job's samples (`integrator::splat`).
        crate::integrator::splat::open();
        let mut local = LocalStats::default();
        let mut replayed = LocalStats::default();
        let mut values = vec![0.0f32; nch];
        let mut split = [Spectrum::ZERO; N_CLASSES];
        // One sample into the block: its channels in `channels`' order.
        let mut put = |pos: Vec2, l: Spectrum, valid: bool, split: &ClassValues| {
            pack(&mut values, l, valid, split);
            block.put(pos, &values);
        };
        // Unique per film pixel (the border may lie outside the film: offset it).
        let stream_at = |x: i32, y: i32| {
            let pixel_index = (y + 64) as u64 * (film.width as u64 + 128) + (x + 64) as u64;
            pixel_index.wrapping_mul(0x1_0000_0000).wrapping_add(chunk as u64)
        };
        if wide {
            // `path` on diffuse scenes: several pixels at once, the same samples in the same order.
            let pixels: Vec<Pixel> = (y0..y0 + h as i32)
                .flat_map(|y| (x0..x0 + w as i32).map(move |x| (x, y)))
                .map(|(x, y)| Pixel { x, y, seed: opts.seed, stream: stream_at(x, y) })
                .collect();
            let mut splat = |pos: Vec2, l: Spectrum, valid: bool| put(pos, l, valid, &split);
            path_wide::render_pixels(scene, &pixels, replay, pass_spp, moment, &mut local, &mut replayed, &mut splat);
        } else {
            for y in y0..y0 + h as i32 {
                for x in x0..x0 + w as i32 {
                    let mut sampler = Sampler::new(opts.seed, stream_at(x, y));
                    // Replayed samples belong to another range: their splats are dropped.
                    let kept = crate::integrator::splat::len();
                    for _ in 0..replay {
                        take_sample(&mut sampler, &mut replayed, x, y, classes.then_some(&mut split));
                    }
                    crate::integrator::splat::truncate(kept);
                    for _ in 0..pass_spp {
                        let (pos, l, valid) =
                            take_sample(&mut sampler, &mut local, x, y, classes.then_some(&mut split));
                        put(pos, l, valid, &split);
                    }
                }
            }
        }
        let splats = crate::integrator::splat::take();
        stats.add(&local);
        let n = w as u64 * h as u64 * pass_spp as u64;
        bar.inc(n);
        Some((block, splats, n))
    };
    // A splat's channels, scaled by `1 / pixels` (one light subpath per camera sample,
    // `integrator::splat`): packed as a sample's, with no alpha, its square as second moment, and
    // the class `internal_reflection`.
    let splat_scale = 1.0 / pixels as f32;
    let splat_values = |v: Spectrum, out: &mut [f32]| {
        let v = v * splat_scale;
        let mut split = [Spectrum::ZERO; N_CLASSES];
        split[PathClass::InternalReflection as usize] = v;
        pack(out, v, false, &split);
    };
    let mut splat_buf = vec![0.0f32; nch];

    // Next sample index per pixel; the image holds samples start_sample..next.
    let mut next = start_sample;
    let mut samples_done = 0u64;
    // Time spent in `on_pass`, excluded from the reported render time.
    let mut callback_seconds = 0.0f64;
    while next < end_sample && !cancel.load(Ordering::Relaxed) {
        // A pass is the rest of the chunk holding `next`: 1, 1, 2, 4, ... 64, 64, ... spp, so that
        // passes end on every power of two. With a time budget, a pass is cut to what the
        // measured rate says fits in the remaining time (and is then the last), and none starts
        // that would end more than half a sample per pixel past the budget.
        let chunk = chunk_start(next);
        let mut pass_end = chunk_end(next).min(end_sample);
        let mut last_pass = false;
        if let Some(t) = opts.time_budget {
            let elapsed = start.elapsed().as_secs_f64() - callback_seconds;
            let spp_done = next - start_sample;
            if spp_done > 0 {
                let per_spp = elapsed / spp_done as f64;
                let remaining = t - elapsed;
                if remaining < 0.5 * per_spp {
                    break;
                }
                let fits = (remaining / per_spp).round().max(1.0).min(u32::MAX as f64) as u32;
                if fits < pass_end - next {
                    pass_end = next + fits;
                    last_pass = true;
                }
            }
        }
        // The passes rendered together: this one, and, when nothing needs the image between
        // passes (no callback, no time budget), the following ones up to the end or
        // `FUSED_BLOCK_BYTES` of blocks, so that threads go from one pass to the next without
        // waiting for each other.
        let mut passes = vec![(chunk, next, pass_end)];
        if on_pass.is_none() && opts.time_budget.is_none() {
            let tile_bytes = (TILE + 2 * film.filter.border_size()).pow(2) as usize * (nch + 1) * 4;
            let max_passes = (FUSED_BLOCK_BYTES / (tile_bytes * tiles.len())).max(1);
            while passes.len() < max_passes && passes[passes.len() - 1].2 < end_sample {
                let n = passes[passes.len() - 1].2;
                passes.push((chunk_start(n), n, chunk_end(n).min(end_sample)));
            }
        }
        // Tiles render in parallel, one job each (rayon would otherwise hand a thread runs of
        // tiles that cannot be stolen, and the other thread waits for the run's end), in pass
        // order; their blocks merge pass by pass in tile order, so the floating-point sums (and
        // so the image) do not depend on the thread count or on how passes were grouped.
        let nt = tiles.len();
        let blocks: Vec<Option<(ImageBlock, Vec<crate::integrator::splat::Splat>, u64)>> = (0..passes.len() * nt)
            .into_par_iter()
            .with_max_len(1)
            .map(|k| {
                let (chunk, next, pass_end) = passes[k / nt];
                render_tile(&tiles[k % nt], chunk, next, pass_end)
            })
            .collect();
        // A pass stopped part way is dropped whole, so the image holds whole sample ranges: the
        // complete passes before the first incomplete one are kept.
        let mut stopped = false;
        for (pass, pass_blocks) in passes.iter().zip(blocks.chunks(nt)) {
            if pass_blocks.iter().any(|b| b.is_none()) {
                stopped = true;
                break;
            }
            for (block, splats, n) in pass_blocks.iter().flatten() {
                full.merge(block);
                for sp in splats {
                    splat_values(sp.value, &mut splat_buf);
                    full.add_unweighted(sp.pos.as_vec2(), &splat_buf);
                }
                samples_done += n;
            }
            pass_end = pass.2;
            next = pass_end;
        }
        if stopped || cancel.load(Ordering::Relaxed) {
            break;
        }
        if let Some(cb) = on_pass.as_mut() {
            let t0 = Instant::now();
            let state = PassState {
                seconds: start.elapsed().as_secs_f64() - callback_seconds,
                samples: (start_sample, next),
                channels: &channels,
                block: &full,
            };
            cb(&state);
            callback_seconds += t0.elapsed().as_secs_f64();
        }
        if end_sample == u32::MAX {
            bar.set_message(format!("{} spp", next - start_sample));
        }
        if last_pass {
            break;
        }
    }
    bar.finish_and_clear();
    // The developed image is part of the render time (as in Mitsuba's `render`, which returns it).
    let data = full.develop();
    let seconds = start.elapsed().as_secs_f64() - callback_seconds;
    RenderOutput {
        width: cw as usize,
        height: ch as usize,
        channels,
        data,
        weights: block_weights(&full),
        first_sample: start_sample,
        stats: RenderStats {
            seconds,
            spp: next - start_sample,
            samples: samples_done,
            connection: if scene.integrator.kind == IntegratorKind::VolpathSnee {
                scene.integrator.connection.name()
            } else {
                ""
            },
            counters: stats.snapshot(),
        },
    }
}

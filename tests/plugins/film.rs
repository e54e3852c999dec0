//! Reconstruction filters and `ImageBlock` against Mitsuba 3.9.1, tile merging, and image writing.
//!
//! Expected numbers are in `tests/data/sensor.json`, written by `scripts/sensor_expected.py`:
//! `mi.load_dict({'type': 'gaussian', ...}).eval(x)` for the filters, and for the blocks (variant
//! `llvm_ad_rgb`, as references are rendered)
//! ```python
//! b = mi.ImageBlock(size=(6, 5), offset=(10, 20), channel_count=2, rfilter=f, border=False, coalesce=True)
//! b.put(pos=mi.Point2f(xs, ys), values=[vs, mi.Float(1.0)])   # channel 1 is the weight
//! ```

use crate::{mitsuba_json, num, nums};
use glam::Vec2;
use serde_json::Value as Json;
use snee::io::write::{write_exr, write_png};
use snee::sensor::{ImageBlock, RFilter};

/// A reconstruction filter as `sensor_expected.py` writes it (Mitsuba's plugin dictionary).
fn rfilter(v: &Json) -> RFilter {
    match v["type"].as_str() {
        Some("gaussian") => RFilter::Gaussian { stddev: v.get("stddev").map_or(0.5, num) },
        Some("tent") => RFilter::Tent { radius: v.get("radius").map_or(1.0, num) },
        Some("box") => RFilter::Box,
        _ => panic!("unknown filter {v}"),
    }
}

#[test]
fn filter_values_match_mitsuba() {
    // Per filter: [(x, Mitsuba's eval(x))].
    for f in mitsuba_json("sensor.json")["filters"].as_array().unwrap() {
        let filter = rfilter(&f["filter"]);
        for xv in f["values"].as_array().unwrap() {
            let [x, expected] = nums(xv);
            let v = filter.eval(x);
            assert!((v - expected).abs() <= 2e-6, "{filter:?} at {x}: {v} vs Mitsuba {expected}");
        }
    }
    assert_eq!(RFilter::Gaussian { stddev: 0.5 }.border_size(), 2);
    assert_eq!(RFilter::Gaussian { stddev: 0.3 }.border_size(), 1);
    assert_eq!(RFilter::Gaussian { stddev: 1.0 }.border_size(), 4);
    assert_eq!(RFilter::Tent { radius: 1.0 }.border_size(), 1);
    assert_eq!(RFilter::Tent { radius: 1.5 }.border_size(), 1);
    assert_eq!(RFilter::Box.border_size(), 0);
}

/// Samples of the block test: (x, y, value) in film pixels.
const BLOCK_OFFSET: (i32, i32) = (10, 20);
const BLOCK_SIZE: (u32, u32) = (6, 5);
const BLOCK_SAMPLES: &[(f32, f32, f32)] = &[
    (12.3, 22.7, 1.0),
    (13.9, 21.2, 2.0),
    (10.05, 20.5, 3.0),
    (15.99, 24.99, 4.0),
    (9.2, 23.4, 5.0),
    (14.5, 26.1, 6.0),
    (12.5, 22.5, 7.0),
    (17.3, 19.6, 8.0),
];

#[test]
fn image_block_matches_mitsuba() {
    // Per filter: Mitsuba's weights and developed values per interior pixel, row-major.
    for b in mitsuba_json("sensor.json")["image_block"]["blocks"].as_array().unwrap() {
        let filter = rfilter(&b["filter"]);
        let weights: Vec<f32> = b["weights"].as_array().unwrap().iter().map(num).collect();
        let values: Vec<f32> = b["values"].as_array().unwrap().iter().map(num).collect();
        let mut block = ImageBlock::new(BLOCK_OFFSET, BLOCK_SIZE, filter, 1);
        for &(x, y, v) in BLOCK_SAMPLES {
            block.put(Vec2::new(x, y), &[v]);
        }
        let img = block.develop();
        let w = BLOCK_SIZE.0;
        for (i, (&wm, &vm)) in weights.iter().zip(values.iter()).enumerate() {
            let (x, y) = (i as u32 % w, i as u32 / w);
            let ours = block.weight(x, y);
            assert!(
                (ours - wm).abs() <= 1e-5 * (1.0 + wm),
                "{filter:?} pixel ({x}, {y}): weight {ours} vs Mitsuba {wm}"
            );
            if wm > 1e-3 {
                assert!(
                    (img[i] - vm).abs() <= 1e-4 * vm.abs().max(1.0),
                    "{filter:?} pixel ({x}, {y}): {} vs {vm}",
                    img[i]
                );
            } else if wm == 0.0 {
                assert_eq!(img[i], 0.0);
            }
        }
    }
}

/// A small deterministic generator for sample positions (no dependence on the renderer's sampler).
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> f32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

const FILTERS: [RFilter; 6] = [
    RFilter::Gaussian { stddev: 0.5 },
    RFilter::Gaussian { stddev: 0.3 },
    RFilter::Gaussian { stddev: 1.3 },
    RFilter::Box,
    RFilter::Tent { radius: 1.0 },
    RFilter::Tent { radius: 2.2 },
];

#[test]
fn merged_tiles_equal_one_block() {
    // A 23x17 crop window at (5, 3), tiles of 8x8 (partial at the edges), 3 channels, samples in every
    // pixel of the crop window: merging the tiles must give the block that received all samples.
    let (off, size, tile) = ((5i32, 3i32), (23u32, 17u32), 8u32);
    for filter in FILTERS {
        let mut whole = ImageBlock::new(off, size, filter, 3);
        let mut merged = ImageBlock::new(off, size, filter, 3);
        let mut tile_block = ImageBlock::new((0, 0), (tile, tile), filter, 3);
        let mut rng = Lcg(7);
        for ty in (0..size.1).step_by(tile as usize) {
            for tx in (0..size.0).step_by(tile as usize) {
                let t_off = (off.0 + tx as i32, off.1 + ty as i32);
                let t_size = (tile.min(size.0 - tx), tile.min(size.1 - ty));
                tile_block.reset(t_off, t_size);
                for y in 0..t_size.1 {
                    for x in 0..t_size.0 {
                        for _ in 0..3 {
                            let pos = Vec2::new(
                                (t_off.0 + x as i32) as f32 + rng.next(),
                                (t_off.1 + y as i32) as f32 + rng.next(),
                            );
                            let v = [rng.next(), 2.0 * rng.next(), 0.5];
                            tile_block.put(pos, &v);
                            whole.put(pos, &v);
                        }
                    }
                }
                merged.merge(&tile_block);
            }
        }
        let (a, b) = (whole.develop(), merged.develop());
        assert_eq!(a.len(), (size.0 * size.1 * 3) as usize);
        for (i, (x, y)) in a.iter().zip(&b).enumerate() {
            assert!(x.is_finite() && (x - y).abs() <= 1e-5 * x.abs().max(1.0), "{filter:?} value {i}: {x} vs {y}");
        }
        for y in 0..size.1 {
            for x in 0..size.0 {
                let (wa, wb) = (whole.weight(x, y), merged.weight(x, y));
                assert!(wa > 0.0 && (wa - wb).abs() <= 1e-5 * wa, "{filter:?} weight ({x}, {y}): {wa} vs {wb}");
            }
        }
    }
}

#[test]
fn constant_image_stays_constant() {
    // Samples of a constant colour develop to that colour in every pixel, at the edges too.
    for filter in FILTERS {
        for sample_border in [false, true] {
            let b = if sample_border { filter.border_size() as i32 } else { 0 };
            let (w, h) = (9u32, 7u32);
            let mut block = ImageBlock::new((0, 0), (w, h), filter, 4);
            let mut rng = Lcg(3);
            for y in -b..h as i32 + b {
                for x in -b..w as i32 + b {
                    for _ in 0..2 {
                        let pos = Vec2::new(x as f32 + rng.next(), y as f32 + rng.next());
                        block.put(pos, &[0.25, 1.0, 7.5, 1.0]);
                    }
                }
            }
            for (i, v) in block.develop().iter().enumerate() {
                let expected = [0.25, 1.0, 7.5, 1.0][i % 4];
                assert!(
                    (v - expected).abs() <= 1e-5 * expected,
                    "{filter:?} border {sample_border}: {v} vs {expected}"
                );
            }
        }
    }
}

#[test]
fn develop_is_finite_and_empty_pixels_are_zero() {
    for filter in FILTERS {
        let mut block = ImageBlock::new((-3, -2), (12, 10), filter, 3);
        block.put(Vec2::new(0.5, 0.5), &[1.0, 2.0, 3.0]);
        block.put(Vec2::new(f32::NAN, 1.0), &[1.0, 2.0, 3.0]);
        block.put(Vec2::new(1e30, -1e30), &[1.0, 2.0, 3.0]);
        block.put(Vec2::new(-2.9, 7.99), &[1e-30, 0.0, 1e30]);
        let img = block.develop();
        assert!(img.iter().all(|v| v.is_finite()), "{filter:?}");
        // Pixel (8, 8) relative to the block (film (5, 6)) is far from every sample.
        let far = ((8 * 12 + 8) * 3) as usize;
        assert_eq!(&img[far..far + 3], &[0.0, 0.0, 0.0]);
        block.clear();
        assert!(block.develop().iter().all(|v| *v == 0.0));
    }
}

#[test]
fn exr_round_trip() {
    let dir = std::env::temp_dir().join(format!("snee-film-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("img.exr");
    let (w, h) = (5usize, 3usize);
    let names = ["R", "G", "B", "A", "var.R"];
    let data: Vec<f32> = (0..w * h * names.len()).map(|i| i as f32 * 0.37 - 3.0).collect();
    write_exr(&path, w, h, &names, &data).unwrap();

    use exr::prelude::*;
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(&path)
        .unwrap();
    let layer = &image.layer_data;
    assert_eq!((layer.size.0, layer.size.1), (w, h));
    let mut found: Vec<String> = Vec::new();
    for ch in &layer.channel_data.list {
        let name = ch.name.to_string();
        let c = names.iter().position(|n| *n == name).unwrap_or_else(|| panic!("unexpected channel {name}"));
        let FlatSamples::F32(samples) = &ch.sample_data else { panic!("channel {name} is not float32") };
        for (p, v) in samples.iter().enumerate() {
            assert_eq!(*v, data[p * names.len() + c], "channel {name}, pixel {p} (row 0 at the top)");
        }
        found.push(name);
    }
    found.sort();
    let mut expected: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    expected.sort();
    assert_eq!(found, expected);

    // Mismatched sizes and repeated channel names are errors, not panics.
    assert!(write_exr(&path, w, h, &names, &data[1..]).is_err());
    assert!(write_exr(&path, w, h, &["R", "R"], &data[..w * h * 2]).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn png_preview() {
    let dir = std::env::temp_dir().join(format!("snee-png-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("img.png");
    let rgb = [0.0, 0.5, 1.0, 2.0, -1.0, f32::NAN, 0.0031308, 0.18, f32::INFINITY];
    write_png(&path, 3, 1, &rgb).unwrap();
    let img = image::open(&path).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (3, 1));
    // sRGB: 0.5 → 0.7354 → 188; 0.18 → 0.4614 → 118; 0.0031308 → 0.04045 → 10; out of range clamps; NaN/inf → 0.
    assert_eq!(img.get_pixel(0, 0).0, [0, 188, 255]);
    assert_eq!(img.get_pixel(1, 0).0, [255, 0, 0]);
    assert_eq!(img.get_pixel(2, 0).0, [10, 118, 0]);
    assert!(write_png(&path, 2, 2, &rgb).is_err());
    std::fs::remove_dir_all(&dir).ok();
}

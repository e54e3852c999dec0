//! Reconstruction filters and `ImageBlock` against Mitsuba 3.9.1, tile merging, and image writing.
//!
//! Expected numbers come from `scripts/sensor_expected.py`: `mi.load_dict({'type': 'gaussian', ...}).eval(x)`
//! for the filters, and for the blocks (variant `llvm_ad_rgb`, as references are rendered)
//! ```python
//! b = mi.ImageBlock(size=(6, 5), offset=(10, 20), channel_count=2, rfilter=f, border=False, coalesce=True)
//! b.put(pos=mi.Point2f(xs, ys), values=[vs, mi.Float(1.0)])   # channel 1 is the weight
//! ```

#![allow(clippy::excessive_precision)] // Mitsuba's values printed with 10 digits
use glam::Vec2;
use snee::io::write::{write_exr, write_png};
use snee::sensor::{ImageBlock, RFilter};

/// `(filter, [(x, Mitsuba's eval(x))])`
#[rustfmt::skip]
const FILTER_VALUES: &[(RFilter, &[(f32, f32)])] = &[
    // gaussian: radius 2.0, border 2
    (RFilter::Gaussian { stddev: 0.5 }, &[(0.0, 9.992471337e-01), (0.1, 9.795333147e-01), (0.25, 8.821667433e-01), (0.49, 6.185593605e-01), (0.5, 6.064230204e-01), (0.75, 3.242425621e-01), (1.0, 1.349604875e-01), (1.2, 5.580844730e-02), (1.5, 1.075820997e-02), (1.9, 3.878818534e-04), (1.99, 2.973749542e-05), (2.0, 1.907348633e-06), (2.3, 0.000000000e+00), (2.5, 0.000000000e+00), (3.0, 0.000000000e+00), (3.5, 0.000000000e+00), (-0.3, 8.350478411e-01), (-1.1, 8.858962357e-02)]),
    // gaussian_0.3: radius 1.2000000476837158, border 1
    (RFilter::Gaussian { stddev: 0.3 }, &[(0.0, 9.992640615e-01), (0.1, 9.454464912e-01), (0.25, 7.065798640e-01), (0.49, 2.630279362e-01), (0.5, 2.489279062e-01), (0.75, 4.362073541e-02), (1.0, 3.538012505e-03), (1.2, 0.000000000e+00), (1.5, 0.000000000e+00), (1.9, 0.000000000e+00), (1.99, 0.000000000e+00), (2.0, 0.000000000e+00), (2.3, 0.000000000e+00), (2.5, 0.000000000e+00), (3.0, 0.000000000e+00), (3.5, 0.000000000e+00), (-0.3, 6.064400077e-01), (-1.1, 8.824804681e-04)]),
    // gaussian_1: radius 4.0, border 4
    (RFilter::Gaussian { stddev: 1.0 }, &[(0.0, 9.992471337e-01), (0.1, 9.942823052e-01), (0.25, 9.686135054e-01), (0.49, 8.865342736e-01), (0.5, 8.821667433e-01), (0.75, 7.547276616e-01), (1.0, 6.064230204e-01), (1.2, 4.865248203e-01), (1.5, 3.242425621e-01), (1.9, 1.640712172e-01), (1.99, 1.376846731e-01), (2.0, 1.349604875e-01), (2.3, 7.068089396e-02), (2.5, 4.360346496e-02), (3.0, 1.075820997e-02), (3.5, 1.843098435e-03), (-0.3, 9.554299116e-01), (-1.1, 5.459148884e-01)]),
    // tent: radius 1.0, border 1
    (RFilter::Tent { radius: 1.0 }, &[(0.0, 1.000000000e+00), (0.1, 8.999999762e-01), (0.25, 7.500000000e-01), (0.49, 5.099999905e-01), (0.5, 5.000000000e-01), (0.75, 2.500000000e-01), (1.0, 0.000000000e+00), (1.2, 0.000000000e+00), (1.5, 0.000000000e+00), (1.9, 0.000000000e+00), (1.99, 0.000000000e+00), (2.0, 0.000000000e+00), (2.3, 0.000000000e+00), (2.5, 0.000000000e+00), (3.0, 0.000000000e+00), (3.5, 0.000000000e+00), (-0.3, 6.999999881e-01), (-1.1, 0.000000000e+00)]),
    // tent_1.5: radius 1.5, border 1
    (RFilter::Tent { radius: 1.5 }, &[(0.0, 1.000000000e+00), (0.1, 9.333333373e-01), (0.25, 8.333333135e-01), (0.49, 6.733332872e-01), (0.5, 6.666666269e-01), (0.75, 5.000000000e-01), (1.0, 3.333333135e-01), (1.2, 1.999999285e-01), (1.5, 0.000000000e+00), (1.9, 0.000000000e+00), (1.99, 0.000000000e+00), (2.0, 0.000000000e+00), (2.3, 0.000000000e+00), (2.5, 0.000000000e+00), (3.0, 0.000000000e+00), (3.5, 0.000000000e+00), (-0.3, 7.999999523e-01), (-1.1, 2.666666508e-01)]),
    // box: radius 0.5, border 0
    (RFilter::Box, &[(0.0, 1.000000000e+00), (0.1, 1.000000000e+00), (0.25, 1.000000000e+00), (0.49, 1.000000000e+00), (0.5, 0.000000000e+00), (0.75, 0.000000000e+00), (1.0, 0.000000000e+00), (1.2, 0.000000000e+00), (1.5, 0.000000000e+00), (1.9, 0.000000000e+00), (1.99, 0.000000000e+00), (2.0, 0.000000000e+00), (2.3, 0.000000000e+00), (2.5, 0.000000000e+00), (3.0, 0.000000000e+00), (3.5, 0.000000000e+00), (-0.3, 1.000000000e+00), (-1.1, 0.000000000e+00)]),
];

#[test]
fn filter_values_match_mitsuba() {
    for (filter, values) in FILTER_VALUES {
        for &(x, expected) in *values {
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

/// `(filter, Mitsuba's weights, Mitsuba's developed values)` per interior pixel, row-major.
#[rustfmt::skip]
const BLOCKS: &[(RFilter, &[f32], &[f32])] = &[
    // ImageBlock gaussian: weights, then developed values (row-major 6x5)
    (RFilter::Gaussian { stddev: 0.5 }, &[6.6639209e-01, 1.4556157e-02, 7.3081926e-03, 2.7223346e-01, 1.8242115e-01, 2.3467068e-03, 9.0084158e-02, 3.5672799e-02, 2.0262340e-01, 6.2762153e-01, 4.0627179e-01, 4.7034053e-03, 7.7566532e-03, 3.9099184e-01, 1.8504635e+00, 2.1082322e-01, 1.6399937e-02, 1.8982129e-04, 3.3345133e-02, 9.5276937e-02, 3.9099273e-01, 3.3707015e-02, 1.3118476e-04, 7.0777750e-03, 2.9872700e-03, 3.3065150e-04, 1.1000512e-03, 8.2676887e-04, 1.2705471e-02, 3.8337612e-01],
     &[3.0000000e+00, 3.0000708e+00, 2.0013039e+00, 2.0000045e+00, 2.0000000e+00, 2.6009076e+00, 2.9988284e+00, 4.1737881e+00, 5.0736909e+00, 2.1401436e+00, 2.0000031e+00, 2.0005915e+00, 4.4340310e+00, 3.0694892e+00, 4.2379055e+00, 4.9541407e+00, 2.0005810e+00, 2.0000000e+00, 4.9603930e+00, 2.1470354e+00, 3.0694840e+00, 4.2422333e+00, 4.0058866e+00, 4.0000000e+00, 4.9981041e+00, 1.0046710e+00, 1.0104443e+00, 5.5986123e+00, 4.8858700e+00, 4.0039654e+00]),
    // ImageBlock tent_1.5: weights, then developed values (row-major 6x5)
    (RFilter::Tent { radius: 1.5 }, &[7.0000011e-01, 3.3333421e-02, 3.5555646e-02, 3.9111087e-01, 3.1999955e-01, 0.0000000e+00, 2.3333335e-01, 2.1555528e-01, 5.5999976e-01, 7.3777825e-01, 4.8000008e-01, 0.0000000e+00, 5.3333312e-02, 7.3777735e-01, 1.7599998e+00, 6.0444480e-01, 8.0000244e-02, 0.0000000e+00, 1.2444429e-01, 3.2888904e-01, 7.3777825e-01, 2.0444459e-01, 4.4445947e-05, 4.4889660e-03, 3.5555489e-02, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 4.4889660e-03, 4.5337796e-01],
     &[3.0000000e+00, 3.0000000e+00, 2.0000000e+00, 2.0000000e+00, 2.0000000e+00, 0.0000000e+00, 3.0000000e+00, 4.1958804e+00, 4.6666684e+00, 2.6987946e+00, 2.0000000e+00, 0.0000000e+00, 5.0000000e+00, 3.7108448e+00, 4.4141421e+00, 4.4705868e+00, 2.0000000e+00, 0.0000000e+00, 5.0000000e+00, 3.0270259e+00, 3.7108417e+00, 4.2608666e+00, 4.0000000e+00, 4.0000000e+00, 5.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 4.0000000e+00, 4.0000000e+00]),
    // ImageBlock gaussian_1: weights, then developed values (row-major 6x5)
    (RFilter::Gaussian { stddev: 1.0 }, &[9.4674474e-01, 5.3971684e-01, 5.6447268e-01, 8.4950340e-01, 6.9253558e-01, 3.5088378e-01, 7.9875946e-01, 9.9762064e-01, 1.4713804e+00, 1.4875159e+00, 9.2660272e-01, 3.0859292e-01, 7.3764759e-01, 1.4353848e+00, 2.1284914e+00, 1.4816275e+00, 5.9627670e-01, 1.7866646e-01, 6.6193414e-01, 9.7324646e-01, 1.3533252e+00, 8.2138902e-01, 3.4719902e-01, 3.4249359e-01, 2.9156077e-01, 2.6701301e-01, 3.7111303e-01, 3.8956740e-01, 6.0820824e-01, 9.5795333e-01],
     &[3.0509422e+00, 3.2911079e+00, 3.1285758e+00, 2.4354639e+00, 2.2327604e+00, 4.2711678e+00, 3.3423576e+00, 3.7361310e+00, 3.7569773e+00, 3.0782819e+00, 2.4171810e+00, 2.7378039e+00, 3.9814162e+00, 3.7467189e+00, 3.9020112e+00, 3.7281592e+00, 3.0455065e+00, 2.8264704e+00, 4.3506432e+00, 3.5696161e+00, 3.7368107e+00, 3.9439201e+00, 4.0054507e+00, 4.0264764e+00, 4.5898399e+00, 3.4738772e+00, 3.7262461e+00, 4.7358479e+00, 4.9048076e+00, 4.3502288e+00]),
    // ImageBlock box: weights, then developed values (row-major 6x5)
    (RFilter::Box, &[1.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 1.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 2.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 1.0000000e+00],
     &[3.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 2.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 4.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 0.0000000e+00, 4.0000000e+00]),
];

#[test]
fn image_block_matches_mitsuba() {
    for (filter, weights, values) in BLOCKS {
        let mut block = ImageBlock::new(BLOCK_OFFSET, BLOCK_SIZE, *filter, 1);
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

//! Reference regression: every `reference/NAME.exr` (rendered by Mitsuba 3 with
//! `scripts/make_references.py`, channels R,G,B mean and var.R,var.G,var.B per-sample variance,
//! spp in `reference/NAME.json`) is compared with our render of `scenes/NAME.xml`.
//!
//! Three statistical tests, each at family-wise level α = 0.01 with Šidák's correction:
//! - per pixel: two-sample Z-test; a pixel's variance is the per-sample variance (ours from the
//!   second-moment channel, the reference's from `var.*`) times the filter's variance factor
//!   f = ∫w² / (∫w)² over the samples that reach the pixel (larger near the image border), over N;
//! - per 8×8 block: Welch-style t-test, our variance the larger of the batch estimate (exact under
//!   the pixel filter's correlations, but blind to rare bright samples in 16 batches) and the
//!   reference's per-sample variance scaled to our sample count (which sees those samples); the
//!   reference's own variance from its variance channel;
//! - the whole image (same batch method), which is what catches a ~1 % bias.
//!
//! Per-pixel tests are fragile where rare, very bright samples dominate (caustics of the sun
//! through glass): even two Mitsuba renders fail a per-pixel Šidák test there (0.2–0.4 % of
//! pixel-channels at 256 spp, measured by `scripts/make_references.py --check`). Those scenes get
//! the block and image tests only. Every variance gets a floor of (1e-4 · reference)² for float
//! rounding (Mitsuba accumulates in float32), far below any bias worth detecting.
//!
//! On failure the render and a per-pixel z-score image are written to `target/test-output/`.

use snee::compare::erfc;
use snee::io::read::read_image;
use snee::render::{render, RenderOptions};
use snee::scene::build::load_scene;
use snee::testing::chi2::sidak;
use snee::testing::student_t::t_p_value;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

const ALPHA: f64 = 0.01;
const BATCHES: usize = 16;
const BLOCK: usize = 8;
/// Relative precision floor added to every variance (see the module docs).
const PRECISION: f64 = 1e-4;

struct Image {
    w: usize,
    h: usize,
    mean: Vec<[f64; 3]>,
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Per-pixel variance factor of the reconstruction filter: f(x, y) = f1(x) f1(y) with
/// f1(p) = ∫₀ᵂ w²(t − p − ½) dt / (∫₀ᵂ w(t − p − ½) dt)² (samples are uniform over the film).
fn variance_factor(filter: &snee::sensor::rfilter::RFilter, w: usize, h: usize) -> Vec<f64> {
    let f1 = |p: usize, size: usize| -> f64 {
        let r = filter.radius() as f64;
        let steps = 4096;
        let (lo, hi) = ((p as f64 + 0.5 - r).max(0.0), (p as f64 + 0.5 + r).min(size as f64));
        let dt = (hi - lo) / steps as f64;
        let (mut s1, mut s2) = (0.0, 0.0);
        for i in 0..steps {
            let t = lo + (i as f64 + 0.5) * dt;
            let v = filter.eval((t - p as f64 - 0.5) as f32) as f64;
            s1 += v * dt;
            s2 += v * v * dt;
        }
        s2 / (s1 * s1)
    };
    let fx: Vec<f64> = (0..w).map(|x| f1(x, w)).collect();
    let fy: Vec<f64> = (0..h).map(|y| f1(y, h)).collect();
    (0..w * h).map(|i| fx[i % w] * fy[i / w]).collect()
}

/// Render `scene` in `BATCHES` independent batches; returns (batch images, mean, per-pixel variance of the mean).
/// Also returns the filter's per-pixel variance factor.
fn render_batches(scene_path: &Path, spp_per_batch: u32) -> (Vec<Image>, Image, Vec<[f64; 3]>, Vec<f64>) {
    let mut scene = load_scene(scene_path, &[]).unwrap_or_else(|e| panic!("{}", e));
    scene.integrator.moment = true;
    let factor = variance_factor(&scene.film.filter, scene.film.crop_size.0 as usize, scene.film.crop_size.1 as usize);
    let cancel = AtomicBool::new(false);
    // `SNEE_TEST_SEED` re-runs the suite on other random streams (robustness checks).
    let seed0 = std::env::var("SNEE_TEST_SEED").ok().and_then(|v| v.parse().ok()).unwrap_or(1000u64);
    let mut batches = Vec::new();
    let mut m2_sum: Vec<[f64; 3]> = Vec::new();
    for b in 0..BATCHES {
        let opts =
            RenderOptions { spp: Some(spp_per_batch), seed: seed0 + b as u64, time_budget: None, progress: false };
        let out = render(&scene, &opts, &cancel);
        let n = out.channels.len();
        let m2i = out.channels.iter().position(|c| c == "m2.R").expect("moment channels");
        let mean: Vec<[f64; 3]> = out.data.chunks(n).map(|p| [p[0] as f64, p[1] as f64, p[2] as f64]).collect();
        let m2: Vec<[f64; 3]> =
            out.data.chunks(n).map(|p| [p[m2i] as f64, p[m2i + 1] as f64, p[m2i + 2] as f64]).collect();
        if m2_sum.is_empty() {
            m2_sum = vec![[0.0; 3]; m2.len()];
        }
        for (s, v) in m2_sum.iter_mut().zip(&m2) {
            for c in 0..3 {
                s[c] += v[c] / BATCHES as f64;
            }
        }
        batches.push(Image { w: out.width, h: out.height, mean });
    }
    let (w, h) = (batches[0].w, batches[0].h);
    let mut mean = vec![[0.0f64; 3]; w * h];
    for b in &batches {
        for (m, v) in mean.iter_mut().zip(&b.mean) {
            for c in 0..3 {
                m[c] += v[c] / BATCHES as f64;
            }
        }
    }
    let total_spp = (spp_per_batch as usize * BATCHES) as f64;
    let var: Vec<[f64; 3]> = mean
        .iter()
        .zip(&m2_sum)
        .zip(&factor)
        .map(|((m, m2), f)| [0, 1, 2].map(|c| ((m2[c] - m[c] * m[c]).max(0.0)) * f / total_spp))
        .collect();
    (batches, Image { w, h, mean }, var, factor)
}

fn write_failure(name: &str, img: &Image, z: &[[f64; 3]]) -> PathBuf {
    let dir = root().join("target/test-output");
    let _ = std::fs::create_dir_all(&dir);
    let data: Vec<f32> = img.mean.iter().flat_map(|p| p.map(|v| v as f32)).collect();
    let zd: Vec<f32> = z.iter().flat_map(|p| p.map(|v| v as f32)).collect();
    let _ = snee::io::write::write_exr(&dir.join(format!("{}.exr", name)), img.w, img.h, &["R", "G", "B"], &data);
    let _ = snee::io::write::write_exr(&dir.join(format!("{}_z.exr", name)), img.w, img.h, &["R", "G", "B"], &zd);
    dir
}

fn check_scene(name: &str, spp_per_batch: u32, per_pixel: bool) {
    match compare_scene(name, spp_per_batch, per_pixel, 1.0) {
        Ok(msg) => eprintln!("{}", msg),
        Err(msg) => panic!("{}", msg),
    }
}

/// Render `name` (our image multiplied by `bias`, 1 for the real test) and run the three tests.
fn compare_scene(name: &str, spp_per_batch: u32, per_pixel: bool, bias: f64) -> Result<String, String> {
    let ref_exr = root().join("reference").join(format!("{}.exr", name));
    let ref_json = root().join("reference").join(format!("{}.json", name));
    let meta: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&ref_json).expect("reference json")).expect("valid json");
    let spp_ref = meta["spp"].as_f64().expect("spp in reference json");
    let r = read_image(&ref_exr, false).unwrap_or_else(|e| panic!("{}", e));
    let ch = |n: &str| r.channel(n).unwrap_or_else(|| panic!("reference lacks channel {}", n));
    let (ir, ig, ib) = (ch("R"), ch("G"), ch("B"));
    let (vr, vg, vb) = (ch("var.R"), ch("var.G"), ch("var.B"));
    let nc = r.channels.len();
    let ref_mean: Vec<[f64; 3]> = r.data.chunks(nc).map(|p| [p[ir] as f64, p[ig] as f64, p[ib] as f64]).collect();
    let (mut batches, mut ours, our_var, factor) =
        render_batches(&root().join("scenes").join(format!("{}.xml", name)), spp_per_batch);
    for img in batches.iter_mut().chain(std::iter::once(&mut ours)) {
        for p in img.mean.iter_mut() {
            *p = p.map(|v| v * bias);
        }
    }
    let ref_var: Vec<[f64; 3]> = r
        .data
        .chunks(nc)
        .zip(&factor)
        .map(|(p, f)| [p[vr] as f64 * f / spp_ref, p[vg] as f64 * f / spp_ref, p[vb] as f64 * f / spp_ref])
        .collect();
    assert_eq!((ours.w, ours.h), (r.width, r.height), "{}: image size differs from the reference", name);
    assert!(ours.mean.iter().all(|p| p.iter().all(|v| v.is_finite())), "{}: non-finite pixels", name);

    // ---- Per-pixel Z-test ----
    let n_pix = ours.mean.len();
    let mut z = vec![[0.0f64; 3]; n_pix];
    let mut min_p: f64 = 1.0;
    let mut worst = String::new();
    for i in 0..n_pix {
        for c in 0..3 {
            let var = our_var[i][c] + ref_var[i][c] + (PRECISION * ref_mean[i][c]).powi(2);
            let d = ours.mean[i][c] - ref_mean[i][c];
            let p = if var > 0.0 {
                z[i][c] = d / var.sqrt();
                erfc(z[i][c].abs() / std::f64::consts::SQRT_2)
            } else if d.abs() > 1e-5 * ref_mean[i][c].abs() + 1e-6 {
                z[i][c] = f64::INFINITY;
                0.0
            } else {
                1.0
            };
            if p < min_p {
                min_p = p;
                worst = format!(
                    "pixel ({}, {}) channel {}: ours {} ref {} z {:.2}",
                    i % ours.w,
                    i / ours.w,
                    c,
                    ours.mean[i][c],
                    ref_mean[i][c],
                    z[i][c]
                );
            }
        }
    }
    let level = sidak(ALPHA, n_pix * 3);

    // ---- Block and whole-image tests (variance from batches) ----
    let bw = ours.w.div_ceil(BLOCK);
    let bh = ours.h.div_ceil(BLOCK);
    let mut regions: Vec<Vec<usize>> = Vec::new();
    for by in 0..bh {
        for bx in 0..bw {
            let mut px = Vec::new();
            for y in by * BLOCK..((by + 1) * BLOCK).min(ours.h) {
                for x in bx * BLOCK..((bx + 1) * BLOCK).min(ours.w) {
                    px.push(y * ours.w + x);
                }
            }
            regions.push(px);
        }
    }
    regions.push((0..n_pix).collect());
    let region_level = sidak(ALPHA, regions.len() * 3);
    let mut region_fail = None;
    for (ri, px) in regions.iter().enumerate() {
        for c in 0..3 {
            let avg = |img: &[[f64; 3]]| px.iter().map(|&i| img[i][c]).sum::<f64>() / px.len() as f64;
            let per_batch: Vec<f64> = batches.iter().map(|b| avg(&b.mean)).collect();
            let m = per_batch.iter().sum::<f64>() / BATCHES as f64;
            let s2 = per_batch.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (BATCHES - 1) as f64;
            let var_ref = px.iter().map(|&i| ref_var[i][c]).sum::<f64>() / (px.len() * px.len()) as f64;
            // Our variance: the batch estimate captures the filter's pixel correlations but misses
            // rare bright samples on heavy-tailed scenes; the reference's per-sample variance (from
            // 8k–16k spp) scaled to our sample count catches those. Take the larger of the two.
            let spp_ours = (spp_per_batch as usize * BATCHES) as f64;
            let var_ours = (s2 / BATCHES as f64).max(var_ref * spp_ref / spp_ours);
            let d = m - avg(&ref_mean);
            let var = var_ours + var_ref + (PRECISION * avg(&ref_mean)).powi(2);
            let p = if var > 0.0 {
                t_p_value(d / var.sqrt(), (BATCHES - 1) as f64)
            } else if d.abs() > 1e-6 {
                0.0
            } else {
                1.0
            };
            if p < region_level && region_fail.is_none() {
                let what = if ri + 1 == regions.len() { "whole image".to_string() } else { format!("block {}", ri) };
                region_fail = Some(format!(
                    "{} channel {}: ours {:.6} ref {:.6} (rel {:+.3}%), p = {:.2e} < {:.2e}",
                    what,
                    c,
                    m,
                    avg(&ref_mean),
                    100.0 * d / avg(&ref_mean).abs().max(1e-12),
                    p,
                    region_level
                ));
            }
        }
    }
    let pixel_fail = per_pixel && min_p < level;
    if pixel_fail || region_fail.is_some() {
        let dir = write_failure(name, &ours, &z);
        return Err(format!(
            "{}: differs from the Mitsuba reference.\n  per-pixel: min p = {:.2e} (level {:.2e}); worst {}\n  regions: {}\n  images in {}",
            name,
            min_p,
            level,
            worst,
            region_fail.unwrap_or_else(|| "ok".into()),
            dir.display()
        ));
    }
    Ok(format!(
        "{}: per-pixel min p = {:.3e} (level {:.2e}, {}); blocks and image mean pass",
        name,
        min_p,
        level,
        if per_pixel { "tested" } else { "not tested: caustics" }
    ))
}

/// The tests can fail: a 1 % brightness bias is caught on the Cornell box and on the glass scene
/// (where only the block and image tests run).
#[test]
fn one_percent_bias_is_detected() {
    for (name, spp, per_pixel) in [("cornell_box", 64, true), ("rough_glass_ggx", 16, false)] {
        for bias in [0.99, 1.01] {
            let r = compare_scene(name, spp, per_pixel, bias);
            assert!(r.is_err(), "{} with a {:+}% bias passed: {:?}", name, (bias - 1.0) * 100.0, r);
        }
    }
}

#[test]
fn t_distribution_sanity() {
    // t = 2.131 with 15 dof has a two-sided p of 0.05.
    assert!((t_p_value(2.131, 15.0) - 0.05).abs() < 5e-4);
    assert!((t_p_value(0.0, 15.0) - 1.0).abs() < 1e-9);
}

// One test per reference scene. Each renders 16 batches; spp per batch keeps every test to a few seconds.
#[test]
fn cornell_box() {
    check_scene("cornell_box", 64, true);
}
#[test]
fn default_scene() {
    check_scene("default", 8, false);
}
#[test]
fn directional_area() {
    check_scene("directional_area", 64, true);
}
#[test]
fn glass_envmap() {
    check_scene("glass_envmap", 16, false);
}
#[test]
fn rough_glass_beckmann() {
    check_scene("rough_glass_beckmann", 16, false);
}
#[test]
fn rough_glass_ggx() {
    check_scene("rough_glass_ggx", 16, false);
}
#[test]
fn spot_point() {
    check_scene("spot_point", 64, true);
}

// Media scenes (volpath). Per-pixel tests only where Mitsuba's own renders pass this very test
// (`scripts/self_test.py`, 16 x 16 spp against the reference: media_null and media_camera_inside
// 0 failures in 15 trials; media_inside failed the per-pixel test in 2 of 15, so blocks only).
// Light that reaches a medium only through glass makes pixel values heavy-tailed (reference/README.md).

// At 16 x 16 spp this fails on a heavy-tailed block (block 65, G: ours 0.1892 vs ref 0.2194,
// -13.8 %, p = 3.01e-5 < 3.07e-5). The sun is reached from the medium only by refracting out of the
// smooth glass, so a few rare samples carry most of the light. Not a visible bias: at 2048 spp our
// image mean is -0.14/-0.12/-0.09 % (R/G/B) from the reference and 8x8 block z-scores have std 0.81,
// max 3.8. Mitsuba itself fails this test in 2 of 5 trials (`scripts/self_test.py`).
#[test]
// Heavy-tailed (sun through smooth glass): fails at 256 spp, so 16 × 128 spp here.
fn media_smooth_glass() {
    check_scene("media_smooth_glass", 128, false);
}
#[test]
fn media_rough_glass() {
    check_scene("media_rough_glass", 16, false);
}
#[test]
fn media_null() {
    check_scene("media_null", 16, true);
}
#[test]
fn media_inside() {
    check_scene("media_inside", 16, false);
}
#[test]
fn media_thin() {
    check_scene("media_thin", 16, false);
}
// At 16 x 16 spp this fails (block 31, B: ours 0.0321 vs ref 0.0363, -11.7 %, p = 1.1e-5 <
// 3.07e-5) and worse at 16 x 32 spp (block 58, R: -19.9 %, p = 2.1e-7). Light enters the medium
// only by emitter sampling at the Beckmann (alpha 0.1) boundary, a narrow lobe: the pixel values
// are firefly-dominated (two Mitsuba renders at 256 spp: per-pixel max |z| = 62, 219 pixel-channels
// over the Sidak level, `make_references.py --check 256`), and Mitsuba fails this test in 5 of 5 trials
// (`scripts/self_test.py`). At 2048 spp our image mean is -1.1/-0.9/-0.6 % from the reference,
// z = -1.4 (not significant).
#[test]
// Firefly-dominated (spot through Beckmann 0.1 glass): fails at 256 spp, so 16 × 128 spp here.
fn media_spot() {
    check_scene("media_spot", 128, false);
}
#[test]
fn media_camera_inside() {
    check_scene("media_camera_inside", 16, true);
}

// Surface BSDF scenes (conductor, roughconductor, plastic, roughplastic, mask): block and per-pixel
// tests (they pass with seeds 5000, 9000 and the default).
#[test]
fn surfaces_metals() {
    check_scene("surfaces_metals", 32, true);
}
#[test]
fn surfaces_plastics() {
    check_scene("surfaces_plastics", 32, true);
}
#[test]
fn surfaces_translucent() {
    check_scene("surfaces_translucent", 128, true);
}
// Anisotropic roughconductor on a rotated uv-mapped mesh, a rotated mesh without uvs, a rotated
// sphere and a tilted disk: the shading frame's tangent must be Mitsuba's dp/du.
#[test]
fn surfaces_anisotropic() {
    check_scene("surfaces_anisotropic", 32, true);
}

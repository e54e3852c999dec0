//! The complete estimator (`volpath_snee`, `connection = complete`) through a flat ROUGH boundary
//! (`roughdielectric`, docs/manifold.md §7): the connection samples the refraction from the light
//! side at every medium vertex and shares the suffix with forward NEE at `x_k` and SNEE under the
//! power heuristic. It must agree with `volpath` where `volpath` converges (forward NEE at the
//! rough `x_k` makes the same paths there):
//! - a rough glass cube (HG medium, GGX α = 0.2 and Beckmann α = 0.1, n = 1.5) under an oblique
//!   directional light: `complete` with `snee = mis` (all techniques) and `snee = forward`
//!   (connection + forward) against `volpath` (Welch on the image and 8×8 blocks of independent
//!   batches, Šidák at family-wise 1 %);
//! - the thick rough slab (GGX α = 0.2, n = 1.33, albedo 0.8) of `scripts/roughness_sweep.py`
//!   read by an irradiancemeter: `complete` against `volpath`, per-seed Welch test;
//! - the rough glass cube (GGX α = 0.1) under an environment map (hidden): the same comparison,
//!   where forward BSDF sampling out of `x_k` is a fourth technique;
//! - `connection = paper` never runs the connection on a rough boundary (no attempt counted).
//!
//! Sample counts chosen before the first run (from the render speed only): cube `volpath`
//! 12 × 512 spp, `complete` 12 × 128; slab `volpath` 8 × 65536, `complete` 8 × 16384.

use crate::common;

use common::{render_batches, scene};
use snee::render::{render, RenderOptions};
use std::sync::atomic::AtomicBool;

const DIRECTIONAL: &str = r#"<emitter type="directional"><vector name="direction" value="0.5, 0.4, -0.75"/><rgb name="irradiance" value="3, 3, 3"/></emitter>"#;

fn rough(distribution: &str, alpha: f64, n: f64) -> String {
    format!(
        r#"<bsdf type="roughdielectric"><string name="distribution" value="{distribution}"/><float name="alpha" value="{alpha}"/><float name="int_ior" value="{n}"/><float name="ext_ior" value="1"/></bsdf>"#
    )
}

const COMPLETE: &str = r#"<string name="connection" value="complete"/>"#;
const COMPLETE_FORWARD: &str = r#"<string name="connection" value="complete"/><string name="snee" value="forward"/>"#;

fn cube_agrees_with_volpath(bsdf: &str, seed: u64) {
    let cube = |integrator: &str, extra: &str| common::medium_cube(integrator, extra, bsdf, DIRECTIONAL);
    let volpath = render_batches(&scene(&cube("volpath", ""), &[]), 12, 512, 8, seed);
    let mis = render_batches(&scene(&cube("volpath_snee", COMPLETE), &[]), 12, 128, 8, seed + 100);
    let fwd = render_batches(&scene(&cube("volpath_snee", COMPLETE_FORWARD), &[]), 12, 128, 8, seed + 200);
    common::assert_complete_agrees(&volpath, &mis, &fwd);
}

#[test]
fn rough_ggx_cube_agrees_with_volpath() {
    cube_agrees_with_volpath(&rough("ggx", 0.2, 1.5), 70_000);
}

#[test]
fn rough_beckmann_cube_agrees_with_volpath() {
    cube_agrees_with_volpath(&rough("beckmann", 0.1, 1.5), 80_000);
}

/// Under an environment (hidden from the camera) the connection shares the suffix with forward
/// BSDF sampling out of the rough `x_k` too: four techniques. 12 × 128 spp each (as the smooth
/// envmap test of `manifold_unbiased.rs`), chosen before the first run.
#[test]
fn rough_cube_under_envmap_agrees_with_volpath() {
    let env = r#"<emitter type="envmap"><string name="filename" value="textures/sky.exr"/></emitter>"#;
    let bsdf = rough("ggx", 0.1, 1.5);
    let hidden = r#"<boolean name="hide_emitters" value="true"/>"#;
    let cube = |integrator: &str, extra: &str| common::medium_cube(integrator, &format!("{hidden}{extra}"), &bsdf, env);
    let volpath = render_batches(&scene(&cube("volpath", ""), &[]), 12, 128, 8, 90_000);
    let mis = render_batches(&scene(&cube("volpath_snee", COMPLETE), &[]), 12, 128, 8, 90_100);
    let fwd = render_batches(&scene(&cube("volpath_snee", COMPLETE_FORWARD), &[]), 12, 128, 8, 90_200);
    common::assert_complete_agrees(&volpath, &mis, &fwd);
}

fn slab(integrator: &str, extra: &str) -> String {
    let integrator =
        format!(r#"<integrator type="{integrator}"><integer name="max_depth" value="-1"/>{extra}</integrator>"#);
    common::slab_scene(&integrator, "0, 0, -1", 0.8, 0.0, &rough("ggx", 0.2, 1.33))
}

#[test]
fn rough_slab_agrees_with_volpath() {
    let (m_vp, se_vp, _) = common::meter_reading(&scene(&slab("volpath", ""), &[]), 65536, 8, 900);
    let (m_c, se_c, rejected) = common::meter_reading(&scene(&slab("volpath_snee", COMPLETE), &[]), 16384, 8, 950);
    assert_eq!(rejected, 0);
    let s = (se_vp * se_vp + se_c * se_c).sqrt();
    let t = (m_c - m_vp) / s;
    eprintln!("volpath {m_vp:.5} ± {se_vp:.5}, complete {m_c:.5} ± {se_c:.5}: t = {t:+.2}");
    // 8 + 8 seeds: Welch's t with at least 7 degrees of freedom; |t| < 3.5 is p > 0.01.
    assert!(t.abs() < 3.5, "rough slab: complete {m_c} ± {se_c} vs volpath {m_vp} ± {se_vp}");
}

#[test]
fn paper_never_connects_through_rough_boundary() {
    let xml = common::medium_cube("volpath_snee", "", &rough("ggx", 0.2, 1.5), DIRECTIONAL);
    let cancel = AtomicBool::new(false);
    let opts = RenderOptions { spp: Some(4), seed: 3, time_budget: None, progress: false };
    let out = render(&scene(&xml, &[]), &opts, &cancel);
    assert_eq!(out.stats.manifold_attempts, 0);
    let xml = common::medium_cube("volpath_snee", COMPLETE, &rough("ggx", 0.2, 1.5), DIRECTIONAL);
    let out = render(&scene(&xml, &[]), &opts, &cancel);
    assert!(out.stats.manifold_solutions > 0, "the rough connection never ran");
}

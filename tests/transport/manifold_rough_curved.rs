//! The complete estimator (`volpath_snee`, `connection = complete`) through a CURVED rough
//! boundary (docs/manifold.md §7.1): a smooth-shaded glass pebble (`scenes/meshes/pebble.ply`,
//! interpolated vertex normals; n = 1.5, HG medium) with a GGX `roughdielectric`. The connection
//! samples the inner direction in the shading frame where the straight line from `x_j` towards the
//! light meets the boundary, and shares the suffix with forward NEE and forward BSDF sampling at
//! `x_k` and SNEE under the power heuristic (densities recomputed from each path's `x_j`). Where
//! `volpath` converges it must agree: `complete` with `snee = mis` and `snee = forward` against
//! `volpath` (Welch on the image and 8×8 blocks of independent batches, Šidák at family-wise 1 %):
//! - under an oblique directional light, α = 0.2 and α = 0.04;
//! - under an environment map (hidden), α = 0.2 (forward BSDF sampling out of `x_k` is a technique);
//! - under a sphere light, α = 0.2 (the finite-light connection of docs/manifold.md §7.2 shares the
//!   suffix with the other techniques; the render must stay unbiased).
//!
//! Sample counts chosen before the first run (as `manifold_rough.rs`): `volpath` 12 × 512 spp,
//! `complete` 12 × 128 spp (envmap: 12 × 128 each).

use crate::common;

use common::{render_batches, scene};

const DIRECTIONAL: &str = r#"<emitter type="directional"><vector name="direction" value="0.5, 0.4, -0.75"/><rgb name="irradiance" value="3, 3, 3"/></emitter>"#;
const COMPLETE: &str = r#"<string name="connection" value="complete"/>"#;
const COMPLETE_FORWARD: &str = r#"<string name="connection" value="complete"/><string name="snee" value="forward"/>"#;

fn ggx(alpha: f64) -> String {
    format!(
        r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="{alpha}"/><float name="int_ior" value="1.5"/><float name="ext_ior" value="1"/></bsdf>"#
    )
}

/// `medium_cube` with the cube replaced by the smooth-shaded pebble mesh.
fn pebble(integrator: &str, props: &str, bsdf: &str, emitter: &str) -> String {
    common::medium_cube(integrator, props, bsdf, emitter)
        .replace(r#"<shape type="cube">"#, r#"<shape type="ply"><string name="filename" value="meshes/pebble.ply"/>"#)
}

fn pebble_agrees_with_volpath(bsdf: &str, emitter: &str, props: &str, spp_volpath: u32, seed: u64) {
    let xml = |integrator: &str, extra: &str| pebble(integrator, &format!("{props}{extra}"), bsdf, emitter);
    let volpath = render_batches(&scene(&xml("volpath", ""), &[]), 12, spp_volpath, 8, seed);
    let mis = render_batches(&scene(&xml("volpath_snee", COMPLETE), &[]), 12, 128, 8, seed + 100);
    let fwd = render_batches(&scene(&xml("volpath_snee", COMPLETE_FORWARD), &[]), 12, 128, 8, seed + 200);
    common::assert_complete_agrees(&volpath, &mis, &fwd);
}

#[test]
fn rough_pebble_ggx020_directional_agrees_with_volpath() {
    pebble_agrees_with_volpath(&ggx(0.2), DIRECTIONAL, "", 512, 110_000);
}

/// FAILED on its first run (counts chosen before it): one dim 8×8 block (the image's top-right
/// corner, a few pebble pixels) read `volpath` 0.000009 against `complete` `mis` 0.000048 (t −8.5),
/// image means agreeing (0.0171 ± 6.9 % vs 0.0169 ± 2.2 %). A longer check of the same scene
/// (`snee render`, `volpath` 16,384 spp against `complete` 2,048 spp, standard errors from the
/// per-pixel moments) agrees in the image and in all nine blocks (|z| ≤ 1.6; that block
/// 0.000026 ± 0.000045 vs 0.000036 ± 0.000026): at α = 0.04 `volpath`'s estimate of that block is
/// heavy-tailed (forward NEE at `x_k` through a narrow lobe), so twelve batches under-estimate both
/// its mean and its spread. Kept, ignored, until a reference that converges there replaces
/// `volpath` (docs/manifold.md §7.1).
#[test]
#[ignore = "volpath's 12 x 512 spp batches are too heavy-tailed at alpha 0.04 for the block test; see the comment"]
fn rough_pebble_ggx004_directional_agrees_with_volpath() {
    pebble_agrees_with_volpath(&ggx(0.04), DIRECTIONAL, "", 512, 120_000);
}

#[test]
fn rough_pebble_under_envmap_agrees_with_volpath() {
    let env = r#"<emitter type="envmap"><string name="filename" value="textures/sky.exr"/></emitter>"#;
    let hidden = r#"<boolean name="hide_emitters" value="true"/>"#;
    pebble_agrees_with_volpath(&ggx(0.2), env, hidden, 128, 130_000);
}

#[test]
fn rough_pebble_under_sphere_light_agrees_with_volpath() {
    let sphere = r#"<shape type="sphere"><point name="center" x="-2" y="1" z="3"/><float name="radius" value="0.5"/>
        <emitter type="area"><rgb name="radiance" value="20, 20, 20"/></emitter></shape>"#;
    pebble_agrees_with_volpath(&ggx(0.2), sphere, "", 512, 140_000);
}

/// The depth factor of the connection's rate (`rough_rate::depth_rate`, docs/manifold.md §7.2
/// "Rate") at work: the pebble at `sigma_t = 20` (optical size above the thin threshold, so the
/// medium's rate is 1; vertices more than 0.15 from the boundary towards the light run the
/// connection at a rate below 1). Counts as the other agreement tests, chosen before the first run.
#[test]
fn thick_rough_pebble_ggx020_directional_agrees_with_volpath() {
    let xml = |integrator: &str, extra: &str| {
        pebble(integrator, extra, &ggx(0.2), DIRECTIONAL)
            .replace(r#"<float name="sigma_t" value="2"/>"#, r#"<float name="sigma_t" value="20"/>"#)
    };
    let volpath = render_batches(&scene(&xml("volpath", ""), &[]), 12, 512, 8, 150_000);
    let mis = render_batches(&scene(&xml("volpath_snee", COMPLETE), &[]), 12, 128, 8, 150_100);
    let fwd = render_batches(&scene(&xml("volpath_snee", COMPLETE_FORWARD), &[]), 12, 128, 8, 150_200);
    common::assert_complete_agrees(&volpath, &mis, &fwd);
}

#[test]
fn curved_rough_connection_runs() {
    use snee::render::{render, RenderOptions};
    use std::sync::atomic::AtomicBool;
    let cancel = AtomicBool::new(false);
    let opts = RenderOptions { spp: Some(4), seed: 3, time_budget: None, progress: false };
    let paper = render(&scene(&pebble("volpath_snee", "", &ggx(0.2), DIRECTIONAL), &[]), &opts, &cancel);
    assert_eq!(paper.stats.manifold_attempts, 0);
    let complete = render(&scene(&pebble("volpath_snee", COMPLETE, &ggx(0.2), DIRECTIONAL), &[]), &opts, &cancel);
    assert!(complete.stats.manifold_solutions > 0, "the curved rough connection never ran");
}

//! The complete estimator (`volpath_snee`, `connection = complete`) with lights at a FINITE
//! distance through a flat smooth boundary (docs/manifold.md §3.2): the manifold connection to a
//! point on an area light (sphere, rectangle) or to a point light, combined with forward tracing
//! and SNEE by MIS, must agree with an independent estimator where that converges.
//! - Smooth glass cube (n = 1.5, HG g = 0.4, grey σt = 2) lit by a SPHERE light and by a
//!   RECTANGLE light (emitters hidden from the camera): forward tracing reaches both through the
//!   smooth boundary, so `volpath` converges; `complete` with `snee = mis` (all four techniques)
//!   and with `snee = forward` (manifold + forward) must agree with it.
//! - Index-matched dielectric cube (int_ior = ext_ior = 1: a delta interface that blocks shadow
//!   rays, no refraction) lit by a POINT light and a SPOT light: `volpath` through a `null` cube
//!   is the reference (there ordinary NEE reaches the light); the paper's estimator misses the
//!   single scattering and is shown to fail the same test.
//!
//! Criterion: Welch test on the image mean and 8×8-block means of independent batches,
//! Šidák-corrected at family-wise 1 % (`common::welch_compare`). Sample counts chosen before the
//! first run: 12 batches × 64 spp (as `manifold_unbiased.rs`). History, for honesty: all four
//! passed at that count, but on the glass cube `volpath`'s image-mean standard error was 3.3 %
//! (rectangle) and 4.5 % (sphere), too weak a test; its count was raised to 12 × 1024 spp and
//! `complete`'s to 12 × 256 before the second run.

use crate::common;

use common::{render_batches, scene, welch_compare, GLASS, MATCHED};

fn cube(integrator: &str, extra: &str, bsdf: &str, emitter: &str) -> String {
    let props = format!(r#"<boolean name="hide_emitters" value="true"/>{extra}"#);
    common::medium_cube(integrator, &props, bsdf, emitter)
}

const COMPLETE: &str = r#"<string name="connection" value="complete"/>"#;
const COMPLETE_FORWARD: &str = r#"<string name="connection" value="complete"/><string name="snee" value="forward"/>"#;

/// `complete` (`snee = mis` and `snee = forward`) against `volpath` on the glass cube.
fn agrees_with_volpath(emitter: &str, seed: u64) {
    let volpath = render_batches(&scene(&cube("volpath", "", GLASS, emitter), &[]), 12, 1024, 8, seed);
    let mis = render_batches(&scene(&cube("volpath_snee", COMPLETE, GLASS, emitter), &[]), 12, 256, 8, seed + 100);
    let fwd =
        render_batches(&scene(&cube("volpath_snee", COMPLETE_FORWARD, GLASS, emitter), &[]), 12, 256, 8, seed + 200);
    common::assert_complete_agrees(&volpath, &mis, &fwd);
}

#[test]
fn sphere_light_through_glass_agrees_with_volpath() {
    let sphere = r#"<shape type="sphere"><point name="center" x="-2" y="1" z="3"/><float name="radius" value="0.5"/>
        <emitter type="area"><rgb name="radiance" value="20, 20, 20"/></emitter></shape>"#;
    agrees_with_volpath(sphere, 10_000);
}

#[test]
fn rectangle_light_through_glass_agrees_with_volpath() {
    // A 1 × 1 rectangle at height 2.5 facing down, off to the side.
    let rectangle = r#"<shape type="rectangle">
        <transform name="to_world"><scale value="0.5"/><rotate x="1" angle="180"/><translate x="0.8" y="-0.6" z="2.5"/></transform>
        <emitter type="area"><rgb name="radiance" value="15, 15, 15"/></emitter></shape>"#;
    agrees_with_volpath(rectangle, 20_000);
}

/// `complete` through the index-matched dielectric against `volpath` through a `null` cube.
fn delta_light_agrees_with_null_boundary(emitter: &str, seed: u64) {
    let volpath = render_batches(&scene(&cube("volpath", "", r#"<bsdf type="null"/>"#, emitter), &[]), 12, 64, 8, seed);
    let complete =
        render_batches(&scene(&cube("volpath_snee", COMPLETE, MATCHED, emitter), &[]), 12, 64, 8, seed + 100);
    assert_eq!(complete.rejected, 0);
    let (report, m_vp, m_c) = welch_compare(&volpath, &complete, 0.01);
    eprintln!(
        "volpath (null boundary) {m_vp:?} ({:.2} %)\ncomplete (matched dielectric) {m_c:?} ({:.2} %)",
        100.0 * common::rel_std_error(&volpath),
        100.0 * common::rel_std_error(&complete)
    );
    assert!(report.is_empty(), "volpath vs complete:\n{report}");
    // The test can fail: the paper's estimator misses the single scattering.
    let paper = render_batches(&scene(&cube("volpath_snee", "", MATCHED, emitter), &[]), 12, 16, 8, seed + 200);
    let (report, _, m_p) = welch_compare(&volpath, &paper, 0.01);
    eprintln!("paper {m_p:?}");
    assert!(!report.is_empty(), "the paper's estimator should disagree with volpath here");
}

#[test]
fn point_light_through_matched_boundary_agrees_with_volpath() {
    let point = r#"<emitter type="point"><point name="position" x="-1.5" y="1.2" z="2.5"/><rgb name="intensity" value="8, 8, 8"/></emitter>"#;
    delta_light_agrees_with_null_boundary(point, 30_000);
}

#[test]
fn spot_light_through_matched_boundary_agrees_with_volpath() {
    let spot = r#"<emitter type="spot">
        <transform name="to_world"><lookat origin="1.5, -1.0, 2.8" target="0, 0, 0"/></transform>
        <rgb name="intensity" value="10, 10, 10"/><float name="cutoff_angle" value="25"/></emitter>"#;
    delta_light_agrees_with_null_boundary(spot, 40_000);
}

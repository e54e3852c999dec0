//! The manifold connection through CURVED smooth boundaries (`manifold/curved.rs`): meshes with
//! interpolated shading normals, under an oblique directional light.
//! - An INDEX-MATCHED smooth `dielectric` pebble (a smooth-shaded convex mesh, int_ior = ext_ior
//!   = 1: a delta interface that blocks shadow rays but does not bend them) of HG medium: the
//!   complete estimator must agree with `volpath` through the same mesh with a `null` BSDF, where
//!   ordinary NEE reaches the light (Welch on image and 8×8-block means, Šidák at 1 %). The
//!   paper's estimator fails the same test (it misses single scattering).
//! - The same pebble and the non-convex blob in GLASS (n = 1.5): the connection alone
//!   (`snee = forward`, Newton on every suffix) against the partition (`snee = mis`: SNEE keeps
//!   the suffixes in its support, the connection the rest). SNEE is an independent technique on
//!   its support, so agreement checks the Newton solution, its beam spread `dω/dω_l` and what the
//!   single seed misses there, through a refracting curved surface.
//!
//! Sample counts chosen before the first run: 12 batches × 64 spp (matched), 12 × 32 (glass).

use crate::common;

use common::{agree_with_reference, render_batches, scene, welch_compare, GLASS, MATCHED};

const DIRECTIONAL: &str = r#"<emitter type="directional"><vector name="direction" value="0.5, 0.4, -0.75"/><rgb name="irradiance" value="3, 3, 3"/></emitter>"#;

/// `medium_cube` with the cube replaced by a PLY mesh (smooth shading normals) of `scenes/meshes`.
fn mesh(integrator: &str, props: &str, bsdf: &str, file: &str) -> String {
    common::medium_cube(integrator, props, bsdf, DIRECTIONAL).replace(
        r#"<shape type="cube">"#,
        &format!(r#"<shape type="ply"><string name="filename" value="meshes/{file}"/>"#),
    )
}

const COMPLETE: &str = r#"<string name="connection" value="complete"/>"#;

#[test]
fn curved_matched_agrees_with_volpath_through_null_boundary() {
    let volpath =
        render_batches(&scene(&mesh("volpath", "", r#"<bsdf type="null"/>"#, "pebble.ply"), &[]), 12, 64, 8, 100);
    let complete = render_batches(&scene(&mesh("volpath_snee", COMPLETE, MATCHED, "pebble.ply"), &[]), 12, 64, 8, 200);
    assert_eq!(complete.rejected, 0);
    let (report, m_vp, m_c) = welch_compare(&volpath, &complete, 0.01);
    eprintln!(
        "volpath (null pebble) {m_vp:?} (rel. s.e. {:.2} %)\ncomplete (matched pebble) {m_c:?} (rel. s.e. {:.2} %)",
        100.0 * common::rel_std_error(&volpath),
        100.0 * common::rel_std_error(&complete)
    );
    assert!(report.is_empty(), "volpath vs complete:\n{report}");
    // The test can fail: the paper's estimator misses the single scattering.
    let paper = render_batches(&scene(&mesh("volpath_snee", "", MATCHED, "pebble.ply"), &[]), 12, 16, 8, 300);
    let (report, _, m_p) = welch_compare(&volpath, &paper, 0.01);
    eprintln!("paper {m_p:?}");
    assert!(!report.is_empty(), "the paper's estimator should disagree with volpath here");
}

/// Glass: the connection alone against SNEE on its support plus the connection elsewhere.
fn glass_techniques_agree(file: &str, seed0: u64) {
    let forward = format!(r#"{COMPLETE}<string name="snee" value="forward"/>"#);
    let alone = render_batches(&scene(&mesh("volpath_snee", &forward, GLASS, file), &[]), 12, 32, 8, seed0);
    let mis = render_batches(&scene(&mesh("volpath_snee", COMPLETE, GLASS, file), &[]), 12, 32, 8, seed0 + 100);
    assert_eq!(alone.rejected + mis.rejected, 0);
    let report = agree_with_reference(("complete snee=forward", &alone), &[("complete snee=mis", &mis)], 0.01);
    assert!(report.is_empty(), "{file}: {report}");
}

#[test]
fn curved_glass_pebble_techniques_agree() {
    glass_techniques_agree("pebble.ply", 400);
}

#[test]
fn curved_glass_blob_techniques_agree() {
    glass_techniques_agree("blob.ply", 600);
}

//! Unbiasedness of the complete estimator (`volpath_snee`, `connection = complete`) where an
//! independent estimator converges, and its neutrality where it does not apply.
//! - An INDEX-MATCHED smooth `dielectric` cube (int_ior = ext_ior = 1: no refraction, no Fresnel,
//!   but still a delta interface that blocks shadow rays) of HG medium under an oblique
//!   directional light, lit through three faces: the manifold connection (every plane enumerated)
//!   combined with SNEE by MIS must agree with `volpath` on the same cube with a `null` boundary,
//!   where ordinary NEE reaches the light (Welch test on image and 8×8-block means of independent
//!   batches, Šidák-corrected at 1 %). The paper's estimator is shown to fail the same test.
//! - A smooth glass cube (n = 1.5) under an envmap (hidden from the camera), where forward tracing
//!   converges: the
//!   connection to the environment, forward tracing and SNEE under the three-way power heuristic
//!   (`snee = mis`), and with `snee = forward` (manifold + forward only) agree with `volpath`.
//! - On a curved boundary under a point light (a glass sphere; not handled: curved boundaries are
//!   connected to directional, sphere and area lights only) the connection draws no samples:
//!   `complete` renders bit for bit what `paper` renders. (Lights at a finite distance through
//!   flat boundaries: `tests/manifold_finite.rs`.)
//!
//! Sample counts: the first run (chromatic σt, 12 batches × 16 spp) passed but volpath's
//! hero-channel weights gave it an 8.5 % standard error, too weak a test; the medium was made grey
//! and the count raised to 12 × 64 spp (image-mean standard errors ~0.25 %).

use crate::common;

use common::{render_batches, scene, welch_compare, GLASS, MATCHED};
use snee::render::{render, RenderOptions};
use std::sync::atomic::AtomicBool;

fn cube(integrator: &str, bsdf: &str, emitter: &str) -> String {
    common::medium_cube(integrator, "", bsdf, emitter)
}

const DIRECTIONAL: &str = r#"<emitter type="directional"><vector name="direction" value="0.5, 0.4, -0.75"/><rgb name="irradiance" value="3, 3, 3"/></emitter>"#;

#[test]
fn complete_agrees_with_volpath_through_null_boundary() {
    let volpath = render_batches(&scene(&cube("volpath", r#"<bsdf type="null"/>"#, DIRECTIONAL), &[]), 12, 64, 8, 1000);
    let xml = cube("volpath_snee", MATCHED, DIRECTIONAL).replace(
        r#"<integer name="max_depth" value="-1"/>"#,
        r#"<integer name="max_depth" value="-1"/><string name="connection" value="complete"/>"#,
    );
    let complete = render_batches(&scene(&xml, &[]), 12, 64, 8, 2000);
    assert_eq!(complete.rejected, 0);
    let (report, m_vp, m_c) = welch_compare(&volpath, &complete, 0.01);
    eprintln!(
        "volpath (null boundary) {m_vp:?} (rel. s.e. {:.2} %)\ncomplete (matched dielectric) {m_c:?} (rel. s.e. {:.2} %)",
        100.0 * common::rel_std_error(&volpath),
        100.0 * common::rel_std_error(&complete)
    );
    assert!(report.is_empty(), "volpath vs complete:\n{report}");
    // The test can fail: the paper's estimator misses the single scattering.
    let paper = render_batches(&scene(&cube("volpath_snee", MATCHED, DIRECTIONAL), &[]), 12, 16, 8, 3000);
    let (report, _, m_p) = welch_compare(&volpath, &paper, 0.01);
    eprintln!("paper {m_p:?}");
    assert!(!report.is_empty(), "the paper's estimator should disagree with volpath here");
}

#[test]
fn complete_agrees_with_volpath_under_envmap() {
    let env = r#"<emitter type="envmap"><string name="filename" value="textures/sky.exr"/></emitter>"#;
    let glass = GLASS;
    // The environment seen directly is hidden: the image is the cube alone.
    let with = |integrator: &str, extra: &str| {
        cube(integrator, glass, env).replace(
            r#"<integer name="max_depth" value="-1"/>"#,
            &format!(r#"<integer name="max_depth" value="-1"/><boolean name="hide_emitters" value="true"/>{extra}"#),
        )
    };
    let complete =
        |extra: &str| with("volpath_snee", &format!(r#"<string name="connection" value="complete"/>{extra}"#));
    let volpath = render_batches(&scene(&with("volpath", ""), &[]), 12, 128, 8, 4000);
    let mis = render_batches(&scene(&complete(""), &[]), 12, 128, 8, 5000);
    let fwd = render_batches(&scene(&complete(r#"<string name="snee" value="forward"/>"#), &[]), 12, 128, 8, 6000);
    assert!(mis.stats.len() > 1);
    common::assert_complete_agrees(&volpath, &mis, &fwd);
}

#[test]
fn complete_is_paper_on_curved_boundary() {
    let area = r#"<emitter type="point"><point name="position" x="-2" y="1" z="3"/><rgb name="intensity" value="8, 8, 8"/></emitter>"#;
    let glass = GLASS;
    let sphere =
        |integrator: &str| cube(integrator, glass, area).replace(r#"<shape type="cube">"#, r#"<shape type="sphere">"#);
    let paper = scene(&sphere("volpath_snee"), &[]);
    let xml = sphere("volpath_snee").replace(
        r#"<integer name="max_depth" value="-1"/>"#,
        r#"<integer name="max_depth" value="-1"/><string name="connection" value="complete"/>"#,
    );
    let complete = scene(&xml, &[]);
    let cancel = AtomicBool::new(false);
    let opts = RenderOptions { spp: Some(8), seed: 7, time_budget: None, progress: false };
    let (a, b) = (render(&paper, &opts, &cancel), render(&complete, &opts, &cancel));
    assert_eq!(b.stats.manifold_attempts, 0);
    assert!(a.data.iter().zip(&b.data).all(|(x, y)| x.to_bits() == y.to_bits()), "images differ");
}

//! The wide `path` loop (`integrator/path_wide.rs`, several pixels at once) renders the images of
//! the scalar loop bit for bit: cornell_box (diffuse, a textured floor, an area light on a
//! rectangle) on a film with partial tiles, whole and as a sample range that replays part of a
//! chunk, with and without emitters hidden, without emitters, and with two-sided boxes seen from
//! behind. Its own test binary: it flips the global switch.

mod common;

use snee::integrator::path_wide;
use snee::render::{render_range, RenderOptions};
use std::sync::atomic::{AtomicBool, Ordering};

#[test]
fn wide_path_matches_scalar_path_bit_for_bit() {
    let xml = std::fs::read_to_string(common::root().join("scenes/cornell_box.xml")).unwrap();
    let hidden = xml.replace(
        r#"<integer name="rr_depth" value="4"/>"#,
        r#"<integer name="rr_depth" value="2"/><boolean name="hide_emitters" value="true"/>"#,
    );
    // No emitter at all (black, but every path still runs): the wide loop's generic emitter branch.
    let start = xml.find("<emitter").unwrap();
    let end = xml.find("</emitter>").unwrap() + "</emitter>".len();
    let dark = format!("{}{}", &xml[..start], &xml[end..]);
    // `twosided` around diffuse with another model behind, on boxes whose normals point inward:
    // the boxes are seen from their back sides (the wide loop's mirrored frame).
    let two_sided = xml
        .replace(
            r#"<bsdf type="diffuse" id="white">
        <rgb name="reflectance" value="0.73, 0.71, 0.68"/>
    </bsdf>"#,
            r#"<bsdf type="twosided" id="white">
        <bsdf type="diffuse"><rgb name="reflectance" value="0.73, 0.71, 0.68"/></bsdf>
        <bsdf type="diffuse"><rgb name="reflectance" value="0.2, 0.5, 0.8"/></bsdf>
    </bsdf>"#,
        )
        .replace(r#"<shape type="cube">"#, r#"<shape type="cube"><boolean name="flip_normals" value="true"/>"#);
    assert!(two_sided.contains("twosided") && two_sided.contains("flip_normals"));
    let cancel = AtomicBool::new(false);
    let mut images = Vec::new();
    for (xml, max_depth) in [(&xml, "8"), (&xml, "-1"), (&hidden, "3"), (&dark, "8"), (&two_sided, "8")] {
        let scene = common::scene(xml, &[("width", "40"), ("height", "23"), ("max_depth", max_depth)]);
        for range in [None, Some((3, 7))] {
            let opts = RenderOptions { spp: Some(8), seed: 5, time_budget: None, progress: false };
            path_wide::ENABLED.store(true, Ordering::Relaxed);
            assert!(path_wide::applies(&scene));
            let wide = render_range(&scene, &opts, range, &cancel, None);
            path_wide::ENABLED.store(false, Ordering::Relaxed);
            assert!(!path_wide::applies(&scene));
            let scalar = render_range(&scene, &opts, range, &cancel, None);
            let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&wide.data), bits(&scalar.data), "max_depth {max_depth}, range {range:?}");
            assert_eq!(bits(&wide.weights), bits(&scalar.weights));
            assert_eq!(wide.stats.rays, scalar.stats.rays);
            assert_eq!(wide.stats.rejected_samples, scalar.stats.rejected_samples);
            assert_eq!(wide.data.iter().any(|&x| x > 0.0), !std::ptr::eq(xml, &dark));
            if max_depth == "8" && range.is_none() {
                images.push(wide.data);
            }
        }
    }
    // images: the one-sided, the dark and the two-sided scene at max_depth 8. The back sides'
    // model shows: the two-sided image is not the one-sided one.
    assert_ne!(images[0], images[2]);
}

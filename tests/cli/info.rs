//! `snee info` speaks in the scene's words: plugin and parameter names as in the XML, colours
//! as numbers, no Rust debug text (`Some("smoke")`, `Volpath`, `Hg { g: 0.5 }`).

use crate::snee;

fn info(args: &[&str]) -> String {
    let o = snee().arg("info").args(args).output().unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn text_uses_plugin_and_parameter_names() {
    let t = info(&["scenes/media_smooth_glass.xml"]);
    for needle in [
        "medium homogeneous (interior) id=\"smoke\"",
        "medium \"smoke\": homogeneous, sigma_t = 2.5, albedo = 0.8, phase isotropic",
        "film: 96x72 hdrfilm, rgb, rfilter gaussian (stddev = 0.5)",
        "integrator: volpath, max_depth = 64, rr_depth = 5, hide_emitters = false",
        "emitters: 1 [envmap]",
    ] {
        assert!(t.contains(needle), "missing {needle:?} in:\n{t}");
    }
    let t = info(&["scenes/paper/directional_ggx004_st02.xml"]);
    assert!(t.contains("max_depth = unbounded"), "{t}");
    for t in [t, info(&["scenes/cornell_box.xml"]), info(&["scenes/media_spot.xml"])] {
        for rust in ["Some(", "None", "Volpath", "Path ", "Isotropic", "Hg {", "[0.", "e-1"] {
            assert!(!t.contains(rust), "Rust debug text {rust:?} in:\n{t}");
        }
    }
}

#[test]
fn json_uses_plugin_names() {
    let v: serde_json::Value = serde_json::from_str(&info(&["scenes/media_smooth_glass.xml", "--json"])).unwrap();
    assert_eq!(v["integrator"]["type"], "volpath");
    assert_eq!(v["media"][0]["id"], "smoke");
    assert_eq!(v["media"][0]["phase"]["type"], "isotropic");
    assert_eq!(v["film"]["pixel_format"], "rgb");
    assert_eq!(v["sampler"], "independent");
}

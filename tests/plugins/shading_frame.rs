//! The shading frame of every shape against Mitsuba 3.9's: point, geometric normal, shading frame
//! (s, t, n) and uv of ray hits on rotated spheres, disks, rectangles, cubes and PLY meshes with
//! and without uvs / vertex normals / flipped normals. The tangent `s` orients anisotropic BSDFs
//! (`alpha_u` along `s`); Mitsuba takes it from dp/du. Expected values: tests/data/shading_frames.json,
//! written by scripts/shading_frame_expected.py with Mitsuba's `scalar_rgb`.

use crate::common;

use snee::math::{Ray, Vec3};

fn vec3(v: &serde_json::Value) -> Vec3 {
    let a = v.as_array().expect("array");
    Vec3::new(a[0].as_f64().unwrap() as f32, a[1].as_f64().unwrap() as f32, a[2].as_f64().unwrap() as f32)
}

#[test]
fn shading_frames_match_mitsuba() {
    let text = std::fs::read_to_string(common::root().join("tests/data/shading_frames.json")).expect("data file");
    let data: serde_json::Value = serde_json::from_str(&text).expect("valid json");
    let mut checked = 0;
    for case in data["cases"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let xml =
            format!("<scene version=\"3.0.0\"><sensor type=\"perspective\"/>{}</scene>", case["xml"].as_str().unwrap());
        let mut scene = common::scene(&xml, &[]);
        // The loader computes uv on hits only where a texture reads it; here every hit's uv is checked.
        for shape in &mut scene.shapes {
            shape.geometry.set_hit_uv(true);
        }
        for hit in case["hits"].as_array().unwrap() {
            let ray = Ray::new(vec3(&hit["o"]), vec3(&hit["d"]));
            let si = scene.ray_intersect(&ray).unwrap_or_else(|| panic!("{name}: no hit for {ray:?}"));
            let close = |a: Vec3, b: Vec3, tol: f32| (a - b).abs().max_element() <= tol;
            let want = |k: &str| vec3(&hit[k]);
            let ctx = format!("{name}, ray {ray:?}");
            assert!(close(si.p, want("p"), 1e-4), "{ctx}: p {} vs {}", si.p, want("p"));
            assert!(close(si.n, want("n"), 1e-4), "{ctx}: n {} vs {}", si.n, want("n"));
            assert!(close(si.sh_frame.n, want("sh_n"), 1e-4), "{ctx}: sh n {} vs {}", si.sh_frame.n, want("sh_n"));
            assert!(close(si.sh_frame.s, want("s"), 1e-4), "{ctx}: s {} vs {}", si.sh_frame.s, want("s"));
            assert!(close(si.sh_frame.t, want("tt"), 1e-4), "{ctx}: t {} vs {}", si.sh_frame.t, want("tt"));
            let uv = hit["uv"].as_array().unwrap();
            let (u, v) = (uv[0].as_f64().unwrap() as f32, uv[1].as_f64().unwrap() as f32);
            assert!((si.uv.x - u).abs() <= 1e-4 && (si.uv.y - v).abs() <= 1e-4, "{ctx}: uv {} vs ({u}, {v})", si.uv);
            checked += 1;
        }
    }
    assert!(checked >= 100, "only {checked} hits checked");
}

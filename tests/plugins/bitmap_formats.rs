//! The image formats Mitsuba's `bitmap` texture reads (PNG, JPEG, BMP, TGA, RGBE, PFM), decoded as
//! Mitsuba 3.9.1 decodes them, with and without `raw` (sRGB → linear for 8-bit data only).
//! Expected values: `tests/data/formats/formats.json`, made by `scripts/make_surface_assets.py`
//! (Mitsuba's `bitmap` texture evaluated at every pixel centre with nearest filtering).

use snee::io::read::read_image;
use std::path::Path;

#[test]
fn formats_match_mitsuba() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/formats");
    let data: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("formats.json")).unwrap()).unwrap();
    let mut failures = Vec::new();
    let mut checked = 0;
    for (key, expected) in data.as_object().unwrap() {
        if key == "planks_mean" {
            continue;
        }
        let (file, raw) = match key.strip_suffix(":raw") {
            Some(f) => (f, true),
            None => (key.as_str(), false),
        };
        let bitmap = read_image(&dir.join(file), !raw).unwrap_or_else(|e| panic!("{key}: {}", e.msg));
        let pixels = bitmap.to_rgb_pixels(file).unwrap();
        assert_eq!(bitmap.width as u64, expected["width"].as_u64().unwrap(), "{key}");
        assert_eq!(bitmap.height as u64, expected["height"].as_u64().unwrap(), "{key}");
        // JPEG decoders may differ by a level or two of 8 bits (IDCT rounding and clamping; the sRGB
        // curve's slope near 1 is 2.4); everything else is exact up to float rounding of the curve.
        let tol = match (file.ends_with(".jpg"), raw) {
            (true, true) => 2.5 / 255.0,
            (true, false) => 6.0 / 255.0,
            _ => 2e-6,
        };
        let mut worst = 0.0f32;
        for (i, (p, e)) in pixels.iter().zip(expected["rgb"].as_array().unwrap()).enumerate() {
            for c in 0..3 {
                let ev = e[c].as_f64().unwrap() as f32;
                let d = (p[c] - ev).abs() / ev.abs().max(1.0);
                worst = worst.max(d);
                if d > tol {
                    failures.push(format!("{key}: pixel {i} channel {c}: {} vs Mitsuba {}", p[c], ev));
                }
            }
            checked += 1;
        }
        eprintln!("{key}: worst difference {worst:.2e}");
    }
    assert!(checked > 500);
    // The scenes' JPEG texture: same mean colour as Mitsuba's decoder gives.
    let planks = read_image(&Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/textures/planks.jpg"), true).unwrap();
    let px = planks.to_rgb_pixels("planks.jpg").unwrap();
    let n = px.len() as f64;
    for c in 0..3 {
        let mean = px.iter().map(|p| p[c] as f64).sum::<f64>() / n;
        let m = data["planks_mean"][c].as_f64().unwrap();
        eprintln!("planks.jpg mean channel {c}: {mean:.6} vs Mitsuba {m:.6}");
        // Decoders differ by ~0.03 %, far below what the reference tests resolve (about 1 %).
        assert!((mean - m).abs() < 1e-3 * m, "planks.jpg mean channel {c}: {mean} vs Mitsuba {m}");
    }
    assert!(failures.is_empty(), "{} failures:\n{}", failures.len(), failures[..failures.len().min(20)].join("\n"));
}

#[test]
fn bad_files_are_errors() {
    let dir = std::env::temp_dir().join("snee_bitmap_formats");
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in [
        ("trunc.pfm", b"PF\n4 4\n-1.0\n\x00\x00".to_vec()),
        ("zero_scale.pfm", b"PF\n1 1\n0\n\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00".to_vec()),
        ("bad.jpg", vec![0xff, 0xd8, 0xff, 0x00, 0x01]),
        ("bad.hdr", b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 2 +X 2\n".to_vec()),
        ("bad.bmp", b"BM\x00\x00".to_vec()),
        ("unknown.xyz", b"hello".to_vec()),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let e = read_image(&path, true).expect_err(name);
        assert!(e.msg.contains(name) || e.to_string().contains(name), "{name}: {}", e);
    }
}

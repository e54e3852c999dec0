//! Textures against Mitsuba 3.9, and the image reader (EXR: half/float, PIZ/ZIP/RLE/none, RGB(A)/Y;
//! PNG: 8/16 bit, grey/RGB(A); bad files).
//!
//! Reference numbers in `tests/data/textures.json`, written by `scripts/emitter_expected.py` (which
//! writes the images in `tests/data/` too):
//!
//! ```python
//! t = mi.load_dict({"type": "bitmap", "filename": "tests/data/tex_rgb8.png", "filter_type": ft, "wrap_mode": wm})
//! si = mi.SurfaceInteraction3f(); si.uv = mi.Point2f(uv); t.eval(si); t.mean()
//! ```
//! Mitsuba stores 8-bit textures in half precision, hence a relative tolerance of 1e-3 for PNG data.

use crate::{data_dir, mitsuba_json, num, rows4, transform, vec2, vec3};
use serde_json::Value as Json;
use snee::color::{luminance, Spectrum};
use snee::io::read::{read_image, srgb_to_linear_value, Bitmap};
use snee::math::Vec2;
use snee::scene::desc::{ObjectDesc, PluginKind, Props, Value};
use snee::scene::resolver::FileResolver;
use snee::scene::SrcPos;
use snee::texture::Texture;
use std::path::{Path, PathBuf};

// ---- Helpers ----

fn resolver() -> FileResolver {
    FileResolver { paths: vec![data_dir(), scratch_dir()] }
}

/// A per-process folder for files the tests write.
fn scratch_dir() -> PathBuf {
    let d = std::env::temp_dir().join(format!("snee_textures_test_{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn desc(plugin: &str, props: Vec<(&str, Value)>) -> ObjectDesc {
    let pos = SrcPos::new("scene.xml", 7, 3);
    let mut p = Props::new(PluginKind::Texture, plugin, pos.clone());
    for (i, (name, v)) in props.into_iter().enumerate() {
        p.push(name, v, SrcPos::new("scene.xml", 8 + i as u32, 5)).unwrap();
    }
    ObjectDesc { kind: PluginKind::Texture, plugin: plugin.to_string(), id: None, pos, props: p }
}

fn texture(plugin: &str, props: Vec<(&str, Value)>) -> Texture {
    Texture::from_desc(&desc(plugin, props), &resolver()).unwrap_or_else(|e| panic!("{e}"))
}

fn texture_err(plugin: &str, props: Vec<(&str, Value)>) -> String {
    Texture::from_desc(&desc(plugin, props), &resolver()).unwrap_err().to_string()
}

fn s(v: &str) -> Value {
    Value::String(v.into())
}

/// `t` at each of `uvs` against Mitsuba's values `want` (JSON arrays of 2- and 3-vectors).
#[track_caller]
fn check_values(t: &Texture, uvs: &Json, want: &Json, rel: f32, what: &str) {
    let (uvs, want) = (uvs.as_array().unwrap(), want.as_array().unwrap());
    assert_eq!(uvs.len(), want.len());
    for (uv, w) in uvs.iter().zip(want) {
        let (uv, w) = (vec2(uv), vec3(w));
        let got = t.eval(uv);
        let err = (got - w).abs().max_element();
        assert!(err <= rel * w.abs().max_element().max(1e-3), "{what} at uv {uv:?}: got {got}, Mitsuba {w}");
    }
}

/// Mitsuba's values (`tests/data/textures.json`, from `scripts/emitter_expected.py`).
fn mitsuba_values() -> Json {
    mitsuba_json("textures.json")
}

#[test]
fn checkerboard_matches_mitsuba() {
    let m = mitsuba_values();
    let t = texture("checkerboard", vec![]);
    check_values(&t, &m["checker_uvs"], &m["checker_default"], 1e-6, "checkerboard default");
    assert!((t.mean() - Spectrum::splat(0.3)).abs().max_element() < 1e-6);
    let t = texture(
        "checkerboard",
        vec![
            ("color0", Value::Rgb([0.9, 0.5, 0.1].into())),
            ("color1", Value::Rgb([0.05, 0.1, 0.7].into())),
            ("to_uv", transform(rows4(&m["checker_to_uv"]))),
        ],
    );
    check_values(&t, &m["checker_uvs"], &m["checker_custom"], 1e-6, "checkerboard custom");
}

#[test]
fn nested_checkerboard_evaluates_inner_texture_at_the_same_uv() {
    let inner = std::rc::Rc::new(desc("bitmap", vec![("filename", s("tex_rgb8.png")), ("filter_type", s("nearest"))]));
    let t = texture("checkerboard", vec![("color1", Value::Object(inner.clone())), ("color0", Value::Float(0.5))]);
    let bitmap = Texture::from_desc(&inner, &resolver()).unwrap();
    // uv (0.6, 0.3): fractional parts 0.6 > ½, 0.3 ≤ ½ → color1.
    let uv = Vec2::new(0.6, 0.3);
    assert_eq!(t.eval(uv), bitmap.eval(uv));
    assert_eq!(t.eval(Vec2::new(0.1, 0.1)), Spectrum::splat(0.5));
    assert!((t.mean() - 0.5 * (Spectrum::splat(0.5) + bitmap.mean())).abs().max_element() < 1e-6);
}

#[test]
fn bitmap_png_matches_mitsuba() {
    let m = mitsuba_values();
    for ft in ["bilinear", "nearest"] {
        for wm in ["repeat", "mirror", "clamp"] {
            let t =
                texture("bitmap", vec![("filename", s("tex_rgb8.png")), ("filter_type", s(ft)), ("wrap_mode", s(wm))]);
            let want = &m[format!("bitmap_{ft}_{wm}")];
            check_values(&t, &m["uvs"], &want["values"], 1e-3, &format!("bitmap {ft} {wm}"));
            assert!((luminance(t.mean()) - num(&want["mean"])).abs() < 2e-4, "mean {}", luminance(t.mean()));
        }
    }
    let t = texture("bitmap", vec![("filename", s("tex_rgb8.png")), ("raw", Value::Bool(true))]);
    check_values(&t, &m["uvs"], &m["bitmap_raw"]["values"], 1e-3, "bitmap raw");
    assert!((luminance(t.mean()) - num(&m["bitmap_raw"]["mean"])).abs() < 2e-4);
    let to_uv = transform(rows4(&m["bitmap_uv_matrix"]));
    let t = texture("bitmap", vec![("filename", s("tex_rgb8.png")), ("to_uv", to_uv)]);
    check_values(&t, &m["uvs"], &m["bitmap_to_uv"]["values"], 1e-3, "bitmap to_uv");
}

#[test]
fn bitmap_exr_matches_mitsuba() {
    let m = mitsuba_values();
    let t = texture("bitmap", vec![("filename", s("tex_y_float.exr"))]);
    check_values(&t, &m["uvs"], &m["bitmap_tex_y_float"]["values"], 1e-5, "bitmap Y float");
    assert!((luminance(t.mean()) - num(&m["bitmap_tex_y_float"]["mean"])).abs() < 1e-5);
    let t = texture(
        "bitmap",
        vec![("filename", s("tex_rgba_float.exr")), ("format", s("variant")), ("accel", Value::Bool(false))],
    );
    check_values(&t, &m["uvs"], &m["bitmap_tex_rgba_float"]["values"], 1e-5, "bitmap RGBA float");
    assert!((luminance(t.mean()) - num(&m["bitmap_tex_rgba_float"]["mean"])).abs() < 1e-6);
}

#[test]
fn bad_texture_descriptions_are_errors_with_positions() {
    let e = texture_err("noise", vec![]);
    assert!(e.starts_with("scene.xml:7:3:") && e.contains("bitmap, checkerboard"), "{e}");
    let e = texture_err("bitmap", vec![("filename", s("tex_rgb8.png")), ("wrap_mode", s("wrap"))]);
    assert!(e.starts_with("scene.xml:9:5:") && e.contains("repeat"), "{e}");
    let e = texture_err("bitmap", vec![("filename", s("tex_rgb8.png")), ("filter_type", s("cubic"))]);
    assert!(e.starts_with("scene.xml:9:5:") && e.contains("nearest"), "{e}");
    let e = texture_err("bitmap", vec![("filename", s("nope.png"))]);
    assert!(e.starts_with("scene.xml:8:5:") && e.contains("nope.png"), "{e}");
    let e = texture_err("bitmap", vec![("filename", s("tex_rgb8.png")), ("gamma", Value::Float(2.2))]);
    assert!(e.contains("gamma"), "{e}");
    let e = texture_err("checkerboard", vec![("color0", Value::Rgb([1.5, 0.0, 0.0].into()))]);
    assert!(e.contains("outside [0, 1]"), "{e}");
}

// ---- Reader: files written by Mitsuba ----

#[test]
fn reads_mitsubas_half_piz_exr_by_channel_name() {
    let b = read_image(&data_dir().join("envmap_half_piz.exr"), true).unwrap();
    assert_eq!((b.width, b.height), (12, 6));
    assert_eq!(b.channels, vec!["B", "G", "R"], "Mitsuba stores B, G, R");
    for y in 0..6 {
        for x in 0..12 {
            let (xf, yf) = (x as f32, y as f32);
            let mut want = Spectrum::new(0.1 + 0.05 * xf + 0.2 * yf, 0.3 + 0.1 * yf, 1.0 + 0.02 * xf * yf);
            if (x, y) == (3, 1) {
                want = Spectrum::new(40.0, 30.0, 20.0);
            }
            let got = b.rgb(x, y);
            assert!((got - want).abs().max_element() <= 1e-3 * want.max_element(), "({x}, {y}): {got} vs {want}");
        }
    }
}

#[test]
fn reads_float_exr_y_and_rgba() {
    let b = read_image(&data_dir().join("tex_y_float.exr"), false).unwrap();
    assert_eq!(b.channels, vec!["Y"]);
    for y in 0..2 {
        for x in 0..3 {
            assert_eq!(b.rgb(x, y), Spectrum::splat(0.25 * (x as f32 + 1.0) + y as f32));
        }
    }
    let b = read_image(&data_dir().join("tex_rgba_float.exr"), false).unwrap();
    let a = b.channel("A").unwrap();
    for y in 0..2 {
        for x in 0..3 {
            let want = Spectrum::new(0.1 * x as f32, 0.2 * y as f32 + 0.05, 0.3);
            assert!((b.rgb(x, y) - want).abs().max_element() < 1e-7);
            assert!((b.data[(y * 3 + x) * 4 + a] - (0.5 + 0.1 * x as f32)).abs() < 1e-7);
        }
    }
}

#[test]
fn reads_srgb_png() {
    let lin = read_image(&data_dir().join("tex_rgb8.png"), true).unwrap();
    let raw = read_image(&data_dir().join("tex_rgb8.png"), false).unwrap();
    assert_eq!(lin.channels, vec!["R", "G", "B"]);
    for y in 0..3 {
        for x in 0..4 {
            let bytes = [x * 60 + 10, y * 100 + 20, (x * y * 37 + 5) % 256];
            let want_raw = Spectrum::from_array(bytes.map(|v| v as f32 / 255.0));
            assert_eq!(raw.rgb(x as usize, y as usize), want_raw);
            let want_lin = Spectrum::from_array(bytes.map(|v| srgb_to_linear_value(v as f32 / 255.0)));
            assert_eq!(lin.rgb(x as usize, y as usize), want_lin);
        }
    }
}

// ---- Reader: every compression and sample type ----

fn write_exr(
    path: &Path,
    compression: exr::prelude::Compression,
    half: bool,
    channels: &[(&str, Vec<f32>)],
    w: usize,
    h: usize,
) {
    use exr::prelude::*;
    let list: Vec<AnyChannel<FlatSamples>> = channels
        .iter()
        .map(|(name, v)| {
            let samples = if half {
                FlatSamples::F16(v.iter().map(|&x| f16::from_f32(x)).collect())
            } else {
                FlatSamples::F32(v.clone())
            };
            AnyChannel::new(*name, samples)
        })
        .collect();
    let layer = Layer::new(
        (w, h),
        LayerAttributes::named(""),
        Encoding { compression, ..Encoding::default() },
        AnyChannels::sort(SmallVec::from_vec(list)),
    );
    Image::from_layer(layer).write().to_file(path).unwrap();
}

#[test]
fn reads_exr_with_every_lossless_compression() {
    use exr::prelude::Compression;
    let (w, h) = (37, 19); // odd sizes cross block boundaries
    let f = |c: usize| -> Vec<f32> { (0..w * h).map(|i| ((i * (c + 3)) % 101) as f32 * 0.125 + c as f32).collect() };
    let dir = scratch_dir();
    for (k, compression) in
        [Compression::Uncompressed, Compression::RLE, Compression::ZIP1, Compression::ZIP16, Compression::PIZ]
            .into_iter()
            .enumerate()
    {
        for half in [false, true] {
            let path = dir.join(format!("c{k}_{half}.exr"));
            write_exr(&path, compression, half, &[("R", f(0)), ("G", f(1)), ("B", f(2)), ("A", f(3))], w, h);
            let b = read_image(&path, true).unwrap_or_else(|e| panic!("{compression:?} half={half}: {e}"));
            assert_eq!((b.width, b.height), (w, h));
            assert_eq!(b.channels, vec!["A", "B", "G", "R"]);
            for i in [0, 1, w, w * h / 2, w * h - 1] {
                let want = Spectrum::new(f(0)[i], f(1)[i], f(2)[i]); // multiples of 1/8 below 16: exact in half
                assert_eq!(b.rgb(i % w, i / w), want, "{compression:?} half={half} pixel {i}");
            }
        }
    }
    // Luminance only.
    let path = dir.join("y_zip.exr");
    write_exr(&path, Compression::ZIP16, true, &[("Y", f(5))], w, h);
    let b = read_image(&path, false).unwrap();
    assert_eq!(b.rgb(3, 4), Spectrum::splat(f(5)[4 * w + 3]));
}

#[test]
fn reads_png_grey_and_16_bit() {
    let dir = scratch_dir();
    let g16: Vec<u16> = vec![0, 1000, 65535, 30000, 5, 40000];
    let p = dir.join("grey16.png");
    image::ImageBuffer::<image::Luma<u16>, _>::from_raw(3, 2, g16.clone()).unwrap().save(&p).unwrap();
    let b = read_image(&p, false).unwrap();
    assert_eq!(b.channels, vec!["Y"]);
    assert_eq!(b.rgb(1, 0), Spectrum::splat(1000.0 / 65535.0));
    let b = read_image(&p, true).unwrap();
    assert_eq!(b.rgb(2, 1), Spectrum::splat(srgb_to_linear_value(40000.0 / 65535.0)));

    let ga: Vec<u8> = vec![10, 255, 200, 128];
    let p = dir.join("grey_alpha.png");
    image::ImageBuffer::<image::LumaA<u8>, _>::from_raw(2, 1, ga).unwrap().save(&p).unwrap();
    let b = read_image(&p, true).unwrap();
    assert_eq!(b.channels, vec!["Y", "A"]);
    assert_eq!(b.rgb(1, 0), Spectrum::splat(srgb_to_linear_value(200.0 / 255.0)));
    assert_eq!(b.data[3], 128.0 / 255.0, "alpha stays linear");

    let rgba: Vec<u16> = vec![100, 200, 300, 65535, 0, 65535, 1, 2];
    let p = dir.join("rgba16.png");
    image::ImageBuffer::<image::Rgba<u16>, _>::from_raw(2, 1, rgba).unwrap().save(&p).unwrap();
    let b = read_image(&p, false).unwrap();
    assert_eq!(b.channels, vec!["R", "G", "B", "A"]);
    assert_eq!(b.rgb(1, 0), Spectrum::new(0.0, 1.0, 1.0 / 65535.0));

    // A grey PNG as a texture gives grey.
    let t = texture(
        "bitmap",
        vec![("filename", s("grey16.png")), ("raw", Value::Bool(true)), ("filter_type", s("nearest"))],
    );
    assert_eq!(t.eval(Vec2::new(0.5, 0.25)), Spectrum::splat(1000.0 / 65535.0));
}

// ---- Reader: bad files ----

#[test]
fn bad_images_are_errors_naming_the_file() {
    let dir = scratch_dir();
    let missing = dir.join("missing.exr");
    let e = read_image(&missing, true).unwrap_err().to_string();
    assert!(e.contains("missing.exr") && e.contains("cannot read"), "{e}");

    let junk = dir.join("junk.exr");
    std::fs::write(&junk, b"not an image at all").unwrap();
    let e = read_image(&junk, true).unwrap_err().to_string();
    assert!(e.contains("junk.exr") && e.contains("unsupported image format"), "{e}");

    let good = std::fs::read(data_dir().join("envmap_half_piz.exr")).unwrap();
    let cut = dir.join("truncated.exr");
    std::fs::write(&cut, &good[..good.len() / 2]).unwrap();
    let e = read_image(&cut, true).unwrap_err().to_string();
    assert!(e.contains("truncated.exr") && e.contains("OpenEXR"), "{e}");

    let good = std::fs::read(data_dir().join("tex_rgb8.png")).unwrap();
    let cut = dir.join("truncated.png");
    std::fs::write(&cut, &good[..good.len() - 20]).unwrap();
    let e = read_image(&cut, true).unwrap_err().to_string();
    assert!(e.contains("truncated.png") && e.contains("PNG"), "{e}");
}

#[test]
fn wrong_channels_and_bad_values_are_errors() {
    use exr::prelude::Compression;
    let dir = scratch_dir();
    write_exr(&dir.join("depth.exr"), Compression::ZIP16, false, &[("Z", vec![1.0; 6])], 3, 2);
    let e = texture_err("bitmap", vec![("filename", s("depth.exr"))]);
    assert!(e.starts_with("scene.xml:8:5:") && e.contains("[Z]") && e.contains("depth.exr"), "{e}");

    let mut r = vec![0.5f32; 6];
    r[4] = f32::NAN;
    write_exr(
        &dir.join("nan.exr"),
        Compression::Uncompressed,
        false,
        &[("R", r), ("G", vec![0.5; 6]), ("B", vec![0.5; 6])],
        3,
        2,
    );
    let e = texture_err("bitmap", vec![("filename", s("nan.exr"))]);
    assert!(e.starts_with("scene.xml:8:5:") && e.contains("pixel (1, 1)"), "{e}");

    let mut g = vec![0.5f32; 6];
    g[2] = -0.25;
    write_exr(
        &dir.join("neg.exr"),
        Compression::Uncompressed,
        false,
        &[("R", vec![0.5; 6]), ("G", g), ("B", vec![0.5; 6])],
        2,
        3,
    );
    let e = texture_err("bitmap", vec![("filename", s("neg.exr"))]);
    assert!(e.contains("pixel (0, 1)") && e.contains("-0.25"), "{e}");

    let b = Bitmap { width: 1, height: 1, channels: vec!["Z".into()], data: vec![1.0] };
    assert!(b.color_layout().is_none());
}

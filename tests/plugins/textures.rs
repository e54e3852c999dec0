//! Textures against Mitsuba 3.9, and the image reader (EXR: half/float, PIZ/ZIP/RLE/none, RGB(A)/Y;
//! PNG: 8/16 bit, grey/RGB(A); bad files).
//!
//! Reference numbers from `scripts/emitter_expected.py` (which writes the images in `tests/data/`):
//!
//! ```python
//! t = mi.load_dict({"type": "bitmap", "filename": "tests/data/tex_rgb8.png", "filter_type": ft, "wrap_mode": wm})
//! si = mi.SurfaceInteraction3f(); si.uv = mi.Point2f(uv); t.eval(si); t.mean()
//! ```
//! Mitsuba stores 8-bit textures in half precision, hence a relative tolerance of 1e-3 for PNG data.

// The reference numbers are pasted as Mitsuba printed them (9 significant digits).
#![allow(clippy::excessive_precision)]

use snee::color::{luminance, Spectrum};
use snee::io::read::{read_image, srgb_to_linear_value, Bitmap};
use snee::math::Vec2;
use snee::scene::desc::{ObjectDesc, PluginKind, Props, Value};
use snee::scene::resolver::FileResolver;
use snee::scene::SrcPos;
use snee::texture::Texture;
use std::path::{Path, PathBuf};

// ---- Helpers ----

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data")
}

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

fn transform(rows: [[f64; 4]; 4]) -> Value {
    Value::Transform(glam::DMat4::from_cols_array_2d(&rows).transpose())
}

#[track_caller]
fn check_values(t: &Texture, uvs: &[[f32; 2]], want: &[[f32; 3]], rel: f32, what: &str) {
    assert_eq!(uvs.len(), want.len());
    for (uv, w) in uvs.iter().zip(want) {
        let got = t.eval(Vec2::from_array(*uv));
        let w = Spectrum::from_array(*w);
        let err = (got - w).abs().max_element();
        assert!(err <= rel * w.abs().max_element().max(1e-3), "{what} at uv {uv:?}: got {got}, Mitsuba {w}");
    }
}

// ---- Values from Mitsuba (scripts/emitter_expected.py) ----

const UVS: &[[f32; 2]] = &[
    [1.000000000e-01, 1.000000000e-01],
    [6.000000000e-01, 3.000000000e-01],
    [-3.000000000e-01, 1.200000000e+00],
    [1.250000000e-01, 1.666666667e-01],
    [9.900000000e-01, 5.100000000e-01],
    [1.700000000e+00, -4.500000000e-01],
    [5.000000000e-01, 5.000000000e-01],
];
const CHECKER_TO_UV: [[f64; 4]; 4] = [
    [3.000000000e+00, 0.000000000e+00, 0.000000000e+00, 3.000000119e-01],
    [0.000000000e+00, 2.000000000e+00, 0.000000000e+00, 4.000000060e-01],
    [0.000000000e+00, 0.000000000e+00, 1.000000000e+00, 0.000000000e+00],
    [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00],
];
const CHECKER_UVS: &[[f32; 2]] = &[
    [1.000000000e-01, 1.000000000e-01],
    [6.000000000e-01, 3.000000000e-01],
    [-3.000000000e-01, 1.200000000e+00],
    [1.250000000e-01, 1.666666667e-01],
    [9.900000000e-01, 5.100000000e-01],
    [1.700000000e+00, -4.500000000e-01],
    [5.000000000e-01, 5.000000000e-01],
    [2.500000000e-01, 7.500000000e-01],
    [7.500000000e-01, 7.500000000e-01],
    [5.000000000e-01, 2.500000000e-01],
    [0.000000000e+00, 0.000000000e+00],
    [5.000000000e-01, 5.000000000e-01],
    [5.000100000e-01, 4.999900000e-01],
];
// checkerboard default
const CHECKER_DEFAULT: &[[f32; 3]] = &[
    [4.000000060e-01, 4.000000060e-01, 4.000000060e-01],
    [2.000000030e-01, 2.000000030e-01, 2.000000030e-01],
    [2.000000030e-01, 2.000000030e-01, 2.000000030e-01],
    [4.000000060e-01, 4.000000060e-01, 4.000000060e-01],
    [4.000000060e-01, 4.000000060e-01, 4.000000060e-01],
    [4.000000060e-01, 4.000000060e-01, 4.000000060e-01],
    [4.000000060e-01, 4.000000060e-01, 4.000000060e-01],
    [2.000000030e-01, 2.000000030e-01, 2.000000030e-01],
    [4.000000060e-01, 4.000000060e-01, 4.000000060e-01],
    [4.000000060e-01, 4.000000060e-01, 4.000000060e-01],
    [4.000000060e-01, 4.000000060e-01, 4.000000060e-01],
    [4.000000060e-01, 4.000000060e-01, 4.000000060e-01],
    [2.000000030e-01, 2.000000030e-01, 2.000000030e-01],
];
// checkerboard custom
const CHECKER_CUSTOM: &[[f32; 3]] = &[
    [8.999999762e-01, 5.000000000e-01, 1.000000015e-01],
    [8.999999762e-01, 5.000000000e-01, 1.000000015e-01],
    [5.000000075e-02, 1.000000015e-01, 6.999999881e-01],
    [8.999999762e-01, 5.000000000e-01, 1.000000015e-01],
    [8.999999762e-01, 5.000000000e-01, 1.000000015e-01],
    [8.999999762e-01, 5.000000000e-01, 1.000000015e-01],
    [5.000000075e-02, 1.000000015e-01, 6.999999881e-01],
    [5.000000075e-02, 1.000000015e-01, 6.999999881e-01],
    [8.999999762e-01, 5.000000000e-01, 1.000000015e-01],
    [8.999999762e-01, 5.000000000e-01, 1.000000015e-01],
    [8.999999762e-01, 5.000000000e-01, 1.000000015e-01],
    [5.000000075e-02, 1.000000015e-01, 6.999999881e-01],
    [5.000000075e-02, 1.000000015e-01, 6.999999881e-01],
];
const BITMAP_UV_MATRIX: [[f64; 4]; 4] = [
    [2.000000000e+00, 0.000000000e+00, 0.000000000e+00, 6.000000238e-01],
    [0.000000000e+00, 5.000000000e-01, 0.000000000e+00, 0.000000000e+00],
    [0.000000000e+00, 0.000000000e+00, 1.000000000e+00, 0.000000000e+00],
    [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00],
];
// bitmap tex_rgb8.png {'filter_type': 'bilinear', 'wrap_mode': 'repeat'}: mean = 2.684369385e-01
const BITMAP_BILINEAR_REPEAT: &[[f32; 3]] = &[
    [5.422353745e-02, 1.487350166e-01, 1.685030572e-02],
    [2.070297152e-01, 7.932554930e-02, 2.998420969e-02],
    [3.107348680e-01, 2.507796139e-02, 1.207843050e-02],
    [3.035269910e-03, 6.995401811e-03, 1.517634955e-03],
    [2.794518173e-01, 2.036569268e-01, 1.046224385e-01],
    [3.107349277e-01, 2.670017481e-01, 1.590709090e-01],
    [1.422369778e-01, 1.878207624e-01, 5.067041516e-02],
];
// bitmap tex_rgb8.png {'filter_type': 'bilinear', 'wrap_mode': 'mirror'}: mean = 2.684369385e-01
const BITMAP_BILINEAR_MIRROR: &[[f32; 3]] = &[
    [3.035269910e-03, 6.995399017e-03, 1.517634955e-03],
    [2.070297152e-01, 7.932554930e-02, 2.998420969e-02],
    [4.378283024e-02, 6.629061699e-01, 5.133412778e-02],
    [3.035269910e-03, 6.995401811e-03, 1.517634955e-03],
    [5.149178505e-01, 2.036569268e-01, 1.924524754e-01],
    [4.378281906e-02, 1.606969535e-01, 1.439088490e-02],
    [1.422369778e-01, 1.878207624e-01, 5.067041516e-02],
];
// bitmap tex_rgb8.png {'filter_type': 'bilinear', 'wrap_mode': 'clamp'}: mean = 2.684369385e-01
const BITMAP_BILINEAR_CLAMP: &[[f32; 3]] = &[
    [3.035269910e-03, 6.995399017e-03, 1.517634955e-03],
    [2.070297152e-01, 7.932554930e-02, 2.998420969e-02],
    [3.035269678e-03, 7.156935334e-01, 1.517634839e-03],
    [3.035269910e-03, 6.995401811e-03, 1.517634955e-03],
    [5.149178505e-01, 2.036569268e-01, 1.924524754e-01],
    [5.149178505e-01, 6.995399483e-03, 1.517635072e-03],
    [1.422369778e-01, 1.878207624e-01, 5.067041516e-02],
];
// bitmap tex_rgb8.png {'filter_type': 'nearest', 'wrap_mode': 'repeat'}: mean = 2.684369385e-01
const BITMAP_NEAREST_REPEAT: &[[f32; 3]] = &[
    [3.035269910e-03, 6.995399017e-03, 1.517634955e-03],
    [2.232278883e-01, 6.995399017e-03, 1.517634955e-03],
    [2.232278883e-01, 6.995399017e-03, 1.517634955e-03],
    [3.035269910e-03, 6.995399017e-03, 1.517634955e-03],
    [5.149178505e-01, 1.878207624e-01, 1.746473908e-01],
    [2.232278883e-01, 1.878207624e-01, 7.818747312e-02],
    [2.232278883e-01, 1.878207624e-01, 7.818747312e-02],
];
// bitmap tex_rgb8.png {'filter_type': 'nearest', 'wrap_mode': 'mirror'}: mean = 2.684369385e-01
const BITMAP_NEAREST_MIRROR: &[[f32; 3]] = &[
    [3.035269910e-03, 6.995399017e-03, 1.517634955e-03],
    [2.232278883e-01, 6.995399017e-03, 1.517634955e-03],
    [6.124606729e-02, 7.156935930e-01, 7.818747312e-02],
    [3.035269910e-03, 6.995399017e-03, 1.517634955e-03],
    [5.149178505e-01, 1.878207624e-01, 1.746473908e-01],
    [6.124606729e-02, 1.878207624e-01, 2.315335535e-02],
    [2.232278883e-01, 1.878207624e-01, 7.818747312e-02],
];
// bitmap tex_rgb8.png {'filter_type': 'nearest', 'wrap_mode': 'clamp'}: mean = 2.684369385e-01
const BITMAP_NEAREST_CLAMP: &[[f32; 3]] = &[
    [3.035269910e-03, 6.995399017e-03, 1.517634955e-03],
    [2.232278883e-01, 6.995399017e-03, 1.517634955e-03],
    [3.035269910e-03, 7.156935930e-01, 1.517634955e-03],
    [3.035269910e-03, 6.995399017e-03, 1.517634955e-03],
    [5.149178505e-01, 1.878207624e-01, 1.746473908e-01],
    [5.149178505e-01, 6.995399017e-03, 1.517634955e-03],
    [2.232278883e-01, 1.878207624e-01, 7.818747312e-02],
];
// bitmap tex_rgb8.png {'raw': True}: mean = 4.370687306e-01
const BITMAP_RAW: &[[f32; 3]] = &[
    [1.098039374e-01, 2.352941036e-01, 3.701961040e-02],
    [4.862745702e-01, 2.352941483e-01, 1.298823804e-01],
    [5.803921819e-01, 1.176471263e-01, 5.298044160e-02],
    [3.921568766e-02, 7.843138278e-02, 1.960784383e-02],
    [4.203921258e-01, 4.823529422e-01, 2.617183924e-01],
    [5.803922415e-01, 5.294118524e-01, 4.033922553e-01],
    [3.921568990e-01, 4.705882668e-01, 2.372549176e-01],
];
// bitmap tex_rgb8.png {'to_uv': 'BITMAP_UV_MATRIX'}: mean = 2.684369385e-01
const BITMAP_TO_UV: &[[f32; 3]] = &[
    [4.274108708e-01, 2.550398111e-01, 2.226309031e-01],
    [4.274109602e-01, 4.243027419e-02, 3.310522065e-02],
    [2.589765787e-01, 3.461826444e-01, 1.771080941e-01],
    [4.857488871e-01, 1.841699481e-01, 1.819359064e-01],
    [1.940711141e-01, 5.491411686e-02, 1.921000890e-02],
    [2.589765787e-01, 6.233158708e-01, 3.329028189e-01],
    [2.070297301e-01, 5.220174044e-02, 1.930924319e-02],
];
// bitmap tex_y_float.exr: mean = 1.000000000e+00
const BITMAP_TEX_Y_FLOAT: &[[f32; 3]] = &[
    [6.499999762e-01, 6.499999762e-01, 6.499999762e-01],
    [6.750000715e-01, 6.750000715e-01, 6.750000715e-01],
    [7.499998808e-01, 7.499998808e-01, 7.499998808e-01],
    [4.791666269e-01, 4.791666269e-01, 4.791666269e-01],
    [1.034999967e+00, 1.034999967e+00, 1.034999967e+00],
    [1.250000119e+00, 1.250000119e+00, 1.250000119e+00],
    [1.000000000e+00, 1.000000000e+00, 1.000000000e+00],
];
// bitmap tex_rgba_float.exr: mean = 1.501917988e-01
const BITMAP_TEX_RGBA_FLOAT: &[[f32; 3]] = &[
    [3.999999911e-02, 1.099999994e-01, 3.000000119e-01],
    [1.300000101e-01, 7.000000030e-02, 3.000000119e-01],
    [1.599999964e-01, 6.999997795e-02, 3.000000119e-01],
    [2.500000037e-02, 8.333332092e-02, 3.000000119e-01],
    [1.059999913e-01, 1.539999992e-01, 3.000000119e-01],
    [1.600000411e-01, 1.700000167e-01, 3.000000119e-01],
    [1.000000015e-01, 1.500000060e-01, 3.000000119e-01],
];

#[test]
fn checkerboard_matches_mitsuba() {
    let t = texture("checkerboard", vec![]);
    check_values(&t, CHECKER_UVS, CHECKER_DEFAULT, 1e-6, "checkerboard default");
    assert!((t.mean() - Spectrum::splat(0.3)).abs().max_element() < 1e-6);
    let t = texture(
        "checkerboard",
        vec![
            ("color0", Value::Rgb([0.9, 0.5, 0.1].into())),
            ("color1", Value::Rgb([0.05, 0.1, 0.7].into())),
            ("to_uv", transform(CHECKER_TO_UV)),
        ],
    );
    check_values(&t, CHECKER_UVS, CHECKER_CUSTOM, 1e-6, "checkerboard custom");
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
    let cases: &[(&str, &str, &[[f32; 3]])] = &[
        ("bilinear", "repeat", BITMAP_BILINEAR_REPEAT),
        ("bilinear", "mirror", BITMAP_BILINEAR_MIRROR),
        ("bilinear", "clamp", BITMAP_BILINEAR_CLAMP),
        ("nearest", "repeat", BITMAP_NEAREST_REPEAT),
        ("nearest", "mirror", BITMAP_NEAREST_MIRROR),
        ("nearest", "clamp", BITMAP_NEAREST_CLAMP),
    ];
    for &(ft, wm, want) in cases {
        let t = texture("bitmap", vec![("filename", s("tex_rgb8.png")), ("filter_type", s(ft)), ("wrap_mode", s(wm))]);
        check_values(&t, UVS, want, 1e-3, &format!("bitmap {ft} {wm}"));
        assert!((luminance(t.mean()) - 2.684369385e-01).abs() < 2e-4, "mean {}", luminance(t.mean()));
    }
    let t = texture("bitmap", vec![("filename", s("tex_rgb8.png")), ("raw", Value::Bool(true))]);
    check_values(&t, UVS, BITMAP_RAW, 1e-3, "bitmap raw");
    assert!((luminance(t.mean()) - 4.370687306e-01).abs() < 2e-4);
    let t = texture("bitmap", vec![("filename", s("tex_rgb8.png")), ("to_uv", transform(BITMAP_UV_MATRIX))]);
    check_values(&t, UVS, BITMAP_TO_UV, 1e-3, "bitmap to_uv");
}

#[test]
fn bitmap_exr_matches_mitsuba() {
    let t = texture("bitmap", vec![("filename", s("tex_y_float.exr"))]);
    check_values(&t, UVS, BITMAP_TEX_Y_FLOAT, 1e-5, "bitmap Y float");
    assert!((luminance(t.mean()) - 1.0).abs() < 1e-5);
    let t = texture(
        "bitmap",
        vec![("filename", s("tex_rgba_float.exr")), ("format", s("variant")), ("accel", Value::Bool(false))],
    );
    check_values(&t, UVS, BITMAP_TEX_RGBA_FLOAT, 1e-5, "bitmap RGBA float");
    assert!((luminance(t.mean()) - 1.501917988e-01).abs() < 1e-6);
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

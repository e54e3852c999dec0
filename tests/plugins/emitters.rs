//! Emitters against Mitsuba 3.9 and their samplers against their pdfs.
//!
//! The reference numbers come from `scripts/emitter_expected.py` (which also writes the images in
//! `tests/data/`), e.g. for the envmap:
//!
//! ```python
//! env = mi.load_dict({"type": "envmap", "filename": "tests/data/envmap_half_piz.exr", "scale": 1.5,
//!                     "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], 30).rotate([1, 0, 0], 20)})
//! si = mi.SurfaceInteraction3f(); si.wi = -mi.Vector3f(d); env.eval(si)
//! ```
//! and for the delta lights `emitter.sample_direction(it, [0.5, 0.5])` with `it.p` the reference point.

// The reference numbers are pasted as Mitsuba printed them (9 significant digits).
#![allow(clippy::excessive_precision)]

use snee::color::{luminance, Spectrum};
use snee::emitter::{Emitter, EnvironmentEmitter};
use snee::interaction::DirectionSample;
use snee::math::{Mat4, Vec2, Vec3};
use snee::scene::desc::{ObjectDesc, PluginKind, Props, Value};
use snee::scene::resolver::FileResolver;
use snee::scene::SrcPos;
use snee::testing::chi2::{chi2_sphere, sidak};
use std::path::PathBuf;

// ---- Helpers ----

fn resolver() -> FileResolver {
    FileResolver { paths: vec![PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/data")] }
}

fn desc(plugin: &str, props: Vec<(&str, Value)>) -> ObjectDesc {
    let pos = SrcPos::new("scene.xml", 3, 5);
    let mut p = Props::new(PluginKind::Emitter, plugin, pos.clone());
    for (i, (name, v)) in props.into_iter().enumerate() {
        p.push(name, v, SrcPos::new("scene.xml", 4 + i as u32, 9)).unwrap();
    }
    ObjectDesc { kind: PluginKind::Emitter, plugin: plugin.to_string(), id: None, pos, props: p }
}

fn emitter(plugin: &str, props: Vec<(&str, Value)>) -> Emitter {
    Emitter::from_desc(&desc(plugin, props), &resolver()).unwrap_or_else(|e| panic!("{e}"))
}

/// A transform property from Mitsuba's row-major matrix.
fn transform(rows: [[f64; 4]; 4]) -> Value {
    Value::Transform(glam::DMat4::from_cols_array_2d(&rows).transpose())
}

fn rgb(v: [f64; 3]) -> Value {
    Value::Rgb(glam::DVec3::from_array(v))
}

fn v3(a: [f32; 3]) -> Vec3 {
    Vec3::from_array(a)
}

#[track_caller]
fn assert_close(got: Vec3, want: Vec3, rel: f32, what: &str) {
    let err = (got - want).abs().max_element();
    assert!(err <= rel * want.abs().max_element().max(1e-3), "{what}: got {got}, Mitsuba {want}");
}

// ---- Values from Mitsuba (scripts/emitter_expected.py) ----

const ENV_TO_WORLD: [[f64; 4]; 4] = [
    [8.660253882e-01, 1.710100621e-01, 4.698463380e-01, 0.000000000e+00],
    [0.000000000e+00, 9.396926761e-01, -3.420201242e-01, 0.000000000e+00],
    [-5.000000000e-01, 2.961980999e-01, 8.137977123e-01, 0.000000000e+00],
    [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00],
];
const ENV_EVAL: &[([f32; 3], [f32; 3])] = &[
    ([0.000000000e+00, 0.000000000e+00, 1.000000000e+00], [1.247785926e+00, 7.532140017e-01, 1.897720456e+00]),
    ([0.000000000e+00, 1.000000000e+00, 0.000000000e+00], [7.291868329e-01, 5.332844257e-01, 1.591552734e+00]),
    ([1.000000000e+00, 0.000000000e+00, 0.000000000e+00], [1.076691389e+00, 7.840058804e-01, 1.730533004e+00]),
    ([-3.030457634e-01, 5.050762723e-01, 8.081220356e-01], [1.124030352e+00, 6.521354318e-01, 1.807229161e+00]),
    ([6.359987280e-01, -7.419985160e-01, 2.119995760e-01], [1.497988224e+00, 9.573481679e-01, 1.951512575e+00]),
    ([1.024631039e-01, 9.733994872e-01, -2.049262078e-01], [4.146475196e-01, 5.722451210e-01, 1.506331921e+00]),
    ([-9.434563530e-01, 1.048284837e-01, -3.144854510e-01], [1.732691050e+00, 8.625009060e-01, 2.333044052e+00]),
    ([2.009162582e-01, -1.004581291e-01, -9.744438524e-01], [1.144743681e+00, 9.101811647e-01, 1.591013432e+00]),
    ([3.566604070e-01, 8.356043820e-01, 4.178021910e-01], [6.191703081e-01, 5.086549520e-01, 1.554899931e+00]),
];
// tex_rgb8.png as an envmap (sRGB -> linear), identity transform
const ENV_PNG_EVAL: &[([f32; 3], [f32; 3])] = &[
    ([0.000000000e+00, 0.000000000e+00, 1.000000000e+00], [1.422369778e-01, 1.878207624e-01, 5.067041144e-02]),
    ([1.000000000e+00, 0.000000000e+00, 0.000000000e+00], [3.214066848e-02, 1.878207624e-01, 1.233549695e-02]),
    ([-3.030457634e-01, 5.050762723e-01, 8.081220356e-01], [1.792336553e-01, 1.268697232e-01, 4.243530333e-02]),
    ([6.359987280e-01, -7.419985160e-01, 2.119995760e-01], [4.406413436e-02, 4.687777162e-01, 3.741284087e-02]),
    ([1.024631039e-01, 9.733994872e-01, -2.049262078e-01], [1.078856066e-01, 3.360676765e-02, 6.736536510e-03]),
];
// spot: cutoff 30, beam 12, intensity (2,3,4), to_world = look_at([1,2,3] -> [1,0,3.5], up z)
const SPOT_TO_WORLD: [[f64; 4]; 4] = [
    [1.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00],
    [0.000000000e+00, 2.425356358e-01, -9.701425433e-01, 2.000000000e+00],
    [0.000000000e+00, 9.701425433e-01, 2.425356358e-01, 3.000000000e+00],
    [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00],
];
const SPOT_WEIGHT: &[([f32; 3], [f32; 3])] = &[
    ([1.000000000e+00, 3.507575989e-01, 3.412310600e+00], [6.920414567e-01, 1.038062215e+00, 1.384082913e+00]),
    ([1.000000000e+00, 3.507575989e-01, 3.412310600e+00], [6.920414567e-01, 1.038062215e+00, 1.384082913e+00]),
    ([1.156880334e+00, 2.603884935e-01, 3.434902877e+00], [6.172838807e-01, 9.259258509e-01, 1.234567761e+00]),
    ([1.041965306e+00, 2.970509529e-01, 3.581552863e+00], [6.172838807e-01, 9.259258509e-01, 1.234567761e+00]),
    ([1.399623722e+00, 1.602698565e-01, 3.459932536e+00], [5.325034261e-01, 7.987551689e-01, 1.065006852e+00]),
    ([1.106898874e+00, 2.536607981e-01, 3.833496273e+00], [5.325034261e-01, 7.987551689e-01, 1.065006852e+00]),
    ([1.422057271e+00, 1.530647278e-01, 3.461733818e+00], [5.113599300e-01, 7.670398951e-01, 1.022719860e+00]),
    ([1.112899825e+00, 2.516982555e-01, 3.856268227e+00], [5.113599300e-01, 7.670398951e-01, 1.022719860e+00]),
    ([1.517638087e+00, 1.258285046e-01, 3.468542874e+00], [4.166669548e-01, 6.250004172e-01, 8.333339095e-01]),
    ([1.138467580e+00, 2.467991114e-01, 3.952425122e+00], [4.166669548e-01, 6.250004172e-01, 8.333339095e-01]),
    ([1.718242288e+00, 8.556497097e-02, 3.478608757e+00], [2.519527078e-01, 3.779290617e-01, 5.039054155e-01]),
    ([1.192128956e+00, 2.534161806e-01, 4.150013566e+00], [2.519529164e-01, 3.779293895e-01, 5.039058328e-01]),
    ([1.929760218e+00, 6.565487385e-02, 3.483586282e+00], [1.147844717e-01, 1.721767038e-01, 2.295689434e-01]),
    ([1.248709753e+00, 2.829371691e-01, 4.352715611e+00], [1.147844866e-01, 1.721767336e-01, 2.295689732e-01]),
    ([2.127649903e+00, 6.639480591e-02, 3.483401299e+00], [1.059414633e-02, 1.589122042e-02, 2.118829265e-02]),
    ([1.301645011e+00, 3.299232721e-01, 4.537515879e+00], [1.059428789e-02, 1.589143276e-02, 2.118857577e-02]),
    ([2.194888353e+00, 7.074737549e-02, 3.482313156e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00]),
    ([1.319631219e+00, 3.499894142e-01, 4.599281430e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00]),
    ([3.511473656e+00, 5.932933092e-01, 3.351676673e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00]),
    ([1.671816289e+00, 1.180217683e+00, 5.699373960e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00]),
];
// spot: cutoff 40 (beam 30), texture tex_rgb8.png, to_world = SPOT_TO_WORLD
const SPOT_TEXTURED_WEIGHT: &[([f32; 3], [f32; 3])] = &[
    ([1.000000000e+00, -4.253563881e-01, 3.606339097e+00], [2.275791392e-02, 3.005131520e-02, 8.107264526e-03]),
    ([1.414731085e+00, -3.573944569e-01, 3.721588373e+00], [3.316377103e-02, 3.791876510e-02, 1.495297998e-02]),
    ([6.441735029e-01, -9.051918983e-02, 4.324053407e+00], [1.340137888e-02, 8.002010733e-02, 1.257606223e-02]),
    ([1.570854068e+00, -4.137463570e-01, 2.687022209e+00], [4.040766135e-02, 9.757268243e-03, 4.368503578e-03]),
    ([1.100004315e-01, -2.839982510e-01, 2.508825243e+00], [3.523127874e-03, 3.242689185e-03, 3.136384184e-04]),
    ([1.831608236e+00, 4.029138088e-01, 4.734284878e+00], [1.186773740e-02, 1.892802864e-02, 1.442172285e-02]),
    ([2.767766953e+00, 2.850140333e-01, 3.428746492e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00]),
];
// spot with defaults (cutoff 20, beam 15) at the origin, along +z; reference points
const SPOT_DEFAULT_WEIGHT: &[([f32; 3], [f32; 3])] = &[
    ([0.000000000e+00, 0.000000000e+00, 2.000000000e+00], [2.500000000e-01, 2.500000000e-01, 2.500000000e-01]),
    ([3.472963553e-01, 0.000000000e+00, 1.969615506e+00], [2.500000596e-01, 2.500000596e-01, 2.500000596e-01]),
    ([5.142655863e-01, 0.000000000e+00, 1.932752159e+00], [2.500000000e-01, 2.500000000e-01, 2.500000000e-01]),
    ([5.512747116e-01, 0.000000000e+00, 1.922523392e+00], [2.000000179e-01, 2.000000179e-01, 2.000000179e-01]),
    ([6.180339887e-01, 0.000000000e+00, 1.902113033e+00], [1.000002176e-01, 1.000002176e-01, 1.000002176e-01]),
    ([6.807591004e-01, 0.000000000e+00, 1.880576254e+00], [4.999955650e-03, 4.999955650e-03, 4.999955650e-03]),
    ([7.167358991e-01, 0.000000000e+00, 1.867160853e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00]),
];
// point at (1,2,3), intensity (5,6,7), from (0.3,-0.2,0.5): d, dist, weight
const POINT: ([f32; 3], f32, [f32; 3]) = (
    [2.057044953e-01, 6.464998722e-01, 7.346588969e-01],
    3.402939796e+00,
    [4.317789972e-01, 5.181347728e-01, 6.044905782e-01],
);
// directional towards (1,-2,0.5), irradiance (3,2,1): d, weight
const DIRECTIONAL: ([f32; 3], [f32; 3]) =
    ([-4.364358187e-01, 8.728716373e-01, -2.182179093e-01], [3.000000000e+00, 2.000000000e+00, 1.000000000e+00]);
// constant radiance (0.5,1,2), sample (0.3,0.7): d, pdf, weight
const CONSTANT: ([f32; 3], f32, [f32; 3]) = (
    [-2.832189202e-01, 8.716576695e-01, -3.999999762e-01],
    7.957746834e-02,
    [6.283185482e+00, 1.256637096e+01, 2.513274193e+01],
);

#[test]
fn envmap_eval_matches_mitsuba() {
    let e = emitter(
        "envmap",
        vec![
            ("filename", Value::String("envmap_half_piz.exr".into())),
            ("scale", Value::Float(1.5)),
            ("to_world", transform(ENV_TO_WORLD)),
        ],
    );
    assert!(e.is_environment() && !e.is_delta());
    for &(d, want) in ENV_EVAL {
        assert_close(e.eval_environment(v3(d)), v3(want), 1e-4, &format!("envmap eval {d:?}"));
    }
}

#[test]
fn envmap_from_png_matches_mitsuba() {
    let e = emitter("envmap", vec![("filename", Value::String("tex_rgb8.png".into()))]);
    for &(d, want) in ENV_PNG_EVAL {
        assert_close(e.eval_environment(v3(d)), v3(want), 1e-4, &format!("envmap (png) eval {d:?}"));
    }
}

#[test]
fn spot_matches_mitsuba() {
    let e = emitter(
        "spot",
        vec![
            ("cutoff_angle", Value::Float(30.0)),
            ("beam_width", Value::Float(12.0)),
            ("to_world", transform(SPOT_TO_WORLD)),
            ("intensity", rgb([2.0, 3.0, 4.0])),
        ],
    );
    assert!(e.is_delta());
    for &(p, want) in SPOT_WEIGHT {
        let (ds, w) = e.sample_direction(v3(p), Vec2::splat(0.5));
        assert!(ds.delta && ds.pdf == 1.0);
        assert!((ds.p - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-5);
        assert_close(w, v3(want), 1e-4, &format!("spot weight from {p:?}"));
        assert_eq!(e.pdf_direction(v3(p), &ds), 0.0);
    }
    let e = emitter("spot", vec![]);
    for &(p, want) in SPOT_DEFAULT_WEIGHT {
        let (_, w) = e.sample_direction(v3(p), Vec2::splat(0.5));
        assert_close(w, v3(want), 1e-4, &format!("default spot weight from {p:?}"));
    }
}

#[test]
fn textured_spot_matches_mitsuba() {
    let pos = SrcPos::new("scene.xml", 9, 9);
    let mut tp = Props::new(PluginKind::Texture, "bitmap", pos.clone());
    tp.push("filename", Value::String("tex_rgb8.png".into()), pos.clone()).unwrap();
    let tex = ObjectDesc { kind: PluginKind::Texture, plugin: "bitmap".into(), id: None, pos, props: tp };
    let e = emitter(
        "spot",
        vec![
            ("cutoff_angle", Value::Float(40.0)),
            ("to_world", transform(SPOT_TO_WORLD)),
            ("texture", Value::Object(std::rc::Rc::new(tex))),
        ],
    );
    for &(p, want) in SPOT_TEXTURED_WEIGHT {
        let (_, w) = e.sample_direction(v3(p), Vec2::splat(0.5));
        // Mitsuba keeps 8-bit textures in half precision.
        assert_close(w, v3(want), 1e-3, &format!("textured spot weight from {p:?}"));
    }
}

#[test]
fn spot_falloff_is_mitsubas_linear_ramp() {
    // cutoff 40°, beam 10°: 1 inside the beam, (40° − θ)/30° in between, 0 outside.
    let e = emitter("spot", vec![("cutoff_angle", Value::Float(40.0)), ("beam_width", Value::Float(10.0))]);
    let Emitter::Spot(s) = &e else { panic!() };
    for k in 0..=90 {
        let theta = k as f32 * 0.5;
        let d = Vec3::new(theta.to_radians().sin(), 0.0, theta.to_radians().cos());
        let want = if theta <= 10.0 {
            1.0
        } else if theta < 40.0 {
            (40.0 - theta) / 30.0
        } else {
            0.0
        };
        assert!((s.falloff(d) - want).abs() < 2e-5, "θ = {theta}: {} vs {want}", s.falloff(d));
    }
}

#[test]
fn point_directional_constant_match_mitsuba() {
    let p = Vec3::new(0.3, -0.2, 0.5);
    let e =
        emitter("point", vec![("position", Value::Point([1.0, 2.0, 3.0].into())), ("intensity", rgb([5.0, 6.0, 7.0]))]);
    let (ds, w) = e.sample_direction(p, Vec2::splat(0.5));
    assert_close(ds.d, v3(POINT.0), 1e-5, "point d");
    assert!((ds.dist - POINT.1).abs() < 1e-5);
    assert_close(w, v3(POINT.2), 1e-5, "point weight");
    assert!(ds.delta && e.is_delta());

    let e = emitter(
        "directional",
        vec![("direction", Value::Vector([1.0, -2.0, 0.5].into())), ("irradiance", rgb([3.0, 2.0, 1.0]))],
    );
    let (ds, w) = e.sample_direction(p, Vec2::splat(0.5));
    assert_close(ds.d, v3(DIRECTIONAL.0), 1e-5, "directional d");
    assert_close(w, v3(DIRECTIONAL.1), 1e-6, "directional weight");
    assert!(ds.delta && ds.dist.is_infinite() && e.pdf_direction(p, &ds) == 0.0);
    assert_eq!(e.eval_environment(-ds.d), Spectrum::ZERO);

    let e = emitter("constant", vec![("radiance", rgb([0.5, 1.0, 2.0]))]);
    let (ds, w) = e.sample_direction(p, Vec2::new(0.3, 0.7));
    assert_close(ds.d, v3(CONSTANT.0), 1e-5, "constant d");
    assert!((ds.pdf - CONSTANT.1).abs() < 1e-7 && (e.pdf_direction(p, &ds) - ds.pdf).abs() < 1e-7);
    assert_close(w, v3(CONSTANT.2), 1e-6, "constant weight");
    assert_eq!(e.eval_environment(ds.d), Spectrum::new(0.5, 1.0, 2.0));
}

#[test]
fn directional_default_travels_along_z() {
    let e = emitter("directional", vec![]);
    let (ds, w) = e.sample_direction(Vec3::ZERO, Vec2::splat(0.5));
    assert_eq!(ds.d, -Vec3::Z);
    assert_eq!(w, Spectrum::ONE);
}

#[test]
fn infinite_emitters_place_points_beyond_the_scene() {
    let mut e = emitter("constant", vec![]);
    e.set_scene_bounds(Vec3::new(10.0, 0.0, 0.0), 3.0);
    let (ds, _) = e.sample_direction(Vec3::new(10.0, 1.0, 0.0), Vec2::new(0.2, 0.9));
    assert!(ds.dist.is_infinite());
    assert!((ds.p - Vec3::new(10.0, 0.0, 0.0)).length() > 3.0);
}

// ---- Errors ----

#[test]
fn bad_emitter_descriptions_are_errors_with_positions() {
    let err = |plugin: &str, props: Vec<(&str, Value)>| {
        Emitter::from_desc(&desc(plugin, props), &resolver()).unwrap_err().to_string()
    };
    let e = err("sun", vec![]);
    assert!(e.starts_with("scene.xml:3:5:") && e.contains("directional, envmap, constant, point, spot"), "{e}");
    let e = err(
        "directional",
        vec![("direction", Value::Vector([0.0, 0.0, 1.0].into())), ("to_world", transform(ENV_TO_WORLD))],
    );
    assert!(e.starts_with("scene.xml:4:9:") && e.contains("only one of"), "{e}");
    let e = err("directional", vec![("direction", Value::Vector([0.0, 0.0, 0.0].into()))]);
    assert!(e.contains("non-zero"), "{e}");
    let e = err("point", vec![("intensty", Value::Float(1.0))]);
    assert!(e.starts_with("scene.xml:4:9:") && e.contains("intensty"), "{e}");
    let e = err("envmap", vec![("filename", Value::String("missing.exr".into()))]);
    assert!(e.starts_with("scene.xml:4:9:") && e.contains("missing.exr"), "{e}");
    let e = err("envmap", vec![]);
    assert!(e.contains("filename"), "{e}");
    let e = err(
        "envmap",
        vec![
            ("filename", Value::String("envmap_half_piz.exr".into())),
            ("to_world", Value::Transform(glam::DMat4::from_scale(glam::DVec3::splat(2.0)))),
        ],
    );
    assert!(e.contains("rotation"), "{e}");
    let e = err("spot", vec![("cutoff_angle", Value::Float(-5.0))]);
    assert!(e.contains("cutoff_angle"), "{e}");
    let e = err("spot", vec![("texture", Value::Float(0.5))]);
    assert!(e.contains("spatially varying"), "{e}");
}

// ---- Sampling against the pdf ----

/// A peaky map: a gradient sky plus a small sun ~1000× brighter (two pixels), and a black ground.
fn sun_and_sky(w: usize, h: usize) -> Vec<Spectrum> {
    let mut px = Vec::with_capacity(w * h);
    for y in 0..h {
        for x in 0..w {
            let v = y as f32 / (h - 1) as f32;
            let mut c = Spectrum::new(0.2 + 0.8 * (1.0 - v), 0.3 + 0.5 * (1.0 - v), 1.0) * (0.05 + x as f32 / w as f32);
            if (x == 5 || x == 6) && y == 3 {
                c += Spectrum::new(500.0, 450.0, 400.0);
            }
            if y >= h - 2 {
                c = Spectrum::ZERO; // black ground: the sampler must never go there
            }
            px.push(c);
        }
    }
    px
}

fn rotated() -> Mat4 {
    Mat4::from_axis_angle(Vec3::new(0.3, 1.0, -0.2).normalize(), 0.7) * Mat4::from_axis_angle(Vec3::X, -0.4)
}

#[test]
fn envmap_sampling_chi2() {
    let (w, h) = (16, 9);
    let env = EnvironmentEmitter::new("sky".into(), "sky", w, h, &sun_and_sky(w, h), 1.0, rotated(), false).unwrap();
    let e = Emitter::Envmap(env);
    let p = Vec3::new(0.1, 0.2, 0.3);
    let r = chi2_sphere(
        |_, u| {
            let (ds, _) = e.sample_direction(p, u);
            (ds.pdf > 0.0).then_some(ds.d)
        },
        |d| e.pdf_direction(p, &DirectionSample { d, ..Default::default() }),
        32,
        64,
        400_000,
        sidak(0.01, 3),
        7,
    );
    assert!(r.passed, "{}", r.report);
    assert!((r.pdf_integral - 1.0).abs() < 2e-3, "∫pdf = {}", r.pdf_integral);
}

#[test]
fn envmap_mis_compensation_sampling_chi2() {
    let (w, h) = (12, 7);
    let env = EnvironmentEmitter::new("sky".into(), "sky", w, h, &sun_and_sky(w, h), 1.0, rotated(), true).unwrap();
    let e = Emitter::Envmap(env);
    let r = chi2_sphere(
        |_, u| {
            let (ds, _) = e.sample_direction(Vec3::ZERO, u);
            (ds.pdf > 0.0).then_some(ds.d)
        },
        |d| e.pdf_direction(Vec3::ZERO, &DirectionSample { d, ..Default::default() }),
        32,
        64,
        200_000,
        sidak(0.01, 3),
        11,
    );
    assert!(r.passed, "{}", r.report);
    assert!((r.pdf_integral - 1.0).abs() < 2e-3, "∫pdf = {}", r.pdf_integral);
}

#[test]
fn constant_sampling_chi2() {
    let e = emitter("constant", vec![]);
    let r = chi2_sphere(
        |_, u| Some(e.sample_direction(Vec3::ZERO, u).0.d),
        |d| e.pdf_direction(Vec3::ZERO, &DirectionSample { d, ..Default::default() }),
        16,
        32,
        100_000,
        sidak(0.01, 3),
        3,
    );
    assert!(r.passed, "{}", r.report);
    assert!((r.pdf_integral - 1.0).abs() < 1e-4);
}

/// Every sample: weight = radiance / pdf, `pdf_direction` reproduces the sampled pdf, radiance
/// is never zero where the sampler goes, and the weights average to the map's irradiance integral.
#[test]
fn envmap_sample_weight_and_pdf_are_consistent() {
    let (w, h) = (16, 9);
    let env = EnvironmentEmitter::new("sky".into(), "sky", w, h, &sun_and_sky(w, h), 2.0, rotated(), false).unwrap();
    let e = Emitter::Envmap(env);
    let p = Vec3::new(-1.0, 0.5, 2.0);
    let n = 256;
    let mut mean_weight = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.37) / n as f32);
            let (ds, wgt) = e.sample_direction(p, u);
            assert!(ds.pdf > 0.0 && !ds.delta && ds.dist.is_infinite());
            assert!((ds.d.length() - 1.0).abs() < 1e-5);
            let pdf = e.pdf_direction(p, &ds);
            assert!((pdf - ds.pdf).abs() <= 1e-3 * ds.pdf, "pdf_direction {pdf} vs sampled {}", ds.pdf);
            let radiance = e.eval_environment(ds.d);
            assert!(luminance(radiance) > 0.0, "sampled a black direction {}", ds.d);
            assert_close(wgt * ds.pdf, radiance, 2e-3, "weight · pdf vs eval");
            mean_weight += luminance(wgt) as f64;
        }
    }
    mean_weight /= (n * n) as f64;
    // Reference: ∫ L dω by a fine midpoint rule in (cos θ, φ) of the local frame.
    let Emitter::Envmap(env) = &e else { unreachable!() };
    let m = 1024;
    let mut integral = 0.0f64;
    for a in 0..m {
        let z = -1.0 + (a as f64 + 0.5) * 2.0 / m as f64;
        for b in 0..(2 * m) {
            let phi = (b as f64 + 0.5) * std::f64::consts::PI / m as f64;
            let r = (1.0 - z * z).sqrt();
            let local = Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32);
            integral += luminance(env.eval(env.to_world.transform_vector3(local))) as f64;
        }
    }
    integral *= 4.0 * std::f64::consts::PI / (2 * m * m) as f64;
    assert!((mean_weight - integral).abs() < 0.02 * integral, "E[weight] = {mean_weight}, ∫L = {integral}");
}

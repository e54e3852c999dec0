//! Emitters against Mitsuba 3.9 and their samplers against their pdfs.
//!
//! The reference numbers are in `tests/data/emitters.json`, written by `scripts/emitter_expected.py`
//! (which also writes the images in `tests/data/`), e.g. for the envmap:
//!
//! ```python
//! env = mi.load_dict({"type": "envmap", "filename": "tests/data/envmap_half_piz.exr", "scale": 1.5,
//!                     "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], 30).rotate([1, 0, 0], 20)})
//! si = mi.SurfaceInteraction3f(); si.wi = -mi.Vector3f(d); env.eval(si)
//! ```
//! and for the delta lights `emitter.sample_direction(it, [0.5, 0.5])` with `it.p` the reference point.

use crate::{data_dir, mitsuba_json, num, rows4, transform, vec3};
use serde_json::Value as Json;
use snee::color::{luminance, Spectrum};
use snee::emitter::{Emitter, EnvironmentEmitter};
use snee::interaction::DirectionSample;
use snee::math::{Mat4, Vec2, Vec3};
use snee::scene::desc::{ObjectDesc, PluginKind, Props, Value};
use snee::scene::resolver::FileResolver;
use snee::scene::SrcPos;
use snee::testing::chi2::{chi2_sphere, sidak};

// ---- Helpers ----

fn resolver() -> FileResolver {
    FileResolver { paths: vec![data_dir()] }
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

fn rgb(v: [f64; 3]) -> Value {
    Value::Rgb(glam::DVec3::from_array(v))
}

#[track_caller]
fn assert_close(got: Vec3, want: Vec3, rel: f32, what: &str) {
    let err = (got - want).abs().max_element();
    assert!(err <= rel * want.abs().max_element().max(1e-3), "{what}: got {got}, Mitsuba {want}");
}

/// Mitsuba's values (`tests/data/emitters.json`, from `scripts/emitter_expected.py`).
fn mitsuba_values() -> Json {
    mitsuba_json("emitters.json")
}

#[test]
fn envmap_eval_matches_mitsuba() {
    let e = emitter(
        "envmap",
        vec![
            ("filename", Value::String("envmap_half_piz.exr".into())),
            ("scale", Value::Float(1.5)),
            ("to_world", transform(rows4(&mitsuba_values()["env_to_world"]))),
        ],
    );
    assert!(e.is_environment() && !e.is_delta());
    for c in mitsuba_values()["env_eval"].as_array().unwrap() {
        let (d, want) = (vec3(&c["d"]), vec3(&c["value"]));
        assert_close(e.eval_environment(d), want, 1e-4, &format!("envmap eval {d:?}"));
    }
}

#[test]
fn envmap_from_png_matches_mitsuba() {
    let e = emitter("envmap", vec![("filename", Value::String("tex_rgb8.png".into()))]);
    for c in mitsuba_values()["env_png_eval"].as_array().unwrap() {
        let (d, want) = (vec3(&c["d"]), vec3(&c["value"]));
        assert_close(e.eval_environment(d), want, 1e-4, &format!("envmap (png) eval {d:?}"));
    }
}

#[test]
fn spot_matches_mitsuba() {
    let e = emitter(
        "spot",
        vec![
            ("cutoff_angle", Value::Float(30.0)),
            ("beam_width", Value::Float(12.0)),
            ("to_world", transform(rows4(&mitsuba_values()["spot_to_world"]))),
            ("intensity", rgb([2.0, 3.0, 4.0])),
        ],
    );
    assert!(e.is_delta());
    for c in mitsuba_values()["spot_weight"].as_array().unwrap() {
        let (p, want) = (vec3(&c["ref"]), vec3(&c["weight"]));
        let (ds, w) = e.sample_direction(p, Vec2::splat(0.5));
        assert!(ds.delta && ds.pdf == 1.0);
        assert!((ds.p - Vec3::new(1.0, 2.0, 3.0)).length() < 1e-5);
        assert_close(w, want, 1e-4, &format!("spot weight from {p:?}"));
        assert_eq!(e.pdf_direction(p, &ds), 0.0);
    }
    let e = emitter("spot", vec![]);
    for c in mitsuba_values()["spot_default_weight"].as_array().unwrap() {
        let (p, want) = (vec3(&c["ref"]), vec3(&c["weight"]));
        let (_, w) = e.sample_direction(p, Vec2::splat(0.5));
        assert_close(w, want, 1e-4, &format!("default spot weight from {p:?}"));
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
            ("to_world", transform(rows4(&mitsuba_values()["spot_to_world"]))),
            ("texture", Value::Object(std::rc::Rc::new(tex))),
        ],
    );
    for c in mitsuba_values()["spot_textured_weight"].as_array().unwrap() {
        let (p, want) = (vec3(&c["ref"]), vec3(&c["weight"]));
        let (_, w) = e.sample_direction(p, Vec2::splat(0.5));
        // Mitsuba keeps 8-bit textures in half precision.
        assert_close(w, want, 1e-3, &format!("textured spot weight from {p:?}"));
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
    let m = mitsuba_values();
    let p = Vec3::new(0.3, -0.2, 0.5);
    let e =
        emitter("point", vec![("position", Value::Point([1.0, 2.0, 3.0].into())), ("intensity", rgb([5.0, 6.0, 7.0]))]);
    let (ds, w) = e.sample_direction(p, Vec2::splat(0.5));
    assert_close(ds.d, vec3(&m["point"]["d"]), 1e-5, "point d");
    assert!((ds.dist - num(&m["point"]["dist"])).abs() < 1e-5);
    assert_close(w, vec3(&m["point"]["weight"]), 1e-5, "point weight");
    assert!(ds.delta && e.is_delta());

    let e = emitter(
        "directional",
        vec![("direction", Value::Vector([1.0, -2.0, 0.5].into())), ("irradiance", rgb([3.0, 2.0, 1.0]))],
    );
    let (ds, w) = e.sample_direction(p, Vec2::splat(0.5));
    assert_close(ds.d, vec3(&m["directional"]["d"]), 1e-5, "directional d");
    assert_close(w, vec3(&m["directional"]["weight"]), 1e-6, "directional weight");
    assert!(ds.delta && ds.dist.is_infinite() && e.pdf_direction(p, &ds) == 0.0);
    assert_eq!(e.eval_environment(-ds.d), Spectrum::ZERO);

    let e = emitter("constant", vec![("radiance", rgb([0.5, 1.0, 2.0]))]);
    let (ds, w) = e.sample_direction(p, Vec2::new(0.3, 0.7));
    assert_close(ds.d, vec3(&m["constant"]["d"]), 1e-5, "constant d");
    assert!((ds.pdf - num(&m["constant"]["pdf"])).abs() < 1e-7 && (e.pdf_direction(p, &ds) - ds.pdf).abs() < 1e-7);
    assert_close(w, vec3(&m["constant"]["weight"]), 1e-6, "constant weight");
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
        vec![
            ("direction", Value::Vector([0.0, 0.0, 1.0].into())),
            ("to_world", transform(rows4(&mitsuba_values()["env_to_world"]))),
        ],
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

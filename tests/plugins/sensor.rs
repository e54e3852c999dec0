//! Perspective camera framing against Mitsuba 3.9.1 and sensor/film/sampler parsing.
//!
//! The expected rays are in `tests/data/sensor.json`, written by `scripts/sensor_expected.py`
//! (Mitsuba `scalar_rgb`), which for each configuration calls
//! ```python
//! sensor = mi.load_dict({"type": "perspective", "film": {...}, "to_world": look_at(...), **params})
//! ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(*s), mi.Point2f(0.5, 0.5))
//! ```
//! for crop-relative position samples `s`, and stores the same point in full-film pixels
//! (`crop_offset + s * crop_size`), Mitsuba's `to_world` matrix and the ray `o`, `d`, `maxt`.

use crate::{mitsuba_json, num, rows4, vec2, vec3};
use glam::{DMat4, DVec3, Vec2, Vec3};
use serde_json::Value as Json;
use snee::scene::desc::{ObjectDesc, PluginKind, Props, Value};
use snee::scene::error::SrcPos;
use snee::scene::resolver::FileResolver;
use snee::sensor::{Camera, PixelFormat, RFilter, SamplerKind, Sensor};
use std::rc::Rc;

// ---- Building scene descriptions by hand (one property per source line) ----

struct Obj {
    kind: PluginKind,
    plugin: &'static str,
    props: Vec<(String, Value)>,
    children: Vec<Rc<ObjectDesc>>,
}

fn obj(kind: PluginKind, plugin: &'static str) -> Obj {
    Obj { kind, plugin, props: Vec::new(), children: Vec::new() }
}

impl Obj {
    fn with(mut self, name: &str, v: Value) -> Obj {
        self.props.push((name.to_string(), v));
        self
    }
    fn child(mut self, c: Rc<ObjectDesc>) -> Obj {
        self.children.push(c);
        self
    }
    fn build(self) -> Rc<ObjectDesc> {
        let pos = SrcPos::new("test.xml", 1, 1);
        let mut props = Props::new(self.kind, self.plugin, pos.clone());
        let mut line = 2;
        for (name, v) in self.props {
            props.push(&name, v, SrcPos::new("test.xml", line, 5)).unwrap();
            line += 1;
        }
        for c in self.children {
            props.push_object(None, c, SrcPos::new("test.xml", line, 5)).unwrap();
            line += 1;
        }
        Rc::new(ObjectDesc { kind: self.kind, plugin: self.plugin.to_string(), id: None, pos, props })
    }
}

fn sensor(o: Obj) -> snee::scene::Result<Sensor> {
    Sensor::from_desc(&o.build(), &FileResolver::default())
}

fn int(v: i64) -> Value {
    Value::Integer(v)
}

// ---- Camera framing against Mitsuba ----

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol * (1.0 + b.abs().max_element())
}

#[test]
fn perspective_rays_match_mitsuba() {
    // Per camera: its parameters, film (width, height, crop window or null), Mitsuba's `to_world`
    // rows, and rays: film position in pixels, then Mitsuba's ray o, d and maxt.
    for case in mitsuba_json("sensor.json")["cameras"].as_array().unwrap() {
        let name = case["name"].as_str().unwrap();
        let film_spec = &case["film"];
        let int_of = |v: &Json| int(v.as_i64().unwrap());
        let mut film = obj(PluginKind::Film, "hdrfilm")
            .with("width", int_of(&film_spec["width"]))
            .with("height", int_of(&film_spec["height"]));
        if let Some(crop) = film_spec["crop"].as_array() {
            film = film
                .with("crop_offset_x", int_of(&crop[0]))
                .with("crop_offset_y", int_of(&crop[1]))
                .with("crop_width", int_of(&crop[2]))
                .with("crop_height", int_of(&crop[3]));
        }
        let to_world = DMat4::from_cols_array_2d(&rows4(&case["to_world_rows"])).transpose();
        let mut s = obj(PluginKind::Sensor, "perspective").child(film.build());
        for (param, p) in case["params"].as_object().unwrap() {
            let v = match p {
                Json::String(text) => Value::String(text.clone()),
                number => Value::Float(number.as_f64().unwrap()),
            };
            s = s.with(param, v);
        }
        if to_world != DMat4::IDENTITY {
            s = s.with("to_world", Value::Transform(to_world));
        }
        let sensor = sensor(s).unwrap_or_else(|e| panic!("{name}: {e}"));
        let origin = to_world.transform_point3(DVec3::ZERO).as_vec3();
        assert!(close(sensor.camera.position(), origin, 1e-6), "{name}: position");
        for r in case["rays"].as_array().unwrap() {
            let (pos, o, d, maxt) = (vec2(&r["pos"]), vec3(&r["o"]), vec3(&r["d"]), num(&r["maxt"]));
            let ray = sensor.camera.sample_ray(pos, Vec2::splat(0.5));
            assert!(close(ray.d, d, 2e-6), "{name} at {pos:?}: d {} vs Mitsuba {}", ray.d, d);
            assert!(close(ray.o, o, 2e-6), "{name} at {pos:?}: o {} vs Mitsuba {}", ray.o, o);
            assert!((ray.tmax - maxt).abs() <= 2e-6 * maxt, "{name} at {pos:?}: tmax {} vs {}", ray.tmax, maxt);
        }
    }
}

#[test]
fn camera_orientation_conventions() {
    // Local +Z forward, +Y up, +X is the image's left; image y grows downward.
    let s = sensor(obj(PluginKind::Sensor, "perspective").with("fov", Value::Float(90.0))).unwrap();
    let Camera::Perspective(p) = &s.camera else { panic!("expected a perspective camera") };
    assert_eq!(p.x_fov, 90.0);
    let (w, h) = (s.film.width as f32, s.film.height as f32);
    let left = s.camera.sample_ray(Vec2::new(0.0, h / 2.0), Vec2::ZERO).d;
    let top = s.camera.sample_ray(Vec2::new(w / 2.0, 0.0), Vec2::ZERO).d;
    assert!(left.x > 0.0 && (left.x - left.z).abs() < 1e-6, "90° horizontal fov: left edge at 45°, got {left}");
    assert!(top.y > 0.0 && top.y < top.z, "top of the image is +Y, got {top}");
}

// ---- Parsing: defaults and errors ----

#[test]
fn defaults_match_mitsuba() {
    let s = sensor(obj(PluginKind::Sensor, "perspective")).unwrap();
    assert_eq!((s.film.width, s.film.height), (768, 576));
    assert_eq!(s.film.crop_size, (768, 576));
    assert_eq!(s.film.filter, RFilter::Gaussian { stddev: 0.5 });
    assert_eq!(s.film.pixel_format, PixelFormat::Rgb);
    assert!(!s.film.sample_border);
    assert_eq!(s.sampler.kind, SamplerKind::Independent);
    assert_eq!((s.sampler.sample_count, s.sampler.seed), (4, 0));
    assert!(s.medium_ref.is_none());
    let Camera::Perspective(p) = &s.camera else { panic!("expected a perspective camera") };
    // 50 mm on the diagonal of a 4:3 film: Mitsuba 3.9.1 reports x_fov = 38.18484115600586 for 768x576
    // (`mi.traverse(mi.load_dict({'type': 'perspective'}))['x_fov']`).
    assert!((p.x_fov - 38.184_84).abs() < 1e-4, "x_fov {}", p.x_fov);
    assert_eq!((p.near_clip, p.far_clip), (0.01, 1e4));
}

#[test]
fn nested_objects_are_parsed() {
    let rfilter = obj(PluginKind::RFilter, "tent").with("radius", Value::Float(1.5)).build();
    let film = obj(PluginKind::Film, "hdrfilm")
        .with("pixel_format", Value::String("RGBA".into()))
        .with("component_format", Value::String("float32".into()))
        .with("sample_border", Value::Bool(true))
        .with("banner", Value::Bool(false))
        .child(rfilter)
        .build();
    let sampler = obj(PluginKind::Sampler, "multijitter")
        .with("sample_count", int(32))
        .with("seed", int(9))
        .with("jitter", Value::Bool(false))
        .build();
    let medium = obj(PluginKind::Medium, "homogeneous").build();
    let s = sensor(
        obj(PluginKind::Sensor, "perspective").with("fov", Value::Float(30.0)).child(film).child(sampler).child(medium),
    )
    .unwrap();
    assert_eq!(s.film.pixel_format, PixelFormat::Rgba);
    assert_eq!(s.film.filter, RFilter::Tent { radius: 1.5 });
    assert!(s.film.sample_border);
    assert_eq!(s.film.sample_window(), ((-1, -1), (770, 578)));
    assert_eq!(s.sampler.kind, SamplerKind::Multijitter);
    // Mitsuba: multijitter rounds 32 up to 35 (7 x 5 strata).
    assert_eq!((s.sampler.sample_count, s.sampler.seed), (35, 9));
    assert_eq!(s.medium_ref.as_ref().map(|m| m.plugin.as_str()), Some("homogeneous"));
}

#[test]
fn sampler_counts_round_like_mitsuba() {
    // (kind, requested, Mitsuba 3.9.1's sample_count())
    let expected = [
        ("stratified", 2, 4),
        ("stratified", 5, 9),
        ("stratified", 16, 16),
        ("stratified", 32, 36),
        ("multijitter", 3, 3),
        ("multijitter", 5, 6),
        ("multijitter", 7, 8),
        ("multijitter", 10, 12),
        ("multijitter", 17, 20),
        ("multijitter", 32, 35),
        ("multijitter", 64, 64),
        ("independent", 5, 5),
    ];
    for (kind, n, want) in expected {
        let sampler = obj(PluginKind::Sampler, kind).with("sample_count", int(n)).build();
        let s = sensor(obj(PluginKind::Sensor, "perspective").child(sampler)).unwrap();
        assert_eq!(s.sampler.sample_count, want, "{kind} {n}");
    }
}

fn err(o: Obj) -> String {
    match sensor(o) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_input_gives_positioned_errors() {
    let persp = || obj(PluginKind::Sensor, "perspective");
    let e = err(obj(PluginKind::Sensor, "thinlens"));
    assert!(e.starts_with("test.xml:1:1:") && e.contains("perspective"), "{e}");
    let e = err(persp().with("fov", Value::Float(45.0)).with("focal_length", Value::String("35mm".into())));
    assert!(e.contains("either"), "{e}");
    let e = err(persp().with("fov_axis", Value::String("y".into())));
    assert!(e.contains("fov_axis") && e.starts_with("test.xml:2:5"), "{e}");
    let e = err(persp().with("fov", Value::Float(45.0)).with("fov_axis", Value::String("q".into())));
    assert!(e.contains("fov_axis"), "{e}");
    let e = err(persp().with("fov", Value::Float(180.0)));
    assert!(e.contains("(0, 180)"), "{e}");
    let e = err(persp().with("focal_length", Value::String("35mmx".into())));
    assert!(e.contains("focal length"), "{e}");
    let e = err(persp().with("near_clip", Value::Float(2.0)).with("far_clip", Value::Float(1.0)));
    assert!(e.contains("far_clip"), "{e}");
    let e = err(persp().with("to_world", Value::Transform(DMat4::from_scale(DVec3::splat(2.0)))));
    assert!(e.contains("scale"), "{e}");
    // A mirror is not a scale (Mitsuba accepts it).
    sensor(persp().with("to_world", Value::Transform(DMat4::from_scale(DVec3::new(1.0, 1.0, -1.0))))).unwrap();
    let e = err(persp().with("fov", Value::Float(45.0)).with("fvo", Value::Float(1.0)));
    assert!(e.contains("fvo") && e.starts_with("test.xml:3:5"), "{e}");
    let e = err(persp().with("fov", int(45)).with("srf", Value::Float(1.0)));
    assert!(e.contains("srf"), "{e}");

    let film = |k: &'static str, v: Value| obj(PluginKind::Film, "hdrfilm").with(k, v).build();
    let e = err(persp().child(film("pixel_format", Value::String("luminance".into()))));
    assert!(e.contains("not supported"), "{e}");
    let e = err(persp().child(film("pixel_format", Value::String("rbg".into()))));
    assert!(e.contains("rbg"), "{e}");
    let e = err(persp().child(film("file_format", Value::String("pfm".into()))));
    assert!(e.contains("not supported"), "{e}");
    let e = err(persp().child(film("width", Value::Float(10.0))));
    assert!(e.contains("width"), "{e}");
    let cropped = obj(PluginKind::Film, "hdrfilm").with("crop_offset_x", int(760)).with("crop_width", int(10));
    let e = err(persp().child(cropped.build()));
    assert!(e.contains("crop"), "{e}");
    let e = err(persp().child(film("height", int(-3))));
    assert!(e.contains("height"), "{e}");
    let e = err(persp().child(obj(PluginKind::Film, "specfilm").build()));
    assert!(e.contains("hdrfilm"), "{e}");
    let rf = |p: &'static str| obj(PluginKind::Film, "hdrfilm").child(obj(PluginKind::RFilter, p).build()).build();
    let e = err(persp().child(rf("mitchell")));
    assert!(e.contains("gaussian, box, tent"), "{e}");
    let e = err(persp().child(
        obj(PluginKind::Film, "hdrfilm")
            .child(obj(PluginKind::RFilter, "box").with("radius", Value::Float(2.5)).build())
            .build(),
    ));
    assert!(e.contains("radius"), "{e}");
    let e = err(persp().child(obj(PluginKind::Sampler, "ldsampler").build()));
    assert!(e.contains("independent, stratified, multijitter"), "{e}");
    let e = err(persp().child(obj(PluginKind::Sampler, "independent").with("jitter", Value::Bool(false)).build()));
    assert!(e.contains("jitter"), "{e}");
    let e = err(persp().child(obj(PluginKind::Sampler, "independent").with("sample_count", int(0)).build()));
    assert!(e.contains("sample_count"), "{e}");
    let e =
        err(persp().child(obj(PluginKind::Film, "hdrfilm").build()).child(obj(PluginKind::Film, "hdrfilm").build()));
    assert!(e.contains("only one"), "{e}");
}

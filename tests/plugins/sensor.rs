//! Perspective camera framing against Mitsuba 3.9.1 and sensor/film/sampler parsing.
//!
//! The expected rays were produced by `scripts/sensor_expected.py` (Mitsuba `scalar_rgb`), which for
//! each configuration calls
//! ```python
//! sensor = mi.load_dict({"type": "perspective", "film": {...}, "to_world": look_at(...), **params})
//! ray, _ = sensor.sample_ray(0.0, 0.5, mi.Point2f(*s), mi.Point2f(0.5, 0.5))
//! ```
//! for crop-relative position samples `s`, and stores the same point in full-film pixels
//! (`crop_offset + s * crop_size`), Mitsuba's `to_world` matrix and the ray `o`, `d`, `maxt`.

#![allow(clippy::excessive_precision)] // Mitsuba's values printed with 10 digits
use glam::{DMat4, DVec3, Vec2, Vec3};
use snee::scene::desc::{ObjectDesc, PluginKind, Props, Value};
use snee::scene::error::SrcPos;
use snee::scene::resolver::FileResolver;
use snee::sensor::{Camera, PixelFormat, RFilter, SamplerKind, Sensor};
use std::rc::Rc;

// ---- Building scene descriptions by hand (one property per source line) ----

enum P {
    F(f64),
    S(&'static str),
}
use P::{F, S};

fn value(p: &P) -> Value {
    match p {
        F(v) => Value::Float(*v),
        S(s) => Value::String(s.to_string()),
    }
}

struct Obj {
    kind: PluginKind,
    plugin: &'static str,
    props: Vec<(&'static str, Value)>,
    children: Vec<Rc<ObjectDesc>>,
}

fn obj(kind: PluginKind, plugin: &'static str) -> Obj {
    Obj { kind, plugin, props: Vec::new(), children: Vec::new() }
}

impl Obj {
    fn with(mut self, name: &'static str, v: Value) -> Obj {
        self.props.push((name, v));
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
            props.push(name, v, SrcPos::new("test.xml", line, 5)).unwrap();
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

/// Film width, height and crop window (offset x, offset y, width, height).
type FilmSpec = (i64, i64, Option<(i64, i64, i64, i64)>);
/// Film position in pixels, then Mitsuba's ray o, d and maxt.
type RaySpec = ([f32; 2], [f32; 3], [f32; 3], f32);

struct Case {
    name: &'static str,
    params: &'static [(&'static str, P)],
    film: FilmSpec,
    to_world_rows: [[f64; 4]; 4],
    rays: &'static [RaySpec],
}

#[rustfmt::skip]
const CASES: &[Case] = &[
    // fov_x_default: {'fov': 45.0} film 64x48 crop None look_at None
    Case {
        name: "fov_x_default",
        params: &[("fov", F(45.0))],
        film: (64, 48, None),
        to_world_rows: [[1.000000000e+00, 0.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 1.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, 1.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00]],
        rays: &[
            ([3.200000000e+01, 2.400000000e+01], [5.960464344e-10, 2.980232172e-10, 9.999999776e-03], [5.960464478e-08, 2.980232239e-08, 1.000000000e+00], 9.999990234e+03),
            ([0.000000000e+00, 0.000000000e+00], [4.142135382e-03, 3.106602235e-03, 1.000000071e-02], [3.678328395e-01, 2.758746743e-01, 8.880270720e-01], 1.126090723e+04),
            ([6.400000000e+01, 4.800000000e+01], [-4.142133985e-03, -3.106600838e-03, 9.999998845e-03], [-3.678328097e-01, -2.758746147e-01, 8.880271912e-01], 1.126090430e+04),
            ([1.600000000e+01, 3.840000000e+01], [2.071068157e-03, -1.863960526e-03, 9.999999776e-03], [1.995070279e-01, -1.795562506e-01, 9.633049369e-01], 1.038091797e+04),
            ([5.760000000e+01, 4.800000000e+00], [-3.313707188e-03, 2.485281555e-03, 9.999999776e-03], [-3.061466813e-01, 2.296101004e-01, 9.238796234e-01], 1.082391016e+04),
        ],
    },
    // focal_default: {} film 768x576 crop None look_at ((0, 0, 5), (0, 0, 0), (0, 1, 0))
    Case {
        name: "focal_default",
        params: &[],
        film: (768, 576, None),
        to_world_rows: [[-1.000000000e+00, 0.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 1.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, -1.000000000e+00, 5.000000000e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00]],
        rays: &[
            ([3.840000000e+02, 2.880000000e+02], [-2.980232172e-10, 2.980232172e-10, 4.989999771e+00], [-2.980232239e-08, 2.980232239e-08, -1.000000000e+00], 9.999990234e+03),
            ([0.000000000e+00, 0.000000000e+00], [-3.461328801e-03, 2.595996484e-03, 4.989999771e+00], [-3.176734447e-01, 2.382550836e-01, -9.177788496e-01], 1.089586035e+04),
            ([7.680000000e+02, 5.760000000e+02], [3.461328102e-03, -2.595996251e-03, 4.989999771e+00], [3.176733851e-01, -2.382550538e-01, -9.177788496e-01], 1.089586035e+04),
            ([1.920000000e+02, 4.608000000e+02], [-1.730664633e-03, -1.557597658e-03, 4.989999771e+00], [-1.685577482e-01, -1.517019272e-01, -9.739480615e-01], 1.026747754e+04),
            ([6.912000000e+02, 5.760000000e+01], [2.769062528e-03, 2.076797420e-03, 4.989999771e+00], [2.616742551e-01, 1.962557435e-01, -9.449921846e-01], 1.058208691e+04),
        ],
    },
    // focal_35mm_tall: {'focal_length': '35mm'} film 40x90 crop None look_at ((1, 2, 3), (0, 0.5, 0), (0, 0, 1))
    Case {
        name: "focal_35mm_tall",
        params: &[("focal_length", S("35mm"))],
        film: (40, 90, None),
        to_world_rows: [[8.320503235e-01, -4.754573405e-01, -2.857142985e-01, 1.000000000e+00], [-5.547001958e-01, -7.131860256e-01, -4.285714626e-01, 2.000000000e+00], [0.000000000e+00, 5.150787830e-01, -8.571429253e-01, 3.000000000e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00]],
        rays: &[
            ([2.000000000e+01, 4.500000000e+01], [9.971428514e-01, 1.995714307e+00, 2.991428614e+00], [-2.857143283e-01, -4.285715520e-01, -8.571428657e-01], 9.999990234e+03),
            ([0.000000000e+00, 0.000000000e+00], [9.965460896e-01, 1.990293622e+00, 2.994337797e+00], [-2.937998176e-01, -8.256550431e-01, -4.816382825e-01], 1.175601270e+04),
            ([4.000000000e+01, 9.000000000e+01], [9.977396131e-01, 2.001134872e+00, 2.988519192e+00], [-1.922732741e-01, 9.654534608e-02, -9.765808582e-01], 1.175600977e+04),
            ([1.000000000e+01, 7.200000000e+01], [9.997984767e-01, 1.997434974e+00, 2.989682913e+00], [-1.895002648e-02, -2.412319630e-01, -9.702824950e-01], 1.063297070e+04),
            ([3.600000000e+01, 9.000000000e+00], [9.933235049e-01, 1.993605733e+00, 2.993756056e+00], [-5.984811783e-01, -5.731863379e-01, -5.597122908e-01], 1.115573242e+04),
        ],
    },
    // fov_y: {'fov': 30.0, 'fov_axis': 'y'} film 100x50 crop None look_at ((2, -1, 4), (0, 0, 0), (0, 1, 0))
    Case {
        name: "fov_y",
        params: &[("fov", F(30.0)), ("fov_axis", S("y"))],
        film: (100, 50, None),
        to_world_rows: [[-8.944271207e-01, 9.758999199e-02, -4.364357591e-01, 2.000000000e+00], [0.000000000e+00, 9.758999348e-01, 2.182178795e-01, -1.000000000e+00], [4.472135603e-01, 1.951799840e-01, -8.728715181e-01, 4.000000000e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00]],
        rays: &[
            ([5.000000000e+01, 2.500000000e+01], [1.995635629e+00, -9.978178144e-01, 3.991271257e+00], [-4.364358187e-01, 2.182179093e-01, -8.728714585e-01], 9.999990234e+03),
            ([0.000000000e+00, 0.000000000e+00], [1.991103888e+00, -9.952028990e-01, 3.994190931e+00], [-7.631182075e-01, 4.115011990e-01, -4.983142912e-01], 1.165753516e+04),
            ([1.000000000e+02, 5.000000000e+01], [2.000167370e+00, -1.000432730e+00, 3.988351583e+00], [1.435720269e-02, -3.712071106e-02, -9.992075562e-01], 1.165753418e+04),
            ([2.500000000e+01, 4.000000000e+01], [1.993082166e+00, -9.993867874e-01, 3.992155790e+00], [-6.603000164e-01, 5.853188038e-02, -7.487175465e-01], 1.047683789e+04),
            ([9.000000000e+01, 5.000000000e+00], [1.999679446e+00, -9.957258701e-01, 3.989772320e+00], [-2.890954167e-02, 3.854228854e-01, -9.222869873e-01], 1.108939648e+04),
        ],
    },
    // fov_diagonal: {'fov': 60.0, 'fov_axis': 'diagonal'} film 30x20 crop None look_at None
    Case {
        name: "fov_diagonal",
        params: &[("fov", F(60.0)), ("fov_axis", S("diagonal"))],
        film: (30, 20, None),
        to_world_rows: [[1.000000000e+00, 0.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 1.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, 1.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00]],
        rays: &[
            ([1.500000000e+01, 1.000000000e+01], [5.960464344e-10, 2.980232172e-10, 9.999999776e-03], [5.960464478e-08, 2.980232239e-08, 1.000000000e+00], 9.999990234e+03),
            ([0.000000000e+00, 0.000000000e+00], [4.803844728e-03, 3.202562919e-03, 9.999999776e-03], [4.160251617e-01, 2.773500979e-01, 8.660253882e-01], 1.154699316e+04),
            ([3.000000000e+01, 2.000000000e+01], [-4.803843331e-03, -3.202562453e-03, 9.999999776e-03], [-4.160250723e-01, -2.773500681e-01, 8.660254478e-01], 1.154699316e+04),
            ([7.500000000e+00, 1.600000000e+01], [2.401922829e-03, -1.921537449e-03, 9.999999776e-03], [2.295769453e-01, -1.836614907e-01, 9.558048844e-01], 1.046237598e+04),
            ([2.700000000e+01, 2.000000000e+00], [-3.843074432e-03, 2.562050475e-03, 9.999999776e-03], [-3.488901854e-01, 2.325935364e-01, 9.078413248e-01], 1.101512988e+04),
        ],
    },
    // fov_smaller_tall: {'fov': 50.0, 'fov_axis': 'smaller'} film 20x30 crop None look_at ((0, 3, 0), (0, 0, 0), (0, 0, -1))
    Case {
        name: "fov_smaller_tall",
        params: &[("fov", F(50.0)), ("fov_axis", S("smaller"))],
        film: (20, 30, None),
        to_world_rows: [[-1.000000000e+00, 0.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, -1.000000000e+00, 3.000000000e+00], [0.000000000e+00, -1.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00]],
        rays: &[
            ([1.000000000e+01, 1.500000000e+01], [-5.960464344e-10, 2.990000010e+00, -5.960464344e-10], [-5.960464478e-08, -1.000000000e+00, -5.960464478e-08], 9.999990234e+03),
            ([0.000000000e+00, 0.000000000e+00], [-4.663076252e-03, 2.990000010e+00, -6.994614378e-03], [-3.569400609e-01, -7.654604912e-01, -5.354101062e-01], 1.306401855e+04),
            ([2.000000000e+01, 3.000000000e+01], [4.663075320e-03, 2.990000010e+00, 6.994613912e-03], [3.569400311e-01, -7.654605508e-01, 5.354101062e-01], 1.306401758e+04),
            ([5.000000000e+00, 2.400000000e+01], [-2.331538359e-03, 2.990000010e+00, 4.196767695e-03], [-2.101859301e-01, -9.014903307e-01, 3.783345819e-01], 1.109273145e+04),
            ([1.800000000e+01, 3.000000000e+00], [3.730459604e-03, 2.990000010e+00, -5.595691036e-03], [3.095544577e-01, -8.298023939e-01, -4.643318355e-01], 1.205104980e+04),
        ],
    },
    // fov_larger_tall: {'fov': 50.0, 'fov_axis': 'larger'} film 20x30 crop None look_at None
    Case {
        name: "fov_larger_tall",
        params: &[("fov", F(50.0)), ("fov_axis", S("larger"))],
        film: (20, 30, None),
        to_world_rows: [[1.000000000e+00, 0.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 1.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, 1.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00]],
        rays: &[
            ([1.000000000e+01, 1.500000000e+01], [2.980232172e-10, 2.980232172e-10, 9.999999776e-03], [2.980232239e-08, 2.980232239e-08, 1.000000000e+00], 9.999990234e+03),
            ([0.000000000e+00, 0.000000000e+00], [3.108717501e-03, 4.663076717e-03, 9.999999776e-03], [2.711875141e-01, 4.067812860e-01, 8.723452687e-01], 1.146333984e+04),
            ([2.000000000e+01, 3.000000000e+01], [-3.108717036e-03, -4.663075786e-03, 9.999999776e-03], [-2.711874843e-01, -4.067812562e-01, 8.723453283e-01], 1.146333887e+04),
            ([5.000000000e+00, 2.400000000e+01], [1.554358867e-03, -2.797845285e-03, 9.999998845e-03], [1.480382383e-01, -2.664687634e-01, 9.524070024e-01], 1.049970215e+04),
            ([1.800000000e+01, 3.000000000e+00], [-2.486973535e-03, 3.730461234e-03, 9.999999776e-03], [-2.269327492e-01, 3.403992057e-01, 9.124855399e-01], 1.095906738e+04),
        ],
    },
    // crop_window: {'fov': 40.0, 'near_clip': 0.5, 'far_clip': 200.0} film 64x48 crop (10, 6, 20, 30) look_at ((-3, 1, 2), (0.5, 0, 0), (0, 1, 0))
    Case {
        name: "crop_window",
        params: &[("fov", F(40.0)), ("near_clip", F(0.5)), ("far_clip", F(200.0))],
        film: (64, 48, Some((10, 6, 20, 30))),
        to_world_rows: [[-4.961389601e-01, 2.090483904e-01, 8.427009583e-01, -3.000000000e+00], [0.000000000e+00, 9.705818295e-01, -2.407717109e-01, 1.000000000e+00], [-8.682431579e-01, -1.194562241e-01, -4.815434217e-01, 2.000000000e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00]],
        rays: &[
            ([2.000000000e+01, 2.100000000e+01], [-2.608941555e+00, 8.961733580e-01, 1.697937489e+00], [7.744893432e-01, -2.056282312e-01, -5.982335210e-01], 2.014647217e+02),
            ([1.000000000e+01, 6.000000000e+00], [-2.619324207e+00, 9.789693356e-01, 1.638369918e+00], [7.244299054e-01, -4.002157971e-02, -6.881858110e-01], 2.096677856e+02),
            ([3.000000000e+01, 3.600000000e+01], [-2.598559141e+00, 8.133773804e-01, 1.757505059e+00], [7.953043580e-01, -3.697226048e-01, -4.804126024e-01], 2.014008179e+02),
            ([1.500000000e+01, 3.000000000e+01], [-2.633749247e+00, 8.464957476e-01, 1.679363012e+00], [7.175717354e-01, -3.007510602e-01, -6.282035708e-01], 2.036508179e+02),
            ([2.800000000e+01, 9.000000000e+00], [-2.572102785e+00, 9.624101520e-01, 1.729287028e+00], [8.427574635e-01, -7.403447479e-02, -5.331779122e-01], 2.025861511e+02),
        ],
    },
    // principal_point: {'fov': 40.0, 'principal_point_offset_x': 0.1, 'principal_point_offset_y': -0.2} film 64x48 crop (8, 4, 32, 24) look_at None
    Case {
        name: "principal_point",
        params: &[("fov", F(40.0)), ("principal_point_offset_x", F(0.1)), ("principal_point_offset_y", F(-0.2))],
        film: (64, 48, Some((8, 4, 32, 24))),
        to_world_rows: [[1.000000000e+00, 0.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 1.000000000e+00, 0.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, 1.000000000e+00, 0.000000000e+00], [0.000000000e+00, 0.000000000e+00, 0.000000000e+00, 1.000000000e+00]],
        rays: &[
            ([2.400000000e+01, 1.600000000e+01], [1.819852332e-04, 2.001836430e-03, 9.999999776e-03], [1.784164831e-02, 1.962580085e-01, 9.803898931e-01], 1.020001367e+04),
            ([8.000000000e+00, 4.000000000e+00], [2.001836197e-03, 3.366724821e-03, 9.999999776e-03], [1.863950938e-01, 3.134826720e-01, 9.311205745e-01], 1.073973633e+04),
            ([4.000000000e+01, 2.800000000e+01], [-1.637865906e-03, 6.369479233e-04, 9.999999776e-03], [-1.613145918e-01, 6.273346394e-02, 9.849072099e-01], 1.015323145e+04),
            ([1.600000000e+01, 2.320000000e+01], [1.091910643e-03, 1.182903186e-03, 9.999998845e-03], [1.078031287e-01, 1.167867258e-01, 9.872888923e-01], 1.012873730e+04),
            ([3.680000000e+01, 6.400000000e+00], [-1.273895497e-03, 3.093746724e-03, 9.999998845e-03], [-1.208072528e-01, 2.933890820e-01, 9.483292699e-01], 1.054484961e+04),
        ],
    },
];

fn close(a: Vec3, b: Vec3, tol: f32) -> bool {
    (a - b).abs().max_element() <= tol * (1.0 + b.abs().max_element())
}

#[test]
fn perspective_rays_match_mitsuba() {
    for case in CASES {
        let (w, h, crop) = case.film;
        let mut film = obj(PluginKind::Film, "hdrfilm").with("width", int(w)).with("height", int(h));
        if let Some((cx, cy, cw, ch)) = crop {
            film = film
                .with("crop_offset_x", int(cx))
                .with("crop_offset_y", int(cy))
                .with("crop_width", int(cw))
                .with("crop_height", int(ch));
        }
        let to_world = DMat4::from_cols_array_2d(&case.to_world_rows).transpose();
        let mut s = obj(PluginKind::Sensor, "perspective").child(film.build());
        for (name, p) in case.params {
            s = s.with(name, value(p));
        }
        if to_world != DMat4::IDENTITY {
            s = s.with("to_world", Value::Transform(to_world));
        }
        let sensor = sensor(s).unwrap_or_else(|e| panic!("{}: {e}", case.name));
        let origin = to_world.transform_point3(DVec3::ZERO).as_vec3();
        assert!(close(sensor.camera.position(), origin, 1e-6), "{}: position", case.name);
        for &(pos, o, d, maxt) in case.rays {
            let ray = sensor.camera.sample_ray(Vec2::from(pos), Vec2::splat(0.5));
            let (o, d) = (Vec3::from(o), Vec3::from(d));
            assert!(close(ray.d, d, 2e-6), "{} at {pos:?}: d {} vs Mitsuba {}", case.name, ray.d, d);
            assert!(close(ray.o, o, 2e-6), "{} at {pos:?}: o {} vs Mitsuba {}", case.name, ray.o, o);
            assert!((ray.tmax - maxt).abs() <= 2e-6 * maxt, "{} at {pos:?}: tmax {} vs {}", case.name, ray.tmax, maxt);
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

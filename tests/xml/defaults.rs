//! Mitsuba's defaults for the plugins built in `scene/build.rs`, `medium/` and `integrator/`
//! (values read from Mitsuba 3.9.1: `mi.load_dict({'type': 'homogeneous'})` etc.).

use snee::bsdf::Bsdf;
use snee::integrator::IntegratorKind;
use snee::medium::Phase;
use snee::scene::build::build_scene;
use snee::scene::world::{Scene, SceneEmitter};
use snee::scene::xml::parse_str;
use snee::shape::Geometry;
use snee::texture::Texture;

fn load_err(body: &str) -> String {
    match load(body) {
        Ok(_) => panic!("{} loaded but should not", body),
        Err(e) => e,
    }
}

fn load(body: &str) -> Result<Scene, String> {
    let xml = format!(
        r#"<scene version="3.0.0">{body}<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor></scene>"#
    );
    let parsed = parse_str(&xml, "t.xml", std::path::Path::new("."), &[]).map_err(|e| e.to_string())?;
    build_scene(&parsed).map_err(|e| e.to_string())
}

#[test]
fn medium_and_phase_defaults() {
    let s = load(r#"<shape type="sphere"><medium name="interior" type="homogeneous"/></shape>
                    <shape type="sphere"><medium name="interior" type="homogeneous"><phase type="hg"/></medium></shape>"#)
    .unwrap();
    let m = &s.media[0];
    assert_eq!(m.albedo.to_array(), [0.75; 3]);
    assert_eq!(m.sigma_t.to_array(), [1.0; 3]);
    assert!(m.sample_emitters);
    assert_eq!(m.phase, Phase::Isotropic);
    assert_eq!(s.media[1].phase, Phase::Hg { g: 0.8 });
    // A medium boundary without a BSDF gets diffuse 0.5 in Mitsuba 3.9 (not null).
    match &s.bsdfs[s.shapes[0].bsdf as usize] {
        Bsdf::Diffuse(d) => assert!(matches!(d.reflectance, Texture::Const(c) if c.to_array() == [0.5; 3])),
        other => panic!("default BSDF {:?}", other),
    }
}

#[test]
fn integrator_defaults() {
    let s = load("").unwrap();
    assert_eq!(s.integrator.kind, IntegratorKind::Path);
    assert_eq!((s.integrator.max_depth, s.integrator.rr_depth, s.integrator.hide_emitters), (-1, 5, false));
    let s = load(r#"<integrator type="moment"><integrator type="volpath"><integer name="max_depth" value="3"/></integrator></integrator>"#).unwrap();
    assert_eq!((s.integrator.kind, s.integrator.max_depth, s.integrator.moment), (IntegratorKind::Volpath, 3, true));
    assert!(load_err(r#"<integrator type="path"><float name="max_depth" value="3"/></integrator>"#).contains("integer"));
    assert!(load_err(r#"<integrator type="bdpt"/>"#).contains("not supported"));
}

#[test]
fn shape_and_area_light_defaults() {
    let s = load(r#"<shape type="sphere"><emitter type="area"/></shape><shape type="sphere"/>"#).unwrap();
    match &s.shapes[0].geometry {
        Geometry::Sphere(sp) => assert_eq!((sp.center.to_array(), sp.radius), ([0.0; 3], 1.0)),
        _ => panic!(),
    }
    // Area light: radiance 1 (untinted); an emitter shape without a BSDF is black diffuse.
    match &s.emitters[0] {
        SceneEmitter::Area { radiance: Texture::Const(c), .. } => assert_eq!(c.to_array(), [1.0; 3]),
        other => panic!("{:?}", other),
    }
    for (shape, expected) in [(0usize, 0.0f32), (1, 0.5)] {
        match &s.bsdfs[s.shapes[shape].bsdf as usize] {
            Bsdf::Diffuse(d) => assert!(matches!(d.reflectance, Texture::Const(c) if c.to_array() == [expected; 3])),
            other => panic!("{:?}", other),
        }
    }
    // Uniform <spectrum> on an emitter is tinted as Mitsuba's RGB mode does; <rgb> is not.
    let s =
        load(r#"<shape type="sphere"><emitter type="area"><spectrum name="radiance" value="2"/></emitter></shape>"#)
            .unwrap();
    match &s.emitters[0] {
        SceneEmitter::Area { radiance: Texture::Const(c), .. } => {
            let expected = [2.40959, 1.89658, 1.81783]; // Mitsuba 3.9.1, scalar_rgb
            for k in 0..3 {
                assert!((c[k] - expected[k]).abs() < 1e-3, "{:?}", c);
            }
        }
        other => panic!("{:?}", other),
    }
}

#[test]
fn shape_errors() {
    for (body, needle) in [
        (r#"<shape type="sphere"><float name="radius" value="-1"/></shape>"#, "radius"),
        (r#"<shape type="ply"/>"#, "filename"),
        (r#"<shape type="ply"><string name="filename" value="nope.ply"/></shape>"#, "not found"),
        (r#"<shape type="sphere"><emitter type="point"/></shape>"#, "only \"area\""),
        (r#"<emitter type="area"/>"#, "inside a <shape>"),
        (
            r#"<shape type="sphere"><transform name="to_world"><scale x="1" y="2" z="1"/></transform></shape>"#,
            "non-uniform",
        ),
        (r#"<emitter type="constant"/><emitter type="constant"/>"#, "at most one environment"),
        (r#"<integrator type="path"/><integrator type="path"/>"#, "at most one integrator"),
        (r#"<film type="hdrfilm"/>"#, "nested"),
    ] {
        let e = load_err(body);
        assert!(e.contains(needle), "{}: {}", body, e);
        assert!(e.starts_with("t.xml:"), "{}", e);
    }
}

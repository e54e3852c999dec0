//! The XML parser on valid scenes: every property type, parameters, includes, paths, references,
//! aliases, version upgrade, and transform / spectrum values compared with Mitsuba 3.9.1.

use crate::data_dir;
use glam::{DMat4, DVec3};
use snee::scene::desc::{ObjectDesc, PluginKind, Prop, SpectrumValue, Value};
use snee::scene::xml::{parse_file, parse_str, ParsedScene};
use std::rc::Rc;

fn defines(d: &[(&str, &str)]) -> Vec<(String, String)> {
    d.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect()
}

fn parse_with(text: &str, d: &[(&str, &str)]) -> ParsedScene {
    match parse_str(text, "test.xml", &data_dir(), &defines(d)) {
        Ok(s) => s,
        Err(e) => panic!("parse failed: {e}"),
    }
}

fn parse(text: &str) -> ParsedScene {
    parse_with(text, &[])
}

/// Wrap scene content in a `<scene>`.
fn scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>")
}

fn prop<'a>(o: &'a ObjectDesc, name: &str) -> &'a Prop {
    o.props.items().iter().find(|p| p.name == name).unwrap_or_else(|| panic!("no property {name} on {}", o.plugin))
}

fn obj<'a>(o: &'a ObjectDesc, name: &str) -> &'a Rc<ObjectDesc> {
    match &prop(o, name).value {
        Value::Object(x) => x,
        v => panic!("{name} is a {}", v.type_name()),
    }
}

fn names(o: &ObjectDesc) -> Vec<String> {
    o.props.items().iter().map(|p| p.name.clone()).collect()
}

fn float(o: &ObjectDesc, name: &str) -> f64 {
    match prop(o, name).value {
        Value::Float(v) => v,
        ref v => panic!("{name} is a {}", v.type_name()),
    }
}

fn vec3(v: &Value) -> DVec3 {
    match v {
        Value::Point(p) | Value::Vector(p) | Value::Rgb(p) => *p,
        v => panic!("not a 3-vector: {}", v.type_name()),
    }
}

fn transform(v: &Value) -> DMat4 {
    match v {
        Value::Transform(m) => *m,
        v => panic!("not a transform: {}", v.type_name()),
    }
}

fn rows(m: DMat4) -> [[f64; 4]; 4] {
    m.transpose().to_cols_array_2d()
}

#[test]
fn every_property_type() {
    let s = parse(&scene(
        r#"<bsdf type="test" id="all">
    <float name="f" value=" 1.5e1 "/>
    <integer name="i" value="-42"/>
    <boolean name="b1" value="TRUE"/>
    <boolean name="b2" value="false"/>
    <string name="s" value="a &amp; b"/>
    <point name="p" x="1" y="2" z="3"/>
    <point name="p2" value="4, 5, 6"/>
    <vector name="v" value="7"/>
    <rgb name="c1" value="0.1 0.2 0.3"/>
    <rgb name="c2" value="0.1,0.2,0.3"/>
    <rgb name="c3" value="0.5"/>
    <spectrum name="su" value="0.25"/>
    <spectrum name="sl" value="400:0.1, 500:0.5, 600:0.9, 700:0.3"/>
    <transform name="t"><translate x="1"/></transform>
</bsdf>"#,
    ));
    let b = obj(&s.root, "_arg_0");
    assert_eq!((b.kind, b.plugin.as_str(), b.id.as_deref()), (PluginKind::Bsdf, "test", Some("all")));
    assert_eq!(float(b, "f"), 15.0);
    assert!(matches!(prop(b, "i").value, Value::Integer(-42)));
    assert!(matches!(prop(b, "b1").value, Value::Bool(true)));
    assert!(matches!(prop(b, "b2").value, Value::Bool(false)));
    assert!(matches!(&prop(b, "s").value, Value::String(s) if s == "a & b"));
    assert!(matches!(prop(b, "p").value, Value::Point(p) if p == DVec3::new(1.0, 2.0, 3.0)));
    assert!(matches!(prop(b, "p2").value, Value::Point(p) if p == DVec3::new(4.0, 5.0, 6.0)));
    assert!(matches!(prop(b, "v").value, Value::Vector(p) if p == DVec3::splat(7.0)));
    for c in ["c1", "c2"] {
        assert!(matches!(prop(b, c).value, Value::Rgb(_)));
        assert_eq!(vec3(&prop(b, c).value), DVec3::new(0.1, 0.2, 0.3));
    }
    assert_eq!(vec3(&prop(b, "c3").value), DVec3::splat(0.5));
    assert!(matches!(prop(b, "su").value, Value::Spectrum(SpectrumValue::Uniform(v)) if v == 0.25));
    assert!(matches!(prop(b, "sl").value, Value::Spectrum(SpectrumValue::Rgb(_))));
    assert_eq!(rows(transform(&prop(b, "t").value))[0], [1.0, 0.0, 0.0, 1.0]);
    // Document order is kept.
    assert_eq!(names(b)[..3], ["f", "i", "b1"]);
}

#[test]
fn positions_of_objects_and_properties() {
    let s = parse("<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n      <float name=\"radius\" value=\"2\"/>\n  </shape>\n</scene>");
    assert_eq!(s.root.kind, PluginKind::Scene);
    assert_eq!(s.root.plugin, "scene");
    assert_eq!(s.root.pos.to_string(), "test.xml:1:1");
    let sh = obj(&s.root, "_arg_0");
    assert_eq!(sh.pos.to_string(), "test.xml:2:3");
    assert_eq!(prop(&s.root, "_arg_0").pos.to_string(), "test.xml:2:3");
    assert_eq!(prop(sh, "radius").pos.to_string(), "test.xml:3:7");
    assert_eq!(sh.props.owner_pos.to_string(), "test.xml:2:3");
}

#[test]
fn unnamed_objects_are_numbered_like_mitsuba() {
    // Mitsuba 3.9.1: _arg_N counts only unnamed objects and refs, per parent.
    let s = parse(&scene(
        r#"<shape type="sphere">
    <bsdf type="diffuse"/>
    <float name="radius" value="1"/>
    <bsdf type="diffuse" name="named"/>
    <ref id="q"/>
</shape>
<bsdf type="diffuse" id="q"/>"#,
    ));
    assert_eq!(names(&s.root), ["_arg_0", "_arg_1"]);
    assert_eq!(names(obj(&s.root, "_arg_0")), ["_arg_0", "radius", "named", "_arg_1"]);
}

#[test]
fn spectrum_with_type_is_a_texture_object() {
    let s = parse(&scene(r#"<bsdf type="diffuse"><spectrum type="regular" name="reflectance"/></bsdf>"#));
    let t = obj(obj(&s.root, "_arg_0"), "reflectance");
    assert_eq!((t.kind, t.plugin.as_str()), (PluginKind::Texture, "regular"));
}

#[test]
fn defaults_defines_and_escapes() {
    let text = scene(
        r#"<default name="spp" value="4"/>
<default name="spp" value="5"/>
<default name="ab" value="X"/>
<default name="a" value="Y"/>
<sampler type="independent">
    <integer name="sample_count" value="$spp"/>
    <string name="s" value="$ab $a $abc \$a"/>
</sampler>"#,
    );
    let s = parse(&text);
    let sampler = obj(&s.root, "_arg_0");
    // The first <default> wins over the second; longest key first, textual (Mitsuba: "X Y Xc $a").
    assert!(matches!(prop(sampler, "sample_count").value, Value::Integer(4)));
    assert!(matches!(&prop(sampler, "s").value, Value::String(v) if v == "X Y Xc $a"));
    // -D wins over <default>.
    let s = parse_with(&text, &[("spp", "16")]);
    assert!(matches!(prop(obj(&s.root, "_arg_0"), "sample_count").value, Value::Integer(16)));
    // Substitution applies to every attribute, including type and name.
    let s = parse_with(
        &scene(r#"<shape type="$t"><float name="$n" value="1"/></shape>"#),
        &[("t", "sphere"), ("n", "radius")],
    );
    let sh = obj(&s.root, "_arg_0");
    assert_eq!(sh.plugin, "sphere");
    assert_eq!(float(sh, "radius"), 1.0);
}

#[test]
fn include_inserts_objects_and_keeps_their_positions() {
    let s = parse_file(&data_dir().join("include_main.xml"), &[]).unwrap();
    // Mitsuba 3.9.1 gives the same structure: red, blue, sphere(radius, bsdf=red), s1.
    assert_eq!(names(&s.root), ["_arg_0", "_arg_1", "_arg_2", "_arg_3"]);
    let red = obj(&s.root, "_arg_0");
    let blue = obj(&s.root, "_arg_1");
    assert_eq!(blue.id.as_deref(), Some("blue"));
    let file = blue.pos.file.to_string();
    assert!(file.ends_with("sub/part.xml"), "{file}");
    assert_eq!((blue.pos.line, blue.pos.col), (4, 5));
    // The included file is version 0.6: its names are upgraded.
    assert_eq!(names(blue), ["reflectance"]);
    let sphere = obj(&s.root, "_arg_2");
    assert_eq!(float(sphere, "radius"), 2.0); // $radius from the main file's <default>
    assert!(Rc::ptr_eq(obj(sphere, "bsdf"), red));
    assert_eq!((prop(sphere, "radius").pos.line, prop(sphere, "radius").pos.col), (8, 9));
    // Non-object properties of an included <scene> are dropped, as in Mitsuba.
    assert!(!names(&s.root).contains(&"dropped".to_string()));
    // A file whose root is an object becomes a nested object named by <include name>.
    let s1 = obj(&s.root, "_arg_3");
    assert!(Rc::ptr_eq(obj(s1, "_arg_0"), blue));
    let leaf = obj(s1, "bsdf_leaf");
    assert_eq!((leaf.kind, leaf.plugin.as_str(), leaf.id.as_deref()), (PluginKind::Bsdf, "conductor", Some("leaf")));
    assert!(leaf.pos.file.ends_with("sub/leaf.xml"));
    assert_eq!((leaf.pos.line, leaf.pos.col), (1, 1));
}

#[test]
fn path_adds_a_search_folder() {
    let s = parse_file(&data_dir().join("path_main.xml"), &[]).unwrap();
    let e = obj(&s.root, "_arg_0");
    assert_eq!(e.plugin, "constant");
    assert!(e.pos.file.ends_with("extra/from_extra.xml"));
    // The resolver searches the <path> folder first, then the scene's folder.
    assert_eq!(s.resolver.paths.len(), 2);
    assert!(s.resolver.paths[0].ends_with("extra"));
    assert_eq!(s.resolver.paths[1], data_dir());
    assert!(s.resolver.resolve("from_extra.xml").is_some());
}

#[test]
fn refs_are_shared_and_may_point_forward() {
    let s = parse(&scene(
        r#"<shape type="sphere">
    <ref id="glass"/>
    <ref name="interior" id="smoke"/>
</shape>
<shape type="sphere"><ref id="glass"/></shape>
<bsdf type="dielectric" id="glass"/>
<medium type="homogeneous" id="smoke"/>"#,
    ));
    let a = obj(&s.root, "_arg_0");
    let b = obj(&s.root, "_arg_1");
    let glass = obj(&s.root, "_arg_2");
    assert!(Rc::ptr_eq(obj(a, "_arg_0"), glass));
    assert!(Rc::ptr_eq(obj(b, "_arg_0"), glass));
    assert!(Rc::ptr_eq(obj(a, "interior"), obj(&s.root, "_arg_3")));
    // The property position of a reference is the <ref> element.
    assert_eq!(prop(a, "interior").pos.line, 4);
}

#[test]
fn alias_names_the_same_object() {
    let s = parse(&scene(
        r#"<bsdf type="diffuse" id="a"/>
<alias id="a" as="b"/>
<shape type="sphere"><ref id="b"/></shape>"#,
    ));
    assert!(Rc::ptr_eq(obj(obj(&s.root, "_arg_1"), "_arg_0"), obj(&s.root, "_arg_0")));
}

#[test]
fn version_0_6_is_upgraded_like_mitsuba() {
    // Expected names and to_uv from Mitsuba 3.9.1's transform_upgrade on the same file.
    let s = parse_file(&data_dir().join("old_v06.xml"), &[]).unwrap();
    assert_eq!(names(obj(&s.root, "_arg_0")), ["max_depth", "rr_depth"]);
    assert_eq!(names(obj(&s.root, "_arg_1")), ["reflectance"]);
    assert_eq!(names(obj(&s.root, "_arg_2")), ["diffuse_reflectance", "int_ior"]);
    let tex = obj(&s.root, "_arg_3");
    assert_eq!(names(tex), ["to_uv"]);
    assert_eq!(
        rows(transform(&prop(tex, "to_uv").value)),
        [[3.0, 0.0, 0.0, 1.5], [0.0, 2.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    );
    assert_eq!(names(obj(&s.root, "_arg_4")), ["to_world", "my_bsdf"]);
    // Version 2 and later are left alone.
    let s = parse("<scene version=\"2.0.0\"><float name=\"fooBar\" value=\"1\"/></scene>");
    assert_eq!(names(&s.root), ["fooBar"]);
}

// Generated by scripts/transforms_expected.py (Mitsuba 3.9.1): the matrix Mitsuba's parser
// builds for each <transform> body (checked there against composing mi.ScalarAffineTransform4d
// operations, each multiplied from the left).
#[rustfmt::skip]
#[allow(clippy::approx_constant)] // numbers printed by Mitsuba
const TRANSFORM_CASES: &[(&str, [[f64; 4]; 4])] = &[
    (r#"<translate x="1" y="2" z="3"/><rotate y="1" angle="30"/>"#, [[0.8660254037844387, 0.0, 0.49999999999999994, 2.3660254037844384], [0.0, 1.0, 0.0, 2.0], [-0.49999999999999994, 0.0, 0.8660254037844387, 2.098076211353316], [0.0, 0.0, 0.0, 1.0]]),
    (r#"<scale value="2"/><rotate value="1, 1, 0" angle="45"/><translate value="0.5 -1 2"/>"#, [[2.0, 0.5857864376269049, 1.414213562373095, 0.5], [0.5857864376269049, 2.0, -1.414213562373095, -1.0], [-1.414213562373095, 1.414213562373095, 1.4142135623730951, 2.0], [0.0, 0.0, 0.0, 1.0]]),
    (r#"<matrix value="0 -1 0 1  1 0 0 2  0 0 1 3  0 0 0 1"/><scale x="2" y="3" z="4"/>"#, [[0.0, -2.0, 0.0, 2.0], [3.0, 0.0, 0.0, 6.0], [0.0, 0.0, 4.0, 12.0], [0.0, 0.0, 0.0, 1.0]]),
    (r#"<lookat origin="1, 2, 3" target="0, 0, 0" up="0, 1, 0"/><translate z="-1"/>"#, [[-0.9486832980505138, -0.16903085094570333, -0.2672612419124244, 1.0], [0.0, 0.8451542547285166, -0.5345224838248488, 2.0], [0.31622776601683794, -0.50709255283711, -0.8017837257372732, 2.0], [0.0, 0.0, 0.0, 1.0]]),
    (r#"<rotate x="2" y="0.5" angle="-60"/><matrix value="1 0.5 0  0 1 0  0.2 0 1"/>"#, [[2.7499999999999996, 0.8125, 0.4330127018922193, 0.0], [0.4999999999999999, 0.6250000000000001, 1.7320508075688772, 0.0], [0.9330127018922192, -1.632050807568877, 0.4133974596215563, 0.0], [0.0, 0.0, 0.0, 1.0]]),
    (r#"<scale value="1 2 3"/><lookat origin="0 5 0" target="0 0 0"/>"#, [[0.0, 2.0, 0.0, 0.0], [0.0, 0.0, -3.0, 5.0], [-1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]),
    (r#"<translate value="1"/><rotate z="1" angle="90"/><scale y="-1"/>"#, [[6.123233995736757e-17, -1.0, 0.0, -0.9999999999999999], [-1.0, -6.123233995736757e-17, 0.0, -1.0], [0.0, 0.0, 1.0, 1.0], [0.0, 0.0, 0.0, 1.0]]),
];

#[test]
fn transforms_compose_like_mitsuba() {
    for (body, expected) in TRANSFORM_CASES {
        let s =
            parse(&scene(&format!("<shape type=\"sphere\"><transform name=\"to_world\">{body}</transform></shape>")));
        let got = rows(transform(&prop(obj(&s.root, "_arg_0"), "to_world").value));
        for (gr, er) in got.iter().zip(expected) {
            for (g, e) in gr.iter().zip(er) {
                assert!((g - e).abs() < 1e-12, "{body}: got {got:?}, Mitsuba {expected:?}");
            }
        }
    }
}

// Generated by scripts/spectrum_expected.py (Mitsuba 3.9.1, scalar_rgb): the colour a diffuse
// reflectance and an area emitter's radiance receive for each wavelength:value list.
#[rustfmt::skip]
const SPECTRUM_CASES: &[(&str, [f64; 3], [f64; 3])] = &[
    ("400:0.1, 500:0.5, 600:0.9, 700:0.3", [0.8547973036766052, 0.68753981590271, 0.26501521468162537], [0.9992340207099915, 0.6596997976303101, 0.22944438457489014]),
    ("380:0.8 450:0.2 520:0.6 610:0.1 780:0.9", [0.0744452252984047, 0.46733710169792175, 0.3085055947303772], [0.1293349266052246, 0.44006630778312683, 0.2872178256511688]),
    ("360:0, 450:0, 520:1, 560:0, 830:0", [0.0, 0.5040206909179688, 0.1340150088071823], [0.0, 0.4683985710144043, 0.11484766006469727]),
    ("400:2, 700:3", [1.0, 1.0, 1.0], [3.339694023132324, 2.3537614345550537, 1.9205830097198486]),
];

#[test]
fn spectrum_lists_convert_like_mitsuba_rgb_mode() {
    for (list, refl, rad) in SPECTRUM_CASES {
        let s = parse(&scene(&format!(
            r#"<bsdf type="diffuse"><spectrum name="reflectance" value="{list}"/></bsdf>
<shape type="sphere"><emitter type="area"><spectrum name="radiance" value="{list}"/></emitter></shape>"#
        )));
        let get = |o: &ObjectDesc, n: &str| match prop(o, n).value {
            Value::Spectrum(SpectrumValue::Rgb(c)) => c,
            ref v => panic!("{v:?}"),
        };
        let r = get(obj(&s.root, "_arg_0"), "reflectance");
        let e = get(obj(obj(&s.root, "_arg_1"), "_arg_0"), "radiance");
        // Mitsuba stores the result in single precision.
        for (got, want) in [(r, refl), (e, rad)] {
            for k in 0..3 {
                assert!((got[k] - want[k]).abs() < 2e-6 * want[k].max(1.0), "{list}: got {got}, Mitsuba {want:?}");
            }
        }
    }
}

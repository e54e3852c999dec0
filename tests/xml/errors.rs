//! The XML parser on broken scenes: every error is an `Error` (never a panic) positioned at the
//! offending element or attribute, in the file where it is, with a message that says what was
//! expected.

use crate::data_dir;
use snee::scene::xml::{parse_file, parse_str};

/// Parse `text` as `err.xml` and check the error's position and message.
fn expect_err(text: &str, defines: &[(&str, &str)], pos: &str, msg: &str) {
    let d: Vec<(String, String)> = defines.iter().map(|(a, b)| (a.to_string(), b.to_string())).collect();
    match parse_str(text, "err.xml", &data_dir(), &d) {
        Ok(_) => panic!("no error for:\n{text}"),
        Err(e) => {
            let got_pos = e.pos.as_ref().map(|p| p.to_string()).unwrap_or_default();
            assert_eq!(got_pos, pos, "position of \"{e}\" for:\n{text}");
            assert!(e.msg.contains(msg), "message \"{}\" lacks \"{msg}\" for:\n{text}", e.msg);
        }
    }
}

/// `expect_err` without `-D` values for every case of `test` in `CASES`.
fn expect_errs(test: &str) {
    let cases: Vec<_> = CASES.iter().filter(|c| c.0 == test).collect();
    assert!(!cases.is_empty(), "no cases for {test}");
    for (_, doc, pos, msg) in cases {
        let text = match doc {
            Scene(text) => text.to_string(),
            Body(body) => in_scene(body),
        };
        expect_err(&text, &[], &format!("err.xml:{pos}"), msg);
    }
}

/// `<scene version="3.0.0">` on line 1, `body` from line 2 (column 1), `</scene>` after it.
fn in_scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>")
}

/// A test document: a whole file, or a body that `in_scene` puts in a scene.
enum Doc {
    Scene(&'static str),
    Body(&'static str),
}
use Doc::{Body, Scene};

/// (test, document, "line:col", message): the cases of each test below.
#[rustfmt::skip]
const CASES: &[(&str, Doc, &str, &str)] = &[
    // malformed_xml
    // A closing tag that does not match the open element.
    ("malformed_xml", Scene("<scene version=\"3.0.0\">\n<shape type=\"sphere\">\n</scene>"), "3:1", "expected `</shape>`, but `</scene>` was found"),
    // End of file with an open element: reported at the element.
    ("malformed_xml", Scene("<scene version=\"3.0.0\">\n  <shape type=\"sphere\"/>\n"), "1:1", "<scene> is not closed"),
    // Unquoted attribute value.
    ("malformed_xml", Scene("<scene version=\"3.0.0\">\n<float name=\"a\" value=1/>\n</scene>"), "2:23", "attribute value not in quotes in <float>"),
    // Duplicated attribute.
    ("malformed_xml", Scene("<scene version=\"3.0.0\">\n<float name=\"a\" name=\"b\" value=\"1\"/>\n</scene>"), "2:17", "duplicated attribute (first given at err.xml:2:8)"),
    // Unterminated tag.
    ("malformed_xml", Scene("<scene version=\"3.0.0\">\n<float name=\"a\""), "2:1", "tag not closed"),
    // Nothing at all.
    ("malformed_xml", Scene("  \n"), "1:1", "no root element"),
    // Unclosed comment.
    ("malformed_xml", Scene("<scene version=\"3.0.0\">\n<!-- oops\n</scene>"), "2:1", "comment not closed"),
    // A second root element.
    ("malformed_xml", Scene("<scene version=\"3.0.0\"/>\n<scene version=\"3.0.0\"/>"), "2:1", "after the end of the root element"),
    // A stray closing tag.
    ("malformed_xml", Scene("<scene version=\"3.0.0\"/>\n</scene>"), "2:1", "close tag `</scene>` does not match any open tag"),
    // root_and_version
    ("root_and_version", Scene("<scene>\n</scene>"), "1:1", "missing version attribute"),
    ("root_and_version", Scene("<scene version=\"3.0\"/>"), "1:8", "invalid version number \"3.0\""),
    ("root_and_version", Scene("<bsdf version=\"3.0.0\" type=\"diffuse\"/>"), "1:1", "root element must be <scene"),
    // old_version_rename_collision
    ("old_version_rename_collision", Scene("<scene version=\"0.6.0\">\n<float name=\"fooBar\" value=\"1\"/>\n<float name=\"foo_bar\" value=\"2\"/>\n</scene>"), "2:1", "renamed \"foo_bar\", which is already specified at err.xml:3:1"),
    // root_and_version
    ("root_and_version", Body("<scene version=\"3.0.0\"/>"), "2:1", "<scene> can only be the root"),
    // tags_and_attributes
    ("tags_and_attributes", Body("<foo/>"), "2:1", "unknown element <foo> (expected one of: integrator"),
    ("tags_and_attributes", Body("<volume type=\"grid\"/>"), "2:1", "<volume> objects are not supported"),
    ("tags_and_attributes", Body("<shape/>"), "2:1", "missing required attribute \"type\" in <shape>"),
    ("tags_and_attributes", Body("<shape type=\"sphere\" version=\"3.0.0\"/>"), "2:22", "unexpected attribute \"version\""),
    ("tags_and_attributes", Body("<float name=\"a\" value=\"1\" extra=\"2\"/>"), "2:27", "unexpected attribute \"extra\" in <float> (allowed: name, value)"),
    ("tags_and_attributes", Body("<float value=\"1\"/>"), "2:1", "missing required attribute \"name\" in <float>"),
    ("tags_and_attributes", Body("<float name=\"a\" value=\"1\"><float name=\"b\" value=\"2\"/></float>"), "2:27", "<float> cannot occur inside <float>"),
    ("tags_and_attributes", Body("<translate x=\"1\"/>"), "2:1", "can only appear inside a <transform>"),
    ("tags_and_attributes", Body("<shape type=\"s\">\n  <path value=\"extra\"/>\n</shape>"), "3:3", "<path> can only be a direct child of the root"),
    ("tags_and_attributes", Body("<path value=\"no_such_folder\"/>"), "2:7", "folder \"no_such_folder\" not found"),
    // values
    ("values", Body("<integer name=\"i\" value=\"1.5\"/>"), "2:19", "could not parse integer value \"1.5\" (an <integer> has no fraction"),
    ("values", Body("<float name=\"f\" value=\"abc\"/>"), "2:17", "could not parse floating point value \"abc\""),
    ("values", Body("<boolean name=\"b\" value=\"yes\"/>"), "2:19", "must be \"true\" or \"false\""),
    ("values", Body("<rgb name=\"c\" value=\"0.1 0.2\"/>"), "2:15", "expected 1 or 3 numbers"),
    ("values", Body("<point name=\"p\" x=\"1\" y=\"2\"/>"), "2:1", "missing required attribute \"z\" in <point>"),
    ("values", Body("<point name=\"p\" x=\"1\" value=\"2\"/>"), "2:23", "cannot mix \"value\" and \"x\"/\"y\"/\"z\""),
    ("values", Body("<vector name=\"v\" value=\"1 2\"/>"), "2:18", "exactly 1 or 3 numbers, got 2"),
    ("values", Body("<spectrum name=\"s\" filename=\"x.spd\"/>"), "2:20", "is not supported"),
    ("values", Body("<spectrum name=\"s\" value=\"500:0.1, 400:0.2\"/>"), "2:20", "increasing order"),
    ("values", Body("<spectrum name=\"s\" value=\"400:0.1, 500\"/>"), "2:20", "expected wavelength:value pairs"),
    ("values", Body("<spectrum name=\"s\"/>"), "2:1", "requires either a \"value\" or a \"filename\""),
    ("values", Body("<float name=\"a\" value=\"1\"/>\n<integer name=\"a\" value=\"2\"/>"), "3:1", "property \"a\" was already specified at err.xml:2:1"),
    // parameters
    ("parameters", Body("<integer name=\"spp\" value=\"$spp\"/>"), "2:21", "undefined parameter $spp"),
    // Defaults apply from where they are written.
    ("parameters", Body("<integer name=\"spp\" value=\"$spp\"/>\n<default name=\"spp\" value=\"4\"/>"), "2:21", "undefined parameter $spp"),
    ("parameters", Body("<default name=\"\" value=\"4\"/>"), "2:10", "name must be non-empty"),
    // ids_and_references
    ("ids_and_references", Body("<bsdf type=\"diffuse\" id=\"a\"/>\n<bsdf type=\"diffuse\" id=\"a\"/>"), "3:1", "duplicate id \"a\" (first defined at err.xml:2:1)"),
    ("ids_and_references", Body("<shape type=\"sphere\">\n  <ref id=\"nope\"/>\n</shape>"), "3:3", "no object has id=\"nope\""),
    ("ids_and_references", Body("<alias id=\"nope\" as=\"b\"/>"), "2:8", "alias source id \"nope\" not found"),
    ("ids_and_references", Body("<bsdf type=\"a\" id=\"a\"><ref id=\"b\"/></bsdf>\n<bsdf type=\"b\" id=\"b\"><ref id=\"a\"/></bsdf>"), "3:23", "circular reference: \"a\" -> \"b\" -> \"a\""),
    ("ids_and_references", Body("<shape type=\"sphere\" id=\"s\">\n  <ref id=\"s\"/>\n</shape>"), "3:3", "circular reference: \"s\" -> \"s\""),
    ("ids_and_references", Body("<shape type=\"sphere\">\n<bsdf type=\"a\" name=\"x\"/>\n<bsdf type=\"b\" name=\"x\"/>\n</shape>"), "4:1", "property \"x\" was already specified"),
    // includes
    ("includes", Body("<include filename=\"missing.xml\"/>"), "2:10", "included file \"missing.xml\" not found"),
    ("includes", Body("<include/>"), "2:1", "missing required attribute \"filename\""),
    // transforms
    ("transforms", Body("<transform name=\"t\">\n<rotate x=\"1\"/>\n</transform>"), "3:1", "missing required attribute \"angle\" in <rotate>"),
    ("transforms", Body("<transform name=\"t\">\n<rotate angle=\"30\"/>\n</transform>"), "3:1", "rotation axis cannot be zero"),
    ("transforms", Body("<transform name=\"t\">\n<rotate x=\"1\" angle=\"thirty\"/>\n</transform>"), "3:15", "could not parse floating point value \"thirty\""),
    ("transforms", Body("<transform name=\"t\">\n<matrix value=\"1 2 3 4 5 6 7 8\"/>\n</transform>"), "3:9", "matrix must have 9 or 16 values, got 8"),
    ("transforms", Body("<transform name=\"t\">\n<lookat origin=\"0 0 0\" target=\"0 1 0\" up=\"0 1 0\"/>\n</transform>"), "3:1", "invalid lookat transformation"),
    ("transforms", Body("<transform name=\"t\">\n<lookat origin=\"1 2\" target=\"0 0 0\"/>\n</transform>"), "3:9", "expected 3 values in \"origin\", got 2"),
    ("transforms", Body("<transform name=\"t\">\n<lookAt origin=\"0 0 0\" target=\"0 0 1\"/>\n</transform>"), "3:1", "spells it <lookat>"),
    ("transforms", Body("<transform name=\"t\">\n<float name=\"x\" value=\"1\"/>\n</transform>"), "3:1", "unexpected <float> element inside <transform>"),
    ("transforms", Body("<transform name=\"t\">\n<translate x=\"1\" w=\"2\"/>\n</transform>"), "3:18", "unexpected attribute \"w\" in <translate>"),
];

#[test]
fn malformed_xml() {
    expect_errs("malformed_xml");
}

#[test]
fn root_and_version() {
    expect_errs("root_and_version");
}

#[test]
fn tags_and_attributes() {
    expect_errs("tags_and_attributes");
}

#[test]
fn values() {
    expect_errs("values");
}

#[test]
fn transforms() {
    expect_errs("transforms");
}

#[test]
fn parameters() {
    expect_errs("parameters");
    let spp8 = [("spp", "8")];
    expect_err(&in_scene("<float name=\"a\" value=\"1\"/>"), &spp8, "err.xml", "unused parameter -D spp=8");
    // As in Mitsuba, a -D that only matches a <default> but is never substituted is unused too.
    expect_err(&in_scene("<default name=\"spp\" value=\"4\"/>"), &spp8, "err.xml", "unused parameter -D spp=8");
}

#[test]
fn ids_and_references() {
    expect_errs("ids_and_references");
}

#[test]
fn old_version_rename_collision() {
    expect_errs("old_version_rename_collision");
}

#[test]
fn includes() {
    expect_errs("includes");
    // An error inside an included file is reported in that file.
    let e = parse_file(&data_dir().join("include_bad.xml"), &[]).unwrap_err();
    let pos = e.pos.clone().unwrap();
    assert!(pos.file.ends_with("sub/bad_value.xml"), "{e}");
    assert_eq!((pos.line, pos.col), (3, 25), "{e}");
    assert!(e.msg.contains("could not parse floating point value \"1.5.2\""), "{e}");
    assert!(e.msg.contains("included at") && e.msg.contains("include_bad.xml:2:5"), "{e}");

    let e = parse_file(&data_dir().join("cycle_a.xml"), &[]).unwrap_err();
    let pos = e.pos.clone().unwrap();
    assert!(pos.file.ends_with("cycle_b.xml"), "{e}");
    assert_eq!((pos.line, pos.col), (3, 5), "{e}");
    assert!(e.msg.contains("include cycle") && e.msg.contains("cycle_a.xml includes"), "{e}");

    let e = parse_file(&data_dir().join("no_such_scene.xml"), &[]).unwrap_err();
    assert!(e.to_string().contains("no_such_scene.xml: could not read the scene file"), "{e}");
}

#[test]
fn bad_utf8_is_an_error() {
    let dir = std::env::temp_dir().join(format!("snee_xml_utf8_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let f = dir.join("bad.xml");
    std::fs::write(&f, b"<scene version=\"3.0.0\">\n<string name=\"s\" value=\"\xff\"/>\n</scene>").unwrap();
    let e = parse_file(&f, &[]).unwrap_err();
    let pos = e.pos.clone().unwrap();
    assert_eq!((pos.line, pos.col), (2, 25), "{e}");
    assert!(e.msg.contains("not valid UTF-8"));
    std::fs::remove_dir_all(&dir).ok();
}

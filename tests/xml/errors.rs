//! The XML parser on broken scenes: every error is an `Error` (never a panic) positioned at the
//! offending element or attribute, in the file where it is, with a message that says what was
//! expected.

use snee::scene::xml::{parse_file, parse_str};
use std::path::{Path, PathBuf};

fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/xml")
}

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

/// `<scene version="3.0.0">` on line 1, `body` from line 2 (column 1), `</scene>` after it.
fn in_scene(body: &str) -> String {
    format!("<scene version=\"3.0.0\">\n{body}\n</scene>")
}

#[test]
fn malformed_xml() {
    // A closing tag that does not match the open element.
    expect_err(
        &in_scene("<shape type=\"sphere\">"),
        &[],
        "err.xml:3:1",
        "expected `</shape>`, but `</scene>` was found",
    );
    // End of file with an open element: reported at the element.
    expect_err("<scene version=\"3.0.0\">\n  <shape type=\"sphere\"/>\n", &[], "err.xml:1:1", "<scene> is not closed");
    // Unquoted attribute value.
    expect_err(
        &in_scene("<float name=\"a\" value=1/>"),
        &[],
        "err.xml:2:23",
        "attribute value not in quotes in <float>",
    );
    // Duplicated attribute.
    expect_err(
        &in_scene("<float name=\"a\" name=\"b\" value=\"1\"/>"),
        &[],
        "err.xml:2:17",
        "duplicated attribute (first given at err.xml:2:8)",
    );
    // Unterminated tag.
    expect_err("<scene version=\"3.0.0\">\n<float name=\"a\"", &[], "err.xml:2:1", "tag not closed");
    // Nothing at all.
    expect_err("  \n", &[], "err.xml:1:1", "no root element");
    // Unclosed comment.
    expect_err("<scene version=\"3.0.0\">\n<!-- oops\n</scene>", &[], "err.xml:2:1", "comment not closed");
    // A second root element.
    expect_err(
        "<scene version=\"3.0.0\"/>\n<scene version=\"3.0.0\"/>",
        &[],
        "err.xml:2:1",
        "after the end of the root element",
    );
    // A stray closing tag.
    expect_err(
        "<scene version=\"3.0.0\"/>\n</scene>",
        &[],
        "err.xml:2:1",
        "close tag `</scene>` does not match any open tag",
    );
}

#[test]
fn root_and_version() {
    expect_err("<scene>\n</scene>", &[], "err.xml:1:1", "missing version attribute");
    expect_err("<scene version=\"3.0\"/>", &[], "err.xml:1:8", "invalid version number \"3.0\"");
    expect_err("<bsdf version=\"3.0.0\" type=\"diffuse\"/>", &[], "err.xml:1:1", "root element must be <scene");
    expect_err(&in_scene("<scene version=\"3.0.0\"/>"), &[], "err.xml:2:1", "<scene> can only be the root");
}

#[test]
fn tags_and_attributes() {
    expect_err(&in_scene("<foo/>"), &[], "err.xml:2:1", "unknown element <foo> (expected one of: integrator");
    expect_err(&in_scene("<volume type=\"grid\"/>"), &[], "err.xml:2:1", "<volume> objects are not supported");
    expect_err(&in_scene("<shape/>"), &[], "err.xml:2:1", "missing required attribute \"type\" in <shape>");
    expect_err(
        &in_scene("<shape type=\"sphere\" version=\"3.0.0\"/>"),
        &[],
        "err.xml:2:22",
        "unexpected attribute \"version\"",
    );
    expect_err(
        &in_scene("<float name=\"a\" value=\"1\" extra=\"2\"/>"),
        &[],
        "err.xml:2:27",
        "unexpected attribute \"extra\" in <float> (allowed: name, value)",
    );
    expect_err(&in_scene("<float value=\"1\"/>"), &[], "err.xml:2:1", "missing required attribute \"name\" in <float>");
    expect_err(
        &in_scene("<float name=\"a\" value=\"1\"><float name=\"b\" value=\"2\"/></float>"),
        &[],
        "err.xml:2:27",
        "<float> cannot occur inside <float>",
    );
    expect_err(&in_scene("<translate x=\"1\"/>"), &[], "err.xml:2:1", "can only appear inside a <transform>");
    expect_err(
        &in_scene("<shape type=\"s\">\n  <path value=\"extra\"/>\n</shape>"),
        &[],
        "err.xml:3:3",
        "<path> can only be a direct child of the root",
    );
    expect_err(
        &in_scene("<path value=\"no_such_folder\"/>"),
        &[],
        "err.xml:2:7",
        "folder \"no_such_folder\" not found",
    );
}

#[test]
fn values() {
    expect_err(
        &in_scene("<integer name=\"i\" value=\"1.5\"/>"),
        &[],
        "err.xml:2:19",
        "could not parse integer value \"1.5\" (an <integer> has no fraction",
    );
    expect_err(
        &in_scene("<float name=\"f\" value=\"abc\"/>"),
        &[],
        "err.xml:2:17",
        "could not parse floating point value \"abc\"",
    );
    expect_err(&in_scene("<boolean name=\"b\" value=\"yes\"/>"), &[], "err.xml:2:19", "must be \"true\" or \"false\"");
    expect_err(&in_scene("<rgb name=\"c\" value=\"0.1 0.2\"/>"), &[], "err.xml:2:15", "expected 1 or 3 numbers");
    expect_err(
        &in_scene("<point name=\"p\" x=\"1\" y=\"2\"/>"),
        &[],
        "err.xml:2:1",
        "missing required attribute \"z\" in <point>",
    );
    expect_err(
        &in_scene("<point name=\"p\" x=\"1\" value=\"2\"/>"),
        &[],
        "err.xml:2:23",
        "cannot mix \"value\" and \"x\"/\"y\"/\"z\"",
    );
    expect_err(&in_scene("<vector name=\"v\" value=\"1 2\"/>"), &[], "err.xml:2:18", "exactly 1 or 3 numbers, got 2");
    expect_err(&in_scene("<spectrum name=\"s\" filename=\"x.spd\"/>"), &[], "err.xml:2:20", "is not supported");
    expect_err(&in_scene("<spectrum name=\"s\" value=\"500:0.1, 400:0.2\"/>"), &[], "err.xml:2:20", "increasing order");
    expect_err(
        &in_scene("<spectrum name=\"s\" value=\"400:0.1, 500\"/>"),
        &[],
        "err.xml:2:20",
        "expected wavelength:value pairs",
    );
    expect_err(
        &in_scene("<spectrum name=\"s\"/>"),
        &[],
        "err.xml:2:1",
        "requires either a \"value\" or a \"filename\"",
    );
    expect_err(
        &in_scene("<float name=\"a\" value=\"1\"/>\n<integer name=\"a\" value=\"2\"/>"),
        &[],
        "err.xml:3:1",
        "property \"a\" was already specified at err.xml:2:1",
    );
}

#[test]
fn transforms() {
    let t = |ops: &str| in_scene(&format!("<transform name=\"t\">\n{ops}\n</transform>"));
    expect_err(&t("<rotate x=\"1\"/>"), &[], "err.xml:3:1", "missing required attribute \"angle\" in <rotate>");
    expect_err(&t("<rotate angle=\"30\"/>"), &[], "err.xml:3:1", "rotation axis cannot be zero");
    expect_err(
        &t("<rotate x=\"1\" angle=\"thirty\"/>"),
        &[],
        "err.xml:3:15",
        "could not parse floating point value \"thirty\"",
    );
    expect_err(&t("<matrix value=\"1 2 3 4 5 6 7 8\"/>"), &[], "err.xml:3:9", "matrix must have 9 or 16 values, got 8");
    expect_err(
        &t("<lookat origin=\"0 0 0\" target=\"0 1 0\" up=\"0 1 0\"/>"),
        &[],
        "err.xml:3:1",
        "invalid lookat transformation",
    );
    expect_err(
        &t("<lookat origin=\"1 2\" target=\"0 0 0\"/>"),
        &[],
        "err.xml:3:9",
        "expected 3 values in \"origin\", got 2",
    );
    expect_err(&t("<lookAt origin=\"0 0 0\" target=\"0 0 1\"/>"), &[], "err.xml:3:1", "spells it <lookat>");
    expect_err(
        &t("<float name=\"x\" value=\"1\"/>"),
        &[],
        "err.xml:3:1",
        "unexpected <float> element inside <transform>",
    );
    expect_err(&t("<translate x=\"1\" w=\"2\"/>"), &[], "err.xml:3:18", "unexpected attribute \"w\" in <translate>");
}

#[test]
fn parameters() {
    expect_err(&in_scene("<integer name=\"spp\" value=\"$spp\"/>"), &[], "err.xml:2:21", "undefined parameter $spp");
    // Defaults apply from where they are written.
    expect_err(
        &in_scene("<integer name=\"spp\" value=\"$spp\"/>\n<default name=\"spp\" value=\"4\"/>"),
        &[],
        "err.xml:2:21",
        "undefined parameter $spp",
    );
    expect_err(&in_scene("<float name=\"a\" value=\"1\"/>"), &[("spp", "8")], "err.xml", "unused parameter -D spp=8");
    // As in Mitsuba, a -D that only matches a <default> but is never substituted is unused too.
    expect_err(
        &in_scene("<default name=\"spp\" value=\"4\"/>"),
        &[("spp", "8")],
        "err.xml",
        "unused parameter -D spp=8",
    );
    expect_err(&in_scene("<default name=\"\" value=\"4\"/>"), &[], "err.xml:2:10", "name must be non-empty");
}

#[test]
fn ids_and_references() {
    expect_err(
        &in_scene("<bsdf type=\"diffuse\" id=\"a\"/>\n<bsdf type=\"diffuse\" id=\"a\"/>"),
        &[],
        "err.xml:3:1",
        "duplicate id \"a\" (first defined at err.xml:2:1)",
    );
    expect_err(
        &in_scene("<shape type=\"sphere\">\n  <ref id=\"nope\"/>\n</shape>"),
        &[],
        "err.xml:3:3",
        "no object has id=\"nope\"",
    );
    expect_err(&in_scene("<alias id=\"nope\" as=\"b\"/>"), &[], "err.xml:2:8", "alias source id \"nope\" not found");
    expect_err(
        &in_scene("<bsdf type=\"a\" id=\"a\"><ref id=\"b\"/></bsdf>\n<bsdf type=\"b\" id=\"b\"><ref id=\"a\"/></bsdf>"),
        &[],
        "err.xml:3:23",
        "circular reference: \"a\" -> \"b\" -> \"a\"",
    );
    expect_err(
        &in_scene("<shape type=\"sphere\" id=\"s\">\n  <ref id=\"s\"/>\n</shape>"),
        &[],
        "err.xml:3:3",
        "circular reference: \"s\" -> \"s\"",
    );
    expect_err(
        &in_scene("<shape type=\"sphere\">\n<bsdf type=\"a\" name=\"x\"/>\n<bsdf type=\"b\" name=\"x\"/>\n</shape>"),
        &[],
        "err.xml:4:1",
        "property \"x\" was already specified",
    );
}

#[test]
fn old_version_rename_collision() {
    expect_err(
        "<scene version=\"0.6.0\">\n<float name=\"fooBar\" value=\"1\"/>\n<float name=\"foo_bar\" value=\"2\"/>\n</scene>",
        &[],
        "err.xml:2:1",
        "renamed \"foo_bar\", which is already specified at err.xml:3:1",
    );
}

#[test]
fn includes() {
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

    expect_err(
        &in_scene("<include filename=\"missing.xml\"/>"),
        &[],
        "err.xml:2:10",
        "included file \"missing.xml\" not found",
    );
    expect_err(&in_scene("<include/>"), &[], "err.xml:2:1", "missing required attribute \"filename\"");

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

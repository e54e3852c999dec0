//! Fuzzing the XML parser: valid scenes mutated (byte flips, truncation, duplicated / removed /
//! inserted tags, random attribute values, deep nesting) must give `Ok` or `Err`, never a panic.
//!
//! The default run is short; for a long run:
//! `PROPTEST_CASES=1000000 FUZZ_MAX_MUTATIONS=10 cargo test --release --test xml fuzz -- --nocapture`.

use crate::data_dir;
use proptest::prelude::*;
use proptest::test_runner::{Config, TestRunner};
use snee::scene::xml::parse_str;

/// Valid scenes covering every tag and most attribute forms.
const SEEDS: &[&str] = &[
    r#"<scene version="3.0.0">
    <default name="spp" value="16"/>
    <default name="r" value="0.5"/>
    <integrator type="volpath"><integer name="max_depth" value="8"/></integrator>
    <sensor type="perspective">
        <float name="fov" value="40"/>
        <transform name="to_world"><lookat origin="0, 0, 5" target="0, 0, 0" up="0, 1, 0"/></transform>
        <film type="hdrfilm"><integer name="width" value="64"/><rfilter type="gaussian"/></film>
        <sampler type="independent"><integer name="sample_count" value="$spp"/></sampler>
    </sensor>
    <bsdf type="dielectric" id="glass"><string name="int_ior" value="bk7"/></bsdf>
    <alias id="glass" as="glass2"/>
    <shape type="sphere">
        <float name="radius" value="$r"/>
        <transform name="to_world">
            <scale value="2"/><rotate x="1" y="1" angle="30"/><translate value="1, 2, 3"/>
            <matrix value="1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1"/>
        </transform>
        <ref id="glass2"/>
        <medium type="homogeneous" name="interior">
            <rgb name="albedo" value="0.9, 0.8, 0.7"/>
            <spectrum name="sigma_t" value="400:0.5, 500:0.7, 700:0.9"/>
            <phase type="hg"><float name="g" value="0.7"/></phase>
        </medium>
    </shape>
    <emitter type="directional"><vector name="direction" value="0, -1, 0"/><spectrum name="irradiance" value="1"/></emitter>
    <shape type="rectangle"><emitter type="area"><rgb name="radiance" value="4"/></emitter><boolean name="flip_normals" value="true"/></shape>
    <texture type="bitmap" id="tex"><string name="filename" value="a \$b.exr"/><point name="p" x="1" y="2" z="3"/></texture>
</scene>"#,
    r#"<scene version="0.6.0">
    <integrator type="path"><integer name="maxDepth" value="3"/></integrator>
    <bsdf type="diffuse"><rgb name="diffuseReflectance" value="0.5"/></bsdf>
    <texture type="bitmap"><float name="uoffset" value="0.5"/><float name="vscale" value="2"/></texture>
    <shape type="obj"><string name="filename" value="mesh.obj"/><transform name="toWorld"><translate x="1"/></transform></shape>
</scene>"#,
    r#"<scene version="3.0.0">
    <path value="extra"/>
    <include filename="from_extra.xml"/>
    <include filename="sub/leaf.xml" name="leaf_bsdf"/>
    <include filename="sub/part.xml"/>
    <default name="radius" value="1"/>
    <shape type="sphere" id="s"><ref id="leaf"/><ref name="x" id="blue"/></shape>
</scene>"#,
];

/// Snippets inserted at random places.
const SNIPPETS: &[&str] = &[
    "<",
    ">",
    "/>",
    "</",
    "\"",
    "'",
    "=",
    "$",
    "\\$",
    "$spp",
    "${",
    "&",
    "&amp;",
    "&#x41;",
    "&#99999999;",
    "<!--",
    "-->",
    "<![CDATA[",
    "]]>",
    "<?xml version=\"1.0\"?>",
    "<!DOCTYPE x>",
    "<scene version=\"3.0.0\">",
    "</scene>",
    "<shape type=\"sphere\">",
    "</shape>",
    "<ref id=\"glass\"/>",
    "<ref id=\"s\"/>",
    "<include filename=\"cycle_a.xml\"/>",
    "<include filename=\"include_main.xml\"/>",
    "<transform name=\"t\">",
    "</transform>",
    "<lookat origin=\"0 0 0\" target=\"0 0 0\"/>",
    "<rotate angle=\"1e308\" x=\"1e308\"/>",
    "<spectrum name=\"q\" value=\"400:1, 400:2\"/>",
    "<alias id=\"glass\" as=\"s\"/>",
    "<default name=\"spp\" value=\"$spp\"/>",
    "<path value=\"sub\"/>",
    "version=\"0.1.0\"",
    " id=\"glass\"",
    " name=\"\"",
    "\u{feff}",
    "é",
    "\u{1F600}",
    "\0",
    "\r\n",
    "\t",
];

/// Characters for random attribute values.
const VALUE_CHARS: &[char] = &[
    '0', '1', '9', '.', '-', '+', 'e', 'E', 'x', ':', ',', ' ', '$', '\\', '&', ';', '<', '>', '"', 'n', 'a', 'i', 'f',
    '_', 'é', '#',
];

#[derive(Clone, Debug)]
enum Mutation {
    FlipByte(usize, u8),
    Truncate(usize),
    DuplicateTag(usize, usize),
    RemoveTag(usize),
    Insert(usize, usize),
    AttrValue(usize, String),
    Nest(usize, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let value = proptest::collection::vec(proptest::sample::select(VALUE_CHARS), 0..12)
        .prop_map(|cs| cs.into_iter().collect::<String>());
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::FlipByte(i, b)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::DuplicateTag(a, b)),
        any::<usize>().prop_map(Mutation::RemoveTag),
        (any::<usize>(), 0..SNIPPETS.len()).prop_map(|(a, b)| Mutation::Insert(a, b)),
        (any::<usize>(), value).prop_map(|(a, v)| Mutation::AttrValue(a, v)),
        (any::<usize>(), 0usize..400).prop_map(|(a, n)| Mutation::Nest(a, n)),
    ]
}

/// Byte offsets of every `<` and the matching `>` after it.
fn tags(s: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    for (i, &b) in s.iter().enumerate() {
        if b == b'<' {
            if let Some(j) = s[i..].iter().position(|&c| c == b'>') {
                out.push((i, i + j + 1));
            }
        }
    }
    out
}

/// Byte ranges inside double quotes.
fn quoted(s: &[u8]) -> Vec<(usize, usize)> {
    let q: Vec<usize> = s.iter().enumerate().filter(|(_, &b)| b == b'"').map(|(i, _)| i).collect();
    q.chunks_exact(2).map(|p| (p[0] + 1, p[1])).collect()
}

fn apply(text: &mut Vec<u8>, m: &Mutation) {
    let n = text.len();
    match m {
        Mutation::FlipByte(i, b) if n > 0 => text[i % n] = *b,
        Mutation::Truncate(i) => text.truncate(i % (n + 1)),
        Mutation::DuplicateTag(a, b) => {
            let t = tags(text);
            if !t.is_empty() {
                let (s, e) = t[a % t.len()];
                let copy = text[s..e].to_vec();
                let at = t[b % t.len()].0;
                text.splice(at..at, copy);
            }
        }
        Mutation::RemoveTag(a) => {
            let t = tags(text);
            if !t.is_empty() {
                let (s, e) = t[a % t.len()];
                text.drain(s..e);
            }
        }
        Mutation::Insert(a, k) => {
            let at = a % (n + 1);
            text.splice(at..at, SNIPPETS[*k].bytes());
        }
        Mutation::AttrValue(a, v) => {
            let q = quoted(text);
            if !q.is_empty() {
                let (s, e) = q[a % q.len()];
                text.splice(s..e, v.bytes());
            }
        }
        Mutation::Nest(a, depth) => {
            let t = tags(text);
            if !t.is_empty() {
                let at = t[a % t.len()].0;
                let open = "<shape type=\"s\">".repeat(*depth);
                let close = "</shape>".repeat(*depth);
                let mut inner = open.into_bytes();
                inner.extend_from_slice(close.as_bytes());
                text.splice(at..at, inner);
            }
        }
        _ => {}
    }
}

#[test]
fn mutated_scenes_never_panic() {
    let cases: u32 = std::env::var("PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(6000);
    let mut runner = TestRunner::new(Config { cases, failure_persistence: None, ..Config::default() });
    let dir = data_dir();
    let max_mutations: usize = std::env::var("FUZZ_MAX_MUTATIONS").ok().and_then(|v| v.parse().ok()).unwrap_or(4);
    let strategy =
        (0..SEEDS.len(), proptest::collection::vec(mutation(), 0..max_mutations.max(1)), proptest::bool::ANY);
    let errors = std::cell::Cell::new(0usize);
    let oks = std::cell::Cell::new(0usize);
    runner
        .run(&strategy, |(seed, muts, with_define)| {
            let mut text = SEEDS[seed].as_bytes().to_vec();
            for m in &muts {
                apply(&mut text, m);
            }
            let text = String::from_utf8_lossy(&text);
            let defines: Vec<(String, String)> =
                if with_define && seed == 0 { vec![("spp".into(), "$r".into())] } else { Vec::new() };
            // Ok or Err are both fine; a panic fails the test (and proptest shrinks the input).
            match parse_str(&text, "fuzz.xml", &dir, &defines) {
                Ok(_) => oks.set(oks.get() + 1),
                Err(e) => {
                    // Every error names a position in some file.
                    prop_assert!(
                        e.pos.is_some() || e.msg.starts_with("empty parameter"),
                        "error without position: {e}"
                    );
                    errors.set(errors.get() + 1);
                }
            }
            Ok(())
        })
        .unwrap();
    let (oks, errors) = (oks.get(), errors.get());
    eprintln!("xml fuzz: {} inputs, {oks} parsed, {errors} rejected with an error", oks + errors);
}

//! Property-based fuzzing of the OBJ and `.serialized` loaders (the PLY loader has its own,
//! `fuzz_ply.rs`): mutated files give a validated mesh or an error naming the file, never a
//! panic. `SNEE_FUZZ_CASES` sets the cases per property (default 20000, about 1 s).

use std::io::Write;

use flate2::write::ZlibEncoder;
use proptest::prelude::*;
use proptest::sample::Index;
use snee::shape::obj::load_obj_from_bytes;
use snee::shape::serialized::load_serialized_from_bytes;

fn cases() -> u32 {
    crate::fuzz_cases(20000)
}

const OBJ: &str = "# base\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nvt 0 0\nvt 1 0\nvt 1 1\n\
                   vn 0 0 1\nvn 0 1 0\ng g\nf 1/1/1 2/2/1 3/3/1 4/1/2\nf -5/-3/-2 -4/-2/-2 -1/-1/-1\n\
                   f 2/2/2 3/3/2 5/1/1 4/2/1 1/3/1\n";

const OBJ_TOKENS: &[&str] = &[
    "",
    "v",
    "vt",
    "vn",
    "f",
    "#",
    "0",
    "1",
    "-1",
    "6",
    "-6",
    "1/1",
    "1//1",
    "1/1/1",
    "1/",
    "/1",
    "//",
    "1/2/3/4",
    "nan",
    "inf",
    "1e39",
    "4294967296",
    "-9223372036854775808",
    "x",
    "\t",
];

fn serialized(body: &[u8], version: u16) -> Vec<u8> {
    let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(body).unwrap();
    let mut out = 0x041Cu16.to_le_bytes().to_vec();
    out.extend(version.to_le_bytes());
    out.extend(z.finish().unwrap());
    // Dictionary: one mesh at offset 0.
    out.extend(if version == 4 { &[0u8; 8][..] } else { &[0u8; 4][..] });
    out.extend(1u32.to_le_bytes());
    out
}

/// Uncompressed body of a v4 mesh with normals, uvs and colours in single precision.
fn serialized_body() -> Vec<u8> {
    let mut b = (0x1000u32 | 0x1 | 0x2 | 0x8).to_le_bytes().to_vec();
    b.extend(b"mesh\0");
    b.extend(4u64.to_le_bytes());
    b.extend(2u64.to_le_bytes());
    let floats = [0f32, 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.];
    floats.iter().for_each(|x| b.extend(x.to_le_bytes())); // positions
    [0f32, 0., 1.].repeat(4).iter().for_each(|x| b.extend(x.to_le_bytes())); // normals
    floats[..8].iter().for_each(|x| b.extend(x.to_le_bytes())); // uvs
    [0.5f32; 12].iter().for_each(|x| b.extend(x.to_le_bytes())); // colours
    [0u32, 1, 2, 0, 2, 3].iter().for_each(|i| b.extend(i.to_le_bytes()));
    b
}

fn check_obj(bytes: &[u8]) {
    match load_obj_from_bytes(bytes, "fuzz.obj", true) {
        Ok(m) => assert!(m.validate("fuzz.obj").is_ok()),
        Err(e) => assert!(e.to_string().starts_with("fuzz.obj"), "{e}"),
    }
}

fn check_serialized(bytes: &[u8], index: u32) {
    match load_serialized_from_bytes(bytes, "fuzz.serialized", index) {
        Ok(m) => assert!(m.validate("fuzz.serialized").is_ok()),
        Err(e) => assert!(e.to_string().starts_with("fuzz.serialized"), "{e}"),
    }
}

#[test]
fn bases_are_valid() {
    let m = load_obj_from_bytes(OBJ.as_bytes(), "base.obj", true).unwrap();
    assert_eq!(m.triangle_count(), 6);
    let m = load_serialized_from_bytes(&serialized(&serialized_body(), 4), "base.serialized", 0).unwrap();
    assert_eq!((m.vertex_count(), m.triangle_count(), m.normals.len(), m.uvs.len()), (4, 2, 4, 4));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_obj_never_panics(
        edits in prop::collection::vec((any::<Index>(), any::<Index>(), prop::sample::select(OBJ_TOKENS)), 1..4),
        flips in prop::collection::vec((any::<Index>(), any::<u8>()), 0..3),
        cut in any::<Index>(),
        truncate in any::<bool>(),
    ) {
        // Token edits on lines, then raw byte writes, then maybe truncation.
        let mut lines: Vec<Vec<String>> =
            OBJ.lines().map(|l| l.split_whitespace().map(str::to_string).collect()).collect();
        for (l, t, s) in &edits {
            let n = lines.len();
            let line = &mut lines[l.index(n)];
            if line.is_empty() {
                line.push(s.to_string());
            } else {
                let k = t.index(line.len() + 1);
                if k == line.len() { line.push(s.to_string()) } else { line[k] = s.to_string() }
            }
        }
        let mut b: Vec<u8> = lines.iter().map(|l| l.join(" ")).collect::<Vec<_>>().join("\n").into_bytes();
        for (i, v) in &flips {
            let k = i.index(b.len());
            b[k] = *v;
        }
        if truncate {
            b.truncate(cut.index(b.len() + 1));
        }
        check_obj(&b);
    }

    #[test]
    fn mutated_serialized_never_panics(
        writes in prop::collection::vec((any::<Index>(), any::<u8>()), 1..4),
        compressed in any::<bool>(),
        version in 3u16..5,
        cut in prop::option::of(any::<Index>()),
        index in 0u32..3,
    ) {
        // Mutate either the uncompressed body (then compress, so the zlib checksum holds and the
        // mesh decoder sees the damage) or the compressed file.
        let mut body = serialized_body();
        if version == 3 {
            body.drain(4..9); // no name in version 3
        }
        if !compressed {
            for (i, v) in &writes {
                let k = i.index(body.len());
                body[k] = *v;
            }
        }
        let mut b = serialized(&body, version);
        if compressed {
            for (i, v) in &writes {
                let k = i.index(b.len());
                b[k] = *v;
            }
        }
        if let Some(cut) = cut {
            b.truncate(cut.index(b.len() + 1));
        }
        check_serialized(&b, index);
    }
}

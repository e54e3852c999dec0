//! Property-based fuzzing of the PLY loader: valid ascii and binary files mutated by byte flips,
//! byte writes, insertions, deletions, truncation and header token edits must give a mesh or an
//! error naming the file, never a panic (or an allocation the file cannot back).
//!
//! Cases per property default to 30000 (about 1-2 s); set `SNEE_FUZZ_CASES` for a long run:
//! `SNEE_FUZZ_CASES=1000000 cargo test --release --test meshes fuzz_ply`.

use proptest::prelude::*;
use proptest::sample::Index;
use snee::shape::ply::load_ply_from_bytes;

fn cases() -> u32 {
    crate::fuzz_cases(30000)
}

/// Valid base files: ascii, binary little and big endian, with normals, uvs, polygons, ignored
/// properties and an extra element holding a list.
fn bases() -> Vec<Vec<u8>> {
    let pos = [[0f32, 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.], [0.5, 0.5, 1.]];
    let faces: [&[u32]; 3] = [&[0, 1, 2, 3], &[0, 1, 4], &[1, 2, 4, 3, 0]];
    let mut out = Vec::new();

    let mut a = String::from(
        "ply\nformat ascii 1.0\ncomment fuzz base\nelement vertex 5\nproperty float x\nproperty float y\n\
         property float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float u\n\
         property float v\nproperty uchar red\nelement face 3\nproperty list uchar int vertex_indices\n\
         property int flags\nelement extra 2\nproperty list int float values\nend_header\n",
    );
    for (k, p) in pos.iter().enumerate() {
        a += &format!("{} {} {} 0 0 1 {} {} {}\n", p[0], p[1], p[2], p[0], p[1], k * 40);
    }
    for f in faces {
        a += &format!("{} {} 7\n", f.len(), f.iter().map(|i| i.to_string()).collect::<Vec<_>>().join(" "));
    }
    a += "2 0.5 1.5\n0\n";
    out.push(a.into_bytes());

    for big in [false, true] {
        let enc = if big { "binary_big_endian" } else { "binary_little_endian" };
        let mut b = format!(
            "ply\nformat {enc} 1.0\nelement vertex 5\nproperty double x\nproperty double y\nproperty double z\n\
             property half s\nproperty half t\nproperty ushort id\nelement face 3\n\
             property list uint ushort vertex_index\nelement extra 2\nproperty list uchar long values\nend_header\n"
        )
        .into_bytes();
        let put = |b: &mut Vec<u8>, le: &[u8], be: &[u8]| b.extend(if big { be } else { le });
        for (k, p) in pos.iter().enumerate() {
            for c in p {
                let c = f64::from(*c);
                put(&mut b, &c.to_le_bytes(), &c.to_be_bytes());
            }
            for h in [0x3800u16, 0x3c00] {
                put(&mut b, &h.to_le_bytes(), &h.to_be_bytes());
            }
            put(&mut b, &(k as u16).to_le_bytes(), &(k as u16).to_be_bytes());
        }
        for f in faces {
            put(&mut b, &(f.len() as u32).to_le_bytes(), &(f.len() as u32).to_be_bytes());
            for &i in f {
                put(&mut b, &(i as u16).to_le_bytes(), &(i as u16).to_be_bytes());
            }
        }
        for n in [1u8, 0] {
            b.push(n);
            for _ in 0..n {
                put(&mut b, &(-5i64).to_le_bytes(), &(-5i64).to_be_bytes());
            }
        }
        out.push(b);
    }
    out
}

const TOKENS: &[&str] = &[
    "",
    "ply",
    "format",
    "ascii",
    "binary_little_endian",
    "binary_big_endian",
    "1.0",
    "element",
    "property",
    "list",
    "end_header",
    "comment",
    "vertex",
    "face",
    "x",
    "y",
    "z",
    "nx",
    "u",
    "v",
    "s",
    "texture_u",
    "vertex_indices",
    "vertex_index",
    "char",
    "uchar",
    "short",
    "ushort",
    "int",
    "uint",
    "long",
    "ulong",
    "half",
    "float",
    "double",
    "float64",
    "0",
    "1",
    "2",
    "3",
    "6",
    "255",
    "65536",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "-1",
    "nan",
    "inf",
    "1e39",
    "\n",
    "x y",
    "\r",
];

#[derive(Clone, Debug)]
enum Mutation {
    FlipBit(Index, u8),
    SetByte(Index, u8),
    Insert(Index, Vec<u8>),
    Delete(Index, usize),
    Truncate(Index),
    /// Replace token `token` of header line `line` (an ascii body line too, for ascii bases).
    Token(Index, Index, &'static str),
    /// Write a byte of the body only (past `end_header`).
    BodyByte(Index, u8),
    /// Duplicate or drop a whole line.
    DupLine(Index),
    DropLine(Index),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<Index>(), 0u8..8).prop_map(|(i, b)| Mutation::FlipBit(i, b)),
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Mutation::SetByte(i, b)),
        (any::<Index>(), prop::collection::vec(any::<u8>(), 1..8)).prop_map(|(i, b)| Mutation::Insert(i, b)),
        (any::<Index>(), 1usize..16).prop_map(|(i, n)| Mutation::Delete(i, n)),
        any::<Index>().prop_map(Mutation::Truncate),
        (any::<Index>(), any::<Index>(), prop::sample::select(TOKENS)).prop_map(|(l, t, s)| Mutation::Token(l, t, s)),
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Mutation::BodyByte(i, b)),
        any::<Index>().prop_map(Mutation::DupLine),
        any::<Index>().prop_map(Mutation::DropLine),
    ]
}

/// Byte ranges of the lines of `b` (up to and including `end_header` for binary files).
fn lines(b: &[u8], whole_file: bool) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut start = 0;
    for (i, &c) in b.iter().enumerate() {
        if c == b'\n' {
            out.push((start, i + 1));
            if !whole_file && b[start..i].starts_with(b"end_header") {
                break;
            }
            start = i + 1;
        }
    }
    out
}

fn apply(b: &mut Vec<u8>, m: &Mutation, ascii: bool) {
    let at = |i: &Index, len: usize| if len == 0 { 0 } else { i.index(len) };
    match m {
        Mutation::FlipBit(i, bit) if !b.is_empty() => {
            let k = at(i, b.len());
            b[k] ^= 1 << bit;
        }
        Mutation::SetByte(i, v) if !b.is_empty() => {
            let k = at(i, b.len());
            b[k] = *v;
        }
        Mutation::Insert(i, bytes) => {
            let k = at(i, b.len() + 1);
            b.splice(k..k, bytes.iter().copied());
        }
        Mutation::Delete(i, n) if !b.is_empty() => {
            let k = at(i, b.len());
            let end = (k + n).min(b.len());
            b.drain(k..end);
        }
        Mutation::Truncate(i) => {
            let k = at(i, b.len() + 1);
            b.truncate(k);
        }
        Mutation::Token(l, t, s) => {
            let ls = lines(b, ascii);
            if ls.is_empty() {
                return;
            }
            let (start, end) = ls[l.index(ls.len())];
            let line = String::from_utf8_lossy(&b[start..end]).into_owned();
            let mut toks: Vec<&str> = line.split_whitespace().collect();
            if toks.is_empty() {
                return;
            }
            let k = t.index(toks.len());
            toks[k] = s;
            let new = toks.join(" ") + "\n";
            b.splice(start..end, new.into_bytes());
        }
        Mutation::BodyByte(i, v) => {
            let start = lines(b, false).last().map_or(0, |l| l.1);
            if start < b.len() {
                let k = start + i.index(b.len() - start);
                b[k] = *v;
            }
        }
        Mutation::DupLine(l) | Mutation::DropLine(l) => {
            let ls = lines(b, ascii);
            if ls.is_empty() {
                return;
            }
            let (start, end) = ls[l.index(ls.len())];
            if matches!(m, Mutation::DupLine(_)) {
                let line = b[start..end].to_vec();
                b.splice(start..start, line);
            } else {
                b.drain(start..end);
            }
        }
        _ => {}
    }
}

fn check(bytes: &[u8], flip: bool) {
    match load_ply_from_bytes(bytes, "fuzz.ply", flip) {
        Ok(m) => {
            // Loaded meshes are validated; check the invariants consumers rely on once more.
            assert!(m.validate("fuzz.ply").is_ok());
            let n = m.positions.len() as u32;
            assert!(m.indices.iter().flatten().all(|&i| i < n));
        }
        Err(e) => assert!(e.to_string().starts_with("fuzz.ply"), "{e}"),
    }
}

#[test]
fn bases_are_valid() {
    for (k, b) in bases().iter().enumerate() {
        let m = load_ply_from_bytes(b, "base.ply", false).unwrap_or_else(|e| panic!("base {k}: {e}"));
        assert_eq!((m.vertex_count(), m.triangle_count()), (5, 6), "base {k}");
        assert_eq!(m.uvs.len(), 5);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: cases(), failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn mutated_ply_never_panics(
        base in 0usize..3,
        muts in prop::collection::vec(mutation(), 1..5),
        flip in any::<bool>(),
    ) {
        let mut b = bases()[base].clone();
        for m in &muts {
            apply(&mut b, m, base == 0);
        }
        check(&b, flip);
    }

    #[test]
    fn random_bodies_never_panic(
        base in 0usize..3,
        body in prop::collection::vec(any::<u8>(), 0..400),
    ) {
        // A valid header followed by arbitrary bytes.
        let b = &bases()[base];
        let header_end = lines(b, false).last().map_or(0, |l| l.1);
        let mut b = b[..header_end].to_vec();
        b.extend(body);
        check(&b, false);
    }
}

/// How the mutated files fare (run with `--ignored --nocapture`): the share that still loads and
/// the most frequent errors, to see that mutations reach past the header.
#[test]
#[ignore]
fn mutation_outcome_stats() {
    use proptest::strategy::ValueTree;
    use proptest::test_runner::TestRunner;
    use std::collections::HashMap;
    let mut runner = TestRunner::deterministic();
    let strategy = (0usize..3, prop::collection::vec(mutation(), 1..5));
    let bases = bases();
    let (mut ok, mut total) = (0, 0);
    let mut errors: HashMap<String, usize> = HashMap::new();
    for _ in 0..cases() {
        let (base, muts) = strategy.new_tree(&mut runner).unwrap().current();
        let mut b = bases[base].clone();
        for m in &muts {
            apply(&mut b, m, base == 0);
        }
        total += 1;
        match load_ply_from_bytes(&b, "fuzz.ply", false) {
            Ok(_) => ok += 1,
            Err(e) => {
                // Group by message without numbers and quoted tokens.
                let msg: String = e.msg.split('"').step_by(2).collect::<Vec<_>>().join("\"…\"");
                let msg: String = msg.chars().filter(|c| !c.is_ascii_digit()).collect();
                *errors.entry(msg).or_default() += 1;
            }
        }
    }
    println!("{ok} of {total} mutated files loaded");
    let mut errors: Vec<_> = errors.into_iter().collect();
    errors.sort_by_key(|e| std::cmp::Reverse(e.1));
    for (msg, n) in errors.iter().take(40) {
        println!("{n:7}  {msg}");
    }
}

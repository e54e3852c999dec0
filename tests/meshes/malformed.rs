//! Malformed mesh files: each must give an error that names the file (and says what is wrong),
//! never a panic and never a mesh.

use std::io::Write;
use std::path::{Path, PathBuf};

use flate2::write::ZlibEncoder;
use snee::shape::obj::load_obj;
use snee::shape::ply::load_ply;
use snee::shape::serialized::{load_serialized, serialized_shape_count};

struct Dir(PathBuf);

impl Dir {
    fn new(test: &str) -> Dir {
        let dir = std::env::temp_dir().join(format!("snee_malformed_{}_{test}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        Dir(dir)
    }
    fn file(&self, name: &str, bytes: impl AsRef<[u8]>) -> PathBuf {
        let p = self.0.join(name);
        std::fs::write(&p, bytes).unwrap();
        p
    }
}

impl Drop for Dir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

/// The error message of a failed load; checks that it names the file and contains `what`.
#[track_caller]
fn expect_err<T: std::fmt::Debug>(path: &Path, r: snee::scene::Result<T>, what: &str) -> String {
    let e = r.expect_err("malformed file must not load").to_string();
    assert!(e.starts_with(&path.display().to_string()), "error does not start with the file name: {e}");
    assert!(e.contains(what), "expected \"{what}\" in: {e}");
    eprintln!("{e}");
    e
}

const PLY_HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                        property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

fn binary_ply(big_endian: bool, faces: &[[i32; 3]]) -> Vec<u8> {
    let enc = if big_endian { "binary_big_endian" } else { "binary_little_endian" };
    let mut b = format!(
        "ply\nformat {enc} 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element face {}\nproperty list uchar int vertex_indices\nend_header\n",
        faces.len()
    )
    .into_bytes();
    for x in [0f32, 0., 0., 1., 0., 0., 0., 1., 0.] {
        b.extend(if big_endian { x.to_be_bytes() } else { x.to_le_bytes() });
    }
    for f in faces {
        b.push(3);
        for i in f {
            b.extend(if big_endian { i.to_be_bytes() } else { i.to_le_bytes() });
        }
    }
    b
}

#[test]
fn malformed_ply_files() {
    let d = Dir::new("ply");
    let good = binary_ply(false, &[[0, 1, 2]]);
    assert!(load_ply(&d.file("good.ply", &good)).is_ok());

    // 1. Truncated binary body.
    let p = d.file("truncated.ply", &good[..good.len() - 5]);
    expect_err(&p, load_ply(&p), "truncated");

    // 2. Truncated inside the vertices (the early size check).
    let p = d.file("truncated_vertices.ply", &good[..good.len() - 30]);
    expect_err(&p, load_ply(&p), "element \"vertex\" needs at least 36 bytes");

    // 3. Face index out of range (big endian).
    let p = d.file("index_range.ply", binary_ply(true, &[[0, 1, 3]]));
    expect_err(&p, load_ply(&p), "face 0 references vertex 3, but the file has 3 vertices");

    // 4. Negative face index.
    let p = d.file("index_negative.ply", binary_ply(false, &[[0, -1, 2]]));
    expect_err(&p, load_ply(&p), "references vertex -1");

    // 5. NaN coordinate, ascii and binary.
    let p = d.file("nan.ply", format!("{PLY_HEAD}0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n"));
    expect_err(&p, load_ply(&p), ":11:7: vertex 1 has a non-finite position (1, NaN, 0)");
    let mut nan = good.clone();
    let at = nan.len() - 13 - 4; // z of the last vertex
    nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let p = d.file("nan_binary.ply", nan);
    expect_err(&p, load_ply(&p), "vertex 2 has a non-finite position");

    // 6. Bad headers: unknown keyword, bad version, missing end_header, not a PLY at all.
    let p = d.file("keyword.ply", PLY_HEAD.replace("element face 1", "elemnt face 1"));
    expect_err(&p, load_ply(&p), ":7:1: invalid PLY header: unknown keyword \"elemnt\"");
    let p = d.file("version.ply", PLY_HEAD.replace("1.0", "1.1"));
    expect_err(&p, load_ply(&p), ":2:14: unsupported PLY version \"1.1\"");
    let p = d.file("no_end.ply", PLY_HEAD.replace("end_header\n", ""));
    expect_err(&p, load_ply(&p), "header ends without \"end_header\"");
    let p = d.file("not_ply.ply", b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR");
    expect_err(&p, load_ply(&p), "not a PLY file");
    let p = d.file("unknown_type.ply", PLY_HEAD.replace("property float y", "property flaot y"));
    expect_err(&p, load_ply(&p), ":5:10: invalid PLY header: unknown type \"flaot\"");

    // 7. Wrong list types: float indices; a scalar where the index list should be.
    let p = d.file("float_list.ply", PLY_HEAD.replace("list uchar int", "list uchar float"));
    expect_err(&p, load_ply(&p), "must have integer count and index types");
    let p = d.file("scalar_indices.ply", PLY_HEAD.replace("list uchar int vertex_indices", "int vertex_indices"));
    expect_err(&p, load_ply(&p), "has no list property \"vertex_indices\"");

    // 8. Integer positions, missing z.
    let p = d.file("int_x.ply", PLY_HEAD.replace("float x", "uchar x"));
    expect_err(&p, load_ply(&p), "vertex property \"x\" has integer type \"uchar\"");
    let p = d.file("no_z.ply", PLY_HEAD.replace("property float z\n", ""));
    expect_err(&p, load_ply(&p), "lacks one of the properties x, y, z");

    // 9. Ascii: bad number with its line and column; value out of the type's range; too few values.
    let p = d.file("bad_number.ply", format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1.0.0 0\n3 0 1 2\n"));
    expect_err(&p, load_ply(&p), ":12:3: invalid value \"1.0.0\" for vertex 2 of 3 (property \"y\")");
    let p = d.file("uchar_range.ply", format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n300 0 1 2\n"));
    expect_err(&p, load_ply(&p), ":13:1: invalid value \"300\"");
    let p = d.file("short_ascii.ply", format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1\n"));
    expect_err(&p, load_ply(&p), "unexpected end of file: expected face 0 of 1");

    // 10. Faces with fewer than 3 vertices.
    let p = d.file("two_vertex_face.ply", format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n2 0 1\n"));
    expect_err(&p, load_ply(&p), "face 0 has 2 vertex indices");

    // 11. Trailing content (Mitsuba rejects it too).
    let mut trailing = good.clone();
    trailing.extend(b"junk");
    let p = d.file("trailing.ply", trailing);
    expect_err(&p, load_ply(&p), "4 bytes of trailing content");
    let p = d.file("trailing.ply", format!("{PLY_HEAD}0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n7\n"));
    expect_err(&p, load_ply(&p), ":14:1: trailing token \"7\"");

    // 12. Huge counts with a tiny body: an error, not an allocation failure.
    let huge = String::from_utf8_lossy(&good).replace("element face 1", "element face 18446744073709551615");
    let p = d.file("huge_count.ply", huge.as_bytes());
    expect_err(&p, load_ply(&p), "truncated");
    let p = d.file("huge_vertices.ply", PLY_HEAD.replace("vertex 3", "vertex 4000000000"));
    expect_err(&p, load_ply(&p), "unexpected end of file");
    let p = d.file(
        "huge_list.ply",
        PLY_HEAD.replace("list uchar int", "list uint int") + "0 0 0\n1 0 0\n0 1 0\n4294967295 0 1 2\n",
    );
    expect_err(&p, load_ply(&p), "unexpected end of file: expected face 0 of 1");

    // 13. Zero-length normal.
    let normals = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
                   property float nx\nproperty float ny\nproperty float nz\nend_header\n0 0 0 0 0 1\n1 0 0 0 0 0\n0 1 0 0 0 1\n";
    let p = d.file("zero_normal.ply", normals);
    expect_err(&p, load_ply(&p), ":12:11: vertex 1 has a zero-length or non-finite normal");

    // 14. Missing file.
    let p = d.0.join("missing.ply");
    expect_err(&p, load_ply(&p), "cannot read PLY file");
}

#[test]
fn malformed_obj_files() {
    let d = Dir::new("obj");
    let v = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

    // 1. Face index out of range, with line and column.
    let p = d.file("index.obj", format!("{v}f 1 2 4\n"));
    expect_err(&p, load_obj(&p), ":4:7: reference to vertex 4, but only 3 are defined so far");

    // 2. Bad number in a vertex; too few numbers.
    let p = d.file("number.obj", "v 0 0 0\nv 1 x 0\n");
    expect_err(&p, load_obj(&p), ":2:5: invalid number \"x\"");
    let p = d.file("short_v.obj", "v 0 0\n");
    expect_err(&p, load_obj(&p), ":1:1: \"v\" needs 3 numbers, found 2");

    // 3. Bad face tokens: not a number, index 0, too many slashes, relative index too far back.
    let p = d.file("face_token.obj", format!("{v}f 1 2 x\n"));
    expect_err(&p, load_obj(&p), ":4:7: invalid vertex index \"x\"");
    let p = d.file("zero.obj", format!("{v}f 0 1 2\n"));
    expect_err(&p, load_obj(&p), "vertex index 0 is invalid");
    let p = d.file("slashes.obj", format!("{v}f 1/1/1/1 2 3\n"));
    expect_err(&p, load_obj(&p), "more than three");
    let p = d.file("relative.obj", format!("{v}f -1 -2 -4\n"));
    expect_err(&p, load_obj(&p), "relative vertex index -4");

    // 4. Texture coordinate / normal index out of range (checked at the end, like Mitsuba).
    let p = d.file("vt_range.obj", format!("{v}vt 0 0\nf 1/1 2/1 3/2\n"));
    expect_err(&p, load_obj(&p), ":5:11: reference to texture coordinate 2, but the file has only 1");
    let p = d.file("vn_range.obj", format!("{v}vn 0 0 1\nf 1//1 2//5 3//1\n"));
    expect_err(&p, load_obj(&p), "reference to normal 5");

    // 5. Face vertices with and without uvs / normals mixed (Mitsuba: uninitialised data).
    let p = d.file("mixed_uv.obj", format!("{v}vt 0 0\nf 1/1 2/1 3\n"));
    expect_err(&p, load_obj(&p), ":5:11: face vertex has no texture coordinate");
    let p = d.file("mixed_n.obj", format!("{v}vn 0 0 1\nf 1//1 2 3//1\n"));
    expect_err(&p, load_obj(&p), "face vertex has no normal");

    // 6. Degenerate face, NaN position, zero normal.
    let p = d.file("two.obj", format!("{v}f 1 2\n"));
    expect_err(&p, load_obj(&p), "face has 2 vertices");
    let p = d.file("nan.obj", "v 0 nan 0\n");
    expect_err(&p, load_obj(&p), ":1:1: non-finite vertex position");
    let p = d.file("zero_n.obj", format!("{v}vn 0 0 0\n"));
    expect_err(&p, load_obj(&p), ":4:1: zero-length or non-finite normal");

    // 7. Missing file.
    let p = d.0.join("missing.obj");
    expect_err(&p, load_obj(&p), "cannot read OBJ file");
}

/// One single-precision mesh stream (header + zlib body) of a `.serialized` file.
fn ser_mesh(version: u16, vertex_count: u64, positions: &[f32], indices: &[u32]) -> Vec<u8> {
    let mut body = 0x1000u32.to_le_bytes().to_vec();
    if version == 4 {
        body.extend(b"name\0");
    }
    body.extend(vertex_count.to_le_bytes());
    body.extend(((indices.len() / 3) as u64).to_le_bytes());
    positions.iter().for_each(|x| body.extend(x.to_le_bytes()));
    indices.iter().for_each(|i| body.extend(i.to_le_bytes()));
    let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&body).unwrap();
    let mut out = 0x041Cu16.to_le_bytes().to_vec();
    out.extend(version.to_le_bytes());
    out.extend(z.finish().unwrap());
    out
}

fn with_dictionary(mut meshes: Vec<u8>, offsets: &[u64]) -> Vec<u8> {
    offsets.iter().for_each(|o| meshes.extend(o.to_le_bytes()));
    meshes.extend((offsets.len() as u32).to_le_bytes());
    meshes
}

#[test]
fn malformed_serialized_files() {
    let d = Dir::new("serialized");
    let tri = [0f32, 0., 0., 1., 0., 0., 0., 1., 0.];
    let one = ser_mesh(4, 3, &tri, &[0, 1, 2]);
    let good = with_dictionary(one.clone(), &[0]);
    let p = d.file("good.serialized", &good);
    assert_eq!(load_serialized(&p, 0).unwrap().triangle_count(), 1);

    // 1. Bad magic, bad version.
    let mut bad = good.clone();
    bad[0] = 0x1D;
    let p = d.file("magic.serialized", &bad);
    expect_err(&p, load_serialized(&p, 0), "not a Mitsuba serialized mesh: format id 0x041D");
    let mut bad = good.clone();
    bad[2] = 5;
    let p = d.file("version.serialized", &bad);
    expect_err(&p, load_serialized(&p, 0), "unsupported serialized mesh version 5");

    // 2. Truncated zlib stream; corrupt zlib data.
    let p = d.file("truncated.serialized", &one[..one.len() - 12]);
    expect_err(&p, load_serialized(&p, 0), "mesh 0");
    let mut corrupt = good.clone();
    for b in &mut corrupt[8..20] {
        *b ^= 0x5A;
    }
    let p = d.file("corrupt.serialized", &corrupt);
    expect_err(&p, load_serialized(&p, 0), "compressed data");

    // 3. Shape index out of range (== count, where Mitsuba's check is off by one).
    let two = with_dictionary([one.clone(), one.clone()].concat(), &[0, one.len() as u64]);
    let p = d.file("two.serialized", &two);
    assert_eq!(serialized_shape_count(&p).unwrap(), 2);
    assert!(load_serialized(&p, 1).is_ok());
    expect_err(&p, load_serialized(&p, 2), "shape_index 2 is out of range: the file holds 2 meshes (0..1)");

    // 4. Broken dictionaries: absurd count, offsets out of order, offset not at a mesh header.
    let mut absurd = good.clone();
    let n = absurd.len();
    absurd[n - 4..].copy_from_slice(&u32::MAX.to_le_bytes());
    let p = d.file("absurd.serialized", &absurd);
    expect_err(&p, serialized_shape_count(&p), "mesh count 4294967295 does not fit");
    let p = d.file("order.serialized", with_dictionary([one.clone(), one.clone()].concat(), &[0, 0]));
    expect_err(&p, load_serialized(&p, 1), "out of order");
    let p = d.file("offset.serialized", with_dictionary([one.clone(), one.clone()].concat(), &[0, 7]));
    expect_err(&p, load_serialized(&p, 1), "not a Mitsuba serialized mesh");

    // 5. Face index out of range; NaN position.
    let p = d.file("index.serialized", with_dictionary(ser_mesh(3, 3, &tri, &[0, 1, 3]), &[]));
    expect_err(&p, load_serialized(&p, 0), "triangle 0 references vertex 3");
    let mut nan = tri;
    nan[4] = f32::NAN;
    let p = d.file("nan.serialized", ser_mesh(4, 3, &nan, &[0, 1, 2]));
    expect_err(&p, load_serialized(&p, 0), "vertex 1 has a non-finite position");

    // 6. Counts far beyond the data: an error, not an allocation of the declared size.
    let p = d.file("huge.serialized", ser_mesh(4, u64::from(u32::MAX), &tri, &[0, 1, 2]));
    expect_err(&p, load_serialized(&p, 0), "ends while reading vertex positions");
    let p = d.file("huge64.serialized", ser_mesh(4, u64::MAX, &tri, &[0, 1, 2]));
    expect_err(&p, load_serialized(&p, 0), "declares 18446744073709551615 vertices");

    // 7. Too short to hold a header; missing file.
    let p = d.file("short.serialized", [0x1Cu8]);
    expect_err(&p, load_serialized(&p, 0), "file is truncated");
    let p = d.0.join("missing.serialized");
    expect_err(&p, load_serialized(&p, 0), "cannot read serialized mesh file");
}

#[test]
fn pathological_counts_stay_cheap() {
    let d = Dir::new("pathological");
    // An ascii element without properties and 2^64 - 1 records: nothing to read, loads at once.
    let ply = PLY_HEAD.replace("end_header", "element empty 18446744073709551615\nend_header")
        + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    let p = d.file("empty_element.ply", ply);
    assert_eq!(load_ply(&p).unwrap().triangle_count(), 1);

    // A `.serialized` name of 1 MiB non-zero bytes (compresses to almost nothing).
    let mut body = 0x1000u32.to_le_bytes().to_vec();
    body.extend(vec![b'a'; 1 << 20]);
    let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    z.write_all(&body).unwrap();
    let mut file = 0x041Cu16.to_le_bytes().to_vec();
    file.extend(4u16.to_le_bytes());
    file.extend(z.finish().unwrap());
    let p = d.file("long_name.serialized", file);
    expect_err(&p, load_serialized(&p, 0), "the name of mesh 0 is longer than 65536 bytes");
}

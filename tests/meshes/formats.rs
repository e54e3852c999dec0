//! Mesh loaders: files compared with what Mitsuba 3.9.1 loads from them, and round trips of
//! generated meshes through independent writers (ply-rs-bw for PLY, small writers here for OBJ
//! and `.serialized`) in every format variant.
//!
//! The `MITSUBA_*` arrays were printed by `tests/data/meshes/make_ply_obj.py --check` and
//! `make_serialized.py --check` (Mitsuba 3.9.1, `scalar_rgb`, `mi.load_dict`).

use std::io::Write;
use std::path::{Path, PathBuf};

use flate2::write::ZlibEncoder;
use ply_rs_bw::ply::{
    Addable, DefaultElement, ElementDef, Encoding, Ply, Property, PropertyDef, PropertyType, ScalarType,
};
use snee::math::{Vec2, Vec3};
use snee::shape::mesh_data::MeshData;
use snee::shape::obj::{load_obj, load_obj_with};
use snee::shape::ply::{load_ply, load_ply_with};
use snee::shape::serialized::{load_serialized, serialized_shape_count};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/meshes").join(name)
}

fn tmp_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("snee_meshes_{}_{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn flat3(v: &[Vec3]) -> Vec<f32> {
    v.iter().flat_map(|p| p.to_array()).collect()
}

fn flat2(v: &[Vec2]) -> Vec<f32> {
    v.iter().flat_map(|p| p.to_array()).collect()
}

fn flat_tri(t: &[[u32; 3]]) -> Vec<u32> {
    t.iter().flatten().copied().collect()
}

/// Mitsuba's printed values (f64 repr of its f32 buffers) back to f32: exact.
fn f32s(v: &[f64]) -> Vec<f32> {
    v.iter().map(|&x| x as f32).collect()
}

// ---- Files checked against Mitsuba 3.9.1 ----

#[rustfmt::skip]
const MITSUBA_PLY_POS: [f64; 15] = [
    0.10000000149011612, 0.20000000298023224, 0.30000001192092896,
    1.0, 0.0, -0.5,
    1.25, 1.5, 0.0,
    -0.3333333432674408, 1.0, 2.0,
    0.5, 0.5, 0.699999988079071,
];
const MITSUBA_PLY_FACES: [u32; 12] = [0, 1, 2, 0, 2, 3, 3, 4, 0, 4, 1, 0];
#[rustfmt::skip]
const MITSUBA_PLY_UV: [f64; 10] = [
    0.0, 0.0,
    1.0, 0.10000000149011612,
    0.699999988079071, 0.8999999761581421,
    0.20000000298023224, 0.6000000238418579,
    0.5, 0.5,
];
#[rustfmt::skip]
const MITSUBA_PLY_NORMALS: [f64; 15] = [
    0.0, 0.0, 1.0,
    0.0, 1.0, 0.0,
    0.7071067690849304, 0.7071067690849304, 0.0,
    0.4242640733718872, -0.5656854510307312, 0.7071067690849304,
    0.0, 0.0, -1.0,
];

#[test]
fn ply_files_match_mitsuba() {
    // Binary little endian: double positions, float normals, `s t` uvs, ignored colours, an extra
    // face property, a `vertex_index` list of uint, and an extra element after the faces.
    // Binary big endian: float positions, `texture_u texture_v`, int list; no normals.
    // Ascii with CRLF line ends: normals, `u v`.
    for (name, has_normals) in [("mitsuba_le.ply", true), ("mitsuba_be.ply", false), ("mitsuba_ascii.ply", true)] {
        let m = load_ply(&data(name)).unwrap();
        assert_eq!(flat3(&m.positions), f32s(&MITSUBA_PLY_POS), "{name}");
        assert_eq!(flat_tri(&m.indices), MITSUBA_PLY_FACES, "{name}");
        // Mitsuba's PLY default is flip_tex_coords = false.
        assert_eq!(flat2(&m.uvs), f32s(&MITSUBA_PLY_UV), "{name}");
        if has_normals {
            assert_eq!(flat3(&m.normals), f32s(&MITSUBA_PLY_NORMALS), "{name}");
        } else {
            assert!(m.normals.is_empty(), "{name}: Mitsuba computes these normals itself");
        }
    }
    // flip_tex_coords = true flips v (checked with Mitsuba on a single triangle: 0.125 → 0.875).
    let m = load_ply_with(&data("mitsuba_le.ply"), true).unwrap();
    let flipped: Vec<f32> = MITSUBA_PLY_UV.chunks(2).flat_map(|c| [c[0] as f32, 1.0 - c[1] as f32]).collect();
    assert_eq!(flat2(&m.uvs), flipped);
}

#[test]
fn obj_matches_mitsuba_dedup_order_and_uv_flip() {
    let m = load_obj(&data("mitsuba_dedup.obj")).unwrap();
    // Mitsuba: V 8 F 7 (the unreferenced `v 9 9 9` is dropped, (v, vt, vn) triples deduplicated
    // in order of first use, quads and the pentagon fan-triangulated).
    assert_eq!((m.vertex_count(), m.triangle_count()), (8, 7));
    // The five points of the PLY files, then the 4th, 3rd and 1st again (new (v, vt, vn) triples).
    let p = &MITSUBA_PLY_POS;
    let pos = [&p[..], &p[9..12], &p[6..9], &p[0..3]].concat();
    let faces = [0, 1, 2, 0, 2, 3, 0, 2, 4, 1, 0, 4, 1, 4, 5, 1, 5, 6, 4, 3, 7];
    #[rustfmt::skip]
    let uv = [
        0.0, 1.0,
        1.0, 0.8999999761581421,
        0.699999988079071, 0.10000002384185791,
        0.20000000298023224, 0.3999999761581421,
        0.20000000298023224, 0.3999999761581421,
        0.0, 1.0,
        0.699999988079071, 0.10000002384185791,
        0.0, 1.0,
    ];
    #[rustfmt::skip]
    let normals = [
        0.0, 0.0, 1.0,
        0.0, 0.0, 1.0,
        0.0, 0.0, 1.0,
        0.0, 0.0, 1.0,
        0.0, 1.0, 0.0,
        0.4242640733718872, -0.5656854510307312, 0.7071067690849304,
        0.4242640733718872, -0.5656854510307312, 0.7071067690849304,
        0.4242640733718872, -0.5656854510307312, 0.7071067690849304,
    ];
    assert_eq!(flat3(&m.positions), f32s(&pos));
    assert_eq!(flat_tri(&m.indices), faces);
    assert_eq!(flat2(&m.uvs), f32s(&uv));
    assert_eq!(flat3(&m.normals), f32s(&normals));

    // flip_tex_coords = false keeps the file's v.
    let m = load_obj_with(&data("mitsuba_dedup.obj"), false).unwrap();
    let unflipped: Vec<f32> = uv.chunks(2).flat_map(|c| [c[0] as f32, 1.0 - c[1] as f32]).collect();
    for (a, b) in flat2(&m.uvs).iter().zip(&unflipped) {
        assert!((a - b).abs() < 1e-6, "{a} vs {b}");
    }
}

#[test]
fn serialized_files_match_mitsuba() {
    for name in ["two_meshes_v4.serialized", "two_meshes_v3.serialized"] {
        let path = data(name);
        assert_eq!(serialized_shape_count(&path).unwrap(), 2, "{name}");

        // Mesh 0: single precision, normals (one of length 2) and uvs.
        let m = load_serialized(&path, 0).unwrap();
        assert_eq!(flat3(&m.positions), [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0]);
        assert_eq!(flat_tri(&m.indices), [0, 1, 2, 0, 2, 3]);
        assert_eq!(flat2(&m.uvs), [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.25, 0.75]);
        let n = [0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.6000000238418579, 0.800000011920929, 0.0, 0.0, 1.0];
        assert_eq!(flat3(&m.normals), f32s(&n));

        // Mesh 1: double precision, vertex colours (skipped), face-normal flag; no normals.
        let m = load_serialized(&path, 1).unwrap();
        let pos = [
            0.10000000149011612,
            0.20000000298023224,
            0.30000001192092896,
            1.7000000476837158,
            -2.5,
            0.0010000000474974513,
            3.1415927410125732,
            2.0,
            -1.0,
        ];
        assert_eq!(flat3(&m.positions), f32s(&pos));
        assert_eq!(flat_tri(&m.indices), [2, 1, 0]);
        assert!(m.normals.is_empty() && m.uvs.is_empty());

        // Mitsuba accepts index 2 of 2 (off by one) and then fails reading garbage.
        let e = load_serialized(&path, 2).unwrap_err().to_string();
        assert!(e.contains(name) && e.contains("shape_index 2 is out of range"), "{e}");
    }
}

// ---- Generated meshes ----

/// Small deterministic generator (64-bit LCG).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self.0.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (self.0 >> 33) as u32
    }
    fn below(&mut self, n: u32) -> u32 {
        self.next() % n
    }
    fn float(&mut self) -> f32 {
        (self.next() as f32 / (1u64 << 31) as f32) * 4.0 - 2.0
    }
}

/// A random polygon soup: `nv` vertices and faces of 3..=5 vertices.
struct Soup {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    uvs: Vec<Vec2>,
    polygons: Vec<Vec<u32>>,
}

fn soup(seed: u64, nv: u32, nf: usize) -> Soup {
    let mut r = Lcg(seed);
    let positions = (0..nv).map(|_| Vec3::new(r.float(), r.float(), r.float())).collect();
    // Unit normals as the loaders return them; stored exactly by every writer.
    let normals = (0..nv).map(|k| [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X][k as usize % 4]).collect();
    let uvs = (0..nv).map(|_| Vec2::new(r.float(), r.float())).collect();
    let polygons = (0..nf).map(|_| (0..3 + r.below(3)).map(|_| r.below(nv)).collect()).collect();
    Soup { positions, normals, uvs, polygons }
}

/// Fan triangulation of the soup's polygons: the expected triangles.
fn fan(polygons: &[Vec<u32>]) -> Vec<[u32; 3]> {
    polygons.iter().flat_map(|p| (1..p.len() - 1).map(move |k| [p[0], p[k], p[k + 1]])).collect()
}

struct PlyVariant {
    encoding: Encoding,
    double: bool,
    normals: bool,
    uv_names: Option<(&'static str, &'static str)>,
    count_type: ScalarType,
    index_type: ScalarType,
    index_name: &'static str,
}

fn write_ply(s: &Soup, v: &PlyVariant) -> Vec<u8> {
    let mut ply = Ply::<DefaultElement>::new();
    ply.header.encoding = v.encoding;
    let mut vertex = ElementDef::new("vertex".to_string());
    let float = if v.double { ScalarType::Double } else { ScalarType::Float };
    let mut names = vec!["x", "y", "z"];
    if v.normals {
        names.extend(["nx", "ny", "nz"]);
    }
    if let Some((u, w)) = v.uv_names {
        names.extend([u, w]);
    }
    for n in &names {
        vertex.properties.add(PropertyDef::new(n.to_string(), PropertyType::Scalar(float.clone())));
    }
    // An ignored property between the used ones.
    vertex.properties.add(PropertyDef::new("red".to_string(), PropertyType::Scalar(ScalarType::UChar)));
    ply.header.elements.add(vertex);

    let mut face = ElementDef::new("face".to_string());
    face.properties.add(PropertyDef::new("flags".to_string(), PropertyType::Scalar(ScalarType::Short)));
    face.properties.add(PropertyDef::new(
        v.index_name.to_string(),
        PropertyType::List(v.count_type.clone(), v.index_type.clone()),
    ));
    face.properties
        .add(PropertyDef::new("texcoord".to_string(), PropertyType::List(ScalarType::UChar, ScalarType::Float)));
    ply.header.elements.add(face);

    // An element Mitsuba would skip, with a list property.
    let mut other = ElementDef::new("material".to_string());
    other.properties.add(PropertyDef::new("ids".to_string(), PropertyType::List(ScalarType::Int, ScalarType::Int)));
    ply.header.elements.add(other);

    let verts = (0..s.positions.len())
        .map(|i| {
            let mut e = DefaultElement::new();
            let mut vals = s.positions[i].to_array().to_vec();
            if v.normals {
                vals.extend(s.normals[i].to_array());
            }
            if v.uv_names.is_some() {
                vals.extend(s.uvs[i].to_array());
            }
            for (n, x) in names.iter().zip(vals) {
                let p = if v.double { Property::Double(f64::from(x)) } else { Property::Float(x) };
                e.insert(n.to_string(), p);
            }
            e.insert("red".to_string(), Property::UChar(i as u8));
            e
        })
        .collect();
    ply.payload.insert("vertex".to_string(), verts);
    let faces = s
        .polygons
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let mut e = DefaultElement::new();
            e.insert("flags".to_string(), Property::Short(-(k as i16)));
            let list = match v.index_type {
                ScalarType::Int => Property::ListInt(p.iter().map(|&i| i as i32).collect()),
                ScalarType::UInt => Property::ListUInt(p.clone()),
                ScalarType::UShort => Property::ListUShort(p.iter().map(|&i| i as u16).collect()),
                _ => unreachable!("test variant"),
            };
            e.insert(v.index_name.to_string(), list);
            e.insert("texcoord".to_string(), Property::ListFloat(vec![0.5; k % 3]));
            e
        })
        .collect();
    ply.payload.insert("face".to_string(), faces);
    let materials = (0..3)
        .map(|k| {
            let mut e = DefaultElement::new();
            e.insert("ids".to_string(), Property::ListInt((0..k).collect()));
            e
        })
        .collect();
    ply.payload.insert("material".to_string(), materials);

    let mut buf = Vec::new();
    ply_rs_bw::writer::Writer::new().write_ply(&mut buf, &mut ply).unwrap();
    buf
}

#[test]
fn ply_round_trips_every_encoding_and_type() {
    let dir = tmp_dir("ply_round_trip");
    let s = soup(7, 40, 60);
    let encodings = [Encoding::Ascii, Encoding::BinaryLittleEndian, Encoding::BinaryBigEndian];
    let mut cases = 0;
    for (e, encoding) in encodings.into_iter().enumerate() {
        for k in 0..6 {
            let v = PlyVariant {
                encoding,
                double: k % 2 == 1,
                normals: k % 3 != 0,
                uv_names: [None, Some(("u", "v")), Some(("s", "t")), Some(("texture_u", "texture_v"))][k % 4],
                count_type: [ScalarType::UChar, ScalarType::Int, ScalarType::UInt][k % 3].clone(),
                index_type: [ScalarType::Int, ScalarType::UInt, ScalarType::UShort][(k + e) % 3].clone(),
                index_name: ["vertex_indices", "vertex_index"][k % 2],
            };
            let path = dir.join(format!("m{e}_{k}.ply"));
            std::fs::write(&path, write_ply(&s, &v)).unwrap();
            let m = load_ply(&path).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(m.positions, s.positions, "{}", path.display());
            assert_eq!(m.indices, fan(&s.polygons), "{}", path.display());
            assert_eq!(m.normals, if v.normals { s.normals.clone() } else { vec![] });
            assert_eq!(m.uvs, if v.uv_names.is_some() { s.uvs.clone() } else { vec![] });
            cases += 1;
        }
    }
    assert_eq!(cases, 18);
    std::fs::remove_dir_all(dir).ok();
}

/// Face vertex forms of the OBJ writer.
#[derive(Clone, Copy)]
enum ObjForm {
    V,
    VVt,
    VVn,
    VVtVn,
}

/// Write an OBJ whose face vertex `i` of a polygon uses position `i`, texcoord `i` and normal
/// `i` (each in the given form), with relative indices on odd faces.
fn write_obj(s: &Soup, form: ObjForm, flip_back: bool) -> String {
    let mut o = String::from("# generated\n");
    for p in &s.positions {
        o += &format!("v {} {} {}\n", p.x, p.y, p.z);
    }
    for uv in &s.uvs {
        // Write 1 - v so that the default flip gives back the soup's uv (not exactly: checked
        // with a tolerance below); `flip_back = false` writes v as is.
        let v = if flip_back { 1.0 - uv.y } else { uv.y };
        o += &format!("vt {} {}\n", uv.x, v);
    }
    for n in &s.normals {
        o += &format!("vn {} {} {}\n", n.x, n.y, n.z);
    }
    let count = s.positions.len() as i64;
    for (k, p) in s.polygons.iter().enumerate() {
        o += "f";
        for &i in p {
            let i = if k % 2 == 1 { i as i64 - count } else { i as i64 + 1 };
            o += &match form {
                ObjForm::V => format!(" {i}"),
                ObjForm::VVt => format!(" {i}/{i}"),
                ObjForm::VVn => format!(" {i}//{i}"),
                ObjForm::VVtVn => format!(" {i}/{i}/{i}"),
            };
        }
        o += "\n";
    }
    o
}

#[test]
fn obj_round_trips_every_face_form() {
    let dir = tmp_dir("obj_round_trip");
    let s = soup(11, 30, 40);
    // Expected output: vertices in order of first use (an independent, quadratic dedup).
    let mut order: Vec<u32> = Vec::new();
    for p in &s.polygons {
        for &i in p {
            if !order.contains(&i) {
                order.push(i);
            }
        }
    }
    let new_id = |i: u32| order.iter().position(|&j| j == i).unwrap() as u32;
    let tris: Vec<[u32; 3]> = fan(&s.polygons).iter().map(|t| t.map(new_id)).collect();
    let positions: Vec<Vec3> = order.iter().map(|&i| s.positions[i as usize]).collect();
    for form in [ObjForm::V, ObjForm::VVt, ObjForm::VVn, ObjForm::VVtVn] {
        let path = dir.join("m.obj");
        std::fs::write(&path, write_obj(&s, form, false)).unwrap();
        let m = load_obj_with(&path, false).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m.positions, positions);
        assert_eq!(m.indices, tris);
        let has_uv = matches!(form, ObjForm::VVt | ObjForm::VVtVn);
        let has_n = matches!(form, ObjForm::VVn | ObjForm::VVtVn);
        let uvs: Vec<Vec2> = order.iter().map(|&i| s.uvs[i as usize]).collect();
        let normals: Vec<Vec3> = order.iter().map(|&i| s.normals[i as usize]).collect();
        assert_eq!(m.uvs, if has_uv { uvs.clone() } else { vec![] });
        assert_eq!(m.normals, if has_n { normals } else { vec![] });

        // Default flip_tex_coords = true on a file written with 1 - v.
        std::fs::write(&path, write_obj(&s, form, true)).unwrap();
        let m = load_obj(&path).unwrap();
        if has_uv {
            for (a, b) in m.uvs.iter().zip(&uvs) {
                assert!((*a - *b).abs().max_element() < 1e-6, "{a} vs {b}");
            }
        }
    }
    std::fs::remove_dir_all(dir).ok();
}

/// One mesh of a `.serialized` file, as written by the test writer.
struct SerMesh<'a> {
    mesh: &'a MeshData,
    double: bool,
    colors: bool,
    name: &'a str,
}

/// Write a `.serialized` file (format of Mitsuba 3.9 `serialized.cpp`) with a dictionary.
fn write_serialized(version: u16, meshes: &[SerMesh]) -> Vec<u8> {
    let mut out = Vec::new();
    let mut offsets = Vec::new();
    for m in meshes {
        offsets.push(out.len() as u64);
        out.extend(0x041Cu16.to_le_bytes());
        out.extend(version.to_le_bytes());
        let mut body = Vec::new();
        let mut flags = if m.double { 0x2000u32 } else { 0x1000 };
        flags |= if m.mesh.normals.is_empty() { 0 } else { 1 };
        flags |= if m.mesh.uvs.is_empty() { 0 } else { 2 };
        flags |= if m.colors { 8 } else { 0 };
        body.extend(flags.to_le_bytes());
        if version == 4 {
            body.extend(m.name.as_bytes());
            body.push(0);
        }
        body.extend((m.mesh.positions.len() as u64).to_le_bytes());
        body.extend((m.mesh.indices.len() as u64).to_le_bytes());
        let mut floats = |vals: Vec<f32>| {
            for x in vals {
                if m.double {
                    body.extend(f64::from(x).to_le_bytes());
                } else {
                    body.extend(x.to_le_bytes());
                }
            }
        };
        floats(flat3(&m.mesh.positions));
        floats(flat3(&m.mesh.normals));
        floats(flat2(&m.mesh.uvs));
        if m.colors {
            floats(vec![0.25; 3 * m.mesh.positions.len()]);
        }
        for i in flat_tri(&m.mesh.indices) {
            body.extend(i.to_le_bytes());
        }
        let mut z = ZlibEncoder::new(Vec::new(), flate2::Compression::default());
        z.write_all(&body).unwrap();
        out.extend(z.finish().unwrap());
    }
    for o in &offsets {
        if version == 4 {
            out.extend(o.to_le_bytes());
        } else {
            out.extend((*o as u32).to_le_bytes());
        }
    }
    out.extend((meshes.len() as u32).to_le_bytes());
    out
}

fn soup_mesh(seed: u64, normals: bool, uvs: bool) -> MeshData {
    let s = soup(seed, 25, 30);
    MeshData {
        indices: fan(&s.polygons),
        normals: if normals { s.normals } else { vec![] },
        uvs: if uvs { s.uvs } else { vec![] },
        positions: s.positions,
    }
}

#[test]
fn serialized_round_trips_versions_precisions_and_flags() {
    let dir = tmp_dir("serialized_round_trip");
    let meshes =
        [soup_mesh(1, true, true), soup_mesh(2, false, true), soup_mesh(3, true, false), soup_mesh(4, false, false)];
    for version in [3u16, 4] {
        for double in [false, true] {
            let entries: Vec<SerMesh> = meshes
                .iter()
                .enumerate()
                .map(|(k, mesh)| SerMesh { mesh, double, colors: k % 2 == 1, name: ["a", "", "long name", "d"][k] })
                .collect();
            let path = dir.join(format!("m{version}_{double}.serialized"));
            std::fs::write(&path, write_serialized(version, &entries)).unwrap();
            assert_eq!(serialized_shape_count(&path).unwrap(), 4);
            for (k, want) in meshes.iter().enumerate() {
                let m = load_serialized(&path, k as u32).unwrap_or_else(|e| panic!("{e}"));
                // The soup's coordinates are f32, so double precision round-trips exactly too.
                assert_eq!(m.positions, want.positions);
                assert_eq!(m.normals, want.normals);
                assert_eq!(m.uvs, want.uvs);
                assert_eq!(m.indices, want.indices);
            }
            assert!(load_serialized(&path, 4).is_err());
        }
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn empty_meshes_load_as_in_mitsuba() {
    // Mitsuba 3.9 loads a PLY with "element face 0" (0 faces); consumers must skip such shapes.
    let dir = tmp_dir("empty");
    let path = dir.join("empty.ply");
    std::fs::write(
        &path,
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
         element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n",
    )
    .unwrap();
    let m = load_ply(&path).unwrap();
    assert_eq!((m.vertex_count(), m.triangle_count()), (3, 0));
    std::fs::remove_dir_all(dir).ok();
}

//! Wavefront OBJ mesh loader.
//!
//! ```xml
//! <shape type="obj">
//!     <string name="filename" value="teapot.obj"/>
//!     <!-- default true: v ↦ 1 − v, the convention of most OBJ files -->
//!     <boolean name="flip_tex_coords" value="true"/>
//! </shape>
//! ```
//!
//! What is read, following Mitsuba 3.9 (`src/shapes/obj.cpp`):
//! - `v x y z` (further values such as `w` or vertex colours are ignored), `vn x y z` (normalised),
//!   `vt u v` (a third value is ignored; `v ↦ 1 − v` when `flip_tex_coords`, the default);
//! - `f` with `v`, `v/vt`, `v//vn` or `v/vt/vn` per vertex; polygons become the fan
//!   `(0, k, k+1)`;
//! - one output vertex per distinct `(v, vt, vn)` triple, numbered in order of first use, so the
//!   vertex order and count equal Mitsuba's; unreferenced `v` lines are dropped;
//! - every other statement (`o`, `g`, `s`, `usemtl`, `mtllib`, `l`, ...) is ignored, `#` starts a
//!   comment.
//!
//! Deliberate differences, each turning a silently broken Mitsuba mesh into either a working one
//! or an error with `file:line:col`:
//! - negative (relative) indices are supported (Mitsuba reports an invalid vertex);
//! - a face vertex without `vt` (or `vn`) while others have one is an error (Mitsuba leaves
//!   those vertices' uvs/normals uninitialised); `vt`/`vn` lines no face uses are ignored
//!   (Mitsuba then fills the buffers with garbage);
//! - faces with fewer than 3 vertices, unparsable face tokens and index 0 are errors (Mitsuba
//!   drops the rest of the line silently);
//! - an OBJ without faces loads as an empty mesh (Mitsuba fails while computing normals).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::path::Path;

use super::mesh_data::{normalize_normal, MeshData};
use crate::math::{Vec2, Vec3};
use crate::scene::error::{Error, Result, SrcPos};

/// Load an OBJ file with Mitsuba's default `flip_tex_coords = true`; the result is validated.
pub fn load_obj(path: &Path) -> Result<MeshData> {
    load_obj_with(path, true)
}

/// Load an OBJ file; `flip_tex_coords` maps `v ↦ 1 − v` as Mitsuba's parameter does.
pub fn load_obj_with(path: &Path, flip_tex_coords: bool) -> Result<MeshData> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| Error::in_file(&file, format!("cannot read OBJ file: {e}")))?;
    load_obj_from_bytes(&bytes, &file, flip_tex_coords)
}

/// Key of an output vertex: 0-based position index, texcoord index + 1 and normal index + 1
/// (0 = absent), as Mitsuba's `(v, vt, vn)` key.
type Key = (u32, u32, u32);

/// Where an output vertex was first used (for errors about it).
#[derive(Clone, Copy)]
struct Use {
    key: Key,
    line: u32,
    col: u32,
}

/// Decode an OBJ file held in memory; `file` names it in errors. The result is validated.
pub fn load_obj_from_bytes(bytes: &[u8], file: &str, flip_tex_coords: bool) -> Result<MeshData> {
    let mut v: Vec<Vec3> = Vec::new();
    let mut vn: Vec<Vec3> = Vec::new();
    let mut vt: Vec<Vec2> = Vec::new();
    let mut ids: HashMap<Key, u32, BuildHasherDefault<FxHasher>> = HashMap::default();
    let mut uses: Vec<Use> = Vec::new();
    let mut indices: Vec<[u32; 3]> = Vec::new();
    let mut polygon: Vec<u32> = Vec::new();

    // Lines end in `\n` (or `\r\n`); a file without any `\n` but with `\r` uses classic Mac
    // line ends (Mitsuba would report one over-long line).
    let eol = if !bytes.contains(&b'\n') && bytes.contains(&b'\r') { b'\r' } else { b'\n' };
    for (line_idx, raw) in bytes.split(|&b| b == eol).enumerate() {
        let line_no = u32::try_from(line_idx + 1).unwrap_or(u32::MAX);
        let at = |col: u32, msg: String| Error::at(&SrcPos::new(file, line_no, col), msg);
        let content = match raw.iter().position(|&b| b == b'#') {
            Some(hash) => &raw[..hash],
            None => raw,
        };
        let mut toks = tokens(content);
        let Some((col0, keyword)) = toks.next() else { continue };
        match keyword {
            b"v" | b"vn" | b"vt" => {
                let dim = if keyword == b"vt" { 2 } else { 3 };
                let mut x = [0f32; 3];
                for (k, slot) in x.iter_mut().take(dim).enumerate() {
                    let Some((col, t)) = toks.next() else {
                        let what = String::from_utf8_lossy(keyword);
                        return Err(at(col0, format!("\"{what}\" needs {dim} numbers, found {k}")));
                    };
                    *slot = parse_f32(t).ok_or_else(|| at(col, format!("invalid number \"{}\"", lossy(t))))?;
                }
                let bad = |what: &str| at(col0, format!("{what} ({}, {}, {})", x[0], x[1], x[2]));
                match keyword {
                    b"v" => {
                        let p = Vec3::from(x);
                        if !p.is_finite() {
                            return Err(bad("non-finite vertex position"));
                        }
                        v.push(p);
                    }
                    b"vn" => {
                        let n = Vec3::from(x);
                        if !n.is_finite() || n == Vec3::ZERO {
                            return Err(bad("zero-length or non-finite normal"));
                        }
                        vn.push(normalize_normal(n));
                    }
                    _ => {
                        let uv = Vec2::new(x[0], if flip_tex_coords { 1.0 - x[1] } else { x[1] });
                        if !uv.is_finite() {
                            return Err(at(col0, format!("non-finite texture coordinate ({}, {})", x[0], x[1])));
                        }
                        vt.push(uv);
                    }
                }
            }
            b"f" => {
                polygon.clear();
                for (col, t) in toks {
                    let key = face_vertex(t, v.len(), vt.len(), vn.len()).map_err(|msg| at(col, msg))?;
                    let next_id = uses.len() as u32;
                    let id = *ids.entry(key).or_insert_with(|| {
                        uses.push(Use { key, line: line_no, col });
                        next_id
                    });
                    polygon.push(id);
                }
                if polygon.len() < 3 {
                    return Err(at(col0, format!("face has {} vertices; a face needs at least 3", polygon.len())));
                }
                // Fan triangulation (0, k, k + 1), as Mitsuba.
                for k in 1..polygon.len() - 1 {
                    indices.push([polygon[0], polygon[k], polygon[k + 1]]);
                }
            }
            _ => {}
        }
    }

    let mesh = assemble(file, &uses, &v, &vt, &vn, indices)?;
    mesh.validate(file)?;
    Ok(mesh)
}

/// Build the per-vertex arrays from the distinct `(v, vt, vn)` keys.
fn assemble(
    file: &str,
    uses: &[Use],
    v: &[Vec3],
    vt: &[Vec2],
    vn: &[Vec3],
    indices: Vec<[u32; 3]>,
) -> Result<MeshData> {
    let at = |u: &Use, msg: String| Error::at(&SrcPos::new(file, u.line, u.col), msg);
    let with_uv = uses.iter().find(|u| u.key.1 != 0);
    let with_n = uses.iter().find(|u| u.key.2 != 0);
    let mut mesh = MeshData { indices, ..MeshData::default() };
    mesh.positions.reserve_exact(uses.len());
    if with_uv.is_some() {
        mesh.uvs.reserve_exact(uses.len());
    }
    if with_n.is_some() {
        mesh.normals.reserve_exact(uses.len());
    }
    for u in uses {
        let (p, t, n) = u.key;
        mesh.positions.push(v[p as usize]);
        if let Some(first) = with_uv {
            if t == 0 {
                return Err(at(
                    u,
                    format!(
                        "face vertex has no texture coordinate, but the one at line {} has: \
                         give every face vertex a \"vt\" or none",
                        first.line
                    ),
                ));
            }
            let uv = vt.get(t as usize - 1).ok_or_else(|| {
                at(u, format!("reference to texture coordinate {t}, but the file has only {}", vt.len()))
            })?;
            mesh.uvs.push(*uv);
        }
        if let Some(first) = with_n {
            if n == 0 {
                return Err(at(
                    u,
                    format!(
                        "face vertex has no normal, but the one at line {} has: \
                         give every face vertex a \"vn\" or none",
                        first.line
                    ),
                ));
            }
            let normal = vn
                .get(n as usize - 1)
                .ok_or_else(|| at(u, format!("reference to normal {n}, but the file has only {}", vn.len())))?;
            mesh.normals.push(*normal);
        }
    }
    Ok(mesh)
}

/// Parse one face vertex `v`, `v/vt`, `v//vn` or `v/vt/vn` into a [`Key`]. Positions must be
/// defined before use (as in Mitsuba); `vt`/`vn` may be defined later and are checked at the end.
fn face_vertex(t: &[u8], nv: usize, nvt: usize, nvn: usize) -> std::result::Result<Key, String> {
    let mut parts = t.split(|&b| b == b'/');
    let mut next = || parts.next().filter(|p| !p.is_empty());
    let (p, tc, n) = (next(), next(), next());
    if parts.next().is_some() {
        return Err(format!("invalid face vertex \"{}\" (more than three '/'-separated indices)", lossy(t)));
    }
    let Some(p) = p else {
        return Err(format!("invalid face vertex \"{}\" (no position index)", lossy(t)));
    };
    let p = index(p, nv, "vertex")?;
    if p as usize >= nv {
        return Err(format!("reference to vertex {}, but only {nv} are defined so far", p + 1));
    }
    let tc = tc.map(|s| index(s, nvt, "texture coordinate")).transpose()?;
    let n = n.map(|s| index(s, nvn, "normal")).transpose()?;
    Ok((p, tc.map_or(0, |i| i + 1), n.map_or(0, |i| i + 1)))
}

/// A 1-based (or negative, relative) OBJ index → 0-based; `count` is how many are defined so far.
fn index(s: &[u8], count: usize, what: &str) -> std::result::Result<u32, String> {
    let bad = || format!("invalid {what} index \"{}\"", lossy(s));
    let i: i64 = std::str::from_utf8(s).ok().and_then(|s| s.parse().ok()).ok_or_else(bad)?;
    let resolved = match i {
        0 => return Err(format!("{what} index 0 is invalid (OBJ indices start at 1)")),
        i if i > 0 => i - 1,
        i => count as i64 + i,
    };
    if resolved < 0 {
        return Err(format!("relative {what} index {i} reaches before the first of the {count} defined so far"));
    }
    // Leave room for the +1 of the key encoding.
    u32::try_from(resolved).ok().filter(|&r| r < u32::MAX).ok_or_else(bad)
}

fn parse_f32(t: &[u8]) -> Option<f32> {
    std::str::from_utf8(t).ok()?.parse().ok()
}

fn lossy(t: &[u8]) -> std::borrow::Cow<'_, str> {
    String::from_utf8_lossy(t)
}

/// Whitespace-separated tokens with their 1-based byte columns.
fn tokens(line: &[u8]) -> impl Iterator<Item = (u32, &[u8])> {
    let mut pos = 0usize;
    std::iter::from_fn(move || {
        while line.get(pos).is_some_and(|b| b.is_ascii_whitespace()) {
            pos += 1;
        }
        let start = pos;
        while line.get(pos).is_some_and(|b| !b.is_ascii_whitespace()) {
            pos += 1;
        }
        (pos > start).then(|| (start as u32 + 1, &line[start..pos]))
    })
}

/// The Fx hash (rustc's): much faster than SipHash for small integer keys; no DoS concern here.
#[derive(Default, Clone, Copy)]
struct FxHasher(u64);

impl Hasher for FxHasher {
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.write_u64(u64::from(b));
        }
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
}

/// The `obj` shape's own parameter: `flip_tex_coords` (default true, as Mitsuba).
pub fn from_props(props: &crate::scene::desc::Props, path: &Path) -> Result<MeshData> {
    load_obj_with(path, props.bool("flip_tex_coords", true)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_vertex_forms() {
        assert_eq!(face_vertex(b"2", 3, 0, 0), Ok((1, 0, 0)));
        assert_eq!(face_vertex(b"2/1", 3, 2, 0), Ok((1, 1, 0)));
        assert_eq!(face_vertex(b"2//2", 3, 0, 2), Ok((1, 0, 2)));
        assert_eq!(face_vertex(b"-1/-2/-1", 3, 2, 4), Ok((2, 1, 4)));
        assert!(face_vertex(b"4", 3, 0, 0).is_err());
        assert!(face_vertex(b"-4", 3, 0, 0).is_err());
        assert!(face_vertex(b"0", 3, 0, 0).is_err());
        assert!(face_vertex(b"1/2/3/4", 3, 9, 9).is_err());
        assert!(face_vertex(b"1.5", 3, 0, 0).is_err());
        assert!(face_vertex(b"/1", 3, 1, 0).is_err());
    }

    #[test]
    fn comments_and_unknown_statements_are_ignored() {
        let obj = b"# c\no x\ng y\ns 1\nusemtl m\nv 0 0 0 # c\nv 1 0 0\nv 0 1 0 1\nf 1 2 3 # tri\nl 1 2\n";
        let m = load_obj_from_bytes(obj, "c.obj", true).unwrap();
        assert_eq!(m.indices, vec![[0, 1, 2]]);
        assert!(m.normals.is_empty() && m.uvs.is_empty());
    }

    #[test]
    fn line_ends() {
        for obj in ["v 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nf 1 2 3\r\n", "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r"] {
            let m = load_obj_from_bytes(obj.as_bytes(), "e.obj", true).unwrap();
            assert_eq!(m.indices, vec![[0, 1, 2]]);
        }
        let e = load_obj_from_bytes(b"v 0 0 0\rv 1 0 0\rf 1 2 3\r", "e.obj", true).unwrap_err();
        assert_eq!(e.to_string(), "e.obj:3:7: reference to vertex 3, but only 2 are defined so far");
    }
}

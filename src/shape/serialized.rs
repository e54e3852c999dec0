//! Mitsuba's `.serialized` mesh format loader.
//!
//! ```xml
//! <shape type="serialized">
//!     <string name="filename" value="scene.serialized"/>
//!     <integer name="shape_index" value="2"/>  <!-- default 0: the first mesh -->
//! </shape>
//! ```
//!
//! Format (Mitsuba 3.9, `src/shapes/serialized.cpp`; all little endian). A file is a sequence of
//! meshes followed by a dictionary. Each mesh is
//! - `u16` format id `0x041C`, `u16` version 3 or 4 (uncompressed), then a zlib stream holding
//! - `u32` flags: `0x1` vertex normals, `0x2` texture coordinates, `0x8` vertex colours,
//!   `0x10` face normals (ignored by Mitsuba 3, and here), `0x2000` double precision (else single);
//! - version 4 only: the shape's name, a NUL-terminated string;
//! - `u64` vertex count, `u64` triangle count;
//! - positions (3 floats per vertex), then if flagged normals (3), uvs (2), colours (3, skipped);
//! - triangles as 3 × `u32`.
//!
//! The dictionary at the end of the file holds the byte offset of each mesh (`u64` in version 4,
//! `u32` in version 3) followed by the `u32` mesh count. As in Mitsuba, `shape_index` 0 reads the
//! first mesh without consulting the dictionary, so single-mesh files need none.
//!
//! Differences from Mitsuba: `shape_index == count` is an error (Mitsuba's bound check is off by
//! one and reads garbage); face indices out of range, non-finite positions and zero normals are
//! errors; the dictionary is checked (offsets increasing, inside the file, each at a mesh header).
//! Normals are normalised, as Mitsuba does after `to_world`.

use std::io::Read;
use std::path::Path;

use flate2::read::ZlibDecoder;

use super::mesh_data::{normalize_normal, MeshData};
use crate::math::{Vec2, Vec3};
use crate::scene::error::{Error, Result, SrcPos};

const FORMAT_ID: u16 = 0x041C;
const HAS_NORMALS: u32 = 0x0001;
const HAS_TEXCOORDS: u32 = 0x0002;
const HAS_COLORS: u32 = 0x0008;
const DOUBLE_PRECISION: u32 = 0x2000;

/// Values decoded per read call: bounds memory by the data actually present, whatever the
/// counts in the (possibly corrupt) header say.
const CHUNK: usize = 1 << 16;

/// Longest shape name accepted (names are read byte by byte).
const MAX_NAME: usize = 1 << 16;

/// Load mesh `shape_index` of a `.serialized` file; the result is validated.
pub fn load_serialized(path: &Path, shape_index: u32) -> Result<MeshData> {
    let file = path.display().to_string();
    let bytes = read_file(path, &file)?;
    load_serialized_from_bytes(&bytes, &file, shape_index)
}

/// Number of meshes in a `.serialized` file, from its end-of-file dictionary.
pub fn serialized_shape_count(path: &Path) -> Result<u32> {
    let file = path.display().to_string();
    let bytes = read_file(path, &file)?;
    let version = header_version(&bytes, 0, &file)?;
    Ok(dictionary(&bytes, version, &file)?.len() as u32)
}

/// Decode mesh `shape_index` of a `.serialized` file held in memory; `file` names it in errors.
pub fn load_serialized_from_bytes(bytes: &[u8], file: &str, shape_index: u32) -> Result<MeshData> {
    let version = header_version(bytes, 0, file)?;
    let offset = if shape_index == 0 {
        0
    } else {
        let offsets = dictionary(bytes, version, file)?;
        let n = offsets.len();
        let Some(&offset) = offsets.get(shape_index as usize) else {
            return Err(Error::in_file(
                file,
                format!("shape_index {shape_index} is out of range: the file holds {n} meshes (0..{})", n - 1),
            ));
        };
        offset as usize
    };
    if header_version(bytes, offset, file)? != version {
        return Err(Error::in_file(file, format!("mesh {shape_index} has a different format version than the file")));
    }
    let compressed = bytes.get(offset + 4..).unwrap_or(&[]);
    let mut s = Stream { z: ZlibDecoder::new(compressed), file, shape: shape_index };
    let mesh = s.mesh(version)?;
    mesh.validate(file)?;
    Ok(mesh)
}

fn read_file(path: &Path, file: &str) -> Result<Vec<u8>> {
    std::fs::read(path).map_err(|e| Error::in_file(file, format!("cannot read serialized mesh file: {e}")))
}

fn le_u16(bytes: &[u8], at: usize) -> Option<u16> {
    Some(u16::from_le_bytes(bytes.get(at..at.checked_add(2)?)?.try_into().ok()?))
}

fn le_u32(bytes: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(bytes.get(at..at.checked_add(4)?)?.try_into().ok()?))
}

fn le_u64(bytes: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(bytes.get(at..at.checked_add(8)?)?.try_into().ok()?))
}

/// Check the uncompressed header at `offset`; returns the version (3 or 4).
fn header_version(bytes: &[u8], offset: usize, file: &str) -> Result<u16> {
    let (Some(id), Some(version)) = (le_u16(bytes, offset), le_u16(bytes, offset + 2)) else {
        return Err(Error::in_file(file, format!("file is truncated: no mesh header at byte {offset}")));
    };
    if id != FORMAT_ID {
        return Err(Error::in_file(
            file,
            format!("not a Mitsuba serialized mesh: format id 0x{id:04X} at byte {offset} (expected 0x041C)"),
        ));
    }
    if version != 3 && version != 4 {
        return Err(Error::in_file(file, format!("unsupported serialized mesh version {version} (expected 3 or 4)")));
    }
    Ok(version)
}

/// The end-of-file dictionary: the byte offset of every mesh.
fn dictionary(bytes: &[u8], version: u16, file: &str) -> Result<Vec<u64>> {
    let bad = |msg: String| Error::in_file(file, format!("invalid mesh dictionary at the end of the file: {msg}"));
    let len = bytes.len();
    let count =
        le_u32(bytes, len.saturating_sub(4)).filter(|_| len >= 8).ok_or_else(|| bad("file too short".into()))?;
    let entry = if version == 4 { 8 } else { 4 };
    // The dictionary must leave room for at least one mesh header before it.
    let dict_start = (count as usize)
        .checked_mul(entry)
        .and_then(|d| len.checked_sub(d + 4))
        .filter(|&s| s >= 4 && count > 0)
        .ok_or_else(|| bad(format!("mesh count {count} does not fit in a {len}-byte file")))?;
    let mut offsets = Vec::with_capacity(count as usize);
    for k in 0..count as usize {
        let at = dict_start + k * entry;
        let off = if version == 4 { le_u64(bytes, at) } else { le_u32(bytes, at).map(u64::from) };
        let off = off.ok_or_else(|| bad("truncated".into()))?;
        let previous = offsets.last().copied();
        if (k == 0 && off != 0) || previous.is_some_and(|p| off <= p) || off.saturating_add(4) > dict_start as u64 {
            return Err(bad(format!("offset {off} of mesh {k} is out of order or outside the file")));
        }
        offsets.push(off);
    }
    Ok(offsets)
}

/// The decompressed stream of one mesh.
struct Stream<'a> {
    z: ZlibDecoder<&'a [u8]>,
    file: &'a str,
    shape: u32,
}

impl Stream<'_> {
    fn read(&mut self, buf: &mut [u8], what: &str) -> Result<()> {
        self.z.read_exact(buf).map_err(|e| {
            let msg = match e.kind() {
                std::io::ErrorKind::UnexpectedEof => {
                    format!("compressed data of mesh {} ends while reading {what} (truncated file?)", self.shape)
                }
                _ => format!("corrupt compressed data in mesh {} while reading {what}: {e}", self.shape),
            };
            Error::in_file(self.file, msg)
        })
    }

    fn u32(&mut self, what: &str) -> Result<u32> {
        let mut b = [0u8; 4];
        self.read(&mut b, what)?;
        Ok(u32::from_le_bytes(b))
    }

    fn u64(&mut self, what: &str) -> Result<u64> {
        let mut b = [0u8; 8];
        self.read(&mut b, what)?;
        Ok(u64::from_le_bytes(b))
    }

    /// `n` floats (single or double precision) as f32, read in chunks.
    fn floats(&mut self, n: usize, double: bool, what: &str) -> Result<Vec<f32>> {
        let size = if double { 8 } else { 4 };
        let mut out = Vec::with_capacity(n.min(CHUNK));
        let mut buf = vec![0u8; n.min(CHUNK) * size];
        let mut left = n;
        while left > 0 {
            let k = left.min(CHUNK);
            let chunk = &mut buf[..k * size];
            self.read(chunk, what)?;
            if double {
                out.extend(
                    chunk
                        .chunks_exact(8)
                        .map(|c| f64::from_le_bytes([c[0], c[1], c[2], c[3], c[4], c[5], c[6], c[7]]) as f32),
                );
            } else {
                out.extend(chunk.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])));
            }
            left -= k;
        }
        Ok(out)
    }

    fn indices(&mut self, n: usize) -> Result<Vec<[u32; 3]>> {
        let mut out = Vec::with_capacity(n.min(CHUNK));
        let mut buf = vec![0u8; n.min(CHUNK) * 12];
        let mut left = n;
        while left > 0 {
            let k = left.min(CHUNK);
            let chunk = &mut buf[..k * 12];
            self.read(chunk, "triangles")?;
            out.extend(chunk.chunks_exact(12).map(|c| {
                let i = |o: usize| u32::from_le_bytes([c[o], c[o + 1], c[o + 2], c[o + 3]]);
                [i(0), i(4), i(8)]
            }));
            left -= k;
        }
        Ok(out)
    }

    fn mesh(&mut self, version: u16) -> Result<MeshData> {
        let flags = self.u32("flags")?;
        if version == 4 {
            // The shape's name, NUL-terminated (unused).
            let mut b = [0u8; 1];
            for len in 0.. {
                if len > MAX_NAME {
                    let msg =
                        format!("the name of mesh {} is longer than {MAX_NAME} bytes (corrupt file?)", self.shape);
                    return Err(Error::in_file(self.file, msg));
                }
                self.read(&mut b, "the shape name")?;
                if b[0] == 0 {
                    break;
                }
            }
        }
        let vertex_count = self.u64("the vertex count")?;
        let triangle_count = self.u64("the triangle count")?;
        let too_many = |n: u64, what: &str| {
            Error::in_file(self.file, format!("mesh {} declares {n} {what}, more than 2^32 - 1", self.shape))
        };
        let nv = u32::try_from(vertex_count).map_err(|_| too_many(vertex_count, "vertices"))? as usize;
        let nt = u32::try_from(triangle_count).map_err(|_| too_many(triangle_count, "triangles"))? as usize;
        // Refuse what cannot fit in memory, when the compressed data left (zlib expands at most
        // 1032:1) can hold the declared counts; otherwise reading reports the truncation.
        let declared = (nv as u64 + nt as u64) * 12;
        if declared / 1032 <= self.z.get_ref().len() as u64 {
            let what = format!("mesh {} ({nv} vertices, {nt} triangles)", self.shape);
            let needed = crate::scene::limits::mesh_bytes(nv as u64, nt as u64);
            crate::scene::limits::check(needed, &what, &SrcPos::file_only(self.file))?;
        }
        let double = flags & DOUBLE_PRECISION != 0;

        let p = self.floats(3 * nv, double, "vertex positions")?;
        let mut mesh = MeshData {
            positions: p.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect(),
            ..MeshData::default()
        };
        if flags & HAS_NORMALS != 0 {
            let n = self.floats(3 * nv, double, "vertex normals")?;
            mesh.normals = n.chunks_exact(3).map(|c| normalize_normal(Vec3::new(c[0], c[1], c[2]))).collect();
        }
        if flags & HAS_TEXCOORDS != 0 {
            let uv = self.floats(2 * nv, double, "texture coordinates")?;
            mesh.uvs = uv.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect();
        }
        if flags & HAS_COLORS != 0 {
            // Mitsuba 3 reads and discards vertex colours.
            let mut left = 3 * nv;
            while left > 0 {
                let k = left.min(CHUNK);
                self.floats(k, double, "vertex colors")?;
                left -= k;
            }
        }
        mesh.indices = self.indices(nt)?;
        Ok(mesh)
    }
}

/// The `serialized` shape's own parameter: `shape_index` (default 0).
pub fn from_props(props: &crate::scene::desc::Props, path: &Path) -> Result<MeshData> {
    let index = props.int("shape_index", 0)?;
    if index < 0 || index > u32::MAX as i64 {
        return Err(props.error("shape_index", "shape_index must be non-negative"));
    }
    load_serialized(path, index as u32)
}

//! PLY (Stanford triangle format) mesh loader: `ascii`, `binary_little_endian` and
//! `binary_big_endian` bodies.
//!
//! ```xml
//! <shape type="ply">
//!     <string name="filename" value="bunny.ply"/>
//!     <!-- optional: v ↦ 1 − v on the texture coordinates (default false for PLY) -->
//!     <boolean name="flip_tex_coords" value="false"/>
//! </shape>
//! ```
//!
//! What is read, following Mitsuba 3.9 (`src/shapes/ply.cpp`, `ply.h`):
//! - header: `ply`, `format <ascii|binary_little_endian|binary_big_endian> 1.0`, `comment`,
//!   `element <name> <count>`, `property <type> <name>`, `property list <count type> <item type>
//!   <name>`, `end_header`. Types: `char uchar short ushort int uint float double` and Mitsuba's
//!   extensions `int8 uint8 int16 uint16 int32 uint32 long ulong half float16 float32 float64`.
//!   `obj_info` lines are accepted as comments (Mitsuba rejects them);
//! - `vertex`: `x y z` (required), `nx ny nz` (all three, else ignored), texture coordinates from
//!   `u v`, else `texture_u texture_v`, else `s t` (Mitsuba ignores `texture_s texture_t`). These
//!   must be `half`, `float` or `double` (Mitsuba silently normalises some integer types, which is
//!   never what a position means). Any other vertex property is skipped;
//! - `face`: the list `vertex_index`, else `vertex_indices`, with any integer count and index
//!   type; other face properties are skipped. Polygons are triangulated as a fan
//!   `(0, k, k+1)` like Mitsuba's OBJ loader (Mitsuba's PLY loader rejects non-triangles);
//! - any other element is skipped, list properties included;
//! - content after the last element is an error, as in Mitsuba.
//!
//! Non-finite positions are errors, as in Mitsuba; unlike Mitsuba, so are face indices out of
//! range and zero or non-finite normals (rather than a silently broken mesh). Errors in ascii files carry `file:line:col`; errors in
//! binary bodies give the byte offset.
//!
//! Speed: the whole file is read into memory and decoded by one monomorphised loop per body
//! encoding; a 1M-triangle binary file loads in well under a second (`examples/bench_ply_load.rs`).

use std::path::Path;

mod body;
mod header;

use super::mesh_data::MeshData;
use crate::scene::error::{Error, Result, SrcPos};
use body::{decode, Ascii, Binary, Plan};
use header::{parse_header, Format};

/// Load a PLY file with Mitsuba's default `flip_tex_coords = false`; the result is validated.
pub fn load_ply(path: &Path) -> Result<MeshData> {
    load_ply_with(path, false)
}

/// Load a PLY file; `flip_tex_coords` maps `v ↦ 1 − v` as Mitsuba's parameter does.
pub fn load_ply_with(path: &Path, flip_tex_coords: bool) -> Result<MeshData> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|e| Error::in_file(&file, format!("cannot read PLY file: {e}")))?;
    load_ply_from_bytes(&bytes, &file, flip_tex_coords)
}

/// Decode a PLY file held in memory; `file` names it in errors. The result is validated.
pub fn load_ply_from_bytes(bytes: &[u8], file: &str, flip_tex_coords: bool) -> Result<MeshData> {
    let header = parse_header(bytes, file)?;
    let plan = Plan::new(&header, file)?;
    // Refuse declared counts that cannot fit in memory (faces counted as one triangle each),
    // when the body can hold them (at least a byte per value); otherwise decoding reports the truncation.
    let declared = |name: &str| header.elements.iter().find(|e| e.name == name).map(|e| (e.count, e.line));
    let min_body =
        header.elements.iter().map(|e| e.count.saturating_mul(e.props.len() as u64)).fold(0, u64::saturating_add);
    if let (Some((vertices, line)), true) = (declared("vertex"), min_body <= bytes.len() as u64) {
        let faces = declared("face").map_or(0, |f| f.0);
        let what = format!("element vertex {vertices} (with {faces} faces)");
        let needed = crate::scene::limits::mesh_bytes(vertices, faces);
        crate::scene::limits::check(needed, &what, &SrcPos::new(file, line, 1))?;
    }
    let body = bytes.get(header.body_start..).unwrap_or(&[]);
    let mut mesh = match header.format {
        Format::Ascii => {
            let mut r = Ascii::new(body, header.body_line);
            decode(&mut r, &header, &plan, file)?
        }
        Format::BinaryLe | Format::BinaryBe => {
            let mut r =
                Binary { bytes: body, pos: 0, base: header.body_start, big_endian: header.format == Format::BinaryBe };
            decode(&mut r, &header, &plan, file)?
        }
    };
    if flip_tex_coords {
        for uv in &mut mesh.uvs {
            uv.y = 1.0 - uv.y;
        }
    }
    mesh.validate(file)?;
    Ok(mesh)
}

/// The `ply` shape's own parameter: `flip_tex_coords` (default false, as Mitsuba).
pub fn from_props(props: &crate::scene::desc::Props, path: &Path) -> Result<MeshData> {
    load_ply_with(path, props.bool("flip_tex_coords", false)?)
}

#[cfg(test)]
mod tests {
    use super::body::*;
    use super::*;

    #[test]
    fn half_conversions() {
        assert_eq!(f16_to_f32(0x3c00), 1.0);
        assert_eq!(f16_to_f32(0xc000), -2.0);
        assert_eq!(f16_to_f32(0x0001), 2f32.powi(-24));
        assert_eq!(f16_to_f32(0x7bff), 65504.0);
        assert_eq!(f16_to_f32(0x7c00), f32::INFINITY);
        assert!(f16_to_f32(0x7e00).is_nan());
        assert_eq!(round_to_f16(1.0), 1.0);
        // 1 + 2^-11 is halfway between 1 and 1 + 2^-10: ties to even gives 1.
        assert_eq!(round_to_f16(1.0 + 2f32.powi(-11)), 1.0);
        assert_eq!(round_to_f16(1.0 + 3.0 * 2f32.powi(-11)), 1.0 + 2.0 * 2f32.powi(-10));
        assert_eq!(round_to_f16(0.1), f16_to_f32(0x2e66));
        assert_eq!(round_to_f16(-65519.0), -65504.0);
        assert_eq!(round_to_f16(65520.0), f32::INFINITY);
        assert_eq!(round_to_f16(3e-8), 2f32.powi(-24));
    }

    #[test]
    fn header_errors_carry_line_and_column() {
        let e = load_ply_from_bytes(b"ply\nformat ascii 1.0\nelement vertex x\n", "a.ply", false).unwrap_err();
        assert_eq!(e.to_string(), "a.ply:3:16: invalid PLY header: bad element count \"x\"");
        let e = load_ply_from_bytes(b"ply\nformat ascii 2.0\n", "a.ply", false).unwrap_err();
        assert_eq!(e.to_string(), "a.ply:2:14: unsupported PLY version \"2.0\" (expected 1.0)");
    }

    #[test]
    fn quad_is_fan_triangulated() {
        let ply = b"ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
            element face 1\nproperty list uchar int vertex_indices\nend_header\n\
            0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n5 0 1 2 3 4\n";
        let m = load_ply_from_bytes(ply, "q.ply", false).unwrap();
        assert_eq!(m.indices, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
    }
}

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

use super::mesh_data::{normalize_normal, MeshData};
use crate::math::{Vec2, Vec3};
use crate::scene::error::{Error, Result, SrcPos};

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

// ---- Header ----

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    I64,
    U64,
    F16,
    F32,
    F64,
}

impl Scalar {
    /// Mitsuba's type table (`ply.h`, `parse_ply_header`).
    fn from_name(name: &str) -> Option<Scalar> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "long" => Scalar::I64,
            "ulong" => Scalar::U64,
            "half" | "float16" => Scalar::F16,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::I64 => "long",
            Scalar::U64 => "ulong",
            Scalar::F16 => "half",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 | Scalar::F16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    fn is_float(self) -> bool {
        matches!(self, Scalar::F16 | Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Copy, Debug)]
enum PropType {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

impl PropType {
    /// Fewest bytes a binary record of this property can take.
    fn min_size(self) -> usize {
        match self {
            PropType::Scalar(s) => s.size(),
            PropType::List { count, .. } => count.size(),
        }
    }
}

#[derive(Debug)]
struct Property {
    name: String,
    ty: PropType,
    line: u32,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
    line: u32,
}

impl Element {
    fn prop(&self, name: &str) -> Option<usize> {
        self.props.iter().position(|p| p.name == name)
    }
    fn min_record_size(&self) -> usize {
        self.props.iter().map(|p| p.ty.min_size()).sum()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Debug)]
struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the body.
    body_start: usize,
    /// Line number on which the body starts (for ascii errors).
    body_line: u32,
}

/// Whitespace-separated tokens of a header line with their 1-based columns.
fn tokens(line: &str) -> impl Iterator<Item = (u32, &str)> {
    line.split(|c: char| c.is_ascii_whitespace())
        .scan(0usize, |offset, tok| {
            let col = *offset;
            *offset += tok.len() + 1;
            Some((col as u32 + 1, tok))
        })
        .filter(|(_, t)| !t.is_empty())
}

fn parse_header(bytes: &[u8], file: &str) -> Result<Header> {
    let mut pos = 0usize;
    let mut line_no = 0u32;
    let mut seen_ply = false;
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        line_no += 1;
        let err = |col: u32, msg: String| Error::at(&SrcPos::new(file, line_no, col), msg);
        let rest = bytes.get(pos..).unwrap_or(&[]);
        let Some(len) = rest.iter().position(|&b| b == b'\n') else {
            let what = if seen_ply { "header ends without \"end_header\"" } else { "not a PLY file" };
            return Err(err(1, format!("invalid PLY header: {what}")));
        };
        let raw = &rest[..len];
        pos += len + 1;
        let Ok(line) = std::str::from_utf8(raw) else {
            let what = if seen_ply { "header line is not text" } else { "not a PLY file" };
            return Err(err(1, format!("invalid PLY header: {what}")));
        };
        let mut toks = tokens(line);
        let Some((col, keyword)) = toks.next() else { continue };
        let excess = |toks: &mut dyn Iterator<Item = (u32, &str)>, after: &str| match toks.next() {
            Some((c, t)) => Err(err(c, format!("invalid PLY header: excess token \"{t}\" after \"{after}\""))),
            None => Ok(()),
        };
        match keyword {
            "comment" | "obj_info" => {}
            "ply" => {
                if seen_ply {
                    return Err(err(col, "invalid PLY header: duplicate \"ply\" tag".into()));
                }
                seen_ply = true;
                excess(&mut toks, "ply")?;
            }
            _ if !seen_ply => {
                return Err(err(col, "not a PLY file (the first line must be \"ply\")".into()));
            }
            "format" => {
                if format.is_some() {
                    return Err(err(col, "invalid PLY header: duplicate \"format\" line".into()));
                }
                let Some((c, f)) = toks.next() else {
                    return Err(err(col, "invalid PLY header: missing encoding after \"format\"".into()));
                };
                format = Some(match f {
                    "ascii" => Format::Ascii,
                    "binary_little_endian" => Format::BinaryLe,
                    "binary_big_endian" => Format::BinaryBe,
                    _ => {
                        return Err(err(
                            c,
                            format!(
                                "invalid PLY header: unknown format \"{f}\" (expected ascii, \
                                 binary_little_endian or binary_big_endian)"
                            ),
                        ))
                    }
                });
                match toks.next() {
                    Some((_, "1.0")) => {}
                    Some((c, v)) => return Err(err(c, format!("unsupported PLY version \"{v}\" (expected 1.0)"))),
                    None => return Err(err(col, "invalid PLY header: missing version after \"format\"".into())),
                }
                excess(&mut toks, "format")?;
            }
            "element" => {
                let (Some((_, name)), Some((c, count))) = (toks.next(), toks.next()) else {
                    return Err(err(col, "invalid PLY header: expected \"element <name> <count>\"".into()));
                };
                let Ok(count) = count.parse::<u64>() else {
                    return Err(err(c, format!("invalid PLY header: bad element count \"{count}\"")));
                };
                if (name == "vertex" || name == "face") && elements.iter().any(|e| e.name == name) {
                    return Err(err(col, format!("invalid PLY header: duplicate element \"{name}\"")));
                }
                if name == "vertex" && count > u64::from(u32::MAX) {
                    return Err(err(c, format!("{count} vertices are more than 32-bit indices can address")));
                }
                elements.push(Element { name: name.to_string(), count, props: Vec::new(), line: line_no });
            }
            "property" => {
                if format.is_none() {
                    return Err(err(col, "invalid PLY header: \"property\" before \"format\"".into()));
                }
                let Some(element) = elements.last_mut() else {
                    return Err(err(col, "invalid PLY header: \"property\" before any \"element\"".into()));
                };
                let scalar = |tok: Option<(u32, &str)>| match tok {
                    Some((c, t)) => {
                        Scalar::from_name(t).ok_or_else(|| err(c, format!("invalid PLY header: unknown type \"{t}\"")))
                    }
                    None => Err(err(col, "invalid PLY header: incomplete \"property\" line".into())),
                };
                let first = toks.next();
                let ty = if matches!(first, Some((_, "list"))) {
                    let count = scalar(toks.next())?;
                    let item = scalar(toks.next())?;
                    PropType::List { count, item }
                } else {
                    PropType::Scalar(scalar(first)?)
                };
                let Some((c, name)) = toks.next() else {
                    return Err(err(col, "invalid PLY header: missing property name".into()));
                };
                if element.prop(name).is_some() {
                    return Err(err(
                        c,
                        format!("invalid PLY header: duplicate property \"{name}\" in element \"{}\"", element.name),
                    ));
                }
                element.props.push(Property { name: name.to_string(), ty, line: line_no });
                excess(&mut toks, "property")?;
            }
            "end_header" => {
                excess(&mut toks, "end_header")?;
                let Some(format) = format else {
                    return Err(err(col, "invalid PLY header: no \"format\" line".into()));
                };
                return Ok(Header { format, elements, body_start: pos, body_line: line_no + 1 });
            }
            _ => return Err(err(col, format!("invalid PLY header: unknown keyword \"{keyword}\""))),
        }
    }
}

// ---- What to do with each property ----

/// Destination of a vertex property: slots x, y, z, nx, ny, nz, u, v.
const SLOT_COUNT: usize = 8;

struct Plan {
    /// Per vertex property: the slot it fills, if any.
    vertex_slots: Vec<Option<usize>>,
    has_normals: bool,
    has_uvs: bool,
    /// Index of the face's vertex index list.
    face_indices: Option<usize>,
    vertex_count: u64,
}

impl Plan {
    fn new(header: &Header, file: &str) -> Result<Plan> {
        let mut plan =
            Plan { vertex_slots: Vec::new(), has_normals: false, has_uvs: false, face_indices: None, vertex_count: 0 };
        for el in &header.elements {
            let at = |line: u32, msg: String| Error::at(&SrcPos::new(file, line, 1), msg);
            match el.name.as_str() {
                "vertex" => {
                    plan.vertex_count = el.count;
                    plan.vertex_slots = vec![None; el.props.len()];
                    let mut assign = |names: &[&str], first_slot: usize| -> Result<bool> {
                        let found: Vec<Option<usize>> = names.iter().map(|n| el.prop(n)).collect();
                        if found.iter().any(Option::is_none) {
                            return Ok(false);
                        }
                        for (k, i) in found.into_iter().flatten().enumerate() {
                            let p = &el.props[i];
                            match p.ty {
                                PropType::Scalar(s) if s.is_float() => plan.vertex_slots[i] = Some(first_slot + k),
                                PropType::Scalar(s) => {
                                    return Err(at(
                                        p.line,
                                        format!(
                                            "vertex property \"{}\" has integer type \"{}\"; use float or double",
                                            p.name,
                                            s.name()
                                        ),
                                    ))
                                }
                                PropType::List { .. } => {
                                    return Err(at(
                                        p.line,
                                        format!("vertex property \"{}\" must not be a list", p.name),
                                    ))
                                }
                            }
                        }
                        Ok(true)
                    };
                    if !assign(&["x", "y", "z"], 0)? {
                        return Err(at(el.line, "element \"vertex\" lacks one of the properties x, y, z".into()));
                    }
                    let has_normals = assign(&["nx", "ny", "nz"], 3)?;
                    let has_uvs =
                        assign(&["u", "v"], 6)? || assign(&["texture_u", "texture_v"], 6)? || assign(&["s", "t"], 6)?;
                    plan.has_normals = has_normals;
                    plan.has_uvs = has_uvs;
                }
                "face" => {
                    let is_list = |i: &usize| matches!(el.props[*i].ty, PropType::List { .. });
                    let idx = el
                        .prop("vertex_index")
                        .filter(is_list)
                        .or_else(|| el.prop("vertex_indices").filter(is_list))
                        .ok_or_else(|| {
                            at(
                                el.line,
                                "element \"face\" has no list property \"vertex_indices\" or \"vertex_index\"".into(),
                            )
                        })?;
                    let p = &el.props[idx];
                    if let PropType::List { count, item } = p.ty {
                        if count.is_float() || item.is_float() {
                            return Err(at(
                                p.line,
                                format!("face list \"{}\" must have integer count and index types", p.name),
                            ));
                        }
                    }
                    plan.face_indices = Some(idx);
                }
                _ => {}
            }
        }
        Ok(plan)
    }
}

// ---- Body readers ----

/// A failed read of one value.
enum ReadErr {
    Eof,
    /// A token that does not parse as the type, or an integer out of the range we accept.
    Bad(String),
}

/// Reads values of a PLY body in order; one implementation per encoding.
trait Body {
    /// A float-typed value, rounded to `f32` as Mitsuba stores it.
    fn float(&mut self, ty: Scalar) -> std::result::Result<f32, ReadErr>;
    /// An integer-typed value (list counts, indices).
    fn int(&mut self, ty: Scalar) -> std::result::Result<i64, ReadErr>;
    /// Consume one value of any type.
    fn skip(&mut self, ty: Scalar) -> std::result::Result<(), ReadErr>;
    /// Bytes left in the body (bounds allocations by what the file can hold).
    fn remaining(&self) -> usize;
    /// Whether the body may be checked against fixed record sizes (binary).
    fn is_binary(&self) -> bool;
    /// Skip `n` bytes (binary only).
    fn skip_bytes(&mut self, n: usize) -> bool;
    /// `Some(description)` of content left after the last element.
    fn trailing(&mut self) -> Option<String>;
    /// An error at the current position.
    fn error(&self, file: &str, msg: String) -> Error;
}

struct Binary<'a> {
    bytes: &'a [u8],
    pos: usize,
    /// Offset of the body in the file, for messages.
    base: usize,
    big_endian: bool,
}

impl Binary<'_> {
    #[inline(always)]
    fn take<const N: usize>(&mut self) -> std::result::Result<[u8; N], ReadErr> {
        let end = self.pos.checked_add(N).ok_or(ReadErr::Eof)?;
        let src = self.bytes.get(self.pos..end).ok_or(ReadErr::Eof)?;
        let mut out = [0u8; N];
        out.copy_from_slice(src);
        self.pos = end;
        Ok(out)
    }
}

macro_rules! read_as {
    ($r:expr, $t:ty) => {{
        let b = $r.take::<{ std::mem::size_of::<$t>() }>()?;
        if $r.big_endian {
            <$t>::from_be_bytes(b)
        } else {
            <$t>::from_le_bytes(b)
        }
    }};
}

impl Body for Binary<'_> {
    #[inline(always)]
    fn float(&mut self, ty: Scalar) -> std::result::Result<f32, ReadErr> {
        Ok(match ty {
            Scalar::F32 => read_as!(self, f32),
            Scalar::F64 => read_as!(self, f64) as f32,
            Scalar::F16 => f16_to_f32(read_as!(self, u16)),
            _ => self.int(ty)? as f32,
        })
    }

    #[inline(always)]
    fn int(&mut self, ty: Scalar) -> std::result::Result<i64, ReadErr> {
        Ok(match ty {
            Scalar::I8 => i64::from(read_as!(self, i8)),
            Scalar::U8 => i64::from(read_as!(self, u8)),
            Scalar::I16 => i64::from(read_as!(self, i16)),
            Scalar::U16 => i64::from(read_as!(self, u16)),
            Scalar::I32 => i64::from(read_as!(self, i32)),
            Scalar::U32 => i64::from(read_as!(self, u32)),
            Scalar::I64 => read_as!(self, i64),
            Scalar::U64 => {
                let v = read_as!(self, u64);
                i64::try_from(v).map_err(|_| ReadErr::Bad(v.to_string()))?
            }
            Scalar::F16 | Scalar::F32 | Scalar::F64 => {
                return Err(ReadErr::Bad(format!("a {} value where an integer is needed", ty.name())))
            }
        })
    }

    #[inline(always)]
    fn skip(&mut self, ty: Scalar) -> std::result::Result<(), ReadErr> {
        if self.skip_bytes(ty.size()) {
            Ok(())
        } else {
            Err(ReadErr::Eof)
        }
    }

    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    fn is_binary(&self) -> bool {
        true
    }

    #[inline(always)]
    fn skip_bytes(&mut self, n: usize) -> bool {
        match self.pos.checked_add(n) {
            Some(end) if end <= self.bytes.len() => {
                self.pos = end;
                true
            }
            _ => false,
        }
    }

    fn trailing(&mut self) -> Option<String> {
        let n = self.remaining();
        (n > 0).then(|| format!("{n} bytes of trailing content after the last element"))
    }

    fn error(&self, file: &str, msg: String) -> Error {
        Error::in_file(file, format!("{msg} (byte offset {})", self.base + self.pos))
    }
}

struct Ascii<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: u32,
    line_start: usize,
    /// Position of the last token read (or of the end of file).
    tok_line: u32,
    tok_col: u32,
}

impl<'a> Ascii<'a> {
    fn new(bytes: &'a [u8], first_line: u32) -> Self {
        Ascii { bytes, pos: 0, line: first_line, line_start: 0, tok_line: first_line, tok_col: 1 }
    }

    #[inline]
    fn token(&mut self) -> std::result::Result<&'a str, ReadErr> {
        let bytes = self.bytes;
        while let Some(&b) = bytes.get(self.pos) {
            if b == b'\n' {
                self.line += 1;
                self.line_start = self.pos + 1;
            } else if !b.is_ascii_whitespace() {
                break;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while bytes.get(self.pos).is_some_and(|b| !b.is_ascii_whitespace()) {
            self.pos += 1;
        }
        self.tok_line = self.line;
        self.tok_col = (start - self.line_start + 1) as u32;
        if start == self.pos {
            return Err(ReadErr::Eof);
        }
        let tok = &bytes[start..self.pos];
        std::str::from_utf8(tok).map_err(|_| ReadErr::Bad(String::from_utf8_lossy(tok).into_owned()))
    }
}

impl Body for Ascii<'_> {
    fn float(&mut self, ty: Scalar) -> std::result::Result<f32, ReadErr> {
        let t = self.token()?;
        let bad = || ReadErr::Bad(t.to_string());
        match ty {
            Scalar::F32 => t.parse::<f32>().map_err(|_| bad()),
            Scalar::F64 => t.parse::<f64>().map(|v| v as f32).map_err(|_| bad()),
            Scalar::F16 => t.parse::<f32>().map(round_to_f16).map_err(|_| bad()),
            _ => Ok(parse_int(t, ty)? as f32),
        }
    }

    fn int(&mut self, ty: Scalar) -> std::result::Result<i64, ReadErr> {
        let t = self.token()?;
        parse_int(t, ty)
    }

    fn skip(&mut self, ty: Scalar) -> std::result::Result<(), ReadErr> {
        if ty.is_float() {
            self.float(ty).map(|_| ())
        } else {
            self.int(ty).map(|_| ())
        }
    }

    fn remaining(&self) -> usize {
        self.bytes.len().saturating_sub(self.pos)
    }

    fn is_binary(&self) -> bool {
        false
    }

    fn skip_bytes(&mut self, _n: usize) -> bool {
        false
    }

    fn trailing(&mut self) -> Option<String> {
        match self.token() {
            Ok(t) => Some(format!("trailing token \"{t}\" after the last element")),
            Err(ReadErr::Bad(t)) => Some(format!("trailing token \"{t}\" after the last element")),
            Err(ReadErr::Eof) => None,
        }
    }

    fn error(&self, file: &str, msg: String) -> Error {
        Error::at(&SrcPos::new(file, self.tok_line, self.tok_col), msg)
    }
}

/// An ascii integer of type `ty`, range-checked like Mitsuba's stream extraction.
fn parse_int(t: &str, ty: Scalar) -> std::result::Result<i64, ReadErr> {
    let bad = || ReadErr::Bad(t.to_string());
    let v = match ty {
        Scalar::U64 => t.parse::<u64>().ok().and_then(|v| i64::try_from(v).ok()),
        _ => t.parse::<i64>().ok(),
    }
    .ok_or_else(bad)?;
    let (lo, hi): (i64, i64) = match ty {
        Scalar::I8 => (i8::MIN.into(), i8::MAX.into()),
        Scalar::U8 => (0, u8::MAX.into()),
        Scalar::I16 => (i16::MIN.into(), i16::MAX.into()),
        Scalar::U16 => (0, u16::MAX.into()),
        Scalar::I32 => (i32::MIN.into(), i32::MAX.into()),
        Scalar::U32 => (0, u32::MAX.into()),
        Scalar::U64 => (0, i64::MAX),
        _ => (i64::MIN, i64::MAX),
    };
    if v < lo || v > hi {
        return Err(bad());
    }
    Ok(v)
}

/// IEEE half → f32 (exact).
fn f16_to_f32(h: u16) -> f32 {
    let sign = if h & 0x8000 != 0 { -1.0 } else { 1.0 };
    let exp = i32::from((h >> 10) & 0x1f);
    let man = f32::from(h & 0x3ff);
    match exp {
        0 => sign * man * (-24f32).exp2(),
        31 if man == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        _ => sign * (1.0 + man / 1024.0) * ((exp - 15) as f32).exp2(),
    }
}

/// Round an f32 to the nearest half-precision value (ties to even), as Mitsuba stores `half`.
fn round_to_f16(x: f32) -> f32 {
    if !x.is_finite() {
        return x;
    }
    let a = x.abs();
    if a >= 65520.0 {
        return x.signum() * f32::INFINITY;
    }
    // Spacing of half values around `a`: 2^-24 below 2^-14 (subnormals), else 2^(e - 10).
    let e = if a < 2f32.powi(-14) { -14 } else { ((a.to_bits() >> 23) as i32) - 127 };
    let quantum = ((e - 10) as f32).exp2();
    x.signum() * (a / quantum).round_ties_even() * quantum
}

// ---- Decoding ----

fn read_err<R: Body>(r: &R, file: &str, e: ReadErr, el: &Element, i: u64, prop: &Property) -> Error {
    let what = format!("{} {} of {} (property \"{}\")", el.name, i, el.count, prop.name);
    match e {
        ReadErr::Eof if r.is_binary() => r.error(file, format!("file is truncated: it ends inside {what}")),
        ReadErr::Eof => r.error(file, format!("unexpected end of file: expected {what}")),
        ReadErr::Bad(t) => r.error(file, format!("invalid value \"{t}\" for {what}")),
    }
}

fn decode<R: Body>(r: &mut R, header: &Header, plan: &Plan, file: &str) -> Result<MeshData> {
    let mut mesh = MeshData::default();
    for el in &header.elements {
        let min_size = el.min_record_size();
        // A binary body must hold at least `count` minimal records.
        if r.is_binary() {
            let need = el.count.checked_mul(min_size as u64);
            if need.is_none_or(|n| n > r.remaining() as u64) {
                let msg = format!(
                    "file is truncated: element \"{}\" needs at least {} bytes, but only {} remain",
                    el.name,
                    need.map_or_else(|| "more than 2^64".to_string(), |n| n.to_string()),
                    r.remaining()
                );
                return Err(r.error(file, msg));
            }
        }
        // Capacity bounded by what the rest of the file can hold (ascii: ≥ 2 bytes per value).
        let per_record = if r.is_binary() { min_size } else { 2 * el.props.len() };
        let cap = (el.count as usize).min(r.remaining() / per_record.max(1));
        match el.name.as_str() {
            "vertex" => read_vertices(r, el, plan, cap, file, &mut mesh)?,
            "face" => read_faces(r, el, plan, cap, file, &mut mesh)?,
            _ => skip_element(r, el, file)?,
        }
    }
    if let Some(msg) = r.trailing() {
        return Err(r.error(file, msg));
    }
    Ok(mesh)
}

fn skip_list<R: Body>(r: &mut R, count: Scalar, item: Scalar) -> std::result::Result<(), ReadErr> {
    let n = r.int(count)?;
    if n < 0 {
        return Err(ReadErr::Bad(format!("negative list length {n}")));
    }
    for _ in 0..n {
        r.skip(item)?;
    }
    Ok(())
}

fn skip_element<R: Body>(r: &mut R, el: &Element, file: &str) -> Result<()> {
    if el.props.is_empty() {
        // Records without properties take no space, however many the header declares.
        return Ok(());
    }
    let fixed = el.props.iter().all(|p| matches!(p.ty, PropType::Scalar(_)));
    if fixed && r.is_binary() {
        // Size was checked against the remaining bytes in `decode`.
        let n = el.count as usize * el.min_record_size();
        if r.skip_bytes(n) {
            return Ok(());
        }
    }
    for i in 0..el.count {
        for p in &el.props {
            let res = match p.ty {
                PropType::Scalar(s) => r.skip(s),
                PropType::List { count, item } => skip_list(r, count, item),
            };
            res.map_err(|e| read_err(r, file, e, el, i, p))?;
        }
    }
    Ok(())
}

fn read_vertices<R: Body>(
    r: &mut R,
    el: &Element,
    plan: &Plan,
    cap: usize,
    file: &str,
    mesh: &mut MeshData,
) -> Result<()> {
    mesh.positions.reserve_exact(cap);
    if plan.has_normals {
        mesh.normals.reserve_exact(cap);
    }
    if plan.has_uvs {
        mesh.uvs.reserve_exact(cap);
    }
    let mut v = [0f32; SLOT_COUNT];
    for i in 0..el.count {
        for (p, slot) in el.props.iter().zip(&plan.vertex_slots) {
            let res = match (p.ty, slot) {
                (PropType::Scalar(s), Some(k)) => r.float(s).map(|x| v[*k] = x),
                (PropType::Scalar(s), None) => r.skip(s),
                (PropType::List { count, item }, _) => skip_list(r, count, item),
            };
            res.map_err(|e| read_err(r, file, e, el, i, p))?;
        }
        // Checked here as well as in `validate`, so that ascii errors carry the line.
        let p = Vec3::new(v[0], v[1], v[2]);
        if !p.is_finite() {
            return Err(r.error(file, format!("vertex {i} has a non-finite position ({}, {}, {})", p.x, p.y, p.z)));
        }
        mesh.positions.push(p);
        if plan.has_normals {
            let n = Vec3::new(v[3], v[4], v[5]);
            if !n.is_finite() || n == Vec3::ZERO {
                let msg = format!("vertex {i} has a zero-length or non-finite normal ({}, {}, {})", n.x, n.y, n.z);
                return Err(r.error(file, msg));
            }
            mesh.normals.push(normalize_normal(n));
        }
        if plan.has_uvs {
            mesh.uvs.push(Vec2::new(v[6], v[7]));
        }
    }
    Ok(())
}

fn read_faces<R: Body>(
    r: &mut R,
    el: &Element,
    plan: &Plan,
    cap: usize,
    file: &str,
    mesh: &mut MeshData,
) -> Result<()> {
    let Some(list) = plan.face_indices else { return skip_element(r, el, file) };
    mesh.indices.reserve_exact(cap);
    let vertex_count = plan.vertex_count;
    for i in 0..el.count {
        for (k, p) in el.props.iter().enumerate() {
            match p.ty {
                PropType::List { count, item } if k == list => {
                    let n = r.int(count).map_err(|e| read_err(r, file, e, el, i, p))?;
                    if n < 3 {
                        let msg = format!("face {i} has {n} vertex indices; a face needs at least 3");
                        return Err(r.error(file, msg));
                    }
                    let index = |r: &mut R| -> Result<u32> {
                        let v = r.int(item).map_err(|e| read_err(r, file, e, el, i, p))?;
                        if v < 0 || v as u64 >= vertex_count {
                            let msg =
                                format!("face {i} references vertex {v}, but the file has {vertex_count} vertices");
                            return Err(r.error(file, msg));
                        }
                        Ok(v as u32)
                    };
                    // Fan triangulation (0, k, k + 1), as Mitsuba's OBJ loader does.
                    let first = index(r)?;
                    let mut prev = index(r)?;
                    for _ in 2..n {
                        let cur = index(r)?;
                        mesh.indices.push([first, prev, cur]);
                        prev = cur;
                    }
                }
                PropType::List { count, item } => {
                    skip_list(r, count, item).map_err(|e| read_err(r, file, e, el, i, p))?
                }
                PropType::Scalar(s) => r.skip(s).map_err(|e| read_err(r, file, e, el, i, p))?,
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
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

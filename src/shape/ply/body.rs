//! PLY body decoding: which property goes where (`Plan`), the ascii and binary readers (`Body`),
//! and the loops that read vertices and faces into a `MeshData`.

use super::header::*;
use crate::math::{Vec2, Vec3};
use crate::scene::error::{Error, Result, SrcPos};
use crate::shape::mesh_data::{normalize_normal, MeshData};

// ---- What to do with each property ----

/// Destination of a vertex property: slots x, y, z, nx, ny, nz, u, v.
pub(super) const SLOT_COUNT: usize = 8;

pub(super) struct Plan {
    /// Per vertex property: the slot it fills, if any.
    pub(super) vertex_slots: Vec<Option<usize>>,
    pub(super) has_normals: bool,
    pub(super) has_uvs: bool,
    /// Index of the face's vertex index list.
    pub(super) face_indices: Option<usize>,
    pub(super) vertex_count: u64,
}

impl Plan {
    pub(super) fn new(header: &Header, file: &str) -> Result<Plan> {
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
pub(super) enum ReadErr {
    Eof,
    /// A token that does not parse as the type, or an integer out of the range we accept.
    Bad(String),
}

/// Reads values of a PLY body in order; one implementation per encoding.
pub(super) trait Body {
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
    /// The unread bytes of a binary little-endian body (for fast paths), else `None`.
    fn little_endian_rest(&self) -> Option<&[u8]> {
        None
    }
}

pub(super) struct Binary<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) pos: usize,
    /// Offset of the body in the file, for messages.
    pub(super) base: usize,
    pub(super) big_endian: bool,
}

impl Binary<'_> {
    #[inline(always)]
    pub(super) fn take<const N: usize>(&mut self) -> std::result::Result<[u8; N], ReadErr> {
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

    fn little_endian_rest(&self) -> Option<&[u8]> {
        (!self.big_endian).then(|| self.bytes.get(self.pos..).unwrap_or(&[]))
    }
}

pub(super) struct Ascii<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) pos: usize,
    pub(super) line: u32,
    pub(super) line_start: usize,
    /// Position of the last token read (or of the end of file).
    pub(super) tok_line: u32,
    pub(super) tok_col: u32,
}

impl<'a> Ascii<'a> {
    pub(super) fn new(bytes: &'a [u8], first_line: u32) -> Self {
        Ascii { bytes, pos: 0, line: first_line, line_start: 0, tok_line: first_line, tok_col: 1 }
    }

    #[inline]
    pub(super) fn token(&mut self) -> std::result::Result<&'a str, ReadErr> {
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
pub(super) fn parse_int(t: &str, ty: Scalar) -> std::result::Result<i64, ReadErr> {
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
pub(super) fn f16_to_f32(h: u16) -> f32 {
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
pub(super) fn round_to_f16(x: f32) -> f32 {
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

pub(super) fn read_err<R: Body>(r: &R, file: &str, e: ReadErr, el: &Element, i: u64, prop: &Property) -> Error {
    let what = format!("{} {} of {} (property \"{}\")", el.name, i, el.count, prop.name);
    match e {
        ReadErr::Eof if r.is_binary() => r.error(file, format!("file is truncated: it ends inside {what}")),
        ReadErr::Eof => r.error(file, format!("unexpected end of file: expected {what}")),
        ReadErr::Bad(t) => r.error(file, format!("invalid value \"{t}\" for {what}")),
    }
}

pub(super) fn decode<R: Body>(r: &mut R, header: &Header, plan: &Plan, file: &str) -> Result<MeshData> {
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

pub(super) fn skip_list<R: Body>(r: &mut R, count: Scalar, item: Scalar) -> std::result::Result<(), ReadErr> {
    let n = r.int(count)?;
    if n < 0 {
        return Err(ReadErr::Bad(format!("negative list length {n}")));
    }
    for _ in 0..n {
        r.skip(item)?;
    }
    Ok(())
}

pub(super) fn skip_element<R: Body>(r: &mut R, el: &Element, file: &str) -> Result<()> {
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

pub(super) fn read_vertices<R: Body>(
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

pub(super) fn read_faces<R: Body>(
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
    let first = fast_triangles(r, el, list, vertex_count, mesh);
    for i in first..el.count {
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

/// Fast path of `read_faces` for the common binary layout: little-endian faces whose only property
/// is a `uchar` count and `int` / `uint` indices. Decodes the leading records that are triangles
/// with indices in range and returns how many; the generic loop reads the rest (and reports errors).
fn fast_triangles<R: Body>(r: &mut R, el: &Element, list: usize, vertex_count: u64, mesh: &mut MeshData) -> u64 {
    const RECORD: usize = 13;
    let signed = match el.props.as_slice() {
        [p] => match p.ty {
            PropType::List { count: Scalar::U8, item: Scalar::I32 } if list == 0 => true,
            PropType::List { count: Scalar::U8, item: Scalar::U32 } if list == 0 => false,
            _ => return 0,
        },
        _ => return 0,
    };
    let Some(bytes) = r.little_endian_rest() else { return 0 };
    // Largest valid index + 1 as a u32 comparison bound (signed indices stop at i32::MAX).
    let limit = vertex_count.min(if signed { 1 << 31 } else { 1 << 32 });
    let records = bytes.len().min(el.count as usize * RECORD) / RECORD;
    let start = mesh.indices.len();
    mesh.indices.extend(bytes[..records * RECORD].chunks_exact(RECORD).map_while(|c| {
        let v = |k: usize| u32::from_le_bytes([c[1 + 4 * k], c[2 + 4 * k], c[3 + 4 * k], c[4 + 4 * k]]);
        let t = [v(0), v(1), v(2)];
        (c[0] == 3 && t.iter().all(|&i| u64::from(i) < limit)).then_some(t)
    }));
    let done = mesh.indices.len() - start;
    r.skip_bytes(done * RECORD);
    done as u64
}

//! PLY header: the `ply` / `format` / `element` / `property` lines up to `end_header`, and the
//! scalar types (Mitsuba 3.9's names and its extensions).

use crate::scene::error::{Error, Result, SrcPos};

// ---- Header ----

/// A PLY scalar type.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Scalar {
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
    pub(super) fn from_name(name: &str) -> Option<Scalar> {
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

    pub(super) fn name(self) -> &'static str {
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

    pub(super) fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 | Scalar::F16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::I64 | Scalar::U64 | Scalar::F64 => 8,
        }
    }

    pub(super) fn is_float(self) -> bool {
        matches!(self, Scalar::F16 | Scalar::F32 | Scalar::F64)
    }
}

#[derive(Clone, Copy, Debug)]
pub(super) enum PropType {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

impl PropType {
    /// Fewest bytes a binary record of this property can take.
    pub(super) fn min_size(self) -> usize {
        match self {
            PropType::Scalar(s) => s.size(),
            PropType::List { count, .. } => count.size(),
        }
    }
}

#[derive(Debug)]
pub(super) struct Property {
    pub(super) name: String,
    pub(super) ty: PropType,
    pub(super) line: u32,
}

#[derive(Debug)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) count: u64,
    pub(super) props: Vec<Property>,
    pub(super) line: u32,
}

impl Element {
    pub(super) fn prop(&self, name: &str) -> Option<usize> {
        self.props.iter().position(|p| p.name == name)
    }
    pub(super) fn min_record_size(&self) -> usize {
        self.props.iter().map(|p| p.ty.min_size()).sum()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Format {
    Ascii,
    BinaryLe,
    BinaryBe,
}

#[derive(Debug)]
pub(super) struct Header {
    pub(super) format: Format,
    pub(super) elements: Vec<Element>,
    /// Byte offset of the body.
    pub(super) body_start: usize,
    /// Line number on which the body starts (for ascii errors).
    pub(super) body_line: u32,
}

/// Whitespace-separated tokens of a header line with their 1-based columns.
pub(super) fn tokens(line: &str) -> impl Iterator<Item = (u32, &str)> {
    line.split(|c: char| c.is_ascii_whitespace())
        .scan(0usize, |offset, tok| {
            let col = *offset;
            *offset += tok.len() + 1;
            Some((col as u32 + 1, tok))
        })
        .filter(|(_, t)| !t.is_empty())
}

pub(super) fn parse_header(bytes: &[u8], file: &str) -> Result<Header> {
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

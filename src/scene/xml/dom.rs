//! Stage 1 of parsing: XML text → a small element tree with source positions.
//!
//! Uses `quick-xml` for tokenising and adds what a scene parser needs on top of it: every
//! element and attribute knows its `file:line:col`, unclosed or extra elements are reported,
//! attribute values are unescaped leniently (like pugixml, which Mitsuba uses: unknown entities
//! stay as written) and their whitespace characters become spaces (pugixml's `wconv_attribute`).
//! Text, comments, CDATA, processing instructions and DOCTYPEs are ignored, as in Mitsuba.

use crate::scene::error::{Error, Result, SrcPos};
use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;
use std::sync::Arc;

/// Deepest element nesting accepted (deeper input is rejected rather than risking the stack).
pub const MAX_DEPTH: usize = 256;

/// One attribute: `name="value"` (value unescaped, not yet `$param`-substituted).
#[derive(Clone, Debug)]
pub struct Attr {
    pub name: String,
    pub value: String,
    /// Position of the attribute name.
    pub pos: SrcPos,
}

/// One element with its attributes and child elements.
#[derive(Clone, Debug)]
pub struct Element {
    pub name: String,
    pub attrs: Vec<Attr>,
    pub children: Vec<Element>,
    /// Position of the `<` that opens the element.
    pub pos: SrcPos,
}

impl Element {
    pub fn attr(&self, name: &str) -> Option<&Attr> {
        self.attrs.iter().find(|a| a.name == name)
    }
}

/// Maps byte offsets of one text to 1-based line and column (columns count characters).
pub struct LineIndex<'a> {
    text: &'a str,
    file: Arc<str>,
    line_starts: Vec<usize>,
}

impl<'a> LineIndex<'a> {
    pub fn new(text: &'a str, file: Arc<str>) -> LineIndex<'a> {
        let mut line_starts = vec![0];
        line_starts.extend(text.bytes().enumerate().filter(|(_, b)| *b == b'\n').map(|(i, _)| i + 1));
        LineIndex { text, file, line_starts }
    }

    /// The position of a byte offset (clamped to the text).
    pub fn pos(&self, offset: usize) -> SrcPos {
        let offset = offset.min(self.text.len());
        let line = self.line_starts.partition_point(|&s| s <= offset).max(1);
        let start = self.line_starts.get(line - 1).copied().unwrap_or(0);
        let col = self.text.get(start..offset).map_or(offset - start, |s| s.chars().count()) + 1;
        SrcPos { file: self.file.clone(), line: line as u32, col: col as u32 }
    }

    /// Byte offset of a sub-slice of the text (None when `part` does not point into it).
    fn offset_of(&self, part: &[u8]) -> Option<usize> {
        let base = self.text.as_ptr() as usize;
        let p = part.as_ptr() as usize;
        (p >= base && p + part.len() <= base + self.text.len()).then(|| p - base)
    }
}

/// Parse a whole document into its root element.
pub fn parse_document(text: &str, file: &Arc<str>) -> Result<Element> {
    let index = LineIndex::new(text, file.clone());
    // A UTF-8 byte order mark is skipped; offsets stay relative to the full text.
    let bom = if text.starts_with('\u{feff}') { '\u{feff}'.len_utf8() } else { 0 };
    let body = &text[bom..];
    let mut reader = Reader::from_str(body);
    reader.config_mut().check_end_names = true;
    reader.config_mut().trim_text(false);

    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        let before = bom + reader.buffer_position() as usize;
        let event = match reader.read_event() {
            Ok(ev) => ev,
            Err(e) => {
                let at = bom + reader.error_position() as usize;
                return Err(Error::at(&index.pos(at), format!("malformed XML: {e}")));
            }
        };
        match event {
            Event::Start(e) => {
                if stack.len() >= MAX_DEPTH {
                    return Err(Error::at(
                        &index.pos(before),
                        format!("elements are nested more than {MAX_DEPTH} levels deep"),
                    ));
                }
                let el = element(&index, &e, before)?;
                stack.push(el);
            }
            Event::Empty(e) => {
                let el = element(&index, &e, before)?;
                attach(&mut stack, &mut root, el)?;
            }
            Event::End(_) => {
                // quick-xml checks that the name matches the open element.
                match stack.pop() {
                    Some(el) => attach(&mut stack, &mut root, el)?,
                    None => {
                        return Err(Error::at(&index.pos(before), "malformed XML: closing tag without an opening tag"))
                    }
                }
            }
            Event::Eof => {
                if let Some(open) = stack.last() {
                    return Err(Error::at(
                        &open.pos,
                        format!("malformed XML: element <{}> is not closed (end of file reached)", open.name),
                    ));
                }
                break;
            }
            // Text, CDATA, comments, declarations, processing instructions, DOCTYPE and entity
            // references in text carry nothing for a scene (Mitsuba ignores them too).
            _ => {}
        }
    }
    root.ok_or_else(|| Error::at(&index.pos(0), "malformed XML: the document has no root element"))
}

fn attach(stack: &mut [Element], root: &mut Option<Element>, el: Element) -> Result<()> {
    if let Some(parent) = stack.last_mut() {
        parent.children.push(el);
        return Ok(());
    }
    match root {
        None => {
            *root = Some(el);
            Ok(())
        }
        Some(r) => Err(Error::at(
            &el.pos,
            format!("malformed XML: element <{}> after the end of the root element <{}>", el.name, r.name),
        )),
    }
}

/// Build an element (without children) from a start tag; `fallback` is the reader position
/// before the event, used if the tag's bytes do not point into the text.
fn element(index: &LineIndex, e: &BytesStart, fallback: usize) -> Result<Element> {
    let content: &[u8] = e;
    // The content starts right after '<'.
    let lt = index.offset_of(content).map_or(fallback, |o| o.saturating_sub(1));
    let pos = index.pos(lt);
    let name = String::from_utf8_lossy(e.name().as_ref()).into_owned();
    let mut attrs: Vec<Attr> = Vec::new();
    for a in e.attributes() {
        let a = a.map_err(|err| {
            use quick_xml::events::attributes::AttrError as E;
            let (rel, what) = match err {
                E::ExpectedEq(p) => (p, "attribute name not followed by '='".to_string()),
                E::ExpectedValue(p) => (p, "attribute without a value after '='".to_string()),
                E::UnquotedValue(p) => (p, "attribute value not in quotes".to_string()),
                E::ExpectedQuote(p, _) => (p, "attribute value without its closing quote".to_string()),
                E::Duplicated(p, prev) => {
                    (p, format!("duplicated attribute (first given at {})", index.pos(lt + 1 + prev)))
                }
            };
            Error::at(&index.pos(lt + 1 + rel), format!("malformed XML: {what} in <{name}>"))
        })?;
        let key = a.key.as_ref();
        let apos = index.offset_of(key).map_or_else(|| pos.clone(), |o| index.pos(o));
        let raw = String::from_utf8_lossy(&a.value);
        attrs.push(Attr {
            name: String::from_utf8_lossy(key).into_owned(),
            value: normalize_whitespace(&unescape_lenient(&raw)),
            pos: apos,
        });
    }
    Ok(Element { name, attrs, children: Vec::new(), pos })
}

/// Replace the predefined entities and character references; leave anything else as written.
pub fn unescape_lenient(s: &str) -> String {
    if !s.contains('&') {
        return s.to_string();
    }
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(i) = rest.find('&') {
        out.push_str(&rest[..i]);
        let tail = &rest[i..];
        let replaced = tail.find(';').and_then(|end| {
            let ent = &tail[1..end];
            let ch = match ent {
                "lt" => Some('<'),
                "gt" => Some('>'),
                "amp" => Some('&'),
                "apos" => Some('\''),
                "quot" => Some('"'),
                _ => {
                    let code = if let Some(hex) = ent.strip_prefix("#x") {
                        u32::from_str_radix(hex, 16).ok()
                    } else if let Some(dec) = ent.strip_prefix('#') {
                        dec.parse::<u32>().ok()
                    } else {
                        None
                    };
                    code.and_then(char::from_u32)
                }
            };
            ch.map(|c| (c, end + 1))
        });
        match replaced {
            Some((c, len)) => {
                out.push(c);
                rest = &tail[len..];
            }
            None => {
                out.push('&');
                rest = &tail[1..];
            }
        }
    }
    out.push_str(rest);
    out
}

/// Tabs, carriage returns and newlines in attribute values become spaces (as pugixml does).
fn normalize_whitespace(s: &str) -> String {
    s.replace(['\t', '\n', '\r'], " ")
}

/// Check that the attributes are among `allowed` and that `required` are present (Mitsuba's
/// `check_attributes`: unexpected attributes are reported first).
pub fn check_attrs(tag: &str, pos: &SrcPos, attrs: &[Attr], allowed: &[&str], required: &[&str]) -> Result<()> {
    for a in attrs {
        if !allowed.contains(&a.name.as_str()) {
            return Err(Error::at(
                &a.pos,
                format!("unexpected attribute \"{}\" in <{tag}> (allowed: {})", a.name, allowed.join(", ")),
            ));
        }
    }
    for r in required {
        if find(attrs, r).is_none() {
            return Err(Error::at(pos, format!("missing required attribute \"{r}\" in <{tag}>")));
        }
    }
    Ok(())
}

pub fn find<'a>(attrs: &'a [Attr], name: &str) -> Option<&'a Attr> {
    attrs.iter().find(|a| a.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Element> {
        parse_document(text, &Arc::from("t.xml"))
    }

    #[test]
    fn positions_of_elements_and_attributes() {
        let root = parse("<a>\n  <b x=\"1\"  y='2'/>\n</a>").unwrap();
        let b = &root.children[0];
        assert_eq!((b.pos.line, b.pos.col), (2, 3));
        assert_eq!((b.attrs[1].pos.line, b.attrs[1].pos.col), (2, 13));
        assert_eq!(b.attrs[1].value, "2");
    }

    #[test]
    fn entities_and_whitespace() {
        let root = parse("<a v=\"x &amp; &foo; &#65;&#x42; &lt;\n\tz\"/>").unwrap();
        assert_eq!(root.attrs[0].value, "x & &foo; AB <  z");
    }

    #[test]
    fn structure_errors() {
        assert!(parse("<a><b></a>").is_err());
        assert!(parse("<a>").is_err());
        assert!(parse("").is_err());
        assert!(parse("<a/><b/>").is_err());
        assert!(parse("<a x=1/>").is_err());
        assert!(parse("<a x=\"1\" x=\"2\"/>").is_err());
        let deep = "<a>".repeat(MAX_DEPTH + 1);
        assert!(parse(&deep).is_err());
    }
}

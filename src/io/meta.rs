//! Text metadata in OpenEXR headers: snee stores a JSON description of how an image was made
//! (scene, seed, sample range, …; see `merge::PartMeta`) as the layer attribute `snee`, so a
//! partial render, a checkpoint or a merged image carries its own provenance and needs no sidecar.
//!
//! EXR text attributes are byte strings; values are written as ASCII with every other character
//! as a JSON `\uXXXX` escape (UTF-16 surrogate pairs beyond the BMP), which JSON parsers undo.

use anyhow::{anyhow, Context};
use std::path::Path;

/// `text` with every non-ASCII character replaced by its JSON escape (`é` → `\u00e9`). Meant for
/// JSON documents, where the escapes are valid inside strings (the only place such characters occur).
pub fn to_ascii(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        if c.is_ascii() {
            out.push(c);
        } else {
            let mut units = [0u16; 2];
            for u in c.encode_utf16(&mut units) {
                out.push_str(&format!("\\u{:04x}", u));
            }
        }
    }
    out
}

/// The text attribute `name` of the first layer (or the image) of the EXR file at `path`, reading
/// only the header. `Ok(None)` when the file has no such attribute; an error naming the file when
/// it is not a readable EXR.
pub fn read_exr_text_attribute(path: &Path, name: &str) -> anyhow::Result<Option<String>> {
    use exr::meta::attribute::AttributeValue;
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let meta = exr::meta::MetaData::read_from_buffered(std::io::Cursor::new(bytes), false)
        .map_err(|e| anyhow!("{}: cannot decode OpenEXR header: {e}", path.display()))?;
    let Some(header) = meta.headers.first() else {
        return Ok(None);
    };
    let found = header
        .own_attributes
        .other
        .iter()
        .chain(header.shared_attributes.other.iter())
        .find(|(k, _)| k.as_slice() == name.as_bytes());
    Ok(match found {
        Some((_, AttributeValue::Text(t))) => Some(t.as_slice().iter().map(|&b| b as char).collect()),
        _ => None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_escapes_round_trip_through_json() {
        let s = serde_json::json!({ "scene": "szène/🎥.xml" }).to_string();
        let a = to_ascii(&s);
        assert!(a.is_ascii());
        let back: serde_json::Value = serde_json::from_str(&a).unwrap();
        assert_eq!(back["scene"], "szène/🎥.xml");
    }

    #[test]
    fn attribute_round_trip() {
        let dir = std::env::temp_dir().join(format!("snee-meta-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.exr");
        crate::io::write::write_exr_with_attributes(&p, 2, 1, &["Y"], &[1.0, 2.0], &[("snee", "{\"x\":\"é\"}")])
            .unwrap();
        let text = read_exr_text_attribute(&p, "snee").unwrap().unwrap();
        assert_eq!(text, "{\"x\":\"\\u00e9\"}");
        assert_eq!(read_exr_text_attribute(&p, "other").unwrap(), None);
        let _ = std::fs::remove_dir_all(&dir);
    }
}

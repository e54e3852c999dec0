//! Scene files: the XML parser against Mitsuba 3.9 (`parse`), errors positioned at the offending
//! element or attribute (`errors`), plugin defaults and errors at scene build (`defaults`), and a
//! mutation fuzzer that must never panic (`fuzz`).

mod defaults;
mod errors;
mod fuzz;
mod parse;

use std::path::{Path, PathBuf};

/// `tests/data/xml`: scenes, includes and folders the tests parse.
pub fn data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/xml")
}

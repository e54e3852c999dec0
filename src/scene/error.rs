//! The one error type of scene loading: a message and, where known, the `file:line:col` it is about.

use std::fmt;
use std::sync::Arc;

/// A position in a source file (1-based line and column).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SrcPos {
    pub file: Arc<str>,
    pub line: u32,
    pub col: u32,
}

impl SrcPos {
    pub fn new(file: &str, line: u32, col: u32) -> SrcPos {
        SrcPos { file: Arc::from(file), line, col }
    }
    /// A position that names only a file (for mesh and image files).
    pub fn file_only(file: &str) -> SrcPos {
        SrcPos { file: Arc::from(file), line: 0, col: 0 }
    }
}

impl fmt::Display for SrcPos {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.line == 0 {
            write!(f, "{}", self.file)
        } else {
            write!(f, "{}:{}:{}", self.file, self.line, self.col)
        }
    }
}

/// A scene or input error. Displays as `file:line:col: message`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Error {
    pub pos: Option<SrcPos>,
    pub msg: String,
}

impl Error {
    pub fn at(pos: &SrcPos, msg: impl Into<String>) -> Error {
        Error { pos: Some(pos.clone()), msg: msg.into() }
    }
    pub fn msg(msg: impl Into<String>) -> Error {
        Error { pos: None, msg: msg.into() }
    }
    /// An error about a whole file (mesh, image, included scene).
    pub fn in_file(file: &str, msg: impl Into<String>) -> Error {
        Error { pos: Some(SrcPos::file_only(file)), msg: msg.into() }
    }
    /// Attach a position when the error has none yet.
    pub fn or_at(mut self, pos: &SrcPos) -> Error {
        if self.pos.is_none() {
            self.pos = Some(pos.clone());
        }
        self
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match &self.pos {
            Some(p) => write!(f, "{}: {}", p, self.msg),
            None => write!(f, "{}", self.msg),
        }
    }
}

impl std::error::Error for Error {}

pub type Result<T> = std::result::Result<T, Error>;

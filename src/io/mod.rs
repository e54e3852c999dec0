//! Image input and output: EXR (any compression in, float32 out), PNG preview, EXR header
//! metadata, and atomic file replacement for everything snee writes.

pub mod atomic;
pub mod meta;
pub mod read;
pub mod write;

//! Image input and output: EXR (any compression in, float32 out), PNG preview.

pub mod read;
pub mod write;

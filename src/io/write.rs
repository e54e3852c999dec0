//! Writing images: float32 EXR with optional extra channels, sRGB PNG previews.

//! Wavefront OBJ loader.

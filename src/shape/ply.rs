//! PLY loader (ascii and binary).

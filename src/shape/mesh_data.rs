//! Triangle mesh data as loaded from a file, before transformation.

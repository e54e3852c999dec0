//! Mesh files (PLY, OBJ, Mitsuba's serialized format): Mitsuba 3.9.1's own files and generated
//! ones in every encoding (`formats`), malformed files as positioned errors (`malformed`), and
//! mutation fuzzers that must never panic (`fuzz` for OBJ and serialized, `fuzz_ply`).

mod formats;
mod fuzz;
mod fuzz_ply;
mod malformed;

/// Fuzz cases per property test: `SNEE_FUZZ_CASES`, else `default`.
pub fn fuzz_cases(default: u32) -> u32 {
    std::env::var("SNEE_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

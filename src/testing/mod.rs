//! Statistical test helpers shared by unit and integration tests: chi-square over the sphere
//! ([`chi2`]) and Student-t tails for batch-based t-tests ([`student_t`]).

pub mod chi2;
pub mod student_t;

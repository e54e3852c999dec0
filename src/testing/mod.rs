//! Statistical test helpers shared by unit and integration tests (chi-square over the sphere).

pub mod chi2;

//! Participating media: Mitsuba's `homogeneous` medium and its phase functions.

pub mod homogeneous;
pub mod phase;

pub use homogeneous::Homogeneous;
pub use phase::Phase;

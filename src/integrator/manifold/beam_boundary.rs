//! Where beams apply for one medium (`manifold/beam.rs`): a leaf type, so that the integrator's
//! scene tables (`snee::options::Snee`) can hold it without importing the technique.

use crate::math::Vec3;

/// The bounding sphere of a medium's smooth dielectric boundary, the disk that beams' light
/// subpaths start from covers it (`beam::beam_boundaries`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BeamBoundary {
    pub center: Vec3,
    pub radius: f32,
}

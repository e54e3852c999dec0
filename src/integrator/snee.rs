//! Subdivision next-event estimation (Koerner et al. 2016): not implemented yet;
//! `render::check_renderable` refuses `volpath_snee`.

use super::stats::LocalStats;
use crate::color::Spectrum;
use crate::math::Ray;
use crate::sampler::Sampler;
use crate::scene::world::Scene;

pub fn li(
    _scene: &Scene,
    _sampler: &mut Sampler,
    _ray: Ray,
    _medium: Option<u32>,
    _stats: &mut LocalStats,
) -> (Spectrum, bool) {
    (Spectrum::ZERO, false)
}

//! MIS between SNEE and forward path tracing for a path suffix `x_i → x_j → x_k → emitter`
//! (docs/snee.md §3): one weight function, called with the same densities whichever technique
//! produced the path.

use super::light::{light_transmission, segment_clear};
use super::options::{Snee, SneeTechnique};
use super::pdf::{suffix_pdfs, SuffixPdfs};
use super::{LightSample, SneeSuffix};
use crate::color::Spectrum;
use crate::integrator::stats::LocalStats;
use crate::interaction::offset_origin;
use crate::scene::world::Scene;

/// MIS weights of the three techniques; they sum to 1 whenever some density is positive.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SuffixWeights {
    pub snee: f64,
    pub fwd_nee: f64,
    pub fwd_bsdf: f64,
}

/// Power heuristic over all techniques (`snee = mis`), SNEE alone where it can produce the
/// suffix (`snee = snee`), or forward alone (`snee = forward`, SNEE's density taken as 0).
pub fn suffix_weights(technique: SneeTechnique, p: SuffixPdfs) -> SuffixWeights {
    let snee = match technique {
        SneeTechnique::Forward => 0.0,
        _ => p.snee,
    };
    if technique == SneeTechnique::Snee && snee > 0.0 {
        return SuffixWeights { snee: 1.0, fwd_nee: 0.0, fwd_bsdf: 0.0 };
    }
    let (a, b, c) = (snee * snee, p.fwd_nee * p.fwd_nee, p.fwd_bsdf * p.fwd_bsdf);
    let sum = a + b + c;
    if !(sum > 0.0) || !sum.is_finite() {
        return SuffixWeights::default();
    }
    SuffixWeights { snee: a / sum, fwd_nee: b / sum, fwd_bsdf: c / sum }
}

/// Which forward technique produced a suffix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ForwardTechnique {
    /// Emitter sampling at a rough `x_k`.
    Nee,
    /// BSDF sampling at `x_k` (rough, or the smooth refraction) that hit the emitter.
    Bsdf,
}

/// The weight of a forward contribution through the suffix `s` towards `light`, or `None` when
/// SNEE cannot produce that path (then volpath's own weight applies). In `forward` mode the
/// caller's `w_volpath` is returned for paths in SNEE's support.
#[allow(clippy::too_many_arguments)]
pub fn forward_weight(
    scene: &Scene,
    snee: &Snee,
    s: &SneeSuffix,
    light: &LightSample,
    technique: ForwardTechnique,
    w_volpath: f32,
    channel: usize,
    stats: &mut LocalStats,
) -> Option<f32> {
    if light.omega_l.dot(s.si_k.n) <= 0.0 {
        return None;
    }
    // SNEE's support: x_k is the probe's first hit from x_i, the light segment is clear.
    let inner_k = offset_origin(s.si_k.p, s.si_k.n, s.x_i.p - s.si_k.p);
    if !segment_clear(scene, s.x_i.p, inner_k, stats)
        || light_transmission(scene, &s.si_k, light, stats) == Spectrum::ZERO
    {
        return None;
    }
    let pdfs = suffix_pdfs(scene, snee, s, light, channel);
    if !(pdfs.snee > 0.0) {
        return None;
    }
    if snee.options.technique == SneeTechnique::Forward {
        return Some(w_volpath);
    }
    let w = suffix_weights(snee.options.technique, pdfs);
    Some(match technique {
        ForwardTechnique::Nee => w.fwd_nee,
        ForwardTechnique::Bsdf => w.fwd_bsdf,
    } as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_partition_unity() {
        let p = SuffixPdfs { snee: 3.0, fwd_nee: 1.0, fwd_bsdf: 2.0 };
        let w = suffix_weights(SneeTechnique::Mis, p);
        assert!((w.snee + w.fwd_nee + w.fwd_bsdf - 1.0).abs() < 1e-12);
        assert!((w.snee - 9.0 / 14.0).abs() < 1e-12);
        let w = suffix_weights(SneeTechnique::Snee, p);
        assert_eq!(w, SuffixWeights { snee: 1.0, fwd_nee: 0.0, fwd_bsdf: 0.0 });
        let w = suffix_weights(SneeTechnique::Forward, p);
        assert!((w.fwd_nee - 0.2).abs() < 1e-12 && w.snee == 0.0);
    }
}

//! Subdivision next-event estimation (Koerner et al. 2016), the technique of `volpath_snee`
//! (`integrator/volpath_snee.rs`). The derivation, every density and its measure are in
//! `docs/snee.md`; the names here are the document's, and the files follow its sections:
//!
//! | file          | docs/snee.md | contents                                                         |
//! |---------------|--------------|------------------------------------------------------------------|
//! | `mod.rs`      | §0, §1       | the vertices and suffix records, the enclosing boundary          |
//! | `sample.rs`   | §2.1–2.4     | one SNEE sample at `x_i`: probe, emitter, `x_j` (↓ or ↑), throughput |
//! | `distance.rs` | §2.2         | transmittance / equiangular distance sampling on a ray           |
//! | `pdf.rs`      | §2.5, §3     | SNEE's density of a suffix, and forward tracing's               |
//! | `light.rs`    | §1           | the light segment `x_k → emitter` through passable surfaces      |
//! | `rate.rs`     | §5           | where SNEE runs and how often (tables built at scene load)       |
//! | `mis.rs`      | §3           | the MIS weights over all techniques, in one place               |
//! | `stage.rs`    | §3           | SNEE's per-path state, called from the volpath loop              |
//! | `options.rs`  | §4           | the options and the built tables ([`Snee`])                      |
//!
//! SNEE runs at every real scattering vertex `x_i` inside a homogeneous medium enclosed by a shape
//! with a `dielectric` or `roughdielectric` BSDF (whose `interior` is that medium, without exterior
//! medium), when the medium samples emitters: a probe ray finds a boundary vertex `x_k`, and the
//! segment `x_i x_k` is subdivided by a medium vertex `x_j` that connects to an emitter through
//! `x_k` (top-to-bottom from the emitter through the refraction, or bottom-to-top by phase
//! sampling, each with transmittance or equiangular distance sampling).

pub mod distance;
pub mod light;
pub mod mis;
pub mod options;
pub mod pdf;
pub mod rate;
pub mod sample;
pub mod stage;

pub use light::{light_along, passable};
pub use mis::{forward_weight, ForwardTechnique};
pub use options::{Snee, SneeOptions, SneeTechnique, SneeTransport};
pub use pdf::{pdf_snee, suffix_pdfs};
pub use rate::{auto_rate, medium_rates, snee_vertex, AUTO_RATE_SHARED};
pub use sample::sample;
pub use stage::SneeStage;

use crate::bsdf::Bsdf;
use crate::color::Spectrum;
use crate::interaction::{DirectionSample, SurfaceInteraction};
use crate::math::Vec3;
use crate::scene::world::Scene;
/// A SNEE vertex `x_i`: a real scatter where SNEE runs (docs/snee.md §0).
#[derive(Clone, Copy, Debug)]
pub struct SneeVertex {
    pub p: Vec3,
    /// Direction back to the previous vertex (phase functions' `wi`).
    pub wi: Vec3,
    pub medium: u32,
    /// Probability that SNEE runs at this vertex (`r`).
    pub rate: f32,
}

/// A forward path that reached an enclosing boundary `x_k` right after `x_i → x_j`.
#[derive(Clone, Copy, Debug)]
pub struct SneeSuffix {
    pub x_i: SneeVertex,
    pub x_j: Vec3,
    pub si_k: SurfaceInteraction,
}

/// The emitter end of a suffix, seen from `x_k`.
#[derive(Clone, Copy, Debug)]
pub struct LightSample {
    /// Unit direction from `x_k` to the emitter.
    pub omega_l: Vec3,
    /// The emitter point (for finite emitters; `dist` infinite otherwise).
    pub p: Vec3,
    pub dist: f32,
    /// `p_light(omega_l)`: solid angle density at `x_k` with selection (discrete 1/#emitters for delta emitters).
    pub p_light: f32,
    pub delta: bool,
    /// Emitted radiance (delta emitters: their strength); zero when only densities are needed.
    pub le: Spectrum,
}

impl LightSample {
    /// The record (densities only) of an emitter hit by forward tracing along `omega_l`: at `p`
    /// (for the environment: any point, `dist` infinite), with emitter-sampling density `p_light`.
    #[inline]
    pub fn hit(omega_l: Vec3, p: Vec3, dist: f32, p_light: f32) -> LightSample {
        LightSample { omega_l, p, dist, p_light, delta: false, le: Spectrum::ZERO }
    }

    /// The record (densities only) of an emitter sample `ds` of forward emitter sampling.
    #[inline]
    pub fn sampled(ds: &DirectionSample) -> LightSample {
        LightSample { omega_l: ds.d, p: ds.p, dist: ds.dist, p_light: ds.pdf, delta: ds.delta, le: Spectrum::ZERO }
    }
}

/// The enclosing interface at `x_k`.
#[derive(Clone, Copy, Debug)]
pub enum Boundary {
    Smooth { eta: f32 },
    Rough,
}

impl Boundary {
    #[inline]
    pub fn of(bsdf: &Bsdf) -> Option<Boundary> {
        match bsdf {
            Bsdf::Dielectric(d) => Some(Boundary::Smooth { eta: d.eta }),
            Bsdf::RoughDielectric(_) => Some(Boundary::Rough),
            _ => None,
        }
    }
}

/// Is `si` on a boundary that encloses `medium` (interior = medium, no exterior medium,
/// dielectric or roughdielectric), reached from the inside along `d`?
#[inline]
pub fn encloses(scene: &Scene, si: &SurfaceInteraction, medium: u32, d: Vec3) -> bool {
    let s = &scene.shapes[si.shape as usize];
    s.interior == Some(medium)
        && s.exterior.is_none()
        && d.dot(si.n) > 0.0
        && Boundary::of(&scene.bsdfs[s.bsdf as usize]).is_some()
}

/// `x_k` with its incident direction set to `omega_kj` (towards `x_j`).
#[inline]
pub fn with_wi(si_k: &SurfaceInteraction, omega_kj: Vec3) -> SurfaceInteraction {
    SurfaceInteraction { wi: si_k.to_local(omega_kj), ..*si_k }
}

//! Light transport through refractive boundaries, one test binary: subdivision NEE (`snee_*`:
//! slab against adding-doubling, agreement with `volpath`, degenerate inputs) and manifold NEE
//! (`manifold_*`: slabs against adding-doubling, oblique beams, options, agreement with `volpath`
//! for environment and finite lights).

#[path = "../common/mod.rs"]
mod common;

mod beams;
mod camera_beams;
mod glint;
mod manifold_chain;
mod manifold_curved;
mod manifold_curved_cone;
mod manifold_curved_finite;
mod manifold_curved_statue;
mod manifold_finite;
mod manifold_oblique;
mod manifold_options;
mod manifold_rough;
mod manifold_rough_curved;
mod manifold_rough_finite;
mod manifold_slab;
mod manifold_unbiased;
mod meter_glint;
mod snee_degenerate;
mod snee_slab;
mod snee_unbiased;
mod split_glints;

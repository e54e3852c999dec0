//! snee: a renderer for Mitsuba 3 scenes, specialised in translucent objects (a scattering medium
//! inside a refractive boundary), with Subdivision Next-Event Estimation (Koerner et al. 2016).
//!
//! Data flow: `scene.xml` → [`scene::xml`] (tree with positions) → [`scene::desc`] (typed properties)
//! → scene build (meshes, BVH, plugins) → render (tiles, film) → EXR.

// `!(x > 0.0)` is how this crate rejects NaN together with non-positive values: deliberate.
#![allow(clippy::neg_cmp_op_on_partial_ord)]

pub mod bsdf;
pub mod color;
pub mod compare;
pub mod emitter;
pub mod info;
pub mod integrator;
pub mod interaction;
pub mod io;
pub mod math;
pub mod medium;
pub mod merge;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod sensor;
pub mod shape;
#[doc(hidden)]
pub mod testing;
pub mod texture;

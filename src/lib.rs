//! snee: a renderer for Mitsuba 3 scenes, specialised in translucent objects (a scattering medium
//! inside a refractive boundary), with Subdivision Next-Event Estimation (Koerner et al. 2016).
//!
//! Data flow: `scene.xml` → [`scene::xml`] (tree with positions) → [`scene::desc`] (typed properties)
//! → [`scene::build`] (meshes, BVH, plugins) → [`render`] (tiles, film) → EXR.

pub mod color;
pub mod interaction;
pub mod math;
pub mod sampler;
pub mod scene;
pub mod texture;

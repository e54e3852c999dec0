//! What the volpath loop must remember for forward paths that the manifold connection could also
//! have made: the last medium vertex `x_j` (where the connection ran) and, after a refraction out
//! through a flat plane of its boundary, the pending suffix `x_j → x_k → …` until the path hits
//! the environment (through passable surfaces only, as the connection's light segment).

use super::flat::{Plane, SAME_NORMAL};
use super::MediumVertex;
use crate::bsdf::Bsdf;
use crate::interaction::SurfaceInteraction;
use crate::scene::world::Scene;

/// A forward path that left the medium at `x_k` right after the medium vertex `x_j`.
#[derive(Clone, Copy, Debug)]
pub struct Pending {
    pub x_j: MediumVertex,
    pub si_k: SurfaceInteraction,
    pub plane: Plane,
}

/// The loop's manifold state (one per camera path).
#[derive(Clone, Copy, Debug, Default)]
pub struct Tracker {
    /// The last medium vertex where the connection ran, until the next surface event.
    pub x_j: Option<MediumVertex>,
    /// The suffix the ray leaving the last surface carries (`ManifoldStage` moves it on).
    pub pending: Option<Pending>,
}

impl Pending {
    /// The record of a refraction out at `s` right after the medium vertex `x_j`, when `s` is on
    /// one of the flat planes of `x_j`'s boundary (`None` elsewhere).
    pub fn start(scene: &Scene, x_j: MediumVertex, s: &SurfaceInteraction) -> Option<Pending> {
        let shape = &scene.shapes[s.shape as usize];
        if shape.interior != Some(x_j.medium) || shape.exterior.is_some() {
            return None;
        }
        let Bsdf::Dielectric(d) = scene.bsdf(s) else { return None };
        let boundary = super::boundary_of(scene, x_j.medium)?;
        let plane = *boundary.planes.iter().find(|p| p.eta == d.eta && p.n.dot(s.n) > SAME_NORMAL)?;
        Some(Pending { x_j, si_k: *s, plane })
    }
}

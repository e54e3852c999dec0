//! What the volpath loop must remember for forward paths that the manifold connection could also
//! have made: the last medium vertex `x_j` (where the connection ran) and, after a refraction out
//! through a flat plane of its boundary, the pending suffix `x_j → x_k → …` until the path hits
//! the environment (through passable surfaces only, as the connection's light segment).

use super::flat::{Plane, SAME_NORMAL};
use super::MediumVertex;
use crate::bsdf::{flags, Bsdf};
use crate::interaction::SurfaceInteraction;
use crate::math::Vec3;
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
    pending: Option<Pending>,
}

impl Tracker {
    /// At a surface event (or escape): the suffix pending for an emitter found along this ray.
    #[inline]
    pub fn surface_event(&mut self) -> Option<Pending> {
        self.pending.take()
    }

    /// After BSDF sampling at `s` (outgoing world direction `wo`): start a pending suffix when
    /// this is the refraction out of `x_j`'s medium through one of its flat planes, carry
    /// `carried` across a passable null surface, otherwise forget. Always ends `x_j`.
    pub fn after_bsdf(
        &mut self,
        scene: &Scene,
        s: &SurfaceInteraction,
        sampled_type: u32,
        wo: Vec3,
        carried: Option<Pending>,
    ) {
        let x_j = self.x_j.take();
        let non_null = sampled_type & flags::NULL == 0;
        self.pending = if non_null && sampled_type & flags::TRANSMISSION != 0 && wo.dot(s.n) > 0.0 {
            x_j.and_then(|x_j| {
                let shape = &scene.shapes[s.shape as usize];
                if shape.interior != Some(x_j.medium) || shape.exterior.is_some() {
                    return None;
                }
                let Bsdf::Dielectric(d) = scene.bsdf(s) else { return None };
                let boundary = super::boundary_of(scene, x_j.medium)?;
                let plane = *boundary.planes.iter().find(|p| p.eta == d.eta && p.n.dot(s.n) > SAME_NORMAL)?;
                Some(Pending { x_j, si_k: *s, plane })
            })
        } else if !non_null && crate::integrator::snee::passable(scene, s) {
            carried
        } else {
            None
        };
    }
}

//! What emitter splitting at smooth dielectric vertices (`manifold/split.rs`, docs/manifold.md
//! §12) needs of the scene, decided once at load: the bounds of the area emitters that a split
//! lobe's ray is tested against before the BVH is queried, and whether an environment is hit by
//! every escaping ray. Plain data, so that the options (`snee::options::Snee`) can hold it
//! without depending on the scene; `split::tables` builds it.

use crate::math::{Aabb, Ray, Vec3};

/// The bound of one area emitter's shape.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightBound {
    /// A sphere: centre and squared (padded) radius.
    Sphere { center: Vec3, radius2: f32 },
    /// Any other shape: its (padded) axis-aligned box.
    Box(Aabb),
}

impl LightBound {
    /// Can `ray` (from `o` along unit `d`, `t > 0`) meet the bounded shape?
    #[inline]
    pub fn meets(&self, ray: &Ray) -> bool {
        match *self {
            LightBound::Sphere { center, radius2 } => {
                let oc = center - ray.o;
                let t_mid = oc.dot(ray.d);
                let miss2 = oc.length_squared() - t_mid * t_mid;
                // The far intersection lies ahead: `t_mid + sqrt(r² − miss²) > 0`.
                miss2 <= radius2 && (t_mid >= 0.0 || t_mid * t_mid <= radius2 - miss2)
            }
            LightBound::Box(b) => {
                let inv = ray.d.recip();
                let t0 = (b.min - ray.o) * inv;
                let t1 = (b.max - ray.o) * inv;
                let near = t0.min(t1).max_element().max(0.0);
                let far = t0.max(t1).min_element();
                // NaN (a zero direction component on a slab's plane) counts as a meeting.
                !(near > far)
            }
        }
    }
}

/// What splitting needs of the scene, built once at load (`split::tables`).
#[derive(Clone, Debug, PartialEq)]
pub struct SplitTables {
    /// The area emitters' bounds (ignored with an environment).
    pub lights: Vec<LightBound>,
    /// Is there an environment emitter (every escaping ray meets it)?
    pub environment: bool,
}

impl SplitTables {
    /// Can a ray meet an emitter that forward tracing hits (an area light or the environment)?
    #[inline]
    pub fn may_hit_emitter(&self, ray: &Ray) -> bool {
        self.environment || self.lights.iter().any(|b| b.meets(ray))
    }
}

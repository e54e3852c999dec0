//! The curved smooth boundary of a medium as the Newton solvers see it (`curved.rs`,
//! `curved_finite.rs`, `chain.rs`): whether the curved connection runs for a medium, the ray cast
//! of each Newton step ([`SceneLocate`]) and the closed-form patch of a boundary hit
//! ([`boundary_patch`]: a triangle with its vertex normals, or an analytic sphere).

use super::newton::{Locate, Patch, Surface};
use crate::bsdf::Bsdf;
use crate::interaction::SurfaceInteraction;
use crate::math::{DVec3, Ray, Vec3};
use crate::scene::world::Scene;
use crate::shape::Geometry;

/// Does the curved connection run for `medium`?
#[inline]
pub fn applies(scene: &Scene, medium: u32) -> bool {
    super::tables(scene).and_then(|t| t.curved.get(medium as usize).copied()).unwrap_or(false)
}

/// The scene as the Newton walk sees it: each step's ray cast from `x_j`, accepted when the first
/// hit is `medium`'s enclosing smooth dielectric, met from inside.
pub struct SceneLocate<'a> {
    pub scene: &'a Scene,
    pub medium: u32,
    pub rays: u64,
}

impl Locate for SceneLocate<'_> {
    fn locate(&mut self, o: DVec3, d: DVec3) -> Option<Patch> {
        self.rays += 1;
        let si = self.scene.ray_intersect(&Ray::new(o.as_vec3(), d.as_vec3().normalize()))?;
        boundary_patch(self.scene, &si, self.medium, d.as_vec3())
    }
}

/// The closed-form patch of the boundary hit `si` (reached from inside `medium` along `d`).
pub fn boundary_patch(scene: &Scene, si: &SurfaceInteraction, medium: u32, d: Vec3) -> Option<Patch> {
    let s = &scene.shapes[si.shape as usize];
    if s.interior != Some(medium) || s.exterior.is_some() || !(d.dot(si.n) > 0.0) {
        return None;
    }
    let Bsdf::Dielectric(b) = scene.bsdf(si) else { return None };
    let surface = match &s.geometry {
        Geometry::Mesh(mesh) => {
            let p = mesh.vertices(si.prim).map(|v| v.as_dvec3());
            let sign = if mesh.flip_normals { -1.0 } else { 1.0 };
            let n = if mesh.normals.is_empty() {
                [si.n.as_dvec3(); 3]
            } else {
                mesh.indices[si.prim as usize].map(|i| mesh.normals[i as usize].as_dvec3() * sign)
            };
            Surface::Triangle { p, n }
        }
        Geometry::Sphere(sp) => Surface::Sphere {
            center: sp.center.as_dvec3(),
            radius: sp.radius as f64,
            outward: if sp.flip_normals { -1.0 } else { 1.0 },
        },
        _ => return None,
    };
    Some(Patch { surface, eta: b.eta as f64 })
}

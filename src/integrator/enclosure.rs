//! Media whose emitter sampling can never contribute, decided once at scene load from the geometry.
//!
//! A shadow ray from a medium vertex walks through the medium to the emitter and stops at the first
//! surface that is not null-transmissive (`walk.rs`, `volpath::shadow_transmittance`). When the
//! medium is the inside of closed, outward-oriented `dielectric` / `roughdielectric` shapes and no
//! emitter or passable surface lies near it, that first surface always blocks: the estimate is
//! exactly 0 after exactly one distance sample (the segment to the first surface). The integrator
//! then skips the ray but draws the same samples, so images stay bit-identical.
//!
//! The test is conservative: a medium qualifies ([`emitters_unreachable`]) only when
//! - every shape with `interior` = the medium is a closed mesh (every edge shared by exactly two
//!   triangles in opposite directions, vertices welded by position) with positive signed volume, or
//!   a sphere, oriented outward (so the interior side is the enclosed volume), with a `dielectric`
//!   or `roughdielectric` BSDF and no area emitter;
//! - no shape has the medium as `exterior` (that would make it unbounded) and the camera is not in it;
//! - inside the bounding box of those shapes, every other shape is opaque (no null or
//!   transmission lobe, so a path cannot leave the enclosure while keeping the medium) and no emitter
//!   (area shape, point or spot position) lies there.

use crate::bsdf::{flags, Bsdf};
use crate::emitter::Emitter;
use crate::math::Aabb;
use crate::scene::world::{Scene, SceneEmitter};
use crate::shape::{Geometry, Mesh, Shape};
use std::collections::HashMap;

/// Per medium of `scene`: true when emitter sampling from inside it always returns exactly 0.
pub fn emitters_unreachable(scene: &Scene) -> Vec<bool> {
    (0..scene.media.len() as u32).map(|m| unreachable(scene, m)).collect()
}

fn unreachable(scene: &Scene, medium: u32) -> bool {
    if scene.sensor_medium == Some(medium) || scene.shapes.iter().any(|s| s.exterior == Some(medium)) {
        return false;
    }
    let mut region = Aabb::EMPTY;
    let mut any = false;
    for s in scene.shapes.iter().filter(|s| s.interior == Some(medium)) {
        let blocking = matches!(scene.bsdfs[s.bsdf as usize], Bsdf::Dielectric(_) | Bsdf::RoughDielectric(_));
        if !blocking || s.emitter.is_some() || !encloses_inside(s) {
            return false;
        }
        region = region.union(&s.bounds());
        any = true;
    }
    if !any {
        return false;
    }
    let opaque_lobes = flags::NULL
        | flags::DIFFUSE_TRANSMISSION
        | flags::GLOSSY_TRANSMISSION
        | flags::DELTA_TRANSMISSION
        | flags::DELTA_1D_TRANSMISSION;
    let others_ok = scene.shapes.iter().filter(|s| s.interior != Some(medium)).all(|s| {
        !overlaps(&region, &s.bounds())
            || (s.emitter.is_none() && scene.bsdfs[s.bsdf as usize].flags() & opaque_lobes == 0)
    });
    let emitters_ok = scene.emitters.iter().all(|e| match e {
        SceneEmitter::Area { shape, .. } => !overlaps(&region, &scene.shapes[*shape as usize].bounds()),
        SceneEmitter::Other(Emitter::Point(e)) => !overlaps(&region, &Aabb { min: e.p, max: e.p }),
        SceneEmitter::Other(Emitter::Spot(e)) => !overlaps(&region, &Aabb { min: e.p, max: e.p }),
        SceneEmitter::Other(_) => true,
    });
    others_ok && emitters_ok
}

/// Do the boxes share a point?
fn overlaps(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

/// Is `s` a closed surface whose interior side (opposite the normal) is the enclosed volume?
fn encloses_inside(s: &Shape) -> bool {
    match &s.geometry {
        Geometry::Sphere(sphere) => !sphere.flip_normals,
        Geometry::Mesh(mesh) => closed_signed_volume(mesh).is_some_and(|v| (v > 0.0) != mesh.flip_normals),
        Geometry::Disk(_) => false,
    }
}

/// The signed volume of `mesh` when it is closed (vertices welded by position; every edge used
/// once in each direction, no degenerate triangle), else `None`.
fn closed_signed_volume(mesh: &Mesh) -> Option<f64> {
    let mut weld: HashMap<[u32; 3], u32> = HashMap::with_capacity(mesh.positions.len());
    let ids: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let n = weld.len() as u32;
            *weld.entry(p.to_array().map(f32::to_bits)).or_insert(n)
        })
        .collect();
    // Undirected edge key · 2 + direction bit: a closed, consistently oriented mesh has each key
    // exactly twice, once per direction.
    let mut edges: Vec<u64> = Vec::with_capacity(mesh.indices.len() * 3);
    let mut volume = 0.0f64;
    for tri in &mesh.indices {
        let v = tri.map(|i| ids[i as usize]);
        if v[0] == v[1] || v[1] == v[2] || v[2] == v[0] {
            return None;
        }
        for k in 0..3 {
            let (a, b) = (v[k] as u64, v[(k + 1) % 3] as u64);
            edges.push((a.min(b) << 33) | (a.max(b) << 1) | (a < b) as u64);
        }
        let [p0, p1, p2] = tri.map(|i| mesh.positions[i as usize].as_dvec3());
        volume += p0.dot(p1.cross(p2)) / 6.0;
    }
    edges.sort_unstable();
    let paired = edges.chunks(2).all(|c| c.len() == 2 && c[0] >> 1 == c[1] >> 1 && c[0] & 1 == 0 && c[1] & 1 == 1);
    (paired && !edges.is_empty()).then_some(volume)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Mat4, Vec3};
    use crate::shape::mesh_data::MeshData;

    fn tetra(flip_winding: bool) -> Mesh {
        let positions = vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
        let mut indices = vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
        if flip_winding {
            indices.iter_mut().for_each(|t| t.swap(1, 2));
        }
        Mesh::new(MeshData { positions, indices, ..Default::default() }, &Mat4::IDENTITY, true, false)
    }

    #[test]
    fn closed_mesh_volume_and_orientation() {
        let v = closed_signed_volume(&tetra(false)).unwrap();
        assert!((v - 1.0 / 6.0).abs() < 1e-9, "{v}");
        assert!(closed_signed_volume(&tetra(true)).unwrap() < 0.0);
    }

    #[test]
    fn open_mesh_is_not_closed() {
        let mut m = tetra(false);
        m.indices.pop();
        assert!(closed_signed_volume(&m).is_none());
    }
}

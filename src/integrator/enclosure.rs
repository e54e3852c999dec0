//! Media whose emitter sampling can never contribute, decided once at scene load from the geometry
//! (and, [`surfaces_block_shadow_rays`], scenes where every surface ends a shadow ray, so its
//! transmittance needs one any-hit query).
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
use rayon::prelude::*;
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

/// True when no shape's BSDF lets a shadow ray through: none is `null`, `thindielectric` or `mask`
/// (the BSDFs whose `eval_null_transmission` can be non-zero) and none has a null lobe. Then a
/// shadow ray ends at the first surface it meets, so its transmittance needs only an any-hit query
/// (`volpath::shadow_transmittance`).
pub fn surfaces_block_shadow_rays(scene: &Scene) -> bool {
    scene.shapes.iter().all(|s| {
        let b = &scene.bsdfs[s.bsdf as usize];
        !matches!(b, Bsdf::Null | Bsdf::ThinDielectric(_) | Bsdf::Mask(_)) && b.flags() & flags::NULL == 0
    })
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

/// The signed volume of `mesh` when it is closed (every edge used once in each direction, no
/// triangle with two corners at one position), else `None`. Closed by vertex index is checked
/// first (linear time); only a mesh that is not is checked again with vertices welded by position.
fn closed_signed_volume(mesh: &Mesh) -> Option<f64> {
    let degenerate = mesh.indices.par_iter().any(|t| {
        let [a, b, c] = t.map(|i| mesh.positions[i as usize].to_array().map(f32::to_bits));
        a == b || b == c || c == a
    });
    if degenerate {
        return None;
    }
    if !closed_by_index(&mesh.indices, mesh.positions.len()) && !closed_welded(mesh) {
        return None;
    }
    // Summed in parallel (the order varies; only the sign is used).
    let volume = mesh
        .indices
        .par_iter()
        .map(|tri| {
            let [p0, p1, p2] = tri.map(|i| mesh.positions[i as usize].as_dvec3());
            p0.dot(p1.cross(p2)) / 6.0
        })
        .sum();
    Some(volume)
}

/// Is every edge of `indices` used exactly once in each direction? Directed edges are bucketed by
/// their smaller vertex (a counting sort), then each small bucket is sorted and paired (in parallel).
fn closed_by_index(indices: &[[u32; 3]], vertex_count: usize) -> bool {
    if indices.is_empty() {
        return false;
    }
    let edge = |t: &[u32; 3], k: usize| (t[k], t[(k + 1) % 3]);
    let mut start = vec![0u32; vertex_count + 1];
    for t in indices {
        for k in 0..3 {
            let (a, b) = edge(t, k);
            if a == b {
                return false;
            }
            start[a.min(b) as usize + 1] += 1;
        }
    }
    for v in 0..vertex_count {
        start[v + 1] += start[v];
    }
    // Per bucket: the larger vertex · 2 + direction bit.
    let mut fill = start.clone();
    let mut other = vec![0u64; 3 * indices.len()];
    for t in indices {
        for k in 0..3 {
            let (a, b) = edge(t, k);
            let slot = &mut fill[a.min(b) as usize];
            other[*slot as usize] = ((a.max(b) as u64) << 1) | (a < b) as u64;
            *slot += 1;
        }
    }
    let paired = |bucket: &[u64]| {
        bucket.chunks(2).all(|c| c.len() == 2 && c[0] >> 1 == c[1] >> 1 && c[0] & 1 == 0 && c[1] & 1 == 1)
    };
    start.par_windows(2).all(|w| {
        let bucket = &other[w[0] as usize..w[1] as usize];
        // Buckets are small (about the vertex valence): sort a copy on the stack.
        let mut small = [0u64; 16];
        if let Some(b) = small.get_mut(..bucket.len()) {
            b.copy_from_slice(bucket);
            insertion_sort(b);
            paired(b)
        } else {
            let mut b = bucket.to_vec();
            b.sort_unstable();
            paired(&b)
        }
    })
}

fn insertion_sort(v: &mut [u64]) {
    for i in 1..v.len() {
        let x = v[i];
        let mut j = i;
        while j > 0 && v[j - 1] > x {
            v[j] = v[j - 1];
            j -= 1;
        }
        v[j] = x;
    }
}

/// Closedness with vertices welded by position (for meshes that split vertices at seams).
fn closed_welded(mesh: &Mesh) -> bool {
    let mut weld: HashMap<[u32; 3], u32> = HashMap::with_capacity(mesh.positions.len());
    let ids: Vec<u32> = mesh
        .positions
        .iter()
        .map(|p| {
            let n = weld.len() as u32;
            *weld.entry(p.to_array().map(f32::to_bits)).or_insert(n)
        })
        .collect();
    let welded: Vec<[u32; 3]> = mesh.indices.iter().map(|tri| tri.map(|i| ids[i as usize])).collect();
    closed_by_index(&welded, weld.len())
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

    /// A seam (a vertex duplicated at the same position) is closed after welding only.
    #[test]
    fn split_vertex_is_welded() {
        let mut m = tetra(false);
        m.positions.push(m.positions[3]);
        m.indices[3][2] = 4;
        assert!(!closed_by_index(&m.indices, m.positions.len()));
        let v = closed_signed_volume(&m).unwrap();
        assert!((v - 1.0 / 6.0).abs() < 1e-9, "{v}");
        // A triangle with two corners at one position is degenerate.
        m.indices[0] = [3, 4, 1];
        assert!(closed_signed_volume(&m).is_none());
    }

    #[test]
    fn open_mesh_is_not_closed() {
        let mut m = tetra(false);
        m.indices.pop();
        assert!(closed_signed_volume(&m).is_none());
    }
}

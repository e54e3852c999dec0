//! Ray-tracing acceleration: an 8-wide BVH over every triangle of the scene ([`bvh8`], built by a
//! parallel binned-SAH builder, [`build`]), traversed nearest first with an AVX node test when the
//! CPU has AVX2 (run-time detection; SSE otherwise) ([`traverse`]), with leaves of four triangles tested at once by the watertight test of Woop,
//! Benthin & Wald 2013 ([`triangle`]). Analytic shapes (spheres, disks) stay out of the BVH and are
//! tested directly before it, in `f32`; scenes are expected to hold few of them.
//!
//! Watertightness: primitive boxes are padded, the node test is conservative (Ize 2013) and the
//! triangle test is watertight, so no ray slips through a shared edge or vertex of a closed mesh
//! (`tests/accel.rs` checks 1.4 M rays through a closed 1.3 M-triangle sphere).

pub mod build;
pub mod bvh8;
pub mod traverse;
pub mod triangle;

use super::{Geometry, Shape};
use crate::math::Ray;
use build::Bounds;
use bvh8::Bvh8;
use glam::{Vec3, Vec3A};
use rayon::prelude::*;
use std::mem::MaybeUninit;
use traverse::STACK;

/// Closest hit: shape, primitive, barycentrics of vertices 1 and 2, distance.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub shape: u32,
    pub prim: u32,
    pub b1: f32,
    pub b2: f32,
    pub t: f32,
}

/// Which node test the CPU runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// Two SSE halves (any x86-64 CPU, and other architectures through glam's fallback).
    Portable,
    /// One AVX register per plane, with BMI1 / LZCNT / POPCNT bit scans.
    Avx2,
}

impl Isa {
    /// The best the running CPU supports.
    pub fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("bmi1")
            && std::arch::is_x86_feature_detected!("lzcnt")
            && std::arch::is_x86_feature_detected!("popcnt")
        {
            return Isa::Avx2;
        }
        Isa::Portable
    }
}

pub struct Accel {
    bvh: Option<Bvh8>,
    /// Shapes tested outside the BVH (spheres, disks).
    analytic: Vec<Analytic>,
    isa: Isa,
    /// The tree is too deep for the fixed traversal stack (`traverse::STACK`): queries use a heap one.
    deep: bool,
}

/// A shape tested outside the BVH, with what its test needs copied out of the shape.
#[derive(Clone, Copy, Debug)]
enum Analytic {
    Sphere { shape: u32, center: Vec3, r2: f32 },
    Disk { shape: u32 },
}

impl Accel {
    pub fn build(shapes: &[Shape]) -> Accel {
        Self::build_with(shapes, Isa::detect())
    }

    /// Build with the given node-test ISA (`Isa::Avx2` falls back to `Isa::Portable` when the CPU
    /// lacks it).
    pub fn build_with(shapes: &[Shape], isa: Isa) -> Accel {
        let isa = if isa == Isa::Avx2 && Isa::detect() != Isa::Avx2 { Isa::Portable } else { isa };
        // Per mesh: (first builder index, shape index); the builder numbers the triangles of the
        // meshes one after another.
        let mut mesh_starts = Vec::new();
        let mut bounds = Vec::new();
        let mut analytic = Vec::new();
        for (si, s) in shapes.iter().enumerate() {
            match &s.geometry {
                Geometry::Mesh(m) => {
                    mesh_starts.push((bounds.len() as u32, si as u32));
                    bounds.par_extend(m.indices.par_iter().map(|idx| {
                        let va = idx.map(|i| Vec3A::from(m.positions[i as usize]));
                        let mut b = Bounds { min: va[0].min(va[1]).min(va[2]), max: va[0].max(va[1]).max(va[2]) };
                        // Pad the box by a little more than the rounding of the node test, so a
                        // ray through a box corner (a vertex shared by triangles) is never culled.
                        let pad =
                            (b.max - b.min).max_element() * 1e-4 + b.min.abs().max(b.max.abs()).max_element() * 1e-6;
                        b.min -= Vec3A::splat(pad);
                        b.max += Vec3A::splat(pad);
                        b
                    }));
                }
                Geometry::Sphere(sp) => {
                    analytic.push(Analytic::Sphere { shape: si as u32, center: sp.center, r2: sp.radius * sp.radius })
                }
                Geometry::Disk(_) => analytic.push(Analytic::Disk { shape: si as u32 }),
            }
        }
        let bvh = build::build(bounds, |id| {
            let (shape, prim) = shape_prim(&mesh_starts, id);
            match &shapes[shape as usize].geometry {
                Geometry::Mesh(m) => (m.vertices(prim), (shape, prim)),
                _ => unreachable!("only meshes are in the BVH"),
            }
        });
        let deep = bvh.as_ref().is_some_and(|b| traverse::stack_size(b.depth) > STACK);
        Accel { bvh, analytic, isa, deep }
    }

    /// Bytes of the BVH (nodes, triangle packets, per-lane shape and triangle).
    pub fn memory_bytes(&self) -> usize {
        self.bvh.as_ref().map_or(0, |b| b.memory_bytes())
    }

    /// BVH nodes, leaf packets and depth.
    pub fn stats(&self) -> (usize, usize, usize) {
        self.bvh.as_ref().map_or((0, 0, 0), |b| (b.nodes.len(), b.packets.len(), b.depth))
    }

    /// Closest hit along the ray in (0, ray.tmax): [`Accel::intersect_inline`] as a call of its own
    /// (benchmarks and tests count its instructions; the renderer inlines the query).
    pub fn intersect(&self, shapes: &[Shape], ray: &Ray) -> Option<Hit> {
        self.intersect_inline(shapes, ray)
    }

    /// True when anything blocks the ray in (0, ray.tmax): [`Accel::occluded_inline`] as a call.
    pub fn occluded(&self, shapes: &[Shape], ray: &Ray) -> bool {
        self.occluded_inline(shapes, ray)
    }

    /// Closest hit along the ray in (0, ray.tmax), inlined into the caller (`Scene::ray_intersect`).
    #[inline(always)]
    pub fn intersect_inline(&self, shapes: &[Shape], ray: &Ray) -> Option<Hit> {
        // A NaN or infinite ray has no hit; the traversal's nearest-first order needs finite distances.
        if !ray_is_finite(ray) {
            return None;
        }
        let (best, tmax) = self.analytic_closest(shapes, ray);
        let Some(bvh) = &self.bvh else { return best };
        bvh_hit(bvh, self.closest(bvh, ray, tmax)).or(best)
    }

    /// True when anything blocks the ray in (0, ray.tmax), inlined into the caller (`Scene::ray_test`).
    #[inline(always)]
    pub fn occluded_inline(&self, shapes: &[Shape], ray: &Ray) -> bool {
        // A NaN or infinite ray carries no light: report it blocked.
        if !ray_is_finite(ray) {
            return true;
        }
        if self.analytic_any(shapes, ray) {
            return true;
        }
        self.bvh.as_ref().is_some_and(|bvh| self.any(bvh, ray))
    }

    /// The analytic shapes' closest hit in (0, ray.tmax), and the distance the BVH must beat.
    #[inline(always)]
    fn analytic_closest(&self, shapes: &[Shape], ray: &Ray) -> (Option<Hit>, f32) {
        let mut best = None;
        let mut tmax = ray.tmax;
        for a in &self.analytic {
            let (shape, t) = analytic_hit(a, shapes, ray, tmax);
            if t < tmax {
                tmax = t;
                best = Some(Hit { shape, prim: 0, b1: 0.0, b2: 0.0, t });
            }
        }
        (best, tmax)
    }

    #[inline(always)]
    fn analytic_any(&self, shapes: &[Shape], ray: &Ray) -> bool {
        self.analytic.iter().any(|a| analytic_hit(a, shapes, ray, ray.tmax).1 < ray.tmax)
    }

    /// The BVH's closest hit in (0, tmax): one call into the traversal compiled for the CPU (the
    /// ray's precomputation happens inside it).
    #[inline(always)]
    fn closest(&self, bvh: &Bvh8, ray: &Ray, tmax: f32) -> Option<(u32, f32, f32, f32)> {
        if self.deep {
            return closest_deep(bvh, ray, tmax, self.isa);
        }
        let stack = &mut [const { MaybeUninit::uninit() }; STACK];
        #[cfg(target_arch = "x86_64")]
        if self.isa == Isa::Avx2 {
            // SAFETY: `Isa::Avx2` is only set when the CPU supports it (checked in `build_with`).
            return unsafe { traverse::closest_avx2(bvh, ray.o, ray.d, tmax, stack) };
        }
        traverse::closest_portable(bvh, ray.o, ray.d, tmax, stack)
    }

    #[inline(always)]
    fn any(&self, bvh: &Bvh8, ray: &Ray) -> bool {
        if self.deep {
            return any_deep(bvh, ray, self.isa);
        }
        let stack = &mut [const { MaybeUninit::uninit() }; STACK];
        #[cfg(target_arch = "x86_64")]
        if self.isa == Isa::Avx2 {
            // SAFETY: as in `closest`.
            return unsafe { traverse::any_avx2(bvh, ray.o, ray.d, ray.tmax, stack) };
        }
        traverse::any_portable(bvh, ray.o, ray.d, ray.tmax, stack)
    }
}

/// The BVH's hit as a `Hit` (shape and triangle of the lane).
#[inline(always)]
fn bvh_hit(bvh: &Bvh8, found: Option<(u32, f32, f32, f32)>) -> Option<Hit> {
    let (lane, t, b1, b2) = found?;
    let (shape, prim) = bvh.lane_prims[lane as usize / 4][lane as usize % 4];
    Some(Hit { shape, prim, b1, b2, t })
}

/// Closest hit in a tree too deep for the fixed stack (a heap stack).
#[cold]
#[inline(never)]
fn closest_deep(bvh: &Bvh8, ray: &Ray, tmax: f32, isa: Isa) -> Option<(u32, f32, f32, f32)> {
    let stack = &mut heap_stack(bvh.depth);
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx2 {
        // SAFETY: `Isa::Avx2` is only set when the CPU supports it.
        return unsafe { traverse::closest_avx2(bvh, ray.o, ray.d, tmax, stack) };
    }
    let _ = isa;
    traverse::closest_portable(bvh, ray.o, ray.d, tmax, stack)
}

/// Any hit in a tree too deep for the fixed stack.
#[cold]
#[inline(never)]
fn any_deep(bvh: &Bvh8, ray: &Ray, isa: Isa) -> bool {
    let stack = &mut heap_stack(bvh.depth);
    #[cfg(target_arch = "x86_64")]
    if isa == Isa::Avx2 {
        // SAFETY: as in `closest_deep`.
        return unsafe { traverse::any_avx2(bvh, ray.o, ray.d, ray.tmax, stack) };
    }
    let _ = isa;
    traverse::any_portable(bvh, ray.o, ray.d, ray.tmax, stack)
}

/// Shape and triangle of builder index `id`.
#[inline]
fn shape_prim(mesh_starts: &[(u32, u32)], id: u32) -> (u32, u32) {
    let k = mesh_starts.partition_point(|m| m.0 <= id) - 1;
    (mesh_starts[k].1, id - mesh_starts[k].0)
}

/// A traversal stack on the heap, for trees too deep for the fixed one.
fn heap_stack(depth: usize) -> Vec<MaybeUninit<traverse::Entry>> {
    vec![MaybeUninit::uninit(); traverse::stack_size(depth)]
}

/// The shape of `a` and its hit distance in (0, tmax) (`f32::INFINITY` when none).
#[inline(always)]
fn analytic_hit(a: &Analytic, shapes: &[Shape], ray: &Ray, tmax: f32) -> (u32, f32) {
    match *a {
        Analytic::Sphere { shape, center, r2 } => {
            (shape, super::sphere::intersect_sphere(center, r2, ray.o, ray.d, tmax).unwrap_or(f32::INFINITY))
        }
        Analytic::Disk { shape } => {
            let t = match &shapes[shape as usize].geometry {
                Geometry::Disk(d) => d.intersect(&Ray { o: ray.o, d: ray.d, tmax }),
                _ => None,
            };
            (shape, t.unwrap_or(f32::INFINITY))
        }
    }
}

#[cfg(test)]
mod tests;

/// Origin and direction finite (a sum is non-finite when either part is, even ±inf cancelling to NaN).
/// `x − x` is exactly 0 for a finite `x` and NaN otherwise, so the three differences sum to 0 exactly
/// when every component is finite: one comparison instead of one per component.
#[inline(always)]
#[allow(clippy::eq_op)] // `s - s` is the finiteness test, not zero
fn ray_is_finite(ray: &Ray) -> bool {
    let s = ray.o + ray.d;
    let z = s - s;
    z.x + z.y + z.z == 0.0
}

//! Ray-tracing acceleration: an 8-wide BVH over every triangle of the scene ([`bvh8`], built by a
//! parallel binned-SAH builder, [`build`]), traversed nearest first with an AVX node test when the
//! CPU has AVX2 (run-time detection; SSE otherwise) ([`traverse`]), with leaves of four triangles tested at once by the watertight test of Woop,
//! Benthin & Wald 2013 ([`triangle`]). Analytic shapes (spheres, disks) stay out of the BVH and are
//! tested directly before it, in `f32`; scenes are expected to hold few of them. A tree of at
//! most sixteen triangles is not traversed: every triangle is tested at once, in one AVX-512
//! register or two AVX2 halves ([`brute`]).
//!
//! Watertightness: primitive boxes are padded, the node test is conservative (Ize 2013) and the
//! triangle test is watertight, so no ray slips through a shared edge or vertex of a closed mesh
//! (`tests/accel.rs` checks 1.4 M rays through a closed 1.3 M-triangle sphere). The tree's large arrays
//! live in huge-page memory ([`pages`]).

pub mod brute;
pub mod build;
pub mod bvh8;
pub mod pages;
pub mod traverse;
pub mod triangle;

use super::{Geometry, Shape};
use crate::math::{Ray, RayA};
use brute::Brute;
use build::Bounds;
use bvh8::{Bvh8, LaneShade, LEAF_SIZE};
use glam::Vec3A;
use rayon::prelude::*;
use std::mem::MaybeUninit;
use traverse::{Found, STACK};

/// Closest hit: shape, primitive, barycentrics of vertices 1 and 2, distance, and the BVH lane
/// that holds the triangle ([`NO_LANE`] for a sphere or disk).
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub shape: u32,
    pub prim: u32,
    pub b1: f32,
    pub b2: f32,
    pub t: f32,
    pub lane: u32,
}

/// [`Hit::lane`] of a hit outside the BVH.
pub const NO_LANE: u32 = u32::MAX;

/// Which node and leaf tests the CPU runs (ordered: each level needs the one below it).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Isa {
    /// Two SSE halves (any x86-64 CPU, and other architectures through glam's fallback).
    Portable,
    /// One AVX register per plane, with BMI1 / LZCNT / POPCNT bit scans.
    Avx2,
    /// The AVX2 tests with AVX-512VL: compares into mask registers, masked min / max and
    /// compress in the ordering and the pushes, 32 vector registers (no spills in the leaf loop).
    Avx512,
}

impl Isa {
    /// The best the running CPU supports.
    pub fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::is_x86_feature_detected as has;
            if has!("avx2") && has!("bmi1") && has!("lzcnt") && has!("popcnt") {
                if has!("avx512f") && has!("avx512vl") && has!("avx512bw") && has!("avx512dq") {
                    return Isa::Avx512;
                }
                return Isa::Avx2;
            }
        }
        Isa::Portable
    }

    /// What `Accel::build` uses: [`Isa::detect`], capped by the environment variable `SNEE_ISA`
    /// (`portable`, `avx2` or `avx512`; for measuring one path against another on the same CPU).
    /// A level the CPU lacks is never chosen.
    pub fn selected() -> Isa {
        let best = Isa::detect();
        match std::env::var("SNEE_ISA").as_deref() {
            Ok("portable") => Isa::Portable,
            Ok("avx2") => best.min(Isa::Avx2),
            _ => best,
        }
    }
}

/// The traversal `$avx512` / `$avx2` / `$portable` for `$isa`, with stack-entry prefetching when
/// `$pf` (a const parameter of each, so each is compiled with and without it).
macro_rules! dispatch {
    ($isa:expr, $pf:expr, $avx512:ident, $avx2:ident, $portable:ident, ($($arg:expr),*)) => {{
        let (isa, pf): (Isa, bool) = ($isa, $pf);
        #[cfg(target_arch = "x86_64")]
        // SAFETY: `isa` is never above what the CPU supports (capped in `Accel::build_with`), and
        // the tree and stack are as the traversals require (`build::build`, `traverse::stack_size`).
        match (isa, pf) {
            (Isa::Avx512, true) => return unsafe { traverse::$avx512::<true>($($arg),*) },
            (Isa::Avx512, false) => return unsafe { traverse::$avx512::<false>($($arg),*) },
            (Isa::Avx2, true) => return unsafe { traverse::$avx2::<true>($($arg),*) },
            (Isa::Avx2, false) => return unsafe { traverse::$avx2::<false>($($arg),*) },
            (Isa::Portable, _) => {}
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = isa;
        if pf {
            traverse::$portable::<true>($($arg),*)
        } else {
            traverse::$portable::<false>($($arg),*)
        }
    }};
}

pub struct Accel {
    bvh: Option<Bvh8>,
    /// Spheres tested outside the BVH, with what their test needs copied out of the shapes.
    spheres: Vec<AnalyticSphere>,
    /// Disks tested outside the BVH (their shape indices).
    disks: Vec<u32>,
    isa: Isa,
    /// The tree is too deep for the fixed traversal stack (`traverse::STACK`): queries use a heap one.
    deep: bool,
    /// The tree is larger than `traverse::PREFETCH_BYTES`: traversals prefetch stack entries.
    prefetch: bool,
    /// A tiny tree's triangles for brute-force queries (`brute.rs`; AVX2 and AVX-512 only).
    brute: Option<Brute>,
}

/// A sphere tested outside the BVH: centre and r² (16-byte vectors: the test runs in SSE lanes).
#[derive(Clone, Copy, Debug)]
struct AnalyticSphere {
    center: Vec3A,
    r2: f32,
    shape: u32,
}

impl Accel {
    pub fn build(shapes: &[Shape]) -> Accel {
        Self::build_with(shapes, Isa::selected())
    }

    /// Build with the given node-test ISA (capped at what the CPU supports: `Isa::Avx512` falls
    /// back to `Isa::Avx2`, and that to `Isa::Portable`), with brute force for a tiny tree unless
    /// the environment variable `SNEE_BRUTE` is `off` (for measuring one against the other).
    pub fn build_with(shapes: &[Shape], isa: Isa) -> Accel {
        Self::build_opts(shapes, isa, std::env::var("SNEE_BRUTE").as_deref() != Ok("off"))
    }

    /// [`Accel::build_with`], with brute force for a tree of at most `brute::MAX_TRIANGLES`
    /// triangles when `brute` (and the ISA is AVX2 or AVX-512), the tree's traversal otherwise.
    pub fn build_opts(shapes: &[Shape], isa: Isa, brute: bool) -> Accel {
        let isa = isa.min(Isa::detect());
        // Per mesh: (first builder index, shape index); the builder numbers the triangles of the
        // meshes one after another.
        let mut mesh_starts = Vec::new();
        let mut bounds = Vec::new();
        let (mut spheres, mut disks) = (Vec::new(), Vec::new());
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
                Geometry::Sphere(sp) => spheres.push(AnalyticSphere {
                    center: sp.center.into(),
                    r2: sp.radius * sp.radius,
                    shape: si as u32,
                }),
                Geometry::Disk(_) => disks.push(si as u32),
            }
        }
        let bvh = build::build(bounds, |id| {
            let (shape, prim) = shape_prim(&mesh_starts, id);
            match &shapes[shape as usize].geometry {
                Geometry::Mesh(m) => (m.vertices(prim), m.lane_shade(shape, prim)),
                _ => unreachable!("only meshes are in the BVH"),
            }
        });
        let deep = bvh.as_ref().is_some_and(|b| traverse::stack_size(b.depth) > STACK);
        let prefetch = bvh.as_ref().is_some_and(|b| b.memory_bytes() > traverse::PREFETCH_BYTES);
        let brute = if brute && isa >= Isa::Avx2 { bvh.as_ref().and_then(Brute::new) } else { None };
        Accel { bvh, spheres, disks, isa, deep, prefetch, brute }
    }

    /// Bytes of the BVH (nodes, triangle packets, per-lane shape and triangle).
    pub fn memory_bytes(&self) -> usize {
        self.bvh.as_ref().map_or(0, |b| b.memory_bytes())
    }

    /// The record of BVH lane `lane` ([`Hit::lane`]) and its triangle's vertices as the leaf packet
    /// holds them (the mesh's positions, the same values); `None` for [`NO_LANE`].
    #[inline(always)]
    pub fn lane(&self, lane: u32) -> Option<(&LaneShade, [Vec3A; 3])> {
        let bvh = self.bvh.as_ref()?;
        let (packet, l) = (lane as usize / LEAF_SIZE, lane as usize % LEAF_SIZE);
        let (record, v) = (bvh.lanes.get(packet)?, &bvh.packets.get(packet)?.v);
        Some((&record[l], [0, 1, 2].map(|j| Vec3A::new(v[j][0][l], v[j][1][l], v[j][2][l]))))
    }

    /// Triangles tested by brute force instead of the tree (0: the tree is traversed).
    pub fn brute_triangles(&self) -> usize {
        self.brute.as_ref().map_or(0, Brute::triangles)
    }

    /// BVH nodes, leaf packets and depth.
    pub fn stats(&self) -> (usize, usize, usize) {
        self.bvh.as_ref().map_or((0, 0, 0), |b| (b.nodes.len(), b.packets.len(), b.depth))
    }

    /// Closest hit along the ray in (0, ray.tmax): [`Accel::intersect_a`] as a call of its own
    /// (benchmarks and tests count its instructions; the renderer inlines the query).
    pub fn intersect(&self, shapes: &[Shape], ray: &Ray) -> Option<Hit> {
        self.intersect_a(shapes, &ray.to_a())
    }

    /// True when anything blocks the ray in (0, ray.tmax): [`Accel::occluded_inline`] as a call.
    pub fn occluded(&self, shapes: &[Shape], ray: &Ray) -> bool {
        self.occluded_inline(shapes, ray)
    }

    /// Closest hit along the ray in (0, ray.tmax), inlined into the caller (`Scene::ray_intersect`'s
    /// bodies and the shadow walk, which hold the ray as a [`RayA`]).
    #[inline(always)]
    pub fn intersect_a(&self, shapes: &[Shape], ray: &RayA) -> Option<Hit> {
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
        self.occluded_a(shapes, &ray.to_a())
    }

    /// [`Accel::occluded_inline`] of a [`RayA`].
    #[inline(always)]
    pub fn occluded_a(&self, shapes: &[Shape], ray: &RayA) -> bool {
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
    /// Spheres are tested before disks; a disk at exactly a sphere's distance wins when its shape
    /// comes first, so the hit is the one of the lowest shape index among the nearest, as a test
    /// of the shapes in scene order gives it.
    #[inline(always)]
    fn analytic_closest(&self, shapes: &[Shape], ray: &RayA) -> (Option<Hit>, f32) {
        let mut best: Option<Hit> = None;
        let mut tmax = ray.tmax;
        let (o, d) = (ray.o, ray.d);
        for s in &self.spheres {
            if let Some(t) = super::sphere::intersect_sphere_a(s.center, s.r2, o, d, tmax) {
                if t < tmax {
                    tmax = t;
                    best = Some(Hit { shape: s.shape, prim: 0, b1: 0.0, b2: 0.0, t, lane: NO_LANE });
                }
            }
        }
        if !self.disks.is_empty() {
            (best, tmax) = disks_closest(&self.disks, shapes, ray, best, tmax);
        }
        (best, tmax)
    }

    #[inline(always)]
    fn analytic_any(&self, shapes: &[Shape], ray: &RayA) -> bool {
        let (o, d) = (ray.o, ray.d);
        self.spheres.iter().any(|s| super::sphere::intersect_sphere_a(s.center, s.r2, o, d, ray.tmax).is_some())
            || (!self.disks.is_empty() && disks_any(&self.disks, shapes, ray))
    }

    /// The BVH's closest hit in (0, tmax): one call into the traversal compiled for the CPU (the
    /// ray's precomputation happens inside it), prefetching stack entries in a large tree.
    #[inline(always)]
    fn closest(&self, bvh: &Bvh8, ray: &RayA, tmax: f32) -> Found {
        #[cfg(target_arch = "x86_64")]
        if let Some(brute) = &self.brute {
            // SAFETY: `brute` is built only for `Isa::Avx2` and above, capped at the CPU's.
            return unsafe {
                if self.isa == Isa::Avx512 {
                    brute.closest_avx512(ray, tmax)
                } else {
                    brute.closest_avx2(ray, tmax)
                }
            };
        }
        if self.deep {
            return closest_deep(bvh, ray, tmax, self.isa);
        }
        let stack = &mut [const { MaybeUninit::uninit() }; STACK];
        dispatch!(self.isa, self.prefetch, closest_avx512, closest_avx2, closest_portable, (bvh, ray, tmax, stack))
    }

    #[inline(always)]
    fn any(&self, bvh: &Bvh8, ray: &RayA) -> bool {
        #[cfg(target_arch = "x86_64")]
        if let Some(brute) = &self.brute {
            // SAFETY: as in `closest`.
            return unsafe {
                if self.isa == Isa::Avx512 {
                    brute.any_avx512(ray)
                } else {
                    brute.any_avx2(ray)
                }
            };
        }
        if self.deep {
            return any_deep(bvh, ray, self.isa);
        }
        let stack = &mut [const { MaybeUninit::uninit() }; STACK];
        dispatch!(self.isa, self.prefetch, any_avx512, any_avx2, any_portable, (bvh, ray, stack))
    }
}

/// The BVH's hit as a `Hit` (shape and triangle of the lane).
#[inline(always)]
fn bvh_hit(bvh: &Bvh8, found: Found) -> Option<Hit> {
    if found.lane == u32::MAX {
        return None;
    }
    let (lane, t, b1, b2) = (found.lane, found.t, found.b1, found.b2);
    let l = &bvh.lanes[lane as usize / 4][lane as usize % 4];
    Some(Hit { shape: l.shape, prim: l.prim, b1, b2, t, lane })
}

/// Closest hit in a tree too deep for the fixed stack (a heap stack; such a tree is large, so
/// its traversal prefetches).
#[cold]
#[inline(never)]
fn closest_deep(bvh: &Bvh8, ray: &RayA, tmax: f32, isa: Isa) -> Found {
    let stack = &mut heap_stack(bvh.depth);
    dispatch!(isa, true, closest_avx512, closest_avx2, closest_portable, (bvh, ray, tmax, stack))
}

/// Any hit in a tree too deep for the fixed stack.
#[cold]
#[inline(never)]
fn any_deep(bvh: &Bvh8, ray: &RayA, isa: Isa) -> bool {
    let stack = &mut heap_stack(bvh.depth);
    dispatch!(isa, true, any_avx512, any_avx2, any_portable, (bvh, ray, stack))
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

/// The disks' closest hit after the spheres' (`best` at distance `tmax`): see
/// [`Accel::analytic_closest`] for the order. Out of line: few scenes hold disks.
#[inline(never)]
fn disks_closest(
    disks: &[u32],
    shapes: &[Shape],
    ray: &RayA,
    mut best: Option<Hit>,
    mut tmax: f32,
) -> (Option<Hit>, f32) {
    for &shape in disks {
        let Geometry::Disk(disk) = &shapes[shape as usize].geometry else { continue };
        let Some(t) = disk.intersect(&ray.ray()) else { continue };
        if t < tmax || (t == tmax && best.is_some_and(|b| shape < b.shape)) {
            tmax = t;
            best = Some(Hit { shape, prim: 0, b1: 0.0, b2: 0.0, t, lane: NO_LANE });
        }
    }
    (best, tmax)
}

/// True when a disk blocks the ray in (0, ray.tmax).
#[inline(never)]
fn disks_any(disks: &[u32], shapes: &[Shape], ray: &RayA) -> bool {
    let ray = &ray.ray();
    disks.iter().any(|&shape| match &shapes[shape as usize].geometry {
        Geometry::Disk(disk) => disk.intersect(ray).is_some(),
        _ => false,
    })
}

#[cfg(test)]
mod tests;

/// Origin and direction finite (a sum is non-finite when either part is, even ±inf cancelling to NaN).
/// `x − x` is exactly 0 for a finite `x` and NaN otherwise, so one vector comparison of the three
/// differences with 0 tests every component.
#[inline(always)]
#[allow(clippy::eq_op)] // `s - s` is the finiteness test, not zero
fn ray_is_finite(ray: &RayA) -> bool {
    let s = ray.o + ray.d;
    (s - s).cmpeq(Vec3A::ZERO).all()
}

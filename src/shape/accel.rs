//! Ray-tracing acceleration: one obvhs `CwBvh` (8-wide compressed BVH) over every triangle and
//! analytic shape of the scene, with a watertight ray/triangle test.
//!
//! obvhs's own triangle test is not watertight: a ray through a shared edge or vertex of a closed
//! mesh can slip through, which breaks media (the path believes it is still inside). We use the
//! test of Woop, Benthin & Wald 2013 ("Watertight Ray/Triangle Intersection", JCGT 2(1)), with a
//! double-precision fallback when an edge function is exactly zero.

use super::{Geometry, Shape};
use crate::math::{Ray, Vec3};
use glam::UVec2;
use glam::{Vec3A, Vec3Swizzles, Vec4};
use obvhs::aabb::Aabb as BvhAabb;
use obvhs::cwbvh::node::{extract_byte64, CwBvhNode};
use obvhs::cwbvh::CwBvh;
use obvhs::ray::Ray as BvhRay;
use obvhs::{Boundable, BvhBuildParams};
use std::time::Duration;

/// A BVH primitive: triangle `prim` of shape `shape`, or a whole analytic shape.
#[derive(Clone, Copy, Debug)]
struct PrimRef {
    shape: u32,
    prim: u32,
}

struct BoundsPrim(BvhAabb);

impl Boundable for BoundsPrim {
    fn aabb(&self) -> BvhAabb {
        self.0
    }
}

/// Closest hit: shape, primitive, barycentrics of vertices 1 and 2, distance.
#[derive(Clone, Copy, Debug)]
pub struct Hit {
    pub shape: u32,
    pub prim: u32,
    pub b1: f32,
    pub b2: f32,
    pub t: f32,
}

/// What the traversal reads per BVH primitive: the triangle's vertex coordinates, one vector per
/// axis (lanes 0..2: vertices 0..2), so that the triangle test needs no shuffles. Lane 3 of `x` is
/// 1 for an analytic shape (then see `PrimRef`), 0 for a triangle.
#[derive(Clone, Copy, Debug)]
struct TriData {
    x: Vec4,
    y: Vec4,
    z: Vec4,
}

impl TriData {
    fn triangle(v: [Vec3A; 3]) -> TriData {
        TriData {
            x: Vec4::new(v[0].x, v[1].x, v[2].x, 0.0),
            y: Vec4::new(v[0].y, v[1].y, v[2].y, 0.0),
            z: Vec4::new(v[0].z, v[1].z, v[2].z, 0.0),
        }
    }

    const ANALYTIC: TriData = TriData { x: Vec4::new(0.0, 0.0, 0.0, 1.0), y: Vec4::ZERO, z: Vec4::ZERO };

    #[inline(always)]
    fn is_analytic(&self) -> bool {
        self.x.w != 0.0
    }
}

pub struct Accel {
    bvh: Option<CwBvh>,
    /// In BVH primitive order.
    prims: Vec<PrimRef>,
    /// Triangle vertices (or the analytic marker) in BVH primitive order.
    tris: Vec<TriData>,
}

impl Accel {
    pub fn build(shapes: &[Shape]) -> Accel {
        Self::build_with(shapes, BvhBuildParams::medium_build())
    }

    fn build_with(shapes: &[Shape], params: BvhBuildParams) -> Accel {
        let mut prims = Vec::new();
        let mut bounds = Vec::new();
        let mut tris = Vec::new();
        for (si, s) in shapes.iter().enumerate() {
            match &s.geometry {
                Geometry::Mesh(m) => {
                    for (pi, idx) in m.indices.iter().enumerate() {
                        let v = idx.map(|i| Vec3A::from(m.positions[i as usize]));
                        let mut b = BvhAabb { min: v[0], max: v[0] };
                        b.min = b.min.min(v[1]).min(v[2]);
                        b.max = b.max.max(v[1]).max(v[2]);
                        // Pad the box: obvhs's ray/box test is not conservative for a ray through a
                        // box corner (a vertex shared by triangles), which let rays slip through
                        // closed meshes. The padding only costs a few extra triangle tests.
                        let pad =
                            (b.max - b.min).max_element() * 1e-4 + b.min.abs().max(b.max.abs()).max_element() * 1e-6;
                        b.min -= Vec3A::splat(pad);
                        b.max += Vec3A::splat(pad);
                        prims.push(PrimRef { shape: si as u32, prim: pi as u32 });
                        bounds.push(BoundsPrim(b));
                        tris.push(TriData::triangle(v));
                    }
                }
                _ => {
                    let b = s.bounds();
                    prims.push(PrimRef { shape: si as u32, prim: 0 });
                    bounds.push(BoundsPrim(BvhAabb { min: b.min.into(), max: b.max.into() }));
                    tris.push(TriData::ANALYTIC);
                }
            }
        }
        if prims.is_empty() {
            return Accel { bvh: None, prims, tris };
        }
        let bvh = obvhs::cwbvh::builder::build_cwbvh(&bounds, params, &mut Duration::default());
        let prims = bvh.primitive_indices.iter().map(|&i| prims[i as usize]).collect();
        let tris = bvh.primitive_indices.iter().map(|&i| tris[i as usize]).collect();
        Accel { bvh: Some(bvh), prims, tris }
    }

    /// Closest hit along the ray in (0, ray.tmax).
    pub fn intersect(&self, shapes: &[Shape], ray: &Ray) -> Option<Hit> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("sse4.1") {
            // SAFETY: the CPU supports SSE4.1 (checked just above).
            return unsafe { self.intersect_sse41(shapes, ray) };
        }
        self.intersect_with(shapes, ray, |node, r, oct| node.intersect_ray(r, oct))
    }

    /// True when anything blocks the ray in (0, ray.tmax).
    pub fn occluded(&self, shapes: &[Shape], ray: &Ray) -> bool {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("sse4.1") {
            // SAFETY: the CPU supports SSE4.1 (checked just above).
            return unsafe { self.occluded_sse41(shapes, ray) };
        }
        self.occluded_with(shapes, ray, |node, r, oct| node.intersect_ray(r, oct))
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse4.1")]
    fn intersect_sse41(&self, shapes: &[Shape], ray: &Ray) -> Option<Hit> {
        self.intersect_with(shapes, ray, |node, r, oct| intersect_node_sse41(node, r, oct))
    }

    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "sse4.1")]
    fn occluded_sse41(&self, shapes: &[Shape], ray: &Ray) -> bool {
        self.occluded_with(shapes, ray, |node, r, oct| intersect_node_sse41(node, r, oct))
    }

    /// Closest-hit traversal (obvhs's `CwBvh::ray_traverse`) with the node test `node_test`.
    #[inline(always)]
    fn intersect_with(
        &self,
        shapes: &[Shape],
        ray: &Ray,
        node_test: impl Fn(&CwBvhNode, &BvhRay, u32) -> u32,
    ) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let ray = &positive_zeros(ray);
        let wt = WatertightRay::new(ray);
        let mut r = BvhRay::new(ray.o.into(), ray.d.into(), 0.0, ray.tmax);
        let (mut b1, mut b2, mut hit_id) = (0.0, 0.0, u32::MAX);
        let mut state = bvh.new_traversal(r.direction);
        let mut node;
        obvhs::traverse!(bvh, node, state, node_test(node, &r, state.oct_inv4), {
            let id = state.primitive_id as usize;
            let tri = &self.tris[id];
            if tri.is_analytic() {
                let t = intersect_analytic(&shapes[self.prims[id].shape as usize], ray, r.tmax);
                if t < r.tmax {
                    (b1, b2, hit_id, r.tmax) = (0.0, 0.0, state.primitive_id, t);
                }
            } else if let Some((t, u, v)) = wt.intersect(tri, r.tmax) {
                (b1, b2, hit_id, r.tmax) = (u, v, state.primitive_id, t);
            }
        });
        let pr = self.prims.get(hit_id as usize)?;
        Some(Hit { shape: pr.shape, prim: pr.prim, b1, b2, t: r.tmax })
    }

    /// Any-hit traversal (obvhs's `CwBvh::ray_traverse_miss`) with the node test `node_test`.
    #[inline(always)]
    fn occluded_with(&self, shapes: &[Shape], ray: &Ray, node_test: impl Fn(&CwBvhNode, &BvhRay, u32) -> u32) -> bool {
        let Some(bvh) = self.bvh.as_ref() else { return false };
        let ray = &positive_zeros(ray);
        let wt = WatertightRay::new(ray);
        let r = BvhRay::new(ray.o.into(), ray.d.into(), 0.0, ray.tmax);
        let mut state = bvh.new_traversal(r.direction);
        let mut node;
        let mut blocked = false;
        'traversal: {
            obvhs::traverse!(bvh, node, state, node_test(node, &r, state.oct_inv4), {
                let id = state.primitive_id as usize;
                let tri = &self.tris[id];
                blocked = if tri.is_analytic() {
                    intersect_analytic(&shapes[self.prims[id].shape as usize], ray, r.tmax) < r.tmax
                } else {
                    wt.intersect(tri, r.tmax).is_some()
                };
                if blocked {
                    break 'traversal;
                }
            });
        }
        blocked
    }
}

/// obvhs's SIMD node test (`CwBvhNode::intersect_ray_simd`, the same floating-point operations and
/// so the same hit mask), with the quantized child planes widened to floats by SSE4.1: three
/// instructions per four planes instead of four scalar conversions, the most expensive part of
/// obvhs's version on a baseline x86-64 build.
/// obvhs's (crate-private) lower bound of the ray interval in its node test.
#[cfg(target_arch = "x86_64")]
const NODE_EPSILON: f32 = 0.0001;

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "sse4.1")]
#[inline]
fn intersect_node_sse41(node: &CwBvhNode, ray: &BvhRay, oct_inv4: u32) -> u32 {
    use std::arch::x86_64::*;
    #[target_feature(enable = "sse4.1")]
    #[inline]
    fn planes(q: &[u8; 8], half: usize) -> __m128 {
        let bytes = [q[4 * half], q[4 * half + 1], q[4 * half + 2], q[4 * half + 3]];
        _mm_cvtepi32_ps(_mm_cvtepu8_epi32(_mm_cvtsi32_si128(i32::from_le_bytes(bytes))))
    }
    let dir_inv = node.compute_extent() * ray.inv_direction;
    let orig = (Vec3A::from(node.p) - ray.origin) * ray.inv_direction;
    let (dx, dy, dz) = (_mm_set1_ps(dir_inv.x), _mm_set1_ps(dir_inv.y), _mm_set1_ps(dir_inv.z));
    let (ox, oy, oz) = (_mm_set1_ps(orig.x), _mm_set1_ps(orig.y), _mm_set1_ps(orig.z));
    let (neg_x, neg_y, neg_z) = (ray.direction.x < 0.0, ray.direction.y < 0.0, ray.direction.z < 0.0);
    let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
    let mut hit_mask = 0u32;
    for half in 0..2 {
        let (lo, hi) = (planes(&node.child_min_x, half), planes(&node.child_max_x, half));
        let (x_min, x_max) = if neg_x { (hi, lo) } else { (lo, hi) };
        let tmin_x = _mm_add_ps(_mm_mul_ps(x_min, dx), ox);
        let tmax_x = _mm_add_ps(_mm_mul_ps(x_max, dx), ox);
        let (lo, hi) = (planes(&node.child_min_y, half), planes(&node.child_max_y, half));
        let (y_min, y_max) = if neg_y { (hi, lo) } else { (lo, hi) };
        let tmin_y = _mm_add_ps(_mm_mul_ps(y_min, dy), oy);
        let tmax_y = _mm_add_ps(_mm_mul_ps(y_max, dy), oy);
        let (lo, hi) = (planes(&node.child_min_z, half), planes(&node.child_max_z, half));
        let (z_min, z_max) = if neg_z { (hi, lo) } else { (lo, hi) };
        let tmin_z = _mm_add_ps(_mm_mul_ps(z_min, dz), oz);
        let tmax_z = _mm_add_ps(_mm_mul_ps(z_max, dz), oz);
        let tmin = _mm_max_ps(tmin_x, _mm_max_ps(tmin_y, tmin_z));
        let tmax = _mm_min_ps(tmax_x, _mm_min_ps(tmax_y, tmax_z));
        let tmin = _mm_max_ps(tmin, _mm_set1_ps(NODE_EPSILON));
        let tmax = _mm_min_ps(tmax, _mm_set1_ps(ray.tmax));
        let mask = _mm_movemask_ps(_mm_cmple_ps(tmin, tmax));
        for j in 0..4 {
            if mask & (1 << j) != 0 {
                let slot = half * 4 + j;
                hit_mask |= extract_byte64(child_bits8, slot) << extract_byte64(bit_index8, slot);
            }
        }
    }
    hit_mask
}

/// obvhs's traversal misses everything for a direction with a −0.0 component (its octant from
/// the sign bit disagrees with its slab test), so turn −0.0 into +0.0 (x + 0.0 does exactly that).
#[inline]
fn positive_zeros(ray: &Ray) -> Ray {
    Ray { o: ray.o, d: ray.d + Vec3::ZERO, tmax: ray.tmax }
}

#[inline]
fn intersect_analytic(shape: &Shape, ray: &Ray, tmax: f32) -> f32 {
    let r = Ray { o: ray.o, d: ray.d, tmax };
    let t = match &shape.geometry {
        Geometry::Sphere(s) => s.intersect(&r),
        Geometry::Disk(d) => d.intersect(&r),
        Geometry::Mesh(_) => None,
    };
    t.unwrap_or(f32::INFINITY)
}

/// Per-ray precomputation of the watertight test (Woop et al. 2013, Sec. 3), arranged for 4-wide
/// SIMD: the permutation and shear of the paper become a matrix with one ±1, one shear coefficient
/// and one zero per row, applied to all three vertices at once. A product with 0 or 1 is exact and
/// adding 0 is exact, so every transformed coordinate equals the paper's `a[kx] - sx * a[kz]`
/// bit for bit (up to the sign of a zero), and shared edges still give identical edge functions.
struct WatertightRay {
    /// Ray origin, each coordinate splatted.
    o: [Vec3A; 3],
    /// Coefficient splats: sheared x = Σ_j rel_j · shear_x[j] (likewise y, z), rel_j = vertex_j - o_j.
    shear_x: [Vec3A; 3],
    shear_y: [Vec3A; 3],
    shear_z: [Vec3A; 3],
}

/// Woop et al. 2013's axis permutation and shear of a ray direction `d`: `kz` is the dominant
/// axis, `kx, ky` follow it (swapped when `d[kz] < 0`, keeping the winding), and
/// `(sx, sy, sz) = (d[kx]/d[kz], d[ky]/d[kz], 1/d[kz])`.
#[inline(always)]
fn shear_axes(d: Vec3) -> ([usize; 3], [f32; 3]) {
    let a = d.abs();
    let kz = if a.x > a.y {
        if a.x > a.z {
            0
        } else {
            2
        }
    } else if a.y > a.z {
        1
    } else {
        2
    };
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let sz = 1.0 / d[kz];
    ([kx, ky, kz], [d[kx] * sz, d[ky] * sz, sz])
}

impl WatertightRay {
    #[inline]
    fn new(ray: &Ray) -> Self {
        let ([kx, ky, kz], [sx, sy, sz]) = shear_axes(ray.d);
        let mut rx = [0.0f32; 3];
        let mut ry = [0.0f32; 3];
        let mut rz = [0.0f32; 3];
        rx[kx] = 1.0;
        rx[kz] = -sx;
        ry[ky] = 1.0;
        ry[kz] = -sy;
        rz[kz] = sz;
        WatertightRay {
            o: [Vec3A::splat(ray.o.x), Vec3A::splat(ray.o.y), Vec3A::splat(ray.o.z)],
            shear_x: rx.map(Vec3A::splat),
            shear_y: ry.map(Vec3A::splat),
            shear_z: rz.map(Vec3A::splat),
        }
    }

    /// (t, b1, b2) of a hit in (0, tmax).
    #[inline(always)]
    fn intersect(&self, tri: &TriData, tmax: f32) -> Option<(f32, f32, f32)> {
        // Vertex coordinates relative to the ray origin: lanes are the vertices a, b, c.
        let px = Vec3A::from_vec4(tri.x) - self.o[0];
        let py = Vec3A::from_vec4(tri.y) - self.o[1];
        let pz = Vec3A::from_vec4(tri.z) - self.o[2];
        let s = &self.shear_x;
        let x = px * s[0] + py * s[1] + pz * s[2];
        let s = &self.shear_y;
        let y = px * s[0] + py * s[1] + pz * s[2];
        // Edge functions (u, v, w) = (cx·by - cy·bx, ax·cy - ay·cx, bx·ay - by·ax).
        let mut uvw = x.zxy() * y.yzx() - y.zxy() * x.yzx();
        if uvw.cmpeq(Vec3A::ZERO).any() {
            let (ax, bx, cx) = (x.x as f64, x.y as f64, x.z as f64);
            let (ay, by, cy) = (y.x as f64, y.y as f64, y.z as f64);
            uvw = Vec3A::new((cx * by - cy * bx) as f32, (ax * cy - ay * cx) as f32, (bx * ay - by * ax) as f32);
        }
        if uvw.cmplt(Vec3A::ZERO).any() && uvw.cmpgt(Vec3A::ZERO).any() {
            return None;
        }
        let det = uvw.x + uvw.y + uvw.z;
        if det == 0.0 {
            return None;
        }
        let s = &self.shear_z;
        let z = px * s[0] + py * s[1] + pz * s[2];
        let tz = uvw * z;
        let t_scaled = tz.x + tz.y + tz.z;
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > 0.0 && t < tmax) {
            return None;
        }
        Some((t, uvw.y * inv_det, uvw.z * inv_det))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;

    /// The paper's scalar formulation (the previous implementation), as the reference.
    fn woop_scalar(ray: &Ray, v: [Vec3; 3], tmax: f32) -> Option<(f32, f32, f32)> {
        let ([kx, ky, kz], [sx, sy, sz]) = shear_axes(ray.d);
        let (a, b, c) = (v[0] - ray.o, v[1] - ray.o, v[2] - ray.o);
        let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
        let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
        let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
        let mut u = cx * by - cy * bx;
        let mut v_ = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v_ == 0.0 || w == 0.0 {
            u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
            v_ = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
            w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
        }
        if (u < 0.0 || v_ < 0.0 || w < 0.0) && (u > 0.0 || v_ > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v_ + w;
        if det == 0.0 {
            return None;
        }
        let t_scaled = u * (sz * a[kz]) + v_ * (sz * b[kz]) + w * (sz * c[kz]);
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > 0.0 && t < tmax) {
            return None;
        }
        Some((t, v_ * inv_det, w * inv_det))
    }

    /// Build and trace times of the BVH on the scenes of `SNEE_BVH_SCENES` (comma-separated),
    /// for the obvhs build presets: `cargo test --release --lib bvh_presets -- --ignored --nocapture`.
    #[test]
    #[ignore]
    fn bvh_presets() {
        use crate::math::{warp, Frame};
        use std::time::Instant;
        let list = std::env::var("SNEE_BVH_SCENES").unwrap_or("scenes/paper/envmap_smooth_st02.xml".into());
        for path in list.split(',') {
            let scene = crate::scene::build::load_scene(std::path::Path::new(path), &[]).unwrap();
            let shapes = &scene.shapes;
            // Rays leaving random surface points (cosine-distributed), as in path tracing.
            let mut s = Sampler::new(3, 0);
            let mut rays = Vec::new();
            let mut shadow = Vec::new();
            for _ in 0..200_000 {
                let shape = &shapes[((s.next_1d() * shapes.len() as f32) as usize).min(shapes.len() - 1)];
                let ps = shape.sample_position(s.next_2d());
                let mut d = Frame::from_normal(ps.n).to_world(warp::square_to_cosine_hemisphere(s.next_2d()));
                if s.next_1d() < 0.5 {
                    d = -d;
                }
                rays.push(Ray::new(crate::interaction::offset_origin(ps.p, ps.n, d), d));
                let other = &shapes[((s.next_1d() * shapes.len() as f32) as usize).min(shapes.len() - 1)];
                let q = other.sample_position(s.next_2d()).p;
                let o = crate::interaction::offset_origin(ps.p, ps.n, q - ps.p);
                shadow.push(crate::interaction::spawn_ray_between(o, q));
            }
            for (name, params) in [
                ("fast", BvhBuildParams::fast_build()),
                ("medium", BvhBuildParams::medium_build()),
                ("slow", BvhBuildParams::slow_build()),
                ("very_slow", BvhBuildParams::very_slow_build()),
            ] {
                let t0 = Instant::now();
                let accel = Accel::build_with(shapes, params);
                let build = t0.elapsed().as_secs_f64();
                let mut best = (f64::INFINITY, f64::INFINITY);
                let mut found = (0, 0);
                for _ in 0..3 {
                    let t0 = Instant::now();
                    found.0 = rays.iter().filter(|r| accel.intersect(shapes, r).is_some()).count();
                    let t1 = Instant::now();
                    found.1 = shadow.iter().filter(|r| accel.occluded(shapes, r)).count();
                    let t2 = Instant::now();
                    best.0 = best.0.min((t1 - t0).as_secs_f64());
                    best.1 = best.1.min((t2 - t1).as_secs_f64());
                }
                // Node and primitive tests per closest-hit ray.
                let (mut nodes, mut prims) = (0u64, 0u64);
                if let Some(bvh) = accel.bvh.as_ref() {
                    for ray in &rays {
                        let ray = positive_zeros(ray);
                        let wt = WatertightRay::new(&ray);
                        let mut r = BvhRay::new(ray.o.into(), ray.d.into(), 0.0, ray.tmax);
                        let mut state = bvh.new_traversal(r.direction);
                        let mut node;
                        obvhs::traverse!(
                            bvh,
                            node,
                            state,
                            {
                                nodes += 1;
                                node.intersect_ray(&r, state.oct_inv4)
                            },
                            {
                                prims += 1;
                                let tri = &accel.tris[state.primitive_id as usize];
                                if !tri.is_analytic() {
                                    if let Some((t, _, _)) = wt.intersect(tri, r.tmax) {
                                        r.tmax = t;
                                    }
                                }
                            }
                        );
                    }
                }
                eprintln!(
                    "  {:.1} nodes and {:.1} primitives tested per ray",
                    nodes as f64 / rays.len() as f64,
                    prims as f64 / rays.len() as f64
                );
                eprintln!(
                    "{path} {name:9}: build {build:.3} s, closest {:.2} Mray/s ({} hits), shadow {:.2} Mray/s ({} blocked), {} nodes",
                    rays.len() as f64 / best.0 / 1e6,
                    found.0,
                    shadow.len() as f64 / best.1 / 1e6,
                    found.1,
                    accel.bvh.as_ref().map_or(0, |b| b.nodes.len())
                );
            }
        }
    }

    /// The SSE4.1 node test gives obvhs's hit masks exactly, on every node of a triangle-soup BVH.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn sse41_node_test_equals_obvhs() {
        if !std::arch::is_x86_feature_detected!("sse4.1") {
            return;
        }
        let mut s = Sampler::new(11, 0);
        let mut data = crate::shape::mesh_data::MeshData::default();
        for i in 0..3000u32 {
            let c = Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * 10.0;
            for _ in 0..3 {
                data.positions.push(c + Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * 0.5);
            }
            data.indices.push([3 * i, 3 * i + 1, 3 * i + 2]);
        }
        let mesh = crate::shape::Mesh::new(data, &crate::math::Mat4::IDENTITY, true, false);
        let shapes = [Shape {
            geometry: Geometry::Mesh(mesh),
            plugin: "ply".into(),
            id: None,
            bsdf: 0,
            emitter: None,
            interior: None,
            exterior: None,
        }];
        let accel = Accel::build(&shapes);
        let bvh = accel.bvh.as_ref().unwrap();
        assert!(bvh.nodes.len() > 50);
        for i in 0..300 {
            let o = Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * 14.0 - 2.0;
            let mut d = crate::math::warp::square_to_uniform_sphere(s.next_2d());
            if i % 5 == 0 {
                d = Vec3::new(d.x, 0.0, d.z).normalize();
            }
            let r = BvhRay::new(o.into(), d.into(), 0.0, 1.0 + 20.0 * s.next_1d());
            let oct = bvh.new_traversal(r.direction).oct_inv4;
            for node in &bvh.nodes {
                // SAFETY: SSE4.1 support checked above.
                let got = unsafe { intersect_node_sse41(node, &r, oct) };
                assert_eq!(got, node.intersect_ray(&r, oct));
            }
        }
    }

    #[test]
    fn simd_test_equals_scalar_reference() {
        let mut s = Sampler::new(7, 0);
        let r3 = |s: &mut Sampler| Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * 4.0 - 2.0;
        let (mut hits, mut n) = (0, 0);
        for i in 0..200_000 {
            let v = [r3(&mut s), r3(&mut s), r3(&mut s)];
            let o = r3(&mut s) * 2.0;
            // Aim at a vertex, an edge point or an interior point; some rays are axis-aligned.
            let target = match i % 4 {
                0 => v[i % 3],
                1 => v[0] + (v[1] - v[0]) * s.next_1d(),
                2 => v[0] * 0.2 + v[1] * 0.3 + v[2] * 0.5,
                _ => r3(&mut s),
            };
            let mut d = (target - o).normalize();
            if i % 7 == 0 {
                d = Vec3::new(d.x, 0.0, -0.0) + Vec3::ZERO;
                d = if d.x == 0.0 { Vec3::X } else { d.normalize() };
            }
            let ray = Ray { o, d, tmax: 10.0 };
            let tri = TriData::triangle(v.map(Vec3A::from));
            let got = WatertightRay::new(&ray).intersect(&tri, ray.tmax);
            let want = woop_scalar(&ray, v, ray.tmax);
            assert_eq!(got, want, "ray {ray:?} triangle {v:?}");
            n += 1;
            hits += got.is_some() as u32;
        }
        assert!(hits > n / 10, "only {hits} hits of {n}");
    }
}

//! Ray-tracing acceleration: one obvhs `CwBvh` (8-wide compressed BVH) over every triangle and
//! analytic shape of the scene, with a watertight ray/triangle test.
//!
//! obvhs's own triangle test is not watertight: a ray through a shared edge or vertex of a closed
//! mesh can slip through, which breaks media (the path believes it is still inside). We use the
//! test of Woop, Benthin & Wald 2013 ("Watertight Ray/Triangle Intersection", JCGT 2(1)), with a
//! double-precision fallback when an edge function is exactly zero.

use super::{Geometry, Shape};
use crate::math::{Ray, Vec3};
use glam::Vec3A;
use obvhs::aabb::Aabb as BvhAabb;
use obvhs::cwbvh::CwBvh;
use obvhs::ray::{Ray as BvhRay, RayHit};
use obvhs::{Boundable, BvhBuildParams};
use std::time::Duration;

/// A BVH primitive: triangle `prim` of shape `shape`, or a whole analytic shape.
#[derive(Clone, Copy, Debug)]
struct PrimRef {
    shape: u32,
    prim: u32,
    analytic: bool,
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

pub struct Accel {
    bvh: Option<CwBvh>,
    /// In BVH primitive order.
    prims: Vec<PrimRef>,
    /// Triangle vertices in BVH primitive order (unused entries for analytic shapes).
    tris: Vec<[Vec3A; 3]>,
}

impl Accel {
    pub fn build(shapes: &[Shape]) -> Accel {
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
                        prims.push(PrimRef { shape: si as u32, prim: pi as u32, analytic: false });
                        bounds.push(BoundsPrim(b));
                        tris.push(v);
                    }
                }
                _ => {
                    let b = s.bounds();
                    prims.push(PrimRef { shape: si as u32, prim: 0, analytic: true });
                    bounds.push(BoundsPrim(BvhAabb { min: b.min.into(), max: b.max.into() }));
                    tris.push([Vec3A::ZERO; 3]);
                }
            }
        }
        if prims.is_empty() {
            return Accel { bvh: None, prims, tris };
        }
        let bvh = obvhs::cwbvh::builder::build_cwbvh(&bounds, BvhBuildParams::medium_build(), &mut Duration::default());
        let prims = bvh.primitive_indices.iter().map(|&i| prims[i as usize]).collect();
        let tris = bvh.primitive_indices.iter().map(|&i| tris[i as usize]).collect();
        Accel { bvh: Some(bvh), prims, tris }
    }

    /// Closest hit along the ray in (0, ray.tmax).
    pub fn intersect(&self, shapes: &[Shape], ray: &Ray) -> Option<Hit> {
        let bvh = self.bvh.as_ref()?;
        let ray = &positive_zeros(ray);
        let wt = WatertightRay::new(ray);
        let bray = BvhRay::new(ray.o.into(), ray.d.into(), 0.0, ray.tmax);
        let mut hit = RayHit::none();
        let (mut b1, mut b2) = (0.0, 0.0);
        let found = bvh.ray_traverse(bray, &mut hit, |r, id| {
            let pr = self.prims[id];
            if pr.analytic {
                let t = intersect_analytic(&shapes[pr.shape as usize], ray, r.tmax);
                if t < r.tmax {
                    b1 = 0.0;
                    b2 = 0.0;
                }
                t
            } else if let Some((t, u, v)) = wt.intersect(&self.tris[id], r.tmax) {
                b1 = u;
                b2 = v;
                t
            } else {
                f32::INFINITY
            }
        });
        if !found {
            return None;
        }
        let pr = self.prims[hit.primitive_id as usize];
        Some(Hit { shape: pr.shape, prim: pr.prim, b1, b2, t: hit.t })
    }

    /// True when anything blocks the ray in (0, ray.tmax).
    pub fn occluded(&self, shapes: &[Shape], ray: &Ray) -> bool {
        let Some(bvh) = self.bvh.as_ref() else { return false };
        let ray = &positive_zeros(ray);
        let wt = WatertightRay::new(ray);
        let bray = BvhRay::new(ray.o.into(), ray.d.into(), 0.0, ray.tmax);
        !bvh.ray_traverse_miss(bray, |r, id| {
            let pr = self.prims[id];
            if pr.analytic {
                intersect_analytic(&shapes[pr.shape as usize], ray, r.tmax)
            } else {
                wt.intersect(&self.tris[id], r.tmax).map_or(f32::INFINITY, |h| h.0)
            }
        })
    }
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

/// Per-ray precomputation of the watertight test (Woop et al. 2013, Sec. 3).
struct WatertightRay {
    o: Vec3A,
    kx: usize,
    ky: usize,
    kz: usize,
    sx: f32,
    sy: f32,
    sz: f32,
}

impl WatertightRay {
    #[inline]
    fn new(ray: &Ray) -> Self {
        let d = ray.d;
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
        WatertightRay { o: ray.o.into(), kx, ky, kz, sx: d[kx] * sz, sy: d[ky] * sz, sz }
    }

    /// (t, b1, b2) of a hit in (0, tmax).
    #[inline]
    fn intersect(&self, v: &[Vec3A; 3], tmax: f32) -> Option<(f32, f32, f32)> {
        let a = v[0] - self.o;
        let b = v[1] - self.o;
        let c = v[2] - self.o;
        let (kx, ky, kz) = (self.kx, self.ky, self.kz);
        let ax = a[kx] - self.sx * a[kz];
        let ay = a[ky] - self.sy * a[kz];
        let bx = b[kx] - self.sx * b[kz];
        let by = b[ky] - self.sy * b[kz];
        let cx = c[kx] - self.sx * c[kz];
        let cy = c[ky] - self.sy * c[kz];
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
        let az = self.sz * a[kz];
        let bz = self.sz * b[kz];
        let cz = self.sz * c[kz];
        let t_scaled = u * az + v_ * bz + w * cz;
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > 0.0 && t < tmax) {
            return None;
        }
        Some((t, v_ * inv_det, w * inv_det))
    }
}

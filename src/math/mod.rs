//! Math foundations: glam re-exports, rays, the local shading [`Frame`], and sample warps.
//!
//! Geometry is single precision (as in Mitsuba's `llvm_ad_rgb`); scene descriptions keep
//! double precision ([`glam::DMat4`]) until the scene is built.

pub mod fast;
pub mod frame;
pub mod warp;

pub use frame::Frame;
pub use glam::{DMat4, DVec3, Mat3, Mat4, UVec3, Vec2, Vec3, Vec4};

pub const PI: f32 = std::f32::consts::PI;
pub const INV_PI: f32 = std::f32::consts::FRAC_1_PI;
pub const INV_TWO_PI: f32 = 0.5 * std::f32::consts::FRAC_1_PI;
pub const INV_FOUR_PI: f32 = 0.25 * std::f32::consts::FRAC_1_PI;

/// A ray `o + t d` valid for `t` in `[0, tmax)`; `d` is normalised.
#[derive(Clone, Copy, Debug)]
pub struct Ray {
    pub o: Vec3,
    pub d: Vec3,
    pub tmax: f32,
}

impl Ray {
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        Ray { o, d, tmax: f32::INFINITY }
    }
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.o + self.d * t
    }

    /// The ray as [`RayA`], for a call that does not inline.
    #[inline(always)]
    pub fn to_a(&self) -> RayA {
        RayA { o: self.o.into(), d: self.d.into(), tmax: self.tmax }
    }
}

/// A [`Ray`] with origin and direction as 16-byte vectors, as the traversals and the hit record
/// take it across a call that does not inline: the caller writes each vector with one 16-byte
/// store and the callee reads it with one load of the same size, which the CPU forwards from the
/// store. A `Ray` assembled field by field (e.g. from a structure of arrays) is written by narrow
/// stores, and the callee's wider loads of its fields cannot be forwarded from them: a stall of
/// a dozen cycles or more per query (a third of `Scene::ray_intersect`'s samples on cornell_box).
#[derive(Clone, Copy, Debug)]
pub struct RayA {
    pub o: glam::Vec3A,
    pub d: glam::Vec3A,
    pub tmax: f32,
}

impl RayA {
    /// The ray as a [`Ray`].
    #[inline(always)]
    pub fn ray(&self) -> Ray {
        Ray { o: self.o.into(), d: self.d.into(), tmax: self.tmax }
    }
}

/// Axis-aligned bounding box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: Vec3,
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb { min: Vec3::splat(f32::INFINITY), max: Vec3::splat(f32::NEG_INFINITY) };
    pub fn expand(&mut self, p: Vec3) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb { min: self.min.min(o.min), max: self.max.max(o.max) }
    }
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x
    }
    pub fn center(&self) -> Vec3 {
        0.5 * (self.min + self.max)
    }
    pub fn extent(&self) -> Vec3 {
        self.max - self.min
    }
}

/// Transform a point by an affine matrix.
#[inline]
pub fn xform_point(m: &Mat4, p: Vec3) -> Vec3 {
    m.transform_point3(p)
}

/// Transform a normal by the inverse transpose (pass the inverse matrix).
#[inline]
pub fn xform_normal(inv: &Mat4, n: Vec3) -> Vec3 {
    inv.transpose().transform_vector3(n)
}

/// Safe square root: 0 for negative input.
#[inline]
pub fn safe_sqrt(x: f32) -> f32 {
    x.max(0.0).sqrt()
}

/// Power heuristic (β = 2) weight for `a` against `b`; 0 for non-finite input (as Mitsuba's `mis_weight`).
#[inline]
pub fn mis_weight(pdf_a: f32, pdf_b: f32) -> f32 {
    let a2 = pdf_a * pdf_a;
    let w = a2 / (a2 + pdf_b * pdf_b);
    if w.is_finite() {
        w
    } else {
        0.0
    }
}

/// Reflect `wi` about the normal `n` (both pointing away from the surface).
#[inline]
pub fn reflect(wi: Vec3, n: Vec3) -> Vec3 {
    2.0 * wi.dot(n) * n - wi
}

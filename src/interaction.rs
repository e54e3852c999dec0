//! Interaction records passed between shapes, BSDFs, emitters and integrators
//! (Mitsuba's `SurfaceInteraction3f`, `DirectionSample3f`, `PositionSample3f`).

use crate::math::{Frame, Ray, Vec2, Vec3};
use glam::Vec3A;

/// Relative ray offset (Mitsuba's `math::RayEpsilon` = 1500 ulp at 1).
pub const RAY_EPSILON: f32 = f32::EPSILON * 0.5 * 1500.0;
/// Shadow rays stop this fraction short of their target (Mitsuba's `ShadowEpsilon`).
pub const SHADOW_EPSILON: f32 = RAY_EPSILON * 10.0;

/// A ray/surface hit in world space, with the incident direction in the local shading frame.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceInteraction {
    /// Ray distance of the hit.
    pub t: f32,
    pub p: Vec3,
    /// Geometric normal (unit, world space, orientation from the mesh winding).
    pub n: Vec3,
    /// Shading frame (interpolated normal when the mesh has normals).
    pub sh_frame: Frame,
    pub uv: Vec2,
    /// Direction towards the previous vertex, in the local shading frame.
    pub wi: Vec3,
    /// Index into `Scene::shapes`.
    pub shape: u32,
    /// Primitive (triangle) index within the shape.
    pub prim: u32,
}

impl SurfaceInteraction {
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.sh_frame.to_world(v)
    }
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        self.sh_frame.to_local(v)
    }
    /// A ray leaving the surface along `d`, origin offset along the geometric normal to the side of `d`.
    #[inline]
    pub fn spawn_ray(&self, d: Vec3) -> Ray {
        Ray::new(offset_origin(self.p, self.n, d), d)
    }
    /// A shadow ray towards `target` that stops just short of it.
    #[inline]
    pub fn spawn_ray_to(&self, target: Vec3) -> Ray {
        let o = offset_origin(self.p, self.n, target - self.p);
        spawn_ray_between(o, target)
    }
}

/// The shading frame around the unit shading normal `n` with its tangent `s` along the surface's
/// dp/du (Mitsuba's `SurfaceInteraction::initialize_sh_frame`): Gram–Schmidt, s = normalize(dp_du −
/// n (n·dp_du)), t = n × s. This orients anisotropic BSDFs (`alpha_u` along `s`). Without a usable
/// dp/du (zero, as Mitsuba tests, or parallel to `n`) the frame is `Frame::from_normal(n)` (Mitsuba's
/// `coordinate_system`).
#[inline]
pub fn shading_frame(n: Vec3, dp_du: Vec3) -> Frame {
    let [s, t, n] = shading_frame_a(n.into(), dp_du.into());
    Frame { s: s.into(), t: t.into(), n: n.into() }
}

/// [`shading_frame`] on 16-byte vectors, as `[s, t, n]` (the mesh hit record computes in them):
/// the same operations in the same order, so the same frame bit for bit.
#[inline(always)]
pub fn shading_frame_a(n: Vec3A, dp_du: Vec3A) -> [Vec3A; 3] {
    let s = dp_du - n * n.dot(dp_du);
    let len2 = s.length_squared();
    if !(len2 > 0.0 && len2.is_finite()) {
        let f = Frame::from_normal(n.into());
        return [f.s.into(), f.t.into(), n];
    }
    let s = s / len2.sqrt();
    [s, n.cross(s), n]
}

/// Offset a surface point along its geometric normal `n`, to the side that `d` points to
/// (Mitsuba's `offset_p`: scaled with the magnitude of the coordinates).
#[inline]
pub fn offset_origin(p: Vec3, n: Vec3, d: Vec3) -> Vec3 {
    let mag = (1.0 + p.abs().max_element()) * RAY_EPSILON;
    let off = if n.dot(d) >= 0.0 { mag } else { -mag };
    p + n * off
}

/// A ray from `o` to `target`, with `tmax` just short of the target.
#[inline]
pub fn spawn_ray_between(o: Vec3, target: Vec3) -> Ray {
    let delta = target - o;
    let dist = delta.length();
    let d = delta / dist;
    Ray { o, d, tmax: dist * (1.0 - SHADOW_EPSILON) }
}

/// A sampled point on a shape or emitter seen from a reference point (Mitsuba's `DirectionSample3f`).
#[derive(Clone, Copy, Debug, Default)]
pub struct DirectionSample {
    /// The sampled point (for infinitely distant emitters: a point far beyond the scene).
    pub p: Vec3,
    /// Surface normal at `p` (zero for environment and delta lights).
    pub n: Vec3,
    pub uv: Vec2,
    /// Unit direction from the reference point towards `p`.
    pub d: Vec3,
    /// Distance from the reference point to `p` (infinite for environment / directional lights).
    pub dist: f32,
    /// Density in solid angle at the reference point (1 for delta emitters, with `delta = true`).
    pub pdf: f32,
    pub delta: bool,
    /// Index into `Scene::emitters` (set by the scene's emitter sampling).
    pub emitter: u32,
}

/// A point sampled on a surface by area (Mitsuba's `PositionSample3f`).
#[derive(Clone, Copy, Debug, Default)]
pub struct PositionSample {
    pub p: Vec3,
    pub n: Vec3,
    pub uv: Vec2,
    /// Density in area measure.
    pub pdf: f32,
}

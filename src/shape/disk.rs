//! Mitsuba's analytic `disk`: the unit disk in the local XY plane, normal +Z, placed by `to_world`.
//! uv = (r, φ / 2π) of the local point; dp/du = to_world (cos φ, sin φ, 0), radial, orients the
//! shading frame's tangent (anisotropic BSDFs), as in Mitsuba 3.9 (`(1, 0)` at the centre).
//!
//! ```xml
//! <shape type="disk"><transform name="to_world"><scale value="0.3"/></transform></shape>
//! ```

use crate::interaction::{shading_frame, PositionSample, SurfaceInteraction};
use crate::math::{warp, Aabb, Mat4, Ray, Vec2, Vec3, INV_TWO_PI, PI};

#[derive(Clone, Debug)]
pub struct Disk {
    pub to_world: Mat4,
    pub to_object: Mat4,
    pub flip_normals: bool,
    /// World-space normal (from the inverse transpose).
    pub n: Vec3,
    area: f32,
}

impl Disk {
    pub fn new(to_world: Mat4, flip_normals: bool) -> Disk {
        let to_object = to_world.inverse();
        let n = to_object.transpose().transform_vector3(Vec3::Z).normalize_or_zero();
        let du = to_world.transform_vector3(Vec3::X);
        let dv = to_world.transform_vector3(Vec3::Y);
        // An affine image of the unit disk is an ellipse of area π |du × dv|.
        let area = PI * du.cross(dv).length();
        Disk { to_world, to_object, flip_normals, n, area }
    }

    pub fn surface_area(&self) -> f32 {
        self.area
    }

    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for (x, y) in [(-1.0, -1.0), (1.0, -1.0), (-1.0, 1.0), (1.0, 1.0)] {
            b.expand(self.to_world.transform_point3(Vec3::new(x, y, 0.0)));
        }
        b
    }

    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        let o = self.to_object.transform_point3(ray.o);
        let d = self.to_object.transform_vector3(ray.d);
        if d.z == 0.0 {
            return None;
        }
        let t = -o.z / d.z;
        let p = o + d * t;
        (t > 0.0 && t < ray.tmax && p.x * p.x + p.y * p.y <= 1.0).then_some(t)
    }

    fn local_uv(local: Vec3) -> Vec2 {
        let r = (local.x * local.x + local.y * local.y).sqrt();
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        Vec2::new(r, phi * INV_TWO_PI)
    }

    pub fn interaction(&self, t: f32, ray: &Ray) -> SurfaceInteraction {
        let hit = ray.at(t);
        let mut local = self.to_object.transform_point3(hit);
        local.z = 0.0;
        let p = self.to_world.transform_point3(local);
        let n = if self.flip_normals { -self.n } else { self.n };
        let r = (local.x * local.x + local.y * local.y).sqrt();
        let (cos_phi, sin_phi) = if r > 0.0 { (local.x / r, local.y / r) } else { (1.0, 0.0) };
        let sh_frame = shading_frame(n, self.to_world.transform_vector3(Vec3::new(cos_phi, sin_phi, 0.0)));
        SurfaceInteraction {
            t,
            p,
            n,
            sh_frame,
            uv: Self::local_uv(local),
            wi: sh_frame.to_local(-ray.d),
            shape: 0,
            prim: 0,
        }
    }

    pub fn sample_position(&self, sample: Vec2) -> PositionSample {
        let d = warp::square_to_uniform_disk_concentric(sample);
        let local = Vec3::new(d.x, d.y, 0.0);
        PositionSample {
            p: self.to_world.transform_point3(local),
            n: if self.flip_normals { -self.n } else { self.n },
            uv: Self::local_uv(local),
            pdf: 1.0 / self.area,
        }
    }
}

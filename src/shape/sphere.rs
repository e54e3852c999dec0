//! Mitsuba's analytic `sphere`: `center` (0,0,0), `radius` 1, `to_world` (uniform scale), `flip_normals`.
//!
//! ```xml
//! <shape type="sphere"><point name="center" value="0, 1, 0"/><float name="radius" value="0.5"/></shape>
//! ```
//! Seen from outside, emitters on it are sampled by the cone of directions it subtends (uniform in
//! solid angle), as Mitsuba does; from inside, by area.
//!
//! Its parametrisation is Mitsuba's, in object space (`to_world` · translate(`center`) ·
//! scale(`radius`), so a rotation turns it): uv = (φ / 2π, θ / π) of the local point, and
//! dp/du = to_world (−y, x, 0), which orients the shading frame's tangent (anisotropic BSDFs).

use crate::interaction::{shading_frame, DirectionSample, PositionSample, SurfaceInteraction};
use crate::math::{warp, Aabb, Frame, Mat4, Ray, Vec2, Vec3, INV_PI, INV_TWO_PI, PI};
use glam::Vec3A;

#[derive(Clone, Debug)]
pub struct Sphere {
    /// World-space centre and radius.
    pub center: Vec3,
    pub radius: f32,
    pub flip_normals: bool,
    /// Unit sphere → world (Mitsuba's `m_to_world`: `to_world` · translate(center) · scale(radius)).
    pub to_world: Mat4,
    pub to_object: Mat4,
    /// Whether samples on the sphere need their uv: set by the scene when an area emitter with a
    /// textured radiance sits on it; otherwise sampling skips the acos / atan2.
    pub sample_uv: bool,
    /// Whether hits need the sphere's uv: set by the scene when its BSDF or area emitter reads a
    /// spatially varying texture; otherwise `interaction` leaves uv zero and skips the acos / atan2.
    pub hit_uv: bool,
}

impl Sphere {
    /// A sphere in world space without rotation (`to_world` = translate(center) · scale(radius)).
    pub fn new(center: Vec3, radius: f32, flip_normals: bool) -> Sphere {
        Sphere::with_to_world(Mat4::from_translation(center) * Mat4::from_scale(Vec3::splat(radius)), flip_normals)
    }

    /// The sphere that `to_world` (uniform scale) makes of the unit sphere at the origin.
    pub fn with_to_world(to_world: Mat4, flip_normals: bool) -> Sphere {
        Sphere {
            center: to_world.transform_point3(Vec3::ZERO),
            radius: to_world.transform_vector3(Vec3::X).length(),
            flip_normals,
            to_world,
            to_object: to_world.inverse(),
            sample_uv: true,
            hit_uv: true,
        }
    }

    pub fn bounds(&self) -> Aabb {
        Aabb { min: self.center - Vec3::splat(self.radius), max: self.center + Vec3::splat(self.radius) }
    }

    pub fn surface_area(&self) -> f32 {
        4.0 * PI * self.radius * self.radius
    }

    /// Nearest intersection distance in (0, tmax) ([`intersect_sphere`]).
    #[inline]
    pub fn intersect(&self, ray: &Ray) -> Option<f32> {
        intersect_sphere(self.center, self.radius * self.radius, ray.o, ray.d, ray.tmax)
    }

    /// uv = (φ / 2π, θ / π) of a point on the unit sphere in object space.
    fn local_uv(local: Vec3) -> Vec2 {
        let theta = local.z.clamp(-1.0, 1.0).acos();
        let mut phi = local.y.atan2(local.x);
        if phi < 0.0 {
            phi += 2.0 * PI;
        }
        Vec2::new(phi * INV_TWO_PI, theta * INV_PI)
    }

    /// uv of a world-space point on the sphere, or zero when sampling does not need it.
    #[inline]
    fn sample_uv_of(&self, p: Vec3) -> Vec2 {
        if self.sample_uv {
            Self::local_uv(self.to_object.transform_point3(p))
        } else {
            Vec2::ZERO
        }
    }

    pub fn interaction(&self, t: f32, ray: &Ray) -> SurfaceInteraction {
        let hit = ray.at(t);
        let mut n = (hit - self.center).normalize();
        // Re-project onto the surface to reduce error (as Mitsuba does).
        let p = self.center + n * self.radius;
        let local = self.to_object.transform_point3(p);
        let uv = if self.hit_uv { Self::local_uv(local) } else { Vec2::ZERO };
        // Mitsuba's dp/du = to_world (−y, x, 0) · 2π (zero at the poles: then coordinate_system(n)).
        let dp_du = self.to_world.transform_vector3(Vec3::new(-local.y, local.x, 0.0));
        if self.flip_normals {
            n = -n;
        }
        let sh_frame = shading_frame(n, dp_du);
        SurfaceInteraction { t, p, n, sh_frame, uv, wi: sh_frame.to_local(-ray.d), shape: 0, prim: 0 }
    }

    pub fn sample_position(&self, sample: Vec2) -> PositionSample {
        let d = warp::square_to_uniform_sphere(sample);
        let p = self.center + d * self.radius;
        PositionSample {
            p,
            n: if self.flip_normals { -d } else { d },
            uv: self.sample_uv_of(p),
            pdf: 1.0 / self.surface_area(),
        }
    }

    /// Sample a point visible from `ref_p` (Mitsuba's `Sphere::sample_direction`).
    pub fn sample_direction(&self, ref_p: Vec3, sample: Vec2) -> DirectionSample {
        let dc = self.center - ref_p;
        let dist2 = dc.length_squared();
        let r2 = self.radius * self.radius;
        if dist2 > r2 * (1.0 + 1e-4) {
            // Outside: uniform in the subtended cone.
            let inv_dc = 1.0 / dist2.sqrt();
            let sin_alpha = self.radius * inv_dc;
            let cos_alpha = (1.0 - sin_alpha * sin_alpha).max(0.0).sqrt();
            let frame = Frame::from_normal(dc * inv_dc);
            let local = warp::square_to_uniform_cone(sample, cos_alpha);
            let d = frame.to_world(local);
            // Intersect the ray with the sphere to find the point.
            let ray = Ray::new(ref_p, d);
            let t = self.intersect(&ray).unwrap_or_else(|| {
                // Grazing: closest point on the ray to the centre.
                dc.dot(d).max(0.0)
            });
            let p = ref_p + d * t;
            let mut n = (p - self.center).normalize_or_zero();
            if self.flip_normals {
                n = -n;
            }
            let pdf = warp::square_to_uniform_cone_pdf(local, cos_alpha);
            DirectionSample { p, n, uv: self.sample_uv_of(p), d, dist: t, pdf, delta: false, emitter: 0 }
        } else {
            let ps = self.sample_position(sample);
            area_to_direction_sample(ref_p, ps)
        }
    }

    pub fn pdf_direction(&self, ref_p: Vec3, ds: &DirectionSample) -> f32 {
        let dc = self.center - ref_p;
        let dist2 = dc.length_squared();
        let r2 = self.radius * self.radius;
        if dist2 > r2 * (1.0 + 1e-4) {
            let sin_alpha = self.radius / dist2.sqrt();
            let cos_alpha = (1.0 - sin_alpha * sin_alpha).max(0.0).sqrt();
            INV_TWO_PI / (1.0 - cos_alpha)
        } else {
            area_pdf_to_solid_angle(1.0 / self.surface_area(), ds.dist, ds.d, ds.n)
        }
    }
}

/// Nearest intersection distance in (0, tmax) of the ray `o + t d` with the sphere of centre
/// `center` and squared radius `r2`, in `f32` with the robust discriminant of Haines et al. 2019
/// (Ray Tracing Gems, ch. 7, Eq. 10: b² − ac = a (r² − |f − (f·d/a) d|²), free of the
/// cancellation of b² − ac) and the stable root pair (Eqs. 13–14).
///
/// A ray starting outside (c > 0) and pointing away from the centre (b < 0) is rejected before
/// the division and the square root: both roots are then negative (their product c / a is
/// positive, their sum 2b / a negative), and the full computation returns `None` for it too
/// (q = b − √disc < 0, so t1 = q / a < 0 and t0 = c / q < 0), so the result is the same bit for bit.
#[inline(always)]
pub fn intersect_sphere(center: Vec3, r2: f32, o: Vec3, d: Vec3, tmax: f32) -> Option<f32> {
    intersect_sphere_a(center.into(), r2, o.into(), d.into(), tmax)
}

/// [`intersect_sphere`] on 16-byte vectors (the BVH's analytic test): the same operations in the
/// same order (glam's `Vec3A::dot` adds (x + y) + z as `Vec3::dot` does), so the same bits.
#[inline(always)]
pub fn intersect_sphere_a(center: Vec3A, r2: f32, o: Vec3A, d: Vec3A, tmax: f32) -> Option<f32> {
    let f = o - center;
    // The quadratic a t² − 2 b t + c = 0 with b = −f·d, c = |f|² − r².
    let b = -f.dot(d);
    let c = f.length_squared() - r2;
    if c > 0.0 && b < 0.0 {
        return None;
    }
    let a = d.length_squared();
    let l = f + d * (b / a);
    let disc = a * (r2 - l.length_squared());
    if !(disc >= 0.0) {
        return None;
    }
    let q = b + disc.sqrt().copysign(b);
    let (mut t0, mut t1) = (c / q, q / a);
    if t0 > t1 {
        std::mem::swap(&mut t0, &mut t1);
    }
    if t0 > 0.0 && t0 < tmax {
        Some(t0)
    } else if t1 > 0.0 && t1 < tmax {
        Some(t1)
    } else {
        None
    }
}

/// Convert an area sample seen from `ref_p` to a direction sample with a solid-angle pdf.
#[inline(always)]
pub fn area_to_direction_sample(ref_p: Vec3, ps: PositionSample) -> DirectionSample {
    let delta = ps.p - ref_p;
    let dist = delta.length();
    let d = if dist > 0.0 { delta / dist } else { Vec3::Z };
    let pdf = area_pdf_to_solid_angle(ps.pdf, dist, d, ps.n);
    DirectionSample { p: ps.p, n: ps.n, uv: ps.uv, d, dist, pdf, delta: false, emitter: 0 }
}

/// pdf_A · r² / |cos θ| (0 when the point is seen edge-on).
#[inline]
pub fn area_pdf_to_solid_angle(pdf_area: f32, dist: f32, d: Vec3, n: Vec3) -> f32 {
    let cos = d.dot(n).abs();
    if cos > 0.0 {
        pdf_area * dist * dist / cos
    } else {
        0.0
    }
}

impl Sphere {
    /// The `sphere` shape's own parameters: `center` (0, 0, 0) and `radius` (1), placed by
    /// `to_world` (which must not scale non-uniformly).
    pub fn from_props(
        props: &crate::scene::desc::Props,
        to_world: &crate::math::Mat4,
        flip_normals: bool,
    ) -> crate::scene::Result<Sphere> {
        let center = props.point("center", Vec3::ZERO)?;
        let radius = props.float("radius", 1.0)?;
        if !(radius > 0.0 && radius.is_finite()) {
            return Err(props.error("radius", "sphere radius must be positive"));
        }
        let sx = to_world.transform_vector3(Vec3::X).length();
        let sy = to_world.transform_vector3(Vec3::Y).length();
        let sz = to_world.transform_vector3(Vec3::Z).length();
        if (sx - sy).abs() > 1e-4 * sx || (sx - sz).abs() > 1e-4 * sx {
            return Err(props.error("to_world", "sphere: to_world must not contain a non-uniform scale"));
        }
        let m = *to_world * Mat4::from_translation(center) * Mat4::from_scale(Vec3::splat(radius));
        Ok(Sphere::with_to_world(m, flip_normals))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;

    /// The spheres of a scene whose body is `shapes` (a 4×4 film).
    fn spheres_of(shapes: &str) -> Vec<Sphere> {
        let xml = format!(
            r#"<scene version="3.0.0">{shapes}<sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor></scene>"#
        );
        let parsed = crate::scene::xml::parse_str(&xml, "t.xml", std::path::Path::new("."), &[]).expect("parses");
        let scene = crate::scene::build::build_scene(&parsed).expect("builds");
        scene
            .shapes
            .iter()
            .filter_map(|s| match &s.geometry {
                crate::shape::Geometry::Sphere(sp) => Some(sp.clone()),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn hit_uv_only_where_a_texture_reads_it() {
        let checker = r#"<texture type="checkerboard" name="reflectance"/>"#;
        let spheres = spheres_of(&format!(
            r#"<shape type="sphere"><bsdf type="dielectric"/></shape>
               <shape type="sphere"><bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf></shape>
               <shape type="sphere"><bsdf type="diffuse">{checker}</bsdf></shape>
               <shape type="sphere"><bsdf type="twosided"><bsdf type="diffuse">{checker}</bsdf></bsdf></shape>
               <shape type="sphere"><bsdf type="mask"><texture type="checkerboard" name="opacity"/><bsdf type="conductor"/></bsdf></shape>
               <shape type="sphere"><emitter type="area"><texture type="checkerboard" name="radiance"/></emitter></shape>
               <shape type="sphere"><emitter type="area"><rgb name="radiance" value="2"/></emitter></shape>"#
        ));
        let hit_uv: Vec<bool> = spheres.iter().map(|s| s.hit_uv).collect();
        assert_eq!(hit_uv, [false, false, true, true, true, true, false]);
    }

    #[test]
    fn interaction_without_uv_is_otherwise_the_same() {
        let mut with_uv = Sphere::with_to_world(
            Mat4::from_translation(Vec3::new(0.3, -0.2, 0.1))
                * Mat4::from_rotation_x(0.7)
                * Mat4::from_scale(Vec3::splat(1.5)),
            false,
        );
        with_uv.hit_uv = true;
        let without = Sphere { hit_uv: false, ..with_uv.clone() };
        let mut sampler = Sampler::new(3, 0);
        for _ in 0..1000 {
            let o = Vec3::new(0.3, -0.2, 0.1) + warp::square_to_uniform_sphere(sampler.next_2d()) * 4.0;
            let target = with_uv.center + warp::square_to_uniform_sphere(sampler.next_2d()) * 0.5;
            let ray = Ray::new(o, (target - o).normalize());
            let t = with_uv.intersect(&ray).expect("aimed inside the sphere");
            let (a, b) = (with_uv.interaction(t, &ray), without.interaction(t, &ray));
            assert_eq!(b.uv, Vec2::ZERO);
            assert_eq!(a.uv, Sphere::local_uv(with_uv.to_object.transform_point3(a.p)));
            assert_eq!((a.p, a.n, a.wi), (b.p, b.n, b.wi));
            assert_eq!((a.sh_frame.s, a.sh_frame.t, a.sh_frame.n), (b.sh_frame.s, b.sh_frame.t, b.sh_frame.n));
        }
    }

    /// The double-precision textbook solution, as the reference.
    fn intersect_f64(s: &Sphere, ray: &Ray) -> Option<f64> {
        let o = (ray.o - s.center).as_dvec3();
        let d = ray.d.as_dvec3();
        let r = s.radius as f64;
        let (a, b, c) = (d.length_squared(), 2.0 * o.dot(d), o.length_squared() - r * r);
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return None;
        }
        let q = if b < 0.0 { -0.5 * (b - disc.sqrt()) } else { -0.5 * (b + disc.sqrt()) };
        let (t0, t1) = ((q / a).min(c / q), (q / a).max(c / q));
        [t0, t1].into_iter().find(|&t| t > 0.0 && t < ray.tmax as f64)
    }

    /// The f32 test agrees with double precision to a small relative error away from grazing
    /// rays, and never misses the sphere from inside.
    #[test]
    fn f32_intersection_matches_double_precision() {
        let mut s = Sampler::new(5, 0);
        let mut checked = 0;
        for i in 0..200_000 {
            let center = (Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) - 0.5) * 200.0;
            let radius = 0.01 * 1000f32.powf(s.next_1d());
            let sphere = Sphere::new(center, radius, false);
            let dir = warp::square_to_uniform_sphere(s.next_2d());
            let dist = if i % 3 == 0 { radius * s.next_1d() * 0.999 } else { radius * (1.0 + 1000.0 * s.next_1d()) };
            let o = center + dir * dist;
            let target = center + warp::square_to_uniform_sphere(s.next_2d()) * radius * (0.5 + 0.6 * s.next_1d());
            let ray = Ray::new(o, (target - o).normalize());
            let got = sphere.intersect(&ray);
            if dist < radius {
                assert!(got.is_some(), "ray from inside missed: {ray:?} {sphere:?}");
            }
            let want = intersect_f64(&sphere, &ray);
            // Compare away from grazing: the closest approach well inside the sphere.
            let f = (ray.o - center).as_dvec3();
            let d = ray.d.as_dvec3();
            let closest = (f - d * f.dot(d)).length();
            if closest < 0.99 * radius as f64 {
                let (g, w) = (got.expect("hit expected"), want.expect("reference hit"));
                let scale = f.length() + radius as f64;
                assert!((g as f64 - w).abs() <= 1e-5 * scale, "t {g} vs {w} for {ray:?} {sphere:?}");
                checked += 1;
            }
        }
        assert!(checked > 50_000, "only {checked} rays compared");
    }

    /// The early reject (outside and pointing away) changes no result: the test equals the full
    /// computation without it, bit for bit, on rays from inside, outside, towards and away.
    #[test]
    fn early_reject_is_exact() {
        let full = |center: Vec3, r2: f32, o: Vec3, d: Vec3, tmax: f32| {
            let f = o - center;
            let (a, b, c) = (d.length_squared(), -f.dot(d), f.length_squared() - r2);
            let l = f + d * (b / a);
            let disc = a * (r2 - l.length_squared());
            if !(disc >= 0.0) {
                return None;
            }
            let q = b + disc.sqrt().copysign(b);
            let (mut t0, mut t1) = (c / q, q / a);
            if t0 > t1 {
                std::mem::swap(&mut t0, &mut t1);
            }
            [t0, t1].into_iter().find(|&t| t > 0.0 && t < tmax)
        };
        let mut s = Sampler::new(9, 0);
        let mut rejected = 0;
        for i in 0..200_000 {
            let center = (Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) - 0.5) * 20.0;
            let r = 0.01 + 3.0 * s.next_1d();
            let o = center + warp::square_to_uniform_sphere(s.next_2d()) * r * (0.5 + 2.0 * s.next_1d());
            let mut d = warp::square_to_uniform_sphere(s.next_2d()) * (0.5 + s.next_1d());
            if i % 5 == 0 {
                d = Vec3::new(d.x, 0.0, -0.0);
            }
            let tmax = if i % 2 == 0 { f32::INFINITY } else { 10.0 * s.next_1d() };
            let got = intersect_sphere(center, r * r, o, d, tmax);
            assert_eq!(got.map(f32::to_bits), full(center, r * r, o, d, tmax).map(f32::to_bits), "{o:?} {d:?}");
            let f = o - center;
            rejected += (f.length_squared() > r * r && f.dot(d) > 0.0) as u32;
        }
        assert!(rejected > 50_000, "only {rejected} rays took the early reject");
    }
}

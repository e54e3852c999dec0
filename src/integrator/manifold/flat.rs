//! Flat smooth boundaries: the planes a medium's enclosing `dielectric` is made of, and the closed-form
//! refraction solution through one of them (docs/manifold.md §2).
//!
//! A medium qualifies when every shape that encloses it (interior = the medium, no exterior medium)
//! is a triangle mesh with a smooth `dielectric` BSDF and flat shading (no vertex normals, or
//! vertex normals equal to the face normal: `rectangle`, `cube`, flat-shaded meshes), and the
//! distinct (face normal, η) pairs number at most [`MAX_PLANES`]. Through a flat facet the
//! refraction constraint has a closed form: for a directional light the inner direction is fixed
//! by the facet's normal alone, so enumerating the planes finds every solution (one per plane).

use crate::bsdf::fresnel::{fresnel, refract};
use crate::bsdf::Bsdf;
use crate::emitter::Emitter;
use crate::interaction::SurfaceInteraction;
use crate::math::{Frame, Vec3};
use crate::scene::world::{Scene, SceneEmitter};
use crate::shape::Geometry;

/// Most distinct planes enumerated per connection (a cube has 6); more: the medium is not handled.
pub const MAX_PLANES: usize = 64;
/// Two unit normals belong to the same plane orientation when their dot product exceeds this.
pub const SAME_NORMAL: f32 = 1.0 - 1e-5;

/// One orientation of the boundary: outward unit normal and `η = η_int / η_ext` of its dielectric.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    pub n: Vec3,
    pub eta: f32,
}

/// The flat boundary of one medium: its distinct plane orientations.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlatBoundary {
    pub planes: Vec<Plane>,
}

/// Per medium of `scene`: its flat boundary, or `None` where the manifold connection does not
/// apply (the scene has neither a directional light nor an environment, the medium does not sample emitters, is not
/// enclosed by a dielectric, or some enclosing shape is curved, shading-normal interpolated,
/// rough, or has too many orientations). Where it is `None` the connection draws no samples, so
/// `connection = complete` renders exactly what `paper` renders.
pub fn flat_boundaries(scene: &Scene) -> Vec<Option<FlatBoundary>> {
    let directional = scene.emitters.iter().any(|e| match e {
        SceneEmitter::Other(e) => matches!(e, Emitter::Directional(_)) || e.is_environment(),
        SceneEmitter::Area { .. } => false,
    });
    (0..scene.media.len() as u32).map(|m| if directional { flat_boundary(scene, m) } else { None }).collect()
}

fn flat_boundary(scene: &Scene, medium: u32) -> Option<FlatBoundary> {
    if !scene.media[medium as usize].sample_emitters {
        return None;
    }
    let mut planes: Vec<Plane> = Vec::new();
    let mut enclosed = false;
    for s in scene.shapes.iter().filter(|s| s.interior == Some(medium) && s.exterior.is_none()) {
        let eta = match &scene.bsdfs[s.bsdf as usize] {
            Bsdf::Dielectric(d) => d.eta,
            Bsdf::RoughDielectric(_) => return None,
            _ => continue,
        };
        let Geometry::Mesh(mesh) = &s.geometry else { return None };
        enclosed = true;
        for (prim, idx) in mesh.indices.iter().enumerate() {
            let [p0, p1, p2] = mesh.vertices(prim as u32);
            let mut n = (p1 - p0).cross(p2 - p0).normalize_or_zero();
            if n == Vec3::ZERO {
                continue; // degenerate: never hit
            }
            if mesh.flip_normals {
                n = -n;
            }
            // Flat shading: every vertex normal equals the face normal.
            if !mesh.normals.is_empty() {
                let flat = idx.iter().all(|&i| {
                    let vn = mesh.normals[i as usize];
                    let vn = if mesh.flip_normals { -vn } else { vn };
                    vn.dot(n) > SAME_NORMAL
                });
                if !flat {
                    return None;
                }
            }
            if !planes.iter().any(|q| q.eta == eta && q.n.dot(n) > SAME_NORMAL) {
                planes.push(Plane { n, eta });
                if planes.len() > MAX_PLANES {
                    return None;
                }
            }
        }
    }
    (enclosed && !planes.is_empty()).then_some(FlatBoundary { planes })
}

/// Refraction of the light direction through a plane (Snell, the closed form of the constraint).
#[derive(Clone, Copy, Debug)]
pub struct Refraction {
    /// Unit direction from the boundary point into the medium (towards the medium vertex).
    pub omega_in: Vec3,
    /// Fresnel reflectance `F` at this angle.
    pub fresnel: f32,
    /// `cos θ_l = n·omega_l > 0` (outside).
    pub cos_l: f32,
    /// `|cos θ_in| = |n·omega_in|` (inside).
    pub cos_in: f32,
}

/// Refract the unit direction towards the light `omega_l` (outside) into the medium through
/// `plane`; `None` when the light is behind the plane or all of it is reflected.
pub fn refract_into(plane: &Plane, omega_l: Vec3) -> Option<Refraction> {
    let cos_l = plane.n.dot(omega_l);
    if !(cos_l > 0.0) {
        return None;
    }
    let frame = Frame::from_normal(plane.n);
    let wl = frame.to_local(omega_l);
    let (f, cos_t, _, eta_ti) = fresnel(wl.z, plane.eta);
    if !(f < 1.0) {
        return None;
    }
    let omega_in = frame.to_world(refract(wl, cos_t, eta_ti)).normalize();
    let cos_in = -plane.n.dot(omega_in);
    (cos_in > 0.0).then_some(Refraction { omega_in, fresnel: f, cos_l, cos_in })
}

/// Is `si` (hit from inside `medium` along `d`) a point of `plane`'s orientation on a boundary
/// that encloses `medium` with the same dielectric?
pub fn on_plane(scene: &Scene, si: &SurfaceInteraction, medium: u32, d: Vec3, plane: &Plane) -> bool {
    let s = &scene.shapes[si.shape as usize];
    s.interior == Some(medium)
        && s.exterior.is_none()
        && d.dot(si.n) > 0.0
        && si.n.dot(plane.n) > SAME_NORMAL
        && matches!(scene.bsdf(si), Bsdf::Dielectric(b) if b.eta == plane.eta)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Snell's law and the reciprocity of the refracted direction, in f64 against f32.
    #[test]
    fn refraction_obeys_snell() {
        let plane = Plane { n: Vec3::new(0.3, -0.2, 0.9).normalize(), eta: 1.33 };
        for k in 0..50 {
            let a = k as f32 * 0.37;
            let omega_l =
                (plane.n + Vec3::new(a.cos(), a.sin(), 0.5 * (2.0 * a).sin()) * (k as f32 * 0.05)).normalize();
            let Some(r) = refract_into(&plane, omega_l) else { continue };
            let sin_l = (1.0 - (r.cos_l as f64).powi(2)).max(0.0).sqrt();
            let sin_in = (1.0 - (r.cos_in as f64).powi(2)).max(0.0).sqrt();
            assert!((sin_l - 1.33 * sin_in).abs() < 1e-5, "{sin_l} vs 1.33 · {sin_in}");
            // omega_l, omega_in and n are coplanar.
            assert!(plane.n.cross(omega_l).dot(r.omega_in).abs() < 1e-5);
            assert!((r.omega_in.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn total_internal_reflection_and_backside_fail() {
        let plane = Plane { n: Vec3::Z, eta: 1.0 / 1.5 };
        // From a denser outside into a rarer medium beyond the critical angle.
        let grazing = Vec3::new(0.9, 0.0, 0.2).normalize();
        assert!(refract_into(&plane, grazing).is_none());
        assert!(refract_into(&Plane { n: Vec3::Z, eta: 1.5 }, -Vec3::Z).is_none());
        let r = refract_into(&Plane { n: Vec3::Z, eta: 1.0 }, Vec3::new(0.6, 0.0, 0.8)).unwrap();
        assert!((r.omega_in - Vec3::new(-0.6, 0.0, -0.8)).length() < 1e-6 && r.fresnel == 0.0);
    }
}

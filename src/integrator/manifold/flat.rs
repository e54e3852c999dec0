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
use crate::interaction::SurfaceInteraction;
use crate::math::{Frame, Vec3};
use crate::scene::world::Scene;
use crate::shape::Geometry;

use super::planes::same_offset;
pub use super::planes::{FlatBoundary, Plane, Support, MAX_PLANES, SAME_NORMAL};

/// Per medium of `scene`: its flat boundary, or `None` where the manifold connection does not
/// apply (the scene has no emitter, the medium does not sample emitters, is not
/// enclosed by a dielectric, or some enclosing shape is curved, shading-normal interpolated,
/// rough, or has too many orientations). Where it is `None` the connection draws no samples, so
/// `connection = complete` renders exactly what `paper` renders.
pub fn flat_boundaries(scene: &Scene) -> Vec<Option<FlatBoundary>> {
    let lit = !scene.emitters.is_empty();
    (0..scene.media.len() as u32).map(|m| if lit { flat_boundary(scene, m) } else { None }).collect()
}

/// A boundary triangle's outward face normal, if the mesh is flat-shaded there.
pub(super) enum FaceNormal {
    /// Every vertex normal (if any) equals the face normal `n` (flip_normals applied).
    Flat(Vec3),
    /// Zero area: never hit, ignored.
    Degenerate,
    /// Interpolated normals differ from the face normal: not a flat facet.
    Curved,
}

/// The face normal of triangle `prim` (vertex indices `idx`) of `mesh`, and whether the mesh is
/// flat-shaded there (shared by the smooth and the rough flat boundaries).
pub(super) fn flat_face_normal(mesh: &crate::shape::mesh::Mesh, prim: usize, idx: &[u32; 3]) -> FaceNormal {
    let [p0, p1, p2] = mesh.vertices(prim as u32);
    let mut n = (p1 - p0).cross(p2 - p0).normalize_or_zero();
    if n == Vec3::ZERO {
        return FaceNormal::Degenerate;
    }
    if mesh.flip_normals {
        n = -n;
    }
    // Flat shading: every vertex normal equals the face normal.
    let flat = mesh.normals.is_empty()
        || idx.iter().all(|&i| {
            let vn = mesh.normals[i as usize];
            let vn = if mesh.flip_normals { -vn } else { vn };
            vn.dot(n) > SAME_NORMAL
        });
    if flat {
        FaceNormal::Flat(n)
    } else {
        FaceNormal::Curved
    }
}

fn flat_boundary(scene: &Scene, medium: u32) -> Option<FlatBoundary> {
    if !scene.media[medium as usize].sample_emitters {
        return None;
    }
    let mut planes: Vec<Plane> = Vec::new();
    let mut supports: Vec<Support> = Vec::new();
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
            let p0 = mesh.vertices(prim as u32)[0];
            let n = match flat_face_normal(mesh, prim, idx) {
                FaceNormal::Flat(n) => n,
                FaceNormal::Degenerate => continue, // never hit
                FaceNormal::Curved => return None,
            };
            if !planes.iter().any(|q| q.eta == eta && q.n.dot(n) > SAME_NORMAL) {
                planes.push(Plane { n, eta });
                if planes.len() > MAX_PLANES {
                    return None;
                }
            }
            let offset = n.dot(p0);
            if supports.len() <= MAX_PLANES
                && !supports
                    .iter()
                    .any(|s| s.plane.eta == eta && s.plane.n.dot(n) > SAME_NORMAL && same_offset(offset, s.offset))
            {
                // One past the limit marks "too many" (cleared below).
                supports.push(Support { plane: Plane { n, eta }, offset });
            }
        }
    }
    if supports.len() > MAX_PLANES {
        supports.clear();
    }
    (enclosed && !planes.is_empty()).then_some(FlatBoundary { planes, supports })
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

/// The refraction point `x_k` on the supporting plane `s` of the path `x_j → x_k → y` from a
/// point `x_j` inside (below the plane) to a point `y` outside (above it); `None` when `x_j` or
/// `y` is on the wrong side. On a plane the solution is unique (Fermat's principle: the optical
/// length `η_int |x_j x_k| + η_ext |x_k y|` is strictly convex in `x_k`) and lies in the plane
/// of incidence, on the segment between the feet of `x_j` and `y`. With `a`, `b` their distances
/// to the plane, `D` the distance between the feet and `s` that of `x_k` from `x_j`'s foot,
/// Snell's law `η sin θ_in = sin θ_l` reads
///
/// ```text
/// g(s) = η s / √(a² + s²) − (D − s) / √(b² + (D − s)²) = 0,
/// ```
///
/// `g` increasing from `g(0) ≤ 0` to `g(D) ≥ 0`: Newton's method safeguarded by bisection,
/// started from the paraxial solution `s = a D / (a + η b)`; in f64.
pub fn solve_point(s: &Support, x_j: Vec3, y: Vec3) -> Option<Vec3> {
    let n = s.plane.n.as_dvec3();
    let (x_j, y) = (x_j.as_dvec3(), y.as_dvec3());
    let offset = s.offset as f64;
    let (a, b) = (offset - n.dot(x_j), n.dot(y) - offset);
    if !(a > 0.0 && b > 0.0) {
        return None;
    }
    let foot_j = x_j + n * a;
    let v = (y - n * b) - foot_j;
    let d = v.length();
    if !(d > 1e-12 * (a + b)) {
        return Some(foot_j.as_vec3());
    }
    let u = v / d;
    let eta = s.plane.eta as f64;
    let (mut lo, mut hi) = (0.0f64, d);
    let mut x = a * d / (a + eta * b);
    for _ in 0..100 {
        let (ra, rb) = ((a * a + x * x).sqrt(), (b * b + (d - x) * (d - x)).sqrt());
        let g = eta * x / ra - (d - x) / rb;
        if g > 0.0 {
            hi = x;
        } else {
            lo = x;
        }
        let dg = eta * a * a / (ra * ra * ra) + b * b / (rb * rb * rb);
        let mut next = x - g / dg;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let done = (next - x).abs() <= 1e-13 * d || hi - lo <= 1e-13 * d;
        x = next;
        if done {
            break;
        }
    }
    Some((foot_j + u * x).as_vec3())
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

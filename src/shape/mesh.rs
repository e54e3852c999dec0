//! World-space triangle mesh: vertex data after `to_world`, area-weighted sampling, and the
//! surface interaction of a hit (geometric normal from the winding, interpolated shading normal).
//!
//! Without vertex normals in the file (and with `face_normals = false`), vertex normals are
//! recomputed by angle weighting as Mitsuba's `Mesh::recompute_vertex_normals` does.
//!
//! The shading frame's tangent `s` follows dp/du as Mitsuba 3.9.1 computes it (checked against its
//! hits in `tests/plugins/shading_frame.rs`): with uvs, dp/du of the triangle's uv parametrisation, or the
//! first vector of `coordinate_system(face normal before flip_normals)` where the uv triangle is
//! degenerate; without uvs, uv = (b1, b2) and dp/du = p1 − p0; then Gram–Schmidt against the
//! shading normal (`interaction::shading_frame`). Face normals and uv tangents do not change per
//! sample: they are computed once at load.

use super::accel::bvh8::LaneShade;
use super::mesh_data::MeshData;
use super::{obj, ply, serialized, Geometry};
use crate::emitter::distribution::Distribution1D;
use crate::interaction::{shading_frame_a, PositionSample, SurfaceInteraction};
use crate::math::{warp, Aabb, Frame, Mat4, Vec2, Vec3};
use crate::scene::desc::ObjectDesc;
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};
use glam::Vec3A;
use rayon::prelude::*;

/// Largest mesh (triangles) that stores a shading frame per triangle (48 bytes each, 12 MB at most).
pub const MAX_FACE_FRAMES: usize = 1 << 18;
/// Largest mesh (triangles) that stores its triangles for area sampling (64 bytes each, and 24 more
/// for the corner uvs of a mesh with uvs: 1.4 MB at most): area lights are rectangles, cubes and
/// small meshes; larger ones read the vertex arrays.
pub const MAX_SAMPLE_TRIANGLES: usize = 1 << 14;

/// What sampling a point on one triangle reads, in one place: a corner, the two edges leaving it
/// and the normal (flipped with `flip_normals`), in 16-byte vectors (four aligned loads; the
/// point `p0 + e0 b1 + e1 b2` is the same per-lane arithmetic as in `Vec3`, so the same bits).
/// The corners' uvs are apart (`Mesh::sample_uvs`): only a textured emitter reads them.
#[derive(Clone, Copy, Debug)]
struct SampleTriangle {
    p0: Vec3A,
    e0: Vec3A,
    e1: Vec3A,
    n: Vec3A,
}

#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    /// One per vertex, or empty when `face_normals` is set.
    pub normals: Vec<Vec3>,
    /// One per vertex, or empty (then uv = barycentrics (b1, b2) as in Mitsuba).
    pub uvs: Vec<Vec2>,
    pub indices: Vec<[u32; 3]>,
    pub flip_normals: bool,
    /// Unit face normal per triangle from the winding, flipped with `flip_normals` (zero if
    /// degenerate): the geometric normal of every hit and sample on the triangle, negated once at
    /// load instead of at each of them.
    pub face_normals: Vec<Vec3>,
    /// dp/du of each triangle's uv parametrisation, or where the uv triangle is degenerate the
    /// first vector of `coordinate_system(face normal before flip_normals)` (both resolved at
    /// load); empty when the mesh has no uvs (then dp/du = p1 − p0 of the barycentric uv).
    pub face_dp_du: Vec<Vec3>,
    /// The shading frame of each triangle when it is the same at every point of every triangle
    /// (no vertex normals, or the three vertex normals of each triangle equal, as on `rectangle`,
    /// `cube` and flat-shaded files) and the mesh has at most [`MAX_FACE_FRAMES`] triangles;
    /// empty otherwise (then it is computed per hit). Stored as `[s, t, n]` in 16-byte vectors,
    /// as the hit record computes with them.
    face_frames: Vec<[Vec3A; 3]>,
    /// Per triangle, what area sampling reads (meshes up to [`MAX_SAMPLE_TRIANGLES`]; else empty).
    sample_triangles: Vec<SampleTriangle>,
    /// Per triangle, the corners' uvs, for meshes with uvs up to [`MAX_SAMPLE_TRIANGLES`]
    /// triangles (else empty: read through the indices).
    sample_uvs: Vec<[Vec2; 3]>,
    /// Triangles by area (alias table, for area sampling).
    area_distr: Distribution1D,
    /// `1 / surface_area()`: the area density of [`Mesh::sample_position`], the same division
    /// done once.
    inv_area: f32,
    /// Whether points sampled on the mesh need their uv: cleared by the scene when the mesh is an
    /// area emitter of constant radiance (nothing then reads it); `sample_position` then leaves uv
    /// zero.
    pub sample_uv: bool,
    /// Whether hits need their uv: cleared by the scene when neither the shape's BSDF nor its area
    /// emitter reads a spatially varying texture; `interaction` then leaves uv zero instead of
    /// interpolating it.
    pub hit_uv: bool,
    /// The plane of a flat mesh (meshes up to [`MAX_SAMPLE_TRIANGLES`]; `None` otherwise), which
    /// the volume integrators' emitter-skip test reads (`volpath::surely_usable`).
    pub plane: Option<MeshPlane>,
    /// Set for Mitsuba's `rectangle` ([`Mesh::set_parallelogram`]): area sampling maps the sample
    /// onto the whole parallelogram, as Mitsuba's rectangle does, instead of picking a triangle.
    parallelogram: Option<Box<Parallelogram>>,
}

/// A parallelogram mesh's area sampling: `p = p0 + u·eu + v·ev` for the sample `(u, v)`, normal
/// `n`, uv = the sample (Mitsuba's `Rectangle::sample_position`: `to_world(2u − 1, 2v − 1, 0)`).
#[derive(Clone, Copy, Debug)]
struct Parallelogram {
    p0: Vec3A,
    eu: Vec3A,
    ev: Vec3A,
    n: Vec3A,
}

/// The plane a flat mesh lies in (`rectangle`, a flat-shaded quad): every face normal within
/// `1e-5` of `n` and every vertex within `1e-6 · scale` of the plane `n · x = c`.
#[derive(Clone, Copy, Debug)]
pub struct MeshPlane {
    /// The unit normal as area sampling returns it (flipped with `flip_normals`).
    pub n: Vec3,
    pub c: f32,
    /// A sphere around the vertices: every sampled point lies within `radius` of `center` (up to
    /// rounding).
    pub center: Vec3,
    pub radius: f32,
    /// 1 + the largest vertex coordinate magnitude (the scale of the rounding in sampled points).
    pub scale: f32,
}

impl Mesh {
    /// Transform loaded data into world space. `face_normals` drops vertex normals.
    pub fn new(data: MeshData, to_world: &Mat4, face_normals: bool, flip_normals: bool) -> Mesh {
        let positions: Vec<Vec3> = data.positions.par_iter().map(|p| to_world.transform_point3(*p)).collect();
        // Face normal and area from one cross product per triangle.
        let (face_n, areas): (Vec<Vec3>, Vec<f32>) = data
            .indices
            .par_iter()
            .map(|idx| {
                let [p0, p1, p2] = idx.map(|i| positions[i as usize]);
                let c = (p1 - p0).cross(p2 - p0);
                (c.normalize_or_zero(), 0.5 * c.length())
            })
            .unzip();
        let face_dp_du = if data.uvs.is_empty() {
            Vec::new()
        } else {
            let mut dp_du = uv_tangents(&positions, &data.uvs, &data.indices);
            // A degenerate uv triangle: coordinate_system(face normal before flipping).
            dp_du.par_iter_mut().zip(&face_n).for_each(|(d, &n)| {
                if *d == Vec3::ZERO {
                    *d = Frame::from_normal(n).s;
                }
            });
            dp_du
        };
        let vertex_normals = || {
            if face_normals {
                Vec::new()
            } else if data.normals.is_empty() {
                recompute_vertex_normals(&positions, &data.indices, &face_n)
            } else {
                let inv_t = to_world.inverse().transpose();
                data.normals
                    .par_iter()
                    .map(|n| {
                        let m = inv_t.transform_vector3(*n);
                        let l = m.length();
                        if l > 0.0 {
                            m / l
                        } else {
                            m
                        }
                    })
                    .collect()
            }
        };
        let (normals, area_distr) = rayon::join(vertex_normals, || Distribution1D::new(&areas));
        let face_n = if flip_normals { face_n.par_iter().map(|&n| -n).collect() } else { face_n };
        let mut mesh = Mesh {
            positions,
            normals,
            uvs: data.uvs,
            indices: data.indices,
            flip_normals,
            face_normals: face_n,
            face_dp_du,
            face_frames: Vec::new(),
            sample_triangles: Vec::new(),
            sample_uvs: Vec::new(),
            inv_area: 1.0 / (area_distr.sum() as f32),
            area_distr,
            sample_uv: true,
            hit_uv: true,
            plane: None,
            parallelogram: None,
        };
        mesh.face_frames = mesh.flat_frames();
        mesh.plane = mesh.flat_plane();
        if mesh.indices.len() <= MAX_SAMPLE_TRIANGLES {
            mesh.sample_triangles = (0..mesh.indices.len() as u32).map(|prim| mesh.sample_triangle(prim)).collect();
            if !mesh.uvs.is_empty() {
                mesh.sample_uvs = mesh.indices.iter().map(|idx| idx.map(|i| mesh.uvs[i as usize])).collect();
            }
        }
        mesh
    }

    /// Sample area as Mitsuba's `rectangle` does: the sample mapped linearly onto the
    /// parallelogram spanned at vertex 0 by the edges to vertices 1 and 2 (`rectangle_data`'s
    /// corners (−1, −1), (1, −1), (−1, 1)), uv = the sample, normal the face normal; the same
    /// density (1 / area) as the triangle pick it replaces. For a mesh of four vertices whose
    /// fourth is `v1 + v2 − v0` (not checked beyond a debug assertion).
    pub fn set_parallelogram(&mut self) {
        let [p0, p1, p2] = [0, 1, 2].map(|i| Vec3A::from(self.positions[i]));
        debug_assert!({
            let p3 = Vec3A::from(self.positions[3]);
            (p1 + p2 - p0 - p3).length() <= 1e-4 * (1.0 + p3.abs().max_element())
        });
        self.parallelogram =
            Some(Box::new(Parallelogram { p0, eu: p1 - p0, ev: p2 - p0, n: Vec3A::from(self.face_normals[0]) }));
    }

    /// The geometric normal (flipped with `flip_normals`) and dp/du of triangle `prim`: both
    /// constant over the triangle.
    #[inline(always)]
    fn normal_and_dp_du(&self, prim: u32) -> (Vec3, Vec3) {
        let n = self.face_normals[prim as usize];
        let dp_du = if self.uvs.is_empty() {
            // uv = (b1, b2): dp/du = p1 − p0.
            let idx = self.indices[prim as usize];
            self.positions[idx[1] as usize] - self.positions[idx[0] as usize]
        } else {
            self.face_dp_du[prim as usize]
        };
        (n, dp_du)
    }

    /// The shading normal at barycentrics (b0, b1, b2) of the triangle with vertices `idx`: the interpolated vertex
    /// normal (flipped with `flip_normals`), or the geometric normal `n` without vertex normals or
    /// where the interpolation vanishes.
    #[inline(always)]
    fn shading_normal(&self, idx: [u32; 3], n: Vec3A, b0: f32, b1: f32, b2: f32) -> Vec3A {
        self.shading_normal_from(|| idx.map(|i| self.normals[i as usize]), n, b0, b1, b2)
    }

    /// [`Self::shading_normal`] with the triangle's vertex normals from `vertex_normals` (called
    /// only when the mesh has vertex normals).
    #[inline(always)]
    fn shading_normal_from(
        &self,
        vertex_normals: impl FnOnce() -> [Vec3; 3],
        n: Vec3A,
        b0: f32,
        b1: f32,
        b2: f32,
    ) -> Vec3A {
        if self.normals.is_empty() {
            return n;
        }
        let [n0, n1, n2] = vertex_normals().map(Vec3A::from);
        let sh_n = (n0 * b0 + n1 * b1 + n2 * b2).normalize_or_zero();
        if sh_n == Vec3A::ZERO {
            n
        } else if self.flip_normals {
            -sh_n
        } else {
            sh_n
        }
    }

    /// Per-triangle shading frames when every triangle's shading normal is constant (see
    /// `face_frames`), else empty. With equal vertex normals the frame is built from the vertex
    /// normal itself: the interpolation `normalize(b0 n + b1 n + b2 n)` is the same vector up to
    /// rounding.
    fn flat_frames(&self) -> Vec<[Vec3A; 3]> {
        if self.indices.len() > MAX_FACE_FRAMES {
            return Vec::new();
        }
        let flat = self.normals.is_empty()
            || self.indices.par_iter().all(|idx| {
                let [n0, n1, n2] = idx.map(|i| self.normals[i as usize]);
                n0 == n1 && n1 == n2
            });
        if !flat {
            return Vec::new();
        }
        (0..self.indices.len() as u32)
            .into_par_iter()
            .map(|prim| {
                let (n, dp_du) = self.normal_and_dp_du(prim);
                shading_frame_a(self.shading_normal(self.indices[prim as usize], n.into(), 1.0, 0.0, 0.0), dp_du.into())
            })
            .collect()
    }

    /// [`Mesh::plane`]: `None` for a mesh that is large, not flat, or has a degenerate triangle.
    fn flat_plane(&self) -> Option<MeshPlane> {
        if self.indices.len() > MAX_SAMPLE_TRIANGLES {
            return None;
        }
        // (Flipped or not, the normals' differences have the same lengths.)
        let n = *self.face_normals.first()?;
        if !(n.length_squared() > 0.5) || self.face_normals.iter().any(|m| !((*m - n).length() <= 1e-5)) {
            return None;
        }
        let vertices = || self.indices.iter().flatten().map(|&i| self.positions[i as usize]);
        let c = n.dot(vertices().next()?);
        let scale = 1.0 + vertices().map(|p| p.abs().max_element()).fold(0.0, f32::max);
        if !scale.is_finite() || vertices().any(|p| !((n.dot(p) - c).abs() <= 1e-6 * scale)) {
            return None;
        }
        let (lo, hi) = vertices().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(p), hi.max(p)));
        let center = (lo + hi) * 0.5;
        let radius = vertices().map(|p| (p - center).length()).fold(0.0, f32::max);
        Some(MeshPlane { n, c, center, radius, scale })
    }

    pub fn surface_area(&self) -> f32 {
        self.area_distr.sum() as f32
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    #[inline]
    pub fn vertices(&self, prim: u32) -> [Vec3; 3] {
        self.indices[prim as usize].map(|i| self.positions[i as usize])
    }

    pub fn bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for p in &self.positions {
            b.expand(*p);
        }
        b
    }

    /// The point at barycentrics `(b1, b2)` of triangle `prim` and its geometric normal (flipped
    /// with `flip_normals`): the part of [`Mesh::interaction`] that a shadow ray crossing the mesh
    /// needs (`walk::shadow_crossing`).
    #[inline(always)]
    pub fn point_and_normal(&self, prim: u32, b1: f32, b2: f32) -> (Vec3, Vec3) {
        let [p0, p1, p2] = self.indices[prim as usize].map(|i| self.positions[i as usize]);
        let b0 = 1.0 - b1 - b2;
        (p0 * b0 + p1 * b1 + p2 * b2, self.face_normals[prim as usize])
    }

    /// The corner, edges and normal of triangle `prim` (see [`SampleTriangle`]).
    #[inline(always)]
    fn sample_triangle(&self, prim: u32) -> SampleTriangle {
        let [p0, p1, p2] = self.indices[prim as usize].map(|i| Vec3A::from(self.positions[i as usize]));
        SampleTriangle { p0, e0: p1 - p0, e1: p2 - p0, n: self.face_normals[prim as usize].into() }
    }

    /// Fill a surface interaction for a hit on triangle `prim` at barycentrics (b1, b2).
    ///
    /// Computed in 16-byte vectors (`Vec3A`: whole-register arithmetic instead of the shuffles
    /// that 12-byte `Vec3`s need), with the same operations in the same order as the `Vec3` forms
    /// ([`Mesh::point_and_normal`], [`shading_frame`], `Frame::to_local`): the same record bit for bit.
    #[inline(always)]
    pub fn interaction(&self, prim: u32, b1: f32, b2: f32, t: f32, ray_d: Vec3) -> SurfaceInteraction {
        let idx = self.indices[prim as usize];
        let v = idx.map(|i| Vec3A::from(self.positions[i as usize]));
        let face_n = self.face_normals[prim as usize];
        self.interaction_with(prim, v, face_n, || idx.map(|i| self.normals[i as usize]), (b1, b2, t), ray_d)
    }

    /// [`Self::interaction`] from a BVH lane's record and the leaf's copy of the vertices (the
    /// same values as the mesh's: the same hit record, bit for bit, without reading the mesh's
    /// indices, positions, normals and face normals, which a large mesh holds in cold memory).
    #[inline(always)]
    pub fn interaction_lane(
        &self,
        lane: &LaneShade,
        v: [Vec3A; 3],
        b1: f32,
        b2: f32,
        t: f32,
        ray_d: Vec3,
    ) -> SurfaceInteraction {
        self.interaction_with(lane.prim, v, lane.face_n, || lane.n, (b1, b2, t), ray_d)
    }

    /// The record of a BVH lane holding triangle `prim` of this mesh (shape `shape`).
    pub fn lane_shade(&self, shape: u32, prim: u32) -> LaneShade {
        let n = if self.normals.is_empty() {
            [Vec3::ZERO; 3]
        } else {
            self.indices[prim as usize].map(|i| self.normals[i as usize])
        };
        LaneShade { shape, prim, n, face_n: self.face_normals[prim as usize] }
    }

    /// The hit record of triangle `prim` with vertices `v`, face normal `face_n` (flipped with
    /// `flip_normals`, as `face_normals` holds it) and vertex normals from `vertex_normals`, at barycentrics `(b1, b2)` and distance `t`.
    #[inline(always)]
    fn interaction_with(
        &self,
        prim: u32,
        [p0, p1, p2]: [Vec3A; 3],
        face_n: Vec3,
        vertex_normals: impl FnOnce() -> [Vec3; 3],
        (b1, b2, t): (f32, f32, f32),
        ray_d: Vec3,
    ) -> SurfaceInteraction {
        let b0 = 1.0 - b1 - b2;
        let p = p0 * b0 + p1 * b1 + p2 * b2;
        let n = face_n;
        let uv = if !self.hit_uv {
            Vec2::ZERO
        } else if self.uvs.is_empty() {
            Vec2::new(b1, b2)
        } else {
            let [u0, u1, u2] = self.indices[prim as usize].map(|i| self.uvs[i as usize]);
            u0 * b0 + u1 * b1 + u2 * b2
        };
        let [sh_s, sh_t, sh_n] = match self.face_frames.get(prim as usize) {
            Some(frame) => *frame,
            None => {
                // dp/du as `normal_and_dp_du` computes it.
                let dp_du = if self.uvs.is_empty() { p1 - p0 } else { Vec3A::from(self.face_dp_du[prim as usize]) };
                shading_frame_a(self.shading_normal_from(vertex_normals, n.into(), b0, b1, b2), dp_du)
            }
        };
        // `Frame::to_local(-ray_d)`.
        let v = -Vec3A::from(ray_d);
        let wi = Vec3::new(v.dot(sh_s), v.dot(sh_t), v.dot(sh_n));
        let sh_frame = Frame { s: sh_s.into(), t: sh_t.into(), n: sh_n.into() };
        SurfaceInteraction { t, p: p.into(), n, sh_frame, uv, wi, shape: 0, prim }
    }

    /// Uniform by area: pick a triangle by area, then a uniform point on it, `p0 + e0 b1 + e1 b2`
    /// as Mitsuba's `Mesh::sample_position` computes it (from the corner and the two edges). The
    /// uv is interpolated from the corners' uvs (`(0,0) (1,0) (0,1)` without uvs: exactly
    /// (b1, b2)), or left zero where nothing reads it (`sample_uv`).
    #[inline(always)]
    pub fn sample_position(&self, sample: Vec2) -> PositionSample {
        if let Some(pg) = &self.parallelogram {
            let p = pg.p0 + pg.eu * sample.x + pg.ev * sample.y;
            let uv = if self.sample_uv { sample } else { Vec2::ZERO };
            return PositionSample { p: p.into(), n: pg.n.into(), uv, pdf: self.inv_area };
        }
        // A mesh of zero area has no valid distribution: its first triangle (pdf 1/0 = inf).
        let (prim, sx, _) = self.area_distr.sample(sample.x).unwrap_or((0, 0.5, 0.0));
        let b = warp::square_to_uniform_triangle(Vec2::new(sx, sample.y));
        let computed;
        let tri = match self.sample_triangles.get(prim) {
            Some(tri) => tri,
            None => {
                computed = self.sample_triangle(prim as u32);
                &computed
            }
        };
        let p = tri.p0 + tri.e0 * b.x + tri.e1 * b.y;
        let uv = if !self.sample_uv {
            Vec2::ZERO
        } else if self.uvs.is_empty() {
            // (0,0) (1,0) (0,1) interpolated: 0 w + 1 b1 + 0 b2 = b1 and 0 w + 0 b1 + 1 b2 = b2
            // exactly (w, b1, b2 are non-negative, so each zero product is +0).
            b
        } else {
            let uv = match self.sample_uvs.get(prim) {
                Some(uv) => *uv,
                None => self.indices[prim].map(|i| self.uvs[i as usize]),
            };
            uv[0] * (1.0 - b.x - b.y) + uv[1] * b.x + uv[2] * b.y
        };
        PositionSample { p: p.into(), n: tri.n.into(), uv, pdf: self.inv_area }
    }
}

impl super::Shape {
    /// A mesh shape on its own: BSDF 0, no emitter, no media (for benchmarks and tests).
    pub fn from_mesh(mesh: Mesh) -> super::Shape {
        super::Shape {
            geometry: Geometry::Mesh(mesh),
            plugin: "mesh".into(),
            id: None,
            bsdf: 0,
            emitter: None,
            interior: None,
            exterior: None,
        }
    }
}

/// dp/du of each triangle's uv parametrisation (Mitsuba's `Mesh::compute_surface_interaction`):
/// with dp0 = p1 − p0, dp1 = p2 − p0, duv0 = uv1 − uv0, duv1 = uv2 − uv0,
/// dp/du = (duv1.y dp0 − duv0.y dp1) / det, det = duv0.x duv1.y − duv0.y duv1.x; zero when det = 0.
pub fn uv_tangents(positions: &[Vec3], uvs: &[Vec2], indices: &[[u32; 3]]) -> Vec<Vec3> {
    indices
        .iter()
        .map(|idx| {
            let [p0, p1, p2] = idx.map(|i| positions[i as usize]);
            let [u0, u1, u2] = idx.map(|i| uvs[i as usize]);
            let (dp0, dp1) = (p1 - p0, p2 - p0);
            let (duv0, duv1) = (u1 - u0, u2 - u0);
            let det = duv0.x * duv1.y - duv0.y * duv1.x;
            let dp_du = (dp0 * duv1.y - dp1 * duv0.y) / det;
            if det != 0.0 && dp_du.is_finite() {
                dp_du
            } else {
                Vec3::ZERO
            }
        })
        .collect()
}

/// Angle-weighted vertex normals (Mitsuba's `recompute_vertex_normals`), from the unit face normals:
/// each corner adds its face normal times the corner angle `acos(d0 · d1)` (`d0`, `d1`: the unit
/// edges leaving the corner). The angles are computed in parallel, the sums in face order.
pub fn recompute_vertex_normals(positions: &[Vec3], indices: &[[u32; 3]], face_normals: &[Vec3]) -> Vec<Vec3> {
    let angles: Vec<[f32; 3]> = indices
        .par_iter()
        .map(|idx| {
            let [p0, p1, p2] = idx.map(|i| positions[i as usize]);
            // Unit edges e01, e12, e20; corner k's edges are e_k(k+1) and −e_(k+2)k.
            let (e01, e12, e20) =
                ((p1 - p0).normalize_or_zero(), (p2 - p1).normalize_or_zero(), (p0 - p2).normalize_or_zero());
            [-e01.dot(e20), -e12.dot(e01), -e20.dot(e12)].map(crate::math::fast::acos)
        })
        .collect();
    let mut normals = vec![Vec3::ZERO; positions.len()];
    for ((idx, &face_n), angle) in indices.iter().zip(face_normals).zip(&angles) {
        if face_n == Vec3::ZERO {
            continue;
        }
        for k in 0..3 {
            if angle[k].is_finite() {
                normals[idx[k] as usize] += face_n * angle[k];
            }
        }
    }
    normals.par_iter_mut().for_each(|n| {
        let l = n.length();
        *n = if l > 0.0 { *n / l } else { Vec3::Z };
    });
    normals
}

/// A mesh loaded from a file (`obj`, `ply`, `serialized`): the `filename` and `face_normals`
/// parameters shared by the three, and the format's own (read by its loader module).
pub fn from_file_props(
    obj: &ObjectDesc,
    resolver: &FileResolver,
    to_world: &Mat4,
    flip_normals: bool,
) -> Result<Geometry> {
    let props = &obj.props;
    let Some(name) = props.string_opt("filename")? else {
        return Err(Error::at(&obj.pos, format!("shape \"{}\" requires a \"filename\"", obj.plugin)));
    };
    let path = resolver.resolve_at(&name, &props.pos_of("filename"))?;
    let face_normals = props.bool("face_normals", false)?;
    let data = match obj.plugin.as_str() {
        "obj" => obj::from_props(props, &path)?,
        "ply" => ply::from_props(props, &path)?,
        _ => serialized::from_props(props, &path)?,
    };
    Ok(Geometry::Mesh(Mesh::new(data, to_world, face_normals, flip_normals)))
}

#[cfg(test)]
mod tests {
    use crate::shape::Geometry;

    /// The hit record of `Mesh::interaction` (computed in `Vec3A`) is the `Vec3` arithmetic it
    /// stands for, bit for bit: point, normal, shading frame (Gram–Schmidt of dp/du against the
    /// interpolated normal, `interaction::shading_frame`) and `wi`, on a smooth mesh (per-hit frames)
    /// and a flat one (frames stored at load), with and without uvs and `flip_normals`.
    #[test]
    fn hit_record_is_the_vec3_arithmetic_bit_for_bit() {
        use super::{Mesh, MeshData};
        use crate::math::{Frame, Mat4, Vec2, Vec3};
        // A 6×6 grid bent into a bump, vertex normals tilted per vertex (or none: flat).
        let (w, h) = (6u32, 6u32);
        let mut data = MeshData::default();
        for j in 0..h {
            for i in 0..w {
                let (x, z) = (i as f32 * 0.37 - 0.9, j as f32 * 0.29 - 0.7);
                data.positions.push(Vec3::new(x, 0.3 * (x * 2.1).sin() * (z * 1.7).cos(), z));
                data.normals.push(Vec3::new(0.2 * x, 1.0, -0.3 * z * x).normalize());
                data.uvs.push(Vec2::new(i as f32 * 0.21 + 0.1 * j as f32, j as f32 * 0.17));
            }
        }
        for j in 0..h - 1 {
            for i in 0..w - 1 {
                let v = j * w + i;
                data.indices.push([v, v + 1, v + w]);
                data.indices.push([v + 1, v + w + 1, v + w]);
            }
        }
        data.uvs[7] = data.uvs[8]; // a degenerate uv triangle: dp/du from the face normal
        let mut sampler = crate::sampler::Sampler::new(7, 0);
        for (normals, uvs, flip) in
            [(true, false, false), (true, true, true), (false, false, true), (false, true, false)]
        {
            let d = MeshData { uvs: if uvs { data.uvs.clone() } else { Vec::new() }, ..data.clone() };
            // Without normals: `face_normals` (else the mesh recomputes smooth vertex normals).
            let mesh = Mesh::new(d, &Mat4::IDENTITY, !normals, flip);
            assert_eq!(mesh.face_frames.is_empty(), normals);
            for _ in 0..2000 {
                let prim = ((sampler.next_1d() * mesh.indices.len() as f32) as u32).min(mesh.indices.len() as u32 - 1);
                let (mut b1, mut b2) = (sampler.next_1d(), sampler.next_1d());
                if b1 + b2 > 1.0 {
                    (b1, b2) = (1.0 - b1, 1.0 - b2);
                }
                let dir = Vec3::new(sampler.next_1d() - 0.5, -1.0, sampler.next_1d() - 0.5).normalize();
                let si = mesh.interaction(prim, b1, b2, 1.5, dir);
                // The reference, in `Vec3`.
                let idx = mesh.indices[prim as usize];
                let [p0, p1, p2] = idx.map(|i| mesh.positions[i as usize]);
                let b0 = 1.0 - b1 - b2;
                let p = p0 * b0 + p1 * b1 + p2 * b2;
                // The face normal from the winding, then flipped; dp/du from the uvs (the
                // coordinate system of the unflipped normal where the uv triangle is degenerate).
                let face_n = (p1 - p0).cross(p2 - p0).normalize_or_zero();
                let n = if flip { -face_n } else { face_n };
                let dp_du = if uvs {
                    let [u0, u1, u2] = idx.map(|i| mesh.uvs[i as usize]);
                    let (duv0, duv1) = (u1 - u0, u2 - u0);
                    let det = duv0.x * duv1.y - duv0.y * duv1.x;
                    let dp_du = ((p1 - p0) * duv1.y - (p2 - p0) * duv0.y) / det;
                    if det != 0.0 && dp_du.is_finite() {
                        dp_du
                    } else {
                        Frame::from_normal(face_n).s
                    }
                } else {
                    p1 - p0
                };
                let sh_n = if mesh.normals.is_empty() {
                    n
                } else {
                    let [n0, n1, n2] = idx.map(|i| mesh.normals[i as usize]);
                    let v = (n0 * b0 + n1 * b1 + n2 * b2).normalize_or_zero();
                    if v == Vec3::ZERO {
                        n
                    } else if flip {
                        -v
                    } else {
                        v
                    }
                };
                let s = dp_du - sh_n * sh_n.dot(dp_du);
                let len2 = s.length_squared();
                let frame = if len2 > 0.0 && len2.is_finite() {
                    let s = s / len2.sqrt();
                    Frame { s, t: sh_n.cross(s), n: sh_n }
                } else {
                    Frame::from_normal(sh_n)
                };
                let v = -dir;
                let wi = Vec3::new(v.dot(frame.s), v.dot(frame.t), v.dot(frame.n));
                let bits = |v: Vec3| v.to_array().map(f32::to_bits);
                let case = format!("normals {normals} uvs {uvs} flip {flip} prim {prim} b ({b1}, {b2})");
                assert_eq!(bits(si.p), bits(p), "p: {case}");
                assert_eq!(bits(si.n), bits(n), "n: {case}");
                assert_eq!(bits(si.sh_frame.s), bits(frame.s), "s: {case}");
                assert_eq!(bits(si.sh_frame.t), bits(frame.t), "t: {case}");
                assert_eq!(bits(si.sh_frame.n), bits(frame.n), "sh_n: {case}");
                assert_eq!(bits(si.wi), bits(wi), "wi: {case}");
            }
        }
    }

    #[test]
    fn hit_uv_skipped_only_where_no_texture_reads_it() {
        let xml = r#"<scene version="3.0.0">
            <shape type="rectangle"><bsdf type="diffuse"><rgb name="reflectance" value="0.2"/></bsdf></shape>
            <shape type="rectangle"><bsdf type="diffuse"><texture type="checkerboard" name="reflectance"/></bsdf></shape>
            <shape type="cube"><bsdf type="twosided"><bsdf type="roughconductor"/></bsdf></shape>
            <shape type="rectangle"><emitter type="area"><texture type="checkerboard" name="radiance"/></emitter></shape>
            <sensor type="perspective"><film type="hdrfilm"><integer name="width" value="4"/><integer name="height" value="4"/></film></sensor></scene>"#;
        let parsed = crate::scene::xml::parse_str(xml, "t.xml", std::path::Path::new("."), &[]).expect("parses");
        let scene = crate::scene::build::build_scene(&parsed).expect("builds");
        let skip: Vec<bool> = scene
            .shapes
            .iter()
            .filter_map(|s| match &s.geometry {
                Geometry::Mesh(m) => Some(!m.hit_uv),
                _ => None,
            })
            .collect();
        assert_eq!(skip, [true, false, true, false]);
        // Skipping changes nothing but the uv.
        let Geometry::Mesh(textured) = &scene.shapes[1].geometry else { panic!("a rectangle is a mesh") };
        let plain = crate::shape::mesh::Mesh { hit_uv: false, ..textured.clone() };
        let d = glam::Vec3::new(0.1, -0.2, -1.0).normalize();
        let (a, b) = (textured.interaction(1, 0.3, 0.25, 2.0, d), plain.interaction(1, 0.3, 0.25, 2.0, d));
        assert_eq!(b.uv, glam::Vec2::ZERO);
        assert_ne!(a.uv, glam::Vec2::ZERO);
        assert_eq!((a.p, a.n, a.wi, a.t, a.prim), (b.p, b.n, b.wi, b.t, b.prim));
        assert_eq!((a.sh_frame.s, a.sh_frame.t, a.sh_frame.n), (b.sh_frame.s, b.sh_frame.t, b.sh_frame.n));
    }
}

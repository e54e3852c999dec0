//! Triangle mesh data as loaded from a file, before transformation.
//!
//! Every loader ([`load_ply`](super::ply::load_ply), [`load_obj`](super::obj::load_obj),
//! [`load_serialized`](super::serialized::load_serialized)) returns a [`MeshData`] that has passed
//! [`MeshData::validate`], so consumers may index it without checks.
//!
//! Conventions shared by the loaders (all follow Mitsuba 3.9):
//! - positions are in object space; `to_world` is applied by the shape, not by the loader;
//! - normals, when present, are unit length (the loaders normalise them as Mitsuba does). Mitsuba
//!   normalises again after applying `to_world`; a shape must do the same. Empty `normals` means
//!   the file had none: Mitsuba then computes smooth area-weighted vertex normals;
//! - uvs are as the file stores them, except that OBJ flips `v` (`v ↦ 1 − v`) by default, as
//!   Mitsuba's `flip_tex_coords` does (PLY does not flip by default);
//! - a mesh may have zero triangles (Mitsuba loads such a PLY or `.serialized` file and renders
//!   nothing): consumers must skip it rather than build an empty acceleration structure.

use crate::math::{Vec2, Vec3};
use crate::scene::error::{Error, Result};

/// An indexed triangle mesh: positions, optional per-vertex normals and uvs, and triangles.
#[derive(Clone, Debug, Default)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    /// Empty when the file has none; else one unit normal per vertex.
    pub normals: Vec<Vec3>,
    /// Empty when the file has none; else one per vertex.
    pub uvs: Vec<Vec2>,
    /// Triangles as indices into `positions` (counter-clockwise winding faces the normal).
    pub indices: Vec<[u32; 3]>,
}

impl MeshData {
    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// Heap bytes held by the mesh (for statistics and the load benchmark).
    pub fn heap_bytes(&self) -> usize {
        self.positions.len() * std::mem::size_of::<Vec3>()
            + self.normals.len() * std::mem::size_of::<Vec3>()
            + self.uvs.len() * std::mem::size_of::<Vec2>()
            + self.indices.len() * std::mem::size_of::<[u32; 3]>()
    }

    /// Every index in range, every position finite, normals/uvs either empty or one per vertex
    /// (normals finite and non-zero, uvs finite); errors name the file.
    pub fn validate(&self, file: &str) -> Result<()> {
        let n = self.positions.len();
        if u32::try_from(n).is_err() {
            return Err(Error::in_file(
                file,
                format!("mesh has {n} vertices, more than the 2^32 - 1 that 32-bit indices can address"),
            ));
        }
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(Error::in_file(
                file,
                format!("vertex {i} has a non-finite position {}", fmt_vec3(self.positions[i])),
            ));
        }
        if !self.normals.is_empty() {
            if self.normals.len() != n {
                return Err(Error::in_file(file, format!("mesh has {} normals for {n} vertices", self.normals.len())));
            }
            let bad = |v: &Vec3| !v.is_finite() || v.length_squared() == 0.0;
            if let Some(i) = self.normals.iter().position(bad) {
                return Err(Error::in_file(
                    file,
                    format!(
                        "vertex {i} has a zero-length or non-finite normal {} (Mitsuba would produce NaN shading normals)",
                        fmt_vec3(self.normals[i])
                    ),
                ));
            }
        }
        if !self.uvs.is_empty() {
            if self.uvs.len() != n {
                return Err(Error::in_file(
                    file,
                    format!("mesh has {} texture coordinates for {n} vertices", self.uvs.len()),
                ));
            }
            if let Some(i) = self.uvs.iter().position(|uv| !uv.is_finite()) {
                let uv = self.uvs[i];
                return Err(Error::in_file(
                    file,
                    format!("vertex {i} has non-finite texture coordinates ({}, {})", uv.x, uv.y),
                ));
            }
        }
        for (t, tri) in self.indices.iter().enumerate() {
            if let Some(&i) = tri.iter().find(|&&i| i as usize >= n) {
                return Err(Error::in_file(
                    file,
                    format!("triangle {t} references vertex {i}, but the mesh has only {n} vertices"),
                ));
            }
        }
        Ok(())
    }
}

/// Normalise as Mitsuba does (`n * rsqrt(|n|²)`, in single precision). Zero or non-finite
/// normals are returned unchanged so that [`MeshData::validate`] reports them.
pub(crate) fn normalize_normal(n: Vec3) -> Vec3 {
    let len2 = n.length_squared();
    if len2 > 0.0 && len2.is_finite() {
        n * (1.0 / len2.sqrt())
    } else if n.is_finite() && n != Vec3::ZERO {
        // |n|² under- or overflows in f32.
        let d = n.as_dvec3();
        (d / d.length()).as_vec3()
    } else {
        n
    }
}

fn fmt_vec3(v: Vec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle() -> MeshData {
        MeshData {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y],
            normals: vec![Vec3::Z; 3],
            uvs: vec![Vec2::ZERO; 3],
            indices: vec![[0, 1, 2]],
        }
    }

    #[test]
    fn valid_mesh_passes() {
        assert!(triangle().validate("t.ply").is_ok());
        assert!(MeshData::default().validate("empty.ply").is_ok());
    }

    #[test]
    fn each_defect_is_reported_with_the_file() {
        let mut m = triangle();
        m.indices[0][2] = 3;
        let e = m.validate("t.ply").unwrap_err().to_string();
        assert!(e.starts_with("t.ply: triangle 0 references vertex 3"), "{e}");

        let mut m = triangle();
        m.positions[1].y = f32::NAN;
        assert!(m.validate("t.ply").unwrap_err().to_string().contains("vertex 1 has a non-finite position"));

        let mut m = triangle();
        m.normals[2] = Vec3::ZERO;
        assert!(m.validate("t.ply").unwrap_err().to_string().contains("vertex 2 has a zero-length"));

        let mut m = triangle();
        m.normals.pop();
        assert!(m.validate("t.ply").unwrap_err().to_string().contains("2 normals for 3 vertices"));

        let mut m = triangle();
        m.uvs.push(Vec2::ONE);
        assert!(m.validate("t.ply").unwrap_err().to_string().contains("4 texture coordinates"));

        let mut m = triangle();
        m.uvs[0].x = f32::INFINITY;
        assert!(m.validate("t.ply").unwrap_err().to_string().contains("non-finite texture"));
    }
}

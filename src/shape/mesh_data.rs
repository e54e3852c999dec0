//! Triangle mesh data as loaded from a file, before transformation.

use crate::math::{Vec2, Vec3};

/// Placeholder until the loaders land (replaced by the meshes branch).
#[derive(Clone, Debug, Default)]
pub struct MeshData {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    pub indices: Vec<[u32; 3]>,
}

//! Mitsuba's `rectangle`: the square [-1, 1]² in the local XY plane, normal +Z, uv = ((x+1)/2,
//! (y+1)/2), placed by `to_world`; a two-triangle mesh.
//!
//! | Parameter      | Type      | Default  | Description                          |
//! |----------------|-----------|----------|--------------------------------------|
//! | `to_world`     | transform | identity | placement (common to every shape)    |
//! | `flip_normals` | boolean   | false    | flip the normal (common)             |
//!
//! ```xml
//! <shape type="rectangle"><transform name="to_world"><scale value="2"/></transform></shape>
//! ```

use super::mesh_data::MeshData;
use super::{Geometry, Mesh};
use crate::math::{Mat4, Vec2, Vec3};

/// Mitsuba's `rectangle`: [-1,1]² in the local XY plane, normal +Z, uv = ((x+1)/2, (y+1)/2).
pub fn rectangle_data() -> MeshData {
    MeshData {
        positions: vec![
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ],
        normals: vec![Vec3::Z; 4],
        uvs: vec![Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0)],
        indices: vec![[1, 2, 0], [1, 3, 2]],
    }
}

/// The shape (no parameters of its own).
pub fn from_props(to_world: &Mat4, flip_normals: bool) -> Geometry {
    Geometry::Mesh(Mesh::new(rectangle_data(), to_world, false, flip_normals))
}

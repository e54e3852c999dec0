//! Mitsuba's `cube`: the cube [-1, 1]³ placed by `to_world`; a 12-triangle mesh with per-face
//! normals and uvs.
//!
//! | Parameter      | Type      | Default  | Description                          |
//! |----------------|-----------|----------|--------------------------------------|
//! | `to_world`     | transform | identity | placement (common to every shape)    |
//! | `flip_normals` | boolean   | false    | flip the normals (common)            |
//!
//! ```xml
//! <shape type="cube"><transform name="to_world"><scale value="0.5"/></transform></shape>
//! ```

use super::mesh_data::MeshData;
use super::{Geometry, Mesh};
use crate::math::{Mat4, Vec2, Vec3};

/// Mitsuba's `cube`: [-1,1]³, 24 vertices with per-face normals and uvs (data read from Mitsuba 3.9).
pub fn cube_data() -> MeshData {
    const P: [[f32; 3]; 24] = [
        [1., -1., -1.],
        [1., -1., 1.],
        [-1., -1., 1.],
        [-1., -1., -1.],
        [1., 1., -1.],
        [-1., 1., -1.],
        [-1., 1., 1.],
        [1., 1., 1.],
        [1., -1., -1.],
        [1., 1., -1.],
        [1., 1., 1.],
        [1., -1., 1.],
        [1., -1., 1.],
        [1., 1., 1.],
        [-1., 1., 1.],
        [-1., -1., 1.],
        [-1., -1., 1.],
        [-1., 1., 1.],
        [-1., 1., -1.],
        [-1., -1., -1.],
        [1., 1., -1.],
        [1., -1., -1.],
        [-1., -1., -1.],
        [-1., 1., -1.],
    ];
    const N: [[f32; 3]; 6] = [[0., -1., 0.], [0., 1., 0.], [1., 0., 0.], [0., 0., 1.], [-1., 0., 0.], [0., 0., -1.]];
    const UV: [[f32; 2]; 4] = [[0., 1.], [1., 1.], [1., 0.], [0., 0.]];
    let mut d = MeshData::default();
    for (i, p) in P.iter().enumerate() {
        d.positions.push(Vec3::from_array(*p));
        d.normals.push(Vec3::from_array(N[i / 4]));
        d.uvs.push(Vec2::from_array(UV[i % 4]));
    }
    for f in 0..6u32 {
        let b = 4 * f;
        d.indices.push([b, b + 1, b + 2]);
        d.indices.push([b + 3, b, b + 2]);
    }
    d
}

/// The shape (no parameters of its own).
pub fn from_props(to_world: &Mat4, flip_normals: bool) -> Geometry {
    Geometry::Mesh(Mesh::new(cube_data(), to_world, false, flip_normals))
}

//! Mitsuba's `rectangle`: the square [-1, 1]² in the local XY plane, normal +Z, uv = ((x+1)/2,
//! (y+1)/2), placed by `to_world`; a two-triangle mesh, sampled as Mitsuba samples it (uniform over
//! the rectangle, uv = the sample).
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

/// The shape (no parameters of its own). Area sampling is Mitsuba's: the sample mapped linearly
/// onto the rectangle, uv = the sample (`Mesh::set_parallelogram`).
pub fn from_props(to_world: &Mat4, flip_normals: bool) -> Geometry {
    let mut mesh = Mesh::new(rectangle_data(), to_world, false, flip_normals);
    mesh.set_parallelogram();
    Geometry::Mesh(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampler::Sampler;
    use crate::testing::chi2::chi2_discrete;

    /// A sheared, scaled, rotated and moved rectangle (flipped): area sampling is Mitsuba's map
    /// `to_world(2u − 1, 2v − 1, 0)` with uv = the sample, the normal of the surface and density
    /// 1 / area, and it is uniform over the rectangle (chi-square over an 8 × 8 grid of its local
    /// square, 200,000 samples, significance 0.01).
    #[test]
    fn area_sampling_is_mitsubas_and_uniform() {
        let to_world = Mat4::from_translation(Vec3::new(0.3, 1.9, -0.4))
            * Mat4::from_rotation_x(1.1)
            * Mat4::from_cols_array(&[1.0, 0.0, 0.0, 0.0, 0.45, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0])
            * Mat4::from_scale(Vec3::new(0.23, 0.61, 1.0));
        let Geometry::Mesh(mesh) = from_props(&to_world, true) else { panic!("a rectangle is a mesh") };
        let (inv, area) = (to_world.inverse(), mesh.surface_area());
        let n = -to_world.transform_vector3(Vec3::X).cross(to_world.transform_vector3(Vec3::Y)).normalize();
        let (mut sampler, mut counts) = (Sampler::new(7, 0), vec![0u64; 64]);
        let samples = 200_000;
        for _ in 0..samples {
            let u = sampler.next_2d();
            let ps = mesh.sample_position(u);
            let mitsuba = to_world.transform_point3(Vec3::new(2.0 * u.x - 1.0, 2.0 * u.y - 1.0, 0.0));
            assert!((ps.p - mitsuba).length() < 1e-5, "{:?} vs {mitsuba:?} at {u:?}", ps.p);
            assert_eq!(ps.uv, u);
            assert!((ps.n - n).length() < 1e-5, "{:?} vs {n:?}", ps.n);
            assert!((ps.pdf * area - 1.0).abs() < 1e-5);
            let l = inv.transform_point3(ps.p);
            let cell = |x: f32| (((x + 1.0) * 4.0) as usize).min(7);
            counts[cell(l.y) * 8 + cell(l.x)] += 1;
        }
        let r = chi2_discrete(&counts, 0, &[1.0 / 64.0; 64], 0.01);
        assert!(r.passed, "{r:?}");
    }
}

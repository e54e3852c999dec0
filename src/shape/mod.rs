//! Shapes: triangle meshes (PLY, OBJ, Mitsuba `.serialized`, and the `rectangle` / `cube` meshes)
//! and Mitsuba's analytic `sphere` and `disk`, each with its BSDF, optional area emitter and
//! interior / exterior media.

pub mod accel;
pub mod cube;
pub mod disk;
pub mod mesh;
pub mod mesh_data;
pub mod obj;
pub mod ply;
pub mod rectangle;
pub mod serialized;
pub mod sphere;

use crate::interaction::{DirectionSample, PositionSample, SurfaceInteraction};
use crate::math::{Aabb, Ray, Vec2, Vec3};
use crate::scene::desc::ObjectDesc;
use crate::scene::resolver::FileResolver;
use crate::scene::{Error, Result};
pub use disk::Disk;
pub use mesh::Mesh;
pub use sphere::Sphere;

#[derive(Clone, Debug)]
pub enum Geometry {
    Mesh(Mesh),
    Sphere(Sphere),
    Disk(Disk),
}

/// The shape types `Geometry::from_desc` reads.
pub const SUPPORTED_SHAPES: &str = "obj, ply, serialized, rectangle, cube, sphere, disk";

impl Geometry {
    /// Whether hits compute their uv (the scene clears it where no texture reads it). Spheres and
    /// meshes honour it; a disk always computes its uv.
    pub fn set_hit_uv(&mut self, on: bool) {
        match self {
            Geometry::Sphere(s) => s.hit_uv = on,
            Geometry::Mesh(m) => m.hit_uv = on,
            Geometry::Disk(_) => {}
        }
    }

    /// The geometry of a `<shape>`: the parameters every shape has (`to_world`, `flip_normals`),
    /// then the plugin's own, read by its file (`rectangle.rs`, `cube.rs`, `sphere.rs`, ...).
    /// The BSDF, emitter and media of the shape are the scene builder's.
    pub fn from_desc(obj: &ObjectDesc, resolver: &FileResolver) -> Result<Geometry> {
        let props = &obj.props;
        let to_world = props.transform("to_world")?;
        if !to_world.is_finite() || to_world.determinant() == 0.0 {
            return Err(props.error("to_world", "to_world is singular or not finite"));
        }
        let flip_normals = props.bool("flip_normals", false)?;
        Ok(match obj.plugin.as_str() {
            "obj" | "ply" | "serialized" => mesh::from_file_props(obj, resolver, &to_world, flip_normals)?,
            "rectangle" => rectangle::from_props(&to_world, flip_normals),
            "cube" => cube::from_props(&to_world, flip_normals),
            "sphere" => Geometry::Sphere(Sphere::from_props(props, &to_world, flip_normals)?),
            "disk" => Geometry::Disk(Disk::new(to_world, flip_normals)),
            other => {
                return Err(Error::at(
                    &obj.pos,
                    format!("shape \"{}\" is not supported (supported: {})", other, SUPPORTED_SHAPES),
                ))
            }
        })
    }
}

/// A shape in the scene with indices into the scene's BSDF, emitter and medium arrays.
#[derive(Clone, Debug)]
pub struct Shape {
    pub geometry: Geometry,
    /// Mitsuba plugin name (`ply`, `sphere`, ...), for summaries.
    pub plugin: String,
    pub id: Option<String>,
    pub bsdf: u32,
    pub emitter: Option<u32>,
    pub interior: Option<u32>,
    pub exterior: Option<u32>,
}

impl Shape {
    pub fn bounds(&self) -> Aabb {
        match &self.geometry {
            Geometry::Mesh(m) => m.bounds(),
            Geometry::Sphere(s) => s.bounds(),
            Geometry::Disk(d) => d.bounds(),
        }
    }

    pub fn surface_area(&self) -> f32 {
        match &self.geometry {
            Geometry::Mesh(m) => m.surface_area(),
            Geometry::Sphere(s) => s.surface_area(),
            Geometry::Disk(d) => d.surface_area(),
        }
    }

    pub fn triangle_count(&self) -> usize {
        match &self.geometry {
            Geometry::Mesh(m) => m.triangle_count(),
            _ => 0,
        }
    }

    /// Number of BVH primitives (triangles, or 1 for an analytic shape).
    pub fn primitive_count(&self) -> usize {
        match &self.geometry {
            Geometry::Mesh(m) => m.triangle_count(),
            _ => 1,
        }
    }

    /// The surface interaction of a hit on primitive `prim` at barycentrics `(b1, b2)`, distance `t`
    /// along `ray` (`walk::shadow_crossing`). `Scene::ray_intersect` makes the same dispatch itself,
    /// returning each arm's record with its `shape` set in place.
    #[inline(always)]
    pub fn interaction(&self, prim: u32, b1: f32, b2: f32, t: f32, ray: &Ray) -> SurfaceInteraction {
        match &self.geometry {
            Geometry::Mesh(m) => m.interaction(prim, b1, b2, t, ray.d),
            Geometry::Sphere(s) => s.interaction(t, ray),
            Geometry::Disk(d) => d.interaction(t, ray),
        }
    }

    pub fn sample_position(&self, sample: Vec2) -> PositionSample {
        match &self.geometry {
            Geometry::Mesh(m) => m.sample_position(sample),
            Geometry::Sphere(s) => s.sample_position(sample),
            Geometry::Disk(d) => d.sample_position(sample),
        }
    }

    /// A point on the shape seen from `ref_p`, with its solid-angle density (Mitsuba's `Shape::sample_direction`).
    /// (Inlined whole into emitter sampling: no position-sample record passed between calls.)
    #[inline(always)]
    pub fn sample_direction(&self, ref_p: Vec3, sample: Vec2) -> DirectionSample {
        match &self.geometry {
            Geometry::Sphere(s) => s.sample_direction(ref_p, sample),
            Geometry::Mesh(m) => sphere::area_to_direction_sample(ref_p, m.sample_position(sample)),
            Geometry::Disk(d) => sphere::area_to_direction_sample(ref_p, d.sample_position(sample)),
        }
    }

    /// Solid-angle density of `ds` (a point on this shape seen from `ref_p`) under `sample_direction`.
    pub fn pdf_direction(&self, ref_p: Vec3, ds: &DirectionSample) -> f32 {
        match &self.geometry {
            Geometry::Sphere(s) => s.pdf_direction(ref_p, ds),
            _ => sphere::area_pdf_to_solid_angle(1.0 / self.surface_area(), ds.dist, ds.d, ds.n),
        }
    }
}

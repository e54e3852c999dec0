//! Shapes: triangle meshes (PLY, OBJ, Mitsuba `.serialized`) and Mitsuba's analytic shapes.

pub mod mesh_data;
pub mod obj;
pub mod ply;
pub mod serialized;

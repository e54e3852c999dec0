//! The planes of flat boundaries as plain data, smooth (found by `flat.rs`) and rough (found by
//! `rough.rs`): the scene's `volpath_snee` tables store them, so this file imports nothing of the
//! scene. Orientations, supporting planes, and the lookup of the plane through a boundary point.

use crate::math::Vec3;

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

/// One supporting plane of the boundary: an orientation and its offset, the points `x` with
/// `plane.n · x = offset` (lights at a finite distance need it: the refraction point depends on it).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Support {
    pub plane: Plane,
    pub offset: f32,
}

/// The flat boundary of one medium: its distinct plane orientations, and its distinct supporting
/// planes (empty when there are more than [`MAX_PLANES`]: then lights at a finite distance are not
/// handled, directional lights and environments still are).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FlatBoundary {
    pub planes: Vec<Plane>,
    pub supports: Vec<Support>,
}

impl FlatBoundary {
    /// The supporting plane through the boundary point `p` with normal `n` and index `eta`.
    pub fn support_at(&self, p: Vec3, n: Vec3, eta: f32) -> Option<&Support> {
        self.supports
            .iter()
            .find(|s| s.plane.eta == eta && s.plane.n.dot(n) > SAME_NORMAL && same_offset(s.plane.n.dot(p), s.offset))
    }
}

/// Two plane offsets (distances along the same normal) are the same plane.
#[inline]
pub(super) fn same_offset(a: f32, b: f32) -> bool {
    (a - b).abs() <= 1e-4 * (1.0 + a.abs().max(b.abs()))
}

/// One orientation of a rough boundary: outward unit normal and the `roughdielectric` (index into
/// `Scene::bsdfs`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RoughPlane {
    pub n: Vec3,
    pub bsdf: u32,
}

/// The rough boundary of one medium: its distinct (normal, BSDF) orientations when it is flat, or
/// `curved` (meshes with interpolated normals, spheres, more than [`MAX_PLANES`] orientations:
/// `planes` is then empty and the connection samples in a reference frame found from `x_j`,
/// docs/manifold.md §7.1).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RoughBoundary {
    pub planes: Vec<RoughPlane>,
    pub curved: bool,
    /// The rate `q` at which the connection runs at a medium vertex (`rough_rate::rate`,
    /// docs/manifold.md §7.2 "Rate").
    pub q: f64,
    /// A lower bound of the Fresnel reflectance of every `roughdielectric` of the boundary at any
    /// angle (`rough_rate::reflect_below`): an inner-direction sample whose `u1` lies below it is a
    /// reflection (a failed sample) in any reference frame.
    pub reflect_below: f64,
}

impl RoughBoundary {
    /// The orientation with geometric normal `n` and BSDF `bsdf`.
    pub fn plane_at(&self, n: Vec3, bsdf: u32) -> Option<&RoughPlane> {
        self.planes.iter().find(|p| p.bsdf == bsdf && p.n.dot(n) > SAME_NORMAL)
    }
}

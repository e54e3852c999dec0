//! The 8-wide BVH: nodes with uncompressed `f32` child boxes stored as a structure of arrays (one
//! AVX register per plane), and leaves of up to four triangles in one SIMD packet, each lane with
//! what its hit record reads in one cache line ([`LaneShade`]).
//!
//! Built by the binned SAH builder in [`super::build`].

use super::pages::Pages;
use super::triangle::TriPacket4;
use glam::Vec3;

/// Child slot value of a leaf: this bit set, the packet index in the others.
pub const LEAF: u32 = 1 << 31;
/// Child slot value of an unused slot (its box is empty, so it is never visited).
pub const EMPTY: u32 = u32::MAX;
/// Triangles per leaf packet.
pub const LEAF_SIZE: usize = 4;

/// One node: the boxes of its eight children as rows min x, max x, min y, max y, min z, max z
/// (an unused slot has min +inf and max −inf, which no ray enters), and the children.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Node8 {
    pub bounds: [[f32; 8]; 6],
    /// Node index, `LEAF | packet`, or `EMPTY`.
    pub child: [u32; 8],
}

impl Node8 {
    /// The row of `bounds` starting at offset `off` (8 × row index) of the bounds read as one array.
    ///
    /// # Safety
    /// `off` must be a multiple of 8 below 48 (as `NodeRay` stores its rows).
    #[inline(always)]
    pub unsafe fn row(&self, off: usize) -> *const f32 {
        debug_assert!(off.is_multiple_of(8) && off < 48);
        // SAFETY: by the caller's contract, the 8 floats from `off` lie inside `bounds`.
        unsafe { self.bounds.as_ptr().cast::<f32>().add(off) }
    }

    pub const UNUSED: Node8 = Node8 {
        bounds: [
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
            [f32::INFINITY; 8],
            [f32::NEG_INFINITY; 8],
        ],
        child: [EMPTY; 8],
    };
}

/// What the hit record of a BVH lane reads besides the leaf's vertices: its shape and triangle,
/// the triangle's vertex normals and its face normal, copied out of the mesh at build time into one
/// cache line per lane. The closest traversal prefetches the line when the lane becomes the nearest
/// hit, so the hit record does not wait on three dependent misses (lane → vertex indices →
/// normals) in large meshes after the traversal ends.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct LaneShade {
    /// Shape and triangle as the builder's caller numbers them (`u32::MAX` in an unused lane).
    pub shape: u32,
    pub prim: u32,
    /// `Mesh::normals` at the triangle's three vertices (zero when the mesh has none).
    pub n: [Vec3; 3],
    /// `Mesh::face_normals[prim]`.
    pub face_n: Vec3,
}

impl LaneShade {
    pub const EMPTY: LaneShade = LaneShade::ids(u32::MAX, u32::MAX);

    /// Shape and triangle only (zero normals).
    pub const fn ids(shape: u32, prim: u32) -> LaneShade {
        LaneShade { shape, prim, n: [Vec3::ZERO; 3], face_n: Vec3::ZERO }
    }
}

/// The arrays are [`Pages`]: read-only once built, in huge-page memory when large.
pub struct Bvh8 {
    pub nodes: Pages<Node8>,
    pub packets: Pages<TriPacket4>,
    /// Per packet and lane: the lane's record ([`LaneShade::EMPTY`] for an unused lane).
    pub lanes: Pages<[LaneShade; LEAF_SIZE]>,
    /// Node 0, or `LEAF | 0` when the whole scene is one packet.
    pub root: u32,
    /// Longest root-to-leaf path in nodes (bounds the traversal stack).
    pub depth: usize,
}

impl Bvh8 {
    /// Bytes of nodes, packets and lane records.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node8>()
            + self.packets.len() * std::mem::size_of::<TriPacket4>()
            + self.lanes.len() * std::mem::size_of::<[LaneShade; LEAF_SIZE]>()
    }
}

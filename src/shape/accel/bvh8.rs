//! The 8-wide BVH: nodes with uncompressed `f32` child boxes stored as a structure of arrays (one
//! AVX register per plane), and leaves of up to four triangles in one SIMD packet.
//!
//! Built from obvhs's binary BVH (PLOC, Meister & Bittner 2018, plus reinsertion optimisation,
//! Meister & Bittner 2021) by collapsing it top down: a node keeps opening its child of largest
//! surface area until it has eight children, and a subtree of at most four triangles becomes one
//! leaf packet.

use super::triangle::TriPacket4;
use crate::math::Vec3;
use obvhs::aabb::Aabb as BvhAabb;
use obvhs::bvh2::reinsertion::ReinsertionOptimizer;
use obvhs::bvh2::Bvh2;
use obvhs::ploc::PlocBuilder;
use obvhs::{Boundable, BvhBuildParams};

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
    const UNUSED: Node8 = Node8 {
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

pub struct Bvh8 {
    pub nodes: Vec<Node8>,
    pub packets: Vec<TriPacket4>,
    /// Per packet lane (`4 · packet + lane`): the index of the triangle in the builder's input, or
    /// `u32::MAX` for an unused lane.
    pub lane_prims: Vec<u32>,
    /// Node 0, or `LEAF | 0` when the whole scene is one packet.
    pub root: u32,
    /// Longest root-to-leaf path in nodes (bounds the traversal stack).
    pub depth: usize,
}

struct BoundsPrim(BvhAabb);

impl Boundable for BoundsPrim {
    fn aabb(&self) -> BvhAabb {
        self.0
    }
}

impl Bvh8 {
    /// A BVH over triangles `tris` with boxes `bounds` (which may be padded). None when empty.
    pub fn build(tris: &[[Vec3; 3]], bounds: &[BvhAabb], params: &BvhBuildParams) -> Option<Bvh8> {
        if tris.is_empty() {
            return None;
        }
        let prims: Vec<BoundsPrim> = bounds.iter().map(|b| BoundsPrim(*b)).collect();
        let mut bvh2 = PlocBuilder::with_capacity(prims.len()).build(
            params.ploc_search_distance,
            &prims,
            (0..prims.len() as u32).collect(),
            params.sort_precision,
            params.search_depth_threshold,
        );
        ReinsertionOptimizer::default().run(&mut bvh2, params.reinsertion_batch_ratio, None);
        let counts = subtree_counts(&bvh2);
        let mut out = Bvh8 { nodes: Vec::new(), packets: Vec::new(), lane_prims: Vec::new(), root: 0, depth: 0 };
        out.root = if counts[0] as usize <= LEAF_SIZE {
            out.leaf(&bvh2, tris, 0)
        } else {
            out.inner(&bvh2, &counts, tris, 0, 1)
        };
        Some(out)
    }

    /// Bytes of nodes, packets and lane indices.
    pub fn memory_bytes(&self) -> usize {
        self.nodes.len() * std::mem::size_of::<Node8>()
            + self.packets.len() * std::mem::size_of::<TriPacket4>()
            + self.lane_prims.len() * 4
    }

    /// Emit the 8-wide node for binary node `n` (an inner node with more than `LEAF_SIZE` triangles).
    fn inner(&mut self, bvh2: &Bvh2, counts: &[u32], tris: &[[Vec3; 3]], n: usize, depth: usize) -> u32 {
        self.depth = self.depth.max(depth);
        let first = bvh2.nodes[n].first_index as usize;
        let mut kids = vec![first, first + 1];
        let openable = |k: usize| bvh2.nodes[k].prim_count == 0 && counts[k] as usize > LEAF_SIZE;
        while kids.len() < 8 {
            let best = (0..kids.len())
                .filter(|&i| openable(kids[i]))
                .max_by(|&a, &b| bvh2.nodes[kids[a]].aabb.half_area().total_cmp(&bvh2.nodes[kids[b]].aabb.half_area()));
            let Some(i) = best else { break };
            let f = bvh2.nodes[kids[i]].first_index as usize;
            kids[i] = f;
            kids.push(f + 1);
        }
        let index = self.nodes.len();
        self.nodes.push(Node8::UNUSED);
        let mut node = Node8::UNUSED;
        for (slot, &k) in kids.iter().enumerate() {
            let b = bvh2.nodes[k].aabb;
            for axis in 0..3 {
                node.bounds[2 * axis][slot] = b.min[axis];
                node.bounds[2 * axis + 1][slot] = b.max[axis];
            }
            node.child[slot] =
                if openable(k) { self.inner(bvh2, counts, tris, k, depth + 1) } else { self.leaf(bvh2, tris, k) };
        }
        self.nodes[index] = node;
        index as u32
    }

    /// Emit one packet with the (at most `LEAF_SIZE`) triangles under binary node `n`.
    fn leaf(&mut self, bvh2: &Bvh2, tris: &[[Vec3; 3]], n: usize) -> u32 {
        let mut packet = TriPacket4::EMPTY;
        let mut lanes = [u32::MAX; LEAF_SIZE];
        let mut lane = 0;
        // A subtree of at most LEAF_SIZE primitives has fewer than 2 · LEAF_SIZE nodes.
        let mut stack = [0usize; 2 * LEAF_SIZE];
        let mut sp = 1;
        stack[0] = n;
        while sp > 0 {
            sp -= 1;
            let node = &bvh2.nodes[stack[sp]];
            if node.prim_count == 0 {
                stack[sp] = node.first_index as usize;
                stack[sp + 1] = node.first_index as usize + 1;
                sp += 2;
                continue;
            }
            assert!(lane + node.prim_count as usize <= LEAF_SIZE, "BVH leaf larger than a packet");
            for i in 0..node.prim_count as usize {
                let prim = bvh2.primitive_indices[node.first_index as usize + i];
                packet.set(lane, tris[prim as usize]);
                lanes[lane] = prim;
                lane += 1;
            }
        }
        self.packets.push(packet);
        self.lane_prims.extend_from_slice(&lanes);
        LEAF | (self.packets.len() - 1) as u32
    }
}

/// Number of primitives under every node of a binary BVH (children may come before parents).
fn subtree_counts(bvh2: &Bvh2) -> Vec<u32> {
    let mut counts = vec![0u32; bvh2.nodes.len()];
    let mut order = Vec::with_capacity(bvh2.nodes.len());
    let mut stack = vec![0usize];
    while let Some(n) = stack.pop() {
        order.push(n);
        let node = &bvh2.nodes[n];
        if node.prim_count == 0 {
            stack.push(node.first_index as usize);
            stack.push(node.first_index as usize + 1);
        }
    }
    for &n in order.iter().rev() {
        let node = &bvh2.nodes[n];
        counts[n] = if node.prim_count == 0 {
            counts[node.first_index as usize] + counts[node.first_index as usize + 1]
        } else {
            node.prim_count
        };
    }
    counts
}

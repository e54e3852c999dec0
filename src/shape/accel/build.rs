//! Binned SAH builder of the 8-wide BVH (Wald 2007, "On fast Construction of SAH-based Bounding
//! Volume Hierarchies"), built eight-wide directly: a node starts with one cluster of primitives
//! and splits the cluster of largest surface area until it has eight (as Embree's builders do,
//! Wald et al. 2014), each split chosen by the surface area heuristic over 32 bins of the
//! centroids on every axis (as many bins as triangles in smaller clusters). A cluster of at most
//! `LEAF_SIZE` triangles becomes one leaf packet; while a node has free slots, such a cluster is
//! still split when its halves' boxes are much smaller than its own (see [`open`]).
//!
//! The cost of a side is its area times its triangle count (counting leaf packets, ⌈n / 4⌉,
//! instead made fuller leaves but slower traversal on the statue and the Cornell box). A cluster
//! whose centroids all coincide is halved by index.
//!
//! Parallel (rayon): large clusters are binned in chunks on every thread, and the subtrees below a
//! large node are built concurrently, each into its own part; [`flatten`] copies the parts into
//! one node array at the end. Leaves are ranges of the builder's index array until then; their
//! packets are made in one parallel pass from the caller's triangles. The result does not depend
//! on the thread count.
//!
//! Node and leaf boxes are exact unions of the (padded) primitive boxes: they come from the
//! partition pass itself, not from the bins.

use super::bvh8::{Bvh8, LaneShade, Node8, EMPTY, LEAF, LEAF_SIZE};
use super::pages::Pages;
use super::triangle::TriPacket4;
use crate::math::Vec3;
use glam::{Vec3A, Vec4};
use rayon::prelude::*;
use std::mem::MaybeUninit;

/// Bins per axis (at most; a cluster of `n` triangles uses `n` of them).
const BINS: usize = 32;
/// Clusters at least this large are binned in parallel chunks of this size.
const PARALLEL_BIN: usize = 1 << 15;
/// A leaf-sized cluster in a node with a free slot is split when its halves' box areas sum to
/// less than this fraction of its own.
const LEAF_SPLIT: f32 = 0.9;
/// Nodes over at least this many triangles build their subtrees in parallel.
const PARALLEL_NODE: usize = 1 << 12;

/// An axis-aligned box (also used for boxes of centroids, stored doubled: `min + max`).
#[derive(Clone, Copy, Debug)]
pub struct Bounds {
    pub min: Vec3A,
    pub max: Vec3A,
}

impl Bounds {
    pub const EMPTY: Bounds = Bounds { min: Vec3A::splat(f32::INFINITY), max: Vec3A::splat(f32::NEG_INFINITY) };

    #[inline(always)]
    fn grow(&mut self, b: &Bounds) {
        self.min = self.min.min(b.min);
        self.max = self.max.max(b.max);
    }

    #[inline(always)]
    fn grow_point(&mut self, p: Vec3A) {
        self.min = self.min.min(p);
        self.max = self.max.max(p);
    }

    #[inline(always)]
    fn union(mut self, b: &Bounds) -> Bounds {
        self.grow(b);
        self
    }

    /// Half the surface area (0 for an empty box).
    #[inline(always)]
    fn half_area(&self) -> f32 {
        let e = (self.max - self.min).max(Vec3A::ZERO);
        e.x * e.y + e.y * e.z + e.z * e.x
    }

    /// Twice the centre (the centroid key the bins use).
    #[inline(always)]
    fn centroid2(&self) -> Vec3A {
        self.min + self.max
    }
}

/// Primitives `start..end` of the current slice, their box and the box of their doubled centroids.
#[derive(Clone, Copy, Debug)]
struct Cluster {
    start: usize,
    end: usize,
    bounds: Bounds,
    centroids: Bounds,
}

impl Cluster {
    fn len(&self) -> usize {
        self.end - self.start
    }
}

#[derive(Clone, Copy)]
struct Bin {
    bounds: Bounds,
    count: u32,
}

type Bins = [[Bin; BINS]; 3];

const EMPTY_BINS: Bins = [[Bin { bounds: Bounds::EMPTY, count: 0 }; BINS]; 3];

/// The bin mapping of a cluster: bin of a doubled centroid `c` on each axis.
#[derive(Clone, Copy)]
struct Binning {
    origin: Vec3A,
    scale: Vec3A,
    /// Bins in use.
    count: usize,
}

impl Binning {
    fn new(centroids: &Bounds, n: usize) -> Binning {
        let count = n.clamp(4, BINS);
        let extent = centroids.max - centroids.min;
        // Slightly under count / extent so that the largest centroid lands in the last bin; an
        // axis without extent (or with an infinite one) maps everything to bin 0.
        let scale = Vec3A::select(
            extent.cmpgt(Vec3A::ZERO) & extent.cmplt(Vec3A::INFINITY),
            Vec3A::splat(count as f32 * 0.999_99) / extent,
            Vec3A::ZERO,
        );
        Binning { origin: centroids.min, scale, count }
    }

    /// Bins of doubled centroid `c` on the three axes (clamped; NaN maps to bin 0). Binning and
    /// partition both use it, so they agree bit for bit.
    #[inline(always)]
    fn bins(&self, c: Vec3A) -> [usize; 3] {
        // max(x, 0) returns 0 for a NaN x (glam's `max` keeps the second operand then).
        let x = ((c - self.origin) * self.scale).max(Vec3A::ZERO).min(Vec3A::splat((self.count - 1) as f32));
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            let mut k = [0i32; 4];
            // SAFETY: SSE2 is part of x86-64; the lanes are in [0, count − 1], so the truncation
            // is exact and `k` holds small non-negative integers.
            unsafe { _mm_storeu_si128(k.as_mut_ptr().cast(), _mm_cvttps_epi32(x.into())) };
            [k[0] as usize & (BINS - 1), k[1] as usize & (BINS - 1), k[2] as usize & (BINS - 1)]
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            x.to_array().map(|v| (v as usize) & (BINS - 1))
        }
    }
}

impl Binning {
    /// Is doubled centroid `c` in a bin below `first` on `axis`? The same float operations as
    /// [`Binning::bins`] (whose truncation is monotonic), so binning and partition agree bit for
    /// bit; NaN is in bin 0, as there.
    #[inline(always)]
    fn below(&self, c: Vec3A, axis: usize, first: usize) -> bool {
        let i = axis.min(2);
        let (c, o, s): (&[f32; 3], &[f32; 3], &[f32; 3]) = (c.as_ref(), self.origin.as_ref(), self.scale.as_ref());
        !((c[i] - o[i]) * s[i] >= first as f32)
    }
}

fn bin_slice(bins: &mut Bins, prims: &[Bounds], binning: &Binning) {
    for p in prims {
        let k = binning.bins(p.centroid2());
        for (axis, bins) in bins.iter_mut().enumerate() {
            let b = &mut bins[k[axis]];
            b.bounds.grow(p);
            b.count += 1;
        }
    }
}

fn merge_bins(mut a: Bins, b: Bins) -> Bins {
    for axis in 0..3 {
        for i in 0..BINS {
            a[axis][i].bounds.grow(&b[axis][i].bounds);
            a[axis][i].count += b[axis][i].count;
        }
    }
    a
}

/// One bin on the three axes, lane a for axis a (lane 3: an empty box without triangles).
struct Transposed {
    /// Min x, y, z of the bin's box.
    lo: [Vec4; 3],
    /// Max x, y, z.
    hi: [Vec4; 3],
    count: Vec4,
}

impl Transposed {
    #[inline(always)]
    fn of(bins: &Bins, i: usize) -> Transposed {
        let b = [&bins[0][i], &bins[1][i], &bins[2][i]];
        let count = Vec4::new(b[0].count as f32, b[1].count as f32, b[2].count as f32, 0.0);
        let lo = transpose3([b[0].bounds.min, b[1].bounds.min, b[2].bounds.min], f32::INFINITY);
        let hi = transpose3([b[0].bounds.max, b[1].bounds.max, b[2].bounds.max], f32::NEG_INFINITY);
        Transposed { lo, hi, count }
    }
}

/// Rows x, y, z of the 3×3 matrix with rows `v`, as vectors with `w` in lane 3.
#[inline(always)]
fn transpose3(v: [Vec3A; 3], w: f32) -> [Vec4; 3] {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::*;
        let [a, b, c]: [__m128; 3] = v.map(Into::into);
        // SAFETY: SSE is part of x86-64 (the usual 4×4 transpose, fourth row all `w`).
        unsafe {
            let d = _mm_set1_ps(w);
            let (ab_lo, cd_lo) = (_mm_unpacklo_ps(a, b), _mm_unpacklo_ps(c, d));
            let (ab_hi, cd_hi) = (_mm_unpackhi_ps(a, b), _mm_unpackhi_ps(c, d));
            [_mm_movelh_ps(ab_lo, cd_lo).into(), _mm_movehl_ps(cd_lo, ab_lo).into(), _mm_movelh_ps(ab_hi, cd_hi).into()]
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        [0, 1, 2].map(|c| Vec4::new(v[0][c], v[1][c], v[2][c], w))
    }
}

/// The cheapest split of the binned cluster: (axis, first bin of the right side), or None when
/// no plane separates the centroids.
///
/// The three axes are swept at once, one SIMD lane each (lane 3 unused): the bins are transposed
/// once, then a right-to-left and a left-to-right pass accumulate boxes and counts. The costs are
/// the same float operations as one axis at a time (`half_area` times the count), so the chosen
/// split is too: the first bin of least cost, on the first axis of least cost.
fn best_split(bins: &Bins, binning: &Binning) -> Option<(usize, usize)> {
    let nb = binning.count;
    // Half the surface area of the boxes (0 for an empty one), as `Bounds::half_area`.
    let half_area = |lo: &[Vec4; 3], hi: &[Vec4; 3]| {
        let e = [0, 1, 2].map(|c| (hi[c] - lo[c]).max(Vec4::ZERO));
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    };
    // Cost of a side: its area times its count; NaN (never below the best) for an empty side.
    let cost =
        |lo: &[Vec4; 3], hi: &[Vec4; 3], n: Vec4| Vec4::select(n.cmpgt(Vec4::ZERO), half_area(lo, hi) * n, Vec4::NAN);
    // Bin i transposed (written by the right-to-left pass, read by the left-to-right one), and
    // the cost of the right side of a split before bin i.
    let mut t = [const { MaybeUninit::<Transposed>::uninit() }; BINS];
    let mut right_cost = [const { MaybeUninit::<Vec4>::uninit() }; BINS];
    let (mut acc_lo, mut acc_hi, mut n) = ([Vec4::INFINITY; 3], [Vec4::NEG_INFINITY; 3], Vec4::ZERO);
    for i in (1..nb).rev() {
        let b = t[i].write(Transposed::of(bins, i));
        for c in 0..3 {
            acc_lo[c] = acc_lo[c].min(b.lo[c]);
            acc_hi[c] = acc_hi[c].max(b.hi[c]);
        }
        n += b.count;
        right_cost[i].write(cost(&acc_lo, &acc_hi, n));
    }
    t[0].write(Transposed::of(bins, 0));
    let (mut acc_lo, mut acc_hi, mut n) = ([Vec4::INFINITY; 3], [Vec4::NEG_INFINITY; 3], Vec4::ZERO);
    let (mut best_cost, mut best_bin) = (Vec4::INFINITY, Vec4::ZERO);
    for i in 1..nb {
        // SAFETY: bins 0..nb and right costs 1..nb were written above.
        let (b, right) = unsafe { (t[i - 1].assume_init_ref(), right_cost[i].assume_init()) };
        for c in 0..3 {
            acc_lo[c] = acc_lo[c].min(b.lo[c]);
            acc_hi[c] = acc_hi[c].max(b.hi[c]);
        }
        n += b.count;
        let total = cost(&acc_lo, &acc_hi, n) + right;
        let better = total.cmplt(best_cost);
        best_cost = Vec4::select(better, total, best_cost);
        best_bin = Vec4::select(better, Vec4::splat(i as f32), best_bin);
    }
    let mut best: Option<(usize, usize)> = None;
    let mut least = f32::INFINITY;
    for axis in 0..3 {
        if binning.scale[axis] != 0.0 && best_cost[axis] < least {
            least = best_cost[axis];
            best = Some((axis, best_bin[axis] as usize));
        }
    }
    // Infinite costs (overflowing areas) leave `best` empty when nothing is finite; then a split
    // with both sides non-empty still exists on any axis with extent: take the middle of it.
    best.or_else(|| {
        (0..3).find(|&axis| binning.scale[axis] != 0.0).and_then(|axis| {
            let total: u32 = bins[axis].iter().map(|b| b.count).sum();
            let mut n = 0;
            (1..nb)
                .find(|&i| {
                    n += bins[axis][i - 1].count;
                    n > 0 && n < total && 2 * n >= total
                })
                .or_else(|| {
                    let mut n = 0;
                    (1..nb).find(|&i| {
                        n += bins[axis][i - 1].count;
                        n > 0 && n < total
                    })
                })
                .map(|i| (axis, i))
        })
    })
}

/// Split cluster `c` of `prims` / `ids` into two non-empty clusters (`bins`: scratch space).
fn split(prims: &mut [Bounds], ids: &mut [u32], c: &Cluster, bins: &mut Bins) -> (Cluster, Cluster) {
    debug_assert!(c.len() >= 2);
    let (p, id) = (&mut prims[c.start..c.end], &mut ids[c.start..c.end]);
    let binning = Binning::new(&c.centroids, p.len());
    if p.len() >= 2 * PARALLEL_BIN {
        *bins = p
            .par_chunks(PARALLEL_BIN)
            .map(|ch| {
                let mut bins = EMPTY_BINS;
                bin_slice(&mut bins, ch, &binning);
                bins
            })
            .reduce(|| EMPTY_BINS, merge_bins);
    } else {
        for axis in bins.iter_mut() {
            axis[..binning.count].fill(Bin { bounds: Bounds::EMPTY, count: 0 });
        }
        bin_slice(bins, p, &binning);
    }
    let (mut lb, mut lc, mut rb, mut rc) = (Bounds::EMPTY, Bounds::EMPTY, Bounds::EMPTY, Bounds::EMPTY);
    let mid = match best_split(bins, &binning) {
        Some((axis, first_right)) => {
            // Hoare's partition: each side scans past the primitives already on their side, and
            // only a misplaced pair is swapped.
            let (mut i, mut j) = (0, p.len());
            'outer: loop {
                let ci = loop {
                    if i == j {
                        break 'outer;
                    }
                    let cen = p[i].centroid2();
                    if !binning.below(cen, axis, first_right) {
                        break cen;
                    }
                    lb.grow(&p[i]);
                    lc.grow_point(cen);
                    i += 1;
                };
                // p[i] belongs right.
                let cj = loop {
                    j -= 1;
                    if j == i {
                        rb.grow(&p[i]);
                        rc.grow_point(ci);
                        break 'outer;
                    }
                    let cen = p[j].centroid2();
                    if binning.below(cen, axis, first_right) {
                        break cen;
                    }
                    rb.grow(&p[j]);
                    rc.grow_point(cen);
                };
                // p[j] belongs left: swap the pair.
                p.swap(i, j);
                id.swap(i, j);
                lb.grow(&p[i]);
                lc.grow_point(cj);
                rb.grow(&p[j]);
                rc.grow_point(ci);
                i += 1;
            }
            i
        }
        None => 0,
    };
    // No separating plane (all centroids equal, or a partition that came out one-sided): halve.
    let mid = if mid == 0 || mid == p.len() {
        let mid = p.len() / 2;
        (lb, lc, rb, rc) = (Bounds::EMPTY, Bounds::EMPTY, Bounds::EMPTY, Bounds::EMPTY);
        for b in &p[..mid] {
            lb.grow(b);
            lc.grow_point(b.centroid2());
        }
        for b in &p[mid..] {
            rb.grow(b);
            rc.grow_point(b.centroid2());
        }
        mid
    } else {
        mid
    };
    let m = c.start + mid;
    (
        Cluster { start: c.start, end: m, bounds: lb, centroids: lc },
        Cluster { start: m, end: c.end, bounds: rb, centroids: rc },
    )
}

/// Box and centroid box of `prims` (in parallel when large).
fn cluster_of(prims: &[Bounds]) -> Cluster {
    let one = |ch: &[Bounds]| {
        let (mut b, mut c) = (Bounds::EMPTY, Bounds::EMPTY);
        for p in ch {
            b.grow(p);
            c.grow_point(p.centroid2());
        }
        (b, c)
    };
    let (bounds, centroids) = if prims.len() >= 2 * PARALLEL_BIN {
        prims
            .par_chunks(PARALLEL_BIN)
            .map(one)
            .reduce(|| (Bounds::EMPTY, Bounds::EMPTY), |a, b| (a.0.union(&b.0), a.1.union(&b.1)))
    } else {
        one(prims)
    };
    Cluster { start: 0, end: prims.len(), bounds, centroids }
}

/// Nodes and leaves of a (sub)tree; child references are local to it. Subtrees built in
/// parallel stay separate parts (`links`) until [`flatten`] copies every part once into the tree.
struct Part {
    nodes: Vec<Node8>,
    /// Per leaf: the first position in the builder's index array and the triangle count.
    leaves: Vec<[u32; 2]>,
    /// Subtrees hanging from slot `slot` of local node `node`, with their local root reference.
    links: Vec<Link>,
    depth: usize,
    /// Scratch bins for the splits.
    bins: Box<Bins>,
}

struct Link {
    node: u32,
    slot: usize,
    part: Part,
    root: u32,
}

impl Part {
    /// An empty part, with room for a subtree over `n` triangles.
    fn new(n: usize) -> Part {
        Part {
            nodes: Vec::with_capacity(n / 12 + 1),
            leaves: Vec::with_capacity(n / 3 + 1),
            links: Vec::new(),
            depth: 0,
            bins: Box::new(EMPTY_BINS),
        }
    }

    fn leaf(&mut self, start: usize, len: usize) -> u32 {
        debug_assert!(len > 0 && len <= LEAF_SIZE);
        self.leaves.push([start as u32, len as u32]);
        LEAF | (self.leaves.len() - 1) as u32
    }

    /// Nodes and leaves of this part and all linked ones.
    fn sizes(&self) -> (usize, usize) {
        self.links.iter().fold((self.nodes.len(), self.leaves.len()), |(n, l), link| {
            let (a, b) = link.part.sizes();
            (n + a, l + b)
        })
    }
}

/// Append `part` (local root reference `root`) and its linked parts to `nodes` and `leaves`,
/// shifting references; returns the shifted root.
fn flatten(part: Part, root: u32, nodes: &mut Vec<Node8>, leaves: &mut Vec<[u32; 2]>) -> u32 {
    let (node_off, leaf_off) = (nodes.len() as u32, leaves.len() as u32);
    let shift = |c: u32| {
        if c == EMPTY {
            c
        } else if c & LEAF != 0 {
            LEAF | ((c & !LEAF) + leaf_off)
        } else {
            c + node_off
        }
    };
    nodes.extend(part.nodes.into_iter().map(|mut n| {
        n.child = n.child.map(shift);
        n
    }));
    leaves.extend(part.leaves);
    for link in part.links {
        let r = flatten(link.part, link.root, nodes, leaves);
        nodes[(node_off + link.node) as usize].child[link.slot] = r;
    }
    shift(root)
}

/// Up to eight clusters covering `c`: the one of largest area is split until there are eight or
/// none is left to split. Clusters of more than `LEAF_SIZE` triangles are always split; a
/// leaf-sized one (two or more triangles) only when its halves' box areas sum to less than
/// `LEAF_SPLIT` times its own (a ray then tests fewer triangles for the same node test: on the
/// Cornell box, walls that would share a room-sized leaf box get their own), as long as every
/// such split tried in this node paid. Sorted by position.
fn open(prims: &mut [Bounds], ids: &mut [u32], c: Cluster, bins: &mut Bins) -> ([Cluster; 8], usize) {
    let mut kids = [c; 8];
    // Leaf-sized clusters are tried largest first; once one does not pay, no other is tried (on
    // a smooth mesh none pays, and trying all of them made the build 7 % slower).
    let mut leaf_splits = true;
    let mut areas = [c.bounds.half_area(); 8];
    let mut n = 1;
    while n < 8 {
        let area = |i: usize| {
            let k = &kids[i];
            if k.len() > LEAF_SIZE || (k.len() >= 2 && leaf_splits) {
                areas[i]
            } else {
                -1.0
            }
        };
        let i = (0..n).fold(0, |b, i| if area(i) > area(b) { i } else { b });
        if area(i) < 0.0 {
            break;
        }
        let halves = if kids[i].len() > LEAF_SIZE {
            Some(split(prims, ids, &kids[i], bins))
        } else {
            split_leaf(prims, ids, &kids[i])
        };
        let Some((l, r)) = halves else {
            leaf_splits = false;
            continue;
        };
        (kids[i], kids[n]) = (l, r);
        (areas[i], areas[n]) = (l.bounds.half_area(), r.bounds.half_area());
        n += 1;
    }
    kids[..n].sort_unstable_by_key(|k| k.start);
    (kids, n)
}

/// The two halves of leaf-sized cluster `c` (at most `LEAF_SIZE` triangles) whose boxes have the
/// least total area, found over every bipartition, when that total is below `LEAF_SPLIT` times the
/// cluster's area; the triangles of the first half are moved to the front of its range.
fn split_leaf(prims: &mut [Bounds], ids: &mut [u32], c: &Cluster) -> Option<(Cluster, Cluster)> {
    const SUBSETS: usize = 1 << LEAF_SIZE;
    let (p, id) = (&mut prims[c.start..c.end], &mut ids[c.start..c.end]);
    let n = p.len();
    debug_assert!((2..=LEAF_SIZE).contains(&n));
    let full = (1usize << n) - 1;
    // Box of every subset, from the subset without its highest member.
    let mut boxes = [Bounds::EMPTY; SUBSETS];
    for mask in 1..=full {
        let top = usize::BITS - 1 - mask.leading_zeros();
        boxes[mask] = boxes[mask & !(1 << top)].union(&p[top as usize]);
    }
    // Subsets holding triangle 0 (each bipartition once), not the whole cluster.
    let (mut best, mut best_area) = (0, LEAF_SPLIT * c.bounds.half_area());
    for mask in (1..full).step_by(2) {
        let a = boxes[mask].half_area() + boxes[full ^ mask].half_area();
        if a < best_area {
            (best, best_area) = (mask, a);
        }
    }
    if best == 0 {
        return None;
    }
    // Members of `best` to the front, keeping the order within each half.
    let (mut pb, mut ib) = ([Bounds::EMPTY; LEAF_SIZE], [0u32; LEAF_SIZE]);
    let mut k = 0;
    for want in [true, false] {
        for j in 0..n {
            if (best >> j & 1 == 1) == want {
                (pb[k], ib[k]) = (p[j], id[j]);
                k += 1;
            }
        }
    }
    p.copy_from_slice(&pb[..n]);
    id.copy_from_slice(&ib[..n]);
    let m = best.count_ones() as usize;
    let centroids = |q: &[Bounds]| {
        let mut b = Bounds::EMPTY;
        q.iter().for_each(|x| b.grow_point(x.centroid2()));
        b
    };
    Some((
        Cluster { start: c.start, end: c.start + m, bounds: boxes[best], centroids: centroids(&p[..m]) },
        Cluster { start: c.start + m, end: c.end, bounds: boxes[full ^ best], centroids: centroids(&p[m..]) },
    ))
}

/// Emit the subtree over cluster `c` (which covers all of `prims`, starting at position `base`
/// of the builder's arrays) into `part`: its reference.
fn emit(part: &mut Part, prims: &mut [Bounds], ids: &mut [u32], c: Cluster, base: usize, depth: usize) -> u32 {
    if c.len() <= LEAF_SIZE {
        return part.leaf(base + c.start, c.len());
    }
    part.depth = part.depth.max(depth);
    let (kids, n) = open(prims, ids, c, &mut part.bins);
    let kids = &kids[..n];
    let index = part.nodes.len();
    part.nodes.push(Node8::UNUSED);
    let mut node = Node8::UNUSED;
    for (slot, k) in kids.iter().enumerate() {
        for axis in 0..3 {
            node.bounds[2 * axis][slot] = k.bounds.min[axis];
            node.bounds[2 * axis + 1][slot] = k.bounds.max[axis];
        }
    }
    let rebase = |k: &Cluster| Cluster { start: 0, end: k.len(), ..*k };
    if c.len() >= PARALLEL_NODE {
        // Disjoint slices per child, built concurrently into their own parts.
        let mut jobs = Vec::with_capacity(kids.len());
        let (mut rest_p, mut rest_i) = (prims, ids);
        for k in kids {
            let (p, tail_p) = std::mem::take(&mut rest_p).split_at_mut(k.len());
            let (i, tail_i) = std::mem::take(&mut rest_i).split_at_mut(k.len());
            (rest_p, rest_i) = (tail_p, tail_i);
            jobs.push((p, i, rebase(k), base + k.start));
        }
        let subs: Vec<(Part, u32)> = jobs
            .into_par_iter()
            .map(|(p, i, k, b)| {
                let mut sub = Part::new(k.len());
                let root = emit(&mut sub, p, i, k, b, depth + 1);
                (sub, root)
            })
            .collect();
        for (slot, (sub, root)) in subs.into_iter().enumerate() {
            part.depth = part.depth.max(sub.depth);
            part.links.push(Link { node: index as u32, slot, part: sub, root });
        }
    } else {
        for (slot, k) in kids.iter().enumerate() {
            node.child[slot] =
                emit(part, &mut prims[k.start..k.end], &mut ids[k.start..k.end], rebase(k), base + k.start, depth + 1);
        }
    }
    part.nodes[index] = node;
    index as u32
}

/// The BVH over triangles with boxes `bounds` (which may be padded); `triangle(i)` gives the
/// vertices of triangle `i` for the leaf packets and the record its lane holds. None when empty.
pub fn build(bounds: Vec<Bounds>, triangle: impl Fn(u32) -> ([Vec3; 3], LaneShade) + Sync) -> Option<Bvh8> {
    if bounds.is_empty() {
        return None;
    }
    let mut prims = bounds;
    let mut ids: Vec<u32> = (0..prims.len() as u32).collect();
    let root_cluster = cluster_of(&prims);
    let mut part = Part::new(prims.len());
    // A whole scene of at most LEAF_SIZE triangles is one packet (depth 0); else node 0 is the root.
    let root = emit(&mut part, &mut prims, &mut ids, root_cluster, 0, 1);
    drop(prims);
    let depth = part.depth;
    let (node_count, leaf_count) = part.sizes();
    let (mut nodes, mut leaves) = (Vec::with_capacity(node_count), Vec::with_capacity(leaf_count));
    let root = flatten(part, root, &mut nodes, &mut leaves);
    let (packets, lanes): (Vec<TriPacket4>, Vec<[LaneShade; LEAF_SIZE]>) = leaves
        .par_iter()
        .map(|&[start, len]| {
            let mut packet = TriPacket4::EMPTY;
            let mut lanes = [LaneShade::EMPTY; LEAF_SIZE];
            for (lane, &id) in ids[start as usize..(start + len) as usize].iter().enumerate() {
                let (tri, r) = triangle(id);
                packet.set(lane, tri);
                lanes[lane] = r;
            }
            (packet, lanes)
        })
        .unzip();
    Some(Bvh8 { nodes: Pages::new(nodes), packets: Pages::new(packets), lanes: Pages::new(lanes), root, depth })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn boxes(points: &[Vec3]) -> Vec<Bounds> {
        points.iter().map(|&p| Bounds { min: Vec3A::from(p), max: Vec3A::from(p) + 0.1 }).collect()
    }

    /// Every triangle is in exactly one lane, every child box contains its subtree's boxes, and
    /// the depth bound holds; also for coincident centroids and huge coordinates.
    #[test]
    fn tree_is_complete_and_boxes_contain_children() {
        let mut s = crate::sampler::Sampler::new(5, 0);
        let mut cases: Vec<Vec<Vec3>> = vec![
            (0..20_000).map(|_| Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * 10.0).collect(),
            vec![Vec3::ONE; 1000],
            (0..3).map(|i| Vec3::splat(i as f32)).collect(),
            (0..500).map(|i| Vec3::new(if i % 2 == 0 { 1e18 } else { -1e18 }, i as f32, 0.0)).collect(),
        ];
        cases.push((0..9000).map(|i| Vec3::new((i % 7) as f32, 0.0, 0.0)).collect());
        for pts in cases {
            let tris: Vec<[Vec3; 3]> = pts.iter().map(|&p| [p, p + Vec3::X * 0.1, p + Vec3::Y * 0.1]).collect();
            let b = boxes(&pts);
            let bvh = build(b.clone(), |i| (tris[i as usize], LaneShade::ids(0, i))).unwrap();
            let mut seen = vec![0u32; pts.len()];
            // (reference, box it must lie in, depth)
            let mut stack = vec![(bvh.root, Bounds { min: Vec3A::NEG_INFINITY, max: Vec3A::INFINITY }, 1)];
            while let Some((r, outer, d)) = stack.pop() {
                if r & LEAF != 0 {
                    let p = (r & !LEAF) as usize;
                    for id in bvh.lanes[p].iter().map(|l| l.prim) {
                        if id != u32::MAX {
                            seen[id as usize] += 1;
                            let pb = b[id as usize];
                            assert!(outer.min.cmple(pb.min).all() && pb.max.cmple(outer.max).all());
                        }
                    }
                    continue;
                }
                assert!(d <= bvh.depth);
                let n = &bvh.nodes[r as usize];
                for slot in 0..8 {
                    if n.child[slot] == EMPTY {
                        continue;
                    }
                    let cb = Bounds {
                        min: Vec3A::new(n.bounds[0][slot], n.bounds[2][slot], n.bounds[4][slot]),
                        max: Vec3A::new(n.bounds[1][slot], n.bounds[3][slot], n.bounds[5][slot]),
                    };
                    assert!(outer.min.cmple(cb.min).all() && cb.max.cmple(outer.max).all());
                    stack.push((n.child[slot], cb, d + 1));
                }
            }
            assert!(seen.iter().all(|&k| k == 1), "a triangle is missing or repeated");
        }
    }
}

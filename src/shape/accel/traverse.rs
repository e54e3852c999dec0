//! Traversal of the 8-wide BVH: closest hit (children visited nearest first, farther ones culled
//! once a hit is closer) and any hit (stops at the first blocker).
//!
//! The node test is the slab test on all eight children at once: one AVX2 instruction per plane
//! when the CPU has AVX2 (detected at run time), two SSE halves otherwise, with the same float
//! operations and so the same hit masks. It is conservative: the far distance of each box is
//! enlarged by 1 + 2γ₃ (Ize 2013, "Robust BVH Ray Traversal", JCGT 2(2)), so rounding never
//! culls a box the ray touches, and a zero direction component gives a finite inverse (no NaN
//! from 0 · ∞).

use super::bvh8::{Bvh8, LaneShade, Node8, EMPTY, LEAF, LEAF_SIZE};
use super::triangle::WatertightRay;
use crate::math::{RayA, Vec3};
use glam::Vec4;
use std::mem::MaybeUninit;

/// 1 + 2γ₃ rounded up, γ_n = n·ε / (1 − n·ε), ε = 2⁻²⁴ (Ize 2013, Sec. 3).
const FAR_SCALE: f32 = 1.000_000_4;

/// The ray as the node test needs it.
#[derive(Clone, Copy, Debug)]
pub struct NodeRay {
    /// −o: the slab test computes `b + (−o)`, which equals `b − o` bit for bit (IEEE negation is
    /// exact, and `x + (−y)` rounds as `x − y`) but lets the box row be read as a memory operand
    /// of the addition (a subtraction only takes the subtrahend from memory).
    pub neg_o: [f32; 3],
    pub inv_d: [f32; 3],
    /// Where the row of `Node8::bounds` holding the near (entry) plane per axis starts in the
    /// bounds read as one array of 48 floats (8 × row; [`Node8::row`]), and the far one's: an offset
    /// the node test adds to the node's address as it is, with no scaling per visit.
    pub near: [usize; 3],
    pub far: [usize; 3],
}

impl NodeRay {
    #[inline(always)]
    pub fn new(o: Vec3, d: Vec3) -> NodeRay {
        // −0.0 → +0.0, so that the sign test and the inverse agree.
        let d0 = Vec4::new(d.x, d.y, d.z, 1.0) + Vec4::ZERO;
        Self::with_inverse(-o, d0, Vec4::ONE / d0)
    }

    /// From `neg_o` = −o, `d0` = d + 0 (w lane 1) and its inverse `inv` = 1 / d0: a non-finite inverse (zero
    /// component) becomes ±`f32::MAX` with the sign of the component, so no 0 · ∞ makes a NaN.
    /// Branch-free; the same values as the scalar `1 / x, else MAX.copysign(x)`.
    #[inline(always)]
    pub fn with_inverse(neg_o: Vec3, d0: Vec4, inv: Vec4) -> NodeRay {
        let finite = inv.abs().cmplt(Vec4::splat(f32::INFINITY));
        let inv_d = Vec4::select(finite, inv, Vec4::splat(f32::MAX).copysign(d0));
        // The w lane (1) is never negative, so the octant is below 8.
        let [nx, ny, nz, fx, fy, fz] = ROWS[d0.cmplt(Vec4::ZERO).bitmask() as usize & 7];
        NodeRay {
            neg_o: neg_o.to_array(),
            inv_d: inv_d.truncate().to_array(),
            near: [nx, ny, nz].map(usize::from),
            far: [fx, fy, fz].map(usize::from),
        }
    }
}

/// `NodeRay`'s row offsets (near x, y, z, far x, y, z) by octant (bit `a` set when `d[a] < 0`):
/// 8 × (row of the near plane), the axis's min row (2a) or its max row when `d[a] < 0`, and the
/// other row for the far plane. One table row instead of shifts and masks per ray.
const ROWS: [[u8; 6]; 8] = rows_table();

/// The rows of [`ROWS`].
const fn rows_table() -> [[u8; 6]; 8] {
    let mut t = [[0; 6]; 8];
    let mut octant = 0;
    while octant < 8 {
        let mut a = 0;
        while a < 3 {
            let neg = (octant >> a) & 1;
            t[octant][a] = (8 * (2 * a + neg)) as u8;
            t[octant][3 + a] = (8 * (2 * a + 1 - neg)) as u8;
            a += 1;
        }
        octant += 1;
    }
    t
}

/// Everything the traversal needs of one ray, computed once per ray with one division: the node
/// test's inverse direction and octant, and the triangle test's axes and shear.
#[derive(Clone, Copy, Debug)]
pub struct TraceRay {
    pub node: NodeRay,
    pub wt: WatertightRay,
}

impl TraceRay {
    #[inline(always)]
    pub fn new(o: Vec3, d: Vec3) -> TraceRay {
        let d0 = Vec4::new(d.x, d.y, d.z, 1.0) + Vec4::ZERO;
        let inv = Vec4::ONE / d0;
        // Opaque to the optimiser, which would otherwise turn `b + (−o)` back into `b − o`.
        let neg_o = std::hint::black_box(-o);
        let node = NodeRay::with_inverse(neg_o, d0, inv);
        TraceRay { node, wt: WatertightRay::with_inverse_d0(neg_o, d, d0, inv) }
    }
}

/// Slab test on the eight children, portable version (two SSE halves on x86-64): hit mask, and
/// each child's entry distance in `t_near`.
#[inline(always)]
pub fn node_test_portable(node: &Node8, r: &NodeRay, tmax: f32, t_near: &mut [f32; 8]) -> u32 {
    let (mask, tn) = node_test_portable_near(node, r, tmax);
    store_near_portable(tn, t_near);
    mask
}

/// [`node_test_portable`] with the entry distances returned as two vectors (lanes 0–3, 4–7), so
/// the traversal stores them only where it orders two or more children.
#[inline(always)]
pub fn node_test_portable_near(node: &Node8, r: &NodeRay, tmax: f32) -> (u32, [Vec4; 2]) {
    let mut mask = 0;
    let mut tns = [Vec4::ZERO; 2];
    for (h, tns) in tns.iter_mut().enumerate() {
        let row = |off: usize| Vec4::from_slice(&node.bounds.as_flattened()[off + 4 * h..off + 4 * h + 4]);
        let slab = |a: usize| {
            let (neg_o, inv) = (Vec4::splat(r.neg_o[a]), Vec4::splat(r.inv_d[a]));
            ((row(r.near[a]) + neg_o) * inv, (row(r.far[a]) + neg_o) * inv)
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        let tn = nx.max(ny).max(nz.max(Vec4::ZERO));
        let tf = (fx.min(fy).min(fz) * Vec4::splat(FAR_SCALE)).min(Vec4::splat(tmax));
        mask |= tn.cmple(tf).bitmask() << (4 * h);
        *tns = tn;
    }
    (mask, tns)
}

/// The entry distances of [`node_test_portable_near`] into `t_near`.
#[inline(always)]
fn store_near_portable(tn: [Vec4; 2], t_near: &mut [f32; 8]) {
    tn[0].write_to_slice(&mut t_near[..4]);
    tn[1].write_to_slice(&mut t_near[4..]);
}

/// The slab test's entry and exit distances of the eight children in AVX registers (`tn`, `tf`),
/// shared by the AVX2 and AVX-512 node tests, which differ only in how they read the comparison.
#[cfg(target_arch = "x86_64")]
macro_rules! slab_avx {
    ($node:expr, $r:expr, $tmax:expr) => {{
        use std::arch::x86_64::*;
        let (node, r, tmax): (&Node8, &NodeRay, f32) = ($node, $r, $tmax);
        macro_rules! slab {
            ($a:expr) => {{
                let neg_o = _mm256_set1_ps(r.neg_o[$a]);
                let inv = _mm256_set1_ps(r.inv_d[$a]);
                // SAFETY: `r.near`/`r.far` are row offsets as `NodeRay::with_inverse` sets them.
                let near = _mm256_loadu_ps(unsafe { node.row(r.near[$a]) });
                let far = _mm256_loadu_ps(unsafe { node.row(r.far[$a]) });
                (_mm256_mul_ps(_mm256_add_ps(near, neg_o), inv), _mm256_mul_ps(_mm256_add_ps(far, neg_o), inv))
            }};
        }
        let (nx, fx) = slab!(0);
        let (ny, fy) = slab!(1);
        let (nz, fz) = slab!(2);
        let tn = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, _mm256_setzero_ps()));
        let tf = _mm256_mul_ps(_mm256_min_ps(_mm256_min_ps(fx, fy), fz), _mm256_set1_ps(FAR_SCALE));
        let tf = _mm256_min_ps(tf, _mm256_set1_ps(tmax));
        (tn, tf)
    }};
}

/// The same slab test in one AVX register per plane (a macro so that it inlines into the AVX2
/// traversal; see `node_test_avx` for a callable version).
#[cfg(target_arch = "x86_64")]
macro_rules! node_test_avx_body {
    ($node:expr, $r:expr, $tmax:expr) => {{
        use std::arch::x86_64::*;
        let (tn, tf) = slab_avx!($node, $r, $tmax);
        (_mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(tn, tf)) as u32, tn)
    }};
}

/// The entry distances of [`node_test_avx_body`] into `t_near` (written only where the traversal
/// orders two or more children).
#[cfg(target_arch = "x86_64")]
macro_rules! store_near_avx {
    ($tn:expr, $t_near:expr) => {{
        let t_near: &mut [f32; 8] = $t_near;
        // SAFETY: `t_near` holds eight floats.
        unsafe { std::arch::x86_64::_mm256_storeu_ps(t_near.as_mut_ptr(), $tn) }
    }};
}

/// The AVX slab test as a function (for tests).
///
/// # Safety
/// The CPU must support AVX, and `r` must come from [`NodeRay::new`] or [`NodeRay::with_inverse`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
pub unsafe fn node_test_avx(node: &Node8, r: &NodeRay, tmax: f32, t_near: &mut [f32; 8]) -> u32 {
    let (mask, tn) = node_test_avx_body!(node, r, tmax);
    store_near_avx!(tn, t_near);
    mask
}

/// `node_test_portable_near` in the form the traversal macros take.
macro_rules! node_test_portable_body {
    ($node:expr, $r:expr, $tmax:expr) => {
        node_test_portable_near($node, $r, $tmax)
    };
}

/// `store_near_portable` in the form the traversal macros take.
macro_rules! store_near_portable_body {
    ($tn:expr, $t_near:expr) => {
        store_near_portable($tn, $t_near)
    };
}

/// Stack entry: a child and a lower bound of its entry distance (`repr(C)`: the AVX2 ordering
/// writes entries as interleaved (child, t) pairs).
#[derive(Clone, Copy)]
#[repr(C)]
pub struct Entry {
    pub child: u32,
    pub t: f32,
}

/// Stack size that suffices for a tree of depth `depth`: the closest-hit traversal's sentinel, at
/// most 7 entries pushed per level, and room for the AVX2 ordering, which writes eight entries from
/// the top (`order_push_avx2`).
pub fn stack_size(depth: usize) -> usize {
    1 + 7 * depth + 8
}

/// The closest-hit traversal's bottom stack entry: its child ends the traversal, and its distance
/// (−∞) is never culled, so popping needs no test for an empty stack. It has the `LEAF` bit set
/// (so the descent stops at it) and is neither `EMPTY` nor a packet (the builder makes fewer than
/// 2³¹ − 2 packets).
const DONE: u32 = EMPTY - 1;

/// The closest hit the traversal found: its lane (index into `Bvh8::lanes` read as one array of
/// lanes; `u32::MAX` when nothing was hit), distance and barycentrics of vertices 1 and 2. Sixteen
/// bytes, returned in registers.
#[derive(Clone, Copy, Debug)]
pub struct Found {
    pub lane: u32,
    pub t: f32,
    pub b1: f32,
    pub b2: f32,
}

/// Start fetching the cache line at `p` (a hint: no fault, no effect on results). The closest
/// traversal calls it on the lane record of each new nearest hit, whose line the hit record reads
/// once the traversal ends.
#[inline(always)]
fn prefetch<T>(p: *const T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: prefetching is a hint and never faults, whatever the address.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>(p.cast::<i8>())
    };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = p;
}

/// Fixed stack size used when the tree allows it (deeper trees use a heap stack).
pub const STACK: usize = 128;

/// A traversal stack of `n` entries; only written entries are ever read.
pub type Stack = [MaybeUninit<Entry>];

/// Element `$i` of `$v` by reference: bounds-checked (`checked`), or not (`unchecked`: only in
/// the AVX2 traversal, whose safety contract guarantees every index: a tree as `build::build`
/// makes it and a stack of `stack_size(depth)` entries).
macro_rules! at {
    (checked, $v:expr, $i:expr) => {
        &$v[$i]
    };
    (unchecked, $v:expr, $i:expr) => {
        unsafe { $v.get_unchecked($i) }
    };
}

/// [`at!`] for writing.
macro_rules! at_mut {
    (checked, $v:expr, $i:expr) => {
        &mut $v[$i]
    };
    (unchecked, $v:expr, $i:expr) => {
        unsafe { $v.get_unchecked_mut($i) }
    };
}

/// Ordering of three or more hit children (`mask`), portable: an insertion sort of their keys
/// (entry distance with the slot in the low three bits) into descending order; pushes all but the
/// last (the nearest) onto the stack, farthest first, advances `sp` and yields the nearest child.
macro_rules! order_push_portable {
    ($node:expr, $mask:expr, $tn:expr, $t_near:expr, $stack:expr, $sp:ident, $key:ident) => {{
        let (node, mut mask, stack): (&Node8, u32, &mut Stack) = ($node, $mask, $stack);
        let mut keys = [0u32; 8];
        let mut n = 0;
        while mask != 0 {
            let slot = mask.trailing_zeros();
            mask &= mask - 1;
            let key = $key(slot);
            let mut i = n;
            while i > 0 && keys[i - 1] < key {
                keys[i] = keys[i - 1];
                i -= 1;
            }
            keys[i] = key;
            n += 1;
        }
        for &key in &keys[..n - 1] {
            stack[$sp] = MaybeUninit::new(Entry { child: node.child[(key & 7) as usize], t: f32::from_bits(key & !7) });
            $sp += 1;
        }
        node.child[(keys[n - 1] & 7) as usize]
    }};
}

/// [`order_push_portable`] in AVX2 registers: the eight keys (0 for a missed child, which sorts
/// last; a hit child's key is distinct from every other hit child's by its slot bits) sorted into
/// descending order by a bitonic network (Batcher 1968; six compare-exchange layers of unsigned
/// max/min), the children gathered by slot with one permute, and all eight (child, t) entries
/// written from the stack top (`stack_size` leaves room); `sp` advances past the `n − 1` farthest.
/// The same order as the insertion sort (the keys are distinct), so the same traversal.
#[cfg(target_arch = "x86_64")]
macro_rules! order_push_avx2 {
    ($node:expr, $mask:expr, $tn:expr, $t_near:expr, $stack:expr, $sp:ident, $key:ident) => {{
        use std::arch::x86_64::*;
        let (node, mask, t_near, stack): (&Node8, u32, &[f32; 8], &mut Stack) = ($node, $mask, $t_near, $stack);
        let bits = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        let hit = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(mask as i32), bits), bits);
        let slot = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let t = _mm256_castps_si256(_mm256_loadu_ps(t_near.as_ptr()));
        let not7 = _mm256_set1_epi32(!7);
        let mut k = _mm256_and_si256(_mm256_or_si256(_mm256_and_si256(t, not7), slot), hit);
        // Compare-exchange with the partner lane `i ^ j`; blend bit i set: lane i keeps the max.
        macro_rules! layer {
            ($partner:expr, $keep_max:literal) => {{
                let p = $partner;
                k = _mm256_blend_epi32::<$keep_max>(_mm256_min_epu32(k, p), _mm256_max_epu32(k, p));
            }};
        }
        layer!(_mm256_shuffle_epi32::<0xB1>(k), 0x99); // j = 1 in blocks of 2
        layer!(_mm256_shuffle_epi32::<0x4E>(k), 0xC3); // j = 2 in blocks of 4
        layer!(_mm256_shuffle_epi32::<0xB1>(k), 0xA5); // j = 1 in blocks of 4
        layer!(_mm256_permute4x64_epi64::<0x4E>(k), 0x0F); // j = 4, whole register descending
        layer!(_mm256_shuffle_epi32::<0x4E>(k), 0x33); // j = 2
        layer!(_mm256_shuffle_epi32::<0xB1>(k), 0x55); // j = 1
                                                       // SAFETY (loads): `child` is eight u32.
        let children = _mm256_loadu_si256(node.child.as_ptr().cast());
        let child = _mm256_permutevar8x32_epi32(children, _mm256_and_si256(k, _mm256_set1_epi32(7)));
        let tk = _mm256_and_si256(k, not7);
        let (lo, hi) = (_mm256_unpacklo_epi32(child, tk), _mm256_unpackhi_epi32(child, tk));
        let n = mask.count_ones() as usize;
        debug_assert!($sp + 8 <= stack.len());
        // SAFETY: `stack_size` leaves room for eight entries from any `sp` the traversal reaches
        // (at most 7 per level above), and `Entry` is `repr(C)` (child, t).
        unsafe {
            let top = stack.as_mut_ptr().add($sp).cast::<__m256i>();
            _mm256_storeu_si256(top, _mm256_permute2x128_si256::<0x20>(lo, hi));
            _mm256_storeu_si256(top.add(1), _mm256_permute2x128_si256::<0x31>(lo, hi));
        }
        $sp += n - 1;
        // SAFETY: written just above.
        unsafe { stack.get_unchecked($sp).assume_init().child }
    }};
}

/// BVHs of more bytes than this are traversed with [`prefetch_child`] of each stack entry: a
/// tree that fits in the L2 cache gains nothing by it and pays its instructions.
pub const PREFETCH_BYTES: usize = 1 << 20;

/// Start loading child `c` (a node or a leaf packet) into the cache: a child pushed onto the stack
/// is visited after the nearer one's subtree, by when the load has arrived. A hint only: it
/// changes no result, and a prefetch never faults.
#[inline(always)]
fn prefetch_child<const PF: bool>(bvh: &Bvh8, c: u32) {
    #[cfg(target_arch = "x86_64")]
    if PF {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let (p, lines) = if c & LEAF == 0 {
            (bvh.nodes.as_ptr().wrapping_add(c as usize).cast::<i8>(), 4)
        } else {
            (bvh.packets.as_ptr().wrapping_add((c & !LEAF) as usize).cast::<i8>(), 3)
        };
        for l in 0..lines {
            // SAFETY: `_mm_prefetch` is SSE (every x86-64 CPU) and never faults.
            unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(64 * l)) };
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (PF, bvh, c);
}

/// [`prefetch_child`] of the stack's top entry (the next to be popped), if any: every entry is
/// prefetched once it is on top, a whole subtree's traversal before it is visited.
macro_rules! prefetch_top {
    ($bvh:expr, $stack:expr, $sp:expr, $chk:ident) => {
        if PF && $sp > 0 {
            // SAFETY: entries below `sp` were written.
            #[allow(unused_unsafe)]
            let e = unsafe { at!($chk, $stack, $sp - 1).assume_init() };
            prefetch_child::<PF>($bvh, e.child);
        }
    };
}

/// A leaf test `$f` (a method of `WatertightRay`); the `_avx512` ones are `unsafe` (they need the
/// CPU features of the traversal that calls them).
macro_rules! leaf {
    ($f:ident, $wt:expr, $p:expr, $tmax:expr) => {{
        #[allow(unused_unsafe)]
        // SAFETY: an `_avx512` test runs only in `closest_avx512` / `any_avx512`, whose callers
        // guarantee the features.
        let r = unsafe { $wt.$f($p, $tmax) };
        r
    }};
}

/// Closest-hit traversal with node test `$node_test`: the nearest triangle in (0, tmax) as a
/// [`Found`]. A macro, so that each instance is compiled with the target features of the function
/// it expands in and the node test inlines.
macro_rules! closest_body {
    ($bvh:expr, $ray:expr, $tmax:expr, $stack:expr, $node_test:ident, $store:ident, $order:ident, $nearest:ident, $chk:ident) => {{
        let (bvh, ray, mut tmax, stack): (&Bvh8, &RayA, f32, &mut Stack) = ($bvh, $ray, $tmax, $stack);
        let tr = TraceRay::new(ray.o.into(), ray.d.into());
        let (nr, wt) = (&tr.node, &tr.wt);
        // The nearest hit so far: its lane (`u32::MAX` while none) and barycentrics; its distance is `tmax`.
        let (mut hit_lane, mut hit_b1, mut hit_b2) = (u32::MAX, 0.0f32, 0.0f32);
        *at_mut!($chk, stack, 0) = MaybeUninit::new(Entry { child: DONE, t: f32::NEG_INFINITY });
        let mut sp = 1usize;
        let mut cur = bvh.root;
        let mut t_near = [0.0f32; 8];
        loop {
            // Descend through inner nodes to the nearest hit child until a leaf (or nothing) is next.
            while cur & LEAF == 0 {
                let node = at!($chk, bvh.nodes, cur as usize);
                let (mask, tn) = $node_test!(node, nr, tmax);
                if mask == 0 {
                    cur = EMPTY;
                    break;
                }
                if mask & (mask - 1) == 0 {
                    cur = node.child[mask.trailing_zeros() as usize];
                    continue;
                }
                // Two or more: order by entry distance (non-negative, so its bits sort as integers;
                // the low three bits carry the slot), push all but the nearest, farthest first.
                $store!(tn, &mut t_near);
                let key = |slot: u32| (t_near[slot as usize].to_bits() & !7) | slot;
                let first = mask.trailing_zeros();
                let rest = mask & (mask - 1);
                if rest & (rest - 1) == 0 {
                    // Exactly two (the most common case): one comparison.
                    let (a, b) = (key(first), key(rest.trailing_zeros()));
                    let (near, far) = if a < b { (a, b) } else { (b, a) };
                    let far_child = node.child[(far & 7) as usize];
                    prefetch_child::<PF>(bvh, far_child);
                    *at_mut!($chk, stack, sp) =
                        MaybeUninit::new(Entry { child: far_child, t: f32::from_bits(far & !7) });
                    sp += 1;
                    cur = node.child[(near & 7) as usize];
                    continue;
                }
                // Three or more: all but the nearest pushed, farthest first.
                cur = $order!(node, mask, tn, &t_near, &mut *stack, sp, key);
                prefetch_top!(bvh, stack, sp, $chk);
            }
            if cur < DONE {
                let packet = (cur & !LEAF) as usize;
                if PF {
                    // In a large tree, the packet's four lane records (256 bytes) are requested
                    // with the packet itself, so that a hit's record, which the hit record reads
                    // right after the traversal, is not one more miss after the packet's.
                    let lanes = bvh.lanes.as_ptr().wrapping_add(packet).cast::<LaneShade>();
                    for l in 0..LEAF_SIZE {
                        prefetch(lanes.wrapping_add(l));
                    }
                }
                if let Some((lane, t, b1, b2)) = leaf!($nearest, wt, at!($chk, bvh.packets, packet), tmax) {
                    (hit_lane, tmax, hit_b1, hit_b2) = ((4 * packet + lane) as u32, t, b1, b2);
                    if !PF {
                        // (In a large tree it was requested with the packet, above.)
                        prefetch(bvh.lanes.as_ptr().wrapping_add(packet).cast::<LaneShade>().wrapping_add(lane));
                    }
                }
            } else if cur == DONE {
                break Found { lane: hit_lane, t: tmax, b1: hit_b1, b2: hit_b2 };
            }
            // Pop the nearest remaining child that may still hold a closer hit (the sentinel at
            // the bottom always qualifies; `!(t > tmax)` also takes it for a NaN `tmax`).
            loop {
                sp -= 1;
                // SAFETY: entries below `sp` were written.
                let e = *at!($chk, stack, sp);
                let e = unsafe { e.assume_init() };
                if !(e.t > tmax) {
                    cur = e.child;
                    break;
                }
            }
            prefetch_top!(bvh, stack, sp, $chk);
        }
    }};
}

/// Any-hit traversal with node test `$node_test`: true when a triangle is hit in (0, tmax).
macro_rules! any_body {
    ($bvh:expr, $ray:expr, $stack:expr, $node_test:ident, $push_rest:ident, $any:ident, $chk:ident) => {{
        let (bvh, ray, stack): (&Bvh8, &RayA, &mut Stack) = ($bvh, $ray, $stack);
        let tmax = ray.tmax;
        let tr = TraceRay::new(ray.o.into(), ray.d.into());
        let (nr, wt) = (&tr.node, &tr.wt);
        let mut sp = 0usize;
        let mut cur = bvh.root;
        loop {
            if cur & LEAF == 0 {
                let node = at!($chk, bvh.nodes, cur as usize);
                let (mask, _) = $node_test!(node, nr, tmax);
                if mask != 0 {
                    // Descend into the hit child of the highest slot; push the others (lowest
                    // first, so they are visited from the highest down).
                    let last = 31 - mask.leading_zeros();
                    $push_rest!(bvh, node, mask & !(1 << last), &mut *stack, sp, $chk);
                    prefetch_top!(bvh, stack, sp, $chk);
                    cur = node.child[last as usize];
                    continue;
                }
            } else if leaf!($any, wt, at!($chk, bvh.packets, (cur & !LEAF) as usize), tmax) {
                break true;
            }
            if sp == 0 {
                break false;
            }
            sp -= 1;
            // SAFETY: entries below `sp` were written.
            let e = *at!($chk, stack, sp);
            cur = unsafe { e.assume_init() }.child;
            prefetch_top!(bvh, stack, sp, $chk);
        }
    }};
}

/// The any-hit traversal's push of the children in `mask`, lowest slot first, one at a time.
macro_rules! push_rest_scalar {
    ($bvh:expr, $node:expr, $mask:expr, $stack:expr, $sp:ident, $chk:ident) => {{
        let (node, mut mask, stack): (&Node8, u32, &mut Stack) = ($node, $mask, $stack);
        while mask != 0 {
            let slot = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            *at_mut!($chk, stack, $sp) = MaybeUninit::new(Entry { child: node.child[slot], t: 0.0 });
            $sp += 1;
        }
    }};
}

/// Closest hit, portable node test.
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(t > tmax)`: see the pop in `closest_body`
pub fn closest_portable<const PF: bool>(bvh: &Bvh8, ray: &RayA, tmax: f32, stack: &mut Stack) -> Found {
    closest_body!(
        bvh,
        ray,
        tmax,
        stack,
        node_test_portable_body,
        store_near_portable_body,
        order_push_portable,
        nearest4,
        checked
    )
}

/// Any hit, portable node test.
pub fn any_portable<const PF: bool>(bvh: &Bvh8, ray: &RayA, stack: &mut Stack) -> bool {
    any_body!(bvh, ray, stack, node_test_portable_body, push_rest_scalar, any4, checked)
}

/// Closest hit, AVX node test.
///
/// # Safety
/// The CPU must support AVX2, BMI1, LZCNT and POPCNT (`Isa::detect`); `bvh` must be as
/// `build::build` makes it (every child and packet index in range, `depth` its depth) and `stack`
/// hold at least `stack_size(bvh.depth)` entries: the traversal indexes both without bounds checks.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,bmi1,lzcnt,popcnt")]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(t > tmax)`: see the pop in `closest_body`
pub unsafe fn closest_avx2<const PF: bool>(bvh: &Bvh8, ray: &RayA, tmax: f32, stack: &mut Stack) -> Found {
    closest_body!(bvh, ray, tmax, stack, node_test_avx_body, store_near_avx, order_push_avx2, nearest4, unchecked)
}

/// Any hit, AVX node test.
///
/// # Safety
/// As for `closest_avx2`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,bmi1,lzcnt,popcnt")]
pub unsafe fn any_avx2<const PF: bool>(bvh: &Bvh8, ray: &RayA, stack: &mut Stack) -> bool {
    any_body!(bvh, ray, stack, node_test_avx_body, push_rest_scalar, any4, unchecked)
}

/// The slab test of [`node_test_avx_body`] (the same float operations on the same registers) with
/// the comparison straight into a mask register (AVX-512VL), which the traversal branches on.
#[cfg(target_arch = "x86_64")]
macro_rules! node_test_avx512_body {
    ($node:expr, $r:expr, $tmax:expr) => {{
        use std::arch::x86_64::*;
        let (tn, tf) = slab_avx!($node, $r, $tmax);
        (_mm256_cmp_ps_mask::<_CMP_LE_OQ>(tn, tf) as u32, tn)
    }};
}

/// The AVX-512 slab test as a function (for tests).
///
/// # Safety
/// The CPU must support AVX-512F and AVX-512VL, and `r` must come from [`NodeRay::new`] or
/// [`NodeRay::with_inverse`].
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl")]
pub unsafe fn node_test_avx512(node: &Node8, r: &NodeRay, tmax: f32, t_near: &mut [f32; 8]) -> u32 {
    let (mask, tn) = node_test_avx512_body!(node, r, tmax);
    store_near_avx!(tn, t_near);
    mask
}

/// [`order_push_avx2`] with AVX-512VL: the keys made in one ternary-logic instruction, zero in the
/// missed lanes (a zero-masked write), each compare-exchange layer a min and a max merged under
/// a lane mask (no blend), and the eight (child, t) entries interleaved by one two-table permute
/// into one 64-byte store. The same sorting network on the same keys, so the same order.
#[cfg(target_arch = "x86_64")]
macro_rules! order_push_avx512 {
    ($node:expr, $mask:expr, $tn:expr, $t_near:expr, $stack:expr, $sp:ident, $key:ident) => {{
        use std::arch::x86_64::*;
        let (node, mask, tn, stack): (&Node8, u32, __m256, &mut Stack) = ($node, $mask, $tn, $stack);
        let slot = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let not7 = _mm256_set1_epi32(!7);
        // (t & !7) | slot (truth table 0xEA: A & B | C), 0 where missed.
        let mut k = _mm256_maskz_ternarylogic_epi32::<0xEA>(mask as __mmask8, _mm256_castps_si256(tn), not7, slot);
        // Compare-exchange with the partner lane `i ^ j`; mask bit i set: lane i keeps the max.
        macro_rules! layer {
            ($partner:expr, $keep_max:literal) => {{
                let p = $partner;
                k = _mm256_mask_max_epu32(_mm256_min_epu32(k, p), $keep_max, k, p);
            }};
        }
        layer!(_mm256_shuffle_epi32::<0xB1>(k), 0x99); // j = 1 in blocks of 2
        layer!(_mm256_shuffle_epi32::<0x4E>(k), 0xC3); // j = 2 in blocks of 4
        layer!(_mm256_shuffle_epi32::<0xB1>(k), 0xA5); // j = 1 in blocks of 4
        layer!(_mm256_permute4x64_epi64::<0x4E>(k), 0x0F); // j = 4, whole register descending
        layer!(_mm256_shuffle_epi32::<0x4E>(k), 0x33); // j = 2
        layer!(_mm256_shuffle_epi32::<0xB1>(k), 0x55); // j = 1
        // The child of each key by its slot bits (the permute reads only the low three bits).
        let children = _mm256_loadu_si256(node.child.as_ptr().cast());
        let child = _mm256_permutexvar_epi32(k, children);
        let tk = _mm256_and_si256(k, not7);
        // (child, t) pairs: lane 2i from `child` lane i, lane 2i + 1 from `tk` lane i (16 + i).
        let pairs = _mm512_permutex2var_epi32(
            _mm512_castsi256_si512(child),
            _mm512_setr_epi32(0, 16, 1, 17, 2, 18, 3, 19, 4, 20, 5, 21, 6, 22, 7, 23),
            _mm512_castsi256_si512(tk),
        );
        let n = mask.count_ones() as usize;
        debug_assert!($sp + 8 <= stack.len());
        // SAFETY: `stack_size` leaves room for eight entries from any `sp` the traversal reaches
        // (at most 7 per level above), and `Entry` is `repr(C)` (child, t).
        unsafe { _mm512_storeu_si512(stack.as_mut_ptr().add($sp).cast(), pairs) };
        $sp += n - 1;
        // SAFETY: written just above.
        unsafe { stack.get_unchecked($sp).assume_init().child }
    }};
}

/// [`push_rest_scalar`] with AVX-512: the children zero-extended to (child, 0.0) pairs and the
/// pushed ones compressed to the front of the register (in slot order) for one 64-byte store;
/// no loop, so no branch on how many are pushed.
#[cfg(target_arch = "x86_64")]
macro_rules! push_rest_avx512 {
    ($bvh:expr, $node:expr, $mask:expr, $stack:expr, $sp:ident, $chk:ident) => {{
        use std::arch::x86_64::*;
        let (node, mask, stack): (&Node8, u32, &mut Stack) = ($node, $mask, $stack);
        let pairs = _mm512_cvtepu32_epi64(_mm256_loadu_si256(node.child.as_ptr().cast()));
        debug_assert!($sp + 8 <= stack.len());
        // SAFETY: as in `order_push_avx512` (at most 7 entries per level; `Entry` is (child, t),
        // and 0.0 is all zero bits).
        unsafe {
            _mm512_storeu_si512(
                stack.as_mut_ptr().add($sp).cast(),
                _mm512_maskz_compress_epi64(mask as __mmask8, pairs),
            )
        };
        $sp += mask.count_ones() as usize;
    }};
}

/// Closest hit, AVX-512 node test and ordering.
///
/// # Safety
/// The CPU must support AVX-512F/VL/BW/DQ, AVX2, BMI1, LZCNT and POPCNT (`Isa::detect`); `bvh` and
/// `stack` as for `closest_avx2`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl,avx512bw,avx512dq,bmi1,lzcnt,popcnt")]
#[allow(clippy::neg_cmp_op_on_partial_ord)] // `!(t > tmax)`: see the pop in `closest_body`
pub unsafe fn closest_avx512<const PF: bool>(bvh: &Bvh8, ray: &RayA, tmax: f32, stack: &mut Stack) -> Found {
    closest_body!(
        bvh,
        ray,
        tmax,
        stack,
        node_test_avx512_body,
        store_near_avx,
        order_push_avx512,
        nearest4_avx512,
        unchecked
    )
}

/// Any hit, AVX-512 node test and push.
///
/// # Safety
/// As for `closest_avx512`.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl,avx512bw,avx512dq,bmi1,lzcnt,popcnt")]
pub unsafe fn any_avx512<const PF: bool>(bvh: &Bvh8, ray: &RayA, stack: &mut Stack) -> bool {
    any_body!(bvh, ray, stack, node_test_avx512_body, push_rest_avx512, any4_avx512, unchecked)
}

//! Brute force for tiny scenes (issue 11: "brute force for tiny meshes"): when the BVH holds at
//! most [`MAX_TRIANGLES`] triangles, a closest or any-hit query tests all of them at once, in one
//! AVX-512 register of sixteen lanes (two halves of eight with AVX2), instead of walking the tree:
//! no node tests, no stack and no branches on the tree's shape, which on a box of a dozen
//! triangles cost more than the triangle tests themselves.
//!
//! Each lane runs `triangle.rs`'s watertight test (Woop, Benthin & Wald 2013) with the same
//! operations in the same order, so a lane's (t, b1, b2) are the bits the packet test gives. When
//! an edge function is exactly zero somewhere, the lanes are handed to the packet test itself
//! (`WatertightRay::intersect4`, which recomputes it in `f64`), out of line.
//! The closest hit is the nearest in (0, tmax); among hits at exactly the same distance the first
//! lane in build order wins, where the tree takes the one in the leaf it visits first (such ties
//! need two triangles hit at the same `f32` distance).

use super::bvh8::{Bvh8, LEAF, LEAF_SIZE};
use super::traverse::Found;
use super::triangle::{nearest_of, TriPacket4, WatertightRay};
use crate::math::RayA;

/// Lanes of the test: one AVX-512 register of `f32`.
pub const WIDTH: usize = 16;

/// The largest triangle count tested by brute force: one register. Chosen by measurement (render
/// time, interleaved pairs at 1 thread, AVX-512; callgrind for AVX2): `media_null` (14 triangles)
/// −6 to −10 % time and −8 % instructions; `cornell_box` (36 triangles, three groups) the same time
/// with AVX-512 (11 pairs, median ratio 0.99) and +27 % instructions with AVX2, so it stays on the
/// tree.
pub const MAX_TRIANGLES: usize = WIDTH;

/// Sixteen triangles, one lane each: `v[vertex][axis][lane]`; an unused lane holds NaN vertices,
/// which never report a hit.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub struct TriPacket16 {
    pub v: [[[f32; WIDTH]; 3]; 3],
}

/// Every triangle of a tiny BVH, one per lane, and each lane's BVH lane (`Found::lane`).
pub struct Brute {
    group: TriPacket16,
    /// Per lane: `4 · packet + lane` of the BVH (`u32::MAX` in an unused lane).
    lane: [u32; WIDTH],
}

/// The watertight test's per-ray state, and the same unpacked for wide rows: the permuted axes,
/// the shear (sx, sy, sz) and −o in the permuted axes.
#[derive(Clone, Copy, Debug)]
struct Sheared {
    wt: WatertightRay,
    k: [usize; 3],
    s: [f32; 3],
    neg_o: [f32; 3],
}

impl Brute {
    /// The BVH's used lanes in packet order, or `None` when it holds more than [`MAX_TRIANGLES`]
    /// or is one leaf packet (whose four-wide test is the whole traversal, cheaper than the sixteen-lane one).
    pub fn new(bvh: &Bvh8) -> Option<Brute> {
        if bvh.root & LEAF != 0 {
            return None;
        }
        let used: Vec<(usize, usize)> = (0..bvh.packets.len())
            .flat_map(|p| (0..LEAF_SIZE).map(move |l| (p, l)))
            .filter(|&(p, l)| bvh.lanes[p][l].shape != u32::MAX)
            .collect();
        if used.is_empty() || used.len() > MAX_TRIANGLES {
            return None;
        }
        let mut group = TriPacket16 { v: [[[f32::NAN; WIDTH]; 3]; 3] };
        let mut lane = [u32::MAX; WIDTH];
        for (i, &(p, l)) in used.iter().enumerate() {
            for j in 0..3 {
                for axis in 0..3 {
                    group.v[j][axis][i] = bvh.packets[p].v[j][axis][l];
                }
            }
            lane[i] = (LEAF_SIZE * p + l) as u32;
        }
        Some(Brute { group, lane })
    }

    /// Triangles tested (the used lanes).
    pub fn triangles(&self) -> usize {
        self.lane.iter().filter(|&&l| l != u32::MAX).count()
    }

    /// Closest hit in (0, tmax), AVX-512: [`Found`] as the tree's traversal returns it.
    ///
    /// # Safety
    /// The CPU must support AVX-512F (`Isa::Avx512`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl,avx512dq,bmi1")]
    pub unsafe fn closest_avx512(&self, ray: &RayA, tmax: f32) -> Found {
        use std::arch::x86_64::*;
        let (ok, t, b1, b2) = test16(&Sheared::new(ray), &self.group, tmax);
        if ok == 0 {
            return Found { lane: u32::MAX, t: tmax, b1: 0.0, b2: 0.0 };
        }
        // The nearest lane, ties to the lowest (as testing the lanes one by one gives); most rays
        // hit one lane.
        let l = if ok & (ok - 1) == 0 {
            ok.trailing_zeros()
        } else {
            let t_hit = _mm512_mask_mov_ps(_mm512_set1_ps(f32::INFINITY), ok, t);
            let t_min = _mm512_set1_ps(_mm512_reduce_min_ps(t_hit));
            _mm512_mask_cmp_ps_mask::<_CMP_EQ_OQ>(ok, t_hit, t_min).trailing_zeros()
        };
        let pick = |x: __m512| _mm512_cvtss_f32(_mm512_permutexvar_ps(_mm512_set1_epi32(l as i32), x));
        Found { lane: self.lane[l as usize % WIDTH], t: pick(t), b1: pick(b1), b2: pick(b2) }
    }

    /// True when a triangle is hit in (0, ray.tmax), AVX-512.
    ///
    /// # Safety
    /// As for [`Brute::closest_avx512`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl,avx512dq,bmi1")]
    pub unsafe fn any_avx512(&self, ray: &RayA) -> bool {
        test16(&Sheared::new(ray), &self.group, ray.tmax).0 != 0
    }

    /// Closest hit in (0, tmax), AVX2: the lanes as two halves of eight.
    ///
    /// # Safety
    /// The CPU must support AVX2 (`Isa::Avx2`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,popcnt")]
    pub unsafe fn closest_avx2(&self, ray: &RayA, mut tmax: f32) -> Found {
        let sh = Sheared::new(ray);
        let mut found = Found { lane: u32::MAX, t: tmax, b1: 0.0, b2: 0.0 };
        for half in 0..2 {
            // The second half against the first's hit: strictly nearer, so ties go to the lower lane.
            let (ok, t, b1, b2) = test8(&sh, &self.group, half, tmax);
            if ok == 0 {
                continue;
            }
            let (t, b1, b2) = (to_array8(t), to_array8(b1), to_array8(b2));
            let best = nearest_of(ok, &t);
            tmax = t[best];
            found = Found { lane: self.lane[8 * half + best], t: t[best], b1: b1[best], b2: b2[best] };
        }
        found
    }

    /// True when a triangle is hit in (0, ray.tmax), AVX2.
    ///
    /// # Safety
    /// As for [`Brute::closest_avx2`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,popcnt")]
    pub unsafe fn any_avx2(&self, ray: &RayA) -> bool {
        let sh = Sheared::new(ray);
        test8(&sh, &self.group, 0, ray.tmax).0 != 0 || test8(&sh, &self.group, 1, ray.tmax).0 != 0
    }
}

impl Sheared {
    /// The state of [`WatertightRay::new`] (the same axes, shear and origin bits).
    #[inline(always)]
    fn new(ray: &RayA) -> Sheared {
        let wt = WatertightRay::new(ray.o.into(), ray.d.into());
        let (k, s, neg_o) = wt.parts();
        Sheared { wt, k, s, neg_o }
    }
}

#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn to_array8(v: std::arch::x86_64::__m256) -> [f32; 8] {
    // SAFETY: `__m256` is eight `f32`.
    unsafe { std::mem::transmute(v) }
}

/// The lanes `lanes` (a range of whole quarters) by the packet test itself, four at a time, as
/// (mask, [t, b1, b2]) arrays (lanes from the range's start): for rays where some edge function is
/// exactly zero, which the packet test recomputes in `f64`. The same bits as the vector tests give
/// elsewhere.
#[cold]
#[inline(never)]
fn lanes_packet(sh: &Sheared, g: &TriPacket16, lanes: std::ops::Range<usize>, tmax: f32) -> (u32, [[f32; 16]; 3]) {
    let (mut mask, mut out) = (0u32, [[0.0f32; 16]; 3]);
    for (q, first) in lanes.step_by(4).enumerate() {
        let mut p = TriPacket4::EMPTY;
        for j in 0..3 {
            for axis in 0..3 {
                p.v[j][axis].copy_from_slice(&g.v[j][axis][first..first + 4]);
            }
        }
        let (m, t, b1, b2) = sh.wt.intersect4(&p, tmax);
        mask |= m << (4 * q);
        for (row, v) in out.iter_mut().zip([t, b1, b2]) {
            row[4 * q..4 * q + 4].copy_from_slice(&v.to_array());
        }
    }
    (mask, out)
}

/// The watertight test on the sixteen lanes: hit mask in (0, tmax) and (t, b1, b2).
/// (Macros, not closures, inside: every intrinsic must inline into this function's features.)
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,avx512f,avx512vl,avx512dq,bmi1")]
#[inline]
unsafe fn test16(
    sh: &Sheared,
    g: &TriPacket16,
    tmax: f32,
) -> (u16, std::arch::x86_64::__m512, std::arch::x86_64::__m512, std::arch::x86_64::__m512) {
    use std::arch::x86_64::*;
    // SAFETY (every intrinsic): the caller runs with AVX-512F; rows are 64-byte aligned.
    let (sx, sy, sz) = (_mm512_set1_ps(sh.s[0]), _mm512_set1_ps(sh.s[1]), _mm512_set1_ps(sh.s[2]));
    let (ox, oy, oz) = (_mm512_set1_ps(sh.neg_o[0]), _mm512_set1_ps(sh.neg_o[1]), _mm512_set1_ps(sh.neg_o[2]));
    macro_rules! vert {
        ($j:expr) => {{
            // SAFETY: the axes are below 3 (`WatertightRay::parts`).
            let v = &g.v[$j];
            let rx = _mm512_add_ps(_mm512_load_ps(v.get_unchecked(sh.k[0]).as_ptr()), ox);
            let ry = _mm512_add_ps(_mm512_load_ps(v.get_unchecked(sh.k[1]).as_ptr()), oy);
            let rz = _mm512_add_ps(_mm512_load_ps(v.get_unchecked(sh.k[2]).as_ptr()), oz);
            (_mm512_sub_ps(rx, _mm512_mul_ps(sx, rz)), _mm512_sub_ps(ry, _mm512_mul_ps(sy, rz)), _mm512_mul_ps(sz, rz))
        }};
    }
    let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (vert!(0), vert!(1), vert!(2));
    macro_rules! cross {
        ($p:expr, $q:expr, $r:expr, $s:expr) => {
            _mm512_sub_ps(_mm512_mul_ps($p, $q), _mm512_mul_ps($r, $s))
        };
    }
    let (u, v, w) = (cross!(cx, by, cy, bx), cross!(ax, cy, ay, cx), cross!(bx, ay, by, ax));
    let zero = _mm512_setzero_ps();
    let exact_zero = _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(u, zero)
        | _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(v, zero)
        | _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(w, zero);
    if exact_zero != 0 {
        let (mask, [t, b1, b2]) = lanes_packet(sh, g, 0..16, tmax);
        return (mask as u16, _mm512_loadu_ps(t.as_ptr()), _mm512_loadu_ps(b1.as_ptr()), _mm512_loadu_ps(b2.as_ptr()));
    }
    let (mn, mx) = (_mm512_min_ps(_mm512_min_ps(u, v), w), _mm512_max_ps(_mm512_max_ps(u, v), w));
    let mixed = _mm512_mask_cmp_ps_mask::<_CMP_GT_OQ>(_mm512_cmp_ps_mask::<_CMP_LT_OQ>(mn, zero), mx, zero);
    let det = _mm512_add_ps(_mm512_add_ps(u, v), w);
    let t_scaled = _mm512_add_ps(_mm512_add_ps(_mm512_mul_ps(u, az), _mm512_mul_ps(v, bz)), _mm512_mul_ps(w, cz));
    let inv_det = _mm512_div_ps(_mm512_set1_ps(1.0), det);
    let t = _mm512_mul_ps(t_scaled, inv_det);
    let ok = _mm512_cmp_ps_mask::<_CMP_NEQ_UQ>(det, zero);
    let ok = _mm512_mask_cmp_ps_mask::<_CMP_GT_OQ>(ok, t, zero);
    let ok = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(ok, t, _mm512_set1_ps(tmax));
    (ok & !mixed, t, _mm512_mul_ps(v, inv_det), _mm512_mul_ps(w, inv_det))
}

/// The watertight test on lanes `8·half .. 8·half + 8` (AVX2): mask, (t, b1, b2).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,bmi1,popcnt")]
#[inline]
unsafe fn test8(
    sh: &Sheared,
    g: &TriPacket16,
    half: usize,
    tmax: f32,
) -> (u32, std::arch::x86_64::__m256, std::arch::x86_64::__m256, std::arch::x86_64::__m256) {
    use std::arch::x86_64::*;
    // SAFETY (every intrinsic): the caller runs with AVX2; rows are 32-byte aligned at 8·half.
    let (sx, sy, sz) = (_mm256_set1_ps(sh.s[0]), _mm256_set1_ps(sh.s[1]), _mm256_set1_ps(sh.s[2]));
    let (ox, oy, oz) = (_mm256_set1_ps(sh.neg_o[0]), _mm256_set1_ps(sh.neg_o[1]), _mm256_set1_ps(sh.neg_o[2]));
    macro_rules! vert {
        ($j:expr) => {{
            // SAFETY: the axes are below 3 and `half` below 2.
            let v = &g.v[$j];
            let rx = _mm256_add_ps(_mm256_load_ps(v.get_unchecked(sh.k[0]).as_ptr().add(8 * half)), ox);
            let ry = _mm256_add_ps(_mm256_load_ps(v.get_unchecked(sh.k[1]).as_ptr().add(8 * half)), oy);
            let rz = _mm256_add_ps(_mm256_load_ps(v.get_unchecked(sh.k[2]).as_ptr().add(8 * half)), oz);
            (_mm256_sub_ps(rx, _mm256_mul_ps(sx, rz)), _mm256_sub_ps(ry, _mm256_mul_ps(sy, rz)), _mm256_mul_ps(sz, rz))
        }};
    }
    let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (vert!(0), vert!(1), vert!(2));
    macro_rules! cross {
        ($p:expr, $q:expr, $r:expr, $s:expr) => {
            _mm256_sub_ps(_mm256_mul_ps($p, $q), _mm256_mul_ps($r, $s))
        };
    }
    let (u, v, w) = (cross!(cx, by, cy, bx), cross!(ax, cy, ay, cx), cross!(bx, ay, by, ax));
    let zero = _mm256_setzero_ps();
    macro_rules! bits {
        ($x:expr) => {
            _mm256_movemask_ps($x) as u32
        };
    }
    // The lanes where `cmp(x, 0)` holds for some edge function x of (u, v, w).
    macro_rules! any_edge {
        ($cmp:ident) => {
            bits!(_mm256_or_ps(
                _mm256_or_ps(_mm256_cmp_ps::<$cmp>(u, zero), _mm256_cmp_ps::<$cmp>(v, zero)),
                _mm256_cmp_ps::<$cmp>(w, zero),
            ))
        };
    }
    if any_edge!(_CMP_EQ_OQ) != 0 {
        let (mask, [t, b1, b2]) = lanes_packet(sh, g, 8 * half..8 * half + 8, tmax);
        return (mask, _mm256_loadu_ps(t.as_ptr()), _mm256_loadu_ps(b1.as_ptr()), _mm256_loadu_ps(b2.as_ptr()));
    }
    let (neg, pos) = (any_edge!(_CMP_LT_OQ), any_edge!(_CMP_GT_OQ));
    let det = _mm256_add_ps(_mm256_add_ps(u, v), w);
    let t_scaled = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(u, az), _mm256_mul_ps(v, bz)), _mm256_mul_ps(w, cz));
    let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
    let t = _mm256_mul_ps(t_scaled, inv_det);
    let ok = _mm256_and_ps(_mm256_cmp_ps::<_CMP_NEQ_UQ>(det, zero), _mm256_cmp_ps::<_CMP_GT_OQ>(t, zero));
    let ok = bits!(_mm256_and_ps(ok, _mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_set1_ps(tmax))));
    (ok & !(neg & pos), t, _mm256_mul_ps(v, inv_det), _mm256_mul_ps(w, inv_det))
}

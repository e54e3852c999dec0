//! Brute force for tiny scenes (issue 11: "brute force for tiny meshes"): when the BVH holds at
//! most [`MAX_TRIANGLES`] triangles, a closest or any-hit query tests every one of them, sixteen
//! per AVX-512 register (two halves of eight with AVX2), instead of walking the tree: no node
//! tests, no stack and no branches on the tree's shape, which on a box of a dozen triangles cost
//! more than the triangle tests themselves.
//!
//! Each lane runs `triangle.rs`'s watertight test (Woop, Benthin & Wald 2013) with the same
//! operations in the same order, so a lane's (t, b1, b2) are the bits the packet test gives, and
//! an edge function that is exactly zero is recomputed in `f64` as there (out of line, per lane).
//! The closest hit is the nearest in (0, tmax); among hits at exactly the same distance the first
//! lane in build order wins, where the tree takes the one in the leaf it visits first (such ties
//! need two triangles hit at the same `f32` distance).

use super::bvh8::{Bvh8, LEAF, LEAF_SIZE};
use super::traverse::Found;
use super::triangle::{nearest_of, WatertightRay};
use crate::math::RayA;

/// Lanes per group.
pub const WIDTH: usize = 16;

/// The largest triangle count tested by brute force: one group. Chosen by measurement (render
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

/// Every triangle of a tiny BVH in groups of sixteen, and each lane's BVH lane (`Found::lane`).
pub struct Brute {
    groups: Vec<TriPacket16>,
    /// Per group lane: `4 · packet + lane` of the BVH (`u32::MAX` in an unused lane).
    lane: Vec<u32>,
}

/// The watertight test's per-ray state, unpacked for wide rows: the permuted axes, the shear
/// (sx, sy, sz) and −o in the permuted axes.
#[derive(Clone, Copy, Debug)]
struct Sheared {
    k: [usize; 3],
    s: [f32; 3],
    neg_o: [f32; 3],
}

impl Brute {
    /// The BVH's used lanes in packet order, or `None` when it holds more than [`MAX_TRIANGLES`]
    /// or is one leaf packet (whose four-wide test is the whole traversal, cheaper than a group's).
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
        let n_groups = used.len().div_ceil(WIDTH);
        let mut groups = vec![TriPacket16 { v: [[[f32::NAN; WIDTH]; 3]; 3] }; n_groups];
        let mut lane = vec![u32::MAX; n_groups * WIDTH];
        for (i, &(p, l)) in used.iter().enumerate() {
            let (g, gl) = (i / WIDTH, i % WIDTH);
            for j in 0..3 {
                for axis in 0..3 {
                    groups[g].v[j][axis][gl] = bvh.packets[p].v[j][axis][l];
                }
            }
            lane[i] = (LEAF_SIZE * p + l) as u32;
        }
        Some(Brute { groups, lane })
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
        let sh = Sheared::new(ray);
        // Every group tested against `tmax` (independent tests, so they overlap in the core), and
        // per lane slot the nearest over the groups kept (strictly nearer: ties to the earlier
        // group), with its group's lane index.
        let iota = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
        let (mut best_t, mut best_b1, mut best_b2) =
            (_mm512_set1_ps(f32::INFINITY), _mm512_setzero_ps(), _mm512_setzero_ps());
        let (mut best_i, mut any) = (_mm512_setzero_si512(), 0u16);
        for (g, group) in self.groups.iter().enumerate() {
            let (ok, t, b1, b2) = test16(&sh, group, tmax);
            let m = _mm512_mask_cmp_ps_mask::<_CMP_LT_OQ>(ok, t, best_t);
            best_t = _mm512_mask_mov_ps(best_t, m, t);
            best_b1 = _mm512_mask_mov_ps(best_b1, m, b1);
            best_b2 = _mm512_mask_mov_ps(best_b2, m, b2);
            best_i = _mm512_mask_mov_epi32(best_i, m, _mm512_add_epi32(iota, _mm512_set1_epi32((g * WIDTH) as i32)));
            any |= ok;
        }
        if any == 0 {
            return Found { lane: u32::MAX, t: tmax, b1: 0.0, b2: 0.0 };
        }
        // The nearest slot; among slots at exactly the same distance the lowest lane index, so
        // the hit is the first nearest lane in build order, as testing the lanes one by one gives.
        let t_min = if any & (any - 1) == 0 { f32::INFINITY } else { _mm512_reduce_min_ps(best_t) };
        let at_min =
            if any & (any - 1) == 0 { any } else { _mm512_cmp_ps_mask::<_CMP_EQ_OQ>(best_t, _mm512_set1_ps(t_min)) };
        let slot = if at_min & (at_min - 1) == 0 {
            at_min.trailing_zeros()
        } else {
            let i = _mm512_mask_mov_epi32(_mm512_set1_epi32(i32::MAX), at_min, best_i);
            (_mm512_reduce_min_epi32(i) as u32) % WIDTH as u32
        };
        let pick = |x: __m512| _mm512_cvtss_f32(_mm512_permutexvar_ps(_mm512_set1_epi32(slot as i32), x));
        let i = _mm512_cvtsi512_si32(_mm512_permutexvar_epi32(_mm512_set1_epi32(slot as i32), best_i)) as usize;
        Found { lane: self.lane[i % self.lane.len()], t: pick(best_t), b1: pick(best_b1), b2: pick(best_b2) }
    }

    /// True when a triangle is hit in (0, ray.tmax), AVX-512.
    ///
    /// # Safety
    /// As for [`Brute::closest_avx512`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,avx512f,avx512vl,avx512dq,bmi1")]
    pub unsafe fn any_avx512(&self, ray: &RayA) -> bool {
        let sh = Sheared::new(ray);
        self.groups.iter().any(|group| test16(&sh, group, ray.tmax).0 != 0)
    }

    /// Closest hit in (0, tmax), AVX2: each group as two halves of eight lanes.
    ///
    /// # Safety
    /// The CPU must support AVX2 (`Isa::Avx2`).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,bmi1,popcnt")]
    pub unsafe fn closest_avx2(&self, ray: &RayA, mut tmax: f32) -> Found {
        let sh = Sheared::new(ray);
        let mut found = Found { lane: u32::MAX, t: tmax, b1: 0.0, b2: 0.0 };
        for (g, group) in self.groups.iter().enumerate() {
            for half in 0..2 {
                let (ok, t, b1, b2) = test8(&sh, group, half, tmax);
                if ok == 0 {
                    continue;
                }
                let (t, b1, b2) = (to_array8(t), to_array8(b1), to_array8(b2));
                let best = nearest_of(ok, &t);
                tmax = t[best];
                let lane = self.lane[g * WIDTH + 8 * half + best];
                found = Found { lane, t: t[best], b1: b1[best], b2: b2[best] };
            }
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
        self.groups.iter().any(|group| test8(&sh, group, 0, ray.tmax).0 != 0 || test8(&sh, group, 1, ray.tmax).0 != 0)
    }
}

impl Sheared {
    /// The state of [`WatertightRay::new`] (the same axes, shear and origin bits).
    #[inline(always)]
    fn new(ray: &RayA) -> Sheared {
        let (k, s, neg_o) = WatertightRay::new(ray.o.into(), ray.d.into()).parts();
        Sheared { k, s, neg_o }
    }
}

#[cfg(target_arch = "x86_64")]
#[inline(always)]
fn to_array8(v: std::arch::x86_64::__m256) -> [f32; 8] {
    // SAFETY: `__m256` is eight `f32`.
    unsafe { std::mem::transmute(v) }
}

/// The watertight test of one lane in scalar code, with the f64 recomputation of the edge
/// functions when one is exactly zero: `Some((t, b1, b2))` for a hit in (0, tmax). The same
/// operations, in the same order, as `WatertightRay::intersect4` (and the vector tests below).
#[inline(never)]
#[cold]
fn lane_scalar(sh: &Sheared, g: &TriPacket16, l: usize, tmax: f32) -> Option<(f32, f32, f32)> {
    let [kx, ky, kz] = sh.k;
    let [sx, sy, sz] = sh.s;
    let [ox, oy, oz] = sh.neg_o;
    let vert = |j: usize| {
        let v = &g.v[j];
        let (rx, ry, rz) = (v[kx][l] + ox, v[ky][l] + oy, v[kz][l] + oz);
        (rx - sx * rz, ry - sy * rz, sz * rz)
    };
    let ((ax, ay, az), (bx, by, bz), (cx, cy, cz)) = (vert(0), vert(1), vert(2));
    let mut u = cx * by - cy * bx;
    let mut v = ax * cy - ay * cx;
    let mut w = bx * ay - by * ax;
    if u == 0.0 || v == 0.0 || w == 0.0 {
        let d = f64::from;
        u = (d(cx) * d(by) - d(cy) * d(bx)) as f32;
        v = (d(ax) * d(cy) - d(ay) * d(cx)) as f32;
        w = (d(bx) * d(ay) - d(by) * d(ax)) as f32;
    }
    if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
        return None;
    }
    let det = u + v + w;
    let t_scaled = u * az + v * bz + w * cz;
    let inv_det = 1.0 / det;
    let t = t_scaled * inv_det;
    (det != 0.0 && t > 0.0 && t < tmax).then_some((t, v * inv_det, w * inv_det))
}

/// The lanes `lanes` of a group by [`lane_scalar`], as (mask, t, b1, b2) arrays.
#[cold]
#[inline(never)]
fn lanes_scalar(sh: &Sheared, g: &TriPacket16, lanes: std::ops::Range<usize>, tmax: f32) -> (u32, [[f32; 16]; 3]) {
    let (mut mask, mut out) = (0u32, [[0.0f32; 16]; 3]);
    for (i, l) in lanes.enumerate() {
        if let Some((t, b1, b2)) = lane_scalar(sh, g, l, tmax) {
            mask |= 1 << i;
            (out[0][i], out[1][i], out[2][i]) = (t, b1, b2);
        }
    }
    (mask, out)
}

/// The watertight test on a group's sixteen lanes: hit mask in (0, tmax) and (t, b1, b2).
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
        let (mask, [t, b1, b2]) = lanes_scalar(sh, g, 0..16, tmax);
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

/// The watertight test on lanes `8·half .. 8·half + 8` of a group (AVX2): mask, (t, b1, b2).
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
        let (mask, [t, b1, b2]) = lanes_scalar(sh, g, 8 * half..8 * half + 8, tmax);
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

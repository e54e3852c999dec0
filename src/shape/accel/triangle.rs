//! Watertight ray/triangle test (Woop, Benthin & Wald 2013, "Watertight Ray/Triangle
//! Intersection", JCGT 2(1)) on four triangles at once, stored as a structure of arrays.
//!
//! Every lane computes exactly the paper's scalar operations (axis permutation, shear, edge
//! functions, double-precision recomputation of an edge function that is exactly zero), so a lane
//! gives the same bits as the scalar test and two triangles sharing an edge agree on which side of
//! it the ray passes: no ray slips between them.

use crate::math::Vec3;
use glam::{Vec4, Vec4Swizzles};

/// Four triangles, one lane each: `v[vertex][axis][lane]`. An unused lane holds NaN vertices,
/// which never report a hit.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct TriPacket4 {
    pub v: [[[f32; 4]; 3]; 3],
}

impl TriPacket4 {
    pub const EMPTY: TriPacket4 = TriPacket4 { v: [[[f32::NAN; 4]; 3]; 3] };

    pub fn set(&mut self, lane: usize, tri: [Vec3; 3]) {
        for (j, p) in tri.iter().enumerate() {
            for axis in 0..3 {
                self.v[j][axis][lane] = p[axis];
            }
        }
    }
}

/// Woop et al. 2013's axis permutation and shear of a ray direction `d`: `kz` is the dominant
/// axis, `kx, ky` follow it (swapped when `d[kz] < 0`, keeping the winding), and
/// `(sx, sy, sz) = (d[kx]/d[kz], d[ky]/d[kz], 1/d[kz])`.
#[inline(always)]
pub fn shear_axes(d: Vec3) -> ([usize; 3], [f32; 3]) {
    let a = d.abs();
    let kz = if a.x > a.y {
        if a.x > a.z {
            0
        } else {
            2
        }
    } else if a.y > a.z {
        1
    } else {
        2
    };
    let mut kx = (kz + 1) % 3;
    let mut ky = (kx + 1) % 3;
    if d[kz] < 0.0 {
        std::mem::swap(&mut kx, &mut ky);
    }
    let sz = 1.0 / d[kz];
    ([kx, ky, kz], [d[kx] * sz, d[ky] * sz, sz])
}

/// `(kx, ky, kz)` of [`shear_axes`] by row `octant | cmp << 3`: `octant` holds the signs of the
/// direction (bit `a` set when `d[a] < 0`) and `cmp` the comparisons of its magnitudes
/// (|dx| > |dy|, |dx| > |dz|, |dy| > |dz| in bits 0, 1, 2), so one load replaces the branches of
/// `shear_axes`. Rows of intransitive comparisons never occur.
const AXES: [[u8; 3]; 64] = axes_table();

/// The rows of [`AXES`], by `shear_axes`'s rule.
const fn axes_table() -> [[u8; 3]; 64] {
    let mut t = [[0; 3]; 64];
    let mut row = 0;
    while row < 64 {
        let (octant, cmp) = (row & 7, row >> 3);
        // a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2).
        let kz = if cmp & 1 != 0 {
            if cmp & 2 != 0 {
                0
            } else {
                2
            }
        } else if cmp & 4 != 0 {
            1
        } else {
            2
        };
        let (kx, ky) = ((kz + 1) % 3, (kz + 2) % 3);
        t[row] = if (octant >> kz) & 1 != 0 { [ky, kx, kz] } else { [kx, ky, kz] };
        row += 1;
    }
    t
}

/// Per-ray precomputation of the watertight test (Woop et al. 2013, Sec. 3).
#[derive(Clone, Copy, Debug)]
pub struct WatertightRay {
    /// Axes (kx, ky, kz), each as 16 × axis: the byte offset of the axis's row in a vertex's
    /// `[[f32; 4]; 3]` (so a visit adds it to the address as it is, with no scaling).
    k: [usize; 3],
    /// Shear (sx, sy, sz, 0), one vector: a leaf visit broadcasts each lane from memory as it
    /// would load a splatted copy, and the per-ray setup stores one vector instead of three.
    s: Vec4,
    /// Minus the ray origin in the permuted axes (x, y, z, 0) (`v + (−o)` is `v − o` bit for bit, and
    /// takes the vertex row as a memory operand).
    neg_o: Vec4,
}

/// The edge functions recomputed in `f64` (Woop et al. 2013, Sec. 3.3) in the lanes of `lanes`,
/// the `f32` ones `uvw` elsewhere. Rare (the ray meets an edge or vertex in float precision), so
/// out of line: it shears the packet's vertices again (the same operations, so the same bits)
/// rather than have the test keep the sheared coordinates alive across the branch, which would
/// spill them on every leaf visit.
#[cold]
#[inline(never)]
fn edges_f64(ray: WatertightRay, p: &TriPacket4, lanes: u32, uvw: [Vec4; 3]) -> [Vec4; 3] {
    let ((ax, ay, _), (bx, by, _), (cx, cy, _)) = (sheared(&ray, p, 0), sheared(&ray, p, 1), sheared(&ray, p, 2));
    let (ax, ay, bx, by) = (ax.as_dvec4(), ay.as_dvec4(), bx.as_dvec4(), by.as_dvec4());
    let (cx, cy) = (cx.as_dvec4(), cy.as_dvec4());
    let u = (cx * by - cy * bx).as_vec4();
    let v = (ax * cy - ay * cx).as_vec4();
    let w = (bx * ay - by * ax).as_vec4();
    let m = glam::BVec4A::new(lanes & 1 != 0, lanes & 2 != 0, lanes & 4 != 0, lanes & 8 != 0);
    [Vec4::select(m, u, uvw[0]), Vec4::select(m, v, uvw[1]), Vec4::select(m, w, uvw[2])]
}

/// The nearest of the hit lanes `mask` (ties to the lowest): (lane, t, b1, b2).
#[inline(always)]
fn nearest_lane(mask: u32, t: Vec4, b1: Vec4, b2: Vec4) -> Option<(usize, f32, f32, f32)> {
    if mask == 0 {
        return None;
    }
    let best = nearest_of(mask, &t.to_array());
    Some((best, t.to_array()[best], b1.to_array()[best], b2.to_array()[best]))
}

/// The lane of the smallest `t` among the lanes of the non-zero `mask`, ties to the lowest (the
/// lanes in ascending order, replaced only by a strictly smaller `t`). `N` is a power of two.
#[inline(always)]
pub fn nearest_of<const N: usize>(mut mask: u32, t: &[f32; N]) -> usize {
    debug_assert!(mask != 0 && N.is_power_of_two());
    // `& (N − 1)`: the lanes of an N-bit mask (free where the compiler knows the mask's width;
    // elsewhere it replaces a bounds check).
    let mut best = mask.trailing_zeros() as usize & (N - 1);
    mask &= mask - 1;
    while mask != 0 {
        let l = mask.trailing_zeros() as usize & (N - 1);
        mask &= mask - 1;
        if t[l] < t[best] {
            best = l;
        }
    }
    best
}

/// The packet test after the edge functions `uvw` (and the sheared z coordinates `z` of the three
/// vertices): the lanes hit in (0, tmax) and their (t, b1, b2).
#[inline(always)]
fn finish4([u, v, w]: [Vec4; 3], [az, bz, cz]: [Vec4; 3], tmax: f32) -> (u32, Vec4, Vec4, Vec4) {
    let zero = Vec4::ZERO;
    let neg = (u.cmplt(zero) | v.cmplt(zero) | w.cmplt(zero)).bitmask();
    let pos = (u.cmpgt(zero) | v.cmpgt(zero) | w.cmpgt(zero)).bitmask();
    let det = u + v + w;
    let t_scaled = u * az + v * bz + w * cz;
    let inv_det = Vec4::ONE / det;
    let t = t_scaled * inv_det;
    let mask =
        !(neg & pos) & det.cmpne(zero).bitmask() & t.cmpgt(zero).bitmask() & t.cmplt(Vec4::splat(tmax)).bitmask();
    (mask & 0xF, t, v * inv_det, w * inv_det)
}

/// The rest of the packet test when an edge function of the lanes `lanes` is exactly 0: those
/// recomputed in `f64` ([`edges_f64`]), the vertices sheared again (the same operations, so the
/// same bits) for their z, and [`finish4`]. Rare, so out of line (for the AVX-512 test).
#[cold]
#[inline(never)]
#[cfg(target_arch = "x86_64")]
fn intersect4_exact_zero(
    ray: WatertightRay,
    p: &TriPacket4,
    lanes: u32,
    uvw: [Vec4; 3],
    tmax: f32,
) -> (u32, Vec4, Vec4, Vec4) {
    let uvw = edges_f64(ray, p, lanes, uvw);
    let z = [0, 1, 2].map(|j| sheared(&ray, p, j).2);
    finish4(uvw, z, tmax)
}

/// Sheared vertex coordinates (x, y, z) of one vertex in the four lanes.
#[inline(always)]
fn sheared(w: &WatertightRay, p: &TriPacket4, j: usize) -> (Vec4, Vec4, Vec4) {
    let v = &p.v[j];
    // SAFETY: `w.k` holds 16 × axis with axis < 3 (set only by `from_parts` and `with_inverse_d0`),
    // so the 16 bytes from each offset are one row of `v`.
    let row = |k: usize| unsafe { Vec4::from_array(*v.as_ptr().cast::<u8>().add(k).cast::<[f32; 4]>()) };
    let rx = row(w.k[0]) + Vec4::splat(w.neg_o.x);
    let ry = row(w.k[1]) + Vec4::splat(w.neg_o.y);
    let rz = row(w.k[2]) + Vec4::splat(w.neg_o.z);
    (rx - Vec4::splat(w.s.x) * rz, ry - Vec4::splat(w.s.y) * rz, Vec4::splat(w.s.z) * rz)
}

impl WatertightRay {
    #[inline]
    pub fn new(o: Vec3, d: Vec3) -> Self {
        let d0 = Vec4::new(d.x, d.y, d.z, 1.0) + Vec4::ZERO;
        Self::with_inverse(-o, d, Vec4::ONE / d0)
    }

    /// The axes (kx, ky, kz) as indices, the shear (sx, sy, sz) and −o in the permuted axes: the
    /// state as plain numbers, for the same test on other layouts (`brute.rs`).
    #[inline(always)]
    pub fn parts(&self) -> ([usize; 3], [f32; 3], [f32; 3]) {
        let (s, o) = (self.s.to_array(), self.neg_o.to_array());
        (self.k.map(|k| k / 16), [s[0], s[1], s[2]], [o[0], o[1], o[2]])
    }

    /// The test's state from axes `k` and shear `s` as [`shear_axes`] gives them.
    pub fn from_parts(k: [usize; 3], s: [f32; 3], o: Vec3) -> Self {
        assert!(k.iter().all(|&a| a < 3), "axes {k:?}");
        WatertightRay {
            k: k.map(|a| 16 * a),
            s: Vec4::new(s[0], s[1], s[2], 0.0),
            neg_o: Vec4::new(-o[k[0]], -o[k[1]], -o[k[2]], 0.0),
        }
    }

    /// [`WatertightRay::new`] given `neg_o` = −o and `inv` = 1 / (d + 0) per axis (the node test's unclamped inverse,
    /// so that one division serves both): the axes of [`shear_axes`] chosen without branches, and
    /// `sz` read from `inv` (the same division; it differs from `1 / d[kz]` only in the sign of an
    /// infinity when `d` is zero, where every lane is NaN and misses either way).
    #[inline(always)]
    pub fn with_inverse(neg_o: Vec3, d: Vec3, inv: Vec4) -> Self {
        Self::with_inverse_d0(neg_o, d, Vec4::new(d.x, d.y, d.z, 1.0) + Vec4::ZERO, inv)
    }

    /// [`WatertightRay::with_inverse`] given also `d0` = d + 0 as a vector (its w lane unused), as
    /// the node test has it. The axes come from one row of [`AXES`], by the signs of `d0` (the node
    /// test's octant; a zero `d[kz]`, i.e. `d` zero, counts as positive, as `d[kz] < 0.0` does for
    /// ±0) and one vector comparison of its magnitudes.
    #[inline(always)]
    pub fn with_inverse_d0(neg_o: Vec3, d: Vec3, d0: Vec4, inv: Vec4) -> Self {
        let octant = d0.cmplt(Vec4::ZERO).bitmask() & 7;
        let a = d0.abs();
        let cmp = a.xxyw().cmpgt(a.yzzw()).bitmask() & 7;
        let [kx, ky, kz] = AXES[(octant | cmp << 3) as usize].map(usize::from);
        let (d, o, inv) = (d.to_array(), neg_o.to_array(), inv.to_array());
        // SAFETY: `kx`, `ky` and `kz` (a row of `AXES`) are below 3.
        let (dx, dy, ox, oy, oz, sz) = unsafe {
            (
                d.get_unchecked(kx),
                d.get_unchecked(ky),
                o.get_unchecked(kx),
                o.get_unchecked(ky),
                o.get_unchecked(kz),
                inv.get_unchecked(kz),
            )
        };
        WatertightRay {
            k: [16 * kx, 16 * ky, 16 * kz],
            s: Vec4::new(dx * sz, dy * sz, *sz, 0.0),
            neg_o: Vec4::new(*ox, *oy, *oz, 0.0),
        }
    }

    /// Lane mask of the hits in (0, tmax) and their (t, b1, b2) (b1, b2: barycentrics of vertices 1, 2).
    #[inline(always)]
    pub fn intersect4(&self, p: &TriPacket4, tmax: f32) -> (u32, Vec4, Vec4, Vec4) {
        let (ax, ay, az) = sheared(self, p, 0);
        let (bx, by, bz) = sheared(self, p, 1);
        let (cx, cy, cz) = sheared(self, p, 2);
        // Edge functions (u, v, w) = (cx·by - cy·bx, ax·cy - ay·cx, bx·ay - by·ax).
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        let zero = Vec4::ZERO;
        let exact_zero = (u.cmpeq(zero) | v.cmpeq(zero) | w.cmpeq(zero)).bitmask();
        if exact_zero != 0 {
            // An edge function exactly 0 (the ray meets an edge or vertex in float precision):
            // recompute that lane's three in double precision, as the paper does (all four lanes
            // at once, kept only where needed; the same products and roundings as scalar code).
            [u, v, w] = edges_f64(*self, p, exact_zero, [u, v, w]);
        }
        finish4([u, v, w], [az, bz, cz], tmax)
    }

    /// The nearest hit in (0, tmax): (lane, t, b1, b2). Ties go to the lowest lane.
    #[inline(always)]
    pub fn nearest4(&self, p: &TriPacket4, tmax: f32) -> Option<(usize, f32, f32, f32)> {
        let (mask, t, b1, b2) = self.intersect4(p, tmax);
        nearest_lane(mask, t, b1, b2)
    }

    /// True when any of the four triangles is hit in (0, tmax).
    #[inline(always)]
    pub fn any4(&self, p: &TriPacket4, tmax: f32) -> bool {
        self.intersect4(p, tmax).0 != 0
    }
}

/// The AVX-512 forms of the packet test: the same float operations as [`WatertightRay::intersect4`]
/// (so the same t, b1, b2 bits), with the lane decisions taken in mask registers (AVX-512VL).
#[cfg(target_arch = "x86_64")]
impl WatertightRay {
    /// [`WatertightRay::intersect4`] with masks: the three exact-zero tests OR-ed as masks; the
    /// sign test as "min(u, v, w) < 0 and max(u, v, w) > 0" (for non-NaN values the same as "some
    /// edge function negative and some positive"; a NaN edge function makes `det` and so `t` NaN,
    /// which `t > 0` rejects either way), the one comparison masked by the other; and the
    /// `det ≠ 0`, `t > 0`, `t < tmax` tests chained as masked comparisons.
    ///
    /// Not itself a `target_feature` function (those cannot be `inline(always)`): it inlines into
    /// the AVX-512 traversal, and the intrinsics with it.
    ///
    /// # Safety
    /// The CPU must support AVX-512F and AVX-512VL.
    #[inline(always)]
    pub unsafe fn intersect4_avx512(&self, p: &TriPacket4, tmax: f32) -> (u32, Vec4, Vec4, Vec4) {
        use std::arch::x86_64::*;
        // SAFETY (every intrinsic below): the caller's contract.
        let (ax, ay, az) = sheared(self, p, 0);
        let (bx, by, bz) = sheared(self, p, 1);
        let (cx, cy, cz) = sheared(self, p, 2);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        let zero = _mm_setzero_ps();
        let is_zero = |x: Vec4| _mm_cmp_ps_mask::<_CMP_EQ_OQ>(x.into(), zero);
        let exact_zero = is_zero(u) | is_zero(v) | is_zero(w);
        if exact_zero != 0 {
            // The whole rest of the test out of line: nothing but the traversal's own state is
            // live across the call, so the common path spills nothing for it.
            return intersect4_exact_zero(*self, p, exact_zero as u32, [u, v, w], tmax);
        }
        let (mn, mx) = (u.min(v).min(w), u.max(v).max(w));
        let mixed = _mm_mask_cmp_ps_mask::<_CMP_GT_OQ>(_mm_cmp_ps_mask::<_CMP_LT_OQ>(mn.into(), zero), mx.into(), zero);
        let det = u + v + w;
        let t_scaled = u * az + v * bz + w * cz;
        let inv_det = Vec4::ONE / det;
        let t = t_scaled * inv_det;
        let ok = _mm_cmp_ps_mask::<_CMP_NEQ_UQ>(det.into(), zero);
        let ok = _mm_mask_cmp_ps_mask::<_CMP_GT_OQ>(ok, t.into(), zero);
        let ok = _mm_mask_cmp_ps_mask::<_CMP_LT_OQ>(ok, t.into(), _mm_set1_ps(tmax));
        ((ok & !mixed & 0xF) as u32, t, v * inv_det, w * inv_det)
    }

    /// [`WatertightRay::nearest4`] on [`WatertightRay::intersect4_avx512`].
    ///
    /// # Safety
    /// As for `intersect4_avx512`.
    #[inline(always)]
    pub unsafe fn nearest4_avx512(&self, p: &TriPacket4, tmax: f32) -> Option<(usize, f32, f32, f32)> {
        // SAFETY: the caller's contract.
        let (mask, t, b1, b2) = unsafe { self.intersect4_avx512(p, tmax) };
        nearest_lane(mask, t, b1, b2)
    }

    /// [`WatertightRay::any4`] on [`WatertightRay::intersect4_avx512`].
    ///
    /// # Safety
    /// As for `intersect4_avx512`.
    #[inline(always)]
    pub unsafe fn any4_avx512(&self, p: &TriPacket4, tmax: f32) -> bool {
        // SAFETY: the caller's contract.
        unsafe { self.intersect4_avx512(p, tmax) }.0 != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;
    use crate::sampler::Sampler;

    /// The paper's scalar formulation, as the reference.
    pub fn woop_scalar(ray: &Ray, v: [Vec3; 3], tmax: f32) -> Option<(f32, f32, f32)> {
        let ([kx, ky, kz], [sx, sy, sz]) = shear_axes(ray.d);
        let (a, b, c) = (v[0] - ray.o, v[1] - ray.o, v[2] - ray.o);
        let (ax, ay) = (a[kx] - sx * a[kz], a[ky] - sy * a[kz]);
        let (bx, by) = (b[kx] - sx * b[kz], b[ky] - sy * b[kz]);
        let (cx, cy) = (c[kx] - sx * c[kz], c[ky] - sy * c[kz]);
        let mut u = cx * by - cy * bx;
        let mut v_ = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v_ == 0.0 || w == 0.0 {
            u = (cx as f64 * by as f64 - cy as f64 * bx as f64) as f32;
            v_ = (ax as f64 * cy as f64 - ay as f64 * cx as f64) as f32;
            w = (bx as f64 * ay as f64 - by as f64 * ax as f64) as f32;
        }
        if (u < 0.0 || v_ < 0.0 || w < 0.0) && (u > 0.0 || v_ > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v_ + w;
        if det == 0.0 {
            return None;
        }
        let t_scaled = u * (sz * a[kz]) + v_ * (sz * b[kz]) + w * (sz * c[kz]);
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > 0.0 && t < tmax) {
            return None;
        }
        Some((t, v_ * inv_det, w * inv_det))
    }

    /// Every lane of the 4-wide test gives the scalar test's bits, on rays aimed at vertices,
    /// edges, interiors and random points, some axis-aligned; unused lanes never hit. The AVX-512
    /// test (where the CPU has it) gives the same lanes and bits.
    #[test]
    fn packet_test_equals_scalar_reference() {
        #[cfg(target_arch = "x86_64")]
        let avx512 = std::arch::is_x86_feature_detected!("avx512f") && std::arch::is_x86_feature_detected!("avx512vl");
        let mut s = Sampler::new(7, 0);
        let r3 = |s: &mut Sampler| Vec3::new(s.next_1d(), s.next_1d(), s.next_1d()) * 4.0 - 2.0;
        let (mut hits, mut n) = (0, 0);
        for i in 0..100_000 {
            let tris: Vec<[Vec3; 3]> = (0..4).map(|_| [r3(&mut s), r3(&mut s), r3(&mut s)]).collect();
            let v = tris[i % 4];
            let o = r3(&mut s) * 2.0;
            let target = match i % 4 {
                0 => v[i % 3],
                1 => v[0] + (v[1] - v[0]) * s.next_1d(),
                2 => v[0] * 0.2 + v[1] * 0.3 + v[2] * 0.5,
                _ => r3(&mut s),
            };
            let mut d = (target - o).normalize();
            if i % 7 == 0 {
                d = Vec3::new(d.x, 0.0, -0.0) + Vec3::ZERO;
                d = if d.x == 0.0 { Vec3::X } else { d.normalize() };
            }
            let ray = Ray { o, d, tmax: 10.0 };
            let lanes = 1 + i % 4;
            let mut p = TriPacket4::EMPTY;
            for (l, t) in tris.iter().enumerate().take(lanes) {
                p.set(l, *t);
            }
            let wt = WatertightRay::new(ray.o, ray.d);
            let (mask, t, b1, b2) = wt.intersect4(&p, ray.tmax);
            #[cfg(target_arch = "x86_64")]
            if avx512 {
                // SAFETY: AVX-512F/VL support checked.
                let (m, t2, b1_2, b2_2) = unsafe { wt.intersect4_avx512(&p, ray.tmax) };
                assert_eq!(m, mask, "ray {ray:?}");
                for l in 0..4 {
                    if mask & (1 << l) != 0 {
                        let bits = |v: Vec4| v.to_array()[l].to_bits();
                        assert_eq!((bits(t2), bits(b1_2), bits(b2_2)), (bits(t), bits(b1), bits(b2)));
                    }
                }
            }
            for (l, tri) in tris.iter().enumerate() {
                let want = if l < lanes { woop_scalar(&ray, *tri, ray.tmax) } else { None };
                let got = (mask & (1 << l) != 0).then(|| (t.to_array()[l], b1.to_array()[l], b2.to_array()[l]));
                assert_eq!(got, want, "lane {l} ray {ray:?} triangle {tri:?}");
                n += 1;
                hits += got.is_some() as u32;
            }
        }
        assert!(hits > n / 20, "only {hits} hits of {n}");
    }
}

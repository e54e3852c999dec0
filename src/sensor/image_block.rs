//! Filtered accumulation of samples into a rectangle of pixels (Mitsuba's `ImageBlock`).
//!
//! A sample at continuous film position `pos` adds `w(x)·w(y)·value` to every pixel whose centre
//! lies within the filter radius of `pos` (`x`, `y`: offsets of the pixel centre from `pos`, in
//! pixels), and the weight `w(x)·w(y)` to a weight channel; [`ImageBlock::develop`]
//! divides the two. A filter of radius 0.5 (the box) puts the whole sample into the pixel that
//! contains `pos`, as Mitsuba does.
//!
//! Blocks store a border of [`RFilter::border_size`] pixels around their interior, so a tile
//! receives every contribution of the samples taken inside it and tiles merge exactly into the
//! full image. Weights are computed from film coordinates, so a sample contributes identical
//! weights whichever block it is put into.

#[cfg(target_arch = "x86_64")]
use super::rfilter::gaussian8_fma;
use super::rfilter::{FilterKernel, RFilter};
use glam::Vec2;

/// Largest filter footprint (pixels per axis) whose weights are computed once per sample on the stack.
const MAX_CACHED_TAPS: usize = 16;

#[derive(Clone, Debug)]
pub struct ImageBlock {
    /// Film position of the interior's top-left pixel.
    offset: (i32, i32),
    /// Interior size in pixels.
    size: (u32, u32),
    border: u32,
    channels: usize,
    filter: RFilter,
    kernel: FilterKernel,
    /// Whether [`ImageBlock::put`] splats by [`ImageBlock::put_rgb_gaussian_avx2`]: three channels, a
    /// Gaussian at most 8 pixels wide per axis, a CPU with AVX2 and FMA, and storage coordinates
    /// exact in `f32` (decided in [`ImageBlock::reset`]).
    rgb_gaussian_avx2: bool,
    /// Whether [`ImageBlock::put_rgb`] adds into one pixel directly: three channels and the box
    /// kernel (decided in [`ImageBlock::reset`]).
    rgb_box: bool,
    /// The storage's first pixel in film coordinates and its width in pixels (for `put_rgb_box`).
    box_origin: (i32, i32),
    box_width: usize,
    /// The storage's first and last pixel in film coordinates, `(x, y, x, y)` in `f32`.
    clip: [f32; 4],
    /// Storage (interior plus border), row-major, `channels` values then the weight per pixel.
    data: Vec<f32>,
}

impl ImageBlock {
    /// A zeroed block for the interior rectangle `offset`, `size` (film pixels), with
    /// `channels` value channels and the border the filter needs.
    pub fn new(offset: (i32, i32), size: (u32, u32), filter: RFilter, channels: usize) -> ImageBlock {
        let mut block = ImageBlock {
            offset,
            size: (0, 0),
            border: filter.border_size(),
            channels,
            filter,
            kernel: FilterKernel::for_splatting(&filter),
            rgb_gaussian_avx2: false,
            rgb_box: false,
            box_origin: (0, 0),
            box_width: 0,
            clip: [0.0; 4],
            data: Vec::new(),
        };
        block.reset(offset, size);
        block
    }

    /// Move and resize the block and zero it, keeping its allocation (to reuse one block per thread).
    pub fn reset(&mut self, offset: (i32, i32), size: (u32, u32)) {
        self.offset = offset;
        self.size = size;
        let (w, h) = self.storage_size();
        self.data.clear();
        self.data.resize(w * h * (self.channels + 1), 0.0);
        let (ox, oy) = self.storage_origin();
        // Pixel indices up to 2^24 are exact in f32, so the fast path clips the footprint in f32.
        let exact = |o: i64, n: usize| o.abs() < 1 << 24 && (o + n as i64).abs() < 1 << 24;
        self.rgb_gaussian_avx2 = self.channels == 3
            && matches!(self.kernel, FilterKernel::Gaussian { radius, .. } if radius <= 3.5)
            && exact(ox, w)
            && exact(oy, h)
            && has_avx2_fma();
        self.rgb_box = self.channels == 3 && matches!(self.kernel, FilterKernel::Box) && exact(ox, w) && exact(oy, h);
        self.clip = [ox as f32, oy as f32, (ox + w as i64 - 1) as f32, (oy + h as i64 - 1) as f32];
        self.box_origin = (ox as i32, oy as i32);
        self.box_width = w;
    }

    /// Zero all pixels and weights.
    pub fn clear(&mut self) {
        self.data.fill(0.0);
    }

    pub fn offset(&self) -> (i32, i32) {
        self.offset
    }
    pub fn size(&self) -> (u32, u32) {
        self.size
    }
    /// Border width in pixels on each side of the interior.
    pub fn border(&self) -> u32 {
        self.border
    }
    /// Number of value channels (the weight channel not included).
    pub fn channels(&self) -> usize {
        self.channels
    }
    pub fn filter(&self) -> RFilter {
        self.filter
    }

    /// Width and height of the storage, border included.
    fn storage_size(&self) -> (usize, usize) {
        let b = 2 * self.border as usize;
        (self.size.0 as usize + b, self.size.1 as usize + b)
    }

    /// Film position of the storage's top-left pixel.
    fn storage_origin(&self) -> (i64, i64) {
        (self.offset.0 as i64 - self.border as i64, self.offset.1 as i64 - self.border as i64)
    }

    /// Splat a sample at film position `pos` (pixels) with `values` (one per channel).
    /// Samples with a non-finite position are ignored; contributions outside the storage are dropped.
    #[inline]
    pub fn put(&mut self, pos: Vec2, values: &[f32]) {
        debug_assert_eq!(values.len(), self.channels, "ImageBlock::put: wrong number of values");
        #[cfg(target_arch = "x86_64")]
        if self.rgb_gaussian_avx2 {
            if let Ok(rgb) = <&[f32; 3]>::try_from(values) {
                // SAFETY: `rgb_gaussian_avx2` is set only where the CPU has AVX2 and FMA.
                if unsafe { self.put_rgb_gaussian_avx2(pos, rgb) } {
                    return;
                }
            }
        }
        if self.rgb_box {
            if let Ok(&rgb) = <&[f32; 3]>::try_from(values) {
                self.put_rgb_box(pos, rgb);
                return;
            }
        }
        self.put_general(pos, values);
    }

    /// The box kernel's path of [`ImageBlock::put_general`] for three channels: the same pixel
    /// (the one containing `pos`), the same four additions (values, then weight 1), so the same bits.
    /// The position is tested against the storage's edges in `f32` (exact: `rgb_box` requires
    /// storage coordinates below 2^24), which also rejects NaN and every position whose floor
    /// would not fit, so the floor itself needs no saturation.
    #[inline(always)]
    fn put_rgb_box(&mut self, pos: Vec2, rgb: [f32; 3]) {
        let [x0, y0, x1, y1] = self.clip;
        // floor(p) in [first, last] <=> first <= p < last + 1, both sides exact in f32.
        if !(pos.x >= x0 && pos.x < x1 + 1.0 && pos.y >= y0 && pos.y < y1 + 1.0) {
            return;
        }
        let (x, y) = (floor_in_range(pos.x) - self.box_origin.0, floor_in_range(pos.y) - self.box_origin.1);
        let base = (y as usize * self.box_width + x as usize) * 4;
        if let Some(px) = self.data.get_mut(base..base + 4) {
            px[0] += rgb[0];
            px[1] += rgb[1];
            px[2] += rgb[2];
            px[3] += 1.0;
        }
    }

    /// [`ImageBlock::put`] for any filter and channel count.
    #[inline(never)]
    fn put_general(&mut self, pos: Vec2, values: &[f32]) {
        if !pos.is_finite() {
            return;
        }
        let (ox, oy) = self.storage_origin();
        let (w, h) = self.storage_size();
        let stride = self.channels + 1;

        let radius = match self.kernel {
            FilterKernel::Box => {
                let (x, y) = (floor_i64(pos.x).saturating_sub(ox), floor_i64(pos.y).saturating_sub(oy));
                if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
                    return;
                }
                let base = (y as usize * w + x as usize) * stride;
                let px = &mut self.data[base..base + stride];
                for (d, v) in px.iter_mut().zip(values) {
                    *d += v;
                }
                px[self.channels] += 1.0;
                return;
            }
            k => k.radius(),
        };

        // Pixels i with centre i + 0.5 within the radius of pos, clipped to the storage.
        let x0 = ceil_i64(pos.x - 0.5 - radius).max(ox);
        let x1 = floor_i64(pos.x - 0.5 + radius).min(ox + w as i64 - 1);
        let y0 = ceil_i64(pos.y - 0.5 - radius).max(oy);
        let y1 = floor_i64(pos.y - 0.5 + radius).min(oy + h as i64 - 1);
        if x0 > x1 || y0 > y1 {
            return;
        }
        let count_x = (x1 - x0 + 1) as usize;
        let count_y = (y1 - y0 + 1) as usize;
        let kernel = self.kernel;
        if count_x > MAX_CACHED_TAPS || count_y > MAX_CACHED_TAPS {
            self.put_uncached(pos, values, (x0, x1), (y0, y1));
            return;
        }
        let taps;
        let (mut weights_x, mut weights_y);
        let (weights_x, weights_y) = if count_x <= 8 && count_y <= 8 {
            // Both axes in one 16-lane evaluation (the Gaussian's footprint is 4–5 taps per axis).
            taps = kernel.eval_taps_xy((x0, pos.x), (y0, pos.y));
            (&taps[..count_x], &taps[8..8 + count_y])
        } else {
            (weights_x, weights_y) = ([0.0f32; MAX_CACHED_TAPS], [0.0f32; MAX_CACHED_TAPS]);
            kernel.eval_taps(x0, pos.x, &mut weights_x[..count_x]);
            kernel.eval_taps(y0, pos.y, &mut weights_y[..count_y]);
            (&weights_x[..count_x], &weights_y[..count_y])
        };
        let first = ((y0 - oy) as usize * w + (x0 - ox) as usize) * stride;
        let row_stride = w * stride;
        // Fixed channel counts let the compiler unroll the per-pixel loop (RGB + alpha, with moments).
        match self.channels {
            4 => accumulate4(&mut self.data[first..], row_stride, values, weights_x, weights_y),
            3 => accumulate3(&mut self.data[first..], row_stride, values, weights_x, weights_y),
            7 => accumulate::<7>(&mut self.data[first..], row_stride, values, weights_x, weights_y),
            _ => {
                for (j, &wy) in weights_y.iter().enumerate() {
                    if wy == 0.0 {
                        continue;
                    }
                    let start = first + j * row_stride;
                    let row = &mut self.data[start..start + count_x * stride];
                    for (px, &wx) in row.chunks_exact_mut(stride).zip(weights_x) {
                        let weight = wx * wy;
                        let (px_values, px_weight) = px.split_at_mut(self.channels);
                        for (d, v) in px_values.iter_mut().zip(values) {
                            *d += v * weight;
                        }
                        px_weight[0] += weight;
                    }
                }
            }
        }
    }

    /// [`ImageBlock::put`] for RGB and a Gaussian filter in AVX2: the footprint found and clipped
    /// in one 4-lane vector, the taps of both axes in one 8-lane polynomial (two when an axis has
    /// more than 4 taps), and two pixels per 8-lane multiply and add. Every tap, product and sum is
    /// the one the general path computes (the same operations lane by lane), so the same bits.
    /// Returns `false`, having done nothing, for another filter or a footprint wider than 8 pixels.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    fn put_rgb_gaussian_avx2(&mut self, pos: Vec2, rgb: &[f32; 3]) -> bool {
        use std::arch::x86_64::*;
        let FilterKernel::Gaussian { ref coeff, radius } = self.kernel else { return false };
        // Lanes (x0, y0, x1, y1): pixels i with centre i + 0.5 within the radius of pos,
        // ceil(p - 0.5 - r) ..= floor(p - 0.5 + r), clipped to the storage.
        let p4 = _mm_setr_ps(pos.x, pos.y, pos.x, pos.y);
        let ends = _mm_add_ps(_mm_sub_ps(p4, _mm_set1_ps(0.5)), _mm_setr_ps(-radius, -radius, radius, radius));
        // A NaN position is ignored (an infinite one clips to an empty footprint).
        let ordered = _mm_movemask_ps(_mm_cmpord_ps(ends, ends));
        let ends = _mm_blend_ps::<0b1100>(_mm_ceil_ps(ends), _mm_floor_ps(ends));
        // SAFETY: `clip` holds 4 floats.
        let clip = unsafe { _mm_loadu_ps(self.clip.as_ptr()) };
        let ends = _mm_blend_ps::<0b1100>(_mm_max_ps(ends, clip), _mm_min_ps(ends, clip));
        // The footprint is empty unless x0 <= x1 and y0 <= y1.
        if _mm_movemask_ps(_mm_cmple_ps(ends, _mm_movehl_ps(ends, ends))) & ordered & 3 != 3 {
            return true;
        }
        // (x0 - storage x, y0 - storage y, count_x - 1, count_y - 1), exact integers in f32.
        let offs = _mm_sub_ps(ends, _mm_blend_ps::<0b1100>(clip, _mm_movelh_ps(ends, ends)));
        let offs = _mm_cvttps_epi32(offs);
        let (ix, iy) = (_mm_cvtsi128_si32(offs) as usize, _mm_extract_epi32::<1>(offs) as usize);
        let (count_x, count_y) = (_mm_extract_epi32::<2>(offs) as usize + 1, _mm_extract_epi32::<3>(offs) as usize + 1);
        if count_x > 8 || count_y > 8 {
            return false;
        }
        // Taps: the weight of pixel first + i is gaussian((first + i) + 0.5 - pos), as `eval_taps_xy`;
        // x taps in taps[0..], y taps in taps[ty..].
        let half = _mm256_set1_ps(0.5);
        let eval = |first: __m256, lane: __m256, p: __m256| {
            let d = _mm256_sub_ps(_mm256_add_ps(_mm256_add_ps(first, lane), half), p);
            _mm256_max_ps(gaussian8_fma(d, coeff), _mm256_setzero_ps())
        };
        let mut taps = [0.0f32; 16];
        let x0 = _mm_shuffle_ps::<0b00_00_00_00>(ends, ends);
        let y0 = _mm_shuffle_ps::<0b01_01_01_01>(ends, ends);
        let (px, py) = (_mm_set1_ps(pos.x), _mm_set1_ps(pos.y));
        let ty = if count_x <= 4 && count_y <= 4 {
            let lane = _mm256_setr_ps(0.0, 1.0, 2.0, 3.0, 0.0, 1.0, 2.0, 3.0);
            let t = eval(_mm256_set_m128(y0, x0), lane, _mm256_set_m128(py, px));
            // SAFETY: `taps` holds 16 floats.
            unsafe { _mm256_storeu_ps(taps.as_mut_ptr(), t) };
            4
        } else {
            let lane = _mm256_setr_ps(0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0);
            let tx = eval(_mm256_set_m128(x0, x0), lane, _mm256_set_m128(px, px));
            let t_y = eval(_mm256_set_m128(y0, y0), lane, _mm256_set_m128(py, py));
            // SAFETY: `taps` holds 16 floats.
            unsafe {
                _mm256_storeu_ps(taps.as_mut_ptr(), tx);
                _mm256_storeu_ps(taps.as_mut_ptr().add(8), t_y);
            }
            8
        };
        let (w, _) = self.storage_size();
        let row_stride = w * 4;
        let first = (iy * w + ix) * 4;
        if first + (count_y - 1) * row_stride + 4 * count_x > self.data.len() {
            return true;
        }
        let v4 = _mm_setr_ps(rgb[0], rgb[1], rgb[2], 1.0);
        let wy = &taps[ty..ty + count_y];
        // SAFETY: AVX2 is enabled, and the footprint's rows lie inside `data` (checked above).
        unsafe {
            let base = self.data.as_mut_ptr().add(first);
            match count_x {
                1 => splat_rows_avx2::<1>(base, row_stride, v4, &taps, wy),
                2 => splat_rows_avx2::<2>(base, row_stride, v4, &taps, wy),
                3 => splat_rows_avx2::<3>(base, row_stride, v4, &taps, wy),
                4 => splat_rows_avx2::<4>(base, row_stride, v4, &taps, wy),
                5 => splat_rows_avx2::<5>(base, row_stride, v4, &taps, wy),
                6 => splat_rows_avx2::<6>(base, row_stride, v4, &taps, wy),
                7 => splat_rows_avx2::<7>(base, row_stride, v4, &taps, wy),
                _ => splat_rows_avx2::<8>(base, row_stride, v4, &taps, wy),
            }
        }
        true
    }

    /// `put` for footprints wider than [`MAX_CACHED_TAPS`]: weights evaluated per pixel.
    fn put_uncached(&mut self, pos: Vec2, values: &[f32], (x0, x1): (i64, i64), (y0, y1): (i64, i64)) {
        let (ox, oy) = self.storage_origin();
        let (w, _) = self.storage_size();
        let stride = self.channels + 1;
        let count_x = (x1 - x0 + 1) as usize;
        let kernel = self.kernel;
        for y in y0..=y1 {
            let wy = kernel.eval(y as f32 + 0.5 - pos.y);
            if wy == 0.0 {
                continue;
            }
            let start = ((y - oy) as usize * w + (x0 - ox) as usize) * stride;
            let row = &mut self.data[start..start + count_x * stride];
            for (i, px) in row.chunks_exact_mut(stride).enumerate() {
                let weight = kernel.eval((x0 + i as i64) as f32 + 0.5 - pos.x) * wy;
                let (px_values, px_weight) = px.split_at_mut(self.channels);
                for (d, v) in px_values.iter_mut().zip(values) {
                    *d += v * weight;
                }
                px_weight[0] += weight;
            }
        }
    }

    /// Add `values` to the pixel containing film position `pos` without a filter weight (a
    /// light-tracing splat, `integrator::splat`: it adds to the pixel's weighted sum, and the
    /// developed value is that sum over the camera samples' weight). Dropped outside the storage.
    pub fn add_unweighted(&mut self, pos: Vec2, values: &[f32]) {
        debug_assert_eq!(values.len(), self.channels, "ImageBlock::add_unweighted: wrong number of values");
        if !pos.is_finite() {
            return;
        }
        let (ox, oy) = self.storage_origin();
        let (w, h) = self.storage_size();
        let (x, y) = (floor_i64(pos.x).saturating_sub(ox), floor_i64(pos.y).saturating_sub(oy));
        if x < 0 || y < 0 || x >= w as i64 || y >= h as i64 {
            return;
        }
        let base = (y as usize * w + x as usize) * (self.channels + 1);
        for (d, v) in self.data[base..base + self.channels].iter_mut().zip(values) {
            *d += v;
        }
    }

    /// Add another block (a tile, border included) into this one where their storages overlap.
    /// Panics if the channel counts differ (a programming error, not a user error).
    pub fn merge(&mut self, other: &ImageBlock) {
        assert_eq!(self.channels, other.channels, "ImageBlock::merge: channel counts differ");
        let stride = self.channels + 1;
        let (sx, sy) = self.storage_origin();
        let (sw, sh) = self.storage_size();
        let (ox, oy) = other.storage_origin();
        let (ow, oh) = other.storage_size();
        let x0 = sx.max(ox);
        let x1 = (sx + sw as i64).min(ox + ow as i64);
        let y0 = sy.max(oy);
        let y1 = (sy + sh as i64).min(oy + oh as i64);
        if x0 >= x1 || y0 >= y1 {
            return;
        }
        let n = (x1 - x0) as usize * stride;
        for y in y0..y1 {
            let dst = ((y - sy) as usize * sw + (x0 - sx) as usize) * stride;
            let src = ((y - oy) as usize * ow + (x0 - ox) as usize) * stride;
            for (d, s) in self.data[dst..dst + n].iter_mut().zip(&other.data[src..src + n]) {
                *d += s;
            }
        }
    }

    /// The interior pixels, row 0 at the top, channels interleaved, each divided by the pixel's
    /// accumulated filter weight (0 where the weight is 0).
    pub fn develop(&self) -> Vec<f32> {
        let (iw, ih) = (self.size.0 as usize, self.size.1 as usize);
        let (w, _) = self.storage_size();
        let b = self.border as usize;
        let stride = self.channels + 1;
        let mut out = Vec::with_capacity(iw * ih * self.channels);
        for y in 0..ih {
            for x in 0..iw {
                let base = ((y + b) * w + x + b) * stride;
                let px = &self.data[base..base + stride];
                let weight = px[self.channels];
                let inv = if weight != 0.0 { 1.0 / weight } else { 0.0 };
                out.extend(px[..self.channels].iter().map(|v| v * inv));
            }
        }
        out
    }

    /// The accumulated filter weight of interior pixel `(x, y)` (relative to the block's offset).
    pub fn weight(&self, x: u32, y: u32) -> f32 {
        let (w, _) = self.storage_size();
        let b = self.border as usize;
        let idx = ((y as usize + b) * w + x as usize + b) * (self.channels + 1) + self.channels;
        self.data.get(idx).copied().unwrap_or(0.0)
    }
}

/// Add `w(x)·w(y)·values` and the weight `w(x)·w(y)` to the pixels of a footprint starting at
/// `data[0]` (rows `row_stride` apart, `N` values then the weight per pixel).
#[inline(always)]
fn accumulate<const N: usize>(data: &mut [f32], row_stride: usize, values: &[f32], wxs: &[f32], wys: &[f32]) {
    let Ok(values) = <&[f32; N]>::try_from(values) else { return };
    for (j, &wy) in wys.iter().enumerate() {
        if wy == 0.0 {
            continue;
        }
        let start = j * row_stride;
        let row = &mut data[start..start + wxs.len() * (N + 1)];
        for (px, &wx) in row.chunks_exact_mut(N + 1).zip(wxs) {
            let weight = wx * wy;
            for c in 0..N {
                px[c] += values[c] * weight;
            }
            px[N] += weight;
        }
    }
}

/// Whether the CPU has AVX2 and FMA (for [`ImageBlock::put_rgb_gaussian_avx2`]).
fn has_avx2_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// `v.floor() as i64` for finite `v` without a libm call (no SSE4.1 `roundss` in the baseline):
/// truncate, then step down when truncation rounded up (negative non-integers).
#[inline(always)]
fn floor_i64(v: f32) -> i64 {
    let i = v as i64;
    i - ((i as f32) > v) as i64
}

/// `v.floor() as i32` for `|v| < 2^24` (the caller's range test; also excludes NaN).
#[inline(always)]
fn floor_in_range(v: f32) -> i32 {
    debug_assert!(v.abs() < 16_777_216.0);
    // SAFETY: |v| < 2^24 (asserted by the caller's comparisons), so the truncation fits in an i32.
    let i: i32 = unsafe { v.to_int_unchecked() };
    i - ((i as f32) > v) as i32
}

/// `v.ceil() as i64` for finite `v` (see [`floor_i64`]).
#[inline(always)]
fn ceil_i64(v: f32) -> i64 {
    let i = v as i64;
    i + ((i as f32) < v) as i64
}

/// `px[0..4] += v · weight` as one 4-lane multiply-add (the same products and sums as the scalar
/// loop, so the same bits).
#[inline(always)]
fn add4(px: &mut [f32], v: glam::Vec4, weight: f32) {
    let px: &mut [f32; 4] = (&mut px[..4]).try_into().expect("four lanes");
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of x86_64; `px` holds four f32 (unaligned loads and stores).
    unsafe {
        use std::arch::x86_64::*;
        let sum = _mm_add_ps(_mm_loadu_ps(px.as_ptr()), _mm_mul_ps(v.into(), _mm_set1_ps(weight)));
        _mm_storeu_ps(px.as_mut_ptr(), sum);
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        *px = (glam::Vec4::from_array(*px) + v * weight).to_array();
    }
}

/// [`accumulate`] for RGB (the common film): a pixel's three values and its weight are four
/// adjacent floats, updated by one 4-lane multiply-add with `(r, g, b, 1)`. Footprints 3–5 pixels
/// wide (the Gaussian's) take an unrolled row loop with one bounds check per row.
#[inline]
fn accumulate3(data: &mut [f32], row_stride: usize, values: &[f32], wxs: &[f32], wys: &[f32]) {
    let Ok(&[r, g, b]) = <&[f32; 3]>::try_from(values) else { return };
    let v = glam::Vec4::new(r, g, b, 1.0);
    #[cfg(target_arch = "x86_64")]
    if (3..=5).contains(&wxs.len()) && std::arch::is_x86_feature_detected!("avx") {
        // SAFETY: the CPU supports AVX (checked just above).
        unsafe {
            match wxs.len() {
                3 => accumulate_rows_avx::<3>(data, row_stride, v, wxs, wys),
                4 => accumulate_rows_avx::<4>(data, row_stride, v, wxs, wys),
                _ => accumulate_rows_avx::<5>(data, row_stride, v, wxs, wys),
            }
        }
        return;
    }
    match wxs.len() {
        3 => accumulate_rows::<3>(data, row_stride, v, wxs, wys),
        4 => accumulate_rows::<4>(data, row_stride, v, wxs, wys),
        5 => accumulate_rows::<5>(data, row_stride, v, wxs, wys),
        n => {
            for (j, &wy) in wys.iter().enumerate() {
                if wy == 0.0 {
                    continue;
                }
                let start = j * row_stride;
                let row = &mut data[start..start + n * 4];
                for (px, &wx) in row.chunks_exact_mut(4).zip(wxs) {
                    add4(px, v, wx * wy);
                }
            }
        }
    }
}

/// The rows of [`accumulate3`] for a footprint `N` pixels wide (`wxs.len() == N`): the same
/// products and sums in the same order, unrolled.
#[inline(always)]
fn accumulate_rows<const N: usize>(data: &mut [f32], row_stride: usize, v: glam::Vec4, wxs: &[f32], wys: &[f32]) {
    let Ok(wxs) = <&[f32; N]>::try_from(wxs) else { return };
    for (j, &wy) in wys.iter().enumerate() {
        if wy == 0.0 {
            continue;
        }
        let start = j * row_stride;
        let row: &mut [f32] = &mut data[start..start + 4 * N];
        for (k, &wx) in wxs.iter().enumerate() {
            add4(&mut row[4 * k..4 * k + 4], v, wx * wy);
        }
    }
}

/// [`accumulate_rows`] with two pixels per 8-lane vector (AVX): `(r, g, b, 1, r, g, b, 1)` times the
/// weights `(wx_k, wx_k, wx_k, wx_k, wx_k+1, ...) · wy`, an odd last pixel as one 4-lane vector. Each
/// lane computes `wx · wy`, then `value · weight`, then the sum, as [`add4`] does: the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx")]
fn accumulate_rows_avx<const N: usize>(data: &mut [f32], row_stride: usize, v: glam::Vec4, wxs: &[f32], wys: &[f32]) {
    use std::arch::x86_64::*;
    let Ok(wxs) = <&[f32; N]>::try_from(wxs) else { return };
    let v4: __m128 = v.into();
    let v8 = _mm256_set_m128(v4, v4);
    // Pixel pairs' x weights, and the last pixel's when N is odd.
    let pairs: [__m256; 2] =
        std::array::from_fn(|k| _mm256_set_m128(_mm_set1_ps(wxs[(2 * k + 1).min(N - 1)]), _mm_set1_ps(wxs[2 * k])));
    let last = _mm_set1_ps(wxs[N - 1]);
    for (j, &wy) in wys.iter().enumerate() {
        if wy == 0.0 {
            continue;
        }
        let start = j * row_stride;
        let row: &mut [f32] = &mut data[start..start + 4 * N];
        let wy8 = _mm256_set1_ps(wy);
        // SAFETY: AVX is enabled; pair k covers row[8k..8k + 8] with 8k + 8 <= 4N, the odd last
        // pixel row[4N - 4..4N] (unaligned loads and stores inside `row`).
        unsafe {
            for (k, &wx) in pairs.iter().enumerate().take(N / 2) {
                let p = row.as_mut_ptr().add(8 * k);
                let add = _mm256_mul_ps(v8, _mm256_mul_ps(wx, wy8));
                _mm256_storeu_ps(p, _mm256_add_ps(_mm256_loadu_ps(p), add));
            }
            if N % 2 == 1 {
                let p = row.as_mut_ptr().add(4 * N - 4);
                let add = _mm_mul_ps(v4, _mm_mul_ps(last, _mm256_castps256_ps128(wy8)));
                _mm_storeu_ps(p, _mm_add_ps(_mm_loadu_ps(p), add));
            }
        }
    }
}

/// The rows of [`ImageBlock::put_rgb_gaussian_avx2`], `N` pixels wide: row `j` (`rows` floats
/// apart from `base`) gets `(r, g, b, 1) · (wx · wy[j])` added per pixel, two pixels per 8-lane
/// vector and an odd last one in 4 lanes (the products and sums of [`accumulate_rows`]); rows
/// with `wy[j] == 0` are skipped, as there.
///
/// Built into its AVX2 caller (the intrinsics compile to AVX there).
///
/// # Safety
/// AVX must be available, and `base[j·rows..j·rows + 4·N]` must lie in one allocation for every
/// `j < wy.len()`.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn splat_rows_avx2<const N: usize>(
    base: *mut f32,
    rows: usize,
    v4: std::arch::x86_64::__m128,
    wx: &[f32; 16],
    wy: &[f32],
) {
    use std::arch::x86_64::*;
    // SAFETY (every intrinsic below): AVX is available (the caller's contract).
    unsafe {
        let v8 = _mm256_set_m128(v4, v4);
        let last = _mm_set1_ps(wx[N - 1]);
        for (j, &wy) in wy.iter().enumerate() {
            if wy == 0.0 {
                continue;
            }
            let wy8 = _mm256_set1_ps(wy);
            // Row j's 4·N floats lie inside the allocation (the caller's contract); pair k covers
            // floats 8k..8k + 8 <= 4·N, the odd last pixel 4·N - 4..4·N.
            let row = base.add(j * rows);
            for k in 0..N / 2 {
                // The pair's x weights (w_2k ×4, w_2k+1 ×4), hoisted out of the row loop.
                let wxk = _mm256_set_m128(_mm_set1_ps(wx[2 * k + 1]), _mm_set1_ps(wx[2 * k]));
                let p = row.add(8 * k);
                let add = _mm256_mul_ps(v8, _mm256_mul_ps(wxk, wy8));
                _mm256_storeu_ps(p, _mm256_add_ps(_mm256_loadu_ps(p), add));
            }
            if N % 2 == 1 {
                let p = row.add(4 * N - 4);
                let add = _mm_mul_ps(v4, _mm_mul_ps(last, _mm256_castps256_ps128(wy8)));
                _mm_storeu_ps(p, _mm_add_ps(_mm_loadu_ps(p), add));
            }
        }
    }
}

/// [`accumulate`] for RGB + alpha: the four values as one 4-lane multiply-add, then the weight.
#[inline]
fn accumulate4(data: &mut [f32], row_stride: usize, values: &[f32], wxs: &[f32], wys: &[f32]) {
    let Ok(values) = <&[f32; 4]>::try_from(values) else { return };
    let v = glam::Vec4::from_array(*values);
    let n = wxs.len();
    for (j, &wy) in wys.iter().enumerate() {
        if wy == 0.0 {
            continue;
        }
        let start = j * row_stride;
        let row = &mut data[start..start + n * 5];
        for (px, &wx) in row.chunks_exact_mut(5).zip(wxs) {
            let weight = wx * wy;
            add4(px, v, weight);
            px[4] += weight;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn floor_and_ceil_without_libm() {
        for v in [-3.5f32, -3.0, -0.25, -0.0, 0.0, 0.25, 1.0, 2.999_999_8, 1e7 + 0.5, -1e7 - 0.5, 16_777_216.0] {
            assert_eq!(floor_i64(v), v.floor() as i64, "floor({v})");
            assert_eq!(ceil_i64(v), v.ceil() as i64, "ceil({v})");
        }
    }

    #[test]
    fn box_puts_into_containing_pixel() {
        let mut b = ImageBlock::new((2, 3), (4, 4), RFilter::Box, 1);
        b.put(Vec2::new(3.9, 3.0), &[2.0]);
        b.put(Vec2::new(3.1, 3.5), &[4.0]);
        b.put(Vec2::new(100.0, 3.5), &[4.0]);
        b.put(Vec2::new(f32::NAN, 3.5), &[4.0]);
        let img = b.develop();
        assert_eq!(img[1], 3.0);
        assert_eq!(img.iter().filter(|v| **v != 0.0).count(), 1);
        assert_eq!(b.weight(1, 0), 2.0);
    }

    #[test]
    fn rgb_box_matches_general_path() {
        // Negative and positive storage origins, positions on and next to every pixel edge, outside
        // the storage, huge and non-finite.
        for offset in [(-3, 5), (0, 0), (1000, -20)] {
            let mut fast = ImageBlock::new(offset, (7, 4), RFilter::Box, 3);
            let mut general = fast.clone();
            assert!(fast.rgb_box);
            let mut coords = vec![f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e30, -1e30, 16_777_216.0];
            for i in -8..16 {
                let e = (offset.0.min(offset.1) + i) as f32;
                coords.extend([e, e.next_up(), e.next_down(), e + 0.5, e + 0.999_999_94]);
            }
            coords.extend([offset.0 as f32 + 3.25, offset.1 as f32 + 2.75]);
            let mut k = 0.0f32;
            for &x in &coords {
                for &y in &coords {
                    k += 1.0;
                    let rgb = [k, 0.5 * k, 0.25 + k];
                    fast.put(Vec2::new(x, y), &rgb);
                    general.put_general(Vec2::new(x, y), &rgb);
                }
            }
            assert!(fast.data.iter().any(|&v| v != 0.0));
            let bits = |b: &ImageBlock| b.data.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
            assert_eq!(bits(&fast), bits(&general), "offset {offset:?}");
        }
    }

    #[test]
    fn footprint_of_gaussian() {
        let mut b = ImageBlock::new((0, 0), (10, 10), RFilter::default(), 1);
        b.put(Vec2::new(5.0, 5.0), &[1.0]);
        // Centres 3.5 .. 6.5 are within 2 of 5.0 → 4 pixels per axis, weight 0 exactly at ±2 not reached.
        let touched = (0..10).flat_map(|y| (0..10).map(move |x| (x, y))).filter(|&(x, y)| b.weight(x, y) > 0.0).count();
        assert_eq!(touched, 16);
    }

    /// The splatted sums equal a per-pixel evaluation of the filter, bit for bit, for the
    /// unrolled channel counts and the generic one.
    #[test]
    fn put_equals_per_pixel_filter() {
        let mut rng = crate::sampler::Sampler::new(5, 0);
        // Gaussians of 3–5, 5–7 and 7–9 taps per axis (the AVX2 path takes up to 8).
        let gaussians = [0.4, 0.5, 0.8, 1.0].map(|stddev| RFilter::Gaussian { stddev });
        for filter in gaussians.into_iter().chain([RFilter::Tent { radius: 1.5 }]) {
            for channels in [3, 4, 5, 7] {
                let (offset, size) = ((3, -2), (9u32, 7u32));
                let mut block = ImageBlock::new(offset, size, filter, channels);
                let border = block.border() as i64;
                let (w, h) = (size.0 as i64 + 2 * border, size.1 as i64 + 2 * border);
                let mut want = vec![0.0f32; (w * h) as usize * (channels + 1)];
                for _ in 0..200 {
                    let pos = Vec2::new(rng.next_1d() * 13.0, rng.next_1d() * 11.0 - 4.0);
                    let values: Vec<f32> = (0..channels).map(|_| rng.next_1d() * 4.0).collect();
                    block.put(pos, &values);
                    // Non-finite positions add nothing.
                    block.put(Vec2::new(f32::NAN, pos.y), &values);
                    block.put(Vec2::new(pos.x, f32::INFINITY), &values);
                    block.put(Vec2::new(f32::NEG_INFINITY, pos.y), &values);
                    for y in 0..h {
                        for x in 0..w {
                            let (fx, fy) = (x + offset.0 as i64 - border, y + offset.1 as i64 - border);
                            let (dx, dy) = (fx as f32 + 0.5 - pos.x, fy as f32 + 0.5 - pos.y);
                            let r = filter.radius();
                            if dx.abs() > r || dy.abs() > r || filter.eval(dy) == 0.0 {
                                continue;
                            }
                            let weight = filter.eval(dx) * filter.eval(dy);
                            let base = ((y * w + x) as usize) * (channels + 1);
                            for c in 0..channels {
                                want[base + c] += values[c] * weight;
                            }
                            want[base + channels] += weight;
                        }
                    }
                }
                assert_eq!(block.data, want, "{filter:?}, {channels} channels");
            }
        }
    }
}

//! Mitsuba's `path` integrator on [`LANES`] pixels at once, for scenes whose every BSDF is `diffuse`
//! or `twosided` around `diffuse` (the same images as `path.rs`, bit for bit).
//!
//! A lane is a pixel of the tile: it runs that pixel's samples one after the other from the
//! pixel's own sampler stream, exactly as the scalar loop does, and when its pixel has done its
//! samples it takes the next pixel of the tile (refill), until every pixel is done. A step of the
//! loop takes every live lane one vertex further:
//! 1. per lane (scalar): the ray (`Scene::ray_intersect`), emission found by it (the scalar code's
//!    calls), the end of the path, the vertex (position, normals, frame, reflectance) into
//!    structure-of-arrays state;
//! 2. vector loops over the lanes: the vertex's five sampler numbers (PCG32 on the lanes' streams,
//!    [`Pcg`]), then, with area lights on meshes, the emitter sample's direction, density and
//!    weight and its shadow ray, after a scalar pick of the light and of its point
//!    (`Scene::select_emitter`, `Shape::sample_position`; other lights: the scalar
//!    `sample_emitter_direction`), then the diffuse BSDF (evaluation, pdf, cosine-weighted
//!    sampling with its concentric-disk warp), frames, MIS, the new ray and the throughput;
//! 3. per lane (scalar): the shadow ray (`Scene::ray_test`), Russian roulette, path ends.
//!
//! The compiler turns the loops of step 2 into AVX2 (2 × 8 lanes) or AVX-512 (16 lanes) code,
//! chosen at run time.
//! Every lane does the scalar code's float operations in its order (IEEE `+ - * / sqrt` are exact
//! per lane; the polynomial `sincos` and the branches of the warps are written as selects with the
//! same constants and association, tested bit for bit below), so each sample's radiance is the
//! scalar one bit for bit. Finished samples are buffered and splatted after the tile in the scalar
//! order (pixel by pixel, samples in order), so the block sums are the scalar ones too
//! (`tests/path_wide.rs`). Decided per render ([`applies`]): `path` without class AOVs, every
//! shape's BSDF `diffuse` or `twosided` around `diffuse`; every other scene keeps the scalar loop.

use super::stats::LocalStats;
use super::Integrator;
use crate::bsdf::{Bsdf, Diffuse};
use crate::color::Spectrum;
use crate::interaction::{offset_origin, DirectionSample};
use crate::math::{mis_weight, Frame, Ray, Vec2, Vec3, INV_PI};
use crate::scene::world::{Scene, SceneEmitter};
use crate::shape::Geometry;
use std::sync::atomic::{AtomicBool, Ordering};

/// Paths in flight (one per pixel): 16, one AVX-512 register of `f32` (measured on cornell_box,
/// 1 thread, against 8: render time 0.587 vs 0.614 s, medians of 7 pairs; under AVX2 +0.4 %
/// instructions, −6 % mispredicted branches in callgrind's model).
pub const LANES: usize = 16;
const N: usize = LANES;

/// Off switch (on by default): the scalar loop renders every scene while this is false (tests
/// compare the two).
pub static ENABLED: AtomicBool = AtomicBool::new(true);

/// One pixel of a tile and its sampler stream: `Sampler::new(seed, stream)`.
pub struct Pixel {
    pub x: i32,
    pub y: i32,
    pub seed: u64,
    pub stream: u64,
}

/// `Sampler` as plain numbers (rand_pcg's `Lcg64Xsh32`, PCG32 XSH RR), so that the lanes' streams
/// advance in vector code: `Pcg::new(seed, stream)` draws what `Sampler::new(seed, stream)` draws.
#[derive(Clone, Copy, Default)]
struct Pcg {
    state: u64,
    increment: u64,
}

const PCG_MULTIPLIER: u64 = 6364136223846793005;

impl Pcg {
    /// `Sampler::new`'s seeding (splitmix64 of seed and pixel), then `Pcg32::new(state, stream)`.
    fn new(seed: u64, pixel: u64) -> Pcg {
        let mut z = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ pixel.wrapping_add(0x632B_E59B_D9B4_E019);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        let stream = pixel.wrapping_mul(2).wrapping_add(seed << 32) | 1;
        let increment = (stream << 1) | 1;
        let state = z.wrapping_add(increment).wrapping_mul(PCG_MULTIPLIER).wrapping_add(increment);
        Pcg { state, increment }
    }
}

/// One PCG32 step from `state`: the next state and `Sampler::next_1d`'s number.
#[inline(always)]
fn pcg_next(state: u64, increment: u64) -> (u64, f32) {
    let next = state.wrapping_mul(PCG_MULTIPLIER).wrapping_add(increment);
    let rot = (state >> 59) as u32;
    let xsh = (((state >> 18) ^ state) >> 27) as u32;
    (next, (xsh.rotate_right(rot) >> 8) as f32 * (1.0 / 16_777_216.0))
}

impl Pcg {
    #[inline(always)]
    fn next_1d(&mut self) -> f32 {
        let (next, u) = pcg_next(self.state, self.increment);
        self.state = next;
        u
    }
    #[inline(always)]
    fn next_2d(&mut self) -> Vec2 {
        let x = self.next_1d();
        Vec2::new(x, self.next_1d())
    }
}

/// True when the wide loop renders `scene` exactly: `path` (class AOVs off), every shape's BSDF
/// diffuse or two-sided diffuse.
pub fn applies(scene: &Scene) -> bool {
    ENABLED.load(Ordering::Relaxed)
        && matches!(scene.integrator, Integrator::Path(_))
        && !scene.integrator.classes
        && scene.shapes.iter().all(|s| scene.bsdfs.get(s.bsdf as usize).is_some_and(|b| diffuse_sides(b).is_some()))
}

/// The diffuse models seen from the front and from the back of a `diffuse` BSDF (`None` behind:
/// black there) or of a `twosided` one around two diffuse models; `None` for any other BSDF.
fn diffuse_sides(bsdf: &Bsdf) -> Option<(&Diffuse, Option<&Diffuse>)> {
    match bsdf {
        Bsdf::Diffuse(d) => Some((d, None)),
        Bsdf::TwoSided(front, back) => match (&**front, &**back) {
            (Bsdf::Diffuse(f), Bsdf::Diffuse(b)) => Some((f, Some(b))),
            _ => None,
        },
        _ => None,
    }
}

/// Samples `0..replay + spp` of every pixel of `pixels` (the first `replay` counted in `replayed`
/// and not splatted); `splat(pos, l, valid)` receives samples `replay..` in the scalar loop's order.
/// `moment`: a sample whose square is not finite is rejected too (as `render_tile`).
#[allow(clippy::too_many_arguments)]
pub fn render_pixels(
    scene: &Scene,
    pixels: &[Pixel],
    replay: u32,
    spp: u32,
    moment: bool,
    local: &mut LocalStats,
    replayed: &mut LocalStats,
    splat: &mut dyn FnMut(Vec2, Spectrum, bool),
) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx512f")
        && std::arch::is_x86_feature_detected!("avx512vl")
        && std::arch::is_x86_feature_detected!("avx512bw")
        && std::arch::is_x86_feature_detected!("avx512dq")
        && std::arch::is_x86_feature_detected!("avx2")
        && std::arch::is_x86_feature_detected!("fma")
    {
        // SAFETY: the CPU supports these features (checked just above).
        return unsafe { render_avx512(scene, pixels, replay, spp, moment, local, replayed, splat) };
    }
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("fma") {
        // SAFETY: the CPU supports AVX2 and FMA (checked just above).
        return unsafe { render_avx2(scene, pixels, replay, spp, moment, local, replayed, splat) };
    }
    render_impl(scene, pixels, replay, spp, moment, local, replayed, splat)
}

// The variants spell their arguments out: handing them over as one struct (destructured in
// `render_impl`) compiles the loop worse, +1.6 % instructions on cornell_box (16 spp, callgrind).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,avx512vl,avx512bw,avx512dq,avx2,fma")]
#[allow(clippy::too_many_arguments)]
fn render_avx512(
    scene: &Scene,
    pixels: &[Pixel],
    replay: u32,
    spp: u32,
    moment: bool,
    local: &mut LocalStats,
    replayed: &mut LocalStats,
    splat: &mut dyn FnMut(Vec2, Spectrum, bool),
) {
    render_impl(scene, pixels, replay, spp, moment, local, replayed, splat)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
#[allow(clippy::too_many_arguments)]
fn render_avx2(
    scene: &Scene,
    pixels: &[Pixel],
    replay: u32,
    spp: u32,
    moment: bool,
    local: &mut LocalStats,
    replayed: &mut LocalStats,
    splat: &mut dyn FnMut(Vec2, Spectrum, bool),
) {
    render_impl(scene, pixels, replay, spp, moment, local, replayed, splat)
}

/// Three lanes-wide coordinates.
#[derive(Clone, Copy, Default)]
struct V3 {
    x: [f32; N],
    y: [f32; N],
    z: [f32; N],
}

impl V3 {
    #[inline(always)]
    fn get(&self, l: usize) -> Vec3 {
        Vec3::new(self.x[l], self.y[l], self.z[l])
    }
    #[inline(always)]
    fn set(&mut self, l: usize, v: Vec3) {
        self.x[l] = v.x;
        self.y[l] = v.y;
        self.z[l] = v.z;
    }
}

/// The lanes' path state and the current vertex, structure of arrays.
#[derive(Default)]
struct Lanes {
    // ---- Path state (path.rs's names) ----
    beta: V3,
    result: V3,
    depth: [u32; N],
    prev_p: V3,
    prev_bsdf_pdf: [f32; N],
    prev_bsdf_delta: [bool; N],
    valid: [bool; N],
    ray_o: V3,
    ray_d: V3,
    // ---- The vertex being shaded ----
    p: V3,
    n: V3,
    frame_s: V3,
    frame_t: V3,
    frame_n: V3,
    /// `wi.z` seen from the side whose model shades (`twosided::to_front`); `flip`: that is the
    /// back side of a two-sided BSDF, so local directions are mirrored in z (`twosided::flip_z`).
    wi_z: [f32; N],
    flip: [bool; N],
    reflectance: V3,
    /// Emitter sample: direction, solid-angle pdf, delta, weight; `nee`: pdf and weight non-zero.
    ds_d: V3,
    ds_pdf: [f32; N],
    ds_delta: [bool; N],
    em_weight: V3,
    nee: [bool; N],
    /// With area lights on meshes and disks only (`mesh_lights`): the point sampled on the light
    /// (`Shape::sample_position`), its normal, area density and the light's radiance there; the
    /// direction sample and the shadow ray (origin, direction, `tmax`) are made in `emitter_rays`.
    ps_p: V3,
    ps_n: V3,
    ps_pdf: [f32; N],
    radiance: V3,
    shadow_o: V3,
    shadow_d: V3,
    shadow_tmax: [f32; N],
    sample2: [Vec2; N],
    /// Each lane's sampler stream (its pixel's); `shading`: the lane draws this vertex's numbers.
    rng_state: [u64; N],
    rng_increment: [u64; N],
    shading: [bool; N],
    em_sample: [Vec2; N],
    // ---- Results of the vector stage ----
    /// Next-event contribution if the emitter is visible; `shadow`: a shadow ray is needed.
    contrib: V3,
    shadow: [bool; N],
    /// BSDF sample: succeeded, the new throughput's largest channel.
    sampled: [bool; N],
    beta_max: [f32; N],
}

/// `fast::sincos_2pi` (its own polynomial parts) with the quadrant switch as selects.
#[inline(always)]
fn sincos_2pi(u: f32) -> (f32, f32) {
    let (s, c, quadrant) = crate::math::fast::sincos_2pi_parts(u);
    // Quadrants 0..3: (s, c), (c, −s), (−s, −c), (−c, s).
    let odd = quadrant & 1 != 0;
    let (s1, c1) = (if odd { c } else { s }, if odd { -s } else { c });
    let half = quadrant & 2 != 0;
    (if half { -s1 } else { s1 }, if half { -c1 } else { c1 })
}

/// `twosided::flip_z` as a select: z negated (exact) where `flip`.
#[inline(always)]
fn flip_z(v: Vec3, flip: bool) -> Vec3 {
    Vec3::new(v.x, v.y, if flip { -v.z } else { v.z })
}

/// `warp::square_to_cosine_hemisphere` (concentric disk, then lift) with its branches as selects.
#[inline(always)]
fn square_to_cosine_hemisphere(s: Vec2) -> Vec3 {
    let x = 2.0 * s.x - 1.0;
    let y = 2.0 * s.y - 1.0;
    let wide = x * x > y * y;
    let r = if wide { x } else { y };
    let turns = if wide { 0.125 * (y / x) } else { 0.25 - 0.125 * (x / y) };
    let (sin_phi, cos_phi) = sincos_2pi(turns);
    let origin = x == 0.0 && y == 0.0;
    let px = if origin { 0.0 } else { r * cos_phi };
    let py = if origin { 0.0 } else { r * sin_phi };
    let z = (1.0 - (px * px + py * py)).max(0.0).sqrt();
    Vec3::new(px, py, z)
}

/// `warp::square_to_cosine_hemisphere_pdf`.
#[inline(always)]
fn cosine_hemisphere_pdf(z: f32) -> f32 {
    if z > 0.0 {
        INV_PI * z
    } else {
        0.0
    }
}

/// The five numbers of a vertex for every shading lane, in `path.rs`'s order: the emitter sample
/// (2), `sample1` (drawn, unused by `diffuse`), `sample2` (2).
#[inline(always)]
fn draw(w: &mut Lanes) {
    for l in 0..N {
        let (inc, s0) = (w.rng_increment[l], w.rng_state[l]);
        let (s1, u0) = pcg_next(s0, inc);
        let (s2, u1) = pcg_next(s1, inc);
        let (s3, _) = pcg_next(s2, inc);
        let (s4, u3) = pcg_next(s3, inc);
        let (s5, u4) = pcg_next(s4, inc);
        w.em_sample[l] = Vec2::new(u0, u1);
        w.sample2[l] = Vec2::new(u3, u4);
        w.rng_state[l] = if w.shading[l] { s5 } else { s0 };
    }
}

/// `area::sample_direction` of a point sampled by area (`sphere::area_to_direction_sample`, the
/// front-side test) and `Scene::sample_emitter_direction`'s selection terms, for every lane, with
/// the shadow ray of `Scene::emitter_visible` (`offset_origin`, `spawn_ray_between`).
#[inline(always)]
fn emitter_rays(w: &mut Lanes, n_emitters: f32) {
    for l in 0..N {
        let (ref_p, ref_n) = (w.p.get(l), w.n.get(l));
        let (ps_p, ps_n) = (w.ps_p.get(l), w.ps_n.get(l));
        let delta = ps_p - ref_p;
        let dist = delta.length();
        let d = if dist > 0.0 { delta / dist } else { Vec3::Z };
        let cos = d.dot(ps_n);
        let pdf = if cos.abs() > 0.0 { w.ps_pdf[l] * dist * dist / cos.abs() } else { 0.0 };
        let front = pdf > 0.0 && cos < 0.0;
        let weight = if front { w.radiance.get(l) / pdf } else { Spectrum::ZERO };
        let pdf = (if front { pdf } else { 0.0 }) / n_emitters;
        let weight = weight * n_emitters;
        let finite = weight.x.is_finite() && weight.y.is_finite() && weight.z.is_finite();
        let weight = if pdf <= 0.0 || !finite { Spectrum::ZERO } else { weight };
        w.ds_d.set(l, d);
        w.ds_pdf[l] = pdf;
        w.ds_delta[l] = false;
        w.em_weight.set(l, weight);
        w.nee[l] = pdf > 0.0 && (weight.x != 0.0 || weight.y != 0.0 || weight.z != 0.0);
        let o = offset_origin(ref_p, ref_n, d);
        let to = ps_p - o;
        let dist = to.length();
        w.shadow_o.set(l, o);
        w.shadow_d.set(l, to / dist);
        w.shadow_tmax[l] = dist * (1.0 - crate::interaction::SHADOW_EPSILON);
    }
}

/// The vector stage for all lanes (inactive lanes compute on stale values; nobody reads them):
/// next-event estimation's BSDF value, pdf and MIS weight, and the diffuse BSDF sample.
#[inline(always)]
fn shade(w: &mut Lanes) {
    for l in 0..N {
        let frame = Frame { s: w.frame_s.get(l), t: w.frame_t.get(l), n: w.frame_n.get(l) };
        let wi_z = w.wi_z[l];
        let reflectance = w.reflectance.get(l);
        let beta = w.beta.get(l);

        // ---- Emitter sampling: diffuse eval and pdf (`Diffuse::eval`, `Diffuse::pdf`) ----
        let flip = w.flip[l];
        let wo = flip_z(frame.to_local(w.ds_d.get(l)), flip);
        let front = !(wi_z <= 0.0 || wo.z <= 0.0);
        let bsdf_val = if front { reflectance * (INV_PI * wo.z) } else { Spectrum::ZERO };
        let bsdf_pdf = if front { cosine_hemisphere_pdf(wo.z) } else { 0.0 };
        let ds_pdf = w.ds_pdf[l];
        let mis = if w.ds_delta[l] { 1.0 } else { mis_weight(ds_pdf, bsdf_pdf) };
        w.contrib.set(l, beta * w.em_weight.get(l) * bsdf_val * mis);
        let nonzero = bsdf_val.x != 0.0 || bsdf_val.y != 0.0 || bsdf_val.z != 0.0;
        w.shadow[l] = w.nee[l] && nonzero;

        // ---- BSDF sampling (`Diffuse::sample`, then `bsdf::nonzero`) ----
        let wo = square_to_cosine_hemisphere(w.sample2[l]);
        let pdf = cosine_hemisphere_pdf(wo.z);
        w.sampled[l] = !(wi_z <= 0.0) && pdf > 0.0 && reflectance.max_element() > 0.0;
        // The path state moves to the sampled direction in every lane: a lane whose sample failed
        // (or that is not shading) ends its path, and a new path sets all of this afresh.
        let beta = beta * reflectance;
        w.beta.set(l, beta);
        w.beta_max[l] = beta.max_element();
        let p = w.p.get(l);
        let wo_world = frame.to_world(flip_z(wo, flip));
        w.ray_d.set(l, wo_world);
        w.ray_o.set(l, offset_origin(p, w.n.get(l), wo_world));
        w.prev_p.set(l, p);
        w.prev_bsdf_pdf[l] = pdf;
        w.prev_bsdf_delta[l] = false;
        w.depth[l] += 1;
    }
}

#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn render_impl(
    scene: &Scene,
    pixels: &[Pixel],
    replay: u32,
    spp: u32,
    moment: bool,
    local: &mut LocalStats,
    replayed: &mut LocalStats,
    splat: &mut dyn FnMut(Vec2, Spectrum, bool),
) {
    let desc = &scene.integrator;
    let max_depth = if desc.max_depth < 0 { u32::MAX } else { desc.max_depth as u32 };
    let rr_depth = desc.rr_depth.max(0) as u32;
    // Mitsuba's `valid_ray` before the first vertex (see `path.rs`).
    let valid0 = !desc.hide_emitters && scene.environment.is_some();
    let total = replay + spp;
    // Area lights on meshes and disks (points sampled by area): emitter sampling in `emitter_rays`.
    let mesh_lights = !scene.emitters.is_empty()
        && scene.emitters.iter().all(|e| match e {
            SceneEmitter::Area { shape, .. } => !matches!(scene.shapes[*shape as usize].geometry, Geometry::Sphere(_)),
            SceneEmitter::Other(_) => false,
        });
    // Finished samples by pixel, splatted in pixel order at the end (flushing pixel by pixel as
    // they complete costs a mispredicted branch per pixel).
    let mut out = vec![(Vec2::ZERO, Spectrum::ZERO, false); pixels.len() * spp as usize];
    let mut w = Lanes::default();
    // Per lane: its pixel (`usize::MAX`: none), the sample index being traced, whether a path is
    // in flight, its film position, camera-ray weight and rays traced.
    let mut pixel = [usize::MAX; N];
    let mut sample = [0u32; N];
    let mut live = [false; N];
    let mut pos = [Vec2::ZERO; N];
    let mut ray_weight = [0.0f32; N];
    let mut rays = [0u64; N];
    let mut next_pixel = 0usize;
    let mut em_ds = [DirectionSample::default(); N];

    // The end of lane `l`'s path: the sample's value as `render_tile`'s `take_sample` makes it.
    macro_rules! finish {
        ($l:expr) => {{
            let l = $l;
            let i = sample[l];
            let stats = if i < replay { &mut *replayed } else { &mut *local };
            stats.rays += rays[l];
            rays[l] = 0;
            let mut value = if w.valid[l] { w.result.get(l) } else { Spectrum::ZERO };
            value *= ray_weight[l];
            if !(value.is_finite() && (!moment || (value * value).is_finite())) {
                stats.rejected_samples += 1;
                value = Spectrum::ZERO;
            }
            if i >= replay {
                out[pixel[l] * spp as usize + (i - replay) as usize] = (pos[l], value, w.valid[l]);
            }
            sample[l] = i + 1;
            live[l] = false;
        }};
    }

    loop {
        // ---- Refill: every free lane starts its pixel's next sample, or the next pixel ----
        for l in 0..N {
            while !live[l] {
                if pixel[l] == usize::MAX || sample[l] == total {
                    if next_pixel == pixels.len() {
                        pixel[l] = usize::MAX;
                        break;
                    }
                    pixel[l] = next_pixel;
                    let Pcg { state, increment } = Pcg::new(pixels[next_pixel].seed, pixels[next_pixel].stream);
                    (w.rng_state[l], w.rng_increment[l]) = (state, increment);
                    next_pixel += 1;
                    sample[l] = 0;
                    continue;
                }
                let px = &pixels[pixel[l]];
                let mut rng = Pcg { state: w.rng_state[l], increment: w.rng_increment[l] };
                let p = Vec2::new(px.x as f32, px.y as f32) + rng.next_2d();
                let aperture = rng.next_2d();
                w.rng_state[l] = rng.state;
                let (ray, weight) = super::primary_ray(scene, p, aperture);
                pos[l] = p;
                ray_weight[l] = weight;
                w.beta.set(l, Spectrum::ONE);
                w.result.set(l, Spectrum::ZERO);
                w.depth[l] = 0;
                w.prev_p.set(l, ray.o);
                w.prev_bsdf_pdf[l] = 1.0;
                w.prev_bsdf_delta[l] = true;
                w.valid[l] = valid0;
                w.ray_o.set(l, ray.o);
                w.ray_d.set(l, ray.d);
                live[l] = true;
                if max_depth == 0 {
                    finish!(l);
                }
            }
        }
        // The live lanes as a list: the loops below visit them without a branch per lane.
        let mut lanes = [0usize; N];
        let mut n_live = 0;
        for (l, &is_live) in live.iter().enumerate() {
            lanes[n_live] = l;
            n_live += is_live as usize;
        }
        if n_live == 0 {
            break;
        }

        // ---- Per lane: the ray, emission, the vertex, the emitter sample, the BSDF sample's numbers ----
        let mut n_shade = 0;
        // (Shading lanes are written back into `lanes`, never ahead of the one being read.)
        for i in 0..n_live {
            let l = lanes[i];
            rays[l] += 1;
            let ray = Ray::new(w.ray_o.get(l), w.ray_d.get(l));
            let si = scene.ray_intersect(&ray);
            let hide = desc.hide_emitters && w.depth[l] == 0;
            let prev_bsdf_delta = w.prev_bsdf_delta[l];
            let prev_bsdf_pdf = w.prev_bsdf_pdf[l];
            let beta = w.beta.get(l);
            let Some(si) = &si else {
                if !hide {
                    if let Some(SceneEmitter::Other(env)) = scene.environment.map(|e| &scene.emitters[e as usize]) {
                        let (le, pdf) = env.eval_environment_pdf(ray.d, !prev_bsdf_delta);
                        let mis = if prev_bsdf_delta {
                            1.0
                        } else {
                            mis_weight(prev_bsdf_pdf, pdf * scene.emitter_selection_pdf())
                        };
                        w.result.set(l, w.result.get(l) + beta * le * mis);
                    }
                }
                finish!(l);
                continue;
            };
            if !hide && scene.shapes[si.shape as usize].emitter.is_some() {
                let le = scene.eval_area_emitter(si);
                if le != Spectrum::ZERO {
                    let mis = if prev_bsdf_delta {
                        1.0
                    } else {
                        let prev_p = w.prev_p.get(l);
                        let ds = scene.direction_sample_for_hit(prev_p, si);
                        mis_weight(prev_bsdf_pdf, scene.pdf_emitter_direction(prev_p, &ds))
                    };
                    w.result.set(l, w.result.get(l) + beta * le * mis);
                }
            }
            if w.depth[l] + 1 >= max_depth {
                finish!(l);
                continue;
            }
            let Some((front, back)) = diffuse_sides(scene.bsdf(si)) else {
                unreachable!("path_wide::applies checks every BSDF")
            };
            // `twosided::to_front`: the back model shades a back-side hit, with wi mirrored.
            let (bsdf, back_side) = match back {
                Some(back) if si.wi.z.is_sign_negative() => (back, true),
                _ => (front, false),
            };
            w.reflectance.set(l, bsdf.reflectance.eval(si.uv));
            w.flip[l] = back_side;
            w.p.set(l, si.p);
            w.n.set(l, si.n);
            w.frame_s.set(l, si.sh_frame.s);
            w.frame_t.set(l, si.sh_frame.t);
            w.frame_n.set(l, si.sh_frame.n);
            w.wi_z[l] = if back_side { -si.wi.z } else { si.wi.z };
            w.shading[l] = true;
            lanes[n_shade] = l;
            n_shade += 1;
        }

        draw(&mut w);

        // ---- Per shading lane: emitter sampling (diffuse is smooth); its BSDF terms in `shade` ----
        if mesh_lights {
            for &l in &lanes[..n_shade] {
                w.shading[l] = false;
                rays[l] += 1;
                // `Scene::sample_emitter_direction` up to the shape's point sample.
                let Some((index, sample)) = scene.select_emitter(w.em_sample[l]) else { unreachable!() };
                let SceneEmitter::Area { shape, radiance } = &scene.emitters[index] else { unreachable!() };
                let ps = scene.shapes[*shape as usize].sample_position(sample);
                w.ps_p.set(l, ps.p);
                w.ps_n.set(l, ps.n);
                w.ps_pdf[l] = ps.pdf;
                w.radiance.set(l, radiance.eval(ps.uv));
            }
            emitter_rays(&mut w, scene.emitters.len() as f32);
        } else {
            for &l in &lanes[..n_shade] {
                w.shading[l] = false;
                w.nee[l] = false;
                if !scene.emitters.is_empty() {
                    rays[l] += 1;
                    let (p, n) = (w.p.get(l), w.n.get(l));
                    let (ds, em_weight) = scene.sample_emitter_direction_inline(p, Some(n), w.em_sample[l], false);
                    w.ds_d.set(l, ds.d);
                    w.ds_pdf[l] = ds.pdf;
                    w.ds_delta[l] = ds.delta;
                    w.em_weight.set(l, em_weight);
                    w.nee[l] = ds.pdf > 0.0 && em_weight != Spectrum::ZERO;
                    em_ds[l] = ds;
                }
            }
        }

        shade(&mut w);

        // ---- Per lane: the shadow ray, the new ray, Russian roulette ----
        for &l in &lanes[..n_shade] {
            if w.shadow[l] {
                let visible = if mesh_lights {
                    let ray = Ray { o: w.shadow_o.get(l), d: w.shadow_d.get(l), tmax: w.shadow_tmax[l] };
                    !scene.ray_test(&ray)
                } else {
                    scene.emitter_visible_inline(w.p.get(l), Some(w.n.get(l)), &em_ds[l])
                };
                if visible {
                    w.result.set(l, w.result.get(l) + w.contrib.get(l));
                }
            }
            // A failed sample of a non-null BSDF still makes the path valid (Mitsuba).
            w.valid[l] = true;
            if !w.sampled[l] {
                finish!(l);
                continue;
            }
            // ---- Russian roulette (`eta` stays 1: diffuse does not refract) ----
            let beta_max = w.beta_max[l];
            if !(beta_max > 0.0 && beta_max < f32::INFINITY) {
                finish!(l);
                continue;
            }
            if w.depth[l] >= rr_depth {
                let eta = 1.0f32;
                let q = (beta_max * eta * eta).min(0.95);
                let (next, u) = pcg_next(w.rng_state[l], w.rng_increment[l]);
                w.rng_state[l] = next;
                if u >= q {
                    finish!(l);
                    continue;
                }
                w.beta.set(l, w.beta.get(l) / q);
            }
        }
    }
    for &(pos, l, valid) in &out {
        splat(pos, l, valid);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{fast, warp};

    /// The lanes' PCG draws what `Sampler` draws.
    #[test]
    fn pcg_matches_sampler() {
        for (seed, pixel) in [(0u64, 0u64), (7, 123 << 32 | 5), (u64::MAX, 99), (3, u64::MAX)] {
            let (mut a, mut b) = (Pcg::new(seed, pixel), crate::sampler::Sampler::new(seed, pixel));
            for _ in 0..1000 {
                assert_eq!(a.next_1d().to_bits(), b.next_1d().to_bits());
            }
        }
    }

    /// The select forms are the scalar functions bit for bit.
    #[test]
    fn warps_match_scalar_bits() {
        let mut sampler = crate::sampler::Sampler::new(1, 2);
        for i in 0..200_000 {
            let s =
                if i < 4 { Vec2::new([0.5, 0.0, 0.5, 0.25][i], [0.5, 0.5, 0.0, 0.75][i]) } else { sampler.next_2d() };
            let (a, b) = (square_to_cosine_hemisphere(s), warp::square_to_cosine_hemisphere(s));
            assert_eq!(a.to_array().map(f32::to_bits), b.to_array().map(f32::to_bits), "{s:?}");
            let u = s.x * 1.125 - 0.125;
            let (a, b) = (sincos_2pi(u), fast::sincos_2pi(u));
            assert_eq!((a.0.to_bits(), a.1.to_bits()), (b.0.to_bits(), b.1.to_bits()), "{u}");
        }
    }
}

//! Manifold NEE to lights at a FINITE distance through a flat smooth boundary (docs/manifold.md
//! §3.2): area lights (rectangles, meshes, spheres — also a distant sphere "sun"), whose point `y`
//! is sampled by area, and point and spot lights, whose `y` is their position. Through each
//! supporting plane of the boundary the refraction point `x_k` is the unique solution of a 1-D
//! root (`flat::solve_point`); the value carries the generalized geometry term
//! `G = dω_j/dA⊥(y)` (`pdf::plane_geometry`, Jakob & Marschner 2012):
//!
//! ```text
//! area:        f_p(wi_j, ω_jk) T(d_jk) (1 − F) η² L_e(y) G cos θ_y / (p_sel p_A(y))
//! point, spot: f_p(wi_j, ω_jk) T(d_jk) (1 − F) η² I(−ω_l) G / p_sel
//! ```
//!
//! (`(1 − F) η²`: the radiance through the interface, as for the directional light, §3).
//! Spheres are sampled uniformly by area, not by the cone seen from `x_j` (Mitsuba's sampling for
//! a reference point): the part of a sphere reachable through a refraction is not the cap seen
//! straight from `x_j`, and uniform sampling reaches all of it.

use super::flat::{on_plane, refract_into, Refraction, Support};
use super::{pdf, MediumVertex};
use crate::color::Spectrum;
use crate::integrator::snee::light::light_transmission;
use crate::integrator::snee::{passable, LightSample};
use crate::integrator::stats::LocalStats;
use crate::interaction::{offset_origin, DirectionSample, SurfaceInteraction};
use crate::math::{Ray, Vec2, Vec3};
use crate::scene::world::{Scene, SceneEmitter};

/// The light end sampled at `x_j`.
#[derive(Clone, Copy, Debug)]
pub struct LightPoint {
    pub y: Vec3,
    /// Area lights: the surface normal and texture coordinates at `y`; `None`: point or spot.
    pub area: Option<(Vec3, Vec2)>,
    /// Index into `Scene::emitters`.
    pub emitter: u32,
    /// Density of `y`: `p_sel · p_A(y)` (area lights, by area), `p_sel` (point and spot lights).
    pub p_y: f64,
}

impl LightPoint {
    /// The emitter's direction record for the area-light point `y` seen from a point at distance
    /// `dist` along `d` (normal `n` and texture coordinates `uv` at `y`), to evaluate its density.
    pub fn direction_sample(&self, n: Vec3, uv: Vec2, d: Vec3, dist: f32) -> DirectionSample {
        DirectionSample { p: self.y, n, uv, d, dist, pdf: 0.0, delta: false, emitter: self.emitter }
    }
}

/// What the emitter sample of the connection picked.
#[derive(Clone, Copy, Debug)]
pub enum Pick {
    /// A light at a finite distance and its point.
    Finite(LightPoint),
    /// A directional light or an environment (`manifold::connect`).
    Distant,
    /// Nothing to connect to.
    Nothing,
}

/// Density by area of a light point on `shape` (uniform area sampling, `Shape::sample_position`).
#[inline]
fn area_pdf(scene: &Scene, shape: u32) -> f64 {
    1.0 / scene.shapes[shape as usize].surface_area() as f64
}

/// Pick an emitter with `u` as `Scene::sample_emitter_direction` does (uniform selection, the same
/// index for the same `u`) and, for a light at a finite distance, its point.
pub fn pick(scene: &Scene, u: Vec2) -> Pick {
    let n = scene.emitters.len();
    if n == 0 {
        return Pick::Nothing;
    }
    let x = u.x * n as f32;
    let index = (x as usize).min(n - 1);
    let u = Vec2::new(x - index as f32, u.y);
    let p_sel = 1.0 / n as f64;
    let emitter = index as u32;
    match &scene.emitters[index] {
        SceneEmitter::Area { shape, .. } => {
            let ps = scene.shapes[*shape as usize].sample_position(u);
            let p_y = p_sel * area_pdf(scene, *shape);
            Pick::Finite(LightPoint { y: ps.p, area: Some((ps.n, ps.uv)), emitter, p_y })
        }
        SceneEmitter::Other(crate::emitter::Emitter::Point(e)) => {
            Pick::Finite(LightPoint { y: e.p, area: None, emitter, p_y: p_sel })
        }
        SceneEmitter::Other(crate::emitter::Emitter::Spot(e)) => {
            Pick::Finite(LightPoint { y: e.p, area: None, emitter, p_y: p_sel })
        }
        SceneEmitter::Other(_) => Pick::Distant,
    }
}

/// One verified solution through a supporting plane.
#[derive(Clone, Copy, Debug)]
pub struct FiniteConnection {
    /// `f / p` without the path throughput and without MIS weight.
    pub value: Spectrum,
    pub si_k: SurfaceInteraction,
    pub refraction: Refraction,
    /// SNEE's record of the light end seen from `x_k` (densities only).
    pub light: LightSample,
    /// The generalized geometry term `G`.
    pub g: f64,
    /// `|cos θ_y|` at an area light's point (1 for point and spot lights).
    pub cos_y: f32,
    pub d_jk: f32,
}

/// Solve and verify the connection from `x_j` through the supporting plane `s` to the light point
/// `lp`: the refraction point, the segment `x_j → x_k` (its first hit must be `x_k` on `s`), the
/// emitter's front side and the light segment through passable surfaces. `None` when `s` does not
/// separate `x_j` from `y` (no candidate); a failed candidate is counted.
pub fn connect(
    scene: &Scene,
    x_j: &MediumVertex,
    s: &Support,
    lp: &LightPoint,
    stats: &mut LocalStats,
) -> Option<FiniteConnection> {
    let x_k = super::flat::solve_point(s, x_j.p, lp.y)?;
    let fail = |stats: &mut LocalStats| {
        stats.manifold_failures += 1;
        None
    };
    let v = x_k - x_j.p;
    let d = v.length();
    if !(d > 0.0) {
        return fail(stats);
    }
    let omega_jk = v / d;
    stats.rays += 1;
    let si_k = match scene.ray_intersect(&Ray::new(x_j.p, omega_jk)) {
        Some(si) if on_plane(scene, &si, x_j.medium, omega_jk, &s.plane) && (si.t - d).abs() <= 1e-3 * (1.0 + d) => si,
        _ => return fail(stats),
    };
    let to_y = lp.y - si_k.p;
    let d_ky = to_y.length();
    let omega_l = to_y / d_ky;
    let Some(r) = refract_into(&s.plane, omega_l) else { return fail(stats) };
    let d_jk = si_k.t;
    let g = pdf::plane_geometry(d_jk, d_ky, r.cos_in, r.cos_l, s.plane.eta);
    let (emitted, cos_y, p_light) = match (&scene.emitters[lp.emitter as usize], lp.area) {
        (SceneEmitter::Area { radiance, .. }, Some((n_y, uv))) => {
            let cos_y = -n_y.dot(omega_l);
            if !(cos_y > 0.0) {
                return fail(stats); // the back of a one-sided emitter
            }
            let ds = lp.direction_sample(n_y, uv, omega_l, d_ky);
            let le = radiance.eval(uv) * (g * cos_y as f64 / lp.p_y) as f32;
            (le, cos_y, scene.pdf_emitter_direction(si_k.p, &ds))
        }
        (SceneEmitter::Other(e), None) => {
            // Point, spot: weight = I(−ω_l) / d_ky² from x_k.
            let (_, w) = e.sample_direction(si_k.p, Vec2::ZERO);
            let intensity = w * (d_ky * d_ky);
            (intensity * (g / lp.p_y) as f32, 1.0, lp.p_y as f32)
        }
        _ => return fail(stats),
    };
    let light = LightSample { omega_l, p: lp.y, dist: d_ky, p_light, delta: lp.area.is_none(), le: Spectrum::ZERO };
    let tr = light_transmission(scene, &si_k, &light, stats);
    if tr == Spectrum::ZERO || emitted == Spectrum::ZERO {
        return fail(stats);
    }
    stats.manifold_solutions += 1;
    let m = &scene.media[x_j.medium as usize];
    let eta = s.plane.eta;
    let value = m.phase.eval(x_j.wi, omega_jk) * m.transmittance(d_jk) * ((1.0 - r.fresnel) * eta * eta) * emitted * tr;
    Some(FiniteConnection { value, si_k, refraction: r, light, g, cos_y, d_jk })
}

/// Upper bound on the passable surfaces walked to find an emitter point.
const MAX_WALK: u32 = 64;

/// The area-light point seen from `x_k` along `omega_l` through passable surfaces, and the
/// manifold connection's density of it, `p_sel p_A(y)`, and `|cos θ_y|`. For SNEE's side of the
/// MIS, which knows `y` but not its shape.
pub fn area_point(scene: &Scene, si_k: &SurfaceInteraction, omega_l: Vec3) -> Option<(f64, f32)> {
    area_point_hit(scene, si_k, omega_l).map(|hit| area_point_density(scene, &hit, omega_l))
}

/// The area-light point seen from `x_k` along `omega_l` through passable surfaces (the hit).
pub fn area_point_hit(scene: &Scene, si_k: &SurfaceInteraction, omega_l: Vec3) -> Option<SurfaceInteraction> {
    let mut ray = Ray::new(offset_origin(si_k.p, si_k.n, omega_l), omega_l);
    for _ in 0..MAX_WALK {
        let hit = scene.ray_intersect(&ray)?;
        if scene.shapes[hit.shape as usize].emitter.is_some() {
            return Some(hit);
        }
        if !passable(scene, &hit) {
            return None;
        }
        ray = Ray::new(offset_origin(hit.p, hit.n, omega_l), omega_l);
    }
    None
}

/// `(p_sel p_A(y), |cos θ_y|)` of an area-light point `hit` reached along `omega_l`.
pub fn area_point_density(scene: &Scene, hit: &SurfaceInteraction, omega_l: Vec3) -> (f64, f32) {
    let p_y = scene.emitter_selection_pdf() as f64 * area_pdf(scene, hit.shape);
    (p_y, hit.n.dot(omega_l).abs())
}

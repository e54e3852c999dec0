//! Glints: a DIRECTIONAL light seen by a pinhole camera through a CURVED smooth dielectric
//! boundary with no medium vertex on the path (`volpath_snee`, `connection = complete`,
//! docs/manifold.md §10), the class `surface` that no other technique of snee makes: a camera
//! ray reflected or refracted by a delta interface never hits a delta light.
//!
//! Two chains, both from the camera:
//!
//! ```text
//! Reflect:  camera → x_1 (outer reflection)                                 → light (omega_l)
//! Through:  camera → x_1 (refraction in) → no collision → x_2 (refraction out) → light (omega_l)
//! ```
//!
//! The unknown is the film position `u` (pixels, 2 degrees of freedom): the pinhole ray through
//! `u` meets the boundary at `x_1` (the first ray cast), is reflected about the interpolated
//! shading normal there, or refracted in, then meets the boundary again at `x_2` (the second ray
//! cast) and refracts out; the outgoing direction is `o(u)`. The constraint is
//! `C(u) = P_l (o(u) − omega_l) = 0` (as `newton.rs`, with the camera's film as the domain).
//! Within the located patches the map is in closed form (f64); its 2×2 Jacobian `do/du` is a
//! central difference of that closed form in tangent coordinates of `omega_l`.
//!
//! The pixel value. A box-filtered pixel `P` (one pixel unit of area) holds
//! `I_P = ∫_P L(u) du`, and for a directional light of irradiance `E`,
//! `L(u) = T(u) E δ(o(u) − omega_l)` (`T`: the Fresnel factors, the `η²` radiance scaling of
//! Mitsuba's `dielectric` — `1/η²` in, `η²` out — and the medium's transmittance between `x_1`
//! and `x_2`), so
//!
//! ```text
//! I_P = Σ_{s: u_s ∈ P} T(u_s) E |det do/du (u_s)|⁻¹        (pixels² per steradian)
//! ```
//!
//! Each camera sample of `P` GATHERS that sum (no splat, so the sample's value, its second moment
//! and its class stay per sample): Newton from the sample's own film position (uniform in `P`),
//! kept when it converges to a solution inside `P`, and specular manifold sampling's unbiased
//! `1/p(s)` (Zeltner et al. 2020, §4.3): the number `N` of seeds uniform in `P` drawn until the
//! same solution comes back (capped at [`MAX_TRIALS`], counted as `glint_trials_capped`). Newton
//! gives up as soon as a full step would leave `P` grown by [`MARGIN`] pixels (a deterministic
//! rule, so `p(s)` is well defined; it makes the samples of the many pixels without a glint cost
//! one ray cast or two and four closed-form evaluations). Weight 1: no other technique makes these
//! paths (forward tracing cannot hit a delta light; SNEE and the manifold connections start at a
//! medium vertex); `transport = snee` excludes them.
//!
//! Scope: a `perspective` sensor in vacuum with a `box` reconstruction filter, shapes with a smooth
//! `dielectric` bounding a medium and no exterior medium, `directional` emitters (summed). Other
//! filters would need a splat at `u_s` (not done: the glints are off there). Internal reflections
//! between the two refractions and chains of more interfaces are left out (docs/manifold.md §10).

use super::newton::{bernoulli_trials_capped, central_jacobian, tangents, Patch, Refracted};
use crate::bsdf::fresnel::fresnel;
use crate::color::Spectrum;
use crate::emitter::Emitter;
use crate::integrator::desc::Integrator;
use crate::integrator::snee::Snee;
use crate::integrator::stats::LocalStats;
use crate::interaction::{offset_origin, SurfaceInteraction};
use crate::math::{DMat4, DVec3, Ray};
use crate::sampler::Sampler;
use crate::scene::world::{Scene, SceneEmitter};
use crate::sensor::perspective::Perspective;
use crate::sensor::rfilter::RFilter;
use crate::sensor::Camera;
use glam::DVec2;

/// Newton steps at most per solve.
pub const MAX_ITERATIONS: u32 = 24;
/// Converged when `|o − omega_l| < TOLERANCE` (f64, radians).
pub const TOLERANCE: f64 = 1e-9;
/// Finite-difference step of the Jacobian (pixels).
const FD_STEP: f64 = 1e-4;
/// Newton gives up when a full step would land farther than this outside the pixel (pixels).
pub const MARGIN: f64 = 0.5;
/// Largest number of Bernoulli trials per solution.
pub const MAX_TRIALS: u32 = 256;

/// Which chain from the camera to the light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Chain {
    /// Outer reflection at `x_1`.
    Reflect,
    /// Refraction in at `x_1`, a straight segment through the medium, refraction out at `x_2`.
    Through,
    /// Refraction in at `x_1`, an internal reflection at `x_2`, refraction out at `x_3`, no
    /// collision on either segment (`inner_glints`).
    Inside,
}

/// The pinhole camera's map from film positions (pixels of the full film) to world directions,
/// in f64 (the same map as `Perspective::sample_ray`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraMap {
    pub origin: DVec3,
    pub to_world: DMat4,
    pub to_camera: DMat4,
    pub film_size: DVec2,
    /// `tan(x_fov / 2)` and that over the aspect ratio.
    pub half_extent: DVec2,
    pub offset: DVec2,
}

impl CameraMap {
    pub fn new(p: &Perspective, width: u32, height: u32) -> CameraMap {
        let to_world = p.to_world.as_dmat4();
        let tan_half = (0.5 * (p.x_fov as f64).to_radians()).tan();
        let aspect = width as f64 / height as f64;
        CameraMap {
            origin: to_world.w_axis.truncate(),
            to_world,
            to_camera: to_world.inverse(),
            film_size: DVec2::new(width as f64, height as f64),
            half_extent: DVec2::new(tan_half, tan_half / aspect),
            offset: p.principal_point_offset.as_dvec2(),
        }
    }

    /// Unit world direction of the pinhole ray through film position `u`.
    pub fn direction(&self, u: DVec2) -> DVec3 {
        let s = u / self.film_size + self.offset;
        let p = DVec3::new((1.0 - 2.0 * s.x) * self.half_extent.x, (1.0 - 2.0 * s.y) * self.half_extent.y, 1.0);
        // Normalized after the rotation: the f32 camera matrix is orthonormal to ~1e-7 only.
        self.to_world.transform_vector3(p).normalize()
    }

    /// The film position whose ray has direction `d` (inverse of [`CameraMap::direction`]).
    pub fn film_position(&self, d: DVec3) -> Option<DVec2> {
        let c = self.to_camera.transform_vector3(d);
        if !(c.z > 0.0) {
            return None;
        }
        let s = DVec2::new(0.5 * (1.0 - c.x / c.z / self.half_extent.x), 0.5 * (1.0 - c.y / c.z / self.half_extent.y));
        Some((s - self.offset) * self.film_size)
    }
}

/// Where the chain's rays meet the boundary (the caller's ray casts).
pub trait GlintLocate {
    /// First hit from the camera `c` along `d`: the patch and its geometric normal, `None` unless
    /// it is a medium's smooth dielectric boundary met from outside.
    fn first(&mut self, c: DVec3, d: DVec3) -> Option<(Patch, DVec3)>;
    /// First hit from `x_1` (on the boundary, geometric normal `n_1`) along the refracted `d`
    /// (inside): the same boundary, met from inside.
    fn second(&mut self, x_1: DVec3, n_1: DVec3, d: DVec3) -> Option<Patch>;
}

/// The closed-form chain at one film position through fixed patches.
#[derive(Clone, Copy, Debug)]
pub struct GlintMap {
    /// Camera ray direction.
    pub d: DVec3,
    pub x_1: DVec3,
    /// Outward shading normal at `x_1`; `cos_1 = −d · n_1 > 0`.
    pub n_1: DVec3,
    pub cos_1: f64,
    /// Direction after `x_1`: reflected (outside) or refracted (inside).
    pub d_1: DVec3,
    /// `Inside`: the internal reflection at `x_2`: point, outward shading normal, distance
    /// `x_1 → x_2`, `cos_2 = d_1 · n_2 > 0`.
    pub refl: Option<(DVec3, DVec3, f64, f64)>,
    /// The refraction out at the last interface (`Through`: `x_2`, `t` the distance `x_1 → x_2`;
    /// `Inside`: `x_3`, `t` the distance `x_2 → x_3`).
    pub out: Option<Refracted>,
    /// Outgoing direction (towards the light at a solution).
    pub o: DVec3,
}

/// Refraction of `d` into the surface at a point with outward shading normal `n`, `cos_1 = −d·n`.
pub(super) fn refract_in(d: DVec3, n: DVec3, cos_1: f64, eta: f64) -> Option<DVec3> {
    let cos_t2 = 1.0 - (1.0 - cos_1 * cos_1) / (eta * eta);
    if !(cos_t2 > 0.0) {
        return None;
    }
    // η_ext sin θ_1 = η_int sin θ_t, the refracted direction pointing inwards.
    Some((d / eta + n * (cos_1 / eta - cos_t2.sqrt())).normalize())
}

/// A small step along a ray leaving the boundary point `x` (selects the far root on a sphere; the
/// line is unchanged).
#[inline]
pub(super) fn nudge(x: DVec3) -> f64 {
    1e-7 * (1.0 + x.abs().max_element())
}

/// `d` reflected about the unit normal `n`, `cos = d · n` (the direction Mitsuba's `dielectric`
/// reflects into).
#[inline]
pub(super) fn mirror(d: DVec3, n: DVec3, cos: f64) -> DVec3 {
    d - n * (2.0 * cos)
}

/// The Newton step `−J⁻¹ r` of the 2×2 system `j` (determinant `det`) on the film.
#[inline]
pub(super) fn newton_step(j: [[f64; 2]; 2], r: [f64; 2], det: f64) -> DVec2 {
    -DVec2::new(j[1][1] * r[0] - j[0][1] * r[1], -j[1][0] * r[0] + j[0][0] * r[1]) / det
}

/// The damped step from `u`: `step` halved (at most 10 times) until `accept` takes the point.
pub(super) fn damped<T>(u: DVec2, step: DVec2, mut accept: impl FnMut(DVec2) -> Option<T>) -> Option<(DVec2, T)> {
    let mut scale = 1.0;
    for _ in 0..10 {
        let cand = u + step * scale;
        if let Some(v) = accept(cand) {
            return Some((cand, v));
        }
        scale *= 0.5;
    }
    None
}

/// The located patches of a chain: `p1` where the camera ray meets the boundary, `p2` the next
/// interface (`Through`, `Inside`), `p3` the one after it (`Inside`).
#[derive(Clone, Copy, Debug)]
pub struct Patches {
    pub p1: Patch,
    pub p2: Option<Patch>,
    pub p3: Option<Patch>,
}

/// The chain through its patches along the camera direction `d`, or `None` when `d` meets `p1`
/// from inside, or a refraction is total, or a later patch is met from outside.
pub fn glint_map(chain: Chain, patches: &Patches, c: DVec3, d: DVec3) -> Option<GlintMap> {
    let Patches { p1, p2, p3 } = *patches;
    let (_, x_1, n_1) = p1.hit(c, d)?;
    let cos_1 = -d.dot(n_1);
    if !(cos_1 > 0.0) {
        return None;
    }
    match chain {
        Chain::Reflect => {
            let o = d + n_1 * (2.0 * cos_1);
            Some(GlintMap { d, x_1, n_1, cos_1, d_1: o, refl: None, out: None, o })
        }
        Chain::Through => {
            let d_1 = refract_in(d, n_1, cos_1, p1.eta)?;
            // Start just past x_1.
            let e = nudge(x_1);
            let mut out = p2?.refract(x_1 + d_1 * e, d_1)?;
            out.t += e;
            Some(GlintMap { d, x_1, n_1, cos_1, d_1, refl: None, out: Some(out), o: out.o })
        }
        Chain::Inside => {
            let d_1 = refract_in(d, n_1, cos_1, p1.eta)?;
            let e = nudge(x_1);
            let (t_12, x_2, n_2) = p2?.hit(x_1 + d_1 * e, d_1)?;
            let cos_2 = d_1.dot(n_2);
            if !(t_12 > 0.0) || !(cos_2 > 0.0) {
                return None;
            }
            let d_2 = mirror(d_1, n_2, cos_2);
            let e_2 = nudge(x_2);
            let mut out = p3?.refract(x_2 + d_2 * e_2, d_2)?;
            out.t += e_2;
            let refl = Some((x_2, n_2, t_12 + e, cos_2));
            Some(GlintMap { d, x_1, n_1, cos_1, d_1, refl, out: Some(out), o: out.o })
        }
    }
}

/// A rectangle of the film (pixels): `lo ≤ u < hi`.
#[derive(Clone, Copy, Debug)]
pub struct Region {
    pub lo: DVec2,
    pub hi: DVec2,
}

impl Region {
    /// The pixel whose corner is `corner`.
    pub fn pixel(corner: DVec2) -> Region {
        Region { lo: corner, hi: corner + DVec2::ONE }
    }
    pub fn contains(&self, u: DVec2) -> bool {
        u.x >= self.lo.x && u.y >= self.lo.y && u.x < self.hi.x && u.y < self.hi.y
    }
    fn near(&self, u: DVec2, margin: f64) -> bool {
        u.x >= self.lo.x - margin && u.y >= self.lo.y - margin && u.x < self.hi.x + margin && u.y < self.hi.y + margin
    }
    /// The point at `(a, b) ∈ [0, 1)²` of the region.
    pub fn at(&self, a: f64, b: f64) -> DVec2 {
        self.lo + (self.hi - self.lo) * DVec2::new(a, b)
    }
}

/// The chain at `u` with its patches located by ray casts.
pub fn locate_at(
    locate: &mut impl GlintLocate,
    cam: &CameraMap,
    chain: Chain,
    u: DVec2,
) -> Option<(Patches, GlintMap)> {
    let d = cam.direction(u);
    let (p1, n_geo) = locate.first(cam.origin, d)?;
    let (p2, p3) = match chain {
        Chain::Reflect => (None, None),
        Chain::Through | Chain::Inside => {
            let (_, x_1, n_1) = p1.hit(cam.origin, d)?;
            let cos_1 = -d.dot(n_1);
            if !(cos_1 > 0.0) {
                return None;
            }
            let d_1 = refract_in(d, n_1, cos_1, p1.eta)?;
            let p2 = locate.second(x_1, n_geo, d_1)?;
            let p3 = if chain == Chain::Inside {
                let (_, x_2, n_2) = p2.hit(x_1 + d_1 * nudge(x_1), d_1)?;
                let cos_2 = d_1.dot(n_2);
                if !(cos_2 > 0.0) {
                    return None;
                }
                // The offset side from the shading normal (the reflected ray goes inwards).
                Some(locate.second(x_2, n_2, mirror(d_1, n_2, cos_2))?)
            } else {
                None
            };
            (Some(p2), p3)
        }
    };
    let patches = Patches { p1, p2, p3 };
    let m = glint_map(chain, &patches, cam.origin, d)?;
    Some((patches, m))
}

#[inline]
fn residual(m: &GlintMap, l: (DVec3, DVec3), omega_l: DVec3) -> [f64; 2] {
    let v = m.o - omega_l;
    [v.dot(l.0), v.dot(l.1)]
}

/// `dC/du` through fixed patches (columns: u.x, u.y), by central differences of the closed form.
fn jacobian(
    cam: &CameraMap,
    chain: Chain,
    patches: &Patches,
    u: DVec2,
    omega_l: DVec3,
    l: (DVec3, DVec3),
) -> Option<[[f64; 2]; 2]> {
    central_jacobian(FD_STEP, |a, b| {
        let moved = u + DVec2::new(a, b);
        Some(residual(&glint_map(chain, patches, cam.origin, cam.direction(moved))?, l, omega_l))
    })
}

/// A converged, located glint.
#[derive(Clone, Copy, Debug)]
pub struct GlintSolution {
    pub chain: Chain,
    /// Film position (pixels).
    pub u: DVec2,
    pub map: GlintMap,
    pub patches: Patches,
    /// `|det do/du|⁻¹`: pixels² per steradian of outgoing directions.
    pub du_do: f64,
    pub iterations: u32,
}

/// Solve `o(u) = omega_l` from `seed` by damped Newton (halved until `|o − omega_l|` decreases, at
/// most 10 halvings); fails when a full step would leave `region` grown by [`MARGIN`], and when
/// the solution lies outside `region`. Returns the solution (if any) and the iterations taken.
pub fn solve(
    locate: &mut impl GlintLocate,
    cam: &CameraMap,
    chain: Chain,
    omega_l: DVec3,
    region: Region,
    seed: DVec2,
) -> (Option<GlintSolution>, u32) {
    let l = tangents(omega_l);
    let mut u = seed;
    let Some((mut patches, mut m)) = locate_at(locate, cam, chain, u) else { return (None, 0) };
    for it in 0..=MAX_ITERATIONS {
        let norm = (m.o - omega_l).length();
        let Some(j) = jacobian(cam, chain, &patches, u, omega_l, l) else { return (None, it) };
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        if norm < TOLERANCE {
            if !(det.abs() > 0.0 && det.is_finite() && region.contains(u)) {
                return (None, it);
            }
            let s = GlintSolution { chain, u, map: m, patches, du_do: 1.0 / det.abs(), iterations: it };
            return (Some(s), it);
        }
        if it == MAX_ITERATIONS || !(det.abs() > 1e-300) {
            return (None, it);
        }
        let step = newton_step(j, residual(&m, l, omega_l), det);
        if !region.near(u + step, MARGIN) {
            return (None, it + 1);
        }
        let accepted =
            damped(u, step, |cand| locate_at(locate, cam, chain, cand).filter(|f| (f.1.o - omega_l).length() < norm));
        let Some((cand, found)) = accepted else { return (None, it + 1) };
        u = cand;
        (patches, m) = found;
    }
    (None, MAX_ITERATIONS)
}

/// Statistics of the solves (for `--stats`).
#[derive(Clone, Copy, Debug, Default)]
pub struct GlintCounts {
    pub solves: u64,
    pub iterations: u64,
    pub capped: u64,
}

/// Specular manifold sampling's estimate of `Σ_{s ∈ region} f(s)`: the solution from `seed`
/// (uniform in `region`) and the number `N` of seeds uniform in `region` (`u()` gives `[0, 1)²`)
/// drawn until it comes back (`E[N | s] = 1/p(s)`, capped at [`MAX_TRIALS`]); `f(s) · N`.
#[allow(clippy::too_many_arguments)]
pub fn sample_solution(
    locate: &mut impl GlintLocate,
    cam: &CameraMap,
    chain: Chain,
    omega_l: DVec3,
    region: Region,
    seed: DVec2,
    u: &mut impl FnMut() -> (f64, f64),
    counts: &mut GlintCounts,
) -> Option<(GlintSolution, u32)> {
    let draw = |locate: &mut _, seed: DVec2, counts: &mut GlintCounts| {
        let (s, it) = solve(locate, cam, chain, omega_l, region, seed);
        counts.solves += 1;
        counts.iterations += it as u64;
        s
    };
    let s = draw(locate, seed, counts)?;
    // Solutions are compared as points `(u, 0)`: the same when within 1e-4 pixels (`newton`'s threshold).
    let key = DVec3::new(s.u.x, s.u.y, 0.0);
    let (n, capped) = bernoulli_trials_capped(key, MAX_TRIALS, || {
        let (a, b) = u();
        draw(locate, region.at(a, b), counts).map(|t| DVec3::new(t.u.x, t.u.y, 0.0))
    });
    counts.capped += capped as u64;
    Some((s, n))
}

/// The weight `T / |det do/du|` of a solution without the medium's transmittance: Fresnel
/// reflectance (`Reflect`), or both Fresnel transmittances with the radiance scaling `η_2² / η_1²`.
pub fn geometric_weight(s: &GlintSolution) -> f64 {
    let eta_1 = s.patches.p1.eta;
    let f_1 = fresnel(s.map.cos_1 as f32, eta_1 as f32).0 as f64;
    let t = match (s.chain, s.map.out, s.patches.p2) {
        (Chain::Reflect, _, _) => f_1,
        (Chain::Through, Some(out), Some(p2)) => {
            let f_2 = fresnel(out.cos_out as f32, p2.eta as f32).0 as f64;
            (1.0 - f_1) * (1.0 - f_2) * (p2.eta * p2.eta) / (eta_1 * eta_1)
        }
        (Chain::Inside, Some(out), Some(p2)) => {
            // The reflection from inside at x_2 (total when beyond the critical angle).
            let cos_2 = s.map.refl.map_or(0.0, |r| r.3);
            let f_2 = fresnel(-cos_2 as f32, p2.eta as f32).0 as f64;
            let eta_3 = s.patches.p3.map_or(p2.eta, |p| p.eta);
            let f_3 = fresnel(out.cos_out as f32, eta_3 as f32).0 as f64;
            (1.0 - f_1) * f_2 * (1.0 - f_3) * (eta_3 * eta_3) / (eta_1 * eta_1)
        }
        _ => 0.0,
    };
    t * s.du_do
}

/// The scene as the glint's rays see it.
pub struct SceneGlint<'a> {
    pub scene: &'a Scene,
    pub rays: u64,
}

/// The patch of a medium's smooth dielectric boundary hit from outside along `d`, and the medium.
pub(super) fn outer_patch(scene: &Scene, si: &SurfaceInteraction, d: crate::math::Vec3) -> Option<(Patch, u32)> {
    let medium = scene.shapes[si.shape as usize].interior?;
    // `boundary_patch` checks the side by the direction of travel from inside: use `−d`.
    Some((super::locate::boundary_patch(scene, si, medium, -d)?, medium))
}

impl GlintLocate for SceneGlint<'_> {
    fn first(&mut self, c: DVec3, d: DVec3) -> Option<(Patch, DVec3)> {
        self.rays += 1;
        let d = d.as_vec3().normalize();
        let si = self.scene.ray_intersect(&Ray::new(c.as_vec3(), d))?;
        let (patch, _) = outer_patch(self.scene, &si, d)?;
        Some((patch, si.n.as_dvec3()))
    }

    fn second(&mut self, x_1: DVec3, n_1: DVec3, d: DVec3) -> Option<Patch> {
        self.rays += 1;
        let d = d.as_vec3().normalize();
        let o = offset_origin(x_1.as_vec3(), n_1.as_vec3(), d);
        let si = self.scene.ray_intersect(&Ray::new(o, d))?;
        let medium = self.scene.shapes[si.shape as usize].interior?;
        super::locate::boundary_patch(self.scene, &si, medium, d)
    }
}

/// Does the renderer's own (f32) hit `si` agree with the solved point and shading normal?
pub(super) fn agrees(si: &SurfaceInteraction, x: DVec3, n_s: DVec3, t: f64) -> bool {
    (si.p.as_dvec3() - x).length() <= 1e-3 * (1.0 + t) && si.sh_frame.n.as_dvec3().dot(n_s) > 1.0 - 1e-4
}

/// The camera ray along `d`: the renderer's own first hit and the medium inside it, when it is a
/// medium's smooth dielectric boundary met from outside and agrees with the solved point `x_1` and
/// shading normal `n_1`.
pub(super) fn camera_hit(
    scene: &Scene,
    cam: &CameraMap,
    d: crate::math::Vec3,
    x_1: DVec3,
    n_1: DVec3,
    stats: &mut LocalStats,
) -> Option<(SurfaceInteraction, u32)> {
    stats.rays += 1;
    let si = scene.ray_intersect(&Ray::new(cam.origin.as_vec3(), d))?;
    let (_, medium) = outer_patch(scene, &si, d)?;
    agrees(&si, x_1, n_1, (x_1 - cam.origin).length()).then_some((si, medium))
}

/// The chain's next interface from `si` along `d` inside `medium`: the renderer's own hit, when it
/// is the medium's boundary met from inside and agrees with the solved point, shading normal and
/// distance `(x, n, t)`.
pub(super) fn next_inside(
    scene: &Scene,
    si: &SurfaceInteraction,
    d: crate::math::Vec3,
    medium: u32,
    (x, n, t): (DVec3, DVec3, f64),
    stats: &mut LocalStats,
) -> Option<SurfaceInteraction> {
    stats.rays += 1;
    let hit = scene.ray_intersect(&Ray::new(offset_origin(si.p, si.n, d), d))?;
    (super::locate::boundary_patch(scene, &hit, medium, d).is_some() && agrees(&hit, x, n, t)).then_some(hit)
}

/// The legs of `Through` and `Inside` inside the medium, with the renderer's rays: in along `d_1`
/// from `si_1`, [the reflection at `x_2`], out at the last interface `out` (facing the light);
/// the last hit and the medium's transmittance along the legs.
fn inner_legs(
    scene: &Scene,
    s: &GlintSolution,
    si_1: &SurfaceInteraction,
    medium: u32,
    out: &Refracted,
    omega_l: crate::math::Vec3,
    stats: &mut LocalStats,
) -> Option<(SurfaceInteraction, Spectrum)> {
    let mut d = s.map.d_1.as_vec3().normalize();
    if !(d.dot(si_1.n) < 0.0) {
        return None;
    }
    let (mut si, mut length) = (*si_1, out.t);
    if let Some((x_2, n_2, t_12, _)) = s.map.refl {
        si = next_inside(scene, &si, d, medium, (x_2, n_2, t_12), stats)?;
        d = mirror(s.map.d_1, n_2, s.map.d_1.dot(n_2)).as_vec3().normalize();
        if !(d.dot(si.n) < 0.0) {
            return None;
        }
        length += t_12;
    }
    let last = next_inside(scene, &si, d, medium, (out.x_k, out.n_s, out.t), stats)?;
    let tr = scene.media[medium as usize].transmittance(length as f32);
    (last.n.dot(omega_l) > 0.0).then_some((last, tr))
}

/// Verify a solution with the renderer's rays and return its value without `N`: the geometric
/// weight times the medium's transmittance and the light segment's.
pub fn verify(scene: &Scene, cam: &CameraMap, s: &GlintSolution, omega_l: DVec3, stats: &mut LocalStats) -> Spectrum {
    let d = s.map.d.as_vec3().normalize();
    let omega_l = omega_l.as_vec3();
    let Some((si_1, medium)) = camera_hit(scene, cam, d, s.map.x_1, s.map.n_1, stats) else { return Spectrum::ZERO };
    let (last, tr_medium) = match (s.chain, s.map.out) {
        (Chain::Reflect, _) => {
            if !(omega_l.dot(si_1.n) > 0.0) {
                return Spectrum::ZERO;
            }
            (si_1, Spectrum::ONE)
        }
        (Chain::Through | Chain::Inside, Some(out)) => {
            let Some(legs) = inner_legs(scene, s, &si_1, medium, &out, omega_l, stats) else { return Spectrum::ZERO };
            legs
        }
        (Chain::Through | Chain::Inside, None) => return Spectrum::ZERO,
    };
    let tr_out = super::light_segment(scene, &last, omega_l, stats);
    tr_medium * tr_out * geometric_weight(s) as f32
}

/// Do glints run in this render, and which chains (`Reflect` needs a path of depth 2, `Through`
/// of depth 3, `Inside` of depth 4 and `inner_glints`)?
pub fn chains(scene: &Scene, snee: &Snee) -> (bool, bool, bool) {
    let Integrator::VolpathSnee(desc, _) = &scene.integrator else { return (false, false, false) };
    let on = super::enabled(scene)
        && snee.options.keeps_all()
        && matches!(scene.camera, Camera::Perspective(_))
        && matches!(scene.film.filter, RFilter::Box)
        && scene.sensor_medium.is_none();
    let depth = |d: i32| desc.max_depth < 0 || desc.max_depth >= d;
    (on && depth(2), on && depth(3), on && snee.options.inner_glints && depth(4))
}

/// The glints gathered by one camera sample (`ray`, from a pixel of a box-filtered film): for
/// every directional emitter and chain, the SMS estimate of the glints inside the sample's pixel.
/// Draws no random numbers when glints do not run.
pub fn sample(scene: &Scene, snee: &Snee, sampler: &mut Sampler, ray: &Ray, stats: &mut LocalStats) -> Spectrum {
    let (reflect, through, inside) = chains(scene, snee);
    if !(reflect || through || inside) {
        return Spectrum::ZERO;
    }
    let Some(cam) = &snee.camera else { return Spectrum::ZERO };
    let Some(pos) = cam.film_position(ray.d.as_dvec3()) else { return Spectrum::ZERO };
    let region = Region::pixel(pos.floor());
    // The sample's own position (rounding may put it a hair outside its pixel).
    let seed = pos.clamp(region.lo, region.hi - DVec2::splat(1e-9));
    let mut result = Spectrum::ZERO;
    for e in &scene.emitters {
        let SceneEmitter::Other(Emitter::Directional(e)) = e else { continue };
        let omega_l = -e.d.as_dvec3().normalize();
        for (chain, on) in [(Chain::Reflect, reflect), (Chain::Through, through), (Chain::Inside, inside)] {
            if !on {
                continue;
            }
            let mut locate = SceneGlint { scene, rays: 0 };
            let mut counts = GlintCounts::default();
            let mut u = || {
                let v = sampler.next_2d();
                (v.x as f64, v.y as f64)
            };
            let found = sample_solution(&mut locate, cam, chain, omega_l, region, seed, &mut u, &mut counts);
            stats.rays += locate.rays;
            stats.glint_solves += counts.solves;
            stats.glint_iterations += counts.iterations;
            stats.glint_trials_capped += counts.capped;
            let Some((s, n)) = found else { continue };
            let value = verify(scene, cam, &s, omega_l, stats) * e.irradiance * n as f32;
            if value != Spectrum::ZERO {
                stats.glint_solutions += 1;
            }
            super::add_finite(&mut result, value, stats);
        }
    }
    result
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::integrator::manifold::newton::Surface;

    /// A glass ball of unit radius at the origin (one analytic sphere) and a camera looking at it.
    struct Ball {
        eta: f64,
    }

    impl Ball {
        fn patch(&self) -> Patch {
            Patch { surface: Surface::Sphere { center: DVec3::ZERO, radius: 1.0, outward: 1.0 }, eta: self.eta }
        }
    }

    impl GlintLocate for Ball {
        fn first(&mut self, c: DVec3, d: DVec3) -> Option<(Patch, DVec3)> {
            let p = self.patch();
            let (_, x, n) = p.hit(c, d)?;
            let _ = x;
            Some((p, n))
        }
        fn second(&mut self, _x_1: DVec3, _n_1: DVec3, _d: DVec3) -> Option<Patch> {
            Some(self.patch())
        }
    }

    /// A 48×64 camera at `(0.3, 0.5, 4)` looking at the ball (also `camera_beam.rs`'s tests').
    pub(in crate::integrator::manifold) fn camera() -> CameraMap {
        // Mitsuba's `lookat`: columns left, up, forward, origin.
        let origin = DVec3::new(0.3, 0.5, 4.0);
        let dir = (DVec3::ZERO - origin).normalize();
        let left = DVec3::Y.cross(dir).normalize();
        let up = dir.cross(left);
        let to_world = DMat4::from_cols(left.extend(0.0), up.extend(0.0), dir.extend(0.0), origin.extend(1.0));
        let tan_half = (0.5f64 * 40f64.to_radians()).tan();
        CameraMap {
            origin: to_world.w_axis.truncate(),
            to_world,
            to_camera: to_world.inverse(),
            film_size: DVec2::new(48.0, 64.0),
            half_extent: DVec2::new(tan_half, tan_half * 64.0 / 48.0),
            offset: DVec2::ZERO,
        }
    }

    /// Directions to the light: two in front (reflection glints), three behind the ball within
    /// 10° of the view direction (glints through it). None near the silhouette's reflections
    /// (a light within θ of a reflection that grazes the rim without reaching it makes the cone
    /// limit at finite θ differ from its limit).
    /// Directions to the light for glints through one internal reflection (`Inside`): on the
    /// camera's side within 42° of the view axis (the primary rainbow's deviation is at least
    /// 138°), away from that caustic.
    fn inside_lights() -> [DVec3; 2] {
        [DVec3::new(0.3, 0.25, 0.92).normalize(), DVec3::new(-0.1, 0.35, 0.93).normalize()]
    }

    /// The (chain, light) pairs the tests check.
    fn cases() -> Vec<(Chain, DVec3)> {
        let mut v = Vec::new();
        for omega_l in lights() {
            v.push((Chain::Reflect, omega_l));
            v.push((Chain::Through, omega_l));
        }
        v.extend(inside_lights().map(|l| (Chain::Inside, l)));
        v
    }

    fn lights() -> [DVec3; 5] {
        [
            DVec3::new(0.3, 0.8, 0.5).normalize(),
            DVec3::new(-0.6, 0.2, 0.7).normalize(),
            DVec3::new(-0.05, -0.1, -1.0).normalize(),
            DVec3::new(0.02, -0.15, -1.0).normalize(),
            DVec3::new(-0.15, -0.05, -1.0).normalize(),
        ]
    }

    /// Every glint of the image (one solve from the centre of every pixel).
    fn all_solutions(ball: &mut Ball, cam: &CameraMap, chain: Chain, omega_l: DVec3) -> Vec<GlintSolution> {
        let mut found: Vec<GlintSolution> = Vec::new();
        for y in 0..64 {
            for x in 0..48 {
                let region = Region::pixel(DVec2::new(x as f64, y as f64));
                if let (Some(s), _) = solve(ball, cam, chain, omega_l, region, region.at(0.5, 0.5)) {
                    if found.iter().all(|f| (f.u - s.u).length() > 1e-3) {
                        found.push(s);
                    }
                }
            }
        }
        found
    }

    #[test]
    fn film_position_inverts_direction() {
        let cam = camera();
        for u in [DVec2::new(0.5, 0.5), DVec2::new(13.25, 40.75), DVec2::new(47.9, 63.1)] {
            let back = cam.film_position(cam.direction(u)).unwrap();
            assert!((back - u).length() < 1e-9, "{u:?} -> {back:?}");
        }
    }

    /// `|det do/du|⁻¹` against the film area of the re-solved solutions for a small square of
    /// light directions; the solutions obey the law of reflection / Snell's law twice.
    #[test]
    fn jacobian_matches_re_solving() {
        let cam = camera();
        let whole = Region { lo: DVec2::new(-100.0, -100.0), hi: DVec2::new(200.0, 200.0) };
        let mut checked = 0;
        for eta in [1.5, 1.33] {
            let mut ball = Ball { eta };
            for (chain, omega_l) in cases() {
                {
                    for s in all_solutions(&mut ball, &cam, chain, omega_l) {
                        let m = &s.map;
                        assert!((m.o - omega_l).length() < 1e-8);
                        match (m.out, m.refl) {
                            (_, Some((x_2, n_2, _, cos_2))) => {
                                // The law of reflection at x_2 and Snell's law at both refractions.
                                let out = m.out.expect("refraction out");
                                let d_2 = (out.x_k - x_2).normalize();
                                assert!((d_2 - (m.d_1 - n_2 * (2.0 * cos_2))).length() < 1e-9);
                                let sin_in = (1.0 - out.cos_in * out.cos_in).sqrt();
                                let sin_out = (1.0 - out.cos_out * out.cos_out).sqrt();
                                assert!((eta * sin_in - sin_out).abs() < 1e-7);
                            }
                            (None, _) => {
                                assert!((m.o.dot(m.n_1) - m.cos_1).abs() < 1e-9);
                                assert!(m.n_1.cross(m.d).dot(m.o).abs() < 1e-9);
                            }
                            (Some(out), None) => {
                                let sin_in = (1.0 - out.cos_in * out.cos_in).sqrt();
                                let sin_out = (1.0 - out.cos_out * out.cos_out).sqrt();
                                assert!((eta * sin_in - sin_out).abs() < 1e-7);
                                let sin_1 = (1.0 - m.cos_1 * m.cos_1).sqrt();
                                let sin_t = (1.0 - m.d_1.dot(m.n_1).powi(2)).sqrt();
                                assert!((sin_1 - eta * sin_t).abs() < 1e-7);
                            }
                        }
                        let h = 1e-4;
                        let (l1, l2) = tangents(omega_l);
                        let mut corner = |a: f64, b: f64| {
                            let w = (omega_l + l1 * a + l2 * b).normalize();
                            solve(&mut ball, &cam, chain, w, whole, s.u).0.expect("perturbed solves").u
                        };
                        let (p00, p10, p11, p01) = (corner(-h, -h), corner(h, -h), corner(h, h), corner(-h, h));
                        let cross = |a: DVec2, b: DVec2| (a.x * b.y - a.y * b.x).abs();
                        let area = 0.5 * (cross(p10 - p00, p11 - p00) + cross(p11 - p00, p01 - p00));
                        let fd = area / (4.0 * h * h);
                        let rel = (fd / s.du_do - 1.0).abs();
                        assert!(rel < 2e-3, "{chain:?} eta {eta}: du/do {} vs re-solved {fd} (rel {rel})", s.du_do);
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked >= 8, "only {checked} glints checked");
    }

    /// The image sum of the gathered estimates (4 per pixel) against the limit of a small cone of
    /// light directions through the closed-form map:
    /// `Σ_s T(s) |det do/du|⁻¹ = lim ∫_film T(u) 1[angle(o(u), ω_l) < θ] du / Ω(θ)`, the right
    /// side by film positions uniform over the image (no Newton, no seeds). Checks the solutions
    /// found, the Jacobian, the pixel gathering and the Bernoulli `1/p` together. Sample counts
    /// fixed before the first run: 2²⁰ film positions (θ = 0.02 rad) in a box around the cone's preimage, 4 estimates per pixel.
    #[test]
    fn gathered_image_matches_the_cone_limit() {
        let cam = camera();
        let mut rng = crate::sampler::Sampler::new(5, 1);
        let theta: f64 = 0.02;
        let cone = std::f64::consts::TAU * (1.0 - theta.cos());
        let mut ball = Ball { eta: 1.5 };
        let p = ball.patch();
        let all = Patches { p1: p, p2: Some(p), p3: Some(p) };
        let mut checked = 0;
        for (chain, omega_l) in cases() {
            {
                // The integrand vanishes outside the cone: film positions uniform over the box of
                // a 1/8-pixel grid's points within 3θ of omega_l, grown by one pixel.
                let (mut lo, mut hi) = (DVec2::splat(f64::MAX), DVec2::splat(f64::MIN));
                for y in 0..64 * 8 {
                    for x in 0..48 * 8 {
                        let u = DVec2::new(x as f64 + 0.5, y as f64 + 0.5) / 8.0;
                        let Some(g) = glint_map(chain, &all, cam.origin, cam.direction(u)) else {
                            continue;
                        };
                        if g.o.dot(omega_l) >= (3.0 * theta).cos() {
                            (lo, hi) = (lo.min(u), hi.max(u));
                        }
                    }
                }
                if lo.x > hi.x {
                    continue;
                }
                let (lo, hi) = (lo - DVec2::ONE, hi + DVec2::ONE);
                let area = (hi - lo).x * (hi - lo).y;
                let m = 1u64 << 20;
                let (mut sum, mut sq) = (0.0, 0.0);
                for _ in 0..m {
                    let v = rng.next_2d();
                    let u = lo + (hi - lo) * DVec2::new(v.x as f64, v.y as f64);
                    let Some(g) = glint_map(chain, &all, cam.origin, cam.direction(u)) else {
                        continue;
                    };
                    if g.o.dot(omega_l) < theta.cos() {
                        continue;
                    }
                    let s = GlintSolution { chain, u, map: g, patches: all, du_do: 1.0, iterations: 0 };
                    let w = geometric_weight(&s) * area / cone;
                    sum += w;
                    sq += w * w;
                }
                let cone_mean = sum / m as f64;
                let cone_se = ((sq / m as f64 - cone_mean * cone_mean) / m as f64).sqrt();
                // The gathered image: per pixel, the mean of 4 estimates; summed over pixels.
                let mut counts = GlintCounts::default();
                let (mut image, mut var) = (0.0, 0.0);
                for y in 0..64 {
                    for x in 0..48 {
                        let region = Region::pixel(DVec2::new(x as f64, y as f64));
                        let (mut s1, mut s2) = (0.0, 0.0);
                        for _ in 0..4 {
                            let v = rng.next_2d();
                            let seed = region.at(v.x as f64, v.y as f64);
                            let mut u = || {
                                let v = rng.next_2d();
                                (v.x as f64, v.y as f64)
                            };
                            let e = sample_solution(&mut ball, &cam, chain, omega_l, region, seed, &mut u, &mut counts)
                                .map_or(0.0, |(s, n)| geometric_weight(&s) * n as f64);
                            s1 += e;
                            s2 += e * e;
                        }
                        image += s1 / 4.0;
                        var += (s2 / 4.0 - (s1 / 4.0).powi(2)).max(0.0) / 3.0;
                    }
                }
                let se = var.sqrt();
                let z = (image - cone_mean) / (se * se + cone_se * cone_se).sqrt();
                eprintln!(
                    "{chain:?} {omega_l:?}: gathered {image:.4} ± {se:.4}, cone limit {cone_mean:.4} ± {cone_se:.4}, z {z:.2}; {counts:?}"
                );
                assert!(image.is_finite());
                checked += 1;
                assert!(z.abs() < 4.0, "{chain:?}: gathered {image} ± {se} vs cone limit {cone_mean} ± {cone_se}");
            }
        }
        assert!(checked >= 7, "only {checked} glints checked");
    }
}

//! Beams: light-traced internal-reflection segments inside a SMOOTH `dielectric` boundary under a
//! DIRECTIONAL light, connected to the camera path's medium vertices (`volpath_snee`,
//! `connection = complete`, parameter `beams`; derivation and measurements: `docs/beams.md`).
//!
//! Per camera sample, at its first medium vertex `x_a` where beams apply, one light subpath is
//! traced ([`trace`]): a point uniform on a disk perpendicular to the light covering the bounding
//! sphere of the medium's boundary (density `1/A`), the first hit along the light must be that
//! boundary from outside; the light refracts in with the flux weight `1 − F` (importance mode: no
//! `η²`), crosses segment 0 (not a beam: its in-scattering is SNEE's and §8's one-refraction
//! support) and reflects at every further boundary hit from inside (weight `F`, 1 under total
//! internal reflection). Each reflected segment `k ≥ 1` is a beam of flux
//! `Φ_k = E A (1 − F_in) Π F Π T`, kept up to [`MAX_REFLECTIONS`] reflections with Russian
//! roulette on the flux.
//!
//! At a camera medium vertex `x_a` every beam is connected through one point `x_b` on it, sampled
//! by equiangular sampling relative to `x_a` (Kulla & Fajardo 2012, [`Equiangular`]):
//!
//! ```text
//! β_a f_p(x_a; wi_a → ω_ab) T(x_a, x_b) / r² · σ_s f_p(x_b; ω_k → x_a − x_b) · Φ_k T(o_k, x_b) / pdf(t)
//! ```
//!
//! where `1 / (r² pdf(t)) = (θ_b − θ_a) / h` is bounded for every `x_b`. No other technique of
//! `complete` makes these paths (camera … → x_a → x_b → reflections inside → refraction out →
//! sun) except the two-vertex chain of `chain.rs` for one reflection, which skips vertices whose
//! predecessor is a medium vertex where beams run (`ManifoldStage::chain_at_scatter`), so the MIS
//! weight is 1.

pub use super::beam_boundary::BeamBoundary;
use super::MediumVertex;
use crate::bsdf::{flags, Bsdf, BsdfContext, TransportMode};
use crate::color::Spectrum;
use crate::emitter::Emitter;
use crate::integrator::cx::Scatter;
use crate::integrator::stats::LocalStats;
use crate::interaction::{offset_origin, spawn_ray_between, SurfaceInteraction};
use crate::math::frame::Frame;
use crate::math::warp::square_to_uniform_disk_concentric;
use crate::math::{Aabb, Ray, Vec3};
use crate::medium::homogeneous::Homogeneous;
use crate::sampler::Sampler;
use crate::scene::world::{Scene, SceneEmitter};

/// Reflections kept per light subpath (beams `k = 1 ..= MAX_REFLECTIONS`).
pub const MAX_REFLECTIONS: usize = 8;
/// Russian roulette on the light subpath: a beam whose flux (largest channel) is below this share
/// of the flux that entered survives with probability `share / ROULETTE_SHARE` (at least
/// [`ROULETTE_MIN`]) and is divided by it.
const ROULETTE_SHARE: f32 = 0.05;
const ROULETTE_MIN: f32 = 0.05;
/// Interfaces crossed (passable surfaces) before the light reaches the boundary, at most.
const MAX_PASSES: u32 = 64;

/// Per medium of `scene`: the boundary where beams apply, built at scene load (with `connection =
/// complete`, `beams`, and a directional light in the scene): the medium samples emitters, and
/// every `dielectric`/`roughdielectric` shape enclosing it (interior = the medium, no exterior
/// medium) is a smooth `dielectric`, at least one (the enclosure rule of SNEE and §8).
pub fn beam_boundaries(scene: &Scene) -> Vec<Option<BeamBoundary>> {
    (0..scene.media.len() as u32).map(|m| boundary(scene, m)).collect()
}

fn boundary(scene: &Scene, medium: u32) -> Option<BeamBoundary> {
    if !scene.media[medium as usize].sample_emitters {
        return None;
    }
    let mut bounds: Option<Aabb> = None;
    for s in scene.shapes.iter().filter(|s| s.interior == Some(medium) && s.exterior.is_none()) {
        match &scene.bsdfs[s.bsdf as usize] {
            Bsdf::Dielectric(_) => {}
            Bsdf::RoughDielectric(_) => return None,
            _ => continue,
        }
        let b = s.bounds();
        bounds = Some(bounds.map_or(b, |a| a.union(&b)));
    }
    let b = bounds.filter(|b| !b.is_empty())?;
    let radius = 0.5 * b.extent().length() * (1.0 + 1e-4) + 1e-5;
    (radius.is_finite() && radius > 0.0).then(|| BeamBoundary { center: b.center(), radius })
}

/// One beam: the segment `o + t d`, `t ∈ [0, len]`, carrying `flux` at `o` (spectral, W), after
/// `reflections` internal reflections.
#[derive(Clone, Copy, Debug, Default)]
pub struct Beam {
    pub o: Vec3,
    pub d: Vec3,
    pub len: f32,
    pub flux: Spectrum,
    pub reflections: u32,
}

/// The beams of one light subpath into `medium`.
#[derive(Clone, Copy, Debug)]
pub struct BeamSet {
    pub medium: u32,
    pub beams: [Beam; MAX_REFLECTIONS],
    pub n: usize,
}

impl BeamSet {
    fn empty(medium: u32) -> BeamSet {
        BeamSet { medium, beams: [Beam::default(); MAX_REFLECTIONS], n: 0 }
    }
    pub fn beams(&self) -> &[Beam] {
        &self.beams[..self.n]
    }
}

/// Is `si` (reached along `d`) a smooth dielectric shape enclosing `medium` (`snee::encloses`),
/// met from inside (`inside`) or from outside?
fn on_boundary(scene: &Scene, si: &SurfaceInteraction, medium: u32, d: Vec3, inside: bool) -> bool {
    let from_inside = if inside { d } else { -d };
    crate::integrator::snee::encloses(scene, si, medium, from_inside) && matches!(scene.bsdf(si), Bsdf::Dielectric(_))
}

/// The adjoint BSDF's shading-normal factor (Veach 1997, §5.3): light arriving from `w_in`
/// (towards where it came from) and leaving along `w_out`, `|w_in·n_s| |w_out·n_g| /
/// (|w_in·n_g| |w_out·n_s|)`; 1 where the shading normal is the geometric one.
fn shading_factor(si: &SurfaceInteraction, w_in: Vec3, w_out: Vec3) -> f32 {
    let n_s = si.sh_frame.n;
    let num = w_in.dot(n_s).abs() * w_out.dot(si.n).abs();
    let den = w_in.dot(si.n).abs() * w_out.dot(n_s).abs();
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

/// The delta lobe `component` (0: reflection, 1: refraction) of the dielectric at `si` for a ray
/// arriving along `d`, sampled in `mode` (importance for light subpaths, radiance for camera
/// paths): the world direction and the BSDF weight, or `None` when that lobe does not exist or
/// leaves on the wrong side (of the geometric or of the shading normal).
pub(super) fn delta_lobe(
    scene: &Scene,
    si: &SurfaceInteraction,
    d: Vec3,
    component: u32,
    mode: TransportMode,
) -> Option<(Vec3, Spectrum)> {
    let si = SurfaceInteraction { wi: si.to_local(-d), ..*si };
    let ctx = BsdfContext { mode, type_mask: flags::ALL, component };
    let (bs, weight) = scene.bsdf(&si).sample(&ctx, &si, 0.5, crate::math::Vec2::splat(0.5))?;
    let wo = si.to_world(bs.wo);
    // Reflection stays on the side the light came from, refraction crosses: geometric and shading
    // sides must agree, as the camera side's verification requires.
    let same_side = (wo.dot(si.n) > 0.0) == ((-d).dot(si.n) > 0.0);
    let shading_same = (bs.wo.z > 0.0) == (si.wi.z > 0.0);
    let want_same = component == 0;
    if same_side != want_same || shading_same != want_same || !(bs.wo.z != 0.0) {
        return None;
    }
    Some((wo, weight))
}

/// [`delta_lobe`] for light arriving along `d` (importance mode): the direction and the flux weight
/// with the shading-normal factor.
fn scatter(scene: &Scene, si: &SurfaceInteraction, d: Vec3, component: u32) -> Option<(Vec3, Spectrum)> {
    let (wo, weight) = delta_lobe(scene, si, d, component, TransportMode::Importance)?;
    Some((wo, weight * shading_factor(si, -d, wo)))
}

/// Trace one light subpath from a directional light into `medium` (bounding sphere `b`) and
/// record its beams. Draws from `sampler`: one number when the scene has several directional
/// lights, two for the disk, one per roulette decision.
pub fn trace(scene: &Scene, medium: u32, b: &BeamBoundary, sampler: &mut Sampler, stats: &mut LocalStats) -> BeamSet {
    let mut set = BeamSet::empty(medium);
    stats.beam_subpaths += 1;
    let lights = || {
        scene.emitters.iter().filter_map(|e| match e {
            SceneEmitter::Other(Emitter::Directional(d)) => Some(d),
            _ => None,
        })
    };
    let n_lights = lights().count();
    if n_lights == 0 {
        return set;
    }
    let pick = if n_lights > 1 { ((sampler.next_1d() * n_lights as f32) as usize).min(n_lights - 1) } else { 0 };
    let Some(light) = lights().nth(pick) else { return set };
    let d = light.d;
    // The disk perpendicular to the light through the boundary's bounding sphere, moved back
    // along the light outside the scene's bounds.
    let frame = Frame::from_normal(d);
    let q = square_to_uniform_disk_concentric(sampler.next_2d()) * b.radius;
    let p = b.center + frame.s * q.x + frame.t * q.y;
    let area = std::f32::consts::PI * b.radius * b.radius;
    let sb = scene.bounds;
    let (c_s, r_s) = (sb.center(), 0.5 * sb.extent().length());
    let back = (p - c_s).dot(d) + r_s * 1.01 + 1e-3;
    let mut ray = Ray::new(p - d * back.max(0.0), d);
    // The first hit that is not passable must be the boundary, from outside.
    let mut tr = light.irradiance * area * n_lights as f32;
    let mut si_in = None;
    for _ in 0..MAX_PASSES {
        stats.rays += 1;
        let Some(hit) = scene.ray_intersect(&ray) else { return set };
        if on_boundary(scene, &hit, medium, d, false) {
            si_in = Some(hit);
            break;
        }
        if !crate::integrator::snee::passable(scene, &hit) {
            return set;
        }
        tr *= scene.bsdf(&hit).eval_null_transmission(&hit);
        ray = Ray::new(offset_origin(hit.p, hit.n, d), d);
    }
    let Some(si_in) = si_in else { return set };
    let Some((mut dir, w)) = scatter(scene, &si_in, d, 1) else { return set };
    let mut flux = tr * w;
    let flux_in = flux.max_element();
    if !(flux_in > 0.0) {
        return set;
    }
    let m = &scene.media[medium as usize];
    let mut at = si_in;
    let mut reflections = 0u32;
    loop {
        stats.rays += 1;
        let Some(hit) = scene.ray_intersect(&Ray::new(offset_origin(at.p, at.n, dir), dir)) else { return set };
        if reflections > 0 {
            set.beams[set.n] = Beam { o: at.p, d: dir, len: hit.t, flux, reflections };
            set.n += 1;
            stats.beams += 1;
        }
        if set.n == MAX_REFLECTIONS || !on_boundary(scene, &hit, medium, dir, true) {
            return set;
        }
        let Some((reflected, w)) = scatter(scene, &hit, dir, 0) else { return set };
        flux *= m.transmittance(hit.t) * w;
        let share = flux.max_element() / flux_in;
        if !(share > 0.0) || !crate::color::is_finite(flux) {
            return set;
        }
        if share < ROULETTE_SHARE {
            let q = (share / ROULETTE_SHARE).max(ROULETTE_MIN);
            if sampler.next_1d() >= q {
                return set;
            }
            flux /= q;
        }
        reflections += 1;
        at = hit;
        dir = reflected;
    }
}

/// Equiangular sampling of a point on the segment `o + t d`, `t ∈ [0, len]`, relative to a point
/// `x` off its line (Kulla & Fajardo 2012): `t = Δ + h tan θ`, `θ` uniform in `[θ_a, θ_b]`, density
/// `h / ((θ_b − θ_a)(h² + (t − Δ)²))`, proportional to `1/r²` (f64 inside).
#[derive(Clone, Copy, Debug)]
pub struct Equiangular {
    /// Parameter of the foot of the perpendicular from `x`.
    pub delta: f64,
    /// Distance from `x` to the line.
    pub h: f64,
    pub theta_a: f64,
    pub theta_b: f64,
}

impl Equiangular {
    /// `None` when `x` lies on the line (to rounding) or the segment is empty.
    pub fn new(o: Vec3, d: Vec3, len: f32, x: Vec3) -> Option<Equiangular> {
        let (o, d, x) = (o.as_dvec3(), d.as_dvec3(), x.as_dvec3());
        let delta = (x - o).dot(d);
        let h = (x - (o + d * delta)).length();
        let len = len as f64;
        if !(h > 1e-9 * (1.0 + x.abs().max_element())) || !(len > 0.0) || !len.is_finite() {
            return None;
        }
        let theta_a = (-delta / h).atan();
        let theta_b = ((len - delta) / h).atan();
        (theta_b > theta_a).then_some(Equiangular { delta, h, theta_a, theta_b })
    }

    /// The parameter `t` for the uniform number `u`.
    pub fn sample(&self, u: f64) -> f64 {
        let theta = self.theta_a + u * (self.theta_b - self.theta_a);
        self.delta + self.h * theta.tan()
    }

    /// The density of `t` (per unit length).
    pub fn pdf(&self, t: f64) -> f64 {
        let s = t - self.delta;
        self.h / ((self.theta_b - self.theta_a) * (self.h * self.h + s * s))
    }

    /// `1 / (r² pdf(t))`, the same for every `t`: `(θ_b − θ_a) / h`.
    pub fn inv_r2_pdf(&self) -> f64 {
        (self.theta_b - self.theta_a) / self.h
    }
}

/// The value of one beam at the camera medium vertex `x` (without `β_a` and without the
/// visibility of `x_b`): `f_p(x) T(r) σ_s f_p(x_b) Φ T(t) / (r² pdf)`, and `x_b`.
pub fn beam_value(m: &Homogeneous, beam: &Beam, x: &MediumVertex, u: f32) -> Option<(Spectrum, Vec3)> {
    let eq = Equiangular::new(beam.o, beam.d, beam.len, x.p)?;
    let t = eq.sample(u as f64).clamp(0.0, beam.len as f64);
    let x_b = beam.o + beam.d * t as f32;
    let ab = x_b - x.p;
    let r = ab.length();
    if !(r > 0.0) {
        return None;
    }
    let w_ab = ab / r;
    let f_a = m.phase.eval(x.wi, w_ab);
    let f_b = m.phase.eval(-w_ab, -beam.d);
    let value =
        m.transmittance(r) * m.sigma_s() * m.transmittance(t as f32) * beam.flux * (f_a * f_b * eq.inv_r2_pdf() as f32);
    Some((value, x_b))
}

/// Every beam of `set` with at most `max_reflections` reflections and inside the depth budget
/// (`depth(x_a) + 1 + k + 1 < max_depth`: `x_b`, `k` reflections and the refraction out), connected
/// to the medium vertex `v` (`β_a = v.beta`). Draws one number per such beam.
pub fn connect(
    scene: &Scene,
    set: &BeamSet,
    v: &Scatter,
    max_reflections: u32,
    sampler: &mut Sampler,
    stats: &mut LocalStats,
) -> Spectrum {
    let m = &scene.media[v.medium as usize];
    let x = MediumVertex { p: v.p, wi: v.wi, medium: v.medium };
    let mut result = Spectrum::ZERO;
    for beam in set.beams() {
        if beam.reflections > max_reflections || v.depth.saturating_add(beam.reflections + 2) >= v.max_depth {
            continue;
        }
        let u = sampler.next_1d();
        stats.beam_connections += 1;
        let Some((value, x_b)) = beam_value(m, beam, &x, u) else { continue };
        if value == Spectrum::ZERO {
            continue;
        }
        stats.rays += 1;
        if scene.ray_test(&spawn_ray_between(x.p, x_b)) {
            stats.beam_blocked += 1;
            continue;
        }
        super::add_finite(&mut result, v.beta * value, stats);
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The equiangular density integrates to 1 over the segment (midpoint rule, 2²⁰ cells), and
    /// 10⁶ samples follow it: Pearson's χ² over 64 bins of equal probability under the pdf's own
    /// quadrature, below the 0.999 quantile of χ²(63) ≈ 103.4. Counts fixed before the first run.
    #[test]
    fn equiangular_pdf_integrates_to_one_and_matches_its_samples() {
        let mut rng = Sampler::new(5, 3);
        let cases = [
            (Vec3::ZERO, Vec3::X, 2.0, Vec3::new(0.5, 0.3, 0.0)),
            (Vec3::ZERO, Vec3::X, 2.0, Vec3::new(-1.0, 0.05, 0.0)),
            (Vec3::new(1.0, 2.0, 3.0), Vec3::new(0.3, -0.4, 0.866).normalize(), 0.7, Vec3::new(1.2, 2.1, 3.0)),
            (Vec3::ZERO, Vec3::Z, 5.0, Vec3::new(0.001, 0.0, 2.5)),
        ];
        for (o, d, len, x) in cases {
            let eq = Equiangular::new(o, d, len, x).expect("x off the line");
            let cells = 1 << 20;
            let dt = len as f64 / cells as f64;
            let total: f64 = (0..cells).map(|i| eq.pdf((i as f64 + 0.5) * dt) * dt).sum();
            assert!((total - 1.0).abs() < 1e-6, "∫ pdf = {total}");
            // Bins of equal probability from the quadrature's cumulative sum.
            let bins = 64;
            // (the crossing located inside its cell by linear interpolation of the cumulative sum).
            let mut edges = vec![0.0f64];
            let mut acc = 0.0;
            for i in 0..cells {
                let cell = eq.pdf((i as f64 + 0.5) * dt) * dt / total;
                let target = edges.len() as f64 / bins as f64;
                if acc + cell >= target && edges.len() < bins {
                    edges.push((i as f64 + (target - acc) / cell) * dt);
                }
                acc += cell;
            }
            edges.push(len as f64);
            let n = 1_000_000;
            let mut counts = vec![0u64; bins];
            for _ in 0..n {
                let t = eq.sample(rng.next_1d() as f64);
                assert!((-1e-9..=len as f64 + 1e-9).contains(&t), "t {t} outside [0, {len}]");
                let k = edges.partition_point(|&e| e <= t).clamp(1, bins) - 1;
                counts[k] += 1;
            }
            let expected = n as f64 / bins as f64;
            let chi2: f64 = counts.iter().map(|&c| (c as f64 - expected).powi(2) / expected).sum();
            assert!(chi2 < 103.4, "χ² {chi2} over {bins} bins ({o} {d} {len} {x})");
            // 1/(r² pdf) is the same at every t.
            for t in [0.0, 0.3 * len as f64, len as f64] {
                let p = o.as_dvec3() + d.as_dvec3() * t;
                let r2 = (p - x.as_dvec3()).length_squared();
                assert!((1.0 / (r2 * eq.pdf(t)) / eq.inv_r2_pdf() - 1.0).abs() < 1e-5);
            }
        }
        assert!(Equiangular::new(Vec3::ZERO, Vec3::X, 1.0, Vec3::new(0.5, 0.0, 0.0)).is_none());
    }
}

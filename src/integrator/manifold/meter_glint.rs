//! Glints seen by an irradiance meter (`connection = complete`, docs/manifold.md §11): the
//! meter's ray directions drawn from a mixture of its cosine lobe and the reflection lobes of the
//! directional lights on the rough boundary it faces.
//!
//! An `irradiancemeter` measures `E = ∫ L(ω) cos θ dω`; Mitsuba draws `ω` cosine-weighted (weight
//! π). Over a rough `roughdielectric` lit by a directional light, the light's reflection (class
//! `surface`: meter → rough reflection → light, forward NEE at the boundary) is non-zero only for
//! directions within a few `α` of the mirror direction, which a cosine sample hits once in ~1/α²
//! samples: at α = 0.001 this glint is the whole variance of the rough slab's reading
//! (docs/manifold.md §7, "Results"). Here the direction is drawn from the one-sample mixture
//!
//! ```text
//! p(ω) = c_cos · cos⁺θ / π + Σ_l (1 − c_cos)/L · [(1 − s) p_l(ω; α) + s p_l(ω; α_w)]
//! ```
//!
//! with `p_l(ω; α)` the density of `ω = −reflect(ω_l, m)`, `m` drawn from `D_α(m) cos θ_m` about
//! the reference normal `n_ref` (Walter et al. 2007, Eq. 14: `p(ω_o) = D(m) cos θ_m / (4 |ω_o·m|)`),
//! `α_w` the widened roughness of `rough_lobe::widened` (share `s` = its `WIDE_SHARE`), and the
//! ray's weight `cos⁺θ / p(ω)` in place of π. The cosine component keeps `p > 0` wherever
//! `cos θ > 0`, so the estimate of `E` is unbiased for any scene; the lobes only move samples to
//! where the glint is.
//!
//! The reference — the boundary the meter faces — is found once at scene load by a probe ray from
//! the centre of the meter's shape along its normal (`volpath_snee::build`); it applies when that
//! ray hits a `roughdielectric` with an isotropic roughness, and there is at least one directional
//! light in front of it.
//! Elsewhere (and with `connection = paper`, and for every other integrator) the meter samples as
//! Mitsuba does, bit for bit.

use crate::bsdf::microfacet::{MicrofacetDistribution, MicrofacetType};
use crate::interaction::offset_origin;
use crate::math::{reflect, warp, Frame, Ray, Vec2, Vec3, INV_PI};
use crate::sensor::irradiance_meter::IrradianceMeter;

/// Probability of the meter's own cosine lobe in the mixture.
pub const COSINE_SHARE: f32 = 0.5;

/// The reflection lobe of one directional light about the reference normal.
#[derive(Clone, Debug, PartialEq)]
struct Lobe {
    /// Unit direction from the boundary to the light, in the reference frame.
    omega_l: Vec3,
    narrow: MicrofacetDistribution,
    /// The widened lobe (`None` where widening changes nothing).
    wide: Option<MicrofacetDistribution>,
}

/// The meter's direction mixture, built once at scene load (`volpath_snee::build` finds the
/// reference with a probe ray and calls [`MeterGlint::new`]).
#[derive(Clone, Debug, PartialEq)]
pub struct MeterGlint {
    /// The boundary's normal towards the meter (`z` of the lobes' frame).
    n_ref: Vec3,
    /// Share of the widened lobe within each light's part (`rough_lobe::WIDE_SHARE`).
    wide_share: f32,
    lobes: Vec<Lobe>,
}

impl MeterGlint {
    /// The mixture about the reference normal `n_ref` (towards the meter) of a boundary with
    /// microfacet distribution `kind` and roughness `alpha` (its widened roughness `wide_alpha`,
    /// share `wide_share`), for the directional lights whose unit directions towards the light are
    /// `lights`; `None` when no light is in front of the boundary.
    pub fn new(
        n_ref: Vec3,
        kind: MicrofacetType,
        alpha: f32,
        wide_alpha: Option<f32>,
        wide_share: f32,
        lights: impl IntoIterator<Item = Vec3>,
    ) -> Option<MeterGlint> {
        let frame = Frame::from_normal(n_ref);
        let wide = wide_alpha.map(|a| distribution(kind, a));
        let lobes: Vec<Lobe> = lights
            .into_iter()
            .filter(|omega_l| omega_l.dot(n_ref) > 0.0)
            .map(|omega_l| Lobe { omega_l: frame.to_local(omega_l), narrow: distribution(kind, alpha), wide })
            .collect();
        (!lobes.is_empty()).then_some(MeterGlint { n_ref, wide_share, lobes })
    }
}

/// `D(m) cos θ_m` sampling (not visible normals: the density must not depend on a direction
/// that is not known before the sample).
fn distribution(kind: MicrofacetType, alpha: f32) -> MicrofacetDistribution {
    MicrofacetDistribution::new(kind, alpha, alpha, false)
}

impl MeterGlint {
    /// The meter's ray through film position `pos` (its fractional part picks the point on the
    /// shape, as [`IrradianceMeter::sample_ray`]) and its importance weight `cos⁺θ / p(ω)`.
    /// `aperture.x` picks the mixture's component and is reused for the direction.
    pub fn sample_ray(&self, meter: &IrradianceMeter, pos: Vec2, aperture: Vec2) -> (Ray, f32) {
        let u = pos - pos.floor();
        let ps = meter.shape.sample_position(u);
        let d = self.sample_direction(ps.n, aperture);
        let weight = self.weight(ps.n, d);
        (Ray::new(offset_origin(ps.p, ps.n, d), d), weight)
    }

    /// A direction from the mixture at a meter point of normal `n`.
    pub fn sample_direction(&self, n: Vec3, sample: Vec2) -> Vec3 {
        let below = 1.0 - f32::EPSILON;
        let c = COSINE_SHARE;
        if sample.x < c {
            let s = Vec2::new((sample.x / c).min(below), sample.y);
            return Frame::from_normal(n).to_world(warp::square_to_cosine_hemisphere(s));
        }
        // Which light, then the narrow or the wide lobe.
        let x = ((sample.x - c) / (1.0 - c)).min(below) * self.lobes.len() as f32;
        let lobe = &self.lobes[(x as usize).min(self.lobes.len() - 1)];
        let x = x.fract();
        let w = self.wide_share;
        let (dist, x) = match &lobe.wide {
            Some(wide) if x < w => (wide, (x / w).min(below)),
            Some(_) => (&lobe.narrow, ((x - w) / (1.0 - w)).min(below)),
            None => (&lobe.narrow, x),
        };
        let (m, _) = dist.sample(Vec3::Z, Vec2::new(x, sample.y));
        // The meter looks against the reflected direction.
        -Frame::from_normal(self.n_ref).to_world(reflect(lobe.omega_l, m)).normalize()
    }

    /// The mixture's solid-angle density of direction `d` at a meter point of normal `n`.
    pub fn pdf(&self, n: Vec3, d: Vec3) -> f32 {
        let c = COSINE_SHARE;
        let mut p = c * d.dot(n).max(0.0) * INV_PI;
        let omega_o = Frame::from_normal(self.n_ref).to_local(-d);
        let share = (1.0 - c) / self.lobes.len() as f32;
        for lobe in &self.lobes {
            let q = match &lobe.wide {
                Some(wide) => {
                    (1.0 - self.wide_share) * lobe_pdf(&lobe.narrow, lobe.omega_l, omega_o)
                        + self.wide_share * lobe_pdf(wide, lobe.omega_l, omega_o)
                }
                None => lobe_pdf(&lobe.narrow, lobe.omega_l, omega_o),
            };
            p += share * q;
        }
        p
    }

    /// The ray weight `cos⁺θ / p(d)`: 0 where the direction leaves the meter's back.
    pub fn weight(&self, n: Vec3, d: Vec3) -> f32 {
        let cos = d.dot(n);
        let p = self.pdf(n, d);
        if cos > 0.0 && p > 0.0 {
            cos / p
        } else {
            0.0
        }
    }
}

/// Density of `omega_o = reflect(omega_l, m)` with `m ~ D(m) cos θ_m` (local frame, `z` the
/// normal): `D(m) cos θ_m / (4 |omega_o · m|)` at the half vector (Walter et al. 2007, Eq. 14).
fn lobe_pdf(dist: &MicrofacetDistribution, omega_l: Vec3, omega_o: Vec3) -> f32 {
    let h = omega_l + omega_o;
    let len = h.length();
    if !(len > 1e-6) {
        return 0.0;
    }
    let m = if h.z < 0.0 { -h / len } else { h / len };
    let dot = omega_o.dot(m).abs();
    if !(dot > 0.0) {
        return 0.0;
    }
    dist.pdf(Vec3::Z, m) / (4.0 * dot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testing::chi2::{chi2_sphere, sidak};

    fn glint(kind: MicrofacetType, alpha: f32, lights: &[Vec3]) -> MeterGlint {
        let wide = Some((alpha * 8.0).min(0.5));
        MeterGlint::new(Vec3::Z, kind, alpha, wide, 0.5, lights.iter().map(|l| l.normalize())).unwrap()
    }

    /// The mixture's sampler against its density (chi-square over the sphere), for a meter facing
    /// down onto the reference plane (and a tilted meter), GGX and Beckmann, one or two lights.
    #[test]
    fn mixture_matches_its_density() {
        let cases = [
            (MicrofacetType::Ggx, 0.1, vec![Vec3::Z], -Vec3::Z),
            (MicrofacetType::Ggx, 0.05, vec![Vec3::new(0.5, 0.2, 1.0)], -Vec3::Z),
            (MicrofacetType::Beckmann, 0.08, vec![Vec3::new(-0.3, 0.6, 1.0), Vec3::Z], Vec3::new(0.3, 0.0, -1.0)),
            (MicrofacetType::Ggx, 0.02, vec![Vec3::new(0.7, 0.0, 0.7)], Vec3::new(-0.4, 0.1, -1.0)),
        ];
        let level = sidak(0.01, cases.len());
        for (kind, alpha, lights, n) in cases {
            let g = glint(kind, alpha, &lights);
            let n = n.normalize();
            let r = chi2_sphere(|_, u| Some(g.sample_direction(n, u)), |d| g.pdf(n, d), 64, 128, 400_000, level, 7);
            assert!(r.passed, "{kind:?} α {alpha}: {}", r.report);
            assert!((r.pdf_integral - 1.0).abs() < 2e-3, "∫p = {}", r.pdf_integral);
        }
    }

    /// The weight averages to the meter's cosine integral over its hemisphere: E[w] = ∫ cos⁺ dω = π.
    #[test]
    fn weights_average_to_pi() {
        let g = glint(MicrofacetType::Ggx, 0.01, &[Vec3::new(0.2, 0.1, 1.0)]);
        let n = Vec3::new(0.1, 0.0, -1.0).normalize();
        let mut rng = crate::sampler::Sampler::new(11, 0);
        let count = 400_000;
        let (mut sum, mut sum2) = (0.0f64, 0.0f64);
        for _ in 0..count {
            let d = g.sample_direction(n, rng.next_2d());
            let w = g.weight(n, d) as f64;
            sum += w;
            sum2 += w * w;
        }
        let mean = sum / count as f64;
        let se = ((sum2 / count as f64 - mean * mean) / count as f64).sqrt();
        assert!((mean - std::f64::consts::PI).abs() < 4.0 * se, "mean {mean} ± {se}");
    }
}

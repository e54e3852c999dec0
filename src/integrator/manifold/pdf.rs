//! Densities of a suffix `x_i → x_j → x_k → light` under the manifold connection and under SNEE, in
//! one measure, and their power-heuristic weights (docs/manifold.md §3–4).
//!
//! With a smooth boundary and a directional light the suffix lives in `(x_k, t)` (area × length,
//! `x_j = x_k + t·omega_in`); `dV(x_j) = |cos θ_in| dA(x_k) dt` converts the forward density of
//! `x_j` (volume measure) into it.

use crate::integrator::snee::SneeTechnique;

/// `dω_in / dω_l` of Snell refraction: `|cos θ_l| / (η² |cos θ_in|)` (η = η_int/η_ext; from
/// `η_ext² cos θ_l dω_l = η_int² cos θ_in dω_in`, Veach 1997, Eq. 5.10 with solid angles).
#[inline]
pub fn solid_angle_ratio(cos_l: f32, cos_in: f32, eta: f32) -> f64 {
    cos_l as f64 / ((eta as f64) * (eta as f64) * cos_in as f64)
}

/// Radiance factor of a smooth interface under a delta light (docs/manifold.md §2):
/// `L_in = (1 − F) η² L_out` (Mitsuba's radiance-mode transmission, η_ti²), and the delta in
/// `ω_l` becomes a delta in `ω_in` scaled by `dω_in/dω_l = cos θ_l / (η² cos θ_in)`; the η² cancel:
/// `E_in = (1 − F) · E · cos θ_l / cos θ_in` (energy through unit interface area is conserved).
#[inline]
pub fn beam_factor(fresnel: f32, cos_l: f32, cos_in: f32) -> f32 {
    (1.0 - fresnel) * cos_l / cos_in
}

/// Density of the manifold technique for the suffix made at `x_j` after forward sampling
/// `x_i → x_j`, in the measure `dt dA(x_k)`, emitter selection included:
/// `p_sel · f_p(wi_i, ω_ij) · σ_t e^{−σ_t t_ij} / t_ij² · |cos θ_in|` (σ_t in the path's channel).
#[inline]
pub fn manifold_density(p_sel: f32, phase_i: f32, sigma_t: f32, t_ij: f32, cos_in: f32) -> f64 {
    let (st, t) = (sigma_t as f64, t_ij as f64);
    let p = p_sel as f64 * phase_i as f64 * st * (-st * t).exp() / (t * t) * cos_in as f64;
    if p.is_finite() {
        p
    } else {
        0.0
    }
}

/// SNEE's smooth-boundary density as `snee::pdf_snee` returns it (the volume-measure expression
/// of docs/snee.md §2.3, which SNEE uses for delta lights too) converted to `dt dA(x_k)`:
/// multiply by the `t_kj² · dω_in/dω_l` that integrating out the Dirac adds to the integrand.
#[inline]
pub fn snee_density(pdf_snee: f64, t_kj: f32, ratio: f64) -> f64 {
    let p = pdf_snee * (t_kj as f64) * (t_kj as f64) * ratio;
    if p.is_finite() {
        p
    } else {
        0.0
    }
}

/// MIS weight of the manifold connection against SNEE for one suffix (both densities in the same
/// measure; `p_snee = 0` outside SNEE's support). `snee = snee` gives SNEE the suffixes it can make,
/// `snee = forward` (SNEE never runs) gives all to the manifold connection.
#[inline]
pub fn manifold_weight(technique: SneeTechnique, p_man: f64, p_snee: f64) -> f64 {
    match technique {
        SneeTechnique::Forward => 1.0,
        SneeTechnique::Snee if p_snee > 0.0 => 0.0,
        _ => power(p_man, p_snee),
    }
}

/// MIS weight of SNEE against the manifold connection (the complement of [`manifold_weight`]).
#[inline]
pub fn snee_weight(technique: SneeTechnique, p_snee: f64, p_man: f64) -> f64 {
    match technique {
        SneeTechnique::Forward => 0.0,
        SneeTechnique::Snee if p_snee > 0.0 => 1.0,
        SneeTechnique::Snee => 0.0,
        SneeTechnique::Mis => power(p_snee, p_man),
    }
}

/// Power heuristic (β = 2) of `a` against `b`; 0 when `a` is 0 or the ratio is not finite.
#[inline]
fn power(a: f64, b: f64) -> f64 {
    if !(a > 0.0) {
        return 0.0;
    }
    let r = b / a;
    let w = 1.0 / (1.0 + r * r);
    if w.is_finite() {
        w
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::manifold::flat::{refract_into, Plane};
    use crate::math::{Frame, Vec3};

    #[test]
    fn weights_partition_unity() {
        for (a, b) in [(1.0, 3.0), (2.0, 0.0), (1e-30, 1e30), (5.0, 5.0)] {
            for t in [SneeTechnique::Mis, SneeTechnique::Snee, SneeTechnique::Forward] {
                let s = manifold_weight(t, a, b) + snee_weight(t, b, a);
                assert!((s - 1.0).abs() < 1e-12, "{t:?} {a} {b}: {s}");
            }
        }
        assert_eq!(manifold_weight(SneeTechnique::Snee, 1.0, 0.0), 1.0);
    }

    /// dω_in/dω_l by finite differences: refract a small cone of light directions and compare the
    /// solid angle of the refracted cone (spherical triangle areas) with the closed form.
    #[test]
    fn jacobian_matches_finite_differences() {
        for eta in [1.33f32, 1.5, 1.0 / 1.33] {
            let plane = Plane { n: Vec3::new(0.1, 0.2, 1.0).normalize(), eta };
            let frame = Frame::from_normal(plane.n);
            for theta in [0.0f64, 0.3, 0.7, 1.0, 1.3] {
                let dir = |th: f64, ph: f64| {
                    frame.to_world(Vec3::new(
                        (th.sin() * ph.cos()) as f32,
                        (th.sin() * ph.sin()) as f32,
                        th.cos() as f32,
                    ))
                };
                let (h, phi) = (2e-3, 0.4);
                let l = [dir(theta + h, phi), dir(theta - h, phi + 0.7 * h / theta.max(h)), dir(theta, phi - h)];
                let Some(r0) = refract_into(&plane, dir(theta, phi)) else { continue };
                let refr: Option<Vec<Vec3>> = l.iter().map(|d| refract_into(&plane, *d).map(|r| r.omega_in)).collect();
                let Some(refr) = refr else { continue };
                let area = |v: &[Vec3]| {
                    let (a, b, c) = (v[0].as_dvec3(), v[1].as_dvec3(), v[2].as_dvec3());
                    // Solid angle of a small spherical triangle (Van Oosterom & Strackee 1983).
                    let num = a.dot(b.cross(c)).abs();
                    let den = 1.0 + a.dot(b) + b.dot(c) + c.dot(a);
                    2.0 * num.atan2(den)
                };
                let fd = area(&refr) / area(&l);
                let closed = solid_angle_ratio(r0.cos_l, r0.cos_in, eta);
                assert!((fd / closed - 1.0).abs() < 5e-3, "eta {eta} theta {theta}: fd {fd} closed {closed}");
            }
        }
    }
}

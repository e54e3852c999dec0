//! Fresnel equations for a smooth dielectric interface and for a conductor, the diffuse Fresnel
//! reflectance, and the reflection / refraction of directions (Mitsuba's `fresnel.h`).
//!
//! Conventions: directions point away from the surface; `eta` is the relative index of refraction
//! interior / exterior, where the exterior is the side the normal points to.

use crate::color::Spectrum;
use crate::math::{safe_sqrt, Vec3};

/// Unpolarized Fresnel reflectance at a dielectric interface (Mitsuba's `fresnel()`).
///
/// `cos_theta_i` is the cosine between the normal and the incident direction (negative when
/// arriving from the interior side), `eta` the relative index interior / exterior.
/// Returns `(F, cos_theta_t, eta_it, eta_ti)`:
/// - `F`: reflectance (1 under total internal reflection, 0 when index-matched),
/// - `cos_theta_t`: signed cosine of the transmitted direction (opposite sign to `cos_theta_i`),
/// - `eta_it`: relative index in the direction of travel (`eta` from outside, `1/eta` from inside),
/// - `eta_ti`: its reciprocal, the factor scaling the tangential components of the refracted direction.
#[inline]
pub fn fresnel(cos_theta_i: f32, eta: f32) -> (f32, f32, f32, f32) {
    let outside = cos_theta_i >= 0.0;
    let rcp_eta = 1.0 / eta;
    let (eta_it, eta_ti) = if outside { (eta, rcp_eta) } else { (rcp_eta, eta) };

    // Snell's law: squared cosine of the transmitted direction.
    let cos_theta_t_sqr = 1.0 - (1.0 - cos_theta_i * cos_theta_i) * (eta_ti * eta_ti);
    let cos_theta_i_abs = cos_theta_i.abs();
    let cos_theta_t_abs = safe_sqrt(cos_theta_t_sqr);

    let index_matched = eta == 1.0;
    let r = if index_matched {
        0.0
    } else if cos_theta_i_abs == 0.0 {
        1.0
    } else {
        // Amplitudes of the reflected s- and p-polarized waves.
        let a_s = (cos_theta_i_abs - eta_it * cos_theta_t_abs) / (cos_theta_i_abs + eta_it * cos_theta_t_abs);
        let a_p = (cos_theta_t_abs - eta_it * cos_theta_i_abs) / (cos_theta_t_abs + eta_it * cos_theta_i_abs);
        0.5 * (a_s * a_s + a_p * a_p)
    };
    // The transmitted direction lies on the other side.
    let cos_theta_t = if cos_theta_i >= 0.0 { -cos_theta_t_abs } else { cos_theta_t_abs };
    (r, cos_theta_t, eta_it, eta_ti)
}

/// Unpolarized Fresnel reflectance of a conductor with complex relative index `eta + i k`, per
/// channel (Mitsuba's `fresnel_conductor`, after K. D. Möller, "Optics", 1988).
///
/// `cos_theta_i` must be positive (light arrives from the outside). `eta = 0, k = 1` gives 1 at every
/// angle (Mitsuba's default "perfect mirror").
pub fn fresnel_conductor(cos_theta_i: f32, eta: Spectrum, k: Spectrum) -> Spectrum {
    let cos_theta_i_2 = cos_theta_i * cos_theta_i;
    let sin_theta_i_2 = 1.0 - cos_theta_i_2;
    let sin_theta_i_4 = sin_theta_i_2 * sin_theta_i_2;
    let channel = |eta_r: f32, eta_i: f32| {
        let temp_1 = eta_r * eta_r - eta_i * eta_i - sin_theta_i_2;
        // a² + b² and a, where (a + ib)² = η² − sin²θi.
        let a_2_pb_2 = safe_sqrt(temp_1 * temp_1 + 4.0 * eta_i * eta_i * eta_r * eta_r);
        let a = safe_sqrt(0.5 * (a_2_pb_2 + temp_1));
        let term_1 = a_2_pb_2 + cos_theta_i_2;
        let term_2 = 2.0 * cos_theta_i * a;
        let r_s = (term_1 - term_2) / (term_1 + term_2);
        let term_3 = a_2_pb_2 * cos_theta_i_2 + sin_theta_i_4;
        let term_4 = term_2 * sin_theta_i_2;
        let r_p = r_s * (term_3 - term_4) / (term_3 + term_4);
        0.5 * (r_s + r_p)
    };
    Spectrum::new(channel(eta.x, k.x), channel(eta.y, k.y), channel(eta.z, k.z))
}

/// Diffuse Fresnel reflectance F_dr: the fraction of uniformly diffuse (cosine-weighted) light
/// reflected by a dielectric interface of relative index `eta` (Mitsuba's
/// `fresnel_diffuse_reflectance`, same polynomial fits): Egan & Hilgeman 1973 for η < 1,
/// d'Eon & Irving 2011 for η ≥ 1.
pub fn fresnel_diffuse_reflectance(eta: f32) -> f32 {
    let inv_eta = 1.0 / eta;
    if eta < 1.0 {
        0.0636 * inv_eta + (eta * (eta * -1.4399 + 0.7099) + 0.6681)
    } else {
        let c = [0.919317f32, -3.4793, 6.75335, -7.80989, 4.98554, -1.36881];
        c.iter().rev().fold(0.0, |acc, &ci| acc * inv_eta + ci)
    }
}

/// Mirror reflection about the local normal +Z.
#[inline]
pub fn reflect_local(wi: Vec3) -> Vec3 {
    Vec3::new(-wi.x, -wi.y, wi.z)
}

/// Refraction through the local normal +Z, with `(cos_theta_t, eta_ti)` from [`fresnel`].
#[inline]
pub fn refract(wi: Vec3, cos_theta_t: f32, eta_ti: f32) -> Vec3 {
    Vec3::new(-eta_ti * wi.x, -eta_ti * wi.y, cos_theta_t)
}

/// Refraction through a microfacet normal `m`, with `(cos_theta_t, eta_ti)` from
/// `fresnel(wi·m, eta)`.
#[inline]
pub fn refract_m(wi: Vec3, m: Vec3, cos_theta_t: f32, eta_ti: f32) -> Vec3 {
    m * (wi.dot(m) * eta_ti + cos_theta_t) - wi * eta_ti
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fresnel reflectance from the textbook s/p formulas with explicit angles, in f64.
    fn fresnel_reference(theta_i: f64, n1: f64, n2: f64) -> f64 {
        let sin_t = n1 / n2 * theta_i.sin();
        if sin_t >= 1.0 {
            return 1.0;
        }
        let theta_t = sin_t.asin();
        let (ci, ct) = (theta_i.cos(), theta_t.cos());
        let rs = (n1 * ci - n2 * ct) / (n1 * ci + n2 * ct);
        let rp = (n1 * ct - n2 * ci) / (n1 * ct + n2 * ci);
        0.5 * (rs * rs + rp * rp)
    }

    #[test]
    fn matches_textbook_formulas() {
        for &eta in &[1.5f32, 1.33, 2.4] {
            for k in 0..=20 {
                let theta = k as f64 / 20.0 * 1.5;
                // From outside.
                let (f, ct, eta_it, eta_ti) = fresnel(theta.cos() as f32, eta);
                assert!((f as f64 - fresnel_reference(theta, 1.0, eta as f64)).abs() < 1e-5);
                assert_eq!((eta_it, eta_ti), (eta, 1.0 / eta));
                assert!(ct < 0.0);
                // From inside (cos θ < 0): index ratio flips, total internal reflection possible.
                let (f, ct, eta_it, _) = fresnel(-(theta.cos() as f32), eta);
                let reference = fresnel_reference(theta, eta as f64, 1.0);
                assert!((f as f64 - reference).abs() < 1e-5, "{} {} {}", theta, f, reference);
                assert_eq!(eta_it, 1.0 / eta);
                assert!(ct >= 0.0);
            }
        }
        assert_eq!(fresnel(0.7, 1.0).0, 0.0);
        assert_eq!(fresnel(0.0, 1.5).0, 1.0);
    }

    #[test]
    fn refraction_obeys_snell() {
        let eta = 1.5f32;
        let wi = Vec3::new(0.6, 0.0, 0.8);
        let (_, ct, _, eta_ti) = fresnel(wi.z, eta);
        let wt = refract(wi, ct, eta_ti);
        assert!((wt.length() - 1.0).abs() < 1e-6);
        // sin θi = η sin θt, on the opposite side, in the plane of incidence.
        let sin_t = (1.0 - wt.z * wt.z).sqrt();
        assert!((0.6 - eta * sin_t).abs() < 1e-6);
        assert!(wt.z < 0.0 && wt.x < 0.0);
        // The microfacet version agrees for m = +Z.
        assert!((refract_m(wi, Vec3::Z, ct, eta_ti) - wt).length() < 1e-6);
        // Reversibility: refracting back from inside returns wi.
        let (_, ct2, _, eta_ti2) = fresnel(wt.z, eta);
        assert!((refract(wt, ct2, eta_ti2) - wi).length() < 1e-5);
        assert_eq!(reflect_local(wi), Vec3::new(-0.6, 0.0, 0.8));
    }

    /// Conductor Fresnel: k = 0 reduces to the dielectric formula; (0, 1) is a perfect mirror.
    #[test]
    fn conductor_limits() {
        for k in 0..=20 {
            let c = (k as f32 / 20.0).max(1e-3);
            let f = fresnel_conductor(c, Spectrum::splat(1.5), Spectrum::ZERO);
            assert!((f.x - fresnel(c, 1.5).0).abs() < 1e-5, "{} {}", c, f.x);
            let mirror = fresnel_conductor(c, Spectrum::ZERO, Spectrum::ONE);
            assert!((mirror - Spectrum::ONE).abs().max_element() < 1e-6);
        }
    }

    /// F_dr against the hemispherical integral 2 ∫ F(cos θ) cos θ sin θ dθ (the fits are good to ~1 %).
    #[test]
    fn diffuse_reflectance_matches_integral() {
        for eta in [1.33f32, 1.5, 1.0 / 1.33, 1.0 / 1.5] {
            let n = 20_000;
            let mut sum = 0.0f64;
            for i in 0..n {
                let mu = (i as f64 + 0.5) / n as f64;
                sum += 2.0 * fresnel(mu as f32, eta).0 as f64 * mu / n as f64;
            }
            let fdr = fresnel_diffuse_reflectance(eta) as f64;
            assert!((fdr - sum).abs() < 0.01 * sum.max(0.05), "eta {}: {} vs {}", eta, fdr, sum);
        }
    }
}

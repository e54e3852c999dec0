//! Fresnel equations for a smooth dielectric interface, and the reflection / refraction of
//! directions (Mitsuba's `fresnel.h`).
//!
//! Conventions: directions point away from the surface; `eta` is the relative index of refraction
//! interior / exterior, where the exterior is the side the normal points to.

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
}

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

/// The generalized geometry term of `x_j → x_k → y` through a plane (docs/manifold.md §3.2): the
/// solid angle at `x_j` per unit area at `y` perpendicular to the ray, `G = dω_j / dA⊥(y)`
/// (Jakob & Marschner 2012, §4, the determinant of the constraint's derivative, here in closed
/// form). With `d_jk`, `d_ky` the two segment lengths, `θ_in`, `θ_l` the angles to the normal
/// inside and outside and `η = η_int/η_ext` (`η sin θ_in = sin θ_l`):
///
/// ```text
/// 1/G = (d_jk + η d_ky) · (d_jk cos θ_l / cos θ_in + η d_ky cos θ_in / cos θ_l)
/// ```
///
/// (`d²` for η = 1; `cos θ_l / (η² cos θ_in d_ky²)` as `d_ky → ∞`, the directional limit).
#[inline]
pub fn plane_geometry(d_jk: f32, d_ky: f32, cos_in: f32, cos_l: f32, eta: f32) -> f64 {
    let (a, b, ci, cl, e) = (d_jk as f64, d_ky as f64, cos_in as f64, cos_l as f64, eta as f64);
    let g = 1.0 / ((a + e * b) * (a * cl / ci + e * b * ci / cl));
    if g.is_finite() {
        g
    } else {
        0.0
    }
}

/// `dV(x_j) / (dA(x_k) dt)` for a light POINT `y` at distance `d_ky` from `x_k`: the cross-section
/// at `x_j` of the refracted tube of rays from `y` through `dA(x_k)`, per `dA(x_k)`. The étendue
/// `η_int² dA⊥(x_j) dω_j = η_ext² dA⊥(y) dω_y` gives `dω_y / dA⊥(x_j) = η² G`, and
/// `dA(x_k) = d_ky² dω_y / cos θ_l`, so `cos θ_l / (d_ky² η² G)` (→ `cos θ_in`, the sheared
/// prism of a directional light, as `d_ky → ∞`).
#[inline]
pub fn point_jacobian(d_ky: f32, cos_l: f32, eta: f32, g: f64) -> f32 {
    let (b, e) = (d_ky as f64, eta as f64);
    let j = cos_l as f64 / (b * b * e * e * g);
    if j.is_finite() {
        j as f32
    } else {
        0.0
    }
}

/// Density of the manifold technique for the suffix made at `x_j` after forward sampling
/// `x_i → x_j`, in the measure `dt dA(x_k)`, emitter selection included:
/// `p_sel · f_p(wi_i, ω_ij) · σ_t e^{−σ_t t_ij} / t_ij² · J` (σ_t in the path's channel), with
/// `J = dV(x_j)/(dA(x_k) dt)`: `|cos θ_in|` for a directional light, [`point_jacobian`] for a
/// point or spot light.
#[inline]
pub fn manifold_density(p_sel: f32, phase_i: f32, sigma_t: f32, t_ij: f32, jacobian: f32) -> f64 {
    let (st, t) = (sigma_t as f64, t_ij as f64);
    let p = p_sel as f64 * phase_i as f64 * st * (-st * t).exp() / (t * t) * jacobian as f64;
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

    use crate::integrator::manifold::flat::{solve_point, Support};
    use glam::DVec3;

    /// Solid angle of a small spherical triangle of unit vectors (Van Oosterom & Strackee 1983).
    fn tri_solid_angle(a: DVec3, b: DVec3, c: DVec3) -> f64 {
        let num = a.dot(b.cross(c)).abs();
        2.0 * num.atan2(1.0 + a.dot(b) + b.dot(c) + c.dot(a))
    }

    fn configurations() -> Vec<(Support, Vec3, Vec3)> {
        let mut v = Vec::new();
        for eta in [1.33f32, 1.5, 1.0 / 1.33, 1.0] {
            let plane = Plane { n: Vec3::new(0.2, -0.1, 1.0).normalize(), eta };
            let s = Support { plane, offset: 0.7 };
            for (xj, y) in [
                (Vec3::new(0.1, 0.2, -1.0), Vec3::new(0.3, -0.2, 3.0)),
                (Vec3::new(-0.5, 0.4, -0.2), Vec3::new(2.0, 1.0, 1.5)),
                (Vec3::new(0.0, 0.0, -3.0), Vec3::new(-4.0, 0.5, 2.0)),
                (Vec3::new(1.0, -1.0, -0.5), Vec3::new(1.1, -1.0, 20.0)),
            ] {
                v.push((s, xj, y));
            }
        }
        v
    }

    /// The refraction point solves Snell's law, lies on the plane, in the plane of incidence.
    #[test]
    fn solve_point_obeys_snell() {
        for (s, xj, y) in configurations() {
            let xk = solve_point(&s, xj, y).unwrap();
            assert!((s.plane.n.dot(xk) - s.offset).abs() < 1e-5);
            let (wi, wl) = ((xj - xk).normalize(), (y - xk).normalize());
            let r = refract_into(&s.plane, wl).expect("a solution refracts");
            assert!((r.omega_in - wi).length() < 2e-5, "{:?} vs {wi:?} (eta {})", r.omega_in, s.plane.eta);
        }
        // Wrong sides.
        let s = Support { plane: Plane { n: Vec3::Z, eta: 1.5 }, offset: 0.0 };
        assert!(solve_point(&s, Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 2.0)).is_none());
        assert!(solve_point(&s, Vec3::new(0.0, 0.0, -1.0), Vec3::new(0.0, 0.0, -2.0)).is_none());
    }

    /// The generalized geometry term by finite differences: move `y` over a small triangle
    /// perpendicular to the ray, re-solve `x_k`, and compare the solid angle of the directions
    /// `x_j → x_k` with `G` times the triangle's area. And `point_jacobian`: move `x_k` over a
    /// small triangle on the plane, follow the refracted rays from `y` to the distance `t` of `x_j`,
    /// and compare the cross-section there with `J` times the triangle's area.
    #[test]
    fn geometry_term_matches_finite_differences() {
        for (s, xj, y) in configurations() {
            let eta = s.plane.eta;
            let xk = solve_point(&s, xj, y).unwrap();
            let (d_jk, d_ky) = ((xk - xj).length(), (y - xk).length());
            let wl = (y - xk) / d_ky;
            let r = refract_into(&s.plane, wl).unwrap();
            let g = plane_geometry(d_jk, d_ky, r.cos_in, r.cos_l, eta);
            // y on a small triangle perpendicular to wl.
            let f = Frame::from_normal(wl);
            let h = 1e-3 * d_ky as f64;
            let offs = [(h, 0.0), (-0.5 * h, 0.8 * h), (-0.4 * h, -0.9 * h)];
            let dirs: Vec<DVec3> = offs
                .iter()
                .map(|&(u, v)| {
                    let yp = y.as_dvec3() + f.s.as_dvec3() * u + f.t.as_dvec3() * v;
                    let xkp = solve_point(&s, xj, yp.as_vec3()).unwrap().as_dvec3();
                    (xkp - xj.as_dvec3()).normalize()
                })
                .collect();
            let area = |p: [DVec3; 3]| 0.5 * (p[1] - p[0]).cross(p[2] - p[0]).length();
            let tri = |(u, v): (f64, f64)| DVec3::new(u, v, 0.0);
            let a_y = area([tri(offs[0]), tri(offs[1]), tri(offs[2])]);
            let fd = tri_solid_angle(dirs[0], dirs[1], dirs[2]) / a_y;
            assert!((fd / g - 1.0).abs() < 2e-2, "eta {eta} xj {xj:?} y {y:?}: fd {fd} closed {g}");

            // x_k on a small triangle on the plane; x_j' at the same distance along each refracted ray.
            let pf = Frame::from_normal(s.plane.n);
            let hk = 1e-3 * d_jk as f64;
            let pts: Vec<DVec3> = offs
                .iter()
                .map(|&(u, v)| {
                    let k = xk.as_dvec3() + (pf.s.as_dvec3() * u + pf.t.as_dvec3() * v) * (hk / h);
                    let w = (y.as_dvec3() - k).normalize().as_vec3();
                    let ri = refract_into(&s.plane, w).unwrap();
                    k + ri.omega_in.as_dvec3() * d_jk as f64
                })
                .collect();
            // Cross-section perpendicular to the central refracted ray.
            let axis = r.omega_in.as_dvec3();
            let proj: Vec<DVec3> = pts.iter().map(|p| *p - axis * p.dot(axis)).collect();
            let a_k = area([tri(offs[0]), tri(offs[1]), tri(offs[2])]) * (hk / h) * (hk / h);
            let fd_j = area([proj[0], proj[1], proj[2]]) / a_k;
            let j = point_jacobian(d_ky, r.cos_l, eta, g) as f64;
            assert!((fd_j / j - 1.0).abs() < 2e-2, "eta {eta}: J fd {fd_j} closed {j}");
        }
    }

    /// pdf integration: the manifold technique's density of the direction `x_j → x_k`, for a light
    /// point sampled uniformly on a rectangle above the plane, `p_A / (G cos θ_y)` (solid angle at
    /// `x_j`), integrates to 1 over the directions whose refracted ray reaches the rectangle
    /// (Monte Carlo over uniform directions at `x_j`, 400 000 samples, fixed sequence).
    #[test]
    fn light_point_density_integrates_to_one() {
        for eta in [1.33f32, 1.5, 1.0 / 1.33] {
            let xj = Vec3::new(0.2, -0.1, -0.6);
            // Rectangle [−1, 1.5] × [−0.5, 1] at height 1.2, facing down (normal −z).
            let (x0, x1, y0, y1, hgt) = (-1.0f64, 1.5, -0.5, 1.0, 1.2);
            let p_a = 1.0 / ((x1 - x0) * (y1 - y0));
            let n = 400_000u32;
            let mut sum = 0.0f64;
            for i in 0..n {
                // A stratified, deterministic sequence over the sphere (Fibonacci lattice).
                let z = 1.0 - (2.0 * i as f64 + 1.0) / n as f64;
                let phi = i as f64 * 2.399963229728653;
                let rz = (1.0 - z * z).sqrt();
                let w = DVec3::new(rz * phi.cos(), rz * phi.sin(), z);
                if w.z <= 0.0 {
                    continue;
                }
                let t = -(xj.z as f64) / w.z;
                let xk = xj.as_dvec3() + w * t;
                // The light direction whose refraction is −w (reverse the path).
                let cos_in = w.z;
                let sin_l2 = (eta as f64).powi(2) * (1.0 - cos_in * cos_in);
                if sin_l2 >= 1.0 {
                    continue;
                }
                let cos_l = (1.0 - sin_l2).sqrt();
                let tang = DVec3::new(w.x, w.y, 0.0);
                let tang = if tang.length() > 0.0 { tang.normalize() } else { DVec3::X };
                let wl = tang * sin_l2.sqrt() + DVec3::Z * cos_l;
                let s_y = hgt / wl.z;
                let y = xk + wl * s_y;
                if !(y.x > x0 && y.x < x1 && y.y > y0 && y.y < y1) {
                    continue;
                }
                let g = plane_geometry(t as f32, s_y as f32, cos_in as f32, cos_l as f32, eta);
                let cos_y = wl.z;
                sum += p_a / (g * cos_y);
            }
            let integral = sum * 4.0 * std::f64::consts::PI / n as f64;
            assert!((integral - 1.0).abs() < 5e-3, "eta {eta}: {integral}");
        }
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

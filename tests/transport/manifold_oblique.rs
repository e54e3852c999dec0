//! The manifold connection's beam factor at oblique incidence, against a semi-analytic reference.
//!
//! A thick slab (σt = 1, 100 deep, 200 wide) behind a smooth `dielectric` (n = 1.33, 1.5) under a
//! collimated beam at θ0 = 50° from the normal, read by an `irradiancemeter` just above, with
//! `max_depth = 4`: the camera ray's refraction (depth 1) and one medium scatter (depth 2) leave
//! room for exactly one connection through the boundary, so only single scattering is rendered
//! (a second scatter has depth 3; SNEE needs depth + 2 < max_depth). Its exact value per unit
//! incident irradiance (flux per unit slab area; docs/manifold.md §5):
//!
//!     R_ss = cos θ0 (1 − F(θ0)) · a ∫_{up} p(ω_t · ω) (1 − F_in(μ)) μ / (μ + μ_t) dω
//!
//! with `ω_t` the refracted beam direction (`μ_t = |cos|`), `F_in(μ)` the Fresnel reflectance seen
//! from inside (1 beyond the critical angle). Adding-doubling cannot check this: iadpython does not
//! implement oblique incidence. Sample counts fixed before the first run: 16 batches × 16384.

use crate::common;

use snee::render::{render, RenderOptions};
use std::f64::consts::PI;
use std::sync::atomic::AtomicBool;

const THETA0_DEG: f64 = 50.0;

fn slab(n: f64, albedo: f64, g: f64) -> String {
    assert!(g != 0.0, "the hg phase is what this test integrates");
    let (s, c) = THETA0_DEG.to_radians().sin_cos();
    let integrator = r#"<integrator type="volpath_snee"><integer name="max_depth" value="4"/><string name="connection" value="complete"/></integrator>"#;
    let boundary = format!(
        r#"<bsdf type="dielectric"><float name="int_ior" value="{n}"/><float name="ext_ior" value="1"/></bsdf>"#
    );
    common::slab_scene(integrator, &format!("{s}, 0, {}", -c), albedo, g, &boundary)
}

/// Unpolarized Fresnel reflectance for a ray with |cos| = `cos_i` on the side of index `n_i`.
fn fresnel(cos_i: f64, n_i: f64, n_t: f64) -> f64 {
    let sin_t = n_i / n_t * (1.0 - cos_i * cos_i).max(0.0).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (n_i * cos_i - n_t * cos_t) / (n_i * cos_i + n_t * cos_t);
    let rp = (n_t * cos_i - n_i * cos_t) / (n_t * cos_i + n_i * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// Single-scattering reflectance (formula in the module header) by midpoint quadrature in (μ, φ).
fn single_scattering(n: f64, albedo: f64, g: f64) -> f64 {
    let (s0, c0) = THETA0_DEG.to_radians().sin_cos();
    let sin_t = s0 / n;
    let mu_t = (1.0 - sin_t * sin_t).sqrt();
    let omega_t = [sin_t, 0.0, -mu_t];
    let hg = |c: f64| (1.0 - g * g) / (4.0 * PI * (1.0 + g * g - 2.0 * g * c).powf(1.5));
    let (nm, np) = (4000, 720);
    let mut sum = 0.0;
    for i in 0..nm {
        let mu = (i as f64 + 0.5) / nm as f64;
        let t_in = 1.0 - fresnel(mu, n, 1.0);
        if t_in == 0.0 {
            continue;
        }
        let sin = (1.0 - mu * mu).sqrt();
        for j in 0..np {
            let phi = 2.0 * PI * (j as f64 + 0.5) / np as f64;
            let c = omega_t[0] * sin * phi.cos() + omega_t[2] * mu;
            sum += hg(c) * t_in * mu / (mu + mu_t);
        }
    }
    let integral = sum * (1.0 / nm as f64) * (2.0 * PI / np as f64);
    c0 * (1.0 - fresnel(c0, 1.0, n)) * albedo * integral
}

#[test]
fn quadrature_reproduces_normal_incidence_closed_form() {
    // Index-matched and isotropic, the 2-D quadrature reduces to a 1-D integral (a check of the
    // quadrature, not of the renderer).
    let a = 0.8;
    let mu_t = THETA0_DEG.to_radians().cos();
    let n1 = 200_000;
    let one_d: f64 = (0..n1)
        .map(|i| {
            let mu = (i as f64 + 0.5) / n1 as f64;
            mu / (mu + mu_t)
        })
        .sum::<f64>()
        / n1 as f64;
    let expected = mu_t * a * 0.5 * one_d; // isotropic: 2π · 1/(4π)
    let got = single_scattering(1.0, a, 0.0);
    assert!((got / expected - 1.0).abs() < 1e-6, "{got} vs {expected}");
}

#[test]
fn oblique_single_scattering_matches() {
    let cancel = AtomicBool::new(false);
    let mut report = Vec::new();
    let mut failed = false;
    for (n, albedo, g) in [(1.33, 0.8, 0.5), (1.5, 0.95, -0.3)] {
        let expected = single_scattering(n, albedo, g);
        let scene = common::scene(&slab(n, albedo, g), &[]);
        let mut v = Vec::new();
        for b in 0..16u64 {
            let opts = RenderOptions { spp: Some(16384), seed: 701 + b, time_budget: None, progress: false };
            let out = render(&scene, &opts, &cancel);
            assert_eq!(out.stats.rejected_samples, 0);
            v.push(out.data[0] as f64);
        }
        let m = v.iter().sum::<f64>() / 16.0;
        let se = (v.iter().map(|x| (x - m) * (x - m)).sum::<f64>() / 15.0 / 16.0).sqrt();
        let z = (m - expected) / se;
        report.push(format!(
            "n={n} a={albedo} g={g}: {m:.5} ± {se:.5}, R_ss {expected:.5}, rel {:+.3}%, z {z:+.2}",
            (m / expected - 1.0) * 100.0
        ));
        // Šidák over 2 cases at 1 %, Student t with 15 degrees of freedom: |t| < 3.29; the
        // standard error must resolve 1 %.
        failed |= z.abs() > 3.29 || se / expected > 0.0033;
    }
    eprintln!("{}", report.join("\n"));
    assert!(!failed, "{}", report.join("\n"));
}

//! The irradiance meter's glint mixture (`manifold/meter_glint.rs`, `connection = complete`):
//! an absorbing slab (albedo 0) behind a GGX `roughdielectric` (n = 1.33) under a directional
//! beam, read by the meter on the `null` quad above. Nothing comes back from the medium, so the
//! reading is the rough surface's reflection alone (class `surface`): `cos θ_i · R(θ_i)` with
//! `R = ∫ f_r cos θ_o dω_o`, computed here by a midpoint quadrature over the half vector
//! (`f_r cos θ_o dω_o = F D G |ω_i·h| / cos θ_i dω_h`, Walter et al. 2007, Eqs. 14, 20), not by
//! the renderer. Sample counts chosen before the first run: 8 batches × 4096 samples.

use crate::common;
use snee::bsdf::fresnel::fresnel;
use snee::bsdf::microfacet::{MicrofacetDistribution, MicrofacetType};
use snee::math::{Vec2, Vec3};

/// `R(θ_i)` of the GGX reflection lobe by a midpoint rule over the `D(h) cos θ_h` warp of the unit
/// square (`n × n` cells): the mean of `F G |ω_i·h| / (cos θ_i cos θ_h)` where `ω_o` is above.
fn reflectance(alpha: f32, eta: f32, wi: Vec3, n: usize) -> f64 {
    let dist = MicrofacetDistribution::new(MicrofacetType::Ggx, alpha, alpha, false);
    let mut sum = 0.0f64;
    for i in 0..n {
        for j in 0..n {
            let u = Vec2::new((i as f32 + 0.5) / n as f32, (j as f32 + 0.5) / n as f32);
            let (h, _) = dist.sample(wi, u);
            let wo = 2.0 * wi.dot(h) * h - wi;
            if wo.z <= 0.0 {
                continue;
            }
            let f = fresnel(wi.dot(h), eta).0;
            sum += (f * dist.g(wi, wo, h) * wi.dot(h).abs() / (wi.z * h.z)) as f64;
        }
    }
    sum / (n * n) as f64
}

#[test]
fn meter_reads_the_rough_reflection() {
    for (alpha, beam) in [(0.01f32, Vec3::new(0.0, 0.0, -1.0)), (0.003, Vec3::new(0.35, 0.0, -1.0).normalize())] {
        let boundary = format!(
            r#"<bsdf type="roughdielectric"><string name="distribution" value="ggx"/><float name="alpha" value="{alpha}"/><float name="int_ior" value="1.33"/></bsdf>"#
        );
        let integrator = r#"<integrator type="volpath_snee"><integer name="max_depth" value="-1"/><string name="connection" value="complete"/></integrator>"#;
        let xml = common::slab_scene(integrator, &format!("{}, {}, {}", beam.x, beam.y, beam.z), 0.0, 0.0, &boundary);
        let scene = common::scene(&xml, &[]);
        let (m, se, rejected) = common::meter_reading(&scene, 4096, 8, 300);
        let wi = -beam;
        let expected = wi.z as f64 * reflectance(alpha, 1.33, wi, 2000);
        eprintln!("alpha {alpha}: meter {m:.6} ± {se:.6}, quadrature {expected:.6}");
        assert_eq!(rejected, 0);
        // The glint is resolved: without the mixture one sample in ~1/α² would see it.
        assert!(se < 0.01 * expected, "standard error {se} too large for a test");
        assert!((m - expected).abs() < 4.0 * se, "meter {m} ± {se} vs quadrature {expected}");
    }
}

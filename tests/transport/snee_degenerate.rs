//! No NaN/Inf from `volpath_snee` in degenerate media (g = ±0.99, albedo 1, σt = 0, chromatic
//! σt with a zero channel), behind smooth and rough boundaries, under directional, constant and
//! area light; and the distance-sampling mixture against its density (1-D histogram, chi-square).

use crate::common;

use snee::integrator::snee::distance::DistanceSampler;
use snee::math::Vec3;
use snee::render::{render, RenderOptions};
use snee::sampler::Sampler;
use snee::testing::chi2::chi2_discrete;
use std::sync::atomic::AtomicBool;

fn xml(medium: &str, bsdf: &str) -> String {
    format!(
        r#"<scene version="3.0.0">
<integrator type="volpath_snee"><integer name="max_depth" value="20"/></integrator>
<sensor type="perspective"><float name="fov" value="30"/>
    <transform name="to_world"><lookat origin="0, 0, 4" target="0, 0, 0" up="0, 1, 0"/></transform>
    <film type="hdrfilm"><integer name="width" value="12"/><integer name="height" value="12"/></film></sensor>
<emitter type="directional"><vector name="direction" value="0.3, -1, -0.2"/><rgb name="irradiance" value="2, 2, 2"/></emitter>
<emitter type="constant"><rgb name="radiance" value="0.5, 0.5, 0.5"/></emitter>
<shape type="sphere"><point name="center" x="3" y="4" z="2"/><float name="radius" value="0.3"/>
    <emitter type="area"><rgb name="radiance" value="20, 20, 20"/></emitter></shape>
<medium type="homogeneous" id="m">{medium}</medium>
<shape type="sphere"><float name="radius" value="1"/>{bsdf}<ref name="interior" id="m"/></shape>
</scene>"#
    )
}

#[test]
fn no_nan_or_inf() {
    let media = [
        r#"<float name="sigma_t" value="2"/><float name="albedo" value="1"/><phase type="hg"><float name="g" value="0.99"/></phase>"#,
        r#"<float name="sigma_t" value="2"/><float name="albedo" value="1"/><phase type="hg"><float name="g" value="-0.99"/></phase>"#,
        r#"<float name="sigma_t" value="0"/><float name="albedo" value="0.8"/>"#,
        r#"<rgb name="sigma_t" value="1, 0, 0.5"/><float name="scale" value="4"/><float name="albedo" value="1"/>"#,
    ];
    let bsdfs = [
        r#"<bsdf type="dielectric"><float name="int_ior" value="1.5"/></bsdf>"#,
        r#"<bsdf type="roughdielectric"><string name="distribution" value="beckmann"/><float name="alpha" value="0.01"/></bsdf>"#,
    ];
    let cancel = AtomicBool::new(false);
    for m in media {
        for b in bsdfs {
            let scene = common::scene(&xml(m, b), &[]);
            let out =
                render(&scene, &RenderOptions { spp: Some(16), seed: 9, time_budget: None, progress: false }, &cancel);
            assert_eq!(out.stats.rejected_samples, 0, "{} / {}", m, b);
            assert!(out.data.iter().all(|v| v.is_finite()), "{} / {}", m, b);
        }
    }
}

/// Histogram of `t` over bins of the map t = s/(1−s), s ∈ [0,1), against the integrated pdf.
fn histogram_test(sampler_of: DistanceSampler, which: &str) {
    let bins = 64;
    let n = 200_000;
    let mut counts = vec![0u64; bins];
    let mut rng = Sampler::new(17, 3);
    for _ in 0..n {
        let u = rng.next_1d();
        let t = match which {
            "mix" => sampler_of.sample(u),
            _ => unreachable!(),
        };
        let s = t / (1.0 + t);
        counts[((s * bins as f32) as usize).min(bins - 1)] += 1;
    }
    let probs: Vec<f64> = (0..bins)
        .map(|b| {
            let k = 200;
            (0..k)
                .map(|i| {
                    let s = (b as f64 + (i as f64 + 0.5) / k as f64) / bins as f64;
                    let t = s / (1.0 - s);
                    sampler_of.pdf(t as f32) as f64 / ((1.0 - s) * (1.0 - s))
                })
                .sum::<f64>()
                / (k * bins) as f64
        })
        .collect();
    let r = chi2_discrete(&counts, 0, &probs, 0.01);
    assert!(r.passed, "{}", r.report);
}

#[test]
fn distance_mixture_chi2() {
    // Transmittance + equiangular mixture, equiangular alone (σt = 0), transmittance alone (centre on the ray).
    let cases = [
        DistanceSampler::new(Vec3::ZERO, Vec3::Z, Vec3::new(0.4, 0.0, 1.5), 1.3),
        DistanceSampler::new(Vec3::ZERO, Vec3::Z, Vec3::new(0.2, 0.1, -0.5), 0.0),
        DistanceSampler::new(Vec3::ZERO, Vec3::Z, Vec3::new(0.0, 0.0, 2.0), 0.7),
    ];
    for c in cases {
        histogram_test(c.expect("sampler"), "mix");
    }
}
